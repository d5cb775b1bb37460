"""Load sharing of the wheelset case: equilibrium with the contact model's own normal forces ("model").

CONTACT (Vollebregt) solves a wheel's patches under approach control, all sharing the wheelset's one rigid
displacement, and adjusts the pose until each wheel carries its load; ``load_sharing = "model"`` does the same
with any registered model. References used here:

* elliptic case (circular wheel on circular rail head, one Hertzian patch per wheel, quadric gap): the model
  equilibrium must differ from Hertz's only by the BEM's discretisation error, predicted independently from one
  BEM approach-control solve at the Hertz approach: F_bem(q_H) = F_H (1 + e_F) and F ~ q^1.5 give
  q_model / q_H - 1 = -(2/3) e_F + O(e_F^2);
* the equilibrium itself: the final patches' vertical force components sum to W per wheel;
* round trip of one patch: BEM under approach control, then BEM under force control with that force, gives back
  the approach.

Recorded (not asserted), Manchester A-2.2 at 5 mm shift / 12 mrad yaw, 10 kN per wheel, bem 40 x 40, default
search field (run of this commit): the right wheel has two patches, contact angles 17.1 deg (flange root) and
7.6 deg (tread). Vertical load split flange-root / tread: Hertz sharing 8033.0 / 1967.0 N, model sharing
8040.0 / 1960.0 N (normal forces 8405.9 / 1984.2 N vs 8413.2 / 1977.2 N): the BEM moves 7 N (0.35 % of the
tread patch's load) to the flange-root patch. Under Hertz sharing the BEM's own approaches of the two patches
(force control) differ from the search's common rigid approach by -0.07 % and +0.13 %; under model sharing they
equal it. Roll -3.5488e-4 (Hertz) vs -3.5493e-4 rad (model); 3 model iterations (Broyden from the Hertz Jacobian).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.hertz import hertz_force_from_approach
from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.types import Creepage
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
from rigid_dynamics.materials import STEEL

CANT = math.atan(1 / 40)
LOAD_N = 10e3
FORCE_TOLERANCE = 1e-6  # DEFAULT_CASE_OPTIONS["force_tolerance"]
QUADRIC = {"search": {"field": False}}  # patches keep the quadric gap: exactly Hertzian geometry


def circular_case(**kwargs):
    """Circular wheel profile (R 100 mm) on a circular rail head (R 300 mm), shifted 2 mm: roll != 0."""
    args = dict(
        wheel_profile="circ_r100",
        rail_profile="circ_r300",
        lateral_shift_m=0.002,
        wheel_load_N=LOAD_N,
        rolling_speed_m_per_s=2.0,
    )
    args.update(kwargs)
    return WheelsetCase(**args)


def a22_5mm():
    return WheelsetCase(
        wheel_profile="MBench_S1002_v3",
        rail_profile="MBench_UIC60_v3",
        lateral_shift_m=5e-3,
        yaw_rad=12e-3,
        rail_inclination_rad=CANT,
        wheel_load_N=LOAD_N,
        rolling_speed_m_per_s=2.0,
    )


def wheel_loads(solution):
    """Sum over each wheel's final patches of N_k (-n_z,k), N (independent of the solver's own bookkeeping)."""
    return {side: sum(p.vertical_force_N for p in solution.patches if p.side == side) for side in ("left", "right")}


@pytest.fixture(scope="module")
def circular_track():
    return build_track(circular_case())


@pytest.fixture(scope="module")
def a22_solutions():
    case = a22_5mm()
    track = build_track(case)
    return {
        "default": solve_wheelset_case(case, STEEL, "bem", track=track),
        "hertz": solve_wheelset_case(case, STEEL, "bem", {"load_sharing": "hertz"}, track=track),
    }


def test_elliptic_model_sharing_differs_from_hertz_by_the_bem_discretisation_error(circular_track):
    case = circular_case()
    hertz = solve_wheelset_case(case, STEEL, "bem", dict(QUADRIC, load_sharing="hertz"), track=circular_track)
    model = solve_wheelset_case(case, STEEL, "bem", dict(QUADRIC, load_sharing="model"), track=circular_track)
    assert hertz.success and model.success, (hertz.message, model.message)
    assert (hertz.load_sharing, model.load_sharing) == ("hertz", "model")
    assert model.model_iterations >= 1
    assert model.equilibrium_residual < FORCE_TOLERANCE
    for side, load in wheel_loads(model).items():
        assert load == pytest.approx(LOAD_N, rel=FORCE_TOLERANCE), side
    bem = get_model("bem")
    for ph, pm in zip(hertz.patches, model.patches, strict=True):
        assert ph.side == pm.side and ph.geometry.is_elliptic
        g = ph.geometry
        f_hertz = float(
            hertz_force_from_approach(
                g.curvature_long_1_per_m,
                g.curvature_lat_1_per_m,
                g.approach_m,
                shear_modulus_Pa=STEEL.shear_modulus_Pa,
                poisson_ratio=STEEL.poisson_ratio,
            )
        )
        e_force = bem.solve(g, Creepage(), STEEL).normal_force_N / f_hertz - 1.0
        assert 0 < abs(e_force) < 2e-3  # the 40 x 40 BEM's error on a Hertz ellipse
        observed = pm.geometry.approach_m / g.approach_m - 1.0
        # one wheel, one patch: both sharings carry W; the poses differ by the approach the BEM needs
        assert observed == pytest.approx(-2.0 / 3.0 * e_force, abs=FORCE_TOLERANCE), (observed, e_force)
        assert pm.result.normal_force_N == pytest.approx(ph.result.normal_force_N, rel=2 * FORCE_TOLERANCE)
        # approach control at the equilibrium: the BEM's approach is the search's rigid approach
        assert pm.result.approach_m == pytest.approx(pm.geometry.approach_m, rel=1e-12)


def test_a22_two_patches_carry_the_wheel_load_with_the_bems_own_split(a22_solutions):
    model, hertz = a22_solutions["default"], a22_solutions["hertz"]
    assert model.success, model.message
    assert model.load_sharing == "model"  # default for bem: two patches on the right wheel
    right = [p for p in model.patches if p.side == "right"]
    assert len(right) == 2 and not all(p.geometry.is_elliptic for p in right)
    assert model.equilibrium_residual < FORCE_TOLERANCE
    for side, load in wheel_loads(model).items():
        assert load == pytest.approx(LOAD_N, rel=FORCE_TOLERANCE), side
    for p in model.patches:
        assert p.result.success, p.result.message
        assert p.result.approach_m == pytest.approx(p.geometry.approach_m, rel=1e-12)
        assert p.result.creep_force_lat_N is not None and p.result.creep_force_lat_N < 0  # solved tangentially
    # Hertz sharing (force control): the same wheel loads, but each patch's BEM approach departs from the common
    # rigid approach of the wheel (the inconsistency the model sharing removes); see the module docstring.
    assert hertz.success and hertz.load_sharing == "hertz"
    for side, load in wheel_loads(hertz).items():
        assert load == pytest.approx(LOAD_N, rel=FORCE_TOLERANCE), side
    mismatch = [p.result.approach_m / p.geometry.approach_m - 1 for p in hertz.patches if p.side == "right"]
    assert max(abs(m) for m in mismatch) > 1e-4


def test_bem_approach_control_round_trips_through_force_control(a22_solutions):
    """One non-elliptic patch (flange root): BEM approach control gives F; BEM force control with F gives back the
    approach (NORM's two modes agree), and the case's final patch is that approach-control solution."""
    patch = max((p for p in a22_solutions["default"].patches if p.side == "right"), key=lambda p: p.geometry.approach_m)
    g = patch.geometry
    assert not g.is_elliptic
    bem = get_model("bem")
    by_approach = bem.solve(g, Creepage(), STEEL)
    by_force = bem.solve(g, Creepage(), STEEL, normal_force_N=by_approach.normal_force_N)
    assert by_approach.success and by_force.success
    assert by_force.approach_m == pytest.approx(g.approach_m, rel=1e-6)
    assert by_force.max_pressure_Pa == pytest.approx(by_approach.max_pressure_Pa, rel=1e-5)
    assert patch.result.normal_force_N == pytest.approx(by_approach.normal_force_N, rel=1e-9)


def test_model_sharing_with_hertz_is_the_hertz_equilibrium(circular_track):
    """Invariant: the hertz model's normal part IS Hertz, so model sharing stops at its first iteration."""
    case = circular_case()
    ref = solve_wheelset_case(case, STEEL, "hertz", QUADRIC, track=circular_track)
    model = solve_wheelset_case(case, STEEL, "hertz", dict(QUADRIC, load_sharing="model"), track=circular_track)
    assert ref.load_sharing == "hertz" and model.load_sharing == "model"
    assert model.success and model.model_iterations == 1
    assert model.vertical_position_m == ref.vertical_position_m and model.roll_rad == ref.roll_rad
    for a, b in zip(ref.patches, model.patches, strict=True):
        assert b.result.normal_force_N == pytest.approx(a.result.normal_force_N, rel=1e-12)


def test_default_sharing_and_approach_control(circular_track):
    case = circular_case()
    elliptic = solve_wheelset_case(case, STEEL, "bem", QUADRIC, track=circular_track)
    assert elliptic.success and elliptic.load_sharing == "hertz"  # one elliptic patch per wheel
    approach = solve_wheelset_case(
        circular_case(wheel_load_N=None, approach_m=2e-5), STEEL, "bem", QUADRIC, track=circular_track
    )
    assert approach.success and approach.load_sharing == "approach"
    assert math.isnan(approach.equilibrium_residual)


def test_model_phase_not_converged_is_reported(circular_track):
    options = dict(QUADRIC, load_sharing="model", model_max_iterations=1)
    sol = solve_wheelset_case(circular_case(), STEEL, "bem", options, track=circular_track)
    assert not sol.success and sol.status == "not-converged"
    assert "did not converge in 1 iterations" in sol.message
    assert sol.equilibrium_residual > FORCE_TOLERANCE
    assert np.isfinite(sol.vertical_position_m)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"load_sharing": "kalker"}, "load_sharing = 'kalker'"),
        ({"model_max_iterations": 0}, "model_max_iterations = 0"),
        ({"model_max_iterations": 2.5}, "model_max_iterations = 2.5"),
    ],
)
def test_bad_load_sharing_options_raise(options, match):
    with pytest.raises(ValueError, match=match):
        solve_wheelset_case(circular_case(), STEEL, "bem", options)
