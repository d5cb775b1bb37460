"""Compiled (numba) sampler of a patch's undeformed distance on the tabulated surfaces: the one sampling code of the
static wheelset case (search._gap_at on TabulatedWheel/TabulatedRail) and the dynamics loop (compiled_rhs).

The mathematics of search._gap_at: at a contact-plane point (x, y) of a patch with centre c and frame
(e_x, e_y, n) (n from the rail into the wheel), base b = c + x e_x + y e_y,

* rail: t with (b + t n)_z = N((b + t n)_x, (b + t n)_y) by Newton's method (f'(t) = n_z - N_x n_x - N_y n_y,
  the slope floored at 1e-3 as search._SideGeometry._distance_along; +inf off the rail, beyond 0.05 m or with a
  vertical residual above 1e-10 m);
* wheel: x_w(alpha, y_d) = b + s n by Newton's method on (alpha, y_d, s) (eq 7-9: x_w = C_D [R cos a, y_d,
  R sin a] + x_t, tangents t_a, t_y), started at alpha0 + x / R(alpha0, y0) and y0 + y (e_y . C_D e_2);
* gap s - t (negative where the undeformed bodies overlap), +inf where y_d leaves the wheel profile.

Surfaces: the record :class:`GapSurfaces` (_search_kernels.Surfaces: Hermite tables of the ideal profiles and
closed-form irregularity rows, the one record of a side's surfaces in every compiled contact kernel). Patch:
:class:`GapPatch` (pose, patch point and frame as float triples, the wheel parameters of the contact point, Newton
iterations). The grid kernels fill caller-given arrays (no allocation: they run in the loop
without NRT).

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

from rigid_dynamics.contact._search_kernels import Surfaces, _table, rail_irregularity, wheel_irregularity

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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
def _wheel(alpha, y_d, surf):
    """R, R_a, R_y of the wheel at (alpha, y_d) (nan off the profile)."""
    r, r_y, _ = _table(y_d, *surf.wheel)
    v, r_a, _ = wheel_irregularity(alpha, surf.wheel_irr)
    return r + v, r_a, r_y


@njit(cache=True, _nrt=False)
def _mul(rot, v0, v1, v2, i):
    return rot[i, 0] * v0 + rot[i, 1] * v1 + rot[i, 2] * v2


@njit(cache=True, _nrt=False)
def gap_point(gx, gy, surf, patch):
    """The gap along n at the contact-plane point (gx, gy) of ``patch``, m (module docstring)."""
    return _gap_solve(gx, gy, surf, patch, (math.nan, 0.0, 0.0, 0.0))[0]


@njit(cache=True, _nrt=False)
def _gap_solve(gx, gy, surf, patch, start):
    """(gap, alpha, y_d, s, t) at (gx, gy): Newton's iterations from start = (alpha, y_d, s, t) of a nearby point
    (alpha NaN: from the patch's parameters, module docstring). The roots are the same; a near start saves
    iterations.
    """
    ex, ey, nn = patch.e_x, patch.e_y, patch.normal
    c = patch.point
    b0 = c[0] + gx * ex[0] + gy * ey[0]
    b1 = c[1] + gx * ex[1] + gy * ey[1]
    b2 = c[2] + gx * ex[2] + gy * ey[2]
    rot, ctr = patch.rot, patch.centre
    radius = _wheel(patch.alpha0, patch.y0, surf)[0]
    alpha, lat, s, t_start = start
    if math.isnan(alpha):
        t_rail = _rail_distance(b0, b1, b2, patch, surf, 0.0)
        alpha = patch.alpha0 + gx / radius
        lat = patch.y0 + gy * (ey[0] * rot[0, 1] + ey[1] * rot[1, 1] + ey[2] * rot[2, 1])
        s = 0.0
    else:
        t_rail = _rail_distance(b0, b1, b2, patch, surf, t_start)
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
        return math.inf, alpha, lat, s, t_rail
    return s - t_rail, alpha, lat, s, t_rail


@njit(cache=True)
def gap_points(gx, gy, surf, patch, out):
    """gap_point at the points (gx[k], gy[k]) into out[k] (1-D arrays)."""
    for k in range(gx.shape[0]):
        out[k] = gap_point(gx[k], gy[k], surf, patch)


@njit(cache=True, _nrt=False)
def sample_grid(surf, patch, box, xs, ys, gap):
    """The gap on the grid xs x ys (linspace of box = (x_lo, x_hi, y_lo, y_hi), filled here) into gap (ny, nx)."""
    x_lo, x_hi, y_lo, y_hi = box
    nx, ny = xs.shape[0], ys.shape[0]
    for i in range(nx):
        xs[i] = x_lo + (x_hi - x_lo) * i / (nx - 1)
    for j in range(ny):
        ys[j] = y_lo + (y_hi - y_lo) * j / (ny - 1)
    for j in range(ny):
        # along the row each point starts from its neighbour's roots (alpha shifted by the step over the radius)
        start = (math.nan, 0.0, 0.0, 0.0)
        for i in range(nx):
            g, alpha, lat, s, t = _gap_solve(xs[i], ys[j], surf, patch, start)
            gap[j, i] = g
            if math.isfinite(g) and math.isfinite(alpha) and math.isfinite(t):
                step = (xs[i + 1] - xs[i]) if i + 1 < nx else 0.0
                start = (alpha + step / _wheel(alpha, lat, surf)[0], lat, s, t)
            else:
                start = (math.nan, 0.0, 0.0, 0.0)


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
def fitted_grid(surf, patch, fit, xs, ys, gap):
    """search._fitted_field in compiled code (module docstring): the gap on a box holding the rigid overlap with a
    margin into xs (nx,), ys (ny,), gap (ny, nx). Returns the number of grid samplings.
    """
    lim_x, lim_y = FIELD_LIMITS_M
    hx = min(max(fit.half_x, fit.min_half), lim_x)
    hy = min(max(fit.half_y, fit.min_half), lim_y)
    x_lo, x_hi, y_lo, y_hi = -hx, hx, -hy, hy
    sample_grid(surf, patch, (x_lo, x_hi, y_lo, y_hi), xs, ys, gap)
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
        sample_grid(surf, patch, (x_lo, x_hi, y_lo, y_hi), xs, ys, gap)
        passes += 1
    c0, c1, r0, r1 = _overlap_extent(gap)
    if c0 < 0:
        return passes
    fx0, fx1, fy0, fy1 = _shrunk_box(xs, ys, (c0, c1, r0, r1), fit.margin)
    if fx1 - fx0 < 0.8 * (x_hi - x_lo) or fy1 - fy0 < 0.8 * (y_hi - y_lo):
        sample_grid(surf, patch, (fx0, fx1, fy0, fy1), xs, ys, gap)
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
def warm_grid(surf, patch, box, margin, xs, ys, gap):
    """The gap on the given box (x_lo, x_hi, y_lo, y_hi; the last evaluation's) when it still fits the overlap as
    fitted_grid's would: the overlap touches no side and the shrunk box keeps at least 80 % of each side. Returns
    True when it fits (then xs, ys, gap hold it), else False (call fitted_grid).
    """
    x_lo, x_hi, y_lo, y_hi = box[BOX_X_LO], box[BOX_X_HI], box[BOX_Y_LO], box[BOX_Y_HI]
    if not x_hi > x_lo:
        return False
    sample_grid(surf, patch, (x_lo, x_hi, y_lo, y_hi), xs, ys, gap)
    c0, c1, r0, r1 = _overlap_extent(gap)
    nx, ny = xs.shape[0], ys.shape[0]
    if c0 <= 0 or c1 >= nx - 1 or r0 <= 0 or r1 >= ny - 1:
        return False
    fx0, fx1, fy0, fy1 = _shrunk_box(xs, ys, (c0, c1, r0, r1), margin)
    return not (fx1 - fx0 < 0.8 * (x_hi - x_lo) or fy1 - fy0 < 0.8 * (y_hi - y_lo))


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
def quadric_grid(quadric, q, box, xs, ys, gap):
    """The quadric gap A x'^2 + B y'^2 - q (quadric = (A, B, angle)) on the grid of box into xs, ys, gap."""
    big_a, big_b, angle = quadric
    c, s = math.cos(angle), math.sin(angle)
    x_lo, x_hi, y_lo, y_hi = box
    nx, ny = xs.shape[0], ys.shape[0]
    for i in range(nx):
        xs[i] = x_lo + (x_hi - x_lo) * i / (nx - 1)
    for j in range(ny):
        ys[j] = y_lo + (y_hi - y_lo) * j / (ny - 1)
    for j in range(ny):
        for i in range(nx):
            xr, yr = c * xs[i] + s * ys[j], -s * xs[i] + c * ys[j]
            gap[j, i] = big_a * xr * xr + big_b * yr * yr - q
