"""The wheelset equilibrium's FEA series at P2 (fea.model ``load_balanced_options``): defaults, the coarser levels a P2
series may put before its first, and the stated errors against Hertz's closed form on a narrow sampled gap.

Why P2 (benchmarks/results/fea_flange_root_p2.md): on manchester-a22's flange-root patch (a strip 1.4 mm wide) P1's
max pressure at one load went 1619, 1577, 1547 MPa at 9.5e3, 2.8e4, 8.6e4 unknowns (order 0.9, about 1e6 unknowns
for 2 %), P2's 1520.1, 1522.1, 1521.1 MPa at 3.0e4, 7.1e4, 2.2e5 against our BEM's converged 1521.2 MPa on the same
gap and force.
"""

import math

import numpy as np
import pytest


def test_load_balanced_options_default_to_p2_from_2_67_elements_unless_the_degree_is_given():
    from fea.model import LOAD_BALANCED_ELEMENTS_PER_SEMI_AXIS, FeaModel

    out = FeaModel.load_balanced_options({"stresses": False})
    assert out == {"stresses": False, "load_balanced": True, "degree": 2,
                   "elements_per_semi_axis": LOAD_BALANCED_ELEMENTS_PER_SEMI_AXIS}  # fmt: skip
    assert LOAD_BALANCED_ELEMENTS_PER_SEMI_AXIS == pytest.approx(6.0 / 1.5**2)
    assert FeaModel.load_balanced_options({"elements_per_semi_axis": 4})["elements_per_semi_axis"] == 4
    assert FeaModel.load_balanced_options({"degree": 1}) == {"degree": 1, "load_balanced": True}
    assert "degree" not in FeaModel.load_balanced_options({"formulation": "two-body"})
    assert FeaModel.coarse_options({}) == {"mesh_tolerance": None}  # the coarse phase stays P1


class _Result:
    def __init__(self, n):
        self.status, self.message = "ok", "ok"
        self.max_pressure_Pa, self.contact_area_m2, self.normal_force_N = 1e9, 1e-5, 1e4
        self.approach_m = self.semi_axis_long_m = self.semi_axis_lat_m = None
        self.extra = {"dofs": int(1e4 * n**3)}


@pytest.mark.parametrize(("degree", "expected"), [(1, [6.0 / 1.5**2]), (2, [6.0 / 1.5**3, 6.0 / 1.5**4])])
def test_a_p2_series_puts_levels_down_to_one_element_per_semi_axis_before_its_first(degree, expected):
    """ORDER_LEVEL_MIN_N (2) counts P1 elements: P2's n elements have the 2 n node intervals of P1's 2 n, so a P2
    series whose first level is 2.67 elements per semi-axis puts 1.78 and 1.19 before it, a P1 series from 4 only
    2.67 (1.78 < 2). Regression test of the rule (a fake level solver)."""
    from fea.model import FeaOptions
    from fea.refinement import FIRST_LEVEL_BUDGET_COARSER, _insert_coarser

    n0 = 6.0 / 1.5 ** (2 if degree == 2 else 1)
    opts = FeaOptions.from_mapping({"degree": degree, "elements_per_semi_axis": n0})
    solved = []

    def solve_level(level_opts, force_N=None):
        solved.append(level_opts.n_per_semi_axis)
        return _Result(level_opts.n_per_semi_axis), None

    levels, records, info = [{}], [{}], {}
    _insert_coarser(solve_level, opts, levels, records, info, FIRST_LEVEL_BUDGET_COARSER, 1e4)
    assert solved == pytest.approx(expected)
    assert [r["elements_per_semi_axis"] for r in records[:-1]] == pytest.approx(expected[::-1])


@pytest.mark.fea
@pytest.mark.slow
def test_a_load_balanced_p2_series_on_a_narrow_sampled_hertz_gap_brackets_hertz():
    """A very elliptic Hertz gap given as samples (A = 0.02, B = 0.6 1/m: a/b = 8.9, the proportions of a flange-root
    strip), E 210 GPa, nu 0.3, under approach control at Hertz's approach for 100 kN, solved as the wheelset
    equilibrium does (``load_balanced_options``: P2 from 2.67 elements per semi-axis, the coarser levels at the
    finest level's force): the max pressure and the area at the finest level's force are within their stated errors
    of Hertz's closed form at that force (Johnson 1985, eq 3.64)."""
    from fea.hertz_reference import hertz_elliptic
    from fea.model import FeaModel
    from rigid_dynamics.contact.types import ContactGeometry, Creepage, UndeformedDistance
    from rigid_dynamics.materials import Material

    steel = Material.from_young(210e9, 0.3, 0.3)
    x, y = np.linspace(-0.06, 0.06, 601), np.linspace(-0.01, 0.01, 101)
    gx, gy = np.meshgrid(x, y)
    a_curv, b_curv = 0.02, 0.6
    approach = hertz_elliptic(a_curv, b_curv, 1e5, steel.combined_modulus_Pa).approach_m
    gap = UndeformedDistance(x, y, a_curv * gx**2 + b_curv * gy**2)
    geo = ContactGeometry(a_curv, b_curv, approach_m=approach, undeformed=gap)
    options = FeaModel.load_balanced_options({"stresses": False})
    r = FeaModel().solve(geo, Creepage(), steel, options=options)
    assert r.success and r.status in ("ok", "mesh-tolerance-not-met"), r.message
    info = r.extra["discretisation_error"]
    assert info["estimated"] and len(info["levels"]) >= 2
    ref = hertz_elliptic(a_curv, b_curv, r.normal_force_N, steel.combined_modulus_Pa)
    area = math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m
    true_p, true_area = abs(r.max_pressure_Pa / ref.max_pressure_Pa - 1), abs(r.contact_area_m2 / area - 1)
    stated = info["relative_error"]
    print(f"p {r.max_pressure_Pa / 1e6:.2f} MPa true {true_p:.3%} stated {stated['max_pressure']:.3%}; area "
          f"{r.contact_area_m2 * 1e6:.3f} mm2 true {true_area:.3%} stated {stated['contact_area']:.3%}; "
          f"levels {[round(lv['elements_per_semi_axis'], 3) for lv in info['levels']]} {r.status}")  # fmt: skip
    assert true_p <= stated["max_pressure"]
    assert true_area <= stated["contact_area"]
