"""Compiled (numba) kernels of wheelset_patches: the contact locus and the plane gap on tabulated surfaces.

The same mathematics as wheelset_patches.contact_locus / plane_gap on search.py's surfaces (ideal profiles as
lateral Hermite tables, irregularities of the rolling angle and rail corrugation in closed form, from
_search_kernels): wheel point x_w = C_D x_d + x_t, x_d = [R cos a, y, R sin a], R = R_id(y) + R_irr(a), with
t_a, t_y and the second derivatives (R_ay = 0: the irregularities depend on the angle alone).

* locus: for each y_d, Newton on f(a) = t_a,z t_y,y - t_y,z t_a,y = 0 (z stationary along the surface curve of
  constant track y), then the vertical gap N(x, y) - z and the rail's contact angle there;
* plane gap: from p = o + x e_x + y e_y, Newton for t with (p + t n)_z = N((p + t n)_x, (p + t n)_y) (rail), and
  Newton in (a, y_d, s) for x_w(a, y_d) = p + s n (wheel; 3 x 3 by Cramer's rule); gap = s - t, +inf where
  either does not converge or leaves a surface.

One side's surfaces come as the record _search_kernels.Surfaces; a kernel's outputs as the records :class:`Locus`,
:class:`OverlapLine` and :class:`PlaneGap` (caller-given arrays, filled here). The wheel point and its derivatives
sit in an (18,) scratch vector at the offsets W_POINT, W_T_ALPHA, W_T_Y, W_X_AA, W_X_AY, W_X_YY (x, y, z each).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact._search_kernels import (
    CHORD_FLAT,
    CORRUGATION_AMPLITUDE,
    CORRUGATION_TAPER,
    CORRUGATION_WAVENUMBER,
    FLAT_DEPTH,
    FLAT_LENGTH,
    FLAT_RADIUS,
    IRR_CODE,
    POLYGON,
    POLYGON_AMPLITUDE,
    POLYGON_ORDER,
    _table,
    rail_irregularity,
    wheel_irregularity,
)

W_POINT, W_T_ALPHA, W_T_Y, W_X_AA, W_X_AY, W_X_YY = range(0, 18, 3)
"""Offsets in the wheel scratch vector (W_LEN,) of :func:`_wheel`: the point, the tangents t_a, t_y and the second
derivatives x_aa, x_ay, x_yy (main frame; x, y, z at offset + 0, 1, 2)."""
W_LEN = 18


class Locus(NamedTuple):
    """A locus kernel's outputs for n wheel parameters y_d: the wheel angle alpha (n,) rad, the wheel point
    (n, 3) m (main frame), the vertical gap (n,) m, the rail height there (n,) m and the rail's contact angle (n,)
    rad.
    """

    alpha: np.ndarray
    point: np.ndarray
    gap: np.ndarray
    rail_z: np.ndarray
    angle: np.ndarray


class OverlapLine(NamedTuple):
    """:func:`out_of_round_locus`'s integrals per y_d: weight (n,) m^3, weighted_x (n,) m, overlap_x (n, 2) m."""

    weight: np.ndarray
    weighted_x: np.ndarray
    overlap_x: np.ndarray


class SortedLocus(NamedTuple):
    """The locus sorted by its main-frame y: y (n,), the wheel's y_d (n,), alpha (n,) and the point's x (n,) (the
    starts of :func:`plane_gap`).
    """

    y: np.ndarray
    lateral: np.ndarray
    alpha: np.ndarray
    x: np.ndarray


class FastScan(NamedTuple):
    """:func:`out_of_round_locus`'s settings: the coarse scan's stride (every stride-th angle first) and whether the
    minimum is found by Newton's steps on dg/da (else the reference's golden section).
    """

    coarse_stride: int
    newton: bool


class PlaneGap(NamedTuple):
    """:func:`plane_gap`'s outputs per plane point: gap (k,) m, the wheel parameters alpha (k,) rad, y_d (k,) m."""

    gap: np.ndarray
    alpha: np.ndarray
    lateral: np.ndarray


@njit(cache=True)
def _wheel(alpha, y, rot, centre, surf, out):
    """Fill out (W_LEN,) at W_POINT the point, W_T_ALPHA t_a, W_T_Y t_y, W_X_AA x_aa, W_X_AY x_ay, W_X_YY x_yy (main
    frame); return R.
    """
    r, r_y, r_yy = _table(y, *surf.wheel)
    v, r_a, r_aa = wheel_irregularity(alpha, surf.wheel_irr)
    r += v
    ca, sa = math.cos(alpha), math.sin(alpha)
    loc = (
        (r * ca, y, r * sa),
        (r_a * ca - r * sa, 0.0, r_a * sa + r * ca),
        (r_y * ca, 1.0, r_y * sa),
        (r_aa * ca - 2.0 * r_a * sa - r * ca, 0.0, r_aa * sa + 2.0 * r_a * ca - r * sa),
        (-r_y * sa, 0.0, r_y * ca),
        (r_yy * ca, 0.0, r_yy * sa),
    )
    for k in range(6):
        a, b, c = loc[k]
        for i in range(3):
            out[W_POINT + 3 * k + i] = rot[i, 0] * a + rot[i, 1] * b + rot[i, 2] * c
    for i in range(3):
        out[W_POINT + i] += centre[i]
    return r


@njit(cache=True, inline="always")
def _wheel_tangents(alpha, y, rot, centre, surf, out):
    """:func:`_wheel`'s point and tangents t_a, t_y alone (out[W_POINT:W_X_AA], the same arithmetic); return R."""
    r, r_y, _ = _table(y, *surf.wheel)
    v, r_a, _ = wheel_irregularity(alpha, surf.wheel_irr)
    r += v
    ca, sa = math.cos(alpha), math.sin(alpha)
    loc = (
        (r * ca, y, r * sa),
        (r_a * ca - r * sa, 0.0, r_a * sa + r * ca),
        (r_y * ca, 1.0, r_y * sa),
    )
    for k in range(3):
        a, b, c = loc[k]
        for i in range(3):
            out[W_POINT + 3 * k + i] = rot[i, 0] * a + rot[i, 1] * b + rot[i, 2] * c
    for i in range(3):
        out[W_POINT + i] += centre[i]
    return r


@njit(cache=True, inline="always")
def _rail(x, y, surf):
    """(N, N_x, N_y) at main-frame (x, y), y clipped to the rail's range."""
    yc = min(max(y, surf.rail_range[0]), surf.rail_range[1])
    n, n_y, _ = _table(yc, *surf.rail)
    if surf.rail_irr.shape[0] > 0:
        v, vx, vy, _, _, _ = rail_irregularity(x, yc, surf.rail_irr, surf.rail_map[0], surf.rail_map[1])
        return n + v, vx, n_y + vy
    return n, 0.0, n_y


@njit(cache=True)
def contact_locus(lats, alpha_start, rot, centre, surf, right, iterations, out):
    """Fill the :class:`Locus` ``out`` for the wheel parameters ``lats`` (see the module docstring) of the wheelset
    pose (C_D ``rot``, ``centre``) on the surfaces ``surf`` (_search_kernels.Surfaces) of the left or the ``right``
    side, Newton from alpha_start.
    """
    alpha, point, gap, rail_z, angle = out
    rail_range = surf.rail_range
    w = np.empty(W_LEN)
    a = alpha_start
    for k in range(lats.shape[0]):
        y = lats[k]
        if not math.isfinite(a) or abs(a - alpha_start) > 0.2:
            a = alpha_start
        for _ in range(iterations):  # from the neighbour's angle: one or two steps suffice
            _wheel(a, y, rot, centre, surf, w)
            # f = t_a,z t_y,y - t_y,z t_a,y and its derivative along alpha
            ta_y, ta_z, ty_y, ty_z = w[W_T_ALPHA + 1], w[W_T_ALPHA + 2], w[W_T_Y + 1], w[W_T_Y + 2]
            f = ta_z * ty_y - ty_z * ta_y
            df = w[W_X_AA + 2] * ty_y + ta_z * w[W_X_AY + 1] - w[W_X_AY + 2] * ta_y - ty_z * w[W_X_AA + 1]
            if not abs(df) > 1e-12:
                break
            step = min(max(f / df, -0.05), 0.05)
            a -= step
            if abs(step) < 1e-13:
                break
        _wheel(a, y, rot, centre, surf, w)
        alpha[k] = a
        point[k, 0], point[k, 1], point[k, 2] = w[0], w[1], w[2]
        if not (w[1] >= rail_range[0] and w[1] <= rail_range[1]) or not math.isfinite(w[2]):
            gap[k], rail_z[k], angle[k] = math.inf, math.nan, math.nan
            continue
        n, n_x, n_y = _rail(w[0], w[1], surf)
        if not math.isfinite(n):
            gap[k], rail_z[k], angle[k] = math.inf, math.nan, math.nan
            continue
        gap[k] = n - w[2]
        rail_z[k] = n
        norm = math.sqrt(n_x * n_x + n_y * n_y + 1.0)
        tilt = -n_y / norm if right else n_y / norm
        angle[k] = math.atan2(tilt, 1.0 / norm)


@njit(cache=True, inline="always")
def _interp(x, xp, fp, j):
    """np.interp(x, xp, fp) with numba's arithmetic (a facsimile of numpy's arr_interp), given j =
    searchsorted(xp, x, "right") - 1: one search for the three start values of :func:`plane_gap`, no allocation.
    """
    n = xp.shape[0]
    if math.isnan(x):
        return x
    if j < 0:
        return fp[0]
    if j >= n - 1:
        return fp[n - 1]
    if xp[j] == x:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    value = slope * (x - xp[j]) + fp[j]
    if math.isnan(value):
        value = slope * (x - xp[j + 1]) + fp[j + 1]
        if math.isnan(value) and fp[j] == fp[j + 1]:
            value = fp[j]
    return value


@njit(cache=True)
def plane_gap(xs, ys, origin, frame, starts, rot, centre, surf, iterations, out):
    """Fill the :class:`PlaneGap` ``out`` at the plane points (xs[k], ys[k]) of the plane (origin, frame: columns
    e_x, e_y, n) (see the module docstring); ``starts``: the :class:`SortedLocus` (start values).
    """
    loc_y, loc_lat, loc_alpha, loc_x = starts
    gap, alpha_out, lat_out = out
    rail_range, y_range = surf.rail_range, surf.y_range
    w = np.empty(W_LEN)
    ex0, ex1, ex2 = frame[0, 0], frame[1, 0], frame[2, 0]
    ey0, ey1, ey2 = frame[0, 1], frame[1, 1], frame[2, 1]
    n0, n1, n2 = frame[0, 2], frame[1, 2], frame[2, 2]
    for k in range(xs.shape[0]):
        b0 = origin[0] + xs[k] * ex0 + ys[k] * ey0
        b1 = origin[1] + xs[k] * ex1 + ys[k] * ey1
        b2 = origin[2] + xs[k] * ex2 + ys[k] * ey2
        # rail along n
        t = 0.0
        ok = False
        for _ in range(iterations + 4):
            px, py, pz = b0 + t * n0, b1 + t * n1, b2 + t * n2
            big_n, n_x, n_y = _rail(px, py, surf)
            f = pz - big_n
            slope = n2 - n_x * n0 - n_y * n1
            if abs(slope) < 1e-3:
                slope = math.copysign(1e-3, slope)
            step = f / slope
            t -= step
            if abs(step) < 1e-14:
                ok = True
                break
        py = b1 + t * n1
        if not ok or not (py >= rail_range[0] and py <= rail_range[1]) or not math.isfinite(t):
            gap[k], alpha_out[k], lat_out[k] = math.inf, math.nan, math.nan
            continue
        # wheel: start at the locus point of the same track y
        j = np.searchsorted(loc_y, b1, side="right") - 1
        lat = _interp(b1, loc_y, loc_lat, j)
        a = _interp(b1, loc_y, loc_alpha, j)
        r = _wheel_tangents(a, lat, rot, centre, surf, w)
        a += (b0 - _interp(b1, loc_y, loc_x, j)) / r
        _wheel_tangents(a, lat, rot, centre, surf, w)
        s = n0 * (w[0] - b0) + n1 * (w[1] - b1) + n2 * (w[2] - b2)
        converged = False
        for it in range(iterations):
            if it > 0:  # the first iteration's point is the one just evaluated
                _wheel_tangents(a, lat, rot, centre, surf, w)
            f0, f1, f2 = w[0] - b0 - s * n0, w[1] - b1 - s * n1, w[2] - b2 - s * n2
            if math.sqrt(f0 * f0 + f1 * f1 + f2 * f2) < 1e-12:
                converged = True
                break
            # J = [t_a, t_y, -n] (columns); solve J d = -f by Cramer's rule
            a0, a1, a2 = w[W_T_ALPHA], w[W_T_ALPHA + 1], w[W_T_ALPHA + 2]
            c0, c1, c2 = w[W_T_Y], w[W_T_Y + 1], w[W_T_Y + 2]
            m0, m1, m2 = -n0, -n1, -n2
            det = a0 * (c1 * m2 - c2 * m1) - c0 * (a1 * m2 - a2 * m1) + m0 * (a1 * c2 - a2 * c1)
            if det == 0.0 or not math.isfinite(det):
                break
            r0, r1, r2 = -f0, -f1, -f2
            da = (r0 * (c1 * m2 - c2 * m1) - c0 * (r1 * m2 - r2 * m1) + m0 * (r1 * c2 - r2 * c1)) / det
            dl = (a0 * (r1 * m2 - r2 * m1) - r0 * (a1 * m2 - a2 * m1) + m0 * (a1 * r2 - a2 * r1)) / det
            ds = (a0 * (c1 * r2 - c2 * r1) - c0 * (a1 * r2 - a2 * r1) + r0 * (a1 * c2 - a2 * c1)) / det
            a, lat, s = a + da, lat + dl, s + ds
        if not converged:
            _wheel_tangents(a, lat, rot, centre, surf, w)
            f0, f1, f2 = w[0] - b0 - s * n0, w[1] - b1 - s * n1, w[2] - b2 - s * n2
            converged = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2) < 1e-10
        if converged and lat >= y_range[0] and lat <= y_range[1]:
            gap[k], alpha_out[k], lat_out[k] = s - t, a, lat
        else:
            gap[k], alpha_out[k], lat_out[k] = math.inf, math.nan, math.nan


@njit(cache=True, inline="always")
def _point_gap(ca, sa, r, y, rot, centre, surf, p):
    """Vertical gap N(x, y) - z of the wheel point of radius r at (cos a, sin a) = (ca, sa) and y_d = y (filled into
    p (3,)); +inf off the rail. The point's arithmetic is :func:`_wheel`'s, operation for operation.
    """
    a, b, c = r * ca, y, r * sa
    for i in range(3):
        p[i] = rot[i, 0] * a + rot[i, 1] * b + rot[i, 2] * c
    for i in range(3):
        p[i] += centre[i]
    if not (p[1] >= surf.rail_range[0] and p[1] <= surf.rail_range[1]) or not math.isfinite(p[2]):
        return math.inf
    n, _, _ = _rail(p[0], p[1], surf)
    if not math.isfinite(n):
        return math.inf
    return n - p[2]


@njit(cache=True, inline="always")
def _angle_gap(a, y, r_id, rot, centre, surf, p):
    """:func:`_point_gap` at the angle a with R = r_id + R_irr(a) (as :func:`_wheel` sums it)."""
    v, _, _ = wheel_irregularity(a, surf.wheel_irr)
    return _point_gap(math.cos(a), math.sin(a), r_id + v, y, rot, centre, surf, p)


@njit(cache=True)
def _hermite_bounds(table):
    """(max |f|, max |f'|, max |f''|) of a lateral Hermite table (lower, step, values, slopes x step, curvatures)
    over its whole range: |f'| <= (|m0| + 2 |A| + 3 |B|) / step and |f''| = |2 A + 6 B t| / step^2 (linear in t)
    per cell, f = v0 + t (m0 + t (A + t B)).
    """
    _, step, value, slope, _ = table
    f0, f1, f2 = 0.0, 0.0, 0.0
    for i in range(value.shape[0] - 1):
        v0, v1, m0, m1 = value[i], value[i + 1], slope[i], slope[i + 1]
        a = 3.0 * (v1 - v0) - 2.0 * m0 - m1
        b = 2.0 * (v0 - v1) + m0 + m1
        f0 = max(f0, abs(v0), abs(v1))
        f1 = max(f1, (abs(m0) + 2.0 * abs(a) + 3.0 * abs(b)) / step)
        f2 = max(f2, max(abs(2.0 * a), abs(2.0 * a + 6.0 * b)) / (step * step))
    return f0, f1, f2


@njit(cache=True)
def gap_curvature_bound(rot, surf):
    """An upper bound of |d^2 g / d alpha^2| of the vertical gap g(alpha) = N(x, y) - z of the wheel points of
    constant y_d (any y_d on the wheel's table), +inf when the wheel has a chord flat (a kink of R: no bound).

    With X = [R cos a, y_d, R sin a], |X'| <= R + |R_a| = X1, |X''| <= R + 2 |R_a| + |R_aa| = X2, the main-frame
    point P = C_D X + x_t has |P_x^(k)|, |P_z^(k)| <= Xk and |P_y^(k)| <= s Xk, s = |C_D[1, 0]| + |C_D[1, 2]|, so
    g'' = N_x P_x'' + N_y P_y'' - P_z'' + N_xx P_x'^2 + 2 N_xy P_x' P_y' + N_yy P_y'^2 is bounded by the maxima
    of the wheel's and the rail's tables (:func:`_hermite_bounds`) and of the irregularity rows (polygon:
    |R_a| <= A n, |R_aa| <= A n^2; rounded flat: d/2 w r_w, d/2 (w r_w)^2, w = 2 pi / L; corrugation: |N_x| <= A k,
    |N_xx| <= A k^2, and its lateral band |w'| <= 1.875 / t, |w''| <= 5.78 / t^2).
    """
    r_max = _hermite_bounds(surf.wheel)[0]
    r_a, r_aa = 0.0, 0.0
    irr = surf.wheel_irr
    for k in range(irr.shape[0]):
        code = irr[k, IRR_CODE]
        if code == POLYGON:
            amp, n = abs(irr[k, POLYGON_AMPLITUDE]), abs(irr[k, POLYGON_ORDER])
            r_max += amp
            r_a += amp * n
            r_aa += amp * n * n
        elif code == CHORD_FLAT:
            return math.inf
        else:  # ROUNDED_FLAT
            depth = abs(irr[k, FLAT_DEPTH])
            wave = 2.0 * math.pi / irr[k, FLAT_LENGTH] * abs(irr[k, FLAT_RADIUS])
            r_max += depth
            r_a += 0.5 * depth * wave
            r_aa += 0.5 * depth * wave * wave
    _, n_y, n_yy = _hermite_bounds(surf.rail)
    n_x, n_xx, n_xy = 0.0, 0.0, 0.0
    for k in range(surf.rail_irr.shape[0]):
        amp, wave = abs(surf.rail_irr[k, CORRUGATION_AMPLITUDE]), abs(surf.rail_irr[k, CORRUGATION_WAVENUMBER])
        taper = abs(surf.rail_irr[k, CORRUGATION_TAPER])
        n_x += amp * wave
        n_xx += amp * wave * wave
        n_y += amp * 1.875 / taper
        n_xy += amp * wave * 1.875 / taper
        n_yy += amp * 5.78 / (taper * taper)
    x1, x2 = r_max + r_a, r_max + 2.0 * r_a + r_aa
    s = abs(rot[1, 0]) + abs(rot[1, 2])
    return n_x * x2 + n_y * s * x2 + x2 + n_xx * x1 * x1 + 2.0 * n_xy * x1 * s * x1 + n_yy * (s * x1) ** 2


@njit(cache=True, inline="always")
def _gap_slope(a, y, rot, centre, surf, w):
    """(g, dg/da, d2g/da2) of the vertical gap g = N(x, y) - z of the wheel point (a, y_d) (filled into w); (+inf,
    nan, nan) off the rail. g is :func:`_vertical_gap`'s; the second derivative takes the rail table's tabulated
    curvature (linear between nodes) for the cubic's (a quasi-Newton step).
    """
    _wheel(a, y, rot, centre, surf, w)
    if not (w[1] >= surf.rail_range[0] and w[1] <= surf.rail_range[1]) or not math.isfinite(w[2]):
        return math.inf, math.nan, math.nan
    n, n_y, n_yy = _table(w[1], *surf.rail)
    n_x, n_xx, n_xy = 0.0, 0.0, 0.0
    if surf.rail_irr.shape[0] > 0:
        v, vx, vy, vxx, vxy, vyy = rail_irregularity(w[0], w[1], surf.rail_irr, surf.rail_map[0], surf.rail_map[1])
        n, n_x, n_y, n_xx, n_xy, n_yy = n + v, vx, n_y + vy, vxx, vxy, n_yy + vyy
    if not math.isfinite(n):
        return math.inf, math.nan, math.nan
    px, py, pz = w[W_T_ALPHA], w[W_T_ALPHA + 1], w[W_T_ALPHA + 2]
    slope = n_x * px + n_y * py - pz
    curvature = n_x * w[W_X_AA] + n_y * w[W_X_AA + 1] - w[W_X_AA + 2]
    curvature += n_xx * px * px + 2.0 * n_xy * px * py + n_yy * py * py
    return n - w[2], slope, curvature


@njit(cache=True)
def _newton_minimum(a, lo, hi, y, rot, centre, surf, w):
    """The angle in [lo, hi] where dg/da = 0 with d2g/da2 > 0, Newton's steps from a; nan when a step leaves [lo, hi],
    meets d2g/da2 <= 0 or has not fallen below 1e-13 rad in 12 steps.
    """
    for _ in range(12):
        _, slope, curvature = _gap_slope(a, y, rot, centre, surf, w)
        if not curvature > 0.0:
            return math.nan
        step = slope / curvature
        a -= step
        if not (a >= lo and a <= hi):
            return math.nan
        if abs(step) < 1e-13:
            return a
    return math.nan


@njit(cache=True)
def out_of_round_locus(lats, alpha_start, half_window, scan_points, integration_points, fast, rot, centre, surf, right,
                       out, line):  # fmt: skip
    """Contact locus of an out-of-round wheel: the results of the full scan (tests/oor_reference.py, the scan of
    every angle with the whole wheel point and golden-section refinement) for less.

    * Each gap with the reference's arithmetic, evaluated for less: the point alone (no tangents or second
      derivatives; the helpers inlined), the ideal radius R_id(y_d) once per y_d (a surface of revolution plus a
      radial irregularity of the angle alone), the scan angles' cosines, sines and R_irr once per call.
    ``fast`` (:class:`FastScan`): the coarse scan's stride and whether the minimum is found by Newton's steps.

    * The scan at every ``coarse_stride``-th angle (and the last), then at every angle of an interval only where the
      gap may dip below the smallest found or below 0: by at most :func:`gap_curvature_bound` (stride step)^2 / 8
      under its lower end (every angle of an interval with an end off the rail). The smallest scanned gap and the
      first and last negative one are the full scan's.
    * ``newton``: the minimum by Newton's steps on dg/da (:func:`_newton_minimum`) from the previous y_d's angle, the
      golden section where they fail; the reference's golden section stops at its rounding (its last steps compare
      gaps closer than their round-off, about 2e-8 rad). Without ``newton`` every output is the reference's to the
      last bit; with it the gap agrees to 1e-15 m, the angle to 1e-7 rad (tests/test_oor_locus_fast.py).
    """
    alpha, point, gap, rail_z, angle = out
    weight, weighted_x, overlap_x = line
    p = np.empty(3)
    w = np.empty(W_LEN)
    a_prev = math.nan
    golden = 0.5 * (math.sqrt(5.0) - 1.0)
    step = 2.0 * half_window / (scan_points - 1)
    g_scan = np.empty(scan_points)
    scan_cos, scan_sin, scan_irr = np.empty(scan_points), np.empty(scan_points), np.empty(scan_points)
    for i in range(scan_points):
        a = alpha_start - half_window + i * step
        scan_cos[i], scan_sin[i] = math.cos(a), math.sin(a)
        scan_irr[i] = wheel_irregularity(a, surf.wheel_irr)[0]
    # the scan at every stride-th angle (and the last), then every angle of the intervals where the gap may dip
    # below the smallest found or below 0: by at most curvature * (stride * step)^2 / 8 under the lower end
    coarse_stride, newton = fast
    stride = max(int(coarse_stride), 1)
    dip = gap_curvature_bound(rot, surf) * (stride * step) ** 2 / 8.0 * (1.0 + 1e-9) + 1e-15
    if not math.isfinite(dip):
        stride = 1
    nodes = np.empty((scan_points - 1) // stride + 2, np.int64)
    n_nodes = 0
    for i in range(0, scan_points, stride):
        nodes[n_nodes] = i
        n_nodes += 1
    if nodes[n_nodes - 1] != scan_points - 1:
        nodes[n_nodes] = scan_points - 1
        n_nodes += 1
    for k in range(lats.shape[0]):
        y = lats[k]
        r_id = _table(y, *surf.wheel)[0]
        best = math.inf
        for j in range(n_nodes):
            i = nodes[j]
            g = _point_gap(scan_cos[i], scan_sin[i], r_id + scan_irr[i], y, rot, centre, surf, p)
            g_scan[i] = g
            best = min(best, g)
        for j in range(n_nodes - 1):
            i0, i1 = nodes[j], nodes[j + 1]
            low = min(g_scan[i0], g_scan[i1])
            if math.isfinite(g_scan[i0]) and math.isfinite(g_scan[i1]) and low - dip > best and low - dip > 0.0:
                for i in range(i0 + 1, i1):
                    g_scan[i] = math.inf  # above the smallest gap and above 0 (not evaluated)
                continue
            for i in range(i0 + 1, i1):
                g = _point_gap(scan_cos[i], scan_sin[i], r_id + scan_irr[i], y, rot, centre, surf, p)
                g_scan[i] = g
                best = min(best, g)
        best, kbest = math.inf, -1
        first, last = -1, -1
        for i in range(scan_points):
            g = g_scan[i]
            if g < best:
                best, kbest = g, i
            if g < 0.0:
                if first < 0:
                    first = i
                last = i
        if kbest < 0:
            _angle_gap(alpha_start, y, r_id, rot, centre, surf, p)
            alpha[k] = alpha_start
            point[k, 0], point[k, 1], point[k, 2] = p[0], p[1], p[2]
            gap[k], rail_z[k], angle[k] = math.inf, math.nan, math.nan
            weight[k], weighted_x[k] = 0.0, math.nan
            overlap_x[k, 0], overlap_x[k, 1] = math.nan, math.nan
            continue
        # the minimum on [a_best - step, a_best + step]: Newton on dg/da from the previous y_d's (or the scan's)
        # angle, the golden section where Newton fails
        lo = alpha_start - half_window + max(kbest - 1, 0) * step
        hi = alpha_start - half_window + min(kbest + 1, scan_points - 1) * step
        a_min = math.nan
        if newton:
            start = a_prev if a_prev >= lo and a_prev <= hi else alpha_start - half_window + kbest * step
            a_min = _newton_minimum(start, lo, hi, y, rot, centre, surf, w)
        if not math.isfinite(a_min):
            c1 = hi - golden * (hi - lo)
            c2 = lo + golden * (hi - lo)
            g1 = _angle_gap(c1, y, r_id, rot, centre, surf, p)
            g2 = _angle_gap(c2, y, r_id, rot, centre, surf, p)
            for _ in range(30):
                if g1 <= g2:
                    hi, c2, g2 = c2, c1, g1
                    c1 = hi - golden * (hi - lo)
                    g1 = _angle_gap(c1, y, r_id, rot, centre, surf, p)
                else:
                    lo, c1, g1 = c1, c2, g2
                    c2 = lo + golden * (hi - lo)
                    g2 = _angle_gap(c2, y, r_id, rot, centre, surf, p)
            a_min = 0.5 * (lo + hi)
        g_min = _angle_gap(a_min, y, r_id, rot, centre, surf, p)
        if g_scan[kbest] < g_min:
            a_min = alpha_start - half_window + kbest * step
            g_min = _angle_gap(a_min, y, r_id, rot, centre, surf, p)
        alpha[k] = a_min
        a_prev = a_min
        point[k, 0], point[k, 1], point[k, 2] = p[0], p[1], p[2]
        gap[k] = g_min
        if math.isfinite(g_min):
            n, n_x, n_y = _rail(p[0], p[1], surf)
            rail_z[k] = n
            norm = math.sqrt(n_x * n_x + n_y * n_y + 1.0)
            tilt = -n_y / norm if right else n_y / norm
            angle[k] = math.atan2(tilt, 1.0 / norm)
        else:
            rail_z[k], angle[k] = math.nan, math.nan
        weight[k], weighted_x[k] = 0.0, math.nan
        overlap_x[k, 0], overlap_x[k, 1] = math.nan, math.nan
        if not g_min < 0.0:
            continue
        # the squared interpenetration along the wheel's surface curve of this y_d
        a_lo, a_hi = a_min - step, a_min + step
        if first >= 0:
            a_lo = min(a_lo, alpha_start - half_window + (first - 1) * step)
            a_hi = max(a_hi, alpha_start - half_window + (last + 1) * step)
        h = (a_hi - a_lo) / (integration_points - 1)
        total, moment = 0.0, 0.0
        x_prev, c_prev, g_prev = math.nan, 0.0, math.nan
        x_lo, x_hi = math.inf, -math.inf
        for i in range(integration_points):
            g = _angle_gap(a_lo + i * h, y, r_id, rot, centre, surf, p)
            c = -g if g < 0.0 else 0.0
            x = p[0]
            if c > 0.0:
                x_lo, x_hi = min(x_lo, x), max(x_hi, x)
            if i > 0:
                dx = abs(x - x_prev)
                total += 0.5 * (c * c + c_prev * c_prev) * dx
                moment += 0.5 * (x * c * c + x_prev * c_prev * c_prev) * dx
                if math.isfinite(g) and math.isfinite(g_prev) and (g < 0.0) != (g_prev < 0.0):
                    xc = x_prev + g_prev / (g_prev - g) * (x - x_prev)  # the zero crossing, linearly
                    x_lo, x_hi = min(x_lo, xc), max(x_hi, xc)
            x_prev, c_prev, g_prev = x, c, g
        weight[k] = total
        weighted_x[k] = moment / total if total > 0.0 else point[k, 0]
        if x_lo <= x_hi:
            overlap_x[k, 0], overlap_x[k, 1] = x_lo, x_hi
        else:
            overlap_x[k, 0], overlap_x[k, 1] = point[k, 0], point[k, 0]
