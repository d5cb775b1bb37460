"""Hertz's theory of elliptic normal contact, vectorised over many patches (seed eq 32-38).

Undeformed distance near the initial contact point (contact frame, x rolling, y lateral)::

    h(x, y) = A x^2 + B y^2 - q            (seed eq 32; A, B > 0 in 1/m, q the approach in m)

For two quasi-identical elastic half-spaces (shear modulus G, Poisson's ratio nu, combined
modulus E* = G/(1 - nu), Johnson 1985 eq 4.22) the contact area is an ellipse with semi-axes
a_major along the direction of the *smaller* relative curvature and b_minor = a_major sqrt(p),
and the pressure is p(x, y) = p0 sqrt(1 - x^2/a_x^2 - y^2/b_y^2). With the complete elliptic
integrals of parameter m = 1 - p (Kalker 1990 notation, m = e^2 = 1 - (b_minor/a_major)^2)::

    D(m) = (K - E)/m,   B(m) = (E - p K)/m,   C(m) = (D - B)/m                (Kalker 1990)
    curvature ratio   r = max(A, B)/min(A, B) = B(m) / (p D(m))              (axial function)
    min(A, B) = 3 N D / (2 pi E* a_major^3)      max(A, B) = 3 N B / (2 pi E* a_major b_minor^2)
    q = 3 N K / (2 pi E* a_major)               p0 = 3 N / (2 pi a_major b_minor)

The seed's axial function (eq 34) cos t = m (D - C)/E with cos t = |A - B|/(A + B) is the same
relation written for (r - 1)/(r + 1); eq 35 gives k_e = p (or 1/p), eq 36 the force from the
approach and eq 37-38 the semi-axes (Johnson 1985 sec. 4.2; Kalker 1990 sec. 1.4).
REFERENCES.md records that eq 34-38 were checked against the classical formulae.

Inverting the axial function: r(p) is solved for s = ln p by a bracketed (safeguarded) Newton
iteration, vectorised over patches. The upper end of the bracket, s <= -ln r, holds because
D(m) >= B(m) (1/Delta grows with sin t), so r(p) <= 1/p; the lower end
``-ln r - ln(2 (1 + ln(16 r)))`` is conservative and is checked (and widened) before iterating.
To keep full precision for every ratio from 1 (A = B) to beyond 1e4 (b/a ~ 4e-3):

* for m < 0.1 the functions D, B, C are summed from their power series (no cancellation in
  K - E when A ~ B),
* otherwise K comes from ``scipy.special.ellipkm1(p)`` (accurate as p -> 0, slender ellipses)
  and E from ``scipy.special.ellipe(m)``.

The loops below are plain Python; :func:`compiled_kernels` compiles the same functions with numba (scipy's two
functions then called through ``scipy.special.cython_special``): a batch of 10,000 costs well
under 1 us per patch there. A small batch in a process that has not imported numba (or one of this module's first
few small batches where numba is loaded: lazy_kernels.PYTHON_CALLS_LIMIT) runs the same source as Python
(scipy's ufuncs: the same compiled functions), so that a command solving one Hertz patch never pays numba's start-up
(about 0.6-0.8 s CPU, benchmarks/results/startup.md); both paths give the same bits (tests/test_hertz.py).

The residual is evaluated to ~1e-15 relative, so the converged semi-axes carry that accuracy
(the tests compare with an independent quadrature of Hertz's potential integrals to 1e-8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.lazy_kernels import compiled_copies, run_as_python

_SERIES_LIMIT = 0.1
_N_SERIES = 24


def _central_binomials(n: int) -> np.ndarray:
    """c_k = (2k)! / (4^k (k!)^2), k = 0..n-1 (so that int_0^{pi/2} sin^{2k} = pi/2 c_k)."""
    c = np.empty(n)
    c[0] = 1.0
    for k in range(1, n):
        c[k] = c[k - 1] * (2 * k - 1) / (2 * k)
    return c


_C = _central_binomials(_N_SERIES + 2)
# D(m) = pi/2 sum c_n c_{n+1} m^n ; B(m) = pi/2 sum c_n (c_n - c_{n+1}) m^n ;
# C(m) = pi/2 sum_{n>=1} c_n (2 c_{n+1} - c_n) m^(n-1)   (expanding (1 - m sin^2)^(-1/2) term by term)
_D_SERIES = 0.5 * math.pi * _C[:_N_SERIES] * _C[1 : _N_SERIES + 1]
_B_SERIES = 0.5 * math.pi * _C[:_N_SERIES] * (_C[:_N_SERIES] - _C[1 : _N_SERIES + 1])
_C_SERIES = 0.5 * math.pi * _C[1 : _N_SERIES + 1] * (2.0 * _C[2 : _N_SERIES + 2] - _C[1 : _N_SERIES + 1])


def _ellipkm1(p):
    """K from scipy's ``ellipkm1`` (K of parameter 1 - p), for the Python path (compiled: compiled_kernels)."""
    from scipy.special import ellipkm1

    return float(ellipkm1(p))


def _ellipe(m):
    """E from scipy's ``ellipe`` (E of parameter m), for the Python path (compiled: compiled_kernels)."""
    from scipy.special import ellipe

    return float(ellipe(m))


def _scipy_externals() -> dict:
    """Scipy's ``ellipkm1``/``ellipe`` for compiled code (``scipy.special.cython_special``), registered as named
    external symbols so that the compiled copies can be cached on disk.
    """
    import llvmlite.binding as llvm
    from numba import types
    from numba.extending import get_cython_function_address

    for name in ("ellipkm1", "ellipe"):
        llvm.add_symbol(f"wheelrail_scipy_{name}", get_cython_function_address("scipy.special.cython_special", name))
    signature = types.float64(types.float64)
    return {
        "_ellipkm1": types.ExternalFunction("wheelrail_scipy_ellipkm1", signature),
        "_ellipe": types.ExternalFunction("wheelrail_scipy_ellipe", signature),
    }


def compiled_kernels() -> dict:
    """Name -> numba-compiled copy of this module's loops (``_kdbc``, ``_shape``, ``_kdbc_many``, ``_shape_many``,
    ``_hertz_many``; lazy_kernels.compiled_copies; imports numba).
    """
    names = ("_kdbc", "_shape", "_kdbc_many", "_shape_many", "_hertz_many")
    return compiled_copies(__name__, names, replacements=_scipy_externals)


def _kernels(n: int):
    """The compiled copies, or None where a batch of ``n`` runs as Python (numba not imported, n small)."""
    return None if run_as_python(n, __name__) else compiled_kernels()


def _kdbc(p):
    """(K, D, B, C) of parameter m = 1 - p for one p in (0, 1] (see :func:`elliptic_kdbc`)."""
    m = 1.0 - p
    k = _ellipkm1(p)
    if m < _SERIES_LIMIT:
        d = _D_SERIES[-1]
        b = _B_SERIES[-1]
        c = _C_SERIES[-1]
        for i in range(_N_SERIES - 2, -1, -1):
            d = d * m + _D_SERIES[i]
            b = b * m + _B_SERIES[i]
            c = c * m + _C_SERIES[i]
        return k, d, b, c
    e = _ellipe(m)
    d = (k - e) / m
    b = (e - p * k) / m
    return k, d, b, (d - b) / m


def _shape(r, rtol, max_iterations):
    """Safeguarded Newton for s = ln p with B(m)/(p D(m)) = r; returns (p, iterations, converged)."""
    if r == 1.0:
        return 1.0, 0, True
    log_r = math.log(r)
    hi = -log_r
    lo = -log_r - math.log(2.0 * (1.0 + math.log(16.0 * r)))
    for _ in range(8):  # make sure g(lo) >= 0 (the bound is conservative; widened if ever needed)
        _, d, b, _ = _kdbc(math.exp(lo))
        if math.log(b) - lo - math.log(d) - log_r >= 0.0:
            break
        lo -= 2.0
    s = min(max(-4.0 / 3.0 * log_r, lo), hi)
    for it in range(1, max_iterations + 1):
        p = math.exp(s)
        _, d, b, c = _kdbc(p)
        g = math.log(b) - s - math.log(d) - log_r
        if g == 0.0:
            return p, it, True
        dg = -(p * c / (2.0 * b) + 0.5 + c / (2.0 * d))
        if g > 0.0:
            lo = s
        else:
            hi = s
        s_new = s - g / dg
        if not (lo <= s_new <= hi):
            s_new = 0.5 * (lo + hi)
        tol = rtol * (1.0 + abs(s))
        if abs(s_new - s) <= tol or hi - lo <= tol:
            return math.exp(s_new), it, True
        s = s_new
    return math.exp(s), max_iterations, False


def _kdbc_many(p, out):
    for i in range(p.shape[0]):
        k, d, b, c = _kdbc(p[i])
        out[i, 0] = k
        out[i, 1] = d
        out[i, 2] = b
        out[i, 3] = c


def _shape_many(r, rtol, max_iterations, p_out, it_out, ok_out):
    for i in range(r.shape[0]):
        p, it, ok = _shape(r[i], rtol, max_iterations)
        p_out[i] = p
        it_out[i] = it
        ok_out[i] = ok


def _hertz_many(curv_long, curv_lat, load, force_control, e_star, rtol, max_iterations, out, it_out, ok_out):
    """out[:, :] = (a, b, q, N, p0, m, major_along_x) per patch (zeros where load <= 0)."""
    for i in range(curv_long.shape[0]):
        A = curv_long[i]
        B = curv_lat[i]
        a_min = min(A, B)
        p, it, ok = _shape(max(A, B) / a_min, rtol, max_iterations)
        it_out[i] = it
        ok_out[i] = ok
        out[i, 5] = 1.0 - p
        out[i, 6] = 1.0 if A <= B else 0.0
        if load[i] <= 0.0:
            for j in range(5):
                out[i, j] = 0.0
            continue
        k, d, _, _ = _kdbc(p)
        if force_control:
            force = load[i]
            major = (3.0 * force * d / (2.0 * math.pi * e_star * a_min)) ** (1.0 / 3.0)
            approach = 3.0 * force * k / (2.0 * math.pi * e_star * major)
        else:
            approach = load[i]
            major = math.sqrt(approach * d / (k * a_min))
            force = 2.0 * math.pi * major * e_star * approach / (3.0 * k)
        minor = major * math.sqrt(p)
        if A <= B:
            out[i, 0] = major
            out[i, 1] = minor
        else:
            out[i, 0] = minor
            out[i, 1] = major
        out[i, 2] = approach
        out[i, 3] = force
        out[i, 4] = 3.0 * force / (2.0 * math.pi * major * minor)


def elliptic_kdbc(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Complete elliptic integrals K, D, B, C of parameter m = 1 - p, to full precision.

    Args:
        p: complementary parameter p = 1 - m in (0, 1], array.

    Returns:
        (K, D, B, C) with K = int dt/Delta, D = int sin^2/Delta, B = int cos^2/Delta,
        C = int sin^2 cos^2/Delta^3 over t in [0, pi/2], Delta = sqrt(1 - m sin^2 t) (Kalker 1990).
        K from scipy's ``ellipkm1(p)``; for m >= 0.1 D, B, C from K and scipy's ``ellipe(m)``,
        for m < 0.1 from their power series.
    """
    p = np.asarray(p, dtype=float)
    out = np.empty((p.size, 4))
    kernels = _kernels(p.size)
    (_kdbc_many if kernels is None else kernels["_kdbc_many"])(np.array(p.ravel(), dtype=float), out)
    return tuple(out[:, i].reshape(p.shape) for i in range(4))


def ellipse_shape_from_curvature_ratio(
    curvature_ratio: np.ndarray, *, rtol: float = 1e-14, max_iterations: int = 60
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Invert the axial function: p = (b_minor/a_major)^2 from r = max(A, B)/min(A, B) >= 1.

    Solves ``ln B(m) - ln p - ln D(m) = ln r`` for s = ln p (m = 1 - p) by Newton's method
    safeguarded by bisection inside a bracket that always contains the root; compiled loop over
    patches. Derivative: d(ln r)/ds = -(p C/(2B) + 1/2 + C/(2D)) (from dD/dm = (D - C)/(2p),
    dB/dm = C/2).

    Args:
        curvature_ratio: r >= 1, array (any shape).
        rtol: stop when the Newton step in s, or the bracket, is below rtol (1 + |s|) (the residual
            itself is only known to a few 1e-15, so smaller values cannot be met everywhere).
        max_iterations: iteration cap; patches not converged by then are flagged.

    Returns:
        (p, iterations, converged): p in (0, 1]; the largest number of iterations used; bool mask.
    """
    r = np.asarray(curvature_ratio, dtype=float)
    if not (np.all(np.isfinite(r)) and np.all(r >= 1.0)):
        raise ValueError(f"curvature_ratio = {curvature_ratio!r}: expected finite values >= 1")
    flat = np.array(r.ravel(), dtype=float)
    p = np.empty(flat.size)
    it = np.empty(flat.size, dtype=np.int64)
    ok = np.empty(flat.size, dtype=np.bool_)
    kernels = _kernels(flat.size)
    (_shape_many if kernels is None else kernels["_shape_many"])(flat, rtol, max_iterations, p, it, ok)
    return p.reshape(r.shape), np.asarray(it.max() if it.size else 0), ok.reshape(r.shape)


@dataclass(frozen=True, eq=False)
class HertzBatch:
    """Hertz solutions for a batch of patches (arrays of one common shape).

    Attributes:
        semi_axis_long_m: a, semi-axis along x (rolling), m.
        semi_axis_lat_m: b, semi-axis along y (lateral), m.
        approach_m: q, rigid approach, m.
        normal_force_N: N, N.
        max_pressure_Pa: p0 = 3 N / (2 pi a b), Pa.
        ellipse_parameter: m = 1 - (b_minor/a_major)^2 (Kalker's m^2 in the seed, eq 34-35).
        major_axis_along_x: True where the major axis lies along x (A <= B).
        converged: the axial-function inversion converged (always True in practice).
        iterations: Newton iterations used for the batch.
    """

    semi_axis_long_m: np.ndarray
    semi_axis_lat_m: np.ndarray
    approach_m: np.ndarray
    normal_force_N: np.ndarray
    max_pressure_Pa: np.ndarray
    ellipse_parameter: np.ndarray
    major_axis_along_x: np.ndarray
    converged: np.ndarray
    iterations: int

    @property
    def contact_area_m2(self) -> np.ndarray:
        """Contact area pi a b, m^2."""
        return math.pi * self.semi_axis_long_m * self.semi_axis_lat_m

    @property
    def ellipse_angle_rad(self) -> np.ndarray:
        """Angle from x to the major axis: 0 (major along x) or pi/2 (major along y), rad."""
        return np.where(self.major_axis_along_x, 0.0, 0.5 * math.pi)


def _check_material(shear_modulus_Pa: float, poisson_ratio: float) -> None:
    if not (np.all(np.isfinite(shear_modulus_Pa)) and np.all(np.asarray(shear_modulus_Pa) > 0)):
        raise ValueError(f"shear_modulus_Pa = {shear_modulus_Pa!r}: expected a finite number > 0")
    nu = np.asarray(poisson_ratio)
    if not (np.all(np.isfinite(nu)) and np.all((nu > -1.0) & (nu < 0.5))):
        raise ValueError(f"poisson_ratio = {poisson_ratio!r}: expected a value in (-1, 0.5)")


def hertz_solve_batch(
    curvature_long_1_per_m: np.ndarray,
    curvature_lat_1_per_m: np.ndarray,
    *,
    normal_force_N: np.ndarray | None = None,
    approach_m: np.ndarray | None = None,
    shear_modulus_Pa: float,
    poisson_ratio: float,
) -> HertzBatch:
    """Solve Hertz's problem for many patches at once (force or approach control).

    Exactly one of ``normal_force_N`` and ``approach_m`` must be given. Patches with a
    non-positive force or approach get zero semi-axes, force, pressure and approach (no contact).

    Args:
        curvature_long_1_per_m: A in h = A x^2 + B y^2 - q, 1/m, > 0 (array or scalar).
        curvature_lat_1_per_m: B, 1/m, > 0.
        normal_force_N: N, N (force control).
        approach_m: q, m (approach control).
        shear_modulus_Pa: G, Pa (both bodies).
        poisson_ratio: nu (both bodies).

    Returns:
        :class:`HertzBatch` with arrays of the broadcast input shape.

    Raises:
        ValueError: non-finite or non-positive curvatures, bad material, or not exactly one of
            normal_force_N / approach_m.
    """
    if (normal_force_N is None) == (approach_m is None):
        raise ValueError("hertz_solve_batch: expected exactly one of normal_force_N or approach_m")
    _check_material(shear_modulus_Pa, poisson_ratio)
    load = np.asarray(normal_force_N if approach_m is None else approach_m, dtype=float)
    A, B, load = np.broadcast_arrays(
        np.asarray(curvature_long_1_per_m, dtype=float), np.asarray(curvature_lat_1_per_m, dtype=float), load
    )
    if not (np.all(np.isfinite(A)) and np.all(A > 0)):
        raise ValueError(f"curvature_long_1_per_m = {curvature_long_1_per_m!r}: expected finite values > 0")
    if not (np.all(np.isfinite(B)) and np.all(B > 0)):
        raise ValueError(f"curvature_lat_1_per_m = {curvature_lat_1_per_m!r}: expected finite values > 0")
    if not np.all(np.isfinite(load)):
        name = "normal_force_N" if approach_m is None else "approach_m"
        raise ValueError(f"{name} = {load!r}: expected finite values")

    e_star = shear_modulus_Pa / (1.0 - poisson_ratio)
    shape = A.shape
    n = A.size
    out = np.empty((n, 7))
    it = np.empty(n, dtype=np.int64)
    ok = np.empty(n, dtype=np.bool_)
    kernels = _kernels(n)
    (_hertz_many if kernels is None else kernels["_hertz_many"])(
        np.array(A.ravel(), dtype=float),
        np.array(B.ravel(), dtype=float),
        np.array(load.ravel(), dtype=float),
        approach_m is None,
        float(e_star),
        1e-14,
        60,
        out,
        it,
        ok,
    )
    col = [out[:, j].reshape(shape) for j in range(7)]
    return HertzBatch(
        semi_axis_long_m=col[0],
        semi_axis_lat_m=col[1],
        approach_m=col[2],
        normal_force_N=col[3],
        max_pressure_Pa=col[4],
        ellipse_parameter=col[5],
        major_axis_along_x=col[6].astype(bool),
        converged=ok.reshape(shape),
        iterations=int(it.max()) if n else 0,
    )


def hertz_force_from_approach(
    curvature_long_1_per_m, curvature_lat_1_per_m, approach_m, *, shear_modulus_Pa: float, poisson_ratio: float
) -> np.ndarray:
    """N(q): normal force for a given approach (seed eq 36), N; 0 where q <= 0."""
    return hertz_solve_batch(
        curvature_long_1_per_m,
        curvature_lat_1_per_m,
        approach_m=approach_m,
        shear_modulus_Pa=shear_modulus_Pa,
        poisson_ratio=poisson_ratio,
    ).normal_force_N


def hertz_approach_from_force(
    curvature_long_1_per_m, curvature_lat_1_per_m, normal_force_N, *, shear_modulus_Pa: float, poisson_ratio: float
) -> np.ndarray:
    """q(N): approach for a given normal force (inverse of seed eq 36), m; 0 where N <= 0."""
    return hertz_solve_batch(
        curvature_long_1_per_m,
        curvature_lat_1_per_m,
        normal_force_N=normal_force_N,
        shear_modulus_Pa=shear_modulus_Pa,
        poisson_ratio=poisson_ratio,
    ).approach_m


def hertz_pressure_Pa(x_m, y_m, semi_axis_long_m: float, semi_axis_lat_m: float, max_pressure_Pa: float) -> np.ndarray:
    """Hertz pressure p0 sqrt(1 - x^2/a^2 - y^2/b^2) inside the ellipse, 0 outside, Pa."""
    rho = 1.0 - np.square(x_m / semi_axis_long_m) - np.square(y_m / semi_axis_lat_m)
    return max_pressure_Pa * np.sqrt(np.clip(rho, 0.0, None))
