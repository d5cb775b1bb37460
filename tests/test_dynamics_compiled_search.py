"""The compiled 3-D contact search (rigid_dynamics.wheelset.compiled_search) against the Python search.

Second implementation: SearchProvider (contact.search.search_side: grid of (alpha, y_d), refinement of every grid
minimum, patch geometry on the exact surfaces, curvature.py) and the compiled search (lateral scan of the vertical
gap, warm starts, tracking, patch geometry on the tabulated surfaces) must find the same patches with the same
geometry at arbitrary poses of real profiles with a polygonal wheel, a wheel flat and rail corrugation; and the
compiled RK4 loop on the compiled search must reproduce the Python RK4 loop on SearchProvider.
"""

from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.kinematics import wheelset_rotation
from rigid_dynamics.wheelset import compiled_records
from rigid_dynamics.wheelset import compiled_search as cs
from rigid_dynamics.wheelset.simulate import build_provider, simulate
from wheelrail.scenes import load_scene, resolve_scene_path


@pytest.fixture(scope="module")
def polygon_scene():
    return load_scene(resolve_scene_path("polygonal-wheel"))


def _poses(n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        y = rng.uniform(-0.008, 0.008)
        yield (
            rng.uniform(-1, 1),
            y,
            -0.46 + rng.uniform(-4e-4, 4e-4) - 0.03 * abs(y),  # deeper with the lateral shift (conicity)
            rng.uniform(-4e-3, 4e-3),
            rng.uniform(-3e-3, 3e-3),
            rng.uniform(-10, 10),
        )


def _compare_geometry(provider, poses, *, full=True, moved=None, point_atol=1e-8, normal_atol=2e-6):
    """Patches of SearchProvider and of the compiled search at each pose; returns the number of patches compared."""
    search = cs.search_args(provider, provider.options)
    cg = np.zeros((4, cs.N_GEO))
    compared = 0
    for pose in poses:
        state = np.zeros(14)
        state[:6] = pose
        search.n_mem[:] = 0
        cs.search_geometry(state, search, True, cg)
        if moved is not None:  # track from this pose to a nearby one without the scan
            state[:6] = np.asarray(pose) + moved
            cs.search_geometry(state, search, full, cg)
        ref = provider.patches(state[:3], state[3], state[4], state[5])
        for side in (0, 1):
            rows = [c for c in (2 * side, 2 * side + 1) if not np.isnan(cg[c, 0]) and cg[c, 0] > 0]
            found = [k for k in range(len(ref)) if ref.side[k] == side and ref.approach_m[k] > 0]
            assert len(rows) == len(found), (pose, side, cg[:, 0], ref.approach_m)
            for c, k in zip(rows, found, strict=True):
                g = cg[c]
                np.testing.assert_allclose(g[0], ref.approach_m[k], atol=1e-11, rtol=1e-8)
                np.testing.assert_allclose(g[1:4], ref.point_m[k] - state[:3], atol=point_atol)
                # normal and contact angle: the tabulated profile slopes (cubic Hermite between nodes, exact at them)
                # differ from the exact ones by up to ~5e-7 in a cell with a curvature jump (seen at a flange contact)
                np.testing.assert_allclose(g[4:7], ref.normal[k], atol=normal_atol)
                # curvatures: second derivatives of the profiles interpolated linearly between table nodes 2e-5 m
                # apart (compiled) against the exact profiles (search_side); within a cell that holds a joint of
                # two profile arcs (where the second derivative jumps, e.g. 1/0.08 -> 1/0.013 1/m on the rail) the
                # interpolation blends them: 3e-4 relative seen at a gauge-corner contact. Near-conformal contacts
                # (B -> 0, a difference of two profile curvatures of 1-10 1/m each) keep an absolute error of
                # ~1e-3 1/m (B = 0.0023 against 0.0033 seen: a non-Hertzian contact where B means little).
                np.testing.assert_allclose(g[7], ref.curvature_long_1_per_m[k], rtol=1e-3, atol=2e-3)
                np.testing.assert_allclose(g[8], ref.curvature_lat_1_per_m[k], rtol=1e-3, atol=2e-3)
                np.testing.assert_allclose(g[9], ref.rolling_radius_m[k], atol=max(1e-10, point_atol))
                np.testing.assert_allclose(g[10], ref.wheel_lateral_m[k], atol=point_atol)
                np.testing.assert_allclose(g[11], ref.contact_angle_rad[k], atol=normal_atol)
                compared += 1
    return compared


def test_rotation_is_the_kinematics_rotation():
    rot = np.zeros((3, 3))
    for angles in [(0.01, -0.02, 1.3), (-0.3, 0.2, -7.0), (0.0, 0.0, 0.0)]:
        cs.rotation(*angles, rot)
        np.testing.assert_allclose(rot, wheelset_rotation(*angles), atol=1e-15)


def test_polygonal_wheel_patches_equal_the_python_search(polygon_scene):
    provider = build_provider(polygon_scene)
    assert compiled_records.supported(polygon_scene, provider)
    compared = _compare_geometry(provider, _poses(40, 1))
    print(f"{compared} patches compared")
    assert compared >= 40


@pytest.mark.parametrize("scene_name", ["wheel-flat", "corrugation"])
def test_flat_and_corrugation_patches_equal_the_python_search(scene_name):
    scene = load_scene(resolve_scene_path(scene_name))
    provider = build_provider(scene)  # the geometry alone: the track model does not enter
    compared = _compare_geometry(provider, _poses(15, 2))
    assert compared >= 15


def test_tracking_equals_a_fresh_search(polygon_scene):
    """Stages without the lateral scan track the last candidates (one Newton step with the stored Hessian): after a
    pose change of RK4's size (5e-6 m, 1e-5 rad, a 0.03 rad turn of the wheel) they must give the fresh search's
    patches: the same approach (to 1e-11 m: h is stationary at the contact point), a contact point within 1e-6 m
    (one quasi-Newton step leaves ~2e-7 m; a moment error of ~0.02 N m at 100 kN) and a normal within 2e-5 (at a
    flange root, curvature ~50 1/m, that point error tilts the normal by ~6e-6: ~0.6 N of lateral force at 100
    kN)."""
    provider = build_provider(polygon_scene)
    moved = np.array([1.4e-2, 5e-6, 2e-6, 1e-5, -1e-5, 0.03])
    compared = _compare_geometry(provider, _poses(25, 3), full=False, moved=moved, point_atol=1e-6, normal_atol=2e-5)
    assert compared >= 20


def test_compiled_search_run_equals_the_python_search_run(polygon_scene):
    """The polygonal-wheel scene for 0.03 s: the compiled loop on the compiled search against the Python RK4 loop on
    SearchProvider (the same steps). Differences come from the tabulated curvatures (~1e-6) and the tracking (one
    quasi-Newton step per stage, contact points within ~2e-7 m, normals ~1e-6): 1e-8 m in the states after 0.03 s,
    i.e. ~20 N (2e-4 N0) at the Hertz stiffness of ~1.3e9 N/m. Bounds: 5e-8 m and 5e-4 N0."""
    scene = replace(polygon_scene, duration_s=0.03)
    fast = simulate(scene, compiled=True)
    slow = simulate(scene, compiled=False)
    assert fast.status == slow.status == "ok"
    assert fast.summary()["compiled"] is True and slow.summary()["compiled"] is False
    n0 = scene.static_wheel_load_N
    d_force = np.nanmax(
        np.abs(np.nan_to_num(fast.patches["normal_force_N"]) - np.nan_to_num(slow.patches["normal_force_N"]))
    )
    d_pos = np.max(np.abs(fast.states[:, :3] - slow.states[:, :3]))
    print(f"max |dN|/N0 {d_force / n0:.2e}, max |d position| {d_pos:.2e} m")
    assert d_force < 5e-4 * n0
    assert d_pos < 5e-8
    np.testing.assert_array_equal(np.isnan(fast.patches["normal_force_N"]), np.isnan(slow.patches["normal_force_N"]))


def test_angle_scan_only_where_the_rolling_direction_can_hold_two_minima():
    """The angle scan (both edges of a flat) is skipped on wheels whose gap stays convex along the rail: the
    embedded polygon (n^2 A / r^2 = 0.013 1/m against 1/r = 2.2 1/m) and corrugation (A k^2 = 0.47 1/m)."""
    r0 = 0.46
    assert cs._convex_along_the_rail(np.array([[0.0, 3, 3e-4, 0, 0, 0, 0]]), np.zeros((0, 7)), r0)
    corrugation = np.array([[0.0, 2 * np.pi / 0.05, 3e-5, 0, 0, 0.01, 0.004]])
    assert cs._convex_along_the_rail(np.zeros((0, 7)), corrugation, r0)
    assert not cs._convex_along_the_rail(np.array([[1.0, 1.1, r0, 0.05, 1e-3, 0, 0]]), np.zeros((0, 7)), r0)
    assert not cs._convex_along_the_rail(np.array([[0.0, 20, 3e-3, 0, 0, 0, 0]]), np.zeros((0, 7)), r0)
