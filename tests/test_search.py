"""3-D contact search (eq 5-11, 12-33) on analytic surfaces with closed-form contact.

Exact reference for a crowned wheel on a crowned rail (no yaw, no roll): in the cross-section x = 0 the wheel's
crown is a circle (centre c_w, radius rho) and the rail's crown a circle (centre c_r, radius Rr); the
approach is q = rho + Rr - |c_w - c_r|, the normal is along c_r -> c_w, and the relative curvatures are
A = cos(gamma)/(2 R_c) (the wheel's circumferential curvature at a point of rolling radius R_c whose normal is
tilted by gamma from the radial direction; the cylindrical rail is straight along x) and
B = (1/rho + 1/Rr)/2.
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.search import WheelsetPose, ellipticity_error, search_side


class CrownWheel:
    """R(alpha, y) = r0 - rho + sqrt(rho^2 - (y - y_c)^2): torus-shaped tread (crown radius rho) about y_c."""

    def __init__(self, r0, rho, y_c):
        self.r0, self.rho, self.y_c = r0, rho, y_c

    def evaluate(self, alpha, y):
        alpha, y = np.broadcast_arrays(np.asarray(alpha, float), np.asarray(y, float))
        u = y - self.y_c
        root = np.sqrt(np.maximum(self.rho**2 - u**2, 1e-12))
        zero = np.zeros_like(u)
        return (self.r0 - self.rho + root, zero, -u / root, zero, zero, -(self.rho**2) / root**3)


class TwoBumpWheel:
    """R = r0 + sum_k d_k exp(-(y - y_k)^2 / w_k^2): two separate 'tread' and 'flange' bumps."""

    def __init__(self, r0, bumps):
        self.r0, self.bumps = r0, bumps

    def evaluate(self, alpha, y):
        alpha, y = np.broadcast_arrays(np.asarray(alpha, float), np.asarray(y, float))
        r, r_y, r_yy = np.full_like(y, self.r0), np.zeros_like(y), np.zeros_like(y)
        for depth, centre, width in self.bumps:
            u = (y - centre) / width
            e = depth * np.exp(-(u**2))
            r += e
            r_y += e * (-2 * u / width)
            r_yy += e * (4 * u**2 - 2) / width**2
        zero = np.zeros_like(y)
        return (r, zero, r_y, zero, zero, r_yy)


class CrownRail:
    """N(x, y) = Rr - sqrt(Rr^2 - (y - y_r)^2) (+ 0 for a flat rail when Rr is inf)."""

    def __init__(self, radius, y_r):
        self.radius, self.y_r = radius, y_r

    def evaluate(self, x, y):
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        zero = np.zeros_like(y)
        if not math.isfinite(self.radius):
            return (zero, zero, zero, zero, zero, zero)
        u = y - self.y_r
        root = np.sqrt(np.maximum(self.radius**2 - u**2, 1e-12))
        return (self.radius - root, zero, u / root, zero, zero, self.radius**2 / root**3)


def crown_case(shift, sink):
    r0, rho, y_w, rr, y_r = 0.46, 0.3, 0.75, 0.3, 0.752
    wheel, rail = CrownWheel(r0, rho, y_w), CrownRail(rr, y_r)
    pose = WheelsetPose(y_m=shift, z_m=-r0 + sink)
    # Exact: circles in the (y, z) plane.
    c_w = np.array([y_w + shift, -r0 + sink + r0 - rho])
    c_r = np.array([y_r, rr])
    dist = np.linalg.norm(c_r - c_w)
    approach = rho + rr - dist
    direction = (c_w - c_r) / dist  # rail -> wheel in (y, z)
    gamma = math.atan2(-direction[0], -direction[1])  # right side: tilt towards -y positive
    return wheel, rail, pose, approach, direction, gamma, (r0, rho, rr, c_w)


@pytest.mark.parametrize(("shift", "sink"), [(0.0, 1e-4), (0.006, 5e-5), (-0.01, 2e-4)])
def test_crowned_wheel_on_crowned_rail_matches_circle_geometry(shift, sink):
    wheel, rail, pose, approach, direction, gamma, (r0, rho, rr, c_w) = crown_case(shift, sink)
    got = search_side(wheel, rail, pose, "right", wheel_lateral_range_m=(0.70, 0.80), rail_lateral_range_m=(0.72, 0.78))
    assert got.status == "ok" and len(got.patches) == 1
    patch = got.patches[0]
    assert patch.approach_m == pytest.approx(approach, rel=1e-7)
    np.testing.assert_allclose(patch.frame[1:, 2], direction, atol=1e-8)
    assert patch.contact_angle_rad == pytest.approx(gamma, abs=1e-8)
    # Rolling radius: distance from the axle to the wheel's contact point on the crown circle.
    contact_on_wheel = c_w - rho * direction
    radius = contact_on_wheel[1] - pose.z_m
    assert patch.rolling_radius_m == pytest.approx(radius, rel=1e-9)
    assert patch.curvature_long_1_per_m == pytest.approx(math.cos(gamma) / (2 * radius), rel=1e-6)
    assert patch.curvature_lat_1_per_m == pytest.approx(0.5 * (1 / rho + 1 / rr), rel=1e-6)
    assert patch.ellipse_angle_rad == pytest.approx(0.0, abs=1e-8)
    assert patch.is_elliptic
    # Sampled gap at the centre equals -q, and it is a quadric of the patch's curvatures to a few %.
    field = patch.undeformed
    assert field.evaluate(0.0, 0.0) == pytest.approx(-approach, rel=1e-3)
    error = ellipticity_error(field, patch.curvature_long_1_per_m, patch.curvature_lat_1_per_m, 0.0, approach)
    assert error < 0.05


def test_gap_only_gives_no_contact_and_min_gap():
    wheel, rail, pose, approach, *_ = crown_case(0.0, -3e-4)
    got = search_side(wheel, rail, pose, "right", wheel_lateral_range_m=(0.70, 0.80), rail_lateral_range_m=(0.72, 0.78))
    assert got.status == "no-contact" and got.patches == []
    assert got.min_gap_m == pytest.approx(-approach, rel=1e-6)


def dense_patches(wheel, rail, pose, y_range, rail_range, step=2e-4):
    """Brute force: h on a dense grid (no Newton refinement of minima), connected regions with h < 0."""
    from scipy import ndimage

    from rigid_dynamics.contact.search import _SideGeometry

    geo = _SideGeometry(wheel, rail, pose, "right", y_range, rail_range)
    alphas = np.pi / 2 + np.linspace(-0.06, 0.06, 121)
    ys = np.arange(y_range[0], y_range[1], step)
    a, y = np.meshgrid(alphas, ys, indexing="ij")
    h = geo.distance(a, y, 12)[0]
    labels, count = ndimage.label(h < 0)
    out = []
    for k in range(1, count + 1):
        idx = np.argmin(np.where(labels == k, h, np.inf))
        out.append((y.flat[idx], -h.flat[idx]))
    return out


@pytest.mark.parametrize("yaw", [0.0, 0.02])
def test_two_point_contact_matches_brute_force_scan(yaw):
    """A wheel with a 'tread' and a 'flange' bump on a flat rail: both patches, as the dense scan finds them."""
    wheel = TwoBumpWheel(0.46, [(8e-5, 0.76, 0.01), (1.2e-4, 0.72, 0.004)])
    rail = CrownRail(math.inf, 0.75)
    pose = WheelsetPose(z_m=-0.46 - 2e-5, yaw_rad=yaw)
    y_range, rail_range = (0.70, 0.80), (0.65, 0.85)
    got = search_side(wheel, rail, pose, "right", wheel_lateral_range_m=y_range, rail_lateral_range_m=rail_range)
    brute = dense_patches(wheel, rail, pose, y_range, rail_range)
    assert len(brute) == 2 and len(got.patches) == 2
    found = sorted((p.point_m[1], p.approach_m) for p in got.patches)
    for (y_b, q_b), (y_s, q_s) in zip(sorted(brute), found, strict=True):
        assert abs(y_b * math.cos(yaw) - y_s) < 2e-3 or abs(y_b - y_s) < 2e-3
        assert q_s >= q_b - 1e-9  # refined minimum is at least as deep as the grid's
        assert q_s == pytest.approx(q_b, rel=0.05)


def test_bad_side_and_option():
    wheel, rail, pose, *_ = crown_case(0.0, 1e-4)
    with pytest.raises(ValueError, match="side = 'middle'"):
        search_side(wheel, rail, pose, "middle", wheel_lateral_range_m=(0.7, 0.8), rail_lateral_range_m=(0.7, 0.8))
    with pytest.raises(ValueError, match="option 'grid'"):
        search_side(
            wheel, rail, pose, "right", wheel_lateral_range_m=(0.7, 0.8), rail_lateral_range_m=(0.7, 0.8),
            options={"grid": 3},
        )  # fmt: skip
    with pytest.raises(ValueError, match="yaw_rad = nan"):
        WheelsetPose(yaw_rad=float("nan"))


def dense_scan_regions(track, pose, side, d_alpha=0.002, d_y=1e-4):
    """Brute force on the real profiles: h on a dense (alpha, y_d) grid with the numpy distance function (not the
    compiled kernels the search uses), connected regions with h < 0, deepest point of each."""
    from scipy import ndimage

    from rigid_dynamics.contact.search import _SideGeometry

    wheel, rail = track.fast[side]
    geo = _SideGeometry(wheel, rail, pose, side, wheel.y_range_m, rail.y_range_m)
    alphas = np.pi / 2 + np.arange(-0.1, 0.1 + 1e-12, d_alpha)
    ys = np.arange(*wheel.y_range_m, d_y)
    a, y = np.meshgrid(alphas, ys, indexing="ij")
    h = geo.distance(a, y, 12)[0]
    labels, count = ndimage.label(h < 0)
    regions = []
    for k in range(1, count + 1):
        idx = np.argmin(np.where(labels == k, h, np.inf))
        regions.append((y.flat[idx], -h.flat[idx]))
    return sorted(regions)


@pytest.mark.parametrize(
    ("shift_mm", "z_m", "roll_rad", "n_right"),
    [(5.0, -0.4599978, -3.5488e-4, 2), (6.5, -0.4629754, -4.2829e-3, 1), (0.0, -0.45980, 0.0, 1)],
)
def test_s1002_uic60_search_finds_every_patch_of_a_dense_scan(shift_mm, z_m, roll_rad, n_right):
    """S1002 on UIC60 1:40 at the A-2.2 poses (tread + flange-root two-point contact at 5 mm, flange at 6.5 mm):
    the search returns one patch per interpenetration region of a dense brute-force scan, as deep or deeper."""
    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import WheelsetCase

    case = WheelsetCase(
        "MBench_S1002_v3", "MBench_UIC60_v3", lateral_shift_m=shift_mm * 1e-3, yaw_rad=shift_mm * 2.4e-3,
        rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4,
    )  # fmt: skip
    track = build_track(case)
    pose = WheelsetPose(y_m=case.lateral_shift_m, z_m=z_m, yaw_rad=case.yaw_rad, roll_rad=roll_rad)
    for side in ("left", "right"):
        got = track.search(pose, side, {"field": False})
        brute = dense_scan_regions(track, pose, side)
        assert len(got.patches) == len(brute), (side, got.patches, brute)
        if side == "right":
            assert len(brute) == n_right
        found = sorted(zip(got.wheel_parameters[:, 1], (p.approach_m for p in got.patches), strict=True))
        for (y_b, q_b), (y_s, q_s) in zip(brute, found, strict=True):
            assert abs(y_b - y_s) < 1.5e-3
            assert q_s >= q_b * (1 - 1e-9)
            assert q_s == pytest.approx(q_b, rel=0.05, abs=2e-7)


def test_irregular_rail_uses_general_path_and_matches_tabulated():
    """A rail with a zero-amplitude irregularity takes the general (numpy, exact-surface) path; it must find the
    same patch as the compiled path on the tabulated ideal surfaces (two implementations of eq 11)."""
    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import WheelsetCase

    class Flat:
        def evaluate(self, x, y):
            zero = np.zeros(np.broadcast(x, y).shape)
            return (zero,) * 6

    case = WheelsetCase(
        "MBench_S1002_v3", "MBench_UIC60_v3", lateral_shift_m=0.003, yaw_rad=0.0072,
        rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4,
    )  # fmt: skip
    ideal = build_track(case)
    bumpy = build_track(case, rail_irregularities={"right": (Flat(),)})
    pose = WheelsetPose(y_m=0.003, z_m=-0.4599, yaw_rad=0.0072)
    a = ideal.search(pose, "right", {"field": False})
    b = bumpy.search(pose, "right", {"field": False})
    assert len(a.patches) == len(b.patches) == 1
    assert b.patches[0].approach_m == pytest.approx(a.patches[0].approach_m, rel=1e-6)
    np.testing.assert_allclose(b.patches[0].point_m, a.patches[0].point_m, atol=1e-6)
    assert b.patches[0].curvature_lat_1_per_m == pytest.approx(a.patches[0].curvature_lat_1_per_m, rel=1e-6)


def test_real_patch_curvatures_match_a_quadratic_fit_of_the_gap():
    """A, B and the ellipse angle from the fundamental forms (eq 12-33) against a least-squares quadratic fit of
    the gap sampled along n on a small grid (+-0.15 mm) around an S1002/UIC60 flange patch (7 mm shift, yaw)."""
    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import WheelsetCase

    case = WheelsetCase(
        "MBench_S1002_v3", "MBench_UIC60_v3", lateral_shift_m=0.007, yaw_rad=0.0168,
        rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4,
    )  # fmt: skip
    track = build_track(case)
    pose = WheelsetPose(y_m=0.007, z_m=-0.4645538, yaw_rad=0.0168, roll_rad=-6.3582e-3)
    options = {"field": True, "field_scale": 1e-6, "field_min_half_size_m": 1.5e-4, "field_points": 9}
    got = track.search(pose, "right", options)
    patch = max(got.patches, key=lambda p: p.contact_angle_rad)
    assert patch.contact_angle_rad > 0.9
    f = patch.undeformed
    x, y = np.meshgrid(f.x_m, f.y_m)
    design = np.stack([x.ravel() ** 2, x.ravel() * y.ravel(), y.ravel() ** 2, x.ravel(), y.ravel(), np.ones(x.size)], 1)
    c = np.linalg.lstsq(design, f.distance_m.ravel(), rcond=None)[0]
    d = np.array([[c[0], c[1] / 2], [c[1] / 2, c[2]]])
    rot = np.array([[math.cos(patch.ellipse_angle_rad), -math.sin(patch.ellipse_angle_rad)],
                    [math.sin(patch.ellipse_angle_rad), math.cos(patch.ellipse_angle_rad)]])  # fmt: skip
    expected = rot @ np.diag([patch.curvature_long_1_per_m, patch.curvature_lat_1_per_m]) @ rot.T
    np.testing.assert_allclose(d, expected, rtol=0.02, atol=0.02 * patch.curvature_long_1_per_m)
    assert c[5] == pytest.approx(-patch.approach_m, rel=1e-3)
