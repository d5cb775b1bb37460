"""The full-scan reference of rigid_dynamics.contact._patch_kernels.out_of_round_locus (tests/test_oor_locus_fast.py
and benchmarks/bench_oor_patches.py compare the fast kernel with it): every angle of the window scanned with the whole
wheel point and its derivatives (_patch_kernels._wheel), the minimum refined by 30 golden-section steps, the squared
interpenetration integrated on ``integration_points`` points. The kernel the production code ran before the fast one
(c67f299), kept here for the comparison only.
"""

import math

import numpy as np
from numba import njit

from rigid_dynamics.contact._patch_kernels import W_LEN, _rail, _wheel


@njit(cache=True)
def _vertical_gap(a, y, rot, centre, surf, w):
    """Vertical gap N(x, y) - z of the wheel point (a, y_d) (filled into w); +inf off the rail."""
    _wheel(a, y, rot, centre, surf, w)
    if not (w[1] >= surf.rail_range[0] and w[1] <= surf.rail_range[1]) or not math.isfinite(w[2]):
        return math.inf
    n, _, _ = _rail(w[0], w[1], surf)
    if not math.isfinite(n):
        return math.inf
    return n - w[2]


@njit(cache=True)
def out_of_round_locus_reference(lats, alpha_start, half_window, scan_points, integration_points, rot, centre, surf,
                                 right, out, line):  # fmt: skip
    """The reference of :func:`out_of_round_locus` (the tests' and benchmarks/bench_oor_patches.py's): the same
    results computed with the whole wheel point and its derivatives (:func:`_wheel`) at every angle.

    Contact locus of an out-of-round wheel: for each y_d the wheel angle of the smallest vertical gap, found by
    a scan of ``scan_points`` angles over alpha_start +- half_window and golden-section refinement (no assumption
    of one stationary point: a flat has two lowest points along x and a hump between), and the squared
    interpenetration integrated along the wheel's surface curve of that y_d:

        weight[k] = int c^2 dx,  weighted_x[k] = int x c^2 dx / weight[k],  c = max(-g, 0),

    by the trapezoidal rule on ``integration_points`` points over the overlap found by the scan (widened by one
    scan step on each side); overlap_x[k] = the x range where g < 0, its ends interpolated linearly between the
    integration points (nan, nan without interpenetration).
    Fills the :class:`Locus` ``out`` like :func:`contact_locus` and the :class:`OverlapLine` ``line`` (weight,
    weighted_x, overlap_x).
    """
    alpha, point, gap, rail_z, angle = out
    weight, weighted_x, overlap_x = line
    w = np.empty(W_LEN)
    golden = 0.5 * (math.sqrt(5.0) - 1.0)
    step = 2.0 * half_window / (scan_points - 1)
    g_scan = np.empty(scan_points)
    for k in range(lats.shape[0]):
        y = lats[k]
        best, kbest = math.inf, -1
        first, last = -1, -1
        for i in range(scan_points):
            a = alpha_start - half_window + i * step
            g = _vertical_gap(a, y, rot, centre, surf, w)
            g_scan[i] = g
            if g < best:
                best, kbest = g, i
            if g < 0.0:
                if first < 0:
                    first = i
                last = i
        if kbest < 0:
            _wheel(alpha_start, y, rot, centre, surf, w)
            alpha[k] = alpha_start
            point[k, 0], point[k, 1], point[k, 2] = w[0], w[1], w[2]
            gap[k], rail_z[k], angle[k] = math.inf, math.nan, math.nan
            weight[k], weighted_x[k] = 0.0, math.nan
            overlap_x[k, 0], overlap_x[k, 1] = math.nan, math.nan
            continue
        # golden section on [a_best - step, a_best + step]
        lo = alpha_start - half_window + max(kbest - 1, 0) * step
        hi = alpha_start - half_window + min(kbest + 1, scan_points - 1) * step
        c1 = hi - golden * (hi - lo)
        c2 = lo + golden * (hi - lo)
        g1 = _vertical_gap(c1, y, rot, centre, surf, w)
        g2 = _vertical_gap(c2, y, rot, centre, surf, w)
        for _ in range(30):
            if g1 <= g2:
                hi, c2, g2 = c2, c1, g1
                c1 = hi - golden * (hi - lo)
                g1 = _vertical_gap(c1, y, rot, centre, surf, w)
            else:
                lo, c1, g1 = c1, c2, g2
                c2 = lo + golden * (hi - lo)
                g2 = _vertical_gap(c2, y, rot, centre, surf, w)
        a_min = 0.5 * (lo + hi)
        g_min = _vertical_gap(a_min, y, rot, centre, surf, w)
        if g_scan[kbest] < g_min:
            a_min = alpha_start - half_window + kbest * step
            g_min = _vertical_gap(a_min, y, rot, centre, surf, w)
        alpha[k] = a_min
        point[k, 0], point[k, 1], point[k, 2] = w[0], w[1], w[2]
        gap[k] = g_min
        if math.isfinite(g_min):
            n, n_x, n_y = _rail(w[0], w[1], surf)
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
            g = _vertical_gap(a_lo + i * h, y, rot, centre, surf, w)
            c = -g if g < 0.0 else 0.0
            x = w[0]
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
