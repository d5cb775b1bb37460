"""Compiled (numba) kernels of the contact search: ideal surfaces as lateral Hermite tables plus closed-form
irregularities.

Same mathematics as search.py (eq 7-11): wheel point x_w = C_D x_d + x_t with x_d = [R cos a, y, R sin a],
tangents t_a = [R_a cos a - R sin a, 0, R_a sin a + R cos a], t_y = [R_y cos a, 1, R_y sin a] (eq 9), outward
normal n_w = t_y x t_a / |.|, distance h along n_w to the rail z = N(x, y) by Newton's method
(f'(h) = n_z - N_x n_x - N_y n_y), and a damped Newton minimisation of h(a, y) with central-difference
derivatives. Tables: (lower, step, values, slopes * step, curvatures) as built by search._LateralTable.

Surfaces (eq 5-6): R(a, y_d) = R_id(y_d) + R_irr(a) and N(x, y) = N_id(y) + N_irr(x, y_r), y_r = s y - e_r.
The irregularities are rows of a (k, 7) float array, evaluated in closed form (the same formulas as
rigid_dynamics.geometry.irregularities; an empty array is the ideal surface):

* wheel, code 0, harmonic out-of-roundness: [0, n, A, phi, -, -, -]: R_irr = A cos(n a + phi);
* wheel, code 1, rounded flat: [1, a0, r_w, L, d, -, -]: s = r_w wrap(a - a0),
  R_irr = -(d/2)(1 + cos(2 pi s / L)) for |s| <= L/2;
* wheel, code 2, new (chord) flat: [2, a0, r_w, d, theta/2, -, -]: R_irr = (r_w - d)/cos(a - a0) - r_w for
  |wrap(a - a0)| <= theta/2;
* rail, code 0, corrugation: [0, k = 2 pi / lambda, A, phi, y_c, b, t]: N_irr = A cos(k x + phi) w(y_r), w the
  C2 lateral band (1 - quintic smooth step of (|y_r - y_c| - b) / t).

The columns of a row are named below (IRR_CODE, then the code's parameters: POLYGON_*, FLAT_*, CHORD_*,
CORRUGATION_*). One side's surfaces travel as the record :class:`Surfaces` (the tables, the irregularity rows, the
rail's lateral map and both lateral ranges), the same record for every compiled contact kernel (the search here,
_patch_kernels, _gap_kernels).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

_FAR = 0.05  # |h| beyond this (m) is not a contact candidate (another branch of the rail, or far away)
_ROOT_RESIDUAL = 1.0e-15  # m: a vertical residual this small ends Newton's iterations on h (round-off ~1e-16 m)

# --- the columns of an irregularity row (module docstring) ---------------------------------------------------------
IRR_CODE = 0
"""The row's code: wheel POLYGON, ROUNDED_FLAT, CHORD_FLAT; rail CORRUGATION (its only code)."""
POLYGON, ROUNDED_FLAT, CHORD_FLAT = range(3)
CORRUGATION = 0
POLYGON_ORDER, POLYGON_AMPLITUDE, POLYGON_PHASE = range(1, 4)
"""Harmonic out-of-roundness: order n, amplitude A (m), phase phi (rad)."""
FLAT_ANGLE, FLAT_RADIUS, FLAT_LENGTH, FLAT_DEPTH = range(1, 5)
"""Rounded flat: centre angle a0 (rad), wheel radius r_w, length L and depth d (m)."""
CHORD_ANGLE, CHORD_RADIUS, CHORD_DEPTH, CHORD_HALF_ANGLE = range(1, 5)
"""New (chord) flat: centre angle a0 (rad), wheel radius r_w and depth d (m), half angle theta/2 (rad)."""
(
    CORRUGATION_WAVENUMBER, CORRUGATION_AMPLITUDE, CORRUGATION_PHASE, CORRUGATION_CENTRE, CORRUGATION_HALF_WIDTH,
    CORRUGATION_TAPER,
) = range(1, 7)  # fmt: skip
"""Rail corrugation: k = 2 pi / lambda (1/m), amplitude A (m), phase phi (rad), band centre y_c, half width b and
taper t of the lateral band (m, rail frame)."""
IRR_COLUMNS = 7


class Surfaces(NamedTuple):
    """One side's tabulated surfaces, as every compiled contact kernel takes them: the ``wheel`` and ``rail`` tables
    (lower, step, values, slopes x step, curvatures; search._LateralTable), the irregularity rows (k, IRR_COLUMNS)
    of each (module docstring; (0, IRR_COLUMNS): ideal), the rail's lateral map (sign, offset: y_r = sign y -
    offset), and the wheel's (y_d) and the rail's (main-frame y) lateral ranges (2,), m.
    """

    wheel: tuple
    rail: tuple
    wheel_irr: np.ndarray
    rail_irr: np.ndarray
    rail_map: np.ndarray
    y_range: np.ndarray
    rail_range: np.ndarray


@njit(cache=True, _nrt=False)
def _table(y, lower, step, value, slope, curvature):
    u = (y - lower) / step
    n = value.shape[0]
    if not (u >= 0.0 and u <= n - 1):
        return math.nan, math.nan, math.nan
    i = int(math.floor(u))
    if i > n - 2:
        i = n - 2
    t = u - i
    v0, v1, m0, m1 = value[i], value[i + 1], slope[i], slope[i + 1]
    val = v0 + t * (m0 + t * (3.0 * (v1 - v0) - 2.0 * m0 - m1 + t * (2.0 * (v0 - v1) + m0 + m1)))
    der = (m0 + t * (6.0 * (v1 - v0) - 4.0 * m0 - 2.0 * m1) + t * t * (6.0 * (v0 - v1) + 3.0 * m0 + 3.0 * m1)) / step
    cur = curvature[i] * (1.0 - t) + curvature[i + 1] * t
    return val, der, cur


@njit(cache=True, _nrt=False)
def _wrap_pi(angle):
    """Angle wrapped to [-pi, pi) (Python's float modulo, as numpy's)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True, _nrt=False)
def wheel_irregularity(alpha, irr):
    """(R_irr, dR_irr/da, d2R_irr/da2) of the rows of ``irr`` at the angle alpha (module docstring)."""
    v, va, vaa = 0.0, 0.0, 0.0
    for k in range(irr.shape[0]):
        code = irr[k, IRR_CODE]
        if code == POLYGON:
            n, amp = irr[k, POLYGON_ORDER], irr[k, POLYGON_AMPLITUDE]
            arg = n * alpha + irr[k, POLYGON_PHASE]
            c = amp * math.cos(arg)
            v += c
            va -= amp * n * math.sin(arg)
            vaa -= n * n * c
        elif code == ROUNDED_FLAT:
            da = _wrap_pi(alpha - irr[k, FLAT_ANGLE])
            r_w, length, depth = irr[k, FLAT_RADIUS], irr[k, FLAT_LENGTH], irr[k, FLAT_DEPTH]
            s = r_w * da
            if abs(s) <= 0.5 * length:
                wave = 2.0 * math.pi / length
                v -= 0.5 * depth * (1.0 + math.cos(wave * s))
                va += 0.5 * depth * wave * r_w * math.sin(wave * s)
                vaa += 0.5 * depth * (wave * r_w) ** 2 * math.cos(wave * s)
        else:  # CHORD_FLAT
            da = _wrap_pi(alpha - irr[k, CHORD_ANGLE])
            r_w, depth, half = irr[k, CHORD_RADIUS], irr[k, CHORD_DEPTH], irr[k, CHORD_HALF_ANGLE]
            if abs(da) <= half:
                f = (r_w - depth) / math.cos(da)
                t = math.tan(da)
                v += f - r_w
                va += f * t
                vaa += f * (1.0 + 2.0 * t * t)
    return v, va, vaa


@njit(cache=True, _nrt=False)
def rail_irregularity(x, y, irr, sign, offset):
    """(N_irr, N_x, N_y, N_xx, N_xy, N_yy) of the rows of ``irr`` at main-frame (x, y); y_r = sign y - offset."""
    v, vx, vy, vxx, vxy, vyy = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    y_r = sign * y - offset
    for k in range(irr.shape[0]):
        wave, amp, phase = irr[k, CORRUGATION_WAVENUMBER], irr[k, CORRUGATION_AMPLITUDE], irr[k, CORRUGATION_PHASE]
        y_c, half, taper = irr[k, CORRUGATION_CENTRE], irr[k, CORRUGATION_HALF_WIDTH], irr[k, CORRUGATION_TAPER]
        u = y_r - y_c
        xi = (abs(u) - half) / taper
        if xi <= 0.0:
            w, dw, d2w = 1.0, 0.0, 0.0
        elif xi >= 1.0:
            continue
        else:
            w = 1.0 - xi**3 * (10.0 - 15.0 * xi + 6.0 * xi * xi)
            dw = -(1.0 if u >= 0 else -1.0) * 30.0 * xi * xi * (1.0 - xi) ** 2 / taper
            d2w = -60.0 * xi * (1.0 - xi) * (1.0 - 2.0 * xi) / (taper * taper)
        c, s = math.cos(wave * x + phase), math.sin(wave * x + phase)
        v += amp * c * w
        vx -= amp * wave * s * w
        vy += sign * amp * c * dw
        vxx -= amp * wave * wave * c * w
        vxy -= sign * amp * wave * s * dw
        vyy += amp * c * d2w
    return v, vx, vy, vxx, vxy, vyy


@njit(cache=True, _nrt=False)
def _checked_root(h, py, pz, surf, rail_irr_value):
    """Return h after Newton's iterations on the rail, or +inf: outside the rail, beyond _FAR, or not converged (the
    normal leaves the rail before meeting it: residual above 1e-10 m).
    """
    if not (py >= surf.rail_range[0] and py <= surf.rail_range[1]) or not math.isfinite(h) or abs(h) > _FAR:
        return math.inf
    big_n = _table(py, *surf.rail)[0] + rail_irr_value
    if not abs(pz - big_n) < 1e-10:
        return math.inf
    return h


@njit(cache=True, _nrt=False)
def _distance_ideal(alpha, y, rot, centre, surf, iterations, h_start=0.0):
    """h(alpha, y) on ideal surfaces (no irregularity rows): the irregular kernel's arithmetic with R_a = N_x = 0."""
    if y < surf.y_range[0] or y > surf.y_range[1]:
        return math.inf
    rail, rail_range = surf.rail, surf.rail_range
    r, r_y, _ = _table(y, *surf.wheel)
    if not math.isfinite(r):
        return math.inf
    ca, sa = math.cos(alpha), math.sin(alpha)
    xd0, xd1, xd2 = r * ca, y, r * sa
    ta0, ta2 = -r * sa, r * ca  # R_a = 0 for an ideal wheel
    ty0, ty1, ty2 = r_y * ca, 1.0, r_y * sa
    p1 = rot[1, 0] * xd0 + rot[1, 1] * xd1 + rot[1, 2] * xd2 + centre[1]
    p2 = rot[2, 0] * xd0 + rot[2, 1] * xd1 + rot[2, 2] * xd2 + centre[2]
    a0 = rot[0, 0] * ta0 + rot[0, 2] * ta2
    a1 = rot[1, 0] * ta0 + rot[1, 2] * ta2
    a2 = rot[2, 0] * ta0 + rot[2, 2] * ta2
    b0 = rot[0, 0] * ty0 + rot[0, 1] * ty1 + rot[0, 2] * ty2
    b1 = rot[1, 0] * ty0 + rot[1, 1] * ty1 + rot[1, 2] * ty2
    b2 = rot[2, 0] * ty0 + rot[2, 1] * ty1 + rot[2, 2] * ty2
    n0 = b1 * a2 - b2 * a1  # t_y x t_a: outward
    n1 = b2 * a0 - b0 * a2
    n2 = b0 * a1 - b1 * a0
    norm = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    n0, n1, n2 = n0 / norm, n1 / norm, n2 / norm
    h = h_start
    for _ in range(iterations):
        py = p1 + h * n1
        inside = py >= rail_range[0] and py <= rail_range[1]
        if py < rail_range[0]:
            py = rail_range[0]
        elif py > rail_range[1]:
            py = rail_range[1]
        big_n, n_y, _ = _table(py, *rail)
        f = p2 + h * n2 - big_n
        if inside and abs(f) < _ROOT_RESIDUAL:  # h exact to round-off already
            return h if abs(h) <= _FAR else math.inf
        slope = n2 - n_y * n1
        if abs(slope) < 1e-3:
            slope = math.copysign(1e-3, slope)
        step = f / slope
        h -= step
        if abs(step) < 1e-13:
            break
    return _checked_root(h, p1 + h * n1, p2 + h * n2, surf, 0.0)


@njit(cache=True, _nrt=False)
def _distance_irregular(alpha, y, rot, centre, surf, iterations, h_start=0.0):
    """h(alpha, y) for one wheel point; +inf outside the surfaces or beyond _FAR. Newton's method on h starts
    from h_start (a nearby point's h saves iterations; the converged root is the same).
    """
    if y < surf.y_range[0] or y > surf.y_range[1]:
        return math.inf
    rail, rail_range, rail_irr, rail_map = surf.rail, surf.rail_range, surf.rail_irr, surf.rail_map
    r, r_y, _ = _table(y, *surf.wheel)
    if not math.isfinite(r):
        return math.inf
    v, r_a, _ = wheel_irregularity(alpha, surf.wheel_irr)
    r += v
    ca, sa = math.cos(alpha), math.sin(alpha)
    xd0, xd1, xd2 = r * ca, y, r * sa
    ta0, ta2 = r_a * ca - r * sa, r_a * sa + r * ca
    ty0, ty1, ty2 = r_y * ca, 1.0, r_y * sa
    p0 = rot[0, 0] * xd0 + rot[0, 1] * xd1 + rot[0, 2] * xd2 + centre[0]
    p1 = rot[1, 0] * xd0 + rot[1, 1] * xd1 + rot[1, 2] * xd2 + centre[1]
    p2 = rot[2, 0] * xd0 + rot[2, 1] * xd1 + rot[2, 2] * xd2 + centre[2]
    a0 = rot[0, 0] * ta0 + rot[0, 2] * ta2
    a1 = rot[1, 0] * ta0 + rot[1, 2] * ta2
    a2 = rot[2, 0] * ta0 + rot[2, 2] * ta2
    b0 = rot[0, 0] * ty0 + rot[0, 1] * ty1 + rot[0, 2] * ty2
    b1 = rot[1, 0] * ty0 + rot[1, 1] * ty1 + rot[1, 2] * ty2
    b2 = rot[2, 0] * ty0 + rot[2, 1] * ty1 + rot[2, 2] * ty2
    n0 = b1 * a2 - b2 * a1  # t_y x t_a: outward
    n1 = b2 * a0 - b0 * a2
    n2 = b0 * a1 - b1 * a0
    norm = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    n0, n1, n2 = n0 / norm, n1 / norm, n2 / norm
    h = h_start
    for _ in range(iterations):
        py = p1 + h * n1
        inside = py >= rail_range[0] and py <= rail_range[1]
        if py < rail_range[0]:
            py = rail_range[0]
        elif py > rail_range[1]:
            py = rail_range[1]
        big_n, n_y, _ = _table(py, *rail)
        v, n_x, vy, _, _, _ = rail_irregularity(p0 + h * n0, py, rail_irr, rail_map[0], rail_map[1])
        big_n, n_y = big_n + v, n_y + vy
        f = p2 + h * n2 - big_n
        if inside and abs(f) < _ROOT_RESIDUAL:  # h exact to round-off already
            return h if abs(h) <= _FAR else math.inf
        slope = n2 - n_x * n0 - n_y * n1
        if abs(slope) < 1e-3:
            slope = math.copysign(1e-3, slope)
        step = f / slope
        h -= step
        if abs(step) < 1e-13:
            break
    x = p0 + h * n0
    py = p1 + h * n1
    return _checked_root(
        h,
        py,
        p2 + h * n2,
        surf,
        rail_irregularity(x, py, rail_irr, rail_map[0], rail_map[1])[0] if rail_irr.shape[0] > 0 else 0.0,
    )


@njit(cache=True, _nrt=False)
def _ideal(surf):
    """Whether the surfaces have no irregularity rows (the ideal kernel serves them)."""
    return surf.wheel_irr.shape[0] == 0 and surf.rail_irr.shape[0] == 0


@njit(cache=True, _nrt=False)
def distance(alpha, y, rot, centre, surf, iterations, h_start=0.0):
    """h(alpha, y) of the wheelset pose (C_D ``rot`` (3, 3), ``centre`` (3,), m) on the :class:`Surfaces` ``surf``
    with ``iterations`` Newton steps on h: the ideal kernel when there are no irregularity rows, else the irregular
    one.
    """
    if _ideal(surf):
        return _distance_ideal(alpha, y, rot, centre, surf, iterations, h_start)
    return _distance_irregular(alpha, y, rot, centre, surf, iterations, h_start)


@njit(cache=True)
def distance_grid(alphas, ys, rot, centre, surf, iterations):
    """H on the grid alphas x ys, shape (len(alphas), len(ys)) (:func:`distance`)."""
    out = np.empty((alphas.shape[0], ys.shape[0]))
    ideal = _ideal(surf)
    for i in range(alphas.shape[0]):
        for j in range(ys.shape[0]):
            if ideal:
                out[i, j] = _distance_ideal(alphas[i], ys[j], rot, centre, surf, iterations)
            else:
                out[i, j] = _distance_irregular(alphas[i], ys[j], rot, centre, surf, iterations)
    return out


@njit(cache=True)
def distance_points(alphas, ys, rot, centre, surf, iterations):
    """H at the points (alphas[k], ys[k]) (:func:`distance`)."""
    out = np.empty(alphas.shape[0])
    ideal = _ideal(surf)
    for k in range(alphas.shape[0]):
        if ideal:
            out[k] = _distance_ideal(alphas[k], ys[k], rot, centre, surf, iterations)
        else:
            out[k] = _distance_irregular(alphas[k], ys[k], rot, centre, surf, iterations)
    return out


@njit(cache=True, _nrt=False)
def _finite_distance(a, y, args, h_start):
    """distance(a, y, *args, h_start), with 1 m standing for +inf (outside the surfaces) in the difference
    quotients.
    """
    v = distance(a, y, *args, h_start)
    return v if math.isfinite(v) else 1.0


_DESCENT_FIRST_M = 5.0e-5  # first trial length of a descent step (five difference steps)
_DESCENT_MAX_M = 3.0e-3  # longest step (the Newton step's limit)
_DESCENT_MIN_M = 1.0e-9  # shortest trial before giving up (below the refinement tolerances' scale)


@njit(cache=True, _nrt=False)
def _along(a, y, u_a, u_y, length, args, hs, y_range):
    """The distance h at ``length`` along the unit direction (u_a per m of arc length, u_y) from (a, y)."""
    return _finite_distance(a + u_a * length, min(max(y + u_y * length, y_range[0]), y_range[1]), args, hs)


@njit(cache=True, _nrt=False)
def _descent_length(a, y, g_a, g_y, h0, args, hs, radius, y_range):
    """Length (m of arc length) of a step from (a, y) along -grad h where h is not convex: the first trial
    (_DESCENT_FIRST_M) is doubled while h keeps decreasing (up to _DESCENT_MAX_M: the step stops near the first
    minimum along the line, not beyond a rise into another region), or halved until h decreases by the Armijo
    fraction 1e-4 of the slope. 0 when no trial decreases h (a stationary point to the differences' resolution).
    """
    g_norm = math.sqrt(g_a * g_a + g_y * g_y)
    if not (g_norm > 0.0 and math.isfinite(g_norm)):
        return 0.0
    u_a, u_y = -g_a / g_norm / radius, -g_y / g_norm
    length = _DESCENT_FIRST_M
    h_l = _along(a, y, u_a, u_y, length, args, hs, y_range)
    if h_l < h0 - 1.0e-4 * g_norm * length:
        while 2.0 * length <= _DESCENT_MAX_M:
            h_2 = _along(a, y, u_a, u_y, 2.0 * length, args, hs, y_range)
            if not h_2 < h_l:
                break
            length, h_l = 2.0 * length, h_2
        return length
    while length > _DESCENT_MIN_M:
        length *= 0.5
        if _along(a, y, u_a, u_y, length, args, hs, y_range) < h0 - 1.0e-4 * g_norm * length:
            return length
    return 0.0


@njit(cache=True, _nrt=False)
def refine_point(a, y, rot, centre, surf, iterations, radius, max_iter, tol, fixed_alpha):
    """Damped Newton on h(alpha, y) from one start (central differences, 9 points; :func:`distance`'s arguments,
    the wheel radius (m, scales the angle steps), at most ``max_iter`` steps, converged below a step of ``tol`` m;
    ``fixed_alpha``: along y alone).

    Returns (alpha, y, converged, h near the point (a start for its distance), and the last difference Hessian
    h_aa, h_yy, h_ay in m/m^2, derivatives by arc length a r and y).
    """
    d = 1.0e-5  # m, difference step in arc length
    da = d / radius
    args = (rot, centre, surf, iterations)
    y_range = surf.y_range
    h_aa = h_yy = h_ay = math.nan
    hs = 0.0
    for _ in range(max_iter):
        h0 = _finite_distance(a, y, args, hs)
        hs = h0 if abs(h0) < _FAR else 0.0  # start of the neighbours' Newton iterations
        h1, h2 = _finite_distance(a + da, y, args, hs), _finite_distance(a - da, y, args, hs)
        h3, h4 = _finite_distance(a, y + d, args, hs), _finite_distance(a, y - d, args, hs)
        h5, h6 = _finite_distance(a + da, y + d, args, hs), _finite_distance(a + da, y - d, args, hs)
        h7, h8 = _finite_distance(a - da, y + d, args, hs), _finite_distance(a - da, y - d, args, hs)
        g_a = (h1 - h2) / (2 * d)
        g_y = (h3 - h4) / (2 * d)
        h_aa = (h1 - 2 * h0 + h2) / (d * d)
        h_yy = (h3 - 2 * h0 + h4) / (d * d)
        h_ay = (h5 - h6 - h7 + h8) / (4 * d * d)
        if fixed_alpha:
            g_a, h_aa, h_ay = 0.0, 1.0, 0.0
        det = h_aa * h_yy - h_ay * h_ay
        if h_aa > 0 and det > 0:
            s_a = -(h_yy * g_a - h_ay * g_y) / det
            s_y = -(h_aa * g_y - h_ay * g_a) / det
            ok = True
        elif h_aa > 0:
            # convex along the rolling direction but not across it (e.g. the conformal arcs of a flange root and a
            # gauge corner of equal radius, R13 on S1002 and UIC60, where h is nearly flat across the profile and
            # its curvature has either sign): a descent step whose length the line search finds (the fixed
            # fraction of the gradient below crawls, ~2e-5 m per iteration, and stopped 0.3 mm short of the
            # minimum: tests/test_search_flange.py)
            length = _descent_length(a, y, g_a, g_y, h0, args, hs, radius, y_range)
            g_norm = math.sqrt(g_a * g_a + g_y * g_y)
            if length > 0.0:
                s_a, s_y = -g_a / g_norm * length, -g_y / g_norm * length
            else:
                s_a, s_y = 0.0, 0.0
            ok = False
        else:
            # concave along the rolling direction: between the two edges of a wheel flat, which the angle grid
            # (search_side) or the angle scan (compiled_search) seeds each; a short gradient step (1e-3 times the
            # gradient, m) keeps this start near its seed (a descent to one edge changes which edges the compiled
            # search's tracked stages hold, and the wheel-flat impact with them)
            s_a, s_y, ok = -g_a * 1e-3, -g_y * 1e-3, False
        norm = math.sqrt(s_a * s_a + s_y * s_y)
        if norm > 3.0e-3:
            s_a *= 3.0e-3 / norm
            s_y *= 3.0e-3 / norm
        a += s_a / radius
        y = min(max(y + s_y, y_range[0]), y_range[1])
        if ok and norm < tol:
            return a, y, True, hs, h_aa, h_yy, h_ay
    return a, y, False, hs, h_aa, h_yy, h_ay


@njit(cache=True)
def refine(alphas, ys, rot, centre, surf, iterations, radius, max_iter, tol, fixed_alpha):
    """refine_point from each start; returns (alpha, y, h, converged)."""
    k_max = alphas.shape[0]
    out_a, out_y, out_h = alphas.copy(), ys.copy(), np.empty(k_max)
    converged = np.zeros(k_max, dtype=np.bool_)
    for k in range(k_max):
        a, y, ok, hs, _, _, _ = refine_point(
            out_a[k], out_y[k], rot, centre, surf, iterations, radius, max_iter, tol, fixed_alpha
        )
        out_a[k], out_y[k], converged[k] = a, y, ok
        out_h[k] = distance(a, y, rot, centre, surf, iterations)
    return out_a, out_y, out_h, converged
