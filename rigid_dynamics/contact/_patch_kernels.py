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
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rigid_dynamics.contact._search_kernels import _table, rail_irregularity, wheel_irregularity


@njit(cache=True)
def _wheel(alpha, y, rot, centre, wheel, wheel_irr, out):
    """Fill out[0:3] point, [3:6] t_a, [6:9] t_y, [9:12] x_aa, [12:15] x_ay, [15:18] x_yy (main frame); return R."""
    r, r_y, r_yy = _table(y, wheel[0], wheel[1], wheel[2], wheel[3], wheel[4])
    v, r_a, r_aa = wheel_irregularity(alpha, wheel_irr)
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
            out[3 * k + i] = rot[i, 0] * a + rot[i, 1] * b + rot[i, 2] * c
    for i in range(3):
        out[i] += centre[i]
    return r


@njit(cache=True)
def _rail(x, y, rail, rail_irr, rail_map, rail_range):
    """(N, N_x, N_y) at main-frame (x, y), y clipped to the rail's range."""
    yc = min(max(y, rail_range[0]), rail_range[1])
    n, n_y, _ = _table(yc, rail[0], rail[1], rail[2], rail[3], rail[4])
    if rail_irr.shape[0] > 0:
        v, vx, vy, _, _, _ = rail_irregularity(x, yc, rail_irr, rail_map[0], rail_map[1])
        return n + v, vx, n_y + vy
    return n, 0.0, n_y


@njit(cache=True)
def contact_locus(lats, alpha_start, rot, centre, wheel, wheel_irr, rail, rail_irr, rail_map, rail_range, right,
                  iterations, alpha, point, gap, rail_z, angle):  # fmt: skip
    """Fill alpha, point (n, 3), gap, rail_z, angle for the wheel parameters ``lats`` (see the module docstring)."""
    w = np.empty(18)
    a = alpha_start
    for k in range(lats.shape[0]):
        y = lats[k]
        if not math.isfinite(a) or abs(a - alpha_start) > 0.2:
            a = alpha_start
        for _ in range(iterations):  # from the neighbour's angle: one or two steps suffice
            _wheel(a, y, rot, centre, wheel, wheel_irr, w)
            f = w[5] * w[7] - w[8] * w[4]
            df = w[11] * w[7] + w[5] * w[13] - w[14] * w[4] - w[8] * w[10]
            if not abs(df) > 1e-12:
                break
            step = min(max(f / df, -0.05), 0.05)
            a -= step
            if abs(step) < 1e-13:
                break
        _wheel(a, y, rot, centre, wheel, wheel_irr, w)
        alpha[k] = a
        point[k, 0], point[k, 1], point[k, 2] = w[0], w[1], w[2]
        if not (w[1] >= rail_range[0] and w[1] <= rail_range[1]) or not math.isfinite(w[2]):
            gap[k], rail_z[k], angle[k] = math.inf, math.nan, math.nan
            continue
        n, n_x, n_y = _rail(w[0], w[1], rail, rail_irr, rail_map, rail_range)
        if not math.isfinite(n):
            gap[k], rail_z[k], angle[k] = math.inf, math.nan, math.nan
            continue
        gap[k] = n - w[2]
        rail_z[k] = n
        norm = math.sqrt(n_x * n_x + n_y * n_y + 1.0)
        tilt = -n_y / norm if right else n_y / norm
        angle[k] = math.atan2(tilt, 1.0 / norm)


@njit(cache=True)
def plane_gap(xs, ys, origin, frame, loc_y, loc_lat, loc_alpha, loc_x, rot, centre, wheel, wheel_irr, rail, rail_irr,
              rail_map, rail_range, y_range, iterations, gap, alpha_out, lat_out):  # fmt: skip
    """Fill gap, alpha_out, lat_out at the plane points (xs[k], ys[k]) (see the module docstring); loc_* is the
    locus sorted by its main-frame y (start values).
    """
    w = np.empty(18)
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
            big_n, n_x, n_y = _rail(px, py, rail, rail_irr, rail_map, rail_range)
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
        lat = np.interp(b1, loc_y, loc_lat)
        a = np.interp(b1, loc_y, loc_alpha)
        r = _wheel(a, lat, rot, centre, wheel, wheel_irr, w)
        a += (b0 - np.interp(b1, loc_y, loc_x)) / r
        _wheel(a, lat, rot, centre, wheel, wheel_irr, w)
        s = n0 * (w[0] - b0) + n1 * (w[1] - b1) + n2 * (w[2] - b2)
        converged = False
        for _ in range(iterations):
            _wheel(a, lat, rot, centre, wheel, wheel_irr, w)
            f0, f1, f2 = w[0] - b0 - s * n0, w[1] - b1 - s * n1, w[2] - b2 - s * n2
            if math.sqrt(f0 * f0 + f1 * f1 + f2 * f2) < 1e-12:
                converged = True
                break
            # J = [t_a, t_y, -n] (columns); solve J d = -f by Cramer's rule
            a0, a1, a2 = w[3], w[4], w[5]
            c0, c1, c2 = w[6], w[7], w[8]
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
            _wheel(a, lat, rot, centre, wheel, wheel_irr, w)
            f0, f1, f2 = w[0] - b0 - s * n0, w[1] - b1 - s * n1, w[2] - b2 - s * n2
            converged = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2) < 1e-10
        if converged and lat >= y_range[0] and lat <= y_range[1]:
            gap[k], alpha_out[k], lat_out[k] = s - t, a, lat
        else:
            gap[k], alpha_out[k], lat_out[k] = math.inf, math.nan, math.nan
