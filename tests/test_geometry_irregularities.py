"""Irregularities (eq 5, 6): shapes against their formulas, derivatives against finite differences, periodicity."""

import math

import numpy as np
import pytest

from rigid_dynamics.geometry import (
    HarmonicOutOfRoundness,
    MeasuredRailIrregularity,
    MeasuredWheelIrregularity,
    RailCorrugation,
    TabulatedRailDeflection,
    TrackGeometry,
    WheelFlat,
    WheelsetGeometry,
    WinklerRailDeflection,
    circular_rail,
    circular_wheel,
)
from rigid_dynamics.geometry.irregularities import smooth_step

H = 1e-6  # finite-difference step (rad or m)


def _check_fd(obj, u, v, hu=H, hv=H, rtol=1e-5, atol=1e-12):
    """Central differences of value and first derivatives against the analytic derivatives."""
    f, fu, fv, fuu, fuv, fvv = obj.evaluate(u, v)
    ep, em = obj.evaluate(u + hu, v), obj.evaluate(u - hu, v)
    fp, fm = obj.evaluate(u, v + hv), obj.evaluate(u, v - hv)
    scale = np.max(np.abs(f)) + atol
    np.testing.assert_allclose(fu, (ep[0] - em[0]) / (2 * hu), rtol=rtol, atol=rtol * scale / hu * hu + atol)
    np.testing.assert_allclose(fv, (fp[0] - fm[0]) / (2 * hv), rtol=rtol, atol=1e-6 * np.max(np.abs(fv)) + atol)
    np.testing.assert_allclose(fuu, (ep[1] - em[1]) / (2 * hu), rtol=rtol, atol=1e-6 * np.max(np.abs(fuu)) + atol)
    np.testing.assert_allclose(fuv, (fp[1] - fm[1]) / (2 * hv), rtol=rtol, atol=1e-6 * np.max(np.abs(fuv)) + atol)
    np.testing.assert_allclose(fvv, (fp[2] - fm[2]) / (2 * hv), rtol=rtol, atol=1e-6 * np.max(np.abs(fvv)) + atol)


def test_harmonic_out_of_roundness_shape_derivatives_period():
    irr = HarmonicOutOfRoundness(order=3, amplitude_m=1e-4, phase_rad=0.4)
    a = np.linspace(0, 2 * np.pi, 37)
    v = irr.evaluate(a, 0.01)
    np.testing.assert_allclose(v[0], 1e-4 * np.cos(3 * a + 0.4), atol=1e-18)
    _check_fd(irr, a, np.full_like(a, 0.01))
    for k in range(6):
        np.testing.assert_allclose(irr.evaluate(a + 2 * np.pi, 0.0)[k], irr.evaluate(a, 0.0)[k], atol=1e-15)


def test_rounded_wheel_flat():
    """R_irr = -(d/2)(1 + cos(2 pi s / L)), s = r (a - a0), |s| <= L/2; d = L^2/(16 r) by default."""
    r, L = 0.46, 0.05
    flat = WheelFlat(length_m=L, wheel_radius_m=r)
    assert flat.depth == pytest.approx(L * L / (16 * r))
    a0 = np.pi / 2
    s = np.linspace(-0.04, 0.04, 81)
    v = flat.evaluate(a0 + s / r, 0.0)
    expected = np.where(np.abs(s) <= L / 2, -0.5 * flat.depth * (1 + np.cos(2 * np.pi * s / L)), 0.0)
    np.testing.assert_allclose(v[0], expected, atol=1e-16)
    assert float(flat.evaluate(a0, 0.0)[0]) == pytest.approx(-flat.depth)
    inner = a0 + np.linspace(-0.02, 0.02, 9) / r
    _check_fd(flat, inner, np.zeros_like(inner))
    # C1 at the edges, periodic in a
    edge = a0 + (L / 2) / r
    assert abs(float(flat.evaluate(edge - 1e-9, 0)[1])) < 1e-9
    np.testing.assert_allclose(flat.evaluate(inner + 2 * np.pi, 0)[0], flat.evaluate(inner, 0)[0], atol=1e-15)


def test_new_wheel_flat_is_a_chord():
    """New flat: the wheel surface follows the chord at distance r - d from the axle: R cos(a - a0) = r - d."""
    r, L = 0.46, 0.06
    flat = WheelFlat(length_m=L, wheel_radius_m=r, shape="new", centre_angle_rad=1.0)
    d = r - math.sqrt(r * r - L * L / 4)
    assert flat.depth == pytest.approx(d)
    half = math.asin(L / 2 / r)
    a = 1.0 + np.linspace(-0.99 * half, 0.99 * half, 21)
    R = r + flat.evaluate(a, 0.0)[0]
    np.testing.assert_allclose(R * np.cos(a - 1.0), r - d, rtol=1e-14)
    np.testing.assert_allclose(2 * r * math.sin(half), L, rtol=1e-14)
    _check_fd(flat, a, np.zeros_like(a))
    assert float(flat.evaluate(1.0 + 1.01 * half, 0.0)[0]) == 0.0


def test_measured_wheel_grid_interpolates_and_is_periodic():
    """A grid sampled from a smooth periodic field is reproduced at the nodes, between nodes to the
    spline accuracy, with C2 continuity across a = a0 + 2 pi."""
    a = np.linspace(0, 2 * np.pi, 48, endpoint=False) + 0.1
    y = np.linspace(-0.03, 0.04, 15)
    A, Y = np.meshgrid(a, y, indexing="ij")

    def field(aa, yy):
        return 1e-4 * (np.cos(2 * aa) + 0.3 * np.sin(5 * aa)) * (1 + 10 * yy)

    irr = MeasuredWheelIrregularity(a, y, field(A, Y))
    np.testing.assert_allclose(irr.evaluate(A, Y)[0], field(A, Y), atol=1e-17)
    aq, yq = np.linspace(-3, 9, 50), np.linspace(-0.029, 0.039, 50)
    np.testing.assert_allclose(irr.evaluate(aq, yq)[0], field(aq, yq), atol=2e-8)
    for k in range(6):
        np.testing.assert_allclose(irr.evaluate(aq + 2 * np.pi, yq)[k], irr.evaluate(aq, yq)[k], atol=1e-12)
    seam = 0.1 + 2 * np.pi
    for k in range(6):
        lo, hi = irr.evaluate(seam - 1e-9, 0.0)[k], irr.evaluate(seam + 1e-9, 0.0)[k]
        assert abs(float(hi - lo)) < 1e-7 * (1 + abs(float(lo)))
    _check_fd(irr, aq[5:-5], yq[5:-5], hv=1e-6, rtol=1e-4, atol=1e-9)
    assert irr.evaluate(0.0, 0.05)[0] == 0.0


def test_rail_corrugation_shape_taper_derivatives():
    corr = RailCorrugation(
        wavelength_m=0.05, amplitude_m=3e-5, phase_rad=0.2, centre_y_m=0.002, half_width_m=0.01, taper_m=0.004
    )
    x = np.linspace(0, 0.1, 41)
    v = corr.evaluate(x, 0.002)
    np.testing.assert_allclose(v[0], 3e-5 * np.cos(2 * np.pi * x / 0.05 + 0.2), atol=1e-18)
    assert np.all(corr.evaluate(x, 0.002 + 0.0141)[0] == 0)
    w = corr.lateral_weight(np.array([0.002 + 0.012]))[0]
    assert float(w[0]) == pytest.approx(1 - smooth_step(0.5)[0])
    xs, ys = np.linspace(0, 0.05, 9), np.linspace(-0.0115, 0.0155, 9)
    _check_fd(corr, xs, ys, hu=1e-7, hv=1e-7, rtol=1e-5, atol=1e-12)
    # smooth step: C2 at both ends
    s, ds, d2s = smooth_step(np.array([0.0, 1.0, 0.5]))
    np.testing.assert_allclose(s, [0, 1, 0.5])
    np.testing.assert_allclose(ds[:2], 0)
    np.testing.assert_allclose(d2s, 0, atol=1e-15)


def test_measured_rail_grid():
    x = np.linspace(0, 0.2, 41)
    y = np.linspace(-0.02, 0.02, 9)
    X, Y = np.meshgrid(x, y, indexing="ij")
    vals = 2e-5 * np.sin(2 * np.pi * X / 0.1) * np.cos(Y / 0.02)
    irr = MeasuredRailIrregularity(x, y, vals)
    np.testing.assert_allclose(irr.evaluate(X, Y)[0], vals, atol=1e-18)
    xq, yq = np.linspace(0.01, 0.19, 19), np.linspace(-0.018, 0.018, 19)
    _check_fd(irr, xq, yq, hu=1e-7, hv=1e-7, rtol=1e-4, atol=1e-12)
    assert irr.evaluate(0.3, 0.0)[0] == 0.0


def test_winkler_deflection_equilibrium_and_derivatives():
    """The foundation carries the load: integral of k w dx = F; w(0) = F beta / (2k)."""
    d = WinklerRailDeflection(
        load_N=1e5, load_position_m=0.3, bending_stiffness_Nm2=6.38e6, foundation_modulus_N_per_m2=5e7
    )
    b = d.beta_1_per_m
    assert b == pytest.approx((5e7 / (4 * 6.38e6)) ** 0.25)
    x = np.linspace(0.3 - 30 / b, 0.3 + 30 / b, 200001)
    w = d.evaluate(x)[0]
    assert np.trapezoid(5e7 * w, x) == pytest.approx(1e5, rel=1e-6)
    assert float(d.evaluate(0.3)[0]) == pytest.approx(1e5 * b / (2 * 5e7))
    xs = 0.3 + np.array([-1.1, -0.4, -0.05, 0.07, 0.5, 1.3])
    h = 1e-6
    f0, f1, f2 = d.evaluate(xs)
    np.testing.assert_allclose(f1, (d.evaluate(xs + h)[0] - d.evaluate(xs - h)[0]) / (2 * h), rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(f2, (d.evaluate(xs + h)[1] - d.evaluate(xs - h)[1]) / (2 * h), rtol=1e-5, atol=1e-10)


def test_tabulated_deflection():
    x = np.linspace(0, 1, 21)
    tab = TabulatedRailDeflection(x, 1e-3 * x**3)
    xs = np.linspace(0.05, 0.95, 7)
    v, dv, d2v = tab.evaluate(xs)
    np.testing.assert_allclose(v, 1e-3 * xs**3, atol=1e-15)
    np.testing.assert_allclose(dv, 3e-3 * xs**2, atol=1e-13)
    np.testing.assert_allclose(d2v, 6e-3 * xs, atol=1e-11)
    assert float(tab.evaluate(2.0)[0]) == pytest.approx(1e-3)


def test_irregularities_enter_the_surfaces():
    """R = R_id + R_irr (eq 5), N = N_d + N_id + N_irr (eq 6); y-derivatives change sign on the left."""
    ws = WheelsetGeometry(circular_wheel(0.2))
    flat = WheelFlat(0.04, 0.46)
    oor = HarmonicOutOfRoundness(2, 5e-5, 0.3)
    for side, s in (("right", 1.0), ("left", -1.0)):
        plain, rough = ws.wheel_surface(side), ws.wheel_surface(side, [flat, oor])
        a, yd = np.linspace(1.4, 1.7, 5), s * np.linspace(0.74, 0.76, 5)
        p, q = plain.evaluate(a, yd), rough.evaluate(a, yd)
        f, o = flat.evaluate(a, s * yd - 0.75), oor.evaluate(a, s * yd - 0.75)
        np.testing.assert_allclose(q.R - p.R, f[0] + o[0], atol=1e-16)
        np.testing.assert_allclose(q.R_a - p.R_a, f[1] + o[1], atol=1e-16)
        np.testing.assert_allclose(q.R_aa - p.R_aa, f[3] + o[3], atol=1e-14)
    corr = RailCorrugation(0.05, 2e-5, half_width_m=0.01, taper_m=0.005)
    defl = WinklerRailDeflection(1e5, 0.0, 6.38e6, 5e7)
    track = TrackGeometry(circular_rail(0.3, 0.12), rail_inclination_rad=0.0)
    for side, s in (("right", 1.0), ("left", -1.0)):
        plain, rough = track.rail_surface(side), track.rail_surface(side, [corr], deflection=defl)
        x = np.linspace(-0.1, 0.1, 7)
        y = s * (track.rail_offset_m + np.linspace(-0.012, 0.012, 7))
        p, q = plain.evaluate(x, y), rough.evaluate(x, y)
        c, d = corr.evaluate(x, s * y - track.rail_offset_m), defl.evaluate(x)
        np.testing.assert_allclose(q.N - p.N, c[0] + d[0], atol=1e-16)
        np.testing.assert_allclose(q.N_x - p.N_x, c[1] + d[1], atol=1e-14)
        np.testing.assert_allclose(q.N_y - p.N_y, s * c[2], atol=1e-14)
        np.testing.assert_allclose(q.N_xy - p.N_xy, s * c[4], atol=1e-12)
        # finite differences on the full surface
        h = 1e-7
        np.testing.assert_allclose(
            q.N_y, (rough.evaluate(x, y + h).N - rough.evaluate(x, y - h).N) / (2 * h), atol=1e-6
        )


def test_irregularity_errors():
    with pytest.raises(ValueError, match="order must be an integer >= 1"):
        HarmonicOutOfRoundness(0, 1e-4)
    with pytest.raises(ValueError, match="amplitude_m must be a finite number >= 0"):
        HarmonicOutOfRoundness(2, -1e-4)
    with pytest.raises(ValueError, match="length_m must be < 2 \\* wheel_radius_m"):
        WheelFlat(1.0, 0.46)
    with pytest.raises(ValueError, match="wheel_radius_m must be a finite number > 0"):
        WheelFlat(0.05, float("nan"))
    with pytest.raises(ValueError, match="shape must be 'rounded' or 'new'"):
        WheelFlat(0.05, 0.46, shape="square")
    with pytest.raises(ValueError, match="depth_m must be a finite number > 0"):
        WheelFlat(0.05, 0.46, depth_m=-1e-3)
    a, y = np.linspace(0, 6, 10), np.linspace(0, 0.01, 5)
    with pytest.raises(ValueError, match="angle_rad must span less than 2 pi"):
        MeasuredWheelIrregularity(np.linspace(0, 7, 10), y, np.zeros((10, 5)))
    with pytest.raises(ValueError, match="values_m must have shape"):
        MeasuredWheelIrregularity(a, y, np.zeros((5, 10)))
    with pytest.raises(ValueError, match="y_m must be strictly increasing"):
        MeasuredWheelIrregularity(a, y[::-1], np.zeros((10, 5)))
    with pytest.raises(ValueError, match="values_m must be finite"):
        MeasuredRailIrregularity(a, y, np.full((10, 5), np.nan))
    with pytest.raises(ValueError, match="x_m must be a 1-D array with at least 4"):
        MeasuredRailIrregularity([0, 1], y, np.zeros((2, 5)))
    with pytest.raises(ValueError, match="wavelength_m must be a finite number > 0"):
        RailCorrugation(0.0, 1e-5)
    with pytest.raises(ValueError, match="taper_m must be a finite number > 0"):
        RailCorrugation(0.05, 1e-5, taper_m=0.0)
    with pytest.raises(ValueError, match="deflection_m must be finite"):
        TabulatedRailDeflection(a, np.zeros(3))
    with pytest.raises(ValueError, match="foundation_modulus_N_per_m2 must be a finite number > 0"):
        WinklerRailDeflection(1e5, 0.0, 6e6, -1.0)


def test_measured_wheel_local_evaluation_equals_dense_regression():
    """Regression (two code paths of one spline): MeasuredWheelIrregularity.evaluate's compiled local bicubic
    evaluation (geometry._bicubic, 16 coefficients per point) equals the dense evaluation it replaced (every lateral
    basis function at every point, through the spline's own scipy objects), value and derivatives to second order,
    across the periodic wrap and outside the lateral range (0 there)."""
    from rigid_dynamics.geometry import MeasuredWheelIrregularity

    rng = np.random.default_rng(3)
    angle = np.sort(rng.uniform(-3.0, 3.0, 40))
    y = np.linspace(-0.03, 0.04, 30)
    irr = MeasuredWheelIrregularity(angle, y, 1e-4 * rng.standard_normal((40, 30)))
    a = rng.uniform(-9.0, 9.0, 3000)
    yy = rng.uniform(-0.04, 0.05, 3000)
    got = irr.evaluate(a, yy)
    inside = (yy >= y[0]) & (yy <= y[-1])
    yc = np.clip(yy, y[0], y[-1])
    for k, (p, q) in enumerate(((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))):
        dense = np.einsum("ij,ij->i", irr._spline_a(a, nu=p), np.nan_to_num(irr._basis_y(yc, nu=q)))
        want = np.where(inside, dense, 0.0)
        np.testing.assert_allclose(got[k], want, rtol=0, atol=1e-12 * max(1.0, np.max(np.abs(want))))
