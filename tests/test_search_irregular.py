"""Compiled contact search on irregular surfaces (polygonal wheel, wheel flats, rail corrugation).

The compiled path (Hermite table of the ideal profile + closed-form irregularities in numba,
contact/_search_kernels.py) must find the same patches as the general numpy path on the exact surfaces
(rigid_dynamics.geometry's WheelSurface/RailSurface ``evaluate``, scipy profile splines): two implementations of
eq 7-11 that share no distance or minimisation code. Stated tolerances: approach 1e-12 m, contact point 1e-9 m,
frame 1e-8, relative curvatures A, B 1e-6 relative (the patch geometry itself comes from the exact surfaces in both
paths; the differences are those of the refined minimum, the table error being ~1e-14 m).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact import _search_kernels as kern
from rigid_dynamics.contact.search import (
    SIDES,
    TabulatedRail,
    TabulatedWheel,
    WheelsetPose,
    _SideGeometry,
    compiled_rail_irregularities,
    compiled_wheel_irregularities,
    search_side,
)
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase
from rigid_dynamics.geometry import (
    HarmonicOutOfRoundness,
    MeasuredWheelIrregularity,
    RailCorrugation,
    WheelFlat,
)

R0 = 0.46
CASE = WheelsetCase(
    "MBench_S1002_v3", "MBench_UIC60_v3", lateral_shift_m=0.0, yaw_rad=0.0,
    rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4,
)  # fmt: skip
# (x, y, spin, yaw): centred, shifted with yaw, the other way, a flange pose; the flat (centre at a = pi/2) is
# under the wheel for spin 0 and 0.02 rad (9 mm from its centre), near its end at 0.05 rad.
POSES = ((0.0, 0.0, 0.0, 0.0), (0.013, 0.003, 0.02, 0.004), (0.031, -0.004, -0.05, -0.003), (0.2, 0.006, 0.3, 0.012))
SCENES = {
    "polygon": {"wheel_irregularities": {s: (HarmonicOutOfRoundness(3, 3e-4, 0.4),) for s in SIDES}},
    "flat": {"wheel_irregularities": {s: (WheelFlat(0.05, R0),) for s in SIDES}},
    "corrugation": {"rail_irregularities": {s: (RailCorrugation(0.05, 3e-5, 0.3),) for s in SIDES}},
}


def _numpy_search(track, pose, side):
    wheel, rail = track.wheels[side], track.rails[side]
    return search_side(
        wheel, rail, pose, side, wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m,
        options={"field": False},
    )  # fmt: skip


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_compiled_irregular_search_equals_numpy_path(scene):
    """Polygon, rounded flat, corrugation: same patches (approach, point, A, B, frame) by both paths."""
    track = build_track(CASE, **SCENES[scene])
    in_contact = 0
    for x, y, spin, yaw in POSES:
        pose = WheelsetPose(x_m=x, y_m=y, z_m=-R0 + 4e-4, yaw_rad=yaw, spin_rad=spin)
        for side in SIDES:
            assert isinstance(track.fast[side][0], TabulatedWheel) and isinstance(track.fast[side][1], TabulatedRail)
            fast, slow = track.search(pose, side, {"field": False}), _numpy_search(track, pose, side)
            assert len(fast.patches) == len(slow.patches), (scene, pose, side)
            in_contact += len(fast.patches)
            for p, q in zip(fast.patches, slow.patches, strict=True):
                assert p.approach_m == pytest.approx(q.approach_m, abs=1e-12)
                np.testing.assert_allclose(p.point_m, q.point_m, atol=1e-9)
                np.testing.assert_allclose(p.frame, q.frame, atol=1e-8)
                assert p.curvature_long_1_per_m == pytest.approx(q.curvature_long_1_per_m, rel=1e-6)
                assert p.curvature_lat_1_per_m == pytest.approx(q.curvature_lat_1_per_m, rel=1e-6)
    assert in_contact >= 6


def test_polygon_shifts_the_approach_by_the_out_of_roundness():
    """Independent check of R_irr in the search: at the lowest point a = pi/2 - phi, a polygon A cos(n a + phi0)
    adds A cos(n (pi/2 - phi) + phi0) to the radius, so for a pure vertical tread contact the approach grows by
    about that much relative to the ideal wheel (exactly, to the contact angle's cosine ~ 1 and second order)."""
    amp, order, phase = 3e-4, 3, 0.4
    ideal = build_track(CASE)
    poly = build_track(CASE, wheel_irregularities={s: (HarmonicOutOfRoundness(order, amp, phase),) for s in SIDES})
    for spin in (0.0, 0.3, 1.1):
        pose = WheelsetPose(z_m=-R0 + 4e-4, spin_rad=spin)
        q0 = max(p.approach_m for p in ideal.search(pose, "right", {"field": False}).patches)
        q1 = max(p.approach_m for p in poly.search(pose, "right", {"field": False}).patches)
        expected = amp * math.cos(order * (0.5 * math.pi - spin) + phase)
        assert q1 - q0 == pytest.approx(expected, abs=0.03 * amp)


def test_closed_forms_equal_the_geometry_package():
    """The numba closed forms (value, first and second derivatives) against rigid_dynamics.geometry's numpy
    evaluate, over a full turn (wrap-around) and across the corrugation band's tapers on both rails."""
    wheel_irr = (
        HarmonicOutOfRoundness(3, 3e-4, 0.4), HarmonicOutOfRoundness(7, 1e-5),
        WheelFlat(0.05, R0, centre_angle_rad=3.0),
        WheelFlat(0.06, R0, centre_angle_rad=-2.9, shape="new"),
    )  # fmt: skip
    rows = compiled_wheel_irregularities(wheel_irr)
    angles = np.linspace(-7.0, 7.0, 4001)
    ref = [sum(irr.evaluate(angles, 0.0)[k] for irr in wheel_irr) for k in (0, 1, 3)]
    got = np.array([kern.wheel_irregularity(a, rows) for a in angles])
    np.testing.assert_allclose(got[:, 0], ref[0], atol=1e-15)
    np.testing.assert_allclose(got[:, 1], ref[1], atol=1e-13)
    np.testing.assert_allclose(got[:, 2], ref[2], atol=1e-11, rtol=1e-12)
    rail_irr = (RailCorrugation(0.05, 3e-5, 0.3, centre_y_m=0.002, half_width_m=0.01, taper_m=0.004),)
    rows = compiled_rail_irregularities(rail_irr)
    track = build_track(CASE, rail_irregularities={s: rail_irr for s in SIDES})
    for side in SIDES:
        rail = track.rails[side]
        lo, hi = rail.y_range_m
        x, y = np.meshgrid(np.linspace(0, 0.1, 7), np.linspace(lo, hi, 301))
        exact = rail.evaluate(x, y)
        ideal = rail.ideal_height(y)
        got = np.array(
            [
                kern.rail_irregularity(a, b, rows, rail.sign, rail.lateral_offset_m)
                for a, b in zip(x.ravel(), y.ravel(), strict=True)
            ]
        )
        np.testing.assert_allclose(got[:, 0], (exact[0] - ideal[0]).ravel(), atol=1e-15)
        np.testing.assert_allclose(got[:, 1], exact[1].ravel(), atol=1e-13)
        np.testing.assert_allclose(got[:, 2], (exact[2] - ideal[1]).ravel(), atol=1e-12)
        np.testing.assert_allclose(got[:, 3], exact[3].ravel(), atol=1e-11)
        np.testing.assert_allclose(got[:, 4], exact[4].ravel(), atol=1e-11)
        np.testing.assert_allclose(got[:, 5], (exact[5] - ideal[2]).ravel(), atol=1e-9)


def test_dense_scan_finds_the_compiled_patches_on_a_polygonal_wheel():
    """Brute force: h on a dense (alpha, y_d) grid of the exact surfaces (numpy eq 11, no minimisation); the
    compiled search is as deep as the scan's deepest point and within its grid error (O(grid^2 curvature))."""
    track = build_track(CASE, **SCENES["polygon"])
    pose = WheelsetPose(x_m=0.013, y_m=0.003, z_m=-R0 + 4e-4, yaw_rad=0.004, spin_rad=0.02)
    got = track.search(pose, "right", {"field": False})
    wheel, rail = track.wheels["right"], track.rails["right"]
    geo = _SideGeometry(wheel, rail, pose, "right", wheel.y_range_m, rail.y_range_m)
    q_fast = max(p.approach_m for p in got.patches)
    y_d = got.wheel_parameters[np.argmax([p.approach_m for p in got.patches]), 1]
    a, y = np.meshgrid(
        0.5 * np.pi - 0.02 + np.arange(-0.02, 0.02, 0.0005), y_d + np.arange(-4e-3, 4e-3, 5e-5), indexing="ij"
    )
    q_scan = -float(np.min(geo.distance(a, y, 12)[0]))
    assert q_fast >= q_scan * (1 - 1e-9)
    assert q_fast == pytest.approx(q_scan, rel=2e-3)


def test_unsupported_irregularities_take_the_numpy_path():
    """A measured grid R_irr(a, y) is not compiled: the wheel stays the exact surface (numpy search)."""
    measured = MeasuredWheelIrregularity(np.linspace(0, 6, 8), np.linspace(-0.05, 0.05, 5), np.zeros((8, 5)))
    track = build_track(CASE, wheel_irregularities={"right": (measured,)})
    assert not isinstance(track.fast["right"][0], TabulatedWheel)
    assert isinstance(track.fast["left"][0], TabulatedWheel)
    assert compiled_wheel_irregularities((measured,)) is None
    assert compiled_rail_irregularities((HarmonicOutOfRoundness(3, 1e-4),)) is None


def test_tabulated_surfaces_reject_unsupported_irregularities():
    measured = MeasuredWheelIrregularity(np.linspace(0, 6, 8), np.linspace(-0.05, 0.05, 5), np.zeros((8, 5)))
    track = build_track(CASE, wheel_irregularities={"right": (measured,)}, rail_irregularities={"right": (measured,)})
    with pytest.raises(ValueError, match="expected HarmonicOutOfRoundness/WheelFlat"):
        TabulatedWheel(track.wheels["right"])
    with pytest.raises(ValueError, match="expected RailCorrugation"):
        TabulatedRail(track.rails["right"])
