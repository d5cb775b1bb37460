"""Compiled (numba) 3-D contact search for the compiled loop: the patches of both wheels at one pose.

The same search as rigid_dynamics.contact.search.search_side with the SearchProvider of providers/search.py, on the
same surfaces (the TabulatedWheel/TabulatedRail stand-ins: Hermite tables of the ideal profiles plus the closed-
form irregularities of contact._search_kernels), with two changes that make it cheap enough to run at every
right-hand side:

* Candidates. search_side refines every minimum of h(alpha, y_d) on an (alpha, y_d) grid. Here a *full*
  evaluation (the first stage of each RK4 step and every recorded sample) scans the vertical gap
  N(p_x, p_y) - p_z of the wheel points at the lowest angle alpha = pi/2 - phi along y_d (step
  ``scan_step_m``); every local minimum of that gap below ``candidate_gap_m / cos(75 deg)`` is a start (a
  vertical gap is the normal gap divided by the cosine of the contact angle to first order, and its minima
  sit where the profile slopes are equal, the 2-D condition of a minimum of h); at each such y_d the gap is scanned
  over search_side's angles (``alpha_points`` over +-``alpha_half_range_rad``), and every minimum over the angle
  (e.g. both edges of a wheel flat) is a start. Where the vertical gap is negative the samples' normal distance h
  is evaluated too: a minimum of h more than 1.5 steps from every vertical-gap minimum is a further start (on
  conformal arcs, S1002's R13 flange root on UIC60's R13 gauge corner, h is nearly flat and deepest inside the
  arc while the vertical gap's minimum sits at its end). The start is the nearest
  candidate of the previous evaluation within ``memory_radius_m`` when there is one (warm start), else the scan
  point. The other RK4 stages start from the previous evaluation's candidates alone (the pose moves by
  O(h v) within a step; a new minimum appears at the next step's scan at the latest), except where the gap is not
  convex along the rail (a flat, a deep polygon or corrugation), which is scanned in every stage: there a minimum
  can jump within a step.
* Patch geometry. Point, normal and curvatures (eq 12-33: curvature tensors of both surfaces in the rolling-
  direction basis, D = (K_w - K_r)/2, principal A nearest the rolling direction; B floored at the profile
  section's MIN_LATERAL_CURVATURE_1_PER_M, as SearchProvider) are evaluated on the same
  tabulated surfaces (the second derivative of each profile interpolated linearly between nodes 2e-5 m apart)
  instead of search_side's exact surfaces.

Each start is refined by contact._search_kernels.refine_point (the damped Newton of search_side), candidates
are deduplicated as in search_side (the same point, or one interpenetration region: h < 0 along the joining
segment), and the two deepest patches of a side, ordered by contact angle, fill slots 0 and 1 (SearchProvider).
A side without contact gets SearchProvider's placeholder in slot 0 (q = -smallest gap) and an absent slot 1
(q = NaN). tests/test_dynamics_compiled_search.py compares the geometry with SearchProvider's.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact._search_kernels import (
    Surfaces,
    _table,
    distance,
    rail_irregularity,
    refine_point,
    wheel_irregularity,
)
from rigid_dynamics.wheelset.layout import (
    G_APPROACH,
    G_CONTACT_ANGLE,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_ELLIPSE_ANGLE,
    G_LEVER,
    G_NORMAL,
    G_ROLLING_RADIUS,
    G_WHEEL_LATERAL,
    N_GEO,
)
from rigid_dynamics.wheelset.providers.surfaces import MIN_LATERAL_CURVATURE_1_PER_M
from rigid_dynamics.wheelset.state import ROLL, SPIN, YAW, X, Y, Z

MAX_START = 8  # starts refined per side and evaluation
MAX_MEMORY = 4  # candidates kept per side for the next evaluation
ABSENT_GAP_M = 0.01  # providers.ABSENT_GAP_M
COS_STEEPEST = math.cos(math.radians(75.0))

# layout of the per-side rows of ``sp`` (search parameters), shape (2, SP_LEN)
(
    S_YLO, S_YHI, S_RLO, S_RHI, S_RSIGN, S_ROFF, S_WLOW, S_WSTEP, S_RLOW, S_RSTEP, S_SIGN,
    S_SCAN, S_GAP, S_NEWTON, S_ITER, S_TOL, S_RADIUS, S_MEMR, S_TRACK, S_AHALF, S_APTS,
) = range(21)  # fmt: skip
SP_LEN = 21

# columns of the candidates' scratch ``cand`` (2 MAX_START, 8): angle alpha, wheel lateral y_d, distance h, mark (the
# lateral scan's gap, then the memory entry a start came from, then -1 when taken), the Hessian of h (h_aa, h_yy,
# h_ay), merged (1: one interpenetration region with a deeper candidate)
C_ALPHA, C_YD, C_H, C_MARK, C_H_AA, C_H_YY, C_H_AY, C_MERGED = range(8)
# columns of the memory ``mem`` (2 sides, MAX_MEMORY, 7): the angle from the lowest point, y_d, h, the Hessian
# (h_aa, h_yy, h_ay), merged
M_ANGLE, M_YD, M_H, M_H_AA, M_H_YY, M_H_AY, M_MERGED = range(7)
# rows of the vector scratch ``vb`` (12, 3) of patch_geometry: the wheel point, its tangents along alpha and y_d, the
# second derivatives (aa, ay, yy; rows 1-5 reused for the rail's), the normal, the rolling-direction basis e1, e2,
# and a local vector
V_POINT, V_T_ALPHA, V_T_Y, V_X_AA, V_X_AY, V_X_YY, V_NORMAL, V_E1, V_E2 = range(9)
V_LOCAL = 11


class SearchArgs(NamedTuple):
    """The search mode's record: the per-side parameters ``sp`` (2, SP_LEN), the profile tables and irregularity
    rows of the four surfaces (wheel left, rail left, wheel right, rail right), the memory of the previous
    evaluation (``mem``, ``n_mem``: warm starts, carried between calls) and scratch (``cand``, ``order``, ``vb``,
    ``rot``).
    """

    sp: np.ndarray
    tabs: tuple
    irrs: tuple
    mem: np.ndarray
    n_mem: np.ndarray
    cand: np.ndarray
    order: np.ndarray
    vb: np.ndarray
    rot: np.ndarray


@njit(cache=True, _nrt=False)
def rotation(yaw, roll, spin, rot):
    """C_D = R_z(psi) R_x(theta) R_y(-phi) (kinematics.wheelset_rotation) into rot (3, 3)."""
    cps, sps, cth, sth, cph, sph = (
        math.cos(yaw),
        math.sin(yaw),
        math.cos(roll),
        math.sin(roll),
        math.cos(spin),
        math.sin(spin),
    )
    # R_z R_x
    a00, a01, a02 = cps, -sps * cth, sps * sth
    a10, a11, a12 = sps, cps * cth, -cps * sth
    a20, a21, a22 = 0.0, sth, cth
    # times R_y(-phi) = [[c, 0, -s], [0, 1, 0], [s, 0, c]]
    rot[0, 0], rot[0, 1], rot[0, 2] = a00 * cph + a02 * sph, a01, -a00 * sph + a02 * cph
    rot[1, 0], rot[1, 1], rot[1, 2] = a10 * cph + a12 * sph, a11, -a10 * sph + a12 * cph
    rot[2, 0], rot[2, 1], rot[2, 2] = a20 * cph + a22 * sph, a21, -a20 * sph + a22 * cph


@njit(cache=True, _nrt=False)
def _vertical_gap(cos_a, sin_a, r_irr, y_d, rot, centre, surf):
    """N(p_x, p_y) - p_z of the wheel point (alpha, y_d) (cos, sin of alpha and R_irr(alpha) given) on the
    _search_kernels.Surfaces ``surf``; +inf where the wheel or the rail is not defined.
    """
    rail_range, rail_irr, rail_map = surf.rail_range, surf.rail_irr, surf.rail_map
    r = _table(y_d, *surf.wheel)[0]
    if not math.isfinite(r):
        return math.inf
    r += r_irr
    x0, x2 = r * cos_a, r * sin_a
    py = rot[1, 0] * x0 + rot[1, 1] * y_d + rot[1, 2] * x2 + centre[1]
    if not (py >= rail_range[0] and py <= rail_range[1]):
        return math.inf
    pz = rot[2, 0] * x0 + rot[2, 1] * y_d + rot[2, 2] * x2 + centre[2]
    big_n = _table(py, *surf.rail)[0]
    if rail_irr.shape[0] > 0:
        px = rot[0, 0] * x0 + rot[0, 1] * y_d + rot[0, 2] * x2 + centre[0]
        big_n += rail_irregularity(px, py, rail_irr, rail_map[0], rail_map[1])[0]
    return big_n - pz


@njit(cache=True, _nrt=False)
def _tensor(du, dv, duu, duv, dvv, n, e1, e2):
    """Curvature tensor (k11, k12, k22) of a parametric surface in the basis (e1, e2) (curvature.curvature_tensor)."""
    h11 = n[0] * duu[0] + n[1] * duu[1] + n[2] * duu[2]
    h12 = n[0] * duv[0] + n[1] * duv[1] + n[2] * duv[2]
    h22 = n[0] * dvv[0] + n[1] * dvv[1] + n[2] * dvv[2]
    a11 = e1[0] * du[0] + e1[1] * du[1] + e1[2] * du[2]
    a12 = e1[0] * dv[0] + e1[1] * dv[1] + e1[2] * dv[2]
    a21 = e2[0] * du[0] + e2[1] * du[1] + e2[2] * du[2]
    a22 = e2[0] * dv[0] + e2[1] * dv[1] + e2[2] * dv[2]
    det = a11 * a22 - a12 * a21
    b11, b12, b21, b22 = a22 / det, -a12 / det, -a21 / det, a11 / det
    k11 = b11 * (h11 * b11 + h12 * b21) + b21 * (h12 * b11 + h22 * b21)
    k12 = b11 * (h11 * b12 + h12 * b22) + b21 * (h12 * b12 + h22 * b22)
    k22 = b12 * (h11 * b12 + h12 * b22) + b22 * (h12 * b12 + h22 * b22)
    return k11, k12, k22


@njit(cache=True, _nrt=False)
def _rot(rot, v, out):
    for i in range(3):
        out[i] = rot[i, 0] * v[0] + rot[i, 1] * v[1] + rot[i, 2] * v[2]


@njit(cache=True, _nrt=False)
def patch_geometry(alpha, y_d, h, rot, centre, surf, right, vb, g):
    """Geometry of the patch at the refined minimum (alpha, y_d) with distance h into g (layout.GEOMETRY_FIELDS):
    search._patch's point, normal and principal relative curvatures, on the tabulated surfaces ``surf``
    (_search_kernels.Surfaces) of the left or the ``right`` side. vb: scratch (12, 3).
    """
    rail_irr, rail_map = surf.rail_irr, surf.rail_map
    r, r_y, r_yy = _table(y_d, *surf.wheel)
    v, r_a, r_aa = wheel_irregularity(alpha, surf.wheel_irr)
    r += v
    ca, sa = math.cos(alpha), math.sin(alpha)
    loc = vb[V_LOCAL]
    p, t_a, t_y, x_aa, x_ay, x_yy = vb[V_POINT], vb[V_T_ALPHA], vb[V_T_Y], vb[V_X_AA], vb[V_X_AY], vb[V_X_YY]
    loc[0], loc[1], loc[2] = r * ca, y_d, r * sa
    _rot(rot, loc, p)
    loc[0], loc[1], loc[2] = r_a * ca - r * sa, 0.0, r_a * sa + r * ca
    _rot(rot, loc, t_a)
    loc[0], loc[1], loc[2] = r_y * ca, 1.0, r_y * sa
    _rot(rot, loc, t_y)
    loc[0], loc[1], loc[2] = r_aa * ca - 2.0 * r_a * sa - r * ca, 0.0, r_aa * sa + 2.0 * r_a * ca - r * sa
    _rot(rot, loc, x_aa)
    loc[0], loc[1], loc[2] = -r_y * sa, 0.0, r_y * ca
    _rot(rot, loc, x_ay)
    loc[0], loc[1], loc[2] = r_yy * ca, 0.0, r_yy * sa
    _rot(rot, loc, x_yy)
    for i in range(3):
        p[i] += centre[i]
    n, e1, e2 = vb[V_NORMAL], vb[V_E1], vb[V_E2]
    # n = -(t_y x t_a)/|.|: from the rail into the wheel
    n[0] = -(t_y[1] * t_a[2] - t_y[2] * t_a[1])
    n[1] = -(t_y[2] * t_a[0] - t_y[0] * t_a[2])
    n[2] = -(t_y[0] * t_a[1] - t_y[1] * t_a[0])
    norm = math.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    for i in range(3):
        n[i] /= norm
    # rail point = p + h * outward normal
    qx, qy, qz = p[0] - h * n[0], p[1] - h * n[1], p[2] - h * n[2]
    # rolling-direction basis (search option rolling_direction = main x)
    e1[0], e1[1], e1[2] = 1.0 - n[0] * n[0], -n[0] * n[1], -n[0] * n[2]
    norm = math.sqrt(e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2)
    for i in range(3):
        e1[i] /= norm
    e2[0] = n[1] * e1[2] - n[2] * e1[1]
    e2[1] = n[2] * e1[0] - n[0] * e1[2]
    e2[2] = n[0] * e1[1] - n[1] * e1[0]
    w11, w12, w22 = _tensor(t_a, t_y, x_aa, x_ay, x_yy, n, e1, e2)
    big_n, n_y, n_yy = _table(qy, *surf.rail)
    _, n_x, vy, n_xx, n_xy, vyy = rail_irregularity(qx, qy, rail_irr, rail_map[0], rail_map[1])
    n_y += vy
    n_yy += vyy
    du, dv, duu, duv, dvv = vb[V_T_ALPHA], vb[V_T_Y], vb[V_X_AA], vb[V_X_AY], vb[V_X_YY]  # reused for the rail
    du[0], du[1], du[2] = 1.0, 0.0, n_x
    dv[0], dv[1], dv[2] = 0.0, 1.0, n_y
    duu[0], duu[1], duu[2] = 0.0, 0.0, n_xx
    duv[0], duv[1], duv[2] = 0.0, 0.0, n_xy
    dvv[0], dvv[1], dvv[2] = 0.0, 0.0, n_yy
    r11, r12, r22 = _tensor(du, dv, duu, duv, dvv, n, e1, e2)
    d11, d12, d22 = 0.5 * (w11 - r11), 0.5 * (w12 - r12), 0.5 * (w22 - r22)
    # principal values; A belongs to the direction within +-pi/4 of e1 (curvature.principal_relative_curvature)
    mean, half = 0.5 * (d11 + d22), math.sqrt(0.25 * (d11 - d22) ** 2 + d12 * d12)
    angle = 0.5 * math.atan2(2.0 * d12, d11 - d22)  # direction of mean + half
    if abs(angle) <= 0.25 * math.pi:
        big_a, big_b = mean + half, mean - half
    else:
        big_a, big_b = mean - half, mean + half
        angle -= math.copysign(0.5 * math.pi, angle)  # A's direction
    g[G_ELLIPSE_ANGLE] = angle
    g[G_APPROACH] = -h
    g[G_LEVER], g[G_LEVER + 1] = 0.5 * (p[0] + qx) - centre[0], 0.5 * (p[1] + qy) - centre[1]
    g[G_LEVER + 2] = 0.5 * (p[2] + qz) - centre[2]
    g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2] = n[0], n[1], n[2]
    # B floored as the profile section floors it (SearchProvider too): on the conformal arcs of a flange root and a
    # gauge corner of equal radius (S1002 / UIC60: 13 mm) the surface curvatures cancel and B is round-off
    g[G_CURVATURE_LONG], g[G_CURVATURE_LAT] = max(big_a, 1e-6), max(big_b, MIN_LATERAL_CURVATURE_1_PER_M)
    g[G_ROLLING_RADIUS] = r
    g[G_WHEEL_LATERAL] = y_d
    tilt = -n[1] if right else n[1]
    g[G_CONTACT_ANGLE] = math.atan2(tilt, -n[2])


@njit(cache=True, _nrt=False)
def _keep_lowest(cand, first, n, alpha, y_d, gap):
    """Add the start (alpha, y_d) with gap to cand[first : first + MAX_START] holding n starts (replacing the
    highest gap when full). Returns the new n.
    """
    if n < MAX_START:
        cand[first + n, C_ALPHA], cand[first + n, C_YD], cand[first + n, C_MARK] = alpha, y_d, gap
        return n + 1
    worst = first
    for j in range(first + 1, first + MAX_START):
        if cand[j, C_MARK] > cand[worst, C_MARK]:
            worst = j
    if gap < cand[worst, C_MARK]:
        cand[worst, C_ALPHA], cand[worst, C_YD], cand[worst, C_MARK] = alpha, y_d, gap
    return n


@njit(cache=True, _nrt=False)
def _track(a, yd, memory, args, radius, limit, y_range):
    """One Newton step on h(alpha, y_d) from a last candidate with central-difference gradient and the Hessian of
    its last refinement (memory = (angle, y_d, h, h_aa, h_yy, h_ay)). Returns (alpha, y_d, h, tracked); not
    tracked when the Hessian is not positive definite, h is undefined or the step is longer than ``limit``.
    """
    d = 1.0e-5
    da = d / radius
    h_aa, h_yy, h_ay = memory[M_H_AA], memory[M_H_YY], memory[M_H_AY]
    det = h_aa * h_yy - h_ay * h_ay
    h0 = distance(a, yd, *args, memory[M_H])
    if not (math.isfinite(h0) and h_aa > 0 and det > 0):
        return a, yd, h0, False
    g_a = (distance(a + da, yd, *args, h0) - distance(a - da, yd, *args, h0)) / (2 * d)
    g_y = (distance(a, yd + d, *args, h0) - distance(a, yd - d, *args, h0)) / (2 * d)
    s_a = -(h_yy * g_a - h_ay * g_y) / det
    s_y = -(h_aa * g_y - h_ay * g_a) / det
    if not (math.isfinite(s_a) and math.isfinite(s_y) and s_a * s_a + s_y * s_y < limit * limit):
        return a, yd, h0, False
    a += s_a / radius
    yd = min(max(yd + s_y, y_range[0]), y_range[1])
    return a, yd, distance(a, yd, *args, h0), True


@njit(cache=True, _nrt=False)
def search_side(s, centre, spin, search, full, cg):
    """Candidates and patches of side s (0 left, 1 right) into cg rows 2 s, 2 s + 1; updates the memory
    mem[s] (MAX_MEMORY, 7: angle from the lowest point alpha - (pi/2 - phi), y_d, h, h_aa, h_yy, h_ay, merged) /
    n_mem[s]: the angle is kept relative to the lowest point, so that a warm start follows the wheel's rotation;
    the Hessian is the last refinement's; merged candidates (one interpenetration region with a deeper one) are
    kept as warm starts of the next scan, not tracked. cand: scratch (2 MAX_START, 8: alpha, y_d, h, mark,
    Hessian, merged; the second half holds the lateral scan's minima),
    order: scratch (MAX_START,) int (all in the record ``search``, :class:`SearchArgs`). Returns the number of
    starts that did not converge.
    """
    sp, tabs, irrs, mem, n_mem, cand, order, vb, rot = search
    # (built here, not returned from a helper: these functions run without NRT reference counting, so no array may
    # be handed back to a caller that counts references)
    wheel = (sp[s, S_WLOW], sp[s, S_WSTEP], tabs[2 * s][0], tabs[2 * s][1], tabs[2 * s][2])
    rail = (sp[s, S_RLOW], sp[s, S_RSTEP], tabs[2 * s + 1][0], tabs[2 * s + 1][1], tabs[2 * s + 1][2])
    wheel_irr, rail_irr = irrs[2 * s], irrs[2 * s + 1]
    y_range, rail_range, rail_map = sp[s, S_YLO : S_YHI + 1], sp[s, S_RLO : S_RHI + 1], sp[s, S_RSIGN : S_ROFF + 1]
    iters, radius = int(sp[s, S_NEWTON]), sp[s, S_RADIUS]
    alpha_mid = 0.5 * math.pi - spin
    n_start = 0
    surf = Surfaces(wheel, rail, wheel_irr, rail_irr, rail_map, y_range, rail_range)
    args = (rot, centre, surf, iters)
    # A gap not convex along the rail (more than one angle scanned, _convex_along_the_rail: a flat, a deep polygon or
    # corrugation) is scanned in every stage: its minima can jump. When a flat's chord tips past level the load moves
    # from its near edge to its far edge within a step; the stages' tracking, which assumes minima that move by
    # O(h v), missed the far edge and let the wheel sink into it for a step (impact peak 3.72 x the static load at
    # 0.1 ms against 3.255 converged; the full scan in every stage gives the Python path's 3.2546, at about 1.15x
    # the loop time of the wheel-flat scene).
    full = full or sp[s, S_APTS] > 1
    if full:
        step = sp[s, S_SCAN]
        # y_d whose lowest point can lie over the rail: p_y = rot[1, 1] y_d + rot[1, 0] x + rot[1, 2] z + c_y with
        # |x|, |z| <= 1.2 r0 (a margin of 0.2 r0 on the radius)
        reach = 1.2 * radius * (abs(rot[1, 0]) + abs(rot[1, 2]))
        lo = (rail_range[0] - centre[1] - reach) / rot[1, 1]
        hi = (rail_range[1] - centre[1] + reach) / rot[1, 1]
        y0 = max(y_range[0], min(lo, hi) - step)
        n_scan = int((min(y_range[1], max(lo, hi) + step) - y0) / step) + 1
        limit = sp[s, S_GAP] / COS_STEEPEST
        cos_a, sin_a, r_irr = math.cos(alpha_mid), math.sin(alpha_mid), wheel_irregularity(alpha_mid, wheel_irr)[0]
        # Along the same samples, where the vertical gap is negative (interpenetration), the distance h along the
        # wheel normal: on conformal arcs (S1002's flange root and UIC60's gauge corner are both R13) h is nearly flat
        # and can be deepest inside the arc while the vertical gap's minimum sits at one end of it. A minimum of h
        # more than 1.5 steps from every vertical-gap minimum is a start too (kept in cand[:MAX_START] until the
        # angle scan below fills those rows).
        g_prev2, g_prev = math.inf, math.inf
        h_prev2, h_prev, h_start = math.inf, math.inf, 0.0
        n_y = 0  # lateral minima, kept in cand[MAX_START:]
        n_h = 0  # minima of h, kept in cand[:MAX_START]
        for k in range(n_scan + 1):
            hk = math.inf
            if k < n_scan:
                yk = y0 + k * step
                gk = _vertical_gap(cos_a, sin_a, r_irr, yk, rot, centre, surf)
                if gk < 0.0:
                    hk = distance(alpha_mid, yk, *args, h_start)
                    if math.isfinite(hk):
                        h_start = hk
            else:
                gk = math.inf
            # the previous sample is a minimum: below its left neighbour, not above its right one
            if k >= 1 and g_prev < g_prev2 and g_prev <= gk and g_prev < limit:
                n_y = _keep_lowest(cand, MAX_START, n_y, alpha_mid, y0 + (k - 1) * step, g_prev)
            if k >= 1 and h_prev < h_prev2 and h_prev <= hk:
                n_h = _keep_lowest(cand, 0, n_h, alpha_mid, y0 + (k - 1) * step, h_prev)
            g_prev2, g_prev = g_prev, gk
            h_prev2, h_prev = h_prev, hk
        n_vertical = n_y
        for i in range(n_h):
            new = True
            for j in range(MAX_START, MAX_START + n_vertical):
                if abs(cand[j, C_YD] - cand[i, C_YD]) <= 1.5 * step:
                    new = False
            if new:
                n_y = _keep_lowest(cand, MAX_START, n_y, alpha_mid, cand[i, C_YD], cand[i, C_MARK])
        # at each lateral minimum, the minima over the angle (search_side's alpha grid: e.g. both edges of a flat)
        n_a, half = int(sp[s, S_APTS]), sp[s, S_AHALF]
        for j in range(MAX_START, MAX_START + n_y):
            y_s = cand[j, C_YD]
            g_prev2, g_prev = math.inf, math.inf
            for i in range(n_a + 1):
                if i < n_a:
                    a_i = alpha_mid + (2.0 * i / (n_a - 1) - 1.0) * half if n_a > 1 else alpha_mid
                    gk = _vertical_gap(
                        math.cos(a_i), math.sin(a_i), wheel_irregularity(a_i, wheel_irr)[0], y_s, rot, centre, surf
                    )
                else:
                    gk = math.inf
                if i >= 1 and g_prev < g_prev2 and g_prev <= gk and g_prev < limit:
                    a_prev = alpha_mid + (2.0 * (i - 1) / (n_a - 1) - 1.0) * half if n_a > 1 else alpha_mid
                    n_start = _keep_lowest(cand, 0, n_start, a_prev, y_s, g_prev)
                g_prev2, g_prev = g_prev, gk
        # warm starts from the memory: a scan minimum within memory_radius_m of a last candidate (in y_d and in
        # arc length along the wheel) is tracked from it
        for j in range(n_start):
            best, dist = -1, sp[s, S_MEMR]
            for m in range(n_mem[s]):
                d = max(
                    abs(mem[s, m, M_YD] - cand[j, C_YD]),
                    radius * abs(alpha_mid + mem[s, m, M_ANGLE] - cand[j, C_ALPHA]),
                )
                if d < dist:
                    best, dist = m, d
            cand[j, C_MARK] = best
    else:
        for m in range(n_mem[s]):
            cand[n_start, C_MARK] = m
            n_start += 1
    failed = 0
    for j in range(n_start):
        m = int(cand[j, C_MARK])
        cand[j, C_MERGED] = 0.0
        if not full and mem[s, m, M_MERGED] > 0:
            # merged into a deeper candidate's region at the last scan: carried to the next scan as a warm start
            cand[j, C_ALPHA], cand[j, C_YD], cand[j, C_H] = mem[s, m, M_ANGLE], mem[s, m, M_YD], mem[s, m, M_H]
            cand[j, C_H_AA], cand[j, C_H_YY], cand[j, C_H_AY] = mem[s, m, M_H_AA], mem[s, m, M_H_YY], mem[s, m, M_H_AY]
            cand[j, C_ALPHA] += alpha_mid
            cand[j, C_MARK], cand[j, C_MERGED] = -1.0, 1.0  # not a candidate of this evaluation
            continue
        tracked = False
        if m >= 0:
            a, yd = alpha_mid + mem[s, m, M_ANGLE], mem[s, m, M_YD]
            a, yd, h, tracked = _track(a, yd, mem[s, m], args, radius, sp[s, S_TRACK], y_range)
            if tracked:
                cand[j, C_H_AA], cand[j, C_H_YY], cand[j, C_H_AY] = (
                    mem[s, m, M_H_AA],
                    mem[s, m, M_H_YY],
                    mem[s, m, M_H_AY],
                )
        else:
            a, yd = cand[j, C_ALPHA], cand[j, C_YD]
        if not tracked:
            a, yd, ok, hs, h_aa, h_yy, h_ay = refine_point(
                a, yd, *args, radius, int(sp[s, S_ITER]), sp[s, S_TOL], False
            )
            h = distance(a, yd, *args, hs)
            cand[j, C_H_AA], cand[j, C_H_YY], cand[j, C_H_AY] = h_aa, h_yy, h_ay
            if not ok:
                failed += 1
        cand[j, C_ALPHA], cand[j, C_YD], cand[j, C_H] = a, yd, h
        cand[j, C_MARK] = 0.0  # not taken yet (the deduplication marks taken starts with -1)
    # deduplicate, deepest first (search_side): the same point, or one interpenetration region
    n_kept = 0
    for _ in range(n_start):
        best = -1
        for j in range(n_start):
            if math.isfinite(cand[j, C_H]) and cand[j, C_MARK] != -1.0 and (best < 0 or cand[j, C_H] < cand[best, C_H]):
                best = j
        if best < 0:
            break
        cand[best, C_MARK] = -1.0  # taken
        duplicate = False
        for i in range(n_kept):
            k = order[i]
            if (
                abs(cand[best, C_YD] - cand[k, C_YD]) < 1e-6
                and abs(cand[best, C_ALPHA] - cand[k, C_ALPHA]) * radius < 1e-6
            ):
                duplicate = True
                break
            if full and cand[best, C_H] < 0:  # (tracked candidates were separate regions at the last scan)
                # one interpenetration region when every wheel point of the joining segment (25 points, the middle
                # first: the likeliest to show a gap) lies inside the rail: its vertical gap, which has the sign of
                # its distance h along the normal, is negative (search_side tests h itself)
                inside = True
                for q in range(-1, 25):
                    t = 0.5 if q < 0 else q / 24.0
                    a_t = cand[k, C_ALPHA] + t * (cand[best, C_ALPHA] - cand[k, C_ALPHA])
                    gap = _vertical_gap(
                        math.cos(a_t), math.sin(a_t), wheel_irregularity(a_t, wheel_irr)[0],
                        cand[k, C_YD] + t * (cand[best, C_YD] - cand[k, C_YD]), rot, centre, surf,
                    )  # fmt: skip
                    if not gap < 0:
                        inside = False
                        break
                if inside:
                    duplicate = True
                    cand[best, C_MERGED] = 1.0  # merged: kept in the memory as a warm start only
                    break
        if not duplicate:
            order[n_kept] = best
            n_kept += 1
    # memory for the next evaluation: the kept candidates, then the merged ones (warm starts only)
    n_mem[s] = 0
    for i in range(n_kept + n_start):
        k = order[i] if i < n_kept else i - n_kept
        if i >= n_kept and cand[k, C_MERGED] != 1.0:
            continue
        if cand[k, C_H] < sp[s, S_GAP] and n_mem[s] < MAX_MEMORY:
            mem[s, n_mem[s], M_ANGLE], mem[s, n_mem[s], M_YD] = cand[k, C_ALPHA] - alpha_mid, cand[k, C_YD]
            mem[s, n_mem[s], M_H] = cand[k, C_H]
            mem[s, n_mem[s], M_H_AA], mem[s, n_mem[s], M_H_YY], mem[s, n_mem[s], M_H_AY] = (
                cand[k, C_H_AA],
                cand[k, C_H_YY],
                cand[k, C_H_AY],
            )
            mem[s, n_mem[s], M_MERGED] = cand[k, C_MERGED]
            n_mem[s] += 1
    # patches: the two deepest (order is by depth), then by contact angle
    right = s == 1
    c0, c1 = 2 * s, 2 * s + 1
    n_patch = 0
    for i in range(min(n_kept, 2)):
        k = order[i]
        if cand[k, C_H] < 0:
            alpha, y_d, h = cand[k, C_ALPHA], cand[k, C_YD], cand[k, C_H]
            patch_geometry(alpha, y_d, h, rot, centre, surf, right, vb, cg[c0 + n_patch])
            n_patch += 1
    if n_patch == 2 and cg[c1, G_CONTACT_ANGLE] < cg[c0, G_CONTACT_ANGLE]:
        for f in range(N_GEO):
            cg[c0, f], cg[c1, f] = cg[c1, f], cg[c0, f]
    if n_patch == 0:
        gap = cand[order[0], C_H] if n_kept > 0 else ABSENT_GAP_M
        sign = sp[s, S_SIGN]
        g = cg[c0]
        g[G_APPROACH] = -gap
        g[G_LEVER], g[G_LEVER + 1], g[G_LEVER + 2] = 0.0, sign * 0.75, radius
        g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2] = 0.0, 0.0, -1.0
        g[G_CURVATURE_LONG], g[G_CURVATURE_LAT], g[G_ROLLING_RADIUS] = 0.5 / radius, 0.5 / 0.3, radius
        g[G_WHEEL_LATERAL], g[G_CONTACT_ANGLE] = sign * 0.75, 0.0
    if n_patch < 2:
        cg[c1, G_APPROACH] = math.nan
    return failed


@njit(cache=True, _nrt=False)
def search_geometry(y, search, full, cg):
    """Both sides' patches at the state y into cg (4, N_GEO) by the search of the record ``search``
    (:class:`SearchArgs`; ``full``: with the lateral scan). Returns the number of unconverged refinements.
    """
    rotation(y[YAW], y[ROLL], y[SPIN], search.rot)
    failed = 0
    for s in range(2):
        failed += search_side(s, y[X : Z + 1], y[SPIN], search, full, cg)
    return failed


@njit(cache=True, _nrt=False)
def search_geometry_on_track(y, rails, search, full, cg, centre):
    """search_geometry with the rails lowered by the elastic track's rail deflections under the wheels and moved
    laterally by its lateral displacements (``rails`` = (deflection left, right, lateral left, right), m; lateral 0
    without the lateral track): each side is searched at the wheelset centre raised by its rail's deflection and
    moved by minus its lateral displacement (centre: a scratch 3-vector), and the levers (contact point - centre)
    are those of that pose (a rigid shift of the rail).
    """
    rail_left_m, rail_right_m, lateral_left_m, lateral_right_m = rails
    rotation(y[YAW], y[ROLL], y[SPIN], search.rot)
    failed = 0
    for s in range(2):
        centre[0] = y[X]
        centre[1] = y[Y] - (lateral_left_m if s == 0 else lateral_right_m)
        centre[2] = y[Z] - (rail_left_m if s == 0 else rail_right_m)
        failed += search_side(s, centre, y[SPIN], search, full, cg)
    return failed


def _convex_along_the_rail(wheel_rows, rail_rows, radius) -> bool:
    """Whether the gap along the rolling direction stays convex (one minimum over the wheel angle): no flat, and
    the curvature the polygons (n^2 A / r^2) and corrugations (A k^2) add stays below half the wheel's 1/r.
    """
    extra = 0.0
    for row in wheel_rows:
        if row[0] != 0.0:  # a flat: concave, two edges
            return False
        extra += row[1] ** 2 * abs(row[2]) / radius**2
    for row in rail_rows:
        extra += abs(row[2]) * row[1] ** 2
    return extra < 0.5 / radius


def pack_search(provider, options=None):
    """(sp, tabs, irrs) of search_geometry from a SearchProvider (its surfaces' fast stand-ins).

    Options (all optional): ``scan_step_m`` (1e-3), ``memory_radius_m`` (2e-3), ``track_step_m`` (1e-4: a
    tracking step longer than this is replaced by a full refinement), and the contact-search options
    candidate_gap_m, newton_iterations, refine_iterations, refine_tolerance_m, alpha_half_range_rad,
    alpha_points (search.DEFAULT_OPTIONS).

    Raises:
        ValueError: a side's surfaces are not tabulated (an irregularity the compiled kernels do not evaluate:
            measured grids, rail deflection).
    """
    from rigid_dynamics.contact.search import DEFAULT_OPTIONS, TabulatedRail, TabulatedWheel

    opts = {
        k: DEFAULT_OPTIONS[k]
        for k in ("candidate_gap_m", "newton_iterations", "refine_iterations", "alpha_half_range_rad", "alpha_points")
    }
    # The contact point after a Newton step of size s is off by O(s^2 / profile radius): a 1e-7 m last step leaves
    # ~1e-12 m, as search_side's 1e-9 m, at fewer refinement iterations.
    opts["refine_tolerance_m"] = 1.0e-7
    opts.update({"scan_step_m": 1.0e-3, "memory_radius_m": 2.0e-3, "track_step_m": 1.0e-4})
    for key, value in (options or {}).items():
        if key in opts:
            opts[key] = value
    sp = np.zeros((2, SP_LEN))
    tabs, irrs = [], []
    for s, side in enumerate(("left", "right")):
        wheel, rail = provider.surfaces.fast[side]
        if not (isinstance(wheel, TabulatedWheel) and isinstance(rail, TabulatedRail)):
            raise ValueError(
                f"{side} side: the compiled search needs tabulated surfaces (ideal profiles with polygon, flat or "
                "corrugation); this scene's irregularities need the Python search"
            )
        w_low, w_step = wheel.table_tuple[:2]
        r_low, r_step = rail.table_tuple[:2]
        sp[s, S_YLO : S_YHI + 1] = wheel.y_range_m
        sp[s, S_RLO : S_RHI + 1] = rail.y_range_m
        sp[s, S_RSIGN : S_ROFF + 1] = rail.lateral_map
        sp[s, S_WLOW], sp[s, S_WSTEP], sp[s, S_RLOW], sp[s, S_RSTEP] = w_low, w_step, r_low, r_step
        sp[s, S_SIGN] = -1.0 if side == "left" else 1.0
        sp[s, S_SCAN], sp[s, S_GAP] = opts["scan_step_m"], opts["candidate_gap_m"]
        sp[s, S_NEWTON], sp[s, S_ITER], sp[s, S_TOL] = (
            opts["newton_iterations"],
            opts["refine_iterations"],
            opts["refine_tolerance_m"],
        )
        sp[s, S_RADIUS] = provider.r0
        sp[s, S_MEMR] = opts["memory_radius_m"]
        sp[s, S_TRACK] = opts["track_step_m"]
        sp[s, S_AHALF], sp[s, S_APTS] = opts["alpha_half_range_rad"], opts["alpha_points"]
        if _convex_along_the_rail(wheel.irregularity_rows, rail.irregularity_rows, provider.r0):
            sp[s, S_APTS] = 1  # one minimum over the angle: the lowest angle seeds it
        tabs.append(np.ascontiguousarray(np.stack(wheel.table_tuple[2:])))
        tabs.append(np.ascontiguousarray(np.stack(rail.table_tuple[2:])))
        irrs.append(np.ascontiguousarray(wheel.irregularity_rows, float).reshape(-1, 7))
        irrs.append(np.ascontiguousarray(rail.irregularity_rows, float).reshape(-1, 7))
    return sp, tuple(tabs), tuple(irrs)


def search_args(provider, options=None) -> SearchArgs:
    """The :class:`SearchArgs` of a SearchProvider (:func:`pack_search` and a fresh :func:`workspace`)."""
    return SearchArgs(*pack_search(provider, options), *workspace())


def no_search_args() -> SearchArgs:
    """A :class:`SearchArgs` of the right types for the modes that do not search (never read)."""
    tab = np.zeros((3, 2))
    irr = np.zeros((0, 7))
    return SearchArgs(np.zeros((2, SP_LEN)), (tab, tab, tab, tab), (irr, irr, irr, irr), *workspace())


def workspace():
    """Scratch and memory arrays of search_geometry: (mem, n_mem, cand, order, vb, rot)."""
    return (
        np.zeros((2, MAX_MEMORY, 7)),
        np.zeros(2, np.int64),
        np.zeros((2 * MAX_START, 8)),
        np.zeros(MAX_START, np.int64),
        np.zeros((12, 3)),
        np.zeros((3, 3)),
    )
