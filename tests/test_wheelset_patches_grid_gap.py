"""The formed patches' undeformed distance on a regular grid (the solvers' element centres) by the strip sampler
(wheelset_patches._grid_gap: _gap_kernels.sample_grid, the loop's sampler) against the per-point Newton solves of
wheelset_patches.plane_gap. Both solve the same roots (the wheel surface and the rail along the plane normal), so
this is a regression test of the faster path, not a physics reference: equal to 2e-12 m where finite, finite at the
same points, on curve-flange's conformal flange-root patch (22-70 deg, CONTACT's solution in
tests/test_contact_curve_flange.py) and tread patch, and on polygonal-wheel's out-of-round tread.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

from rigid_dynamics.contact import wheelset_patches
from rigid_dynamics.contact.search import WheelsetPose
from rigid_dynamics.wheelset.formed_patches import PatchFormer

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from make_contact_curve_flange import STATE  # noqa: E402

TOLERANCE_M = 2e-12


def _former(scene_name: str) -> PatchFormer:
    from rigid_dynamics.wheelset.simulate import build_provider
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    path = resolve_scene_path(scene_name)
    doc = read_toml(path, "scene file")
    return PatchFormer(build_provider(parse_scene(doc, base_dir=path.parent)).surfaces)


def _patches(former, y_m, z_m, yaw_rad, roll_rad):
    pose = WheelsetPose(0.0, y_m, z_m, yaw_rad, roll_rad, 0.0)
    return [p for side in ("left", "right") for p in former.patches(side, pose)]


def _compare(patch, n):
    und = patch.geometry.undeformed
    x0, x1, y0, y1 = und.potential_area_m
    gx, gy = np.meshgrid(np.linspace(x0, x1, n), np.linspace(y0, y1, n))
    grid = und.evaluate(gx, gy)  # a regular grid: the strip sampler
    points = und.evaluate(gx.ravel(), gy.ravel()).reshape(gx.shape)  # 1-D points: plane_gap per point
    assert np.array_equal(np.isfinite(grid), np.isfinite(points))
    finite = np.isfinite(points)
    assert finite.sum() > 0.5 * finite.size and (points[finite] < 0).any()
    return float(np.max(np.abs(grid[finite] - points[finite])))


@pytest.mark.parametrize("n", [24, 65])
def test_curve_flange_root_and_tread(n):
    patches = _patches(_former("curve-flange"), STATE["y_m"], STATE["z_m"], STATE["yaw_rad"], STATE["roll_rad"])
    angles = sorted(p.geometry.contact_angle_rad for p in patches)
    assert angles[-1] > 0.7  # the flange root's formed patch (CONTACT's 0.8124 rad)
    assert max(_compare(p, n) for p in patches) < TOLERANCE_M


def test_polygonal_wheel_tread():
    former = _former("polygonal-wheel")
    lo, hi = -0.47, -0.45  # wheelset centre heights (z down): out of contact, deep
    for _ in range(60):  # bisection to about 40 um of interpenetration
        z = 0.5 * (lo + hi)
        patches = _patches(former, 0.0, z, 0.0, 0.0)
        depth = max((p.geometry.approach_m for p in patches), default=0.0)
        if abs(depth - 4e-5) < 5e-6:
            break
        lo, hi = (z, hi) if depth < 4e-5 else (lo, z)
    assert patches and abs(depth - 4e-5) < 5e-6
    assert max(_compare(p, 40) for p in patches) < TOLERANCE_M


def test_not_a_regular_grid_falls_back_to_plane_gap():
    """Non-uniform spacing, fewer than GRID_SAMPLER_MIN_POINTS rows or scattered points: _grid_gap gives None and
    the geometry's gap comes from plane_gap per point."""
    (patch, *_) = _patches(_former("curve-flange"), STATE["y_m"], STATE["z_m"], STATE["yaw_rad"], STATE["roll_rad"])
    exact = patch.geometry.undeformed.exact  # wheelset_patches' gap_of: the side's geometry in its closure
    geo = dict(zip(exact.__code__.co_freevars, (c.cell_contents for c in exact.__closure__), strict=True))["geo"]
    origin, frame, start = exact.__defaults__
    x0, x1, y0, y1 = patch.geometry.undeformed.potential_area_m
    xs, ys = np.linspace(x0, x1, 8), np.linspace(y0, y1, 8)
    gx, gy = np.meshgrid(xs, ys)
    assert wheelset_patches._grid_gap(geo, origin, frame, start, gx, gy) is not None
    uneven = np.meshgrid(xs, y0 + (y1 - y0) * np.linspace(0, 1, 8) ** 2)
    for x, y in (uneven, (gx[:2], gy[:2]), (gx.ravel(), gy.ravel()), (gx[:, ::-1], gy)):
        assert wheelset_patches._grid_gap(geo, origin, frame, start, x, y) is None
