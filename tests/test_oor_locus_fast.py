"""Regression tests (two code paths): the out-of-round contact locus's fast kernel against its full scan.

_patch_kernels.out_of_round_locus (the point alone per angle, the scan at every 8th angle refined where a bound of
the gap's curvature lets it dip, Newton on dg/da for the minimum) against the full scan (tests/oor_reference.py:
every one of the 161 angles with the whole wheel point and derivatives, 30 golden-section steps), on a 3rd-order
polygon of 0.3 mm and a 50 mm rounded flat (depth 0.34 mm; the flat's two lowest points along x and the hump
between), S1002 on UIC60 1:40, several wheel angles, with yaw:

* with the golden section kept (``newton`` False) every output equals the reference's to the last bit;
* with Newton the gap agrees to 1e-15 m, the angle to 1e-7 rad (the golden section's own resolution: its last
  steps compare gaps that differ by less than their rounding, about 2e-8 rad here), the point to 1e-7 m, the
  integrals (weight per y_d 2e-8 relative: the integration interval follows the angle; weighted x and overlap
  ends 1e-9 m) and the formed patches' geometry.

And an independent check of the bound that lets the scan skip angles: the gap's second differences along the angle
never exceed gap_curvature_bound.
"""

import math

import numpy as np
import pytest
from oor_reference import _vertical_gap, out_of_round_locus_reference

from rigid_dynamics.contact import _patch_kernels as kern
from rigid_dynamics.contact import wheelset_patches as wp
from rigid_dynamics.contact.search import WheelsetPose, _SideGeometry
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase
from rigid_dynamics.geometry import HarmonicOutOfRoundness, WheelFlat

CASE = WheelsetCase(
    wheel_profile="S1002", rail_profile="UIC60", rail_inclination_rad=0.025, wheel_load_N=80e3
)  # fmt: skip
FLAT = WheelFlat(0.05, 0.46, centre_angle_rad=0.5 * math.pi)
POLYGON = HarmonicOutOfRoundness(3, 3.0e-4)


@pytest.fixture(scope="module", params=["polygon", "flat"])
def wheel_rail(request):
    irregularity = POLYGON if request.param == "polygon" else FLAT
    track = build_track(CASE, wheel_irregularities={"right": (irregularity,)})
    return request.param, track.fast["right"]


def _geo(wheel, rail, pose):
    return _SideGeometry(wheel, rail, pose, "right", wheel.y_range_m, rail.y_range_m)


def _pose(wheel, rail, spin_rad, sink_m=1.0e-4):
    """The pose at spin_rad (yaw 2 mrad) lowered sink_m below the out-of-round wheel's first touch."""
    z = -0.46
    for _ in range(3):  # the screened locus needs the wheel near its rail first
        pose = WheelsetPose(z_m=z, spin_rad=spin_rad, yaw_rad=0.002)
        z += float(np.nanmin(wp.contact_locus(_geo(wheel, rail, pose)).gap_m))
    return WheelsetPose(z_m=z + sink_m, spin_rad=spin_rad, yaw_rad=0.002)


def _both(wheel, rail, pose, newton):
    """(reference, fast) kernel outputs on the y_d the locus screens at ``pose``."""
    geo = _geo(wheel, rail, pose)
    locus = wp.contact_locus(geo)
    lat = np.ascontiguousarray(locus.lateral_m[np.isfinite(locus.gap_m) & (locus.gap_m < 5e-4)])
    alpha_start = 0.5 * math.pi - pose.spin_rad
    surf = wp._surfaces(geo)
    outputs = []
    for fast in (False, True):
        k = lat.size
        out = [np.empty(k), np.empty((k, 3)), np.empty(k), np.empty(k), np.empty(k), np.empty(k), np.empty(k),
               np.empty((k, 2))]  # fmt: skip
        args = (lat, alpha_start, wp.OUT_OF_ROUND_WINDOW_RAD, wp.OUT_OF_ROUND_SCAN_POINTS,
                wp.OUT_OF_ROUND_INTEGRATION_POINTS)  # fmt: skip
        tail = (geo.rot, geo.centre, surf, True, kern.Locus(*out[:5]), kern.OverlapLine(*out[5:]))
        if fast:
            kern.out_of_round_locus(*args, kern.FastScan(wp.OUT_OF_ROUND_COARSE_STRIDE, newton), *tail)
        else:
            out_of_round_locus_reference(*args, *tail)
        outputs.append(out)
    return outputs


# the flat's centre at the lowest point (offset 0: one overlap with the hump at its middle), on its sides and off
OFFSETS_RAD = (-0.05, -0.02, 0.0, 0.004, 0.03)


@pytest.mark.parametrize("offset", OFFSETS_RAD)
def test_fast_scan_with_the_golden_section_is_the_full_scan_to_the_last_bit(wheel_rail, offset):
    name, (wheel, rail) = wheel_rail
    ref, new = _both(wheel, rail, _pose(wheel, rail, offset), newton=False)
    assert (ref[2] < 0).sum() > 100, f"{name}: no contact at offset {offset}"
    names = ("alpha", "point", "gap", "rail_z", "angle", "weight", "x", "overlap")
    for a, b, what in zip(ref, new, names, strict=True):
        assert np.array_equal(a, b, equal_nan=True), f"{name} {offset}: {what} differs"


@pytest.mark.parametrize("offset", OFFSETS_RAD)
def test_fast_kernel_equals_the_full_scan_within_the_golden_sections_resolution(wheel_rail, offset):
    name, (wheel, rail) = wheel_rail
    ref, new = _both(wheel, rail, _pose(wheel, rail, offset), newton=True)
    touching = ref[2] < 0
    assert touching.sum() > 100
    assert np.array_equal(touching, new[2] < 0)
    finite = np.isfinite(ref[2])
    assert np.array_equal(finite, np.isfinite(new[2]))
    np.testing.assert_allclose(new[2][finite], ref[2][finite], rtol=0, atol=1e-15)
    np.testing.assert_allclose(new[0], ref[0], rtol=0, atol=1e-7)
    np.testing.assert_allclose(new[1], ref[1], rtol=0, atol=1e-7)
    np.testing.assert_allclose(new[3][finite], ref[3][finite], rtol=0, atol=1e-10)  # the point moved: 1e-8 m
    np.testing.assert_allclose(new[4][finite], ref[4][finite], rtol=0, atol=1e-8)
    np.testing.assert_allclose(new[5], ref[5], rtol=0, atol=1e-9 * ref[5].max())
    np.testing.assert_allclose(new[6][touching], ref[6][touching], rtol=0, atol=1e-9)
    np.testing.assert_allclose(new[7][touching], ref[7][touching], rtol=0, atol=1e-9)


def test_formed_patches_are_the_full_scans(wheel_rail, monkeypatch):
    """wheel_patches through the fast kernel and through the reference (patched in): the same patches."""
    name, (wheel, rail) = wheel_rail
    kwargs = dict(wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m, nominal_radius_m=0.46)
    for offset in (-0.02, 0.0):
        pose = _pose(wheel, rail, offset, 2e-4)
        fast, _ = wp.wheel_patches(wheel, rail, pose, "right", **kwargs)
        with monkeypatch.context() as m:
            m.setattr(kern, "out_of_round_locus", lambda *a: out_of_round_locus_reference(*a[:5], *a[6:]))
            ref, _ = wp.wheel_patches(wheel, rail, pose, "right", **kwargs)
        assert len(fast) == len(ref) >= 1
        for p, q in zip(fast, ref, strict=True):
            np.testing.assert_allclose(p.geometry.point_m, q.geometry.point_m, rtol=0, atol=1e-9)
            assert p.geometry.contact_angle_rad == pytest.approx(q.geometry.contact_angle_rad, abs=1e-9)
            assert p.geometry.approach_m == pytest.approx(q.geometry.approach_m, abs=1e-12)
            assert p.geometry.curvature_long_1_per_m == pytest.approx(q.geometry.curvature_long_1_per_m, rel=1e-6)
            np.testing.assert_allclose(
                p.geometry.undeformed.potential_area_m, q.geometry.undeformed.potential_area_m, atol=1e-9
            )
            # the sampled field: its box follows the overlap's ends (1e-9 m apart), the gaps there 1e-12 m apart
            np.testing.assert_allclose(
                p.geometry.undeformed.distance_m, q.geometry.undeformed.distance_m, rtol=0, atol=1e-10
            )


def test_curvature_bound_holds_on_the_gap(wheel_rail):
    """Second differences of g(alpha) on a 1e-3 rad grid over the scanned window, at every screened y_d, stay below
    gap_curvature_bound (which the scan's skipping relies on)."""
    name, (wheel, rail) = wheel_rail
    pose = _pose(wheel, rail, 0.004)
    geo = _geo(wheel, rail, pose)
    surf = wp._surfaces(geo)
    bound = kern.gap_curvature_bound(geo.rot, surf)
    h = 1e-3
    angles = 0.5 * math.pi - pose.spin_rad + np.arange(-0.2, 0.2 + h / 2, h)
    locus = wp.contact_locus(geo)
    lats = locus.lateral_m[np.isfinite(locus.gap_m) & (locus.gap_m < 5e-4)][::10]
    w = np.empty(kern.W_LEN)
    worst = 0.0
    for y in lats:
        g = np.array([_vertical_gap(a, y, geo.rot, geo.centre, surf, w) for a in angles])
        second = (g[2:] - 2 * g[1:-1] + g[:-2]) / h**2
        worst = max(worst, float(np.max(np.abs(second[np.isfinite(second)]))))
    assert 0.3 < worst <= bound, (name, worst, bound)
