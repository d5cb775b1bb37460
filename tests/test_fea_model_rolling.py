"""The FEA contact model's creep forces (fea.model "Creep forces"): the rolling mesh series wired into FeaModel.

Physics: the Hertz circle (R = 0.3 m both ways, P = 10 kN, E = 210 GPa, nu = 0.3, mu = 0.3) at xi = 5e-4 (F about
0.37 mu P) through ``FeaModel.solve``: the creep force of the series' finest mesh (n = 9) within its stated error of
the BEM's (a second method, its own stated grid error added), and with the BEM's sign (on the wheel, opposing the
creepage). Measured: -1146.4 N against the BEM's -1115.7 N (2.8 %), stated 6.4 % (benchmarks/results/fea_friction.md
has the series itself). About 25 s CPU for the series (three rolling blocks) and 3 s for the BEM.

Wiring (fast, the series replaced by a fabricated one or not reached): a series that is not "ok" gives creep forces
None with its status and reason, never a number; spin, the option "off" and bad options are statuses or one-line
errors.
"""

import math
import time

import pytest

from fea.model import FeaModel, FeaOptions
from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

pytestmark = pytest.mark.fea

RADIUS_M, FORCE_N, XI = 0.3, 1e4, 5e-4
STEEL = Material.from_young(210e9, 0.3, 0.3)
CIRCLE = ContactGeometry.quadric(RADIUS_M, RADIUS_M)
NORMAL_OPTIONS = {"quick": True, "mesh_tolerance": None, "stresses": False}
"""A cheap normal solve (one coarse mesh): the creep forces come from the series' own meshes."""


@pytest.mark.slow
def test_fea_model_creep_force_within_its_stated_error_of_the_bem_with_the_bems_sign():
    from comparisons.stated_errors import stated_errors
    from rigid_dynamics.contact.registry import get_model

    creepage = Creepage(longitudinal=XI)
    fea = FeaModel().solve(CIRCLE, creepage, STEEL, normal_force_N=FORCE_N, options=NORMAL_OPTIONS)
    tangential = fea.extra["tangential"]
    assert tangential["status"] == "ok", tangential["message"]
    assert [lv["n"] for lv in tangential["levels"]] == [4.0, 6.0, 9.0]
    bem = get_model("bem").solve(CIRCLE, creepage, STEEL, normal_force_N=FORCE_N)
    assert bem.status == "ok"
    fx, fy = fea.creep_force_long_N, fea.creep_force_lat_N
    assert fx < 0 and bem.creep_force_long_N < 0  # on the wheel, against the creepage (Carter, Kalker)
    error_x, error_y = tangential["stated_error_N"]
    band = bem.extra["grid_error"]["relative"]["creep_force_N"] * abs(bem.creep_force_long_N)
    assert abs(fx - bem.creep_force_long_N) <= error_x + band
    assert abs(fy - bem.creep_force_lat_N) <= error_y + 1e-3 * abs(fx)  # zero by the mesh's symmetry
    # the stated error where every rung states it (comparisons.stated_errors), the vector on the BEM's scale
    relative = stated_errors(fea)["creep_force_long"]
    assert relative == pytest.approx(math.hypot(error_x, error_y) / abs(math.hypot(fx, fy)), rel=1e-12)
    assert stated_errors(fea)["creep_force_lat"] == relative
    assert relative <= 0.08  # not vacuous (measured 6.4 %)
    assert "creep forces from the rolling series" in fea.message


def _unresolved_series(*args, **kwargs):
    """The xi = 5e-5 situation (fea.rolling_series): every row sticks to its last node on the coarse levels."""
    from fea.rolling_series import series_from_levels

    levels = [
        {"n": n, "creep_force_N": (f, 0.0), "slip_nodes": s, "contact_nodes": c, "rows": r}
        for n, f, s, c, r in ((4.0, -120.0, 0, 49, 7), (6.0, -110.0, 0, 107, 11), (9.0, -106.0, 4, 241, 17))
    ]
    return series_from_levels(levels, (4.0, 6.0, 9.0))


def test_an_unresolved_series_gives_no_creep_forces_and_says_why(monkeypatch):
    import fea.rolling_series

    monkeypatch.setattr(fea.rolling_series, "solve_rolling_series", _unresolved_series)
    result = FeaModel().solve(
        CIRCLE, Creepage(longitudinal=5e-5), STEEL, normal_force_N=FORCE_N, options=NORMAL_OPTIONS
    )
    assert result.success and result.normal_force_N == pytest.approx(FORCE_N, rel=1e-6)
    assert result.creep_force_long_N is None and result.creep_force_lat_N is None
    tangential = result.extra["tangential"]
    assert tangential["status"] == "unresolved" and tangential["creep_force_N"] is None
    assert tangential["message"].startswith("creep forces None: series unresolved") and "slip zone" in tangential[
        "message"]  # fmt: skip
    assert "creep_force_long" not in ((result.extra.get("discretisation_error") or {}).get("relative_error") or {})


def _normal_result():
    return ContactResult(
        method="fea", success=True, status="ok", message="normal", normal_force_N=FORCE_N, max_pressure_Pa=1e9,
        contact_area_m2=2e-5, approach_m=1e-5, creepage=Creepage(), extra={"tangential": {"status": "not-solved"}},
    )  # fmt: skip


@pytest.mark.parametrize(
    ("creepage", "options", "geometry", "status", "words"),
    [
        (Creepage(lateral=-3e-4, spin_1_per_m=0.3), {}, CIRCLE, "not-solved", "spin 0.3 1/m"),
        (Creepage(longitudinal=XI), {"rolling": "off"}, CIRCLE, "off", "rolling = 'off'"),
        (Creepage(), {}, CIRCLE, "no-creepage", "no creepage"),
        (Creepage(longitudinal=XI), {"formulation": "two-body"}, CIRCLE, "not-solved", "formulation 'two-body'"),
    ],
)
def test_patches_without_a_series_keep_creep_forces_none_with_the_reason(
    monkeypatch, creepage, options, geometry, status, words
):
    import fea.rolling_series
    from fea.model import _with_rolling

    def never(*args, **kwargs):
        raise AssertionError("the series must not run here")

    monkeypatch.setattr(fea.rolling_series, "solve_rolling_series", never)
    opts = FeaOptions.from_mapping(options)
    out = _with_rolling(_normal_result(), geometry, creepage, STEEL, FORCE_N, opts, None, time.perf_counter())
    assert out.creep_force_long_N is None and out.creep_force_lat_N is None
    assert out.extra["tangential"]["status"] == status and words in out.extra["tangential"]["message"]


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"rolling": "always"}, "'rolling' = 'always': expected one of"),
        ({"rolling_elements": [4, 6, 8]}, "constant ratio"),
        ({"rolling_elements": [4, 6]}, "three numbers"),
    ],
)
def test_bad_rolling_options_are_one_line_errors(options, match):
    with pytest.raises(ValueError, match=match) as info:
        FeaModel.check_options(options)
    assert "\n" not in str(info.value)


def test_a_stated_creep_error_above_mesh_tolerance_is_a_status(monkeypatch):
    """A regular series (fabricated: F_x -1211.0/-1171.0/-1146.4 N, observed order 1.2, stated 4.3 %) whose stated
    error is above ``mesh_tolerance``: creep forces given, status "mesh-tolerance-not-met" as the normal problem's."""
    import fea.rolling_series
    from fea.model import _with_rolling
    from fea.rolling_series import series_from_levels

    levels = [
        {"n": n, "creep_force_N": (f, 0.0), "slip_nodes": 20, "contact_nodes": 60, "rows": 7}
        for n, f in ((4.0, -1211.0), (6.0, -1171.0), (9.0, -1146.4))
    ]
    monkeypatch.setattr(
        fea.rolling_series, "solve_rolling_series", lambda *a, **k: series_from_levels(levels, (4.0, 6.0, 9.0))
    )
    creepage = Creepage(longitudinal=XI)
    for tolerance, status in ((0.04, "mesh-tolerance-not-met"), (0.05, "ok")):
        opts = FeaOptions.from_mapping({"mesh_tolerance": tolerance})
        out = _with_rolling(_normal_result(), CIRCLE, creepage, STEEL, FORCE_N, opts, None, time.perf_counter())
        assert out.creep_force_long_N == -1146.4 and out.creep_force_lat_N == 0.0
        relative = out.extra["discretisation_error"]["relative_error"]["creep_force_long"]
        assert relative == pytest.approx(24.6 / 0.5 / 1146.4)  # |F_3 - F_2| / (1.5 - 1) over |F|
        assert out.status == status and out.extra["tangential"]["status"] == "ok"
