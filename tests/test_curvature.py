"""Principal curvatures (eq 12-21) and relative curvature (eq 24-33) against closed forms.

References (exact, differential geometry of surfaces of revolution):
* sphere of radius R: both principal curvatures 1/R towards the centre;
* cylinder of radius R: 1/R across the axis, 0 along it;
* torus ((R + r cos v) cos u, (R + r cos v) sin u, r sin v): w.r.t. the normal pointing to the tube's centre,
  1/r along v and cos v / (R + r cos v) along u;
* a wheel of eq 7 with a circular crown against a cylindrical rail crossed at an angle: the relative curvature D
  is compared with the Hessian of the gap h(x, y) = N(x, y) - z_w(x, y) (explicit surfaces) by finite
  differences.
"""

import numpy as np
import pytest

from rigid_dynamics.contact.curvature import (
    common_principal_angle,
    curvature_tensor,
    principal_relative_curvature,
    relative_curvature,
    surface_curvature,
    symmetric_eigen,
)


def sphere(u, v, radius):
    """Sphere in latitude/longitude: x = R (cos v cos u, cos v sin u, sin v)."""
    cu, su, cv, sv = np.cos(u), np.sin(u), np.cos(v), np.sin(v)
    x = radius * np.stack([cv * cu, cv * su, sv], -1)
    d_u = radius * np.stack([-cv * su, cv * cu, 0 * u], -1)
    d_v = radius * np.stack([-sv * cu, -sv * su, cv], -1)
    d_uu = radius * np.stack([-cv * cu, -cv * su, 0 * u], -1)
    d_uv = radius * np.stack([sv * su, -sv * cu, 0 * u], -1)
    d_vv = radius * np.stack([-cv * cu, -cv * su, -sv], -1)
    return x, d_u, d_v, d_uu, d_uv, d_vv


def torus(u, v, big, small):
    cu, su, cv, sv = np.cos(u), np.sin(u), np.cos(v), np.sin(v)
    rho = big + small * cv
    x = np.stack([rho * cu, rho * su, small * sv], -1)
    d_u = np.stack([-rho * su, rho * cu, 0 * u], -1)
    d_v = np.stack([-small * sv * cu, -small * sv * su, small * cv], -1)
    d_uu = np.stack([-rho * cu, -rho * su, 0 * u], -1)
    d_uv = np.stack([small * sv * su, -small * sv * cu, 0 * u], -1)
    d_vv = np.stack([-small * cv * cu, -small * cv * su, -small * sv], -1)
    return x, d_u, d_v, d_uu, d_uv, d_vv


def test_sphere_both_curvatures_are_inverse_radius():
    u, v = np.meshgrid(np.linspace(0, 6, 7), np.linspace(-1.2, 1.2, 5))
    x, *derivs = sphere(u, v, 0.46)
    got = surface_curvature(*derivs, normal_towards=-x)  # inward normal
    np.testing.assert_allclose(got.principal_curvatures_1_per_m, 1 / 0.46, rtol=1e-9)
    np.testing.assert_allclose(got.normal, -x / 0.46, atol=1e-14)
    out = surface_curvature(*derivs, normal_towards=x)
    np.testing.assert_allclose(out.principal_curvatures_1_per_m, -1 / 0.46, rtol=1e-9)


def test_cylinder_skewed_parameters_gives_axis_and_hoop_directions():
    """Cylinder x = (R cos s, t, R sin s) with the non-orthogonal parameters s = u + 0.7 v, t = 2 v - 0.3 u.

    Exact: curvature 1/R along the hoop (e_s direction), 0 along the axis (0, 1, 0). A code that took eq 20's
    directions from the eigenvectors of H G^-1 would fail here because G is not diagonal.
    """
    radius = 0.3
    u, v = np.array([0.2, 1.1, -0.5]), np.array([0.4, -0.9, 0.05])
    s, t = u + 0.7 * v, 2 * v - 0.3 * u
    cs, ss = np.cos(s), np.sin(s)
    z = 0 * s
    ds = np.stack([-radius * ss, z, radius * cs], -1)  # d/ds
    dt = np.stack([z, 1 + z, z], -1)  # d/dt
    dss = np.stack([-radius * cs, z, -radius * ss], -1)
    d_u = ds * 1.0 + dt * (-0.3)
    d_v = ds * 0.7 + dt * 2.0
    d_uu, d_uv, d_vv = dss * 1.0, dss * 0.7, dss * 0.49
    centre = np.stack([z, t, z], -1)
    point = np.stack([radius * cs, t, radius * ss], -1)
    got = surface_curvature(d_u, d_v, d_uu, d_uv, d_vv, normal_towards=centre - point)
    np.testing.assert_allclose(got.principal_curvatures_1_per_m[..., 0], 1 / radius, rtol=1e-9)
    np.testing.assert_allclose(got.principal_curvatures_1_per_m[..., 1], 0, atol=1e-9 / radius)
    hoop = ds / radius
    np.testing.assert_allclose(np.abs(np.sum(got.principal_directions[..., 0, :] * hoop, -1)), 1, rtol=1e-12)
    np.testing.assert_allclose(np.abs(got.principal_directions[..., 1, 1]), 1, rtol=1e-12)
    frame = got.frame
    np.testing.assert_allclose(np.linalg.det(frame), 1, rtol=1e-12)


@pytest.mark.parametrize("big, small", [(0.46, 0.3), (2.0, 0.1)])
def test_torus_closed_form(big, small):
    u, v = np.meshgrid(np.linspace(0, 6, 5), np.linspace(-3, 3, 9))
    x, *derivs = torus(u, v, big, small)
    tube_centre = np.stack([big * np.cos(u), big * np.sin(u), 0 * u], -1)
    got = surface_curvature(*derivs, normal_towards=tube_centre - x)
    k_v = np.full_like(u, 1 / small)
    k_u = np.cos(v) / (big + small * np.cos(v))
    expected = np.stack([np.maximum(k_u, k_v), np.minimum(k_u, k_v)], -1)
    np.testing.assert_allclose(got.principal_curvatures_1_per_m, expected, rtol=1e-9, atol=1e-9 / small)
    # Second fundamental form consistency: the eigenvalues of G^-1 H equal the principal curvatures (eq 17).
    eig = np.sort(np.linalg.eigvals(np.linalg.solve(got.first_form, got.second_form)).real, axis=-1)[..., ::-1]
    np.testing.assert_allclose(eig, expected, rtol=1e-9, atol=1e-9 / small)


def test_symmetric_eigen_reconstructs_tensor():
    rng = np.random.default_rng(1)
    m = rng.normal(size=(50, 2, 2))
    m = m + np.swapaxes(m, -1, -2)
    l1, l2, angle = symmetric_eigen(m)
    c, s = np.cos(angle), np.sin(angle)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
    back = rot @ (np.stack([l1, l2], -1)[..., None] * np.swapaxes(rot, -1, -2))
    np.testing.assert_allclose(back, m, atol=1e-12)
    assert np.all(l1 >= l2)


@pytest.mark.parametrize("eps", [0.0, 0.3, -1.0, 1.4])
def test_eq25_angle_diagonalises_D(eps):
    """REFERENCES.md: eq 25 must make the off-diagonal term of D (eq 33) vanish, with both curvature pairs
    w.r.t. the same normal; D = (K_w - K_r)/2."""
    cw = np.array([2.2, -0.4])
    cr = np.array([-1.0, -5.0])
    rot = lambda a: np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])  # noqa: E731
    k_w = np.diag(cw)
    k_r = rot(eps) @ np.diag(cr) @ rot(eps).T  # rail's principal frame at angle eps from the wheel's
    d = relative_curvature(k_w, k_r)
    eps_w = common_principal_angle(cw, cr, eps)
    d_rot = rot(eps_w).T @ d @ rot(eps_w)
    assert abs(d_rot[0, 1]) < 1e-12 * np.abs(d).max()
    # eq 33 with T_w2, T_r2 (eq 29-30) and eps_r = eps_w - eps (eq 26) gives the same diagonal D.
    t_w, t_r = rot(-eps_w), rot(-(eps_w - eps))
    d33 = 0.5 * (t_w @ np.diag(cw) @ t_w.T - t_r @ np.diag(cr) @ t_r.T)
    np.testing.assert_allclose(d33, d_rot, atol=1e-12)


def test_principal_relative_curvature_keeps_A_along_rolling():
    a_true, b_true, ang = 1.1, 7.0, 0.2
    rot = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    d = rot @ np.diag([a_true, b_true]) @ rot.T
    a, b, angle = principal_relative_curvature(d)
    assert (a, b, angle) == pytest.approx((a_true, b_true, ang), abs=1e-13)
    a, b, angle = principal_relative_curvature(np.diag([3.0, 1.0]))
    assert (a, b, angle) == pytest.approx((3.0, 1.0, 0.0), abs=1e-15)


def test_wheel_on_crossed_cylindrical_rail_matches_gap_hessian():
    """Wheel of eq 7 with a circular crown R(y) = r0 - rho + sqrt(rho^2 - y^2), centre at (0, 0, -r0), touching
    at the origin a cylindrical rail N = Rr - sqrt(Rr^2 - s^2), s = -x sin(eps) + y cos(eps) (axis turned by eps).

    Independent reference: the gap h(x, y) = N(x, y) - z_w(x, y) with the wheel's lowest surface
    z_w = sqrt(R(y)^2 - x^2) - r0, differentiated twice by central differences; h = x^T D x in the basis
    e1 = main x, e2 = n x e1 = main -y (n = (0, 0, -1) rail -> wheel).
    """
    r0, rho, rr, eps = 0.46, 0.5, 0.3, 0.25
    n = np.array([0.0, 0.0, -1.0])
    e1, e2 = np.array([1.0, 0, 0]), np.cross(n, [1.0, 0, 0])
    # Wheel, parameters (alpha, y) at alpha = pi/2, y = 0 (eq 7, shifted by the centre).
    big, d_big, dd_big = r0, 0.0, -1 / rho  # R, R', R'' at y = 0
    a = np.pi / 2
    ca, sa = np.cos(a), np.sin(a)
    w_a = np.array([-big * sa, 0, big * ca])
    w_y = np.array([d_big * ca, 1, d_big * sa])
    w_aa = np.array([-big * ca, 0, -big * sa])
    w_ay = np.array([-d_big * sa, 0, d_big * ca])
    w_yy = np.array([dd_big * ca, 0, dd_big * sa])
    k_w = curvature_tensor(w_a, w_y, w_aa, w_ay, w_yy, n, e1, e2)
    # Rail, parameters (x, y): N_xx = sin^2/Rr, N_xy = -sin cos/Rr, N_yy = cos^2/Rr at the origin.
    se, ce = np.sin(eps), np.cos(eps)
    r_x, r_y = np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    r_xx, r_xy, r_yy = np.array([0, 0, se**2 / rr]), np.array([0, 0, -se * ce / rr]), np.array([0, 0, ce**2 / rr])
    k_r = curvature_tensor(r_x, r_y, r_xx, r_xy, r_yy, n, e1, e2)
    d = relative_curvature(k_w, k_r)

    def gap(x, y):
        radius = r0 - rho + np.sqrt(rho**2 - y**2)
        s = -x * se + y * ce
        return (rr - np.sqrt(rr**2 - s**2)) - (np.sqrt(radius**2 - x**2) - r0)

    h = 1e-4
    hxx = (gap(h, 0) - 2 * gap(0, 0) + gap(-h, 0)) / h**2
    hyy = (gap(0, h) - 2 * gap(0, 0) + gap(0, -h)) / h**2
    hxy = (gap(h, h) - gap(h, -h) - gap(-h, h) + gap(-h, -h)) / (4 * h**2)
    flip = np.diag([1.0, -1.0])  # main (x, y) -> (e1, e2)
    expected = 0.5 * flip @ np.array([[hxx, hxy], [hxy, hyy]]) @ flip
    np.testing.assert_allclose(d, expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    a_rel, b_rel, _ = principal_relative_curvature(d)
    assert a_rel > 0 and b_rel > 0
