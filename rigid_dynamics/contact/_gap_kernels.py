"""Compiled (numba) sampler of a patch's undeformed distance on the tabulated surfaces: the one sampling code of the
static wheelset case (search._gap_at on TabulatedWheel/TabulatedRail) and the dynamics loop (compiled_rhs).

The mathematics of search._gap_at: at a contact-plane point (x, y) of a patch with centre c and frame
(e_x, e_y, n) (n from the rail into the wheel), base b = c + x e_x + y e_y,

* rail: t with (b + t n)_z = N((b + t n)_x, (b + t n)_y) by Newton's method (f'(t) = n_z - N_x n_x - N_y n_y,
  the slope floored at 1e-3 as search._SideGeometry._distance_along; +inf off the rail, beyond 0.05 m or with a
  vertical residual above 1e-10 m);
* wheel: x_w(alpha, y_d) = b + s n (eq 7-9: x_w = C_D [R cos a, y_d, R sin a] + x_t, R = R_id(y_d) + R_irr(a));
* gap s - t (negative where the undeformed bodies overlap), +inf where y_d leaves the wheel profile.

"Exact" (:func:`exact_gap`, :func:`exact_grid`: the reference): each point solved from the patch's parameters
alone, the rail's Newton from t = 0 and the wheel's on (alpha, y_d, s) started at alpha0 + x / R(alpha0, y0) and
y0 + y (e_y . C_D e_2).

The sampler (:func:`sample_grid`, :func:`gap_points`) finds the same roots faster. The wheel is a surface of
revolution: in the axle frame (p = C_D^T (x - x_t)) the point p = P_c + x u + y v + s w of the line (u, v, w =
C_D^T e_x, e_y, n) is on it where F(s) = |(p_0, p_2)| - R_id(p_1) - R_irr(atan2(p_2, p_0)) = 0, a 1-D root with one
profile lookup per step. Harmonic wheel rows (polygons) are evaluated once per column x, at the angle alpha_c of
P_c + x u, and at a point by their series in alpha - alpha_c to second order (third-order term below 1e-13 m;
beyond, and for flats, the rows at the point). The rail is extruded along x: with e_x the main x projected on the
contact plane its (y, z) part is parallel to n's, so along a lateral strip (a row of constant y) the line moves
along itself in the rail's section plane and t(x) = t(x_0) + (x - x_0) dt/dx exactly (an ideal rail; with rail
rows Newton's method per point). Per strip three anchors (first, middle, last column) are solved by Newton's
method from the strip before (:func:`chain_point`: each root from its neighbour's, moved by its derivatives), the
strip's other wheel roots by Newton's method from the quadratic through the anchors' s(x), the points interleaved;
each root is iterated to a step below 1e-9 m (then exact to c step^2, c the surfaces' curvature: round-off), and a
point whose start fails is solved from its neighbour or the patch's parameters. So the sampler's gap is the exact
one to round-off (tests/test_gap_kernels.py: < 1e-12 m, with 40 exact iterations: the exact solve's 8 leave far
corners of a doubled box unconverged by 3e-8 m).

Surfaces: the record :class:`GapSurfaces` (_search_kernels.Surfaces: Hermite tables of the ideal profiles and
closed-form irregularity rows, the one record of a side's surfaces in every compiled contact kernel). Patch:
:class:`GapPatch` (pose, patch point and frame as float triples, the wheel parameters of the contact point, Newton
iterations). The grid kernels fill caller-given arrays (no allocation: they run in the loop without NRT).

:func:`fitted_grid` is search._fitted_field's box (start at +-scale times the quadric's overlap semi-axes, at least
``min_half``; grow every side the overlap touches by the box's width up to _FIELD_LIMITS_M, at most 4 passes; then
shrink to the overlap's extent plus ``margin`` of it and two spacings on each side when that saves over 20 % of a
side). :func:`ellipticity_residual` is search.ellipticity_error.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact._search_kernels import (
    IRR_CODE,
    POLYGON,
    POLYGON_AMPLITUDE,
    POLYGON_ORDER,
    Surfaces,
    _table,
    rail_irregularity,
    wheel_irregularity,
)

_FAR = 0.05  # m, search._FAR_M
FIELD_LIMITS_M = (0.05, 0.03)  # search._FIELD_LIMITS_M: largest |x|, |y| of the sampled field
BOX_X_LO, BOX_X_HI, BOX_Y_LO, BOX_Y_HI = range(4)
"""Entries of a grid's box (x_lo, x_hi, y_lo, y_hi), m, contact frame (a tuple, or a row of an array of boxes)."""


GapSurfaces = Surfaces
"""One side's tabulated surfaces (_search_kernels.Surfaces, the record the search and the locus kernels take)."""


class GapPatch(NamedTuple):
    """A patch as the sampler needs it: the wheelset rotation C_D (3, 3) and centre (3,) (main frame, m), the
    patch centre and its frame vectors e_x, e_y, n as float triples, the contact point's wheel parameters
    (alpha0 rad, y0 m) and the Newton iterations.
    """

    rot: np.ndarray
    centre: np.ndarray
    point: tuple
    e_x: tuple
    e_y: tuple
    normal: tuple
    alpha0: float
    y0: float
    iterations: int


class GridFit(NamedTuple):
    """How :func:`fitted_grid` sizes the box: first half-sizes (m), the margin (fraction of the overlap's extent),
    and the smallest half-size, m.
    """

    half_x: float
    half_y: float
    margin: float
    min_half: float


@njit(cache=True, _nrt=False, inline="always")
def _rail(x, y, surf):
    """N, N_x, N_y of the rail at main-frame (x, y) (y clipped to the rail's range)."""
    lo, hi = surf.rail_range[0], surf.rail_range[1]
    yc = min(max(y, lo), hi)
    big_n, n_y, _ = _table(yc, *surf.rail)
    n_x = 0.0
    if surf.rail_irr.shape[0] > 0:
        v, vx, vy, _, _, _ = rail_irregularity(x, yc, surf.rail_irr, surf.rail_map[0], surf.rail_map[1])
        big_n, n_x, n_y = big_n + v, vx, n_y + vy
    return big_n, n_x, n_y


@njit(cache=True, _nrt=False)
def _rail_distance(b0, b1, b2, patch, surf, t):
    """The distance t along n from the base point (b0, b1, b2) to the rail, Newton's method from t; +inf off the
    rail (module docstring).
    """
    n0, n1, n2 = patch.normal
    for _ in range(patch.iterations):
        big_n, n_x, n_y = _rail(b0 + t * n0, b1 + t * n1, surf)
        f = b2 + t * n2 - big_n
        slope = n2 - n_x * n0 - n_y * n1
        if not abs(slope) > 1e-3:
            slope = math.copysign(1e-3, slope)
        step = f / slope
        t -= step
        if not abs(step) > 1e-13:
            break
    py = b1 + t * n1
    if not (py >= surf.rail_range[0] and py <= surf.rail_range[1] and math.isfinite(t) and abs(t) <= _FAR):
        return math.inf
    if not abs(b2 + t * n2 - _rail(b0 + t * n0, py, surf)[0]) < 1e-10:
        return math.inf
    return t


@njit(cache=True, _nrt=False, inline="always")
def _wheel(alpha, y_d, surf):
    """R, R_a, R_y of the wheel at (alpha, y_d) (nan off the profile)."""
    r, r_y, _ = _table(y_d, *surf.wheel)
    v, r_a, _ = wheel_irregularity(alpha, surf.wheel_irr)
    return r + v, r_a, r_y


@njit(cache=True, _nrt=False)
def _mul(rot, v0, v1, v2, i):
    return rot[i, 0] * v0 + rot[i, 1] * v1 + rot[i, 2] * v2


@njit(cache=True, _nrt=False)
def _wheel_exact(gx, gy, b0, b1, b2, surf, patch):
    """(s, lateral y_d) of the wheel at (gx, gy), base (b0, b1, b2): Newton's method on (alpha, y_d, s) from the
    patch's parameters (module docstring, "exact"); s is +inf where y_d leaves the wheel profile.
    """
    ey, nn = patch.e_y, patch.normal
    rot, ctr = patch.rot, patch.centre
    radius = _wheel(patch.alpha0, patch.y0, surf)[0]
    alpha = patch.alpha0 + gx / radius
    lat = patch.y0 + gy * (ey[0] * rot[0, 1] + ey[1] * rot[1, 1] + ey[2] * rot[2, 1])
    s = 0.0
    for _ in range(patch.iterations):
        r, r_a, r_y = _wheel(alpha, lat, surf)
        ca, sa = math.cos(alpha), math.sin(alpha)
        x0, x2 = r * ca, r * sa
        a0, a2 = r_a * ca - r * sa, r_a * sa + r * ca
        y0_, y2 = r_y * ca, r_y * sa
        # residual = point - base - s n; jacobian columns t_a, t_y, -n
        res0 = _mul(rot, x0, lat, x2, 0) + ctr[0] - b0 - s * nn[0]
        res1 = _mul(rot, x0, lat, x2, 1) + ctr[1] - b1 - s * nn[1]
        res2 = _mul(rot, x0, lat, x2, 2) + ctr[2] - b2 - s * nn[2]
        ta0, ta1, ta2 = _mul(rot, a0, 0.0, a2, 0), _mul(rot, a0, 0.0, a2, 1), _mul(rot, a0, 0.0, a2, 2)
        ty0, ty1, ty2 = _mul(rot, y0_, 1.0, y2, 0), _mul(rot, y0_, 1.0, y2, 1), _mul(rot, y0_, 1.0, y2, 2)
        m0, m1, m2 = -nn[0], -nn[1], -nn[2]
        det = ta0 * (ty1 * m2 - ty2 * m1) - ty0 * (ta1 * m2 - ta2 * m1) + m0 * (ta1 * ty2 - ta2 * ty1)
        r0, r1, r2 = -res0, -res1, -res2
        d_a = (r0 * (ty1 * m2 - ty2 * m1) - ty0 * (r1 * m2 - r2 * m1) + m0 * (r1 * ty2 - r2 * ty1)) / det
        d_y = (ta0 * (r1 * m2 - r2 * m1) - r0 * (ta1 * m2 - ta2 * m1) + m0 * (ta1 * r2 - ta2 * r1)) / det
        d_s = (ta0 * (ty1 * r2 - ty2 * r1) - ty0 * (ta1 * r2 - ta2 * r1) + r0 * (ta1 * ty2 - ta2 * ty1)) / det
        alpha, lat, s = alpha + d_a, lat + d_y, s + d_s
        if not (abs(d_a) * radius + abs(d_y) + abs(d_s) > 1e-15):
            break
    if not (lat >= surf.y_range[0] and lat <= surf.y_range[1]):
        return math.inf, lat
    return s, lat


@njit(cache=True, _nrt=False, inline="always")
def _base(gx, gy, patch):
    """The main-frame base point c + gx e_x + gy e_y of the contact-plane point (gx, gy)."""
    ex, ey, c = patch.e_x, patch.e_y, patch.point
    return c[0] + gx * ex[0] + gy * ey[0], c[1] + gx * ex[1] + gy * ey[1], c[2] + gx * ex[2] + gy * ey[2]


@njit(cache=True, _nrt=False)
def exact_gap(gx, gy, surf, patch):
    """The gap along n at (gx, gy), each surface solved from the patch's parameters alone (module docstring,
    "exact": the rail's Newton from t = 0, the wheel's on (alpha, y_d, s)); the reference of :func:`gap_points`.
    """
    b0, b1, b2 = _base(gx, gy, patch)
    t_rail = _rail_distance(b0, b1, b2, patch, surf, 0.0)
    s = _wheel_exact(gx, gy, b0, b1, b2, surf, patch)[0]
    return s - t_rail if math.isfinite(s) else math.inf


@njit(cache=True)
def exact_points(gx, gy, surf, patch, out):
    """:func:`exact_gap` at the points (gx[k], gy[k]) into out[k] (1-D arrays)."""
    for k in range(gx.shape[0]):
        out[k] = exact_gap(gx[k], gy[k], surf, patch)


# --- the chained sampler: each point's roots by Newton's method from its neighbour's, predicted to first order -----
STEP_TOLERANCE_M = 1.0e-9
"""A Newton step below this ends a chained root's iterations: the root is then exact to about c step^2 (c the
surfaces' curvature, < 1e3 1/m: < 1e-15 m)."""
CHAIN_REACH_M = 5.0e-3
"""A neighbour farther than this (|dx| + |dy|, m) starts no chain: the point is solved from the patch's parameters."""
SERIES_ERROR_M = 1.0e-13
"""The largest error of the wheel irregularity's column series (the third-order term's bound, m)."""
NO_CHAIN = (math.nan, math.nan, math.nan, 0.0, 0.0, math.nan, math.nan, math.nan, 0.0, 0.0)
"""A chain state with no neighbour: (x, y of the rail's last root, t, dt/dx, dt/dy, x, y of the wheel's, s, ds/dx,
ds/dy)."""
CHAIN_RAIL_X, CHAIN_RAIL_Y, CHAIN_T, CHAIN_T_X, CHAIN_T_Y, CHAIN_WHEEL_X, CHAIN_WHEEL_Y, CHAIN_S = range(8)
"""Entries of a chain state (NO_CHAIN's layout; 8, 9: ds/dx, ds/dy)."""
SERIES_COS, SERIES_SIN, SERIES_VALUE, SERIES_SLOPE, SERIES_CURVATURE = range(5)
"""Entries of a column series (:func:`chain_column`): cos, sin alpha_c, R_irr, dR_irr/da, d2R_irr/da2."""
WHEEL_IDEAL, WHEEL_SERIES, WHEEL_EXACT = range(3)
"""How the chained wheel root evaluates R_irr: none; harmonic rows by the column series; flats at each iterate."""


@njit(cache=True, _nrt=False)
def _to_axle(rot, v0, v1, v2):
    """C_D^T v: a main-frame vector in the wheelset's axle frame."""
    return (
        rot[0, 0] * v0 + rot[1, 0] * v1 + rot[2, 0] * v2,
        rot[0, 1] * v0 + rot[1, 1] * v1 + rot[2, 1] * v2,
        rot[0, 2] * v0 + rot[1, 2] * v1 + rot[2, 2] * v2,
    )


@njit(cache=True, _nrt=False)
def chain_axes(surf, patch):
    """The patch in the axle frame and the wheel's irregularity mode: ((P_c, u, v, w), mode, series limit): P_c =
    C_D^T (c - x_centre), u, v, w = C_D^T e_x, e_y, n; mode WHEEL_IDEAL (no rows), WHEEL_SERIES (harmonic rows
    only) or WHEEL_EXACT (a flat); the largest |tan(alpha - alpha_c)| the column series serves (its third-order
    term sum |A| n^3 |da|^3 / 6 below SERIES_ERROR_M; beyond it the rows are evaluated at the point).
    """
    rot, c, ctr = patch.rot, patch.point, patch.centre
    pc = _to_axle(rot, c[0] - ctr[0], c[1] - ctr[1], c[2] - ctr[2])
    u = _to_axle(rot, patch.e_x[0], patch.e_x[1], patch.e_x[2])
    v = _to_axle(rot, patch.e_y[0], patch.e_y[1], patch.e_y[2])
    w = _to_axle(rot, patch.normal[0], patch.normal[1], patch.normal[2])
    irr = surf.wheel_irr
    mode, third = WHEEL_IDEAL, 0.0
    for k in range(irr.shape[0]):
        if irr[k, IRR_CODE] == POLYGON:
            mode = max(mode, WHEEL_SERIES)
            third += abs(irr[k, POLYGON_AMPLITUDE]) * abs(irr[k, POLYGON_ORDER]) ** 3
        else:
            mode = WHEEL_EXACT
    limit = min(1.0e-3, (6.0 * SERIES_ERROR_M / third) ** (1.0 / 3.0)) if third > 0.0 else 1.0e-3
    return (pc, u, v, w), mode, limit


@njit(cache=True, _nrt=False)
def chain_column(gx, surf, axes, mode):
    """The wheel irregularity's column series at the contact-plane x = gx (WHEEL_SERIES): (cos alpha_c, sin alpha_c,
    R_irr, dR_irr/da, d2R_irr/da2 at alpha_c), alpha_c the angle of the axle-frame point P_c + gx u; zeros else.
    """
    if mode != WHEEL_SERIES:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    pc, u = axes[0], axes[1]
    p0, p2 = pc[0] + gx * u[0], pc[2] + gx * u[2]
    rho = math.sqrt(p0 * p0 + p2 * p2)
    v, va, vaa = wheel_irregularity(math.atan2(p2, p0), surf.wheel_irr)
    return p0 / rho, p2 / rho, v, va, vaa


@njit(cache=True, _nrt=False, inline="always")
def _wheel_irr_at(p0, p2, rho, surf, mode, col, limit):
    """(R_irr, dR_irr/da) at the axle-frame point (p0, ., p2) at radius rho: the column series in
    da = alpha - alpha_c (tan da from the point, da to fifth order) when it serves, else the rows at the point's
    angle.
    """
    if mode == WHEEL_IDEAL:
        return 0.0, 0.0
    if mode == WHEEL_SERIES:
        ca, sa = col[SERIES_COS], col[SERIES_SIN]
        den = ca * p0 + sa * p2
        tan_da = (ca * p2 - sa * p0) / den
        if den > 0.0 and abs(tan_da) <= limit:
            t2 = tan_da * tan_da
            da = tan_da * (1.0 - t2 * (1.0 / 3.0 - 0.2 * t2))
            value, slope, curvature = col[SERIES_VALUE], col[SERIES_SLOPE], col[SERIES_CURVATURE]
            return value + da * (slope + 0.5 * da * curvature), slope + da * curvature
    v, va, _ = wheel_irregularity(math.atan2(p2, p0), surf.wheel_irr)
    return v, va


@njit(cache=True, _nrt=False, inline="always")
def _wheel_root(gx, gy, s, surf, patch, axes, mode, col, limit):
    """The wheel's distance s along n from the base of (gx, gy) by Newton's method on
    F(s) = |(p_0, p_2)| - R(p_1) - R_irr(alpha), p = P_c + gx u + gy v + s w (axle frame: the surface of
    revolution), from s. Returns (s, ds/dx, ds/dy, y_d, converged); s +inf where y_d leaves the profile.
    """
    pc, u, v, w = axes
    b0 = pc[0] + gx * u[0] + gy * v[0]
    b1 = pc[1] + gx * u[1] + gy * v[1]
    b2 = pc[2] + gx * u[2] + gy * v[2]
    for _ in range(patch.iterations):
        p0, p1, p2 = b0 + s * w[0], b1 + s * w[1], b2 + s * w[2]
        rho = math.sqrt(p0 * p0 + p2 * p2)
        r, r_y, _ = _table(p1, *surf.wheel)
        irr, irr_a = _wheel_irr_at(p0, p2, rho, surf, mode, col, limit)
        # the gradient of F in the axle frame (alpha = atan2(p_2, p_0): d alpha = (p_0 dp_2 - p_2 dp_0) / rho^2)
        g0 = (p0 + irr_a * p2 / rho) / rho
        g2 = (p2 - irr_a * p0 / rho) / rho
        slope = g0 * w[0] - r_y * w[1] + g2 * w[2]
        step = (rho - r - irr) / slope
        if not math.isfinite(step):
            break
        s -= step
        if abs(step) < STEP_TOLERANCE_M:
            lat = p1 - step * w[1]
            s_x = -(g0 * u[0] - r_y * u[1] + g2 * u[2]) / slope
            s_y = -(g0 * v[0] - r_y * v[1] + g2 * v[2]) / slope
            if not (lat >= surf.y_range[0] and lat <= surf.y_range[1]):
                return math.inf, 0.0, 0.0, lat, True
            return s, s_x, s_y, lat, True
    return math.nan, 0.0, 0.0, math.nan, False


@njit(cache=True, _nrt=False, inline="always")
def _rail_root(b0, b1, b2, patch, surf, t):
    """The rail's distance t along n from the base (b0, b1, b2) by Newton's method from t (the slope floored as
    :func:`_rail_distance`). Returns (t, dt/dx, dt/dy, converged); t +inf off the rail or beyond 0.05 m.
    """
    n0, n1, n2 = patch.normal
    ex, ey = patch.e_x, patch.e_y
    for _ in range(patch.iterations):
        big_n, n_x, n_y = _rail(b0 + t * n0, b1 + t * n1, surf)
        slope = n2 - n_x * n0 - n_y * n1
        if not abs(slope) > 1e-3:
            slope = math.copysign(1e-3, slope)
        step = (b2 + t * n2 - big_n) / slope
        if not math.isfinite(step):
            break
        t -= step
        if abs(step) < STEP_TOLERANCE_M:
            py = b1 + t * n1
            if not (py >= surf.rail_range[0] and py <= surf.rail_range[1] and abs(t) <= _FAR):
                return math.inf, 0.0, 0.0, True
            # G(t) = b_z + t n_z - N(b + t n): dG/db = (-N_x, -N_y, 1), dG/dt = slope
            t_x = -(ex[2] - n_x * ex[0] - n_y * ex[1]) / slope
            t_y = -(ey[2] - n_x * ey[0] - n_y * ey[1]) / slope
            return t, t_x, t_y, True
    return math.nan, 0.0, 0.0, False


@njit(cache=True, _nrt=False)
def chain_point(gx, gy, surf, patch, axes, mode, col, limit, chain):
    """The gap at (gx, gy) and the chain state after it: each surface's root by Newton's method from the chain's
    last root of that surface (``chain``: NO_CHAIN's layout) moved by its derivatives to (gx, gy), when that root
    is within CHAIN_REACH_M; else, or when that Newton fails, from the patch's parameters (:func:`exact_gap`'s
    solves), then polished by the chained Newton for its derivatives. The roots are the exact solves' (to the
    step tolerance); col: :func:`chain_column` at gx.
    """
    rx, ry, t0, t_x, t_y, wx, wy, s0, s_x, s_y = chain
    b0, b1, b2 = _base(gx, gy, patch)
    ok = False
    if abs(gx - rx) + abs(gy - ry) <= CHAIN_REACH_M:
        t, tx, ty, ok = _rail_root(b0, b1, b2, patch, surf, t0 + t_x * (gx - rx) + t_y * (gy - ry))
    if not ok:
        t = _rail_distance(b0, b1, b2, patch, surf, 0.0)
        tx, ty = 0.0, 0.0
        if math.isfinite(t):
            t1, tx1, ty1, ok1 = _rail_root(b0, b1, b2, patch, surf, t)
            if ok1 and math.isfinite(t1):
                t, tx, ty, ok = t1, tx1, ty1, True
    if ok and math.isfinite(t):
        rx, ry, t0, t_x, t_y = gx, gy, t, tx, ty
    ok = False
    if abs(gx - wx) + abs(gy - wy) <= CHAIN_REACH_M:
        s, sx, sy, lat, ok = _wheel_root(gx, gy, s0 + s_x * (gx - wx) + s_y * (gy - wy), surf, patch, axes, mode,
                                         col, limit)  # fmt: skip
    if not ok:
        s = _wheel_exact(gx, gy, b0, b1, b2, surf, patch)[0]
        sx, sy = 0.0, 0.0
        if math.isfinite(s):
            s1, sx1, sy1, _, ok1 = _wheel_root(gx, gy, s, surf, patch, axes, mode, col, limit)
            if ok1 and math.isfinite(s1):
                s, sx, sy, ok = s1, sx1, sy1, True
    if ok and math.isfinite(s):
        wx, wy, s0, s_x, s_y = gx, gy, s, sx, sy
    gap = s - t if math.isfinite(s) else math.inf
    return gap, (rx, ry, t0, t_x, t_y, wx, wy, s0, s_x, s_y)


@njit(cache=True, _nrt=False)
def gap_point(gx, gy, surf, patch):
    """The gap along n at the contact-plane point (gx, gy) of ``patch``, m (module docstring)."""
    axes, mode, limit = chain_axes(surf, patch)
    return chain_point(gx, gy, surf, patch, axes, mode, chain_column(gx, surf, axes, mode), limit, NO_CHAIN)[0]


@njit(cache=True)
def gap_points(gx, gy, surf, patch, out):
    """The gap at the points (gx[k], gy[k]) into out[k] (1-D arrays), chained in their order (:func:`chain_point`:
    a grid's points row by row chain from their neighbours).
    """
    axes, mode, limit = chain_axes(surf, patch)
    chain = NO_CHAIN
    col = chain_column(0.0, surf, axes, mode)
    last_x = math.nan
    for k in range(gx.shape[0]):
        if gx[k] != last_x:
            col, last_x = chain_column(gx[k], surf, axes, mode), gx[k]
        out[k], chain = chain_point(gx[k], gy[k], surf, patch, axes, mode, col, limit, chain)


@njit(cache=True, _nrt=False)
def _rail_follows_rows(surf, patch):
    """Whether the rail's root is linear along a row, t(x) = t(x_0) + (x - x_0) dt/dx exactly: an ideal rail
    (extruded along x, no irregularity rows) and e_x's (y, z) part parallel to n's (e_x the main x projected on
    the contact plane, as compiled_patch and search._patch build it): moving the base along e_x moves it along the
    line b + t n in the (y, z) plane, where the rail's section lies.
    """
    ex, nn = patch.e_x, patch.normal
    return surf.rail_irr.shape[0] == 0 and abs(ex[1] * nn[2] - ex[2] * nn[1]) <= 1e-14


@njit(cache=True, _nrt=False, inline="always")
def _column(columns, i):
    return (
        columns[i, SERIES_COS], columns[i, SERIES_SIN], columns[i, SERIES_VALUE], columns[i, SERIES_SLOPE],
        columns[i, SERIES_CURVATURE],
    )  # fmt: skip


@njit(cache=True, _nrt=False, inline="always")
def _rooted_here(state, gx, gy):
    """Whether a chain state's wheel root is at (gx, gy) (else the chain kept an older root: none here)."""
    return state[CHAIN_WHEEL_X] == gx and state[CHAIN_WHEEL_Y] == gy


@njit(cache=True, _nrt=False, inline="always")
def grid_axes(box, xs, ys):
    """Fill xs, ys with the linspace of box = (x_lo, x_hi, y_lo, y_hi) at their lengths; (nx, ny)."""
    x_lo, x_hi, y_lo, y_hi = box
    nx, ny = xs.shape[0], ys.shape[0]
    for i in range(nx):
        xs[i] = x_lo + (x_hi - x_lo) * i / (nx - 1)
    for j in range(ny):
        ys[j] = y_lo + (y_hi - y_lo) * j / (ny - 1)
    return nx, ny


@njit(cache=True, _nrt=False)
def sample_grid(surf, patch, box, xs, ys, gap, columns):
    """The gap on the grid xs x ys (linspace of box = (x_lo, x_hi, y_lo, y_hi), filled here) into gap (ny, nx).

    Per row (a lateral strip): three anchors solved by :func:`chain_point` (first, middle and last column, each
    chained from the same column of the row before; the first row's from the patch centre); every other point's
    wheel root by Newton's method (to the step tolerance) from the quadratic through the anchors' s(x), its rail
    root from the middle anchor's moved by dt/dx (exact along a row on an ideal rail, :func:`_rail_follows_rows`;
    else Newton's method from there). The points of a row are independent of each other. A point whose start
    fails is solved by :func:`chain_point` from the middle anchor. columns (nx, COLUMN_SCRATCH):
    scratch (the wheel's column series, the row's roots). Every root is the exact solve's to the step tolerance.
    """
    nx, ny = grid_axes(box, xs, ys)
    axes, mode, limit = chain_axes(surf, patch)
    for i in range(nx):
        col = chain_column(xs[i], surf, axes, mode)
        for k in range(5):
            columns[i, k] = col[k]
        columns[i, COL_OFFSET] = 0.0
    linear_rail = _rail_follows_rows(surf, patch)
    centre = chain_point(0.0, 0.0, surf, patch, axes, mode, chain_column(0.0, surf, axes, mode), limit, NO_CHAIN)[1]
    first, middle, last = centre, centre, centre
    i0, i1, i2 = 0, nx // 2, nx - 1
    x0, x1, x2 = xs[i0], xs[i1], xs[i2]
    for j in range(ny):
        gy = ys[j]
        gap[j, i0], first = chain_point(x0, gy, surf, patch, axes, mode, _column(columns, i0), limit, first)
        gap[j, i1], middle = chain_point(x1, gy, surf, patch, axes, mode, _column(columns, i1), limit, middle)
        gap[j, i2], last = chain_point(x2, gy, surf, patch, axes, mode, _column(columns, i2), limit, last)
        wheel_ok = _rooted_here(first, x0, gy) and _rooted_here(middle, x1, gy) and _rooted_here(last, x2, gy)
        rail_ok = middle[CHAIN_RAIL_X] == x1 and middle[CHAIN_RAIL_Y] == gy
        s0, s1, s2 = first[CHAIN_S], middle[CHAIN_S], last[CHAIN_S]
        t1, t_x = middle[CHAIN_T], middle[CHAIN_T_X]
        if not (wheel_ok and rail_ok):
            for i in range(nx):
                columns[i, COL_OFFSET] = 0.0
        else:
            _polish_row(xs, gy, (x0, x1, x2), (s0, s1, s2), surf, axes, mode, limit, columns)
        for i in range(nx):
            if i == i0 or i == i1 or i == i2:
                continue
            gx = xs[i]
            done = False
            if wheel_ok and rail_ok and columns[i, COL_STEP] == 0.0:
                s = columns[i, COL_ROOT]
                t = t1 + t_x * (gx - x1)
                if linear_rail:
                    r_ok = True
                    if not abs(t) <= _FAR:
                        t = math.inf
                else:
                    b0, b1, b2 = _base(gx, gy, patch)
                    t, _, _, r_ok = _rail_root(b0, b1, b2, patch, surf, t)
                if r_ok:
                    gap[j, i] = s - t if math.isfinite(s) else math.inf
                    done = True
            if not done:
                gap[j, i] = chain_point(gx, gy, surf, patch, axes, mode, _column(columns, i), limit, middle)[0]


COL_ROOT, COL_STEP, COL_LATERAL, COL_OFFSET = 5, 6, 7, 8
"""Columns of sample_grid's scratch after the series (0-4): a row's wheel roots s, 0 where the root converged
(else 1), its y_d, and the root's offset from the anchors' quadratic (the next row's start adds it)."""
COLUMN_SCRATCH = 9
"""Columns of sample_grid's scratch."""
ROW_SWEEPS = 4
"""Newton sweeps over a row's points at most (they end when every step of a sweep is below STEP_TOLERANCE_M)."""


@njit(cache=True, _nrt=False)
def _polish_row(xs, gy, anchor_x, anchor_s, surf, axes, mode, limit, columns):
    """The wheel roots of a row into columns[:, COL_ROOT] (COL_STEP 0 where converged, else 1): Newton's steps
    of :func:`_wheel_root` at every point from Lagrange's quadratic through the anchors' (x, s), the points
    interleaved (independent: the processor overlaps their iterations), repeated up to ROW_SWEEPS times until
    every step is below STEP_TOLERANCE_M (a point converged when its last step is: s then exact to about
    c step^2); s +inf where y_d leaves the profile. The start adds to the quadratic the previous row's offset of
    its root from its quadratic (COL_OFFSET; 0 after a row not polished): it varies slowly across the rows.
    """
    x0, x1, x2 = anchor_x
    s0, s1, s2 = anchor_s
    d0, d1, d2 = s0 / ((x0 - x1) * (x0 - x2)), s1 / ((x1 - x0) * (x1 - x2)), s2 / ((x2 - x0) * (x2 - x1))
    pc, u, v, w = axes
    nx = xs.shape[0]
    for i in range(nx):
        gx = xs[i]
        quadratic = d0 * (gx - x1) * (gx - x2) + d1 * (gx - x0) * (gx - x2) + d2 * (gx - x0) * (gx - x1)
        columns[i, COL_ROOT] = quadratic + columns[i, COL_OFFSET]
        columns[i, COL_OFFSET] = quadratic
    c0, c1, c2 = pc[0] + gy * v[0], pc[1] + gy * v[1], pc[2] + gy * v[2]
    for _ in range(ROW_SWEEPS):
        worst = 0.0
        for i in range(nx):
            gx, s = xs[i], columns[i, COL_ROOT]
            p0, p1, p2 = c0 + gx * u[0] + s * w[0], c1 + gx * u[1] + s * w[1], c2 + gx * u[2] + s * w[2]
            rho = math.sqrt(p0 * p0 + p2 * p2)
            r, r_y, _ = _table(p1, *surf.wheel)
            irr, irr_a = _wheel_irr_at(p0, p2, rho, surf, mode, _column(columns, i), limit)
            g0 = (p0 + irr_a * p2 / rho) / rho
            g2 = (p2 - irr_a * p0 / rho) / rho
            step = (rho - r - irr) / (g0 * w[0] - r_y * w[1] + g2 * w[2])
            columns[i, COL_ROOT] = s - step
            columns[i, COL_STEP] = 0.0 if abs(step) < STEP_TOLERANCE_M else 1.0
            columns[i, COL_LATERAL] = p1 - step * w[1]
            if not abs(step) <= worst:
                worst = abs(step)
        if worst < STEP_TOLERANCE_M:
            break
    for i in range(nx):
        lat = columns[i, COL_LATERAL]
        offset = columns[i, COL_ROOT] - columns[i, COL_OFFSET]
        columns[i, COL_OFFSET] = offset if columns[i, COL_STEP] == 0.0 and math.isfinite(offset) else 0.0
        if not (lat >= surf.y_range[0] and lat <= surf.y_range[1]):
            columns[i, COL_ROOT] = math.inf


@njit(cache=True, _nrt=False)
def exact_grid(surf, patch, box, xs, ys, gap):
    """The gap on the grid of box by :func:`exact_gap` at every point (the reference of :func:`sample_grid`)."""
    nx, ny = grid_axes(box, xs, ys)
    for j in range(ny):
        for i in range(nx):
            gap[j, i] = exact_gap(xs[i], ys[j], surf, patch)


@njit(cache=True, _nrt=False)
def _overlap_extent(gap):
    """(first column, last column, first row, last row) of gap < 0 (finite: -inf where the normal misses the rail
    is not an overlap); first column -1 when none.
    """
    ny, nx = gap.shape
    c0, c1, r0, r1 = nx, -1, ny, -1
    for j in range(ny):
        for i in range(nx):
            if gap[j, i] < 0.0 and math.isfinite(gap[j, i]):
                c0, c1, r0, r1 = min(c0, i), max(c1, i), min(r0, j), max(r1, j)
    if c1 < 0:
        return -1, -1, -1, -1
    return c0, c1, r0, r1


@njit(cache=True, _nrt=False)
def fitted_grid(surf, patch, fit, xs, ys, gap, columns):
    """search._fitted_field in compiled code (module docstring): the gap on a box holding the rigid overlap with a
    margin into xs (nx,), ys (ny,), gap (ny, nx). Returns the number of grid samplings.
    """
    lim_x, lim_y = FIELD_LIMITS_M
    hx = min(max(fit.half_x, fit.min_half), lim_x)
    hy = min(max(fit.half_y, fit.min_half), lim_y)
    x_lo, x_hi, y_lo, y_hi = -hx, hx, -hy, hy
    sample_grid(surf, patch, (x_lo, x_hi, y_lo, y_hi), xs, ys, gap, columns)
    passes = 1
    nx, ny = xs.shape[0], ys.shape[0]
    for _ in range(4):
        c0, c1, r0, r1 = _overlap_extent(gap)
        if c0 < 0:
            return passes
        grown = False
        width = x_hi - x_lo
        if c0 == 0 and x_lo > -lim_x:
            x_lo, grown = max(x_lo - width, -lim_x), True
        if c1 == nx - 1 and x_hi < lim_x:
            x_hi, grown = min(x_hi + width, lim_x), True
        width = y_hi - y_lo
        if r0 == 0 and y_lo > -lim_y:
            y_lo, grown = max(y_lo - width, -lim_y), True
        if r1 == ny - 1 and y_hi < lim_y:
            y_hi, grown = min(y_hi + width, lim_y), True
        if not grown:
            break
        sample_grid(surf, patch, (x_lo, x_hi, y_lo, y_hi), xs, ys, gap, columns)
        passes += 1
    c0, c1, r0, r1 = _overlap_extent(gap)
    if c0 < 0:
        return passes
    fx0, fx1, fy0, fy1 = _shrunk_box(xs, ys, (c0, c1, r0, r1), fit.margin)
    if fx1 - fx0 < 0.8 * (x_hi - x_lo) or fy1 - fy0 < 0.8 * (y_hi - y_lo):
        sample_grid(surf, patch, (fx0, fx1, fy0, fy1), xs, ys, gap, columns)
        passes += 1
    return passes


@njit(cache=True, _nrt=False)
def _shrunk_box(xs, ys, extent, margin):
    """fitted_grid's last box: the overlap's extent (columns c0..c1, rows r0..r1 of the grid xs, ys) plus margin
    of it and two spacings each side, within the grid's box and _FIELD_LIMITS_M.
    """
    lim_x, lim_y = FIELD_LIMITS_M
    c0, c1, r0, r1 = extent
    nx, ny = xs.shape[0], ys.shape[0]
    x_lo, x_hi, y_lo, y_hi = xs[0], xs[nx - 1], ys[0], ys[ny - 1]
    sx = (x_hi - x_lo) / max(nx - 1, 1)
    lo, hi = xs[c0], xs[c1]
    pad = margin * (hi - lo) + 2 * sx
    fx0, fx1 = max(min(lo - pad, -sx), -lim_x, x_lo), min(max(hi + pad, sx), lim_x, x_hi)
    sy = (y_hi - y_lo) / max(ny - 1, 1)
    lo, hi = ys[r0], ys[r1]
    pad = margin * (hi - lo) + 2 * sy
    fy0, fy1 = max(min(lo - pad, -sy), -lim_y, y_lo), min(max(hi + pad, sy), lim_y, y_hi)
    return fx0, fx1, fy0, fy1


@njit(cache=True, _nrt=False)
def warm_grid(surf, patch, box, margin, xs, ys, gap, columns):
    """The gap on the given box (x_lo, x_hi, y_lo, y_hi; the last evaluation's) when it holds the overlap as
    fitted_grid's would: the overlap touches no side; when the box is then more than 20 % too large on a side, the
    gap on fitted_grid's last box (the overlap's extent plus margin, :func:`_shrunk_box`) of this sampling. Returns
    the number of samplings (1 or 2; xs, ys, gap hold the gap), or 0 when the box does not hold the overlap (call
    fitted_grid).
    """
    x_lo, x_hi, y_lo, y_hi = box[BOX_X_LO], box[BOX_X_HI], box[BOX_Y_LO], box[BOX_Y_HI]
    if not x_hi > x_lo:
        return 0
    sample_grid(surf, patch, (x_lo, x_hi, y_lo, y_hi), xs, ys, gap, columns)
    c0, c1, r0, r1 = _overlap_extent(gap)
    nx, ny = xs.shape[0], ys.shape[0]
    if c0 <= 0 or c1 >= nx - 1 or r0 <= 0 or r1 >= ny - 1:
        return 0
    fx0, fx1, fy0, fy1 = _shrunk_box(xs, ys, (c0, c1, r0, r1), margin)
    if fx1 - fx0 < 0.8 * (x_hi - x_lo) or fy1 - fy0 < 0.8 * (y_hi - y_lo):
        sample_grid(surf, patch, (fx0, fx1, fy0, fy1), xs, ys, gap, columns)
        return 2
    return 1


@njit(cache=True, _nrt=False)
def ellipticity_residual(xs, ys, gap, quadric, q):
    """search.ellipticity_error: max |g - g_q| / q over the points where the sampled or the quadric gap
    g_q = A x'^2 + B y'^2 - q (x', y' rotated by the ellipse angle; quadric = (A, B, angle)) is negative; inf when
    q <= 0 or no such point.
    """
    big_a, big_b, angle = quadric
    c, s = math.cos(angle), math.sin(angle)
    worst = -1.0
    for j in range(ys.shape[0]):
        for i in range(xs.shape[0]):
            g = gap[j, i]
            if not math.isfinite(g):
                continue
            xr, yr = c * xs[i] + s * ys[j], -s * xs[i] + c * ys[j]
            gq = big_a * xr * xr + big_b * yr * yr - q
            if min(g, gq) < 0.0:
                worst = max(worst, abs(g - gq))
    if q <= 0.0 or worst < 0.0:
        return math.inf
    return worst / q


@njit(cache=True, _nrt=False)
def curvature_change(xs, ys, gap, big_a, big_b):
    """auto._local_curvature_change on a sampled grid: (max - min) of d2g/dx2 / 2 over the overlap (g < 0, the
    centre point of the difference inside it), / A; the same along y, / B; the larger (0 where fewer than two
    differences are defined or A, B <= 0).
    """
    out = 0.0
    nx, ny = xs.shape[0], ys.shape[0]
    for axis in range(2):
        n = nx if axis == 0 else ny
        ref = big_a if axis == 0 else big_b
        if n < 3 or not ref > 0.0:
            continue
        d = (xs[1] - xs[0]) if axis == 0 else (ys[1] - ys[0])
        lo, hi, count = math.inf, -math.inf, 0
        for j in range(ny):
            for i in range(nx):
                g = gap[j, i]
                if not (math.isfinite(g) and g < 0.0):
                    continue
                if axis == 0:
                    if i == 0 or i == nx - 1:
                        continue
                    second = (gap[j, i + 1] - 2.0 * g + gap[j, i - 1]) / (2.0 * d * d)
                else:
                    if j == 0 or j == ny - 1:
                        continue
                    second = (gap[j + 1, i] - 2.0 * g + gap[j - 1, i]) / (2.0 * d * d)
                if math.isfinite(second):
                    lo, hi, count = min(lo, second), max(hi, second), count + 1
        if count >= 2:
            out = max(out, (hi - lo) / ref)
    return out


@njit(cache=True, _nrt=False)
def _overlap_row(gap, j):
    """Whether row j of a sampled grid has a point in overlap (finite g < 0)."""
    for i in range(gap.shape[1]):
        if math.isfinite(gap[j, i]) and gap[j, i] < 0.0:
            return True
    return False


@njit(cache=True, _nrt=False)
def _run_stop(gap, start):
    """The last row of the run of consecutive overlap rows that starts at row ``start``."""
    j = start
    while j + 1 < gap.shape[0] and _overlap_row(gap, j + 1):
        j += 1
    return j


@njit(cache=True, _nrt=False)
def second_patch_nearness(ys, gap):
    """auto._second_patch_nearness on a sampled grid: the lateral extent of the widest run of overlap rows over its
    clearance to the nearest other run (at least one spacing); 0 with one run.
    """
    ny = ys.shape[0]
    if ny < 2:
        return 0.0
    # pass 1: the widest run (the first of equal widths) and the number of runs
    runs, main_start, main_stop = 0, -1, -2
    j = 0
    while j < ny:
        if _overlap_row(gap, j):
            stop = _run_stop(gap, j)
            runs += 1
            if stop - j > main_stop - main_start:
                main_start, main_stop = j, stop
            j = stop
        j += 1
    if runs < 2:
        return 0.0
    # pass 2: the clearance to the nearest other run
    dy = ys[1] - ys[0]
    clearance = math.inf
    j = 0
    while j < ny:
        if _overlap_row(gap, j):
            stop = _run_stop(gap, j)
            if j != main_start:
                rows = j - main_stop - 1 if j > main_stop else main_start - stop - 1
                clearance = min(clearance, rows * dy)
            j = stop
        j += 1
    return (main_stop - main_start + 1) * dy / max(clearance, dy)


@njit(cache=True, _nrt=False)
def quadric_grid(quadric, q, box, xs, ys, gap):
    """The quadric gap A x'^2 + B y'^2 - q (quadric = (A, B, angle)) on the grid of box into xs, ys, gap."""
    big_a, big_b, angle = quadric
    c, s = math.cos(angle), math.sin(angle)
    nx, ny = grid_axes(box, xs, ys)
    for j in range(ny):
        for i in range(nx):
            xr, yr = c * xs[i] + s * ys[j], -s * xs[i] + c * ys[j]
            gap[j, i] = big_a * xr * xr + big_b * yr * yr - q
