"""Placement of wheel and rail profiles on wheelset and track; wheel and rail surfaces (eq 5, 6)."""

import math

import numpy as np
import pytest

from rigid_dynamics.geometry import CircularArcCurve, TrackGeometry, WheelsetGeometry, load_profile


@pytest.mark.parametrize(
    ("name", "canted", "cant"),
    [
        ("uic60_true", False, math.atan(1 / 40)),
        ("uic60_true", False, math.atan(1 / 20)),
        ("uic60_true", False, 0.0),
        ("MBench_UIC60_v3", True, math.atan(1 / 40)),
        ("site_b_hr", False, math.atan(1 / 40)),
    ],
)
def test_gauge_measured_on_placed_rails(name, canted, cant):
    """Measuring the gauge on the evaluated surfaces N_id(y) (root of N = h_g) gives back the requested gauge."""
    track = TrackGeometry(
        load_profile(name), gauge_m=1.435, gauge_height_m=0.014, rail_inclination_rad=cant, profile_is_canted=canted
    )
    assert track.measured_gauge_m() == pytest.approx(1.435, abs=1e-9)
    for side in ("left", "right"):
        n = track.rail_surface(side).ideal_height(np.linspace(*track.rail_surface(side).y_range_m, 2001))[0]
        assert np.nanmin(n) == pytest.approx(0.0, abs=1e-9)  # rail top at z = 0


@pytest.mark.parametrize("cant", [0.0, math.atan(1 / 40), math.atan(1 / 20)])
def test_circular_rail_placement_closed_form(cant):
    """Circular head of radius R (centre (0, R) in profile coordinates), canted by b:

    centre -> (R sin b, R cos b); top Z_top = R cos b - R; gauge point at depth h on the gauge side:
    Y_g = R sin b - sqrt(2 R h - h^2); so e_r = G/2 - Y_g; N(y) = Z_c - sqrt(R^2 - (Y - Y_c)^2) - Z_top.
    """
    R, G, h = 0.3, 1.435, 0.014
    arc = CircularArcCurve(R, 0.12, "rail")
    track = TrackGeometry(arc, gauge_m=G, gauge_height_m=h, rail_inclination_rad=cant)
    yc, zc = R * math.sin(cant), R * math.cos(cant)
    assert track.rail_offset_m == pytest.approx(G / 2 - (yc - math.sqrt(2 * R * h - h * h)), abs=1e-12)
    right = track.rail_surface("right")
    y = np.linspace(track.rail_offset_m - 0.04, track.rail_offset_m + 0.04, 41)
    v = right.evaluate(0.0, y)
    u = y - track.rail_offset_m - yc
    root = np.sqrt(R * R - u * u)
    np.testing.assert_allclose(v.N, zc - root - (zc - R), atol=1e-13)
    np.testing.assert_allclose(v.N_y, u / root, atol=1e-11)
    np.testing.assert_allclose(v.N_yy, R * R / root**3, rtol=1e-9)
    assert np.all(v.N_x == 0) and np.all(v.N_xx == 0) and np.all(v.N_xy == 0)
    left = track.rail_surface("left").evaluate(0.0, -y)
    np.testing.assert_allclose(left.N, v.N, atol=1e-15)
    np.testing.assert_allclose(left.N_y, -v.N_y, atol=1e-15)
    np.testing.assert_allclose(left.N_yy, v.N_yy, rtol=1e-12)


def test_circular_wheel_is_a_torus():
    """Circular (crowned) wheel profile z_p = -(R_c - sqrt(R_c^2 - y_p^2)), z_p down: R_id = r0 + z_p."""
    Rc, r0 = 0.1, 0.46
    ws = WheelsetGeometry(CircularArcCurve(Rc, 0.05, "wheel"), flange_back_distance_m=1.36, nominal_radius_m=r0)
    e = ws.tape_circle_offset_m
    assert e == pytest.approx(0.75)
    for side, s in (("right", 1.0), ("left", -1.0)):
        w = ws.wheel_surface(side)
        y_d = s * (e + np.linspace(-0.04, 0.04, 17))
        a = np.linspace(0, 2 * np.pi, 17)
        v = w.evaluate(a, y_d)
        yp = s * y_d - e
        root = np.sqrt(Rc * Rc - yp * yp)
        np.testing.assert_allclose(v.R, r0 - (Rc - root), atol=1e-15)
        np.testing.assert_allclose(v.R_y, -s * yp / root, atol=1e-13)
        np.testing.assert_allclose(v.R_yy, -Rc * Rc / root**3, rtol=1e-12)
        assert np.all(v.R_a == 0) and np.all(v.R_aa == 0) and np.all(v.R_ay == 0)


def test_s1002_wheelset_placement():
    """MBench wheelset: tape circles at |y_d| = 750 mm with R = r0; flanges inside; flange backs at 680 mm."""
    ws = WheelsetGeometry(load_profile("MBench_S1002_v3"))
    for side, s in (("right", 1.0), ("left", -1.0)):
        w = ws.wheel_surface(side)
        assert float(w.evaluate(np.pi / 2, s * 0.75).R) == pytest.approx(0.46, abs=1e-15)
        lo, hi = w.y_range_m
        assert min(abs(lo), abs(hi)) == pytest.approx(0.75 - 0.0696, abs=1e-4)
        y = np.linspace(lo, hi, 2001)
        R = w.ideal_radius(y)[0]
        y_flange = y[np.nanargmax(R)]
        assert abs(y_flange) < 0.75  # flange towards the track centre
        assert np.nanmax(R) == pytest.approx(0.46 + 0.028, abs=5e-5)
    # mirror symmetry of the two wheels
    y = np.linspace(0.69, 0.80, 23)
    r, left = ws.wheel_surface("right").evaluate(0.3, y), ws.wheel_surface("left").evaluate(0.3, -y)
    np.testing.assert_allclose(left.R, r.R, atol=0)
    np.testing.assert_allclose(left.R_y, -r.R_y, atol=0)
    np.testing.assert_allclose(left.R_yy, r.R_yy, atol=0)


def test_wheel_surface_derivatives_against_finite_differences():
    ws = WheelsetGeometry(load_profile("worn_high_mileage"))
    w = ws.wheel_surface("left")
    y = np.linspace(-0.79, -0.71, 9)
    h = 1e-6
    v = w.evaluate(0.0, y)
    np.testing.assert_allclose(v.R_y, (w.evaluate(0.0, y + h).R - w.evaluate(0.0, y - h).R) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(
        v.R_yy, (w.evaluate(0.0, y + h).R_y - w.evaluate(0.0, y - h).R_y) / (2 * h), rtol=1e-4, atol=1e-3
    )


def test_rail_surface_derivatives_against_finite_differences():
    track = TrackGeometry(load_profile("MBench_UIC60_v3"), profile_is_canted=True)
    r = track.rail_surface("left")
    y = np.linspace(-0.745, -0.73, 7)
    h = 1e-7
    v = r.evaluate(1.0, y)
    np.testing.assert_allclose(v.N_y, (r.evaluate(1.0, y + h).N - r.evaluate(1.0, y - h).N) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(
        v.N_yy, (r.evaluate(1.0, y + h).N_y - r.evaluate(1.0, y - h).N_y) / (2 * h), rtol=1e-4, atol=1e-2
    )
    yp, zp = r.to_profile_coordinates(y, v.N)
    np.testing.assert_allclose(zp, track.curve.z(yp) - 0.0, atol=1e-12 + abs(track._canted.z_top))


def test_outside_range_is_nan():
    track = TrackGeometry(load_profile("uic60_true"))
    r = track.rail_surface("right")
    assert np.isnan(r.evaluate(0.0, 0.0).N)
    assert np.isnan(WheelsetGeometry(load_profile("MBench_S1002_v3")).wheel_surface("right").evaluate(0.0, 0.0).R)


def test_placement_errors():
    rail, wheel = load_profile("uic60_true"), load_profile("MBench_S1002_v3")
    with pytest.raises(ValueError, match="gauge_m must be a finite number > 0"):
        TrackGeometry(rail, gauge_m=-1.0)
    with pytest.raises(ValueError, match="gauge_height_m must be"):
        TrackGeometry(rail, gauge_height_m=float("nan"))
    with pytest.raises(ValueError, match="rail_inclination_rad must be"):
        TrackGeometry(rail, rail_inclination_rad=1.0)
    with pytest.raises(ValueError, match="profile_is_canted must be True or False"):
        TrackGeometry(rail, profile_is_canted=1)
    with pytest.raises(ValueError, match="must be a rail profile"):
        TrackGeometry(wheel)
    with pytest.raises(ValueError, match="must be a wheel profile"):
        WheelsetGeometry(rail)
    with pytest.raises(ValueError, match="does not reach gauge_height_m"):
        TrackGeometry(rail, gauge_height_m=0.03)
    with pytest.raises(ValueError, match="nominal_radius_m must be"):
        WheelsetGeometry(wheel, nominal_radius_m=0.0)
    with pytest.raises(ValueError, match="flange_back_distance_m must be"):
        WheelsetGeometry(wheel, flange_back_distance_m=float("inf"))
    with pytest.raises(ValueError, match="side must be one of"):
        WheelsetGeometry(wheel).wheel_surface("middle")
    with pytest.raises(ValueError, match="side must be one of"):
        TrackGeometry(rail).rail_surface("up")
    with pytest.raises(ValueError, match="wheel_profile must be a Profile or a profile curve"):
        WheelsetGeometry("S1002")
    with pytest.raises(ValueError, match="irregularities must have an evaluate"):
        WheelsetGeometry(wheel).wheel_surface("left", irregularities=(1.0,))
    with pytest.raises(ValueError, match="deflection must have an evaluate"):
        TrackGeometry(rail).rail_surface("left", deflection=2.0)
    with pytest.raises(ValueError, match="must contain the tape circle"):
        WheelsetGeometry(CircularArcCurve(0.1, 0.01, "wheel", centre_y_m=0.05))


def _wheel_principal_curvatures(v):
    """Principal curvatures of x(a, y) = [R cos a, y, R sin a] from R and its derivatives (fundamental forms)."""
    R, Ra, Ry, Raa, Ray, Ryy = (np.asarray(q, float) for q in v)
    ca, sa = np.cos(0.7), np.sin(0.7)
    xa = np.stack([Ra * ca - R * sa, 0 * R, Ra * sa + R * ca], -1)
    xy = np.stack([Ry * ca, 1 + 0 * R, Ry * sa], -1)
    xaa = np.stack([Raa * ca - 2 * Ra * sa - R * ca, 0 * R, Raa * sa + 2 * Ra * ca - R * sa], -1)
    xay = np.stack([Ray * ca - Ry * sa, 0 * R, Ray * sa + Ry * ca], -1)
    xyy = np.stack([Ryy * ca, 0 * R, Ryy * sa], -1)
    n = np.cross(xa, xy)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    G = np.array([[np.sum(xa * xa, -1), np.sum(xa * xy, -1)], [np.sum(xy * xa, -1), np.sum(xy * xy, -1)]])
    Hm = np.array([[np.sum(n * xaa, -1), np.sum(n * xay, -1)], [np.sum(n * xay, -1), np.sum(n * xyy, -1)]])
    G, Hm = np.moveaxis(G, (0, 1), (-2, -1)), np.moveaxis(Hm, (0, 1), (-2, -1))
    return np.sort(np.abs(np.linalg.eigvals(np.linalg.solve(G, Hm)).real), axis=-1)


def test_analytic_test_surfaces_sphere_and_cylinder_curvature():
    """Wheel surfaces from exact curves: a circular profile of radius r0 centred on the axle is a sphere
    (both principal curvatures 1/r0); a 0-conicity wheel is a cylinder (0 and 1/r0); to 1e-9 relative."""
    r0 = 0.46
    sphere = WheelsetGeometry(CircularArcCurve(r0, 0.06, "wheel"), nominal_radius_m=r0).wheel_surface("left")
    y = -0.75 + np.linspace(-0.05, 0.05, 11)
    k = _wheel_principal_curvatures(sphere.evaluate(0.7, y))
    np.testing.assert_allclose(k, 1 / r0, rtol=1e-9)
    from rigid_dynamics.geometry import conical_wheel

    cyl = WheelsetGeometry(conical_wheel(0.0), nominal_radius_m=r0).wheel_surface("right")
    k = _wheel_principal_curvatures(cyl.evaluate(0.7, 0.75 + np.linspace(-0.04, 0.05, 10)))
    np.testing.assert_allclose(k[:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(k[:, 1], 1 / r0, rtol=1e-9)


def test_gauge_point_of_an_interpolated_point_profile_is_contacts():
    """An interpolated point profile's gauge point lies on the chord-length spline through its points, as CONTACT's:
    MBench_UIC60_v3 (canted 1:40 in its points) at 14 mm, gauge 1435 mm: CONTACT (rev 2707, X_PROFIL = 3 on
    tests/data/contact_friction/force_control/force_control.inp) prints "rail gauge point yg= -43.032558, offset
    rail->track= 760.532558" (mm). The z(y) spline's gauge point lies 0.31 um further out; the placed surface then
    measures the gauge within 1 um of G. With smoothing the curve is measured on itself (gauge exact)."""
    track = TrackGeometry(
        load_profile("MBench_UIC60_v3"), gauge_m=1.435, gauge_height_m=0.014, rail_inclination_rad=math.atan(1 / 40),
        profile_is_canted=True, smoothing_wavelength_m=0.0,
    )  # fmt: skip
    assert track.rail_offset_m == pytest.approx(0.760532558, abs=2e-8)
    assert track.measured_gauge_m() == pytest.approx(1.435, abs=1e-6)
