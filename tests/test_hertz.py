"""Hertz elliptic contact (seed eq 32-38) against closed forms and an independent quadrature.

References:
* sphere on a plane and crossed equal cylinders: Johnson, Contact Mechanics (1985), sec. 4.2
  (a = (3 N R / (4 E*))^(1/3), q = a^2 / R, p0 = 3 N / (2 pi a^2));
* general ellipse: Hertz's potential of the ellipsoidal pressure p0 sqrt(1 - x^2/a^2 - y^2/b^2)
  (Johnson 1985, sec. 3.7 and eq. 4.29 area): the total surface displacement is
  u(x, y) = p0 a b / (2 E*) * int_0^inf (1 - x^2/(a^2+w) - y^2/(b^2+w)) dw / sqrt(w (a^2+w)(b^2+w)),
  so q, A, B follow from three one-dimensional integrals, evaluated here with scipy's quad
  (no elliptic integrals involved, independent of the code under test).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import elliprd

from rigid_dynamics.contact.hertz import (
    ellipse_shape_from_curvature_ratio,
    elliptic_kdbc,
    hertz_approach_from_force,
    hertz_force_from_approach,
    hertz_solve_batch,
)

G = 82.0e9
NU = 0.28
E_STAR = G / (1.0 - NU)


def _quad_split(f, breaks):
    total = 0.0
    for lo, hi in zip(breaks[:-1], breaks[1:], strict=True):
        val, _ = quad(f, lo, hi, epsabs=0.0, epsrel=2e-13, limit=400)
        total += val
    return total


def hertz_by_quadrature(a_major, b_minor, p0):
    """(A_major_dir, B_minor_dir, q, N) of the Hertz pressure with semi-axes a_major >= b_minor."""
    a2, b2 = a_major**2, b_minor**2

    def root(t):
        return math.sqrt((a2 + t * t) * (b2 + t * t))

    breaks = [0.0, b_minor, math.sqrt(a_major * b_minor), a_major, 10 * a_major, 1e3 * a_major, math.inf]
    pref = p0 * a_major * b_minor / (2.0 * E_STAR)
    q = pref * _quad_split(lambda t: 2.0 / root(t), breaks)
    curv_a = pref * _quad_split(lambda t: 2.0 / ((a2 + t * t) * root(t)), breaks)
    curv_b = pref * _quad_split(lambda t: 2.0 / ((b2 + t * t) * root(t)), breaks)
    force = 2.0 / 3.0 * math.pi * a_major * b_minor * p0
    return curv_a, curv_b, q, force


def test_sphere_on_plane_closed_form():
    radius = 0.46
    force = np.array([1.0e3, 5.0e4, 1.2e5])
    sol = hertz_solve_batch(0.5 / radius, 0.5 / radius, normal_force_N=force, shear_modulus_Pa=G, poisson_ratio=NU)
    a = np.cbrt(3.0 * force * radius / (4.0 * E_STAR))
    np.testing.assert_allclose(sol.semi_axis_long_m, a, rtol=1e-13)
    np.testing.assert_allclose(sol.semi_axis_lat_m, a, rtol=1e-13)
    np.testing.assert_allclose(sol.approach_m, a**2 / radius, rtol=1e-13)
    np.testing.assert_allclose(sol.max_pressure_Pa, 3.0 * force / (2.0 * math.pi * a**2), rtol=1e-13)


def test_crossed_equal_cylinders_closed_form():
    # two cylinders of radius R crossed at right angles: h = (x^2 + y^2)/(2R), i.e. a sphere of
    # radius R on a plane (Johnson 1985, sec. 4.2)
    radius = 0.3
    approach = 2.0e-5
    sol = hertz_solve_batch(0.5 / radius, 0.5 / radius, approach_m=approach, shear_modulus_Pa=G, poisson_ratio=NU)
    a = math.sqrt(approach * radius)
    force = 4.0 * E_STAR * a**3 / (3.0 * radius)
    assert sol.semi_axis_long_m == pytest.approx(a, rel=1e-13)
    assert sol.normal_force_N == pytest.approx(force, rel=1e-13)


@pytest.mark.parametrize("major_along_x", [True, False])
def test_against_quadrature_over_full_ratio_range(major_along_x):
    # b/a from 1 to 3e-3 covers curvature ratios 1 .. 1.6e4 (and the mirrored orientation)
    b_over_a = np.concatenate([[1.0, 1.0 - 1e-9, 0.999], np.logspace(-0.1, -2.5, 9)])
    a_major, p0 = 6.0e-3, 1.1e9
    rows = [hertz_by_quadrature(a_major, a_major * g, p0) for g in b_over_a]
    curv_major, curv_minor, q, force = (np.array(c) for c in zip(*rows, strict=True))
    ratio = curv_minor / curv_major
    assert ratio.max() > 1.0e4  # the range the issue asks for is covered
    A, B = (curv_major, curv_minor) if major_along_x else (curv_minor, curv_major)
    sol = hertz_solve_batch(A, B, normal_force_N=force, shear_modulus_Pa=G, poisson_ratio=NU)
    a_x, b_y = (
        (sol.semi_axis_long_m, sol.semi_axis_lat_m)
        if major_along_x
        else (
            sol.semi_axis_lat_m,
            sol.semi_axis_long_m,
        )
    )
    np.testing.assert_allclose(a_x, a_major, rtol=1e-8)
    np.testing.assert_allclose(b_y, a_major * b_over_a, rtol=1e-8)
    np.testing.assert_allclose(sol.approach_m, q, rtol=1e-8)
    np.testing.assert_allclose(sol.max_pressure_Pa, p0, rtol=1e-8)
    assert np.all(sol.major_axis_along_x == (major_along_x | (b_over_a == 1.0)))
    # approach control gives the same patch
    sol_q = hertz_solve_batch(A, B, approach_m=q, shear_modulus_Pa=G, poisson_ratio=NU)
    np.testing.assert_allclose(sol_q.normal_force_N, force, rtol=1e-8)
    np.testing.assert_allclose(sol_q.semi_axis_long_m, sol.semi_axis_long_m, rtol=1e-8)


def test_axial_function_inversion_accuracy():
    """The inverted ratio reproduces r = RD(0,1,p)/RD(0,p,1) (Carlson forms, DLMF 19.25.1) to 1e-13."""
    ratio = np.concatenate([np.logspace(0.0, 4.0, 801), 1.0 + np.logspace(-15, -1, 29), np.logspace(4, 8, 9)])
    p, iterations, converged = ellipse_shape_from_curvature_ratio(ratio)
    assert converged.all()
    assert iterations <= 12
    back = elliprd(0.0, 1.0, p) / elliprd(0.0, p, 1.0)
    rel = np.abs(back / ratio - 1.0)
    assert rel.max() < 1e-13, f"max relative residual {rel.max():.2e}"
    # monotone: larger curvature ratio -> more slender ellipse
    assert np.all(np.diff(p[:801]) <= 0)


def test_elliptic_functions_against_carlson_forms():
    p = np.concatenate([np.logspace(-12, 0, 60), [0.9, 0.95, 0.999999]])
    k, d, b, c = elliptic_kdbc(p)
    np.testing.assert_allclose(d, elliprd(0.0, p, 1.0) / 3.0, rtol=1e-14)
    np.testing.assert_allclose(b, p * elliprd(0.0, 1.0, p) / 3.0, rtol=1e-14)
    # C = int sin^2 cos^2 / Delta^3 by quadrature at a few points
    for pi, ci in zip(p[20::10], c[20::10], strict=True):  # p >= 1e-8: quad resolves the peak
        m = 1.0 - pi
        ref, _ = quad(
            lambda t, m=m: math.sin(t) ** 2 * math.cos(t) ** 2 / (1 - m * math.sin(t) ** 2) ** 1.5,
            0,
            math.pi / 2,
            epsrel=1e-13,
            limit=400,
        )
        assert ci == pytest.approx(ref, rel=1e-9)


def test_force_approach_round_trip():
    rng = np.random.default_rng(3)
    A = rng.uniform(0.2, 60.0, 200)
    B = rng.uniform(0.2, 60.0, 200)
    force = rng.uniform(1.0e2, 2.0e5, 200)
    q = hertz_approach_from_force(A, B, force, shear_modulus_Pa=G, poisson_ratio=NU)
    back = hertz_force_from_approach(A, B, q, shear_modulus_Pa=G, poisson_ratio=NU)
    np.testing.assert_allclose(back, force, rtol=1e-12)
    # N ~ q^(3/2) (seed eq 36)
    q2 = hertz_approach_from_force(A, B, 8.0 * force, shear_modulus_Pa=G, poisson_ratio=NU)
    np.testing.assert_allclose(q2, 4.0 * q, rtol=1e-12)


def test_no_contact_gives_zeros():
    sol = hertz_solve_batch([1.0, 1.0], [2.0, 2.0], approach_m=[-1e-6, 0.0], shear_modulus_Pa=G, poisson_ratio=NU)
    assert np.all(sol.normal_force_N == 0) and np.all(sol.semi_axis_long_m == 0) and np.all(sol.max_pressure_Pa == 0)


def test_bad_input_raises():
    with pytest.raises(ValueError, match="exactly one of normal_force_N or approach_m"):
        hertz_solve_batch(1.0, 1.0, shear_modulus_Pa=G, poisson_ratio=NU)
    with pytest.raises(ValueError, match="exactly one of normal_force_N or approach_m"):
        hertz_solve_batch(1.0, 1.0, normal_force_N=1.0, approach_m=1.0, shear_modulus_Pa=G, poisson_ratio=NU)
    with pytest.raises(ValueError, match="curvature_long_1_per_m"):
        hertz_solve_batch(-1.0, 1.0, normal_force_N=1.0, shear_modulus_Pa=G, poisson_ratio=NU)
    with pytest.raises(ValueError, match="curvature_lat_1_per_m"):
        hertz_solve_batch(1.0, np.nan, normal_force_N=1.0, shear_modulus_Pa=G, poisson_ratio=NU)
    with pytest.raises(ValueError, match="shear_modulus_Pa"):
        hertz_solve_batch(1.0, 1.0, normal_force_N=1.0, shear_modulus_Pa=0.0, poisson_ratio=NU)
    with pytest.raises(ValueError, match="poisson_ratio"):
        hertz_solve_batch(1.0, 1.0, normal_force_N=1.0, shear_modulus_Pa=G, poisson_ratio=0.5)
    with pytest.raises(ValueError, match="normal_force_N"):
        hertz_solve_batch(1.0, 1.0, normal_force_N=np.inf, shear_modulus_Pa=G, poisson_ratio=NU)


@pytest.mark.parametrize(("A", "B"), [(0.8, 2.4), (2.4, 0.8), (1.0, 1.0 + 1e-6), (0.5, 500.0), (30.0, 0.7)])
def test_seed_equations_34_to_38_as_printed(A, B):
    """Seed eq 34-38 evaluated literally (brentq on eq 34 with scipy's K, E) give the same patch.

    Note on eq 35: for D11 > D22 the seed sets k_e = 1/(1 - m^2); put into eq 36-37 as printed this
    does not reproduce Hertz (checked below). With k_e = 1 - m^2 in eq 36-37 for both orientations,
    eq 37 gives the semi-axis along the smaller relative curvature (as REFERENCES.md states) and
    b = a sqrt(k_e) the other one; that is the reading used here.
    """
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipk

    def kalker_dce(m2):
        k, e = ellipk(m2), ellipe(m2)
        d = (k - e) / m2
        b_ = k - d
        c = (d - b_) / m2
        return d, c, e

    def axial(m2):  # eq 34
        d, c, e = kalker_dce(m2)
        return m2 * (d - c) / e

    cos_t = abs(A - B) / (A + B)
    m2 = brentq(lambda m2: axial(m2) - cos_t, 1e-9, 1 - 1e-12, xtol=1e-15, rtol=1e-15)
    K, E = ellipk(m2), ellipe(m2)
    q = 2.0e-5

    def eq36_37(k_e):
        force = 2 * math.pi * G / (3 * (1 - NU)) * math.sqrt(E * q**3 / ((A + B) * k_e * K**3))  # eq 36, h -> -q
        a_ce = (3 * force * (1 - NU) * E / (2 * math.pi * G * (A + B) * k_e)) ** (1 / 3)  # eq 37
        return force, a_ce, a_ce * math.sqrt(k_e)  # eq 38

    force, major, minor = eq36_37(1 - m2)
    sol = hertz_solve_batch(A, B, approach_m=q, shear_modulus_Pa=G, poisson_ratio=NU)
    a_x, b_y = (major, minor) if A <= B else (minor, major)
    rtol = 1e-6 if abs(A - B) < 1e-3 else 1e-9  # brentq on the printed form loses digits near A = B
    assert sol.normal_force_N == pytest.approx(force, rel=rtol)
    assert sol.semi_axis_long_m == pytest.approx(a_x, rel=rtol)
    assert sol.semi_axis_lat_m == pytest.approx(b_y, rel=rtol)
    if A > B:
        literal_force, _, _ = eq36_37(1 / (1 - m2))
        assert abs(literal_force / force - 1) > 0.1


def test_regression_python_path_gives_the_compiled_bits():
    """Regression (two code paths of ours, not physics): hertz.py's loops run as Python (a small batch before numba
    is imported, e.g. ``wheelrail contact --method hertz``) and compiled by numba (hertz.compiled_kernels) give the
    same bits, over curvature ratios 1 to 2e4 (both branches of K, D, B, C), both axis orders, force and approach
    control."""
    from rigid_dynamics.contact import hertz

    compiled = hertz.compiled_kernels()

    rng = np.random.default_rng(7)
    ratio = np.concatenate([[1.0, 1.0 + 1e-9, 1.05, 1.2, 3.0, 100.0, 2e4], np.exp(rng.uniform(0.0, 9.9, 120))])
    curv_a = rng.uniform(1.0, 200.0, ratio.size)
    curv_b = curv_a * ratio
    swap = rng.random(ratio.size) < 0.5
    curv_a, curv_b = np.where(swap, curv_b, curv_a), np.where(swap, curv_a, curv_b)
    load = rng.uniform(-1e3, 2e5, ratio.size)
    for force_control, values in ((True, load), (False, np.abs(load) * 1e-10)):
        runs = []
        for kernel in (hertz._hertz_many, compiled["_hertz_many"]):
            out = np.empty((ratio.size, 7))
            it = np.empty(ratio.size, dtype=np.int64)
            ok = np.empty(ratio.size, dtype=np.bool_)
            kernel(curv_a, curv_b, values, force_control, E_STAR, 1e-14, 60, out, it, ok)
            runs.append((out, it, ok))
        for python_values, compiled_values in zip(*runs, strict=True):
            np.testing.assert_array_equal(python_values, compiled_values)
    for kernel in (hertz._kdbc_many, compiled["_kdbc_many"]):
        out = np.empty((ratio.size, 4))
        kernel(1.0 / ratio, out)
        runs.append(out)
    np.testing.assert_array_equal(runs[-2], runs[-1])


def test_small_batch_before_numba_runs_as_python():
    """A one-patch solve in a fresh process (the ``--method hertz`` command's path) does not import numba, and
    matches the compiled batch's bits once numba is loaded (regression between our two paths)."""
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import sys\n"
        "from rigid_dynamics.contact.hertz import hertz_solve_batch\n"
        "h = hertz_solve_batch(3.1, 27.5, normal_force_N=1.2e5, shear_modulus_Pa=82e9, poisson_ratio=0.28)\n"
        "print('numba' in sys.modules, repr(float(h.max_pressure_Pa)), repr(float(h.semi_axis_lat_m)))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=str(Path(__file__).resolve().parents[1]),
    )
    assert done.returncode == 0, done.stderr
    imported, p0, b = done.stdout.split()
    assert imported == "False"
    batch = hertz_solve_batch(
        np.full(20, 3.1), np.full(20, 27.5), normal_force_N=1.2e5, shear_modulus_Pa=82e9, poisson_ratio=0.28
    )
    assert float(p0) == float(batch.max_pressure_Pa[0]) and float(b) == float(batch.semi_axis_lat_m[0])
