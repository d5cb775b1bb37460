"""The FEA's discretisation error (fea.refinement): Richardson's estimate against closed forms.

* Synthetic sequences Q_k = Q + C h_k^p with known Q: the estimate of the finest level's error (exact for p = 1,
  the order it assumes at most; conservative for p = 2; a chance crossing of the limit is caught).
* The Hertz case of tests/test_fea_contact.py (R_long 0.46 m, R_lat 0.15 m, P = 100 kN, E 210 GPa, nu 0.3;
  Johnson 1985 eq 3.64: p0 = 1604.6 MPa, a = 7.909 mm, b = 3.762 mm, approach 0.11517 mm) solved to
  mesh_tolerance 1 %: p0, a, b and the approach within 1 % of the closed form, and on every level of the
  refinement series the stated error of each quantity at least its true error (the estimate brackets it).
"""

import math

import pytest

from fea.refinement import REFINEMENT_RATIO, estimate, richardson_error


def _sequence(limit, constant, order, levels=3, h0=1.0):
    return [limit + constant * (h0 / REFINEMENT_RATIO**k) ** order for k in range(levels)]


def test_richardson_is_exact_for_a_first_order_sequence():
    values = _sequence(2.0, 0.3, 1.0)
    error, order, observed = richardson_error(values)
    assert observed == pytest.approx(1.0)
    assert order == pytest.approx(1.0)
    assert error == pytest.approx(abs(values[-1] - 2.0), rel=1e-12)


def test_richardson_is_conservative_for_a_second_order_sequence():
    values = _sequence(2.0, -0.3, 2.0)
    error, order, observed = richardson_error(values)
    assert observed == pytest.approx(2.0) and order == 1.0  # capped at the nominal first order
    assert error > abs(values[-1] - 2.0)


def test_two_levels_assume_first_order_and_a_crossing_uses_the_previous_difference():
    error, order, observed = richardson_error([1.1, 1.05])
    assert observed is None and order == 1.0 and error == pytest.approx(0.1)
    # 1.10 -> 1.0001 -> 1.0000: the values crossed their limit (1.03 say) by chance; the last difference alone
    # would claim 2e-4
    error, _, observed = richardson_error([1.10, 1.0001, 1.0])
    assert observed > 3 and error == pytest.approx(0.0999 / REFINEMENT_RATIO / (REFINEMENT_RATIO - 1))


def test_estimate_adds_the_block_size_error_to_force_approach_and_pressure_only():
    levels = [{"approach": 1.0, "contact_area": 10.0}, {"approach": 1.01, "contact_area": 10.1}]
    out = estimate(levels, {"approach": 1.02, "contact_area": 10.5})
    assert out["block_size_relative_error"]["contact_area"] is None
    assert out["block_size_relative_error"]["approach"] == pytest.approx(0.02 / (1 - 2**-0.75) / 1.01)
    assert out["relative_error"]["approach"] == pytest.approx(
        out["mesh_relative_error"]["approach"] + out["block_size_relative_error"]["approach"]
    )


def test_approach_control_takes_the_pressure_block_error_as_a_third_of_the_force_s():
    """Hertz at a fixed patch shape: N ~ q^(3/2), p ~ q^(1/2), so dp/p = dN/(3 N); the two blocks' coarse-mesh
    pressures (which differ by mesh scatter, here 10 %) are not used under approach control."""
    levels = [{"normal_force": 100.0, "max_pressure": 1.0}, {"normal_force": 100.0, "max_pressure": 1.0}]
    block = {"normal_force": 102.0, "max_pressure": 1.1}
    force = estimate(levels, block, approach_control=True)["block_size_relative_error"]["normal_force"]
    out = estimate(levels, block, approach_control=True)["block_size_relative_error"]["max_pressure"]
    assert out == pytest.approx(force / 3.0)
    assert estimate(levels, block)["block_size_relative_error"]["max_pressure"] == pytest.approx(0.1 / (1 - 2**-0.75))


def test_richardson_needs_two_levels():
    with pytest.raises(ValueError, match="at least two levels"):
        richardson_error([1.0])


@pytest.mark.fea
@pytest.mark.slow
def test_hertz_within_one_percent_and_the_estimate_brackets_the_true_error():
    from fea.hertz_reference import hertz_elliptic
    from fea.model import FeaModel
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    steel = Material.from_young(210e9, 0.3, 0.3)
    geo = ContactGeometry.quadric(0.46, 0.15)
    ref = hertz_elliptic(geo.curvature_long_1_per_m, geo.curvature_lat_1_per_m, 1e5, steel.combined_modulus_Pa)
    exact = {
        "max_pressure": ref.max_pressure_Pa,
        "semi_axis_long": ref.semi_axis_long_m,
        "semi_axis_lat": ref.semi_axis_lat_m,
        "approach": ref.approach_m,
        "contact_area": math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m,
    }
    assert ref.max_pressure_Pa == pytest.approx(1604.6e6, rel=1e-4)
    options = {"degree": 2, "elements_per_semi_axis": 3, "domain_factor": 80, "mesh_tolerance": 0.01, "stresses": False}
    r = FeaModel().solve(geo, Creepage(), steel, normal_force_N=1e5, options=options)
    assert r.success and r.status == "ok", r.message
    info = r.extra["discretisation_error"]
    levels = info["levels"]
    assert len(levels) >= 2 and info["estimated"]
    for name, value in (
        ("max_pressure", r.max_pressure_Pa),
        ("semi_axis_long", r.semi_axis_long_m),
        ("semi_axis_lat", r.semi_axis_lat_m),
        ("approach", r.approach_m),
    ):
        assert value == pytest.approx(exact[name], rel=0.01), name
    for name in ("max_pressure", "contact_area"):
        assert info["relative_error"][name] <= 0.01
    block = {k: v for k, v in info["block_size_check"].items() if k != "domain_factor"}
    for k in range(1, len(levels)):
        stated = estimate(levels[: k + 1], block)["relative_error"]
        for name, value in exact.items():
            true = abs(levels[k][name] / value - 1.0)
            assert true <= stated[name], f"level {k} {name}: true {true:.4%} > stated {stated[name]:.4%}"


@pytest.mark.fea
def test_one_element_per_semi_axis_does_not_end_ok():
    """A budget that stops the series above the tolerance gives status "mesh-tolerance-not-met" (not "ok")."""
    from fea.model import FeaModel
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    options = {"elements_per_semi_axis": 1, "max_dofs": 3000, "stresses": False}
    r = FeaModel().solve(
        ContactGeometry.quadric(0.46, 0.15),
        Creepage(),
        Material.from_young(210e9, 0.3, 0.3),
        normal_force_N=1e5,
        options=options,
    )
    assert r.success and r.status == "mesh-tolerance-not-met"
    assert "above mesh_tolerance = 0.02" in r.message and "max_dofs = 3000" in r.message
    info = r.extra["discretisation_error"]
    assert info["estimated"] and max(info["relative_error"][n] for n in info["judged"]) > 0.02


@pytest.mark.fea
def test_without_tolerance_the_error_is_not_estimated():
    from fea.model import FeaModel
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    r = FeaModel().solve(
        ContactGeometry.quadric(0.46, 0.15),
        Creepage(),
        Material.from_young(210e9, 0.3, 0.3),
        normal_force_N=1e5,
        options={"quick": True, "mesh_tolerance": None, "stresses": False},
    )
    assert r.success and r.status == "error-not-estimated"
    assert r.extra["discretisation_error"] == {
        "estimated": False,
        "reason": "mesh_tolerance is None: one mesh, no error estimate",
    }


@pytest.mark.parametrize(
    ("options", "match"),
    [({"mesh_tolerance": 0.0}, "mesh_tolerance"), ({"grading": -1.0}, "grading"), ({"max_dofs": 0}, "max_dofs")],
)
def test_bad_refinement_options_raise(options, match):
    from fea.model import FeaOptions

    with pytest.raises(ValueError, match=match):
        FeaOptions.from_mapping(options)
