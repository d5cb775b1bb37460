"""Wheelset contact case (Manchester benchmark A-2.2 set-up): equilibrium, placement, creepages, bad input.

Independent reference for the equilibrium: the roll angles that the CONTACT program (E.A.H. Vollebregt,
open source, Apache-2.0) computed for the same profiles, gauge, flange-back distance and load, recorded in its
example input ``examples/mbench_a22_right.inp`` (repository eve70a/CONTACT): theta = -3.5540e-4 rad at 5.0 mm,
-6.2720e-4 at 6.0 mm, -4.3760e-3 at 6.5 mm (the jump: flange contact), -6.3930e-3 at 7.0 mm and -1.126431e-2 at
10.0 mm (yaw 2.4 mrad per mm of shift). Our profile splines are smoothed over 2 mm, so a few 1e-3 relative
difference is expected.
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
from rigid_dynamics.materials import STEEL

CANT = math.atan(1 / 40)


def a22(shift_mm, **kwargs):
    args = dict(
        wheel_profile="MBench_S1002_v3",
        rail_profile="MBench_UIC60_v3",
        lateral_shift_m=shift_mm * 1e-3,
        yaw_rad=shift_mm * 2.4e-3,
        rail_inclination_rad=CANT,
        wheel_load_N=10e3,
        rolling_speed_m_per_s=2.0,
    )
    args.update(kwargs)
    return WheelsetCase(**args)


NO_FIELD = {"spin_rate": "nominal"}  # the fastest kinematics (no axle-moment iteration)


def test_centred_wheelset_is_symmetric_and_carries_the_load():
    """Centred, no yaw: both wheels carry 10 kN (creep forces included), the solution is mirror-symmetric, and
    the freely rolling wheelset (zero net axle moment) has no longitudinal creepage; with phi' = V/r0 instead
    (hand derivation, test_creepage.py) xi = 1 - R_w/r0 with R_w the wheel's radius at the reference point and
    the spin -/+ sin(delta)/r0 on the left/right wheel."""
    sol = solve_wheelset_case(a22(0.0), STEEL, "linear")
    assert sol.success, sol.message
    assert sol.roll_rad == pytest.approx(0.0, abs=1e-12)
    for side in ("left", "right"):
        assert sol.wheel_vertical_load_N[side] == pytest.approx(10e3, rel=1e-5)
    left, right = (p for p in sol.patches)
    assert left.side == "left" and right.side == "right"
    np.testing.assert_allclose(left.geometry.point_m * [1, -1, 1], right.geometry.point_m, atol=1e-9)
    assert left.geometry.contact_angle_rad == pytest.approx(right.geometry.contact_angle_rad, abs=1e-9)
    assert sol.spin_rate_mode == "zero-axle-moment"
    assert abs(sol.axle_moment_Nm) < 1e-6 * 10e3 * 0.46
    for patch in (left, right):
        assert patch.creepage.longitudinal == pytest.approx(0.0, abs=1e-7)
    nominal = solve_wheelset_case(a22(0.0), STEEL, "hertz", {"spin_rate": "nominal"})
    assert nominal.spin_rate_rad_per_s == pytest.approx(2.0 / 0.46, rel=1e-12)
    for patch, sign in ((p, -1 if p.side == "left" else 1) for p in nominal.patches):
        g = patch.geometry
        xi = 1 - g.rolling_radius_m / 0.46  # relative to V (eq 41); the case divides by the mean rolling speed:
        mean = 2.0 / (2.0 - xi)  # V (2 - xi)/2 (Kalker, CONTACT)
        assert patch.creepage.longitudinal == pytest.approx(xi * mean, abs=1e-9)
        assert patch.creepage.spin_1_per_m == pytest.approx(
            mean * sign * math.sin(g.contact_angle_rad) / 0.46, rel=1e-6
        )
        assert patch.creepage.lateral == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    ("shift_mm", "roll_ref", "flange"),
    [(5.0, -3.5540e-4, False), (6.0, -6.2720e-4, False), (6.5, -4.3760e-3, True), (7.0, -6.3930e-3, True),
     (10.0, -1.126431e-2, True)],
)  # fmt: skip
def test_roll_and_flange_contact_match_contact_program(shift_mm, roll_ref, flange):
    sol = solve_wheelset_case(a22(shift_mm), STEEL, "hertz", NO_FIELD)
    assert sol.success, sol.message
    assert sol.roll_rad == pytest.approx(roll_ref, rel=0.03)
    for side in ("left", "right"):
        assert sol.wheel_vertical_load_N[side] == pytest.approx(10e3, rel=1e-5)
    right_angles = [p.geometry.contact_angle_rad for p in sol.patches if p.side == "right"]
    assert (max(right_angles) > 0.7) == flange  # flange contact: contact angle ~ 40-70 deg
    left_angles = [p.geometry.contact_angle_rad for p in sol.patches if p.side == "left"]
    assert max(left_angles) < 0.05  # the left wheel stays on its tread


def test_approach_control_sets_the_deepest_approach_on_each_wheel():
    sol = solve_wheelset_case(a22(3.0, wheel_load_N=None, approach_m=2e-5), STEEL, "hertz", NO_FIELD)
    assert sol.success, sol.message
    for side in ("left", "right"):
        deepest = max(p.geometry.approach_m for p in sol.patches if p.side == side)
        assert deepest == pytest.approx(2e-5, rel=1e-5)


def test_mean_rolling_radius_spin_gives_opposite_longitudinal_creepages():
    """With phi' = V / mean(R_left, R_right) the wheels' longitudinal creepages are nearly equal and opposite,
    as in CONTACT's A-2.2 input: xi = 1 - phi' cos(psi) r_z / V with r_z the contact point's lever (R minus half
    the approach along n), so xi_left + xi_right = O(psi^2 + q/r0)."""
    options = {"search": {"field": False}, "spin_rate": "mean-rolling-radius"}
    case = a22(3.0)
    sol = solve_wheelset_case(case, STEEL, "hertz", options)
    xi = {p.side: p.creepage.longitudinal for p in sol.patches}
    q = max(p.geometry.approach_m for p in sol.patches)
    assert abs(xi["left"] + xi["right"]) < case.yaw_rad**2 + 2 * q / 0.46
    assert abs(xi["left"]) > 5e-4


def test_patch_fields_and_rail_coordinates_are_filled():
    sol = solve_wheelset_case(a22(7.0), STEEL, "hertz")
    flange = max((p for p in sol.patches if p.side == "right"), key=lambda p: p.geometry.contact_angle_rad)
    g = flange.geometry
    assert g.undeformed is not None and g.undeformed.distance_m.shape == (25, 25)
    assert np.nanmin(g.undeformed.distance_m) == pytest.approx(-g.approach_m, rel=0.05)
    # the gap is evaluated exactly off the sampled grid: at the plane origin it is the rail-to-wheel distance
    # along the normal, which the wheel point and the reference point (on the rail) give independently
    assert g.undeformed.exact is not None
    x0 = np.array([0.0])
    assert g.undeformed.evaluate(x0, x0)[0] < 0.0
    y_rail, z_rail = g.contact_point_rail_m
    assert -0.045 < y_rail < -0.030 and 0.0 < z_rail < 0.015  # on the gauge face, below the top
    assert g.rolling_radius_m > 0.47  # up the flange


def test_canted_rail_file_is_not_canted_twice_and_flange_is_outside_r0():
    track = build_track(a22(0.0))
    assert track.rails["right"].cant_rad == pytest.approx(0.0, abs=1e-15)
    vertical = build_track(a22(0.0, rail_profile="uic60_true"))
    assert vertical.rails["right"].cant_rad == pytest.approx(CANT, rel=1e-12)
    # S1002: flange height 28 mm above the tape circle, so the flange tip radius is r0 + 28 mm.
    wheel = track.wheels["right"]
    y = np.linspace(*wheel.y_range_m, 4001)
    radius = wheel.evaluate(np.full_like(y, np.pi / 2), y)[0]
    assert np.nanmax(radius) == pytest.approx(0.46 + 0.028, abs=2e-4)
    assert wheel.evaluate(np.pi / 2, 0.75)[0] == pytest.approx(0.46, abs=1e-9)


def test_cant_is_data_of_the_profile_not_of_its_name(tmp_path):
    """A byte-identical copy of the canted Manchester rail under another name: its cant is whatever the case states
    (default 0, as for any file), never guessed from the name; stated, it places the rail as the built-in one."""
    from rigid_dynamics.geometry.readers import BUILTIN_PROFILE_DIR

    copy = tmp_path / "my_rail.prr"
    copy.write_bytes((BUILTIN_PROFILE_DIR / "MBench_UIC60_v3.prr").read_bytes())
    builtin = build_track(a22(0.0))
    stated = build_track(a22(0.0, rail_profile=str(copy), rail_profile_cant_rad=CANT))
    unstated = build_track(a22(0.0, rail_profile=str(copy)))
    y = np.linspace(0.72, 0.79, 15)
    np.testing.assert_allclose(stated.rails["right"].evaluate(0.0, y)[0], builtin.rails["right"].evaluate(0.0, y)[0])
    assert unstated.rails["right"].cant_rad == pytest.approx(CANT)  # canted by the case's 1:40 on top of the file's
    assert stated.rails["right"].cant_rad == pytest.approx(0.0, abs=1e-15)


def test_a_wheel_file_with_z_up_is_an_error_that_names_the_fix():
    with pytest.raises(ValueError, match="wheel_profile_mirror_z"):
        build_track(a22(0.0, wheel_profile_mirror_z=True))  # z turned up: the flange points to the axle


def test_left_and_right_profiles_may_differ():
    """A worn left wheel on the new right one: each side gets its own surface; with equal profiles named on both
    sides the result is the one-profile shorthand's."""
    both = build_track(a22(0.0, wheel_profile_left="MBench_S1002_v3"))
    one = build_track(a22(0.0))
    y = np.linspace(-0.79, -0.70, 12)
    np.testing.assert_allclose(
        both.wheels["left"].evaluate(np.pi / 2, y)[0], one.wheels["left"].evaluate(np.pi / 2, y)[0]
    )
    worn = build_track(a22(0.0, wheel_profile_left="worn_high_mileage"))
    y = np.linspace(-0.78, -0.71, 15)
    r_worn, r_new = (t.wheels["left"].evaluate(np.pi / 2, y)[0] for t in (worn, one))
    assert np.nanmax(np.abs(r_worn - r_new)) > 1e-4
    right = (t.wheels["right"].evaluate(np.pi / 2, -y)[0] for t in (worn, one))
    np.testing.assert_allclose(*right)
    sol = solve_wheelset_case(a22(0.0, wheel_profile_left="worn_high_mileage"), STEEL, "hertz", NO_FIELD)
    assert sol.success, sol.message
    assert sol.roll_rad != pytest.approx(0.0, abs=1e-7)  # no longer symmetric


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"wheel_profile": ""}, "wheel_profile = ''"),
        ({"lateral_shift_m": float("nan")}, "lateral_shift_m = nan"),
        ({"gauge_m": -1.0}, "gauge_m = -1.0: expected > 0"),
        ({"flange_back_distance_m": 1.5}, "flange_back_distance_m = 1.5"),
        ({"yaw_rad": 0.5}, "yaw_rad = 0.5"),
        ({"wheel_load_N": None}, "expected exactly one"),
        ({"approach_m": 1e-5}, "expected exactly one"),
        ({"wheel_load_N": -3.0}, "wheel_load_N = -3.0"),
        ({"gauge_height_m": -0.01}, "gauge_height_m = -0.01"),
        ({"rail_inclination_rad": 0.3}, "rail_inclination_rad = 0.3"),
        ({"rolling_speed_m_per_s": 0.0}, "rolling_speed_m_per_s = 0.0"),
        ({"rail_profile_cant_rad": 0.3}, "rail_profile_cant_rad = 0.3"),
        ({"profile_smoothing_m": -1e-3}, "profile_smoothing_m = -0.001"),
        ({"rail_profile_smoothing_m": 0.1}, r"rail_profile_smoothing_m = 0.1: expected a length in \[0, 0.05\] m"),
        ({"wheel_profile_mirror_z": 1}, "wheel_profile_mirror_z = 1"),
        ({"wheel_profile_left": ""}, "wheel_profile_left = ''"),
    ],
)
def test_bad_case_raises(kwargs, match):
    with pytest.raises(ValueError, match=match):
        a22(0.0, **kwargs)


def test_bad_options_and_model_raise():
    case = a22(0.0)
    with pytest.raises(ValueError, match="option 'grid'"):
        solve_wheelset_case(case, STEEL, "hertz", {"grid": 1})
    with pytest.raises(ValueError, match="spin_rate = 'fast'"):
        solve_wheelset_case(case, STEEL, "hertz", {"spin_rate": "fast"})
    with pytest.raises(ValueError, match="contact model = 'nope'"):
        solve_wheelset_case(case, STEEL, "nope")
    with pytest.raises(ValueError, match="no_such_profile"):
        solve_wheelset_case(a22(0.0, rail_profile="no_such_profile"), STEEL, "hertz")


def test_mirrored_case_mirrors_the_solution():
    """Invariant: shifting and yawing the other way mirrors everything (y -> -y, roll -> -roll, left <-> right);
    the flange contact then sits on the left wheel with the same (positive) contact angle."""
    right = solve_wheelset_case(a22(7.0), STEEL, "hertz", NO_FIELD)
    left = solve_wheelset_case(a22(-7.0), STEEL, "hertz", NO_FIELD)
    assert left.roll_rad == pytest.approx(-right.roll_rad, rel=1e-6)
    assert left.vertical_position_m == pytest.approx(right.vertical_position_m, abs=1e-9)
    mirror = {"left": "right", "right": "left"}
    for p in right.patches:
        q = next(q for q in left.patches if q.side == mirror[p.side])
        np.testing.assert_allclose(q.geometry.point_m * [1, -1, 1], p.geometry.point_m, atol=2e-7)
        assert q.geometry.contact_angle_rad == pytest.approx(p.geometry.contact_angle_rad, abs=1e-6)
        assert q.geometry.rolling_radius_m == pytest.approx(p.geometry.rolling_radius_m, abs=1e-8)
        assert q.creepage.longitudinal == pytest.approx(p.creepage.longitudinal, abs=1e-8)
        assert q.creepage.spin_1_per_m == pytest.approx(-p.creepage.spin_1_per_m, rel=1e-5)


def test_rail_smoothing_apart_from_the_wheels():
    """rail_profile_smoothing_m (CONTACT's per-profile SMOOTH) smooths the rails alone: the wheels are those of the
    case's profile_smoothing_m, the rails those of a case smoothed with the rail's value throughout."""
    from rigid_dynamics.contact.track import build_track

    both = build_track(a22(0.0, profile_smoothing_m=0.005))
    split = build_track(a22(0.0, profile_smoothing_m=0.005, rail_profile_smoothing_m=0.0))
    bare = build_track(a22(0.0, profile_smoothing_m=0.0))
    y = np.linspace(-0.02, 0.02, 41)
    wheel = [t.wheels["right"].evaluate(np.pi / 2, y)[0] for t in (both, split)]
    np.testing.assert_array_equal(*wheel)
    y_rail = np.linspace(*bare.rails["right"].y_range_m, 401)[5:-5]
    rail = [t.rails["right"].evaluate(np.zeros_like(y_rail), y_rail)[0] for t in (split, bare, both)]
    np.testing.assert_array_equal(rail[0], rail[1])
    assert np.isfinite(rail[0]).sum() > 300 and np.nanmax(np.abs(rail[0] - rail[2])) > 1e-7


def test_case_file_rail_smoothing_key(tmp_path):
    """``geometry.rail_profile_smoothing_m`` in a case file: read, and a bad value is a one-line error naming it."""
    from hardening_helpers import STEEL

    from wheelrail.cases import load_case
    from wheelrail.config import ConfigError

    head = STEEL + '[geometry]\nkind = "wheelset"\nwheel_profile = "S1002"\nrail_profile = "UIC60"\n'
    tail = "[loading]\nwheel_load_N = 8e4\n"
    (tmp_path / "ok.toml").write_text(head + "rail_profile_smoothing_m = 0.0\n" + tail)
    assert load_case(tmp_path / "ok.toml").wheelset.rail_profile_smoothing_m == 0.0
    (tmp_path / "bad.toml").write_text(head + "rail_profile_smoothing_m = 0.5\n" + tail)
    with pytest.raises(ConfigError, match=r"rail_profile_smoothing_m = 0.5: expected a length in \[0, 0.05\] m"):
        load_case(tmp_path / "bad.toml")


# test_default_bem_rebalances_on_the_grids_that_meet_its_tolerance is in tests/test_docs.py: it checks the solution
# of the README's Python block (the same `wr.solve_case("manchester-a22", "bem")`), so the case is solved once.
