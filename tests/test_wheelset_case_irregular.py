"""Wheel irregularities in wheelset contact cases: case keys, and CONTACT-style patches on an out-of-round wheel.

References, independent of the code under test:

* the weight of a lateral position on a round wheel, int (c - x^2/(2 R))^2 dx = 16/15 c^2 sqrt(2 R c) (closed form,
  wheelset_patches module docstring), with R the wheel's radius at that position;
* the longitudinal curvature of a polygonal wheel R(a) = R + A cos(n a) at a crest, from the curvature of a
  plane curve in polar form: kappa = (R^2 + 2 R_a^2 - R R_aa) / (R^2 + R_a^2)^(3/2) = (R + A + n^2 A)/(R + A)^2
  (R_a = 0, R_aa = -n^2 A), hence Hertz's A = kappa / 2 against the straight rail;
* the rounded flat's longitudinal shape in closed form (WheelFlat): the wheel point at angle theta from the bottom is
  x = (R + R_irr) sin theta, height (R - (R + R_irr) cos theta) above the round wheel's lowest point; a hand-built
  gap h_round(0, y) + that height is the second method for the undeformed distance on a flat.

CONTACT's examples/wheelflat.inp (Chalmers' measured flat as slice files) is not compared here: the slice-file
reader is not written (see the branch's report).
"""

import dataclasses
import math

import numpy as np
import pytest
from hardening_helpers import QUADRIC, wheelset_case

from rigid_dynamics.contact.search import WheelsetPose, _SideGeometry
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
from rigid_dynamics.contact.wheelset_patches import contact_locus, wheel_patches
from rigid_dynamics.geometry import HarmonicOutOfRoundness, WheelFlat
from rigid_dynamics.materials import STEEL
from wheelrail.cases import parse_case
from wheelrail.config import ConfigError

R0 = 0.46
CASE = WheelsetCase(
    wheel_profile="S1002", rail_profile="UIC60", rail_inclination_rad=math.atan(1 / 40), wheel_load_N=80e3
)


def _track(irregularities=()):
    return build_track(CASE, wheel_irregularities={"right": tuple(irregularities)} if irregularities else None)


def _geo(track, pose):
    wheel, rail = track.fast["right"]
    return _SideGeometry(wheel, rail, pose, "right", wheel.y_range_m, rail.y_range_m)


def _patches(track, sink_m, rotation_rad=0.0, options=None):
    """Patches of the right wheel with the wheelset lowered by sink_m below the round wheel's touch."""
    rest = WheelsetPose(z_m=track.rest_z_m)
    touch = float(np.nanmin(contact_locus(_geo(_track(), rest)).gap_m))
    pose = WheelsetPose(z_m=track.rest_z_m + touch + sink_m, spin_rad=rotation_rad)
    wheel, rail = track.fast["right"]
    patches, locus = wheel_patches(
        wheel, rail, pose, "right", wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m,
        nominal_radius_m=R0, options=options,
    )  # fmt: skip
    return patches, locus, pose


# ----------------------------------------------------------------------------------------------- round limits
def test_zero_polygon_locus_weight_matches_the_closed_form_of_the_circle():
    """The out-of-round locus (scan + integral along x) on a wheel that is round: same gap as the round locus
    (Newton), weight = 16/15 c^2 sqrt(2 R c) with the wheel's radius R there."""
    round_patches, round_locus, pose = _patches(_track(), 1e-4)
    patches, locus, _ = _patches(_track([HarmonicOutOfRoundness(3, 0.0)]), 1e-4)
    assert locus.weight_line_m3 is not None and round_locus.weight_line_m3 is None
    inside = np.isfinite(round_locus.gap_m) & (round_locus.gap_m < -1e-6)
    assert inside.sum() > 20
    np.testing.assert_allclose(locus.gap_m[inside], round_locus.gap_m[inside], atol=1e-12)
    c = -locus.gap_m[inside]
    radius = pose.centre_m[2] * 0 + np.linalg.norm(
        (locus.point_m[inside] - pose.centre_m)[:, [0, 2]], axis=1
    )  # distance from the axle (no yaw, no roll)
    closed = 16.0 / 15.0 * c**2 * np.sqrt(2.0 * radius * c)
    np.testing.assert_allclose(locus.weight_line_m3[inside], closed, rtol=2e-3)
    # the patch: reference point and contact angle as the round wheel's (its weight uses r0 for every y)
    (p,), (q,) = patches, round_patches
    assert abs(p.geometry.point_m[1] - q.geometry.point_m[1]) < 2e-5
    assert abs(p.geometry.point_m[0]) < 1e-9
    assert abs(p.geometry.contact_angle_rad - q.geometry.contact_angle_rad) < 1e-4
    assert p.geometry.approach_m == pytest.approx(q.geometry.approach_m, abs=1e-10)


def test_flat_away_from_the_contact_gives_the_round_wheel_case():
    """Regression: a flat a quarter turn away from the contact changes nothing (whole equilibrium, Hertz)."""
    opts = {"spin_rate": "nominal"}
    flat = dataclasses.replace(CASE, wheel_irregularities_right=(WheelFlat(0.05, R0, centre_angle_rad=0.0),))
    a = solve_wheelset_case(CASE, STEEL, "hertz", options=opts)
    b = solve_wheelset_case(flat, STEEL, "hertz", options=opts)
    assert a.success and b.success
    assert len(a.patches) == len(b.patches)
    for p, q in zip(a.patches, b.patches, strict=True):
        assert q.result.normal_force_N == pytest.approx(p.result.normal_force_N, rel=1e-6)
        assert q.result.max_pressure_Pa == pytest.approx(p.result.max_pressure_Pa, rel=2e-3)
        np.testing.assert_allclose(q.geometry.point_m, p.geometry.point_m, atol=2e-5)


# ------------------------------------------------------------------------------------------------- polygon
def test_polygon_crest_longitudinal_curvature_is_the_closed_form():
    """A 20th-order polygon of 0.1 mm with its crest at the contact: Hertz's A of the patch equals
    kappa / 2 = (R + A_p + n^2 A_p) / (2 (R + A_p)^2) at the rolling radius R (the rail is straight along x);
    the round wheel's is 1 / (2 R)."""
    n, amp = 20, 1.0e-4
    (q,), _, _ = _patches(_track(), 5e-5)
    (p,), locus, _ = _patches(_track([HarmonicOutOfRoundness(n, amp, -n * math.pi / 2)]), 5e-5)  # crest at pi/2
    r_round = q.geometry.rolling_radius_m
    assert q.geometry.curvature_long_1_per_m == pytest.approx(0.5 / r_round, rel=2e-3)
    r = p.geometry.rolling_radius_m
    assert r == pytest.approx(r_round + amp, abs=1e-5)  # the reference point moves laterally by ~0.1 mm
    kappa = (r + n * n * amp) / r**2  # r already holds A_p
    assert p.geometry.curvature_long_1_per_m == pytest.approx(0.5 * kappa, rel=2e-3)
    assert p.geometry.curvature_long_1_per_m / q.geometry.curvature_long_1_per_m == pytest.approx(1.087, abs=2e-3)
    # the rigid overlap along x at the deepest point: half-length sqrt(c / (kappa / 2)) (the polygon's quartic term
    # changes it by (n x / R)^2 / 12 ~ 0.1 %)
    k = p.regions[0].deepest_index
    c = -locus.gap_m[k]
    half = 0.5 * (locus.overlap_x_m[k, 1] - locus.overlap_x_m[k, 0])
    assert half == pytest.approx(math.sqrt(c / (0.5 * kappa)), rel=3e-3)


# --------------------------------------------------------------------------------------------------- flat
def _flat_height(flat, x):
    """Height of the flat wheel's surface above the round wheel's lowest point at x (closed form), m."""
    theta = np.linspace(-0.2, 0.2, 40001)
    r = flat.wheel_radius_m + flat.evaluate(0.5 * math.pi + theta, 0.0)[0]
    xs, height = r * np.sin(theta), flat.wheel_radius_m - r * np.cos(theta)
    return np.interp(x, xs, height)


def test_flat_at_the_contact_patch_against_a_hand_built_gap():
    """A 50 mm rounded flat (depth 0.34 mm) at the contact: its overlap is longer than the circle's sqrt(q/a);
    the patch's exact undeformed distance equals the hand-built h_round(0, y) + height_flat(x) (second method), and
    the potential area holds the whole overlap."""
    flat = WheelFlat(0.05, R0)
    track = _track([flat])
    (p,), locus, pose = _patches(track, flat.depth + 1.0e-4)
    und = p.geometry.undeformed
    x0, x1, y0, y1 = und.potential_area_m
    # the flat's overlap reaches ~ +-18 mm along x (round wheel at this approach: ~ +-9.6 mm)
    assert x1 > 0.016 and x0 < -0.016
    assert abs(p.geometry.point_m[0]) < 1e-6  # symmetric flat: reference point at x = 0
    # the same plane on the round wheel at the same pose: h_round(0, y)
    round_track = _track()
    wheel, rail = round_track.fast["right"]
    round_geo = _geo(round_track, pose)
    round_locus = contact_locus(round_geo)
    from rigid_dynamics.contact.wheelset_patches import plane_gap

    ys = np.linspace(y0, y1, 9)
    xs = np.linspace(-0.02, 0.02, 41)
    gx, gy = np.meshgrid(xs, ys)
    h_round0 = plane_gap(round_geo, round_locus, p.geometry.point_m, p.geometry.frame, np.zeros_like(ys), ys)[0]
    hand = h_round0[:, None] + _flat_height(flat, gx)
    exact = und.exact(gx, gy)
    ok = np.isfinite(exact) & np.isfinite(hand)
    assert ok.mean() > 0.9
    np.testing.assert_allclose(exact[ok], hand[ok], atol=2e-6)  # plane tilt and R(y) terms: ~1 um
    # every overlap point of the exact gap lies inside the potential area
    over = exact < 0
    assert over.any()
    assert gx[over].min() >= x0 and gx[over].max() <= x1


def test_flat_at_the_contact_bem_patch_is_long_and_not_cut_by_the_potential_area():
    """BEM on the flat (approach control): the contact does not touch the potential area's edge, and the patch is
    longer and flatter than the round wheel's at the same approach."""
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import Creepage

    flat = WheelFlat(0.05, R0)
    bem = get_model("bem")
    (p,), _, _ = _patches(_track([flat]), flat.depth + 1.0e-4)
    (q,), _, _ = _patches(_track(), 1.0e-4)
    zero = Creepage(0.0, 0.0, 0.0, 1.0)
    rp = bem.solve(p.geometry, zero, STEEL, normal_force_N=None, options={"nx": 40, "ny": 30})
    rq = bem.solve(q.geometry, zero, STEEL, normal_force_N=None, options={"nx": 40, "ny": 30})
    assert rp.success and rq.success
    assert not rp.extra.get("contact_touches_potential_area_edge", False)
    assert rp.contact_area_m2 > 1.3 * rq.contact_area_m2
    assert rp.max_pressure_Pa < rq.max_pressure_Pa


def test_flat_rotated_to_the_contact_by_wheel_rotation():
    """The rotation angle puts the irregularity at the contact: a flat at alpha_0 = pi/2 - 0.3 with phi = 0.3 is
    the flat at alpha_0 = pi/2 with phi = 0 (same patch)."""
    a, _, _ = _patches(_track([WheelFlat(0.05, R0)]), 5e-4)
    b, _, _ = _patches(_track([WheelFlat(0.05, R0, centre_angle_rad=0.5 * math.pi - 0.3)]), 5e-4, rotation_rad=0.3)
    assert len(a) == len(b) == 1
    assert b[0].geometry.approach_m == pytest.approx(a[0].geometry.approach_m, abs=1e-9)
    np.testing.assert_allclose(b[0].geometry.point_m, a[0].geometry.point_m, atol=1e-7)


# ------------------------------------------------------------------------------------------------ case keys
GOOD = wheelset_case("""[kinematics]
wheel_rotation_rad = 0.3
[irregularities]
flat_length_m = 0.05
flat_angle_rad = 1.2707963
side = "right"
""")


def _parse(text):
    import tomllib

    return parse_case(tomllib.loads(text))


def test_case_keys_reach_the_wheelset_case():
    case = _parse(GOOD).wheelset
    assert case.wheel_rotation_rad == 0.3
    assert case.wheel_irregularities_left == ()
    (flat,) = case.wheel_irregularities_right
    assert flat == WheelFlat(0.05, R0, None, 1.2707963, "rounded")
    both = _parse(
        GOOD.replace('side = "right"', 'polygon_order = 3\npolygon_amplitude_m = 1e-4\nflat_shape = "new"')
    ).wheelset
    assert both.wheel_irregularities_left == both.wheel_irregularities_right
    assert both.wheel_irregularities_left[0] == HarmonicOutOfRoundness(3, 1e-4, 0.0)
    assert both.wheel_irregularities_left[1].shape == "new"


@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ('side = "right"', 'side = "front"', r"key 'irregularities.side' = 'front': expected 'both', 'left' or"),
        ('side = "right"', "corrugation_amplitude_m = 1e-4", r"unknown key 'irregularities.corrugation_amplitude_m'"),
        ("flat_length_m = 0.05", "flat_length_m = 1.0", r"'irregularities.flat_length_m' = 1.0: expected a length <"),
        ("flat_length_m = 0.05", "flat_length_m = -0.05", r"'irregularities.flat_length_m' = -0.05: expected a num"),
        ('side = "right"', "flat_depth_m = 0.5", r"'irregularities.flat_depth_m' = 0.5: expected a depth < r0"),
        ('side = "right"', 'flat_shape = "square"', r"'irregularities.flat_shape' = 'square': expected 'rounded'"),
        ('side = "right"', 'flat_shape = "new"\nflat_depth_m = 1e-3', r"flat_depth_m' = 0.001: expected 0 with"),
        ('side = "right"', "polygon_order = 2.5", r"'irregularities.polygon_order' = 2.5: expected an integer >= 0"),
        ('side = "right"', "polygon_amplitude_m = 1e-4", r"'irregularities.polygon_order' = 0: expected an integer"),
        ('side = "right"', "polygon_order = 20\npolygon_amplitude_m = 2e-3", r"polygon_amplitude_m' = 0.002: exp"),
        ('side = "right"', 'flat_angle_rad = "up"', r"'irregularities.flat_angle_rad' = 'up': expected a finite"),
        (
            "wheel_rotation_rad = 0.3",
            "wheel_rotation_rad = inf",
            r"key 'kinematics.wheel_rotation_rad' = inf: expected a finite",
        ),
        ("[kinematics]", "[kinematics]\nwheel_spin = 1", r"unknown key 'kinematics.wheel_spin'"),
    ],
)
def test_bad_irregularity_keys_fail_with_one_line(tmp_path, capsys, old, new, pattern):
    import re

    from wheelrail.cli import main

    assert old in GOOD
    text = GOOD.replace(old, new, 1)
    if "flat_angle_rad" in new:
        text = text.replace("flat_angle_rad = 1.2707963\n", "", 1)
    with pytest.raises(ConfigError, match=pattern):
        _parse(text)
    path = tmp_path / "case.toml"
    path.write_text(text)
    code = main(["contact", str(path), "--method", "hertz", "--json"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("wheelrail: error: ") and err.count("\n") == 1
    assert re.search(pattern, err), err


def test_irregularities_table_is_refused_in_a_quadric_case():
    text = (
        QUADRIC
        + """
[irregularities]
flat_length_m = 0.05
"""
    )
    with pytest.raises(ConfigError, match=r"table \[irregularities\]: expected only in a wheelset case"):
        _parse(text)


def test_wheelset_case_rejects_non_irregularities():
    with pytest.raises(ValueError, match=r"wheel_irregularities_right = \(1.0,\): expected a tuple of wheel"):
        dataclasses.replace(CASE, wheel_irregularities_right=(1.0,))
    with pytest.raises(ValueError, match=r"wheel_rotation_rad = nan: expected a finite number"):
        dataclasses.replace(CASE, wheel_rotation_rad=math.nan)


def test_out_of_round_locus_numpy_path_equals_the_compiled_one():
    """Regression (two of our paths): the numpy locus (measured grids take it) on the exact surfaces equals the
    compiled one on the tabulated surfaces, for the flat at the contact."""
    track = _track([WheelFlat(0.05, R0)])
    _, _, pose = _patches(track, 0.34e-3 + 1.0e-4)
    fast = contact_locus(_geo(track, pose), 2e-4)
    exact = contact_locus(
        _SideGeometry(
            track.wheels["right"],
            track.rails["right"],
            pose,
            "right",
            track.fast["right"][0].y_range_m,
            track.fast["right"][1].y_range_m,
        ),
        2e-4,
    )
    inside = fast.gap_m < 0
    assert inside.sum() > 20
    np.testing.assert_allclose(exact.gap_m[inside], fast.gap_m[inside], atol=2e-8)  # Hermite table vs spline
    np.testing.assert_allclose(exact.weight_line_m3[inside], fast.weight_line_m3[inside], rtol=2e-3)
    np.testing.assert_allclose(exact.overlap_x_m[inside], fast.overlap_x_m[inside], atol=2e-5)


def test_wheelset_case_with_a_flat_at_the_contact_carries_the_load_with_bem():
    """The whole case (per-wheel kinematics, prescribed pitch rate) with the flat at the contact converges with the
    BEM: the vertical contact force equals the load and the contact is not cut by the potential area."""
    case = dataclasses.replace(
        CASE, roll_rad=0.0, pitch_rate_rad_per_s=-1.0 / R0, wheel_irregularities_right=(WheelFlat(0.05, R0),)
    )
    sol = solve_wheelset_case(case, STEEL, "bem", options={"sides": ("right",), "model": {"nx": 40, "ny": 30}})
    assert sol.success, sol.message
    assert sol.wheel_vertical_load_N["right"] == pytest.approx(80e3, rel=1e-6)
    (patch,) = sol.patches
    assert not patch.result.extra.get("contact_touches_potential_area_edge", False)
    assert patch.result.contact_area_m2 > 3.0e-4  # the round wheel's: 1.7e-4 m^2
