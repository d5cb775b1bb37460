"""CONTACT's KPEC normal method and FASTSIM per strip, as compiled kernels (plain arrays in, no Python objects).

The semi-Hertzian method of the open-source CONTACT program (E.A.H. Vollebregt, J.J. Kalker; eve70a/CONTACT,
Apache-2.0, user guide sec. "Fast or detailed solution"): Kik and Piotrowski's virtual penetration (W. Kik,
J. Piotrowski, Proc. 2nd Mini Conf. on Contact Mechanics, Budapest 1996; J. Piotrowski, W. Kik, Vehicle System
Dynamics 46 (2008) 27-48) with CONTACT's "ellipse correction" (KPEC: a virtual-penetration factor that varies
with y so that a quadric gap gives Hertz's ellipse exactly), and FASTSIM (J.J. Kalker, Vehicle System Dynamics 11
(1982) 1-13) along every strip of the KPEC patch with CONTACT's three flexibilities (Vollebregt & Voltr, VSD 61
(2023) 309-317). Written from the method's description and CONTACT's documented behaviour; no code copied.

Input: the gap h[j, i] = h0(x_i, y_j) - delta (m; the undeformed distance with the rigid approach subtracted,
negative where the bodies interpenetrate) at the element centres of a regular grid (x_i, y_j), element size
dx x dy: the sampled undeformed distance of the patch (the wheelset case evaluates it exactly at the centres,
``ContactGeometry.gap_m``). Steps (h_min = min h < 0, pen = -h_min):

1. **Equivalent ellipse** (:func:`equivalent_ellipse`). With Kik-Piotrowski's threshold h_kp = h_min/2:
   A = (h[j0, i0 + k] - 2 h[j0, i0] + h[j0, i0 - k]) / (2 (k dx)^2) along the row j0 of the deepest element i0,
   k the smallest offset with max(h[j0, i0 +- k]) > h_kp; y_sta, y_end the lateral ends of {h <= h_kp}
   (first and last such rows, interpolated linearly towards the neighbouring row at the same column as the row's
   minimum), y_m their middle and B = (h_kp - h_min) / (y_end - y_m)^2 (at least 1e-4 1/mm, CONTACT's floor);
   Hertz's semi-axes a (x), b (y) of A x^2 + B y^2 at approach pen. A patch of one row keeps b >= 1.1 |y_j0 - y_m|.
2. **Contact area**: element (i, j) is in contact when h <= (1 - eps(y_j)) h_min with
   eps(y) = (A a^2 - (A a^2 - B b^2) ((y - y_m)/b)^2) / pen clipped to [0, 1]: for a quadric gap exactly Hertz's
   ellipse; elsewhere the virtual penetration of Kik and Piotrowski with a lateral shape correction.
3. **Pressure** (p_max = 1 first): in each row j with contact, from its first to its last element in contact,
   p = sqrt((L_j/2)^2 - (x - x_cj)^2) / (L_max/2), where the row's edges x_t, x_l are interpolated linearly on h
   at the row's threshold (L_j = x_l - x_t, x_cj their middle) and L_max = dx times the most elements in a row.
4. **Scale**: p_max = pen / u_n(deepest element), u_n the normal displacement difference of that pressure on the
   two elastic half-spaces (Love's piecewise-constant rectangle coefficient (1 - nu)/(pi G) times the integral of
   1/r over each element; quasi-identical bodies). Elements between the first and last of a row that are not in
   contact carry pressure in u_n and are then cleared (as CONTACT).
5. **Tangential** (:func:`fastsim_strips`): FASTSIM along every row from its leading edge (+x) with the rolling
   step dq = dx: u_i = u_(i-1) - dq w(x_i + dq/6, y_j), traction u_i / L (k_eff = 1), capped at mu p_i in its
   direction; u = 0 ahead of each contact run. Rigid slip w = (xi - (L1/L3) phi y, eta + (L2/L3) phi x), so the
   traction is -(1/L1) integral (xi - phi y L1/L3) dx: the spin acts with its own flexibility L3. The offset dq/6
   of the rigid slip is CONTACT's (its ``facphi``, an empirical correction of the spin term).
6. **Flexibilities** (:func:`simplified_flexibilities`): Kik-Piotrowski's equivalent ellipse of the contact area
   (area A_c and extents l x w: a = sqrt(A_c/pi) sqrt(l/w), b = sqrt(A_c/pi) sqrt(w/l)), Kalker's
   L1 = 8a/(3 C11 G), L2 = 8a/(3 C22 G), L3 = pi a sqrt(a/b)/(4 C23 G) (C_ij for a/b, :mod:`.kalker`), blended
   towards one flexibility L_c = (xi^2 + eta^2 + (phi f)^2) / (xi^2/L1 + eta^2/L2 + (phi f)^2/L3),
   f = (pi a^2/4)/(8a/3), with weight min(1, r/3), r = sqrt(xi^2 + eta^2) / sqrt(c_xi^2 + c_eta^2),
   c_xi = mu F_N/(c^2 G C11), c_eta = mu F_N/(c^2 G C22), c = sqrt(ab) (Vollebregt & Voltr 2023).

Alternatives: :func:`analyn_pressure` (CONTACT's modified ANALYN, B = 6) instead of steps 1-4, and
:func:`fastrip_strips` (FaStrip per strip) instead of step 5.

Symbols: h (m); A, B (1/m); a, b, x, y, dx, dy (m); p, G (Pa); L1..L3 (m/Pa); F_N (N); mu, nu, xi, eta (-);
phi (1/m). Grid arrays are (ny, nx), x along rolling (leading edge at +x), y lateral. Forces act on the wheel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rigid_dynamics.contact import hertz, kalker
from rigid_dynamics.contact.fastrip import _circle_integral

# the compiled copies of Hertz's and Kalker's loops (lazy_kernels.py), called from this module's kernels
_kdbc = hertz.compiled_kernels()["_kdbc"]
_shape = hertz.compiled_kernels()["_shape"]
_coefficients_many = kalker.compiled_kernels()["_coefficients_many"]

KP_THRESHOLD_FACTOR = 0.5
"""Kik-Piotrowski's virtual-penetration factor of the equivalent-ellipse step (CONTACT: 0.5)."""
MIN_LATERAL_CURVATURE_1_PER_M = 0.1
"""Floor of the equivalent ellipse's lateral curvature B (CONTACT: 1e-4 1/mm)."""
ROLLING_SLIP_OFFSET = 1.0 / 6.0
"""Offset of the rigid slip from the element centre along rolling, in rolling steps dq (CONTACT's facphi)."""


@njit(cache=True)
def hertz_semi_axes(curv_long, curv_lat, combined_modulus_Pa, approach_m):
    """Hertz's semi-axes (a along x, b along y), m, of h = A x^2 + B y^2 at approach q (approach control).

    Kalker's elliptic functions as :mod:`.hertz`: a_major = sqrt(q D / (K min(A, B))), a_minor = a_major sqrt(p).
    """
    a_min = min(curv_long, curv_lat)
    p, _, _ = _shape(max(curv_long, curv_lat) / a_min, 1e-14, 60)
    k, d, _, _ = _kdbc(p)
    major = math.sqrt(approach_m * d / (k * a_min))
    minor = major * math.sqrt(p)
    if curv_long <= curv_lat:
        return major, minor
    return minor, major


@njit(cache=True)
def equivalent_ellipse(h, x, y, combined_modulus_Pa):
    """Step 1 of the module docstring: (A, B, y_m, a, b, j0, i0) for the gap h (ny, nx) with min h < 0."""
    ny, nx = h.shape
    dy = y[1] - y[0] if ny > 1 else 1.0
    k0 = np.argmin(h)
    j0 = k0 // nx
    i0 = k0 - j0 * nx
    h_min = h[j0, i0]
    pen = -h_min
    h_kp = (1.0 - KP_THRESHOLD_FACTOR) * h_min
    lo = max(i0 - 1, 0)
    hi = min(i0 + 1, nx - 1)
    while not (lo <= 0 or hi >= nx - 1 or max(h[j0, lo], h[j0, hi]) > h_kp):
        lo -= 1
        hi += 1
    if hi > i0:
        curv_a = (h[j0, hi] - 2.0 * h[j0, i0] + h[j0, lo]) / (2.0 * (x[hi] - x[i0]) ** 2)
    else:
        curv_a = (h[j0, hi] - 2.0 * h[j0, i0] + h[j0, lo]) / (2.0 * (x[i0] - x[lo]) ** 2)
    r0 = ny
    r1 = -1
    for j in range(ny):
        for i in range(nx):
            if h[j, i] <= h_kp:
                if r0 == ny:
                    r0 = j
                r1 = j
                break
    if r0 <= 0:
        r0 = min(1, ny - 1)
    im = np.argmin(h[r0])
    if r0 >= 1 and h[r0 - 1, im] != h[r0, im]:
        y_sta = y[r0] - (h_kp - h[r0, im]) * dy / (h[r0 - 1, im] - h[r0, im])
    else:
        y_sta = y[r0] - 0.5 * dy
    if r1 >= ny - 1:
        r1 = max(ny - 2, 0)
    one_row = r0 >= r1  # after the edge adjustments, as CONTACT
    im = np.argmin(h[r1])
    if r1 + 1 < ny and h[r1 + 1, im] != h[r1, im]:
        y_end = y[r1] + (h_kp - h[r1, im]) * dy / (h[r1 + 1, im] - h[r1, im])
    else:
        y_end = y[r1] + 0.5 * dy
    y_mid = 0.5 * (y_sta + y_end)
    half = y_end - y_mid
    curv_b = MIN_LATERAL_CURVATURE_1_PER_M
    if half != 0.0:
        curv_b = max(curv_b, (h_kp - h_min) / (half * half))
    # a row with h_min at its ends has no x-curvature: keep the ellipse finite (CONTACT does not guard it)
    curv_a = max(curv_a, 1e-9 * curv_b)
    a, b = hertz_semi_axes(curv_a, curv_b, combined_modulus_Pa, pen)
    if one_row:
        b = max(b, 1.1 * abs(y[j0] - y_mid))
    return curv_a, curv_b, y_mid, a, b, j0, i0


@njit(cache=True)
def _love_zz(dx_c, dy_c, hx, hy):
    """Integral of 1/r over the rectangle |x - dx_c| <= hx, |y - dy_c| <= hy seen from the origin, m."""
    acc = 0.0
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            cx = dx_c + sx * hx
            cy = dy_c + sy * hy
            v = 0.0
            if cx != 0.0:
                v += cx * math.asinh(cy / abs(cx))
            if cy != 0.0:
                v += cy * math.asinh(cx / abs(cy))
            acc += sx * sy * v
    return acc


@njit(cache=True)
def _row_threshold(yj, h_min, curv_a, curv_b, y_mid, a, b):
    """eps(y) of step 2 (unclipped above) and the row's threshold (1 - eps) h_min."""
    pen = -h_min
    s = (yj - y_mid) / b
    eps = (curv_a * a * a - (curv_a * a * a - curv_b * b * b) * s * s) / pen
    return max(0.0, eps)


@njit(cache=True)
def kpec_pressure(h, x, y, shear_modulus_Pa, poisson_ratio, pressure, in_contact):
    """Steps 1-4 of the module docstring: fills ``pressure`` (Pa) and ``in_contact`` (ny, nx).

    Returns (normal force N (the pressure before the in-row gaps are cleared, CONTACT's F_N for the flexibilities),
    p_max Pa, A, B, y_m, a, b (the equivalent ellipse), penetration m); zeros when min h >= 0.
    """
    ny = h.shape[0]
    rows = (np.full(ny, -1, dtype=np.int64), np.full(ny, -1, dtype=np.int64))
    return kpec_pressure_into(h, x, y, (shear_modulus_Pa, poisson_ratio), (pressure, in_contact), rows)


@njit(cache=True, _nrt=False)
def kpec_pressure_into(h, x, y, material, fields, rows):
    """:func:`kpec_pressure` without allocation (the dynamics loop): material = (G Pa, nu), fields = (pressure,
    in_contact) (ny, nx) filled here, rows = (first, last) (ny,) int64 scratch.
    """
    shear_modulus_Pa, poisson_ratio = material
    pressure, in_contact = fields
    first, last = rows
    ny, nx = h.shape
    dx = x[1] - x[0] if nx > 1 else 1.0
    dy = y[1] - y[0] if ny > 1 else 1.0
    for j in range(ny):
        first[j] = -1
        last[j] = -1
        for i in range(nx):
            pressure[j, i] = 0.0
            in_contact[j, i] = False
    h_min = np.inf
    for j in range(ny):
        for i in range(nx):
            h_min = min(h_min, h[j, i])
    if not h_min < 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    e_star = shear_modulus_Pa / (1.0 - poisson_ratio)
    curv_a, curv_b, y_mid, a, b, j0, i0 = equivalent_ellipse(h, x, y, e_star)
    most = 0
    for j in range(ny):
        thr = (1.0 - min(1.0, _row_threshold(y[j], h_min, curv_a, curv_b, y_mid, a, b))) * h_min
        for i in range(nx):
            if h[j, i] <= thr:
                in_contact[j, i] = True
                if first[j] < 0:
                    first[j] = i
                last[j] = i
        if first[j] >= 0:
            most = max(most, last[j] - first[j] + 1)
    if most == 0:
        return 0.0, 0.0, curv_a, curv_b, y_mid, a, b, -h_min
    half_max = 0.5 * most * dx
    for j in range(ny):
        if first[j] < 0:
            continue
        thr = (1.0 - _row_threshold(y[j], h_min, curv_a, curv_b, y_mid, a, b)) * h_min
        i = first[j]
        if i <= 0:
            x_t = x[i] - 0.5 * dx
        else:
            x_t = min(x[i], x[i - 1] + dx * (thr - h[j, i - 1]) / (h[j, i] - h[j, i - 1]))
        i = last[j]
        if i >= nx - 1:
            x_l = x[i] + 0.5 * dx
        else:
            x_l = max(x[i], x[i] + dx * (thr - h[j, i]) / (h[j, i + 1] - h[j, i]))
        half = 0.5 * (x_l - x_t)
        mid = 0.5 * (x_l + x_t)
        for i in range(first[j], last[j] + 1):
            u = x[i] - mid
            pressure[j, i] = math.sqrt(max(0.0, half * half - u * u)) / half_max
    # step 4: the displacement at the deepest element, Love's coefficients
    u_n = 0.0
    for j in range(ny):
        if first[j] < 0:
            continue
        for i in range(first[j], last[j] + 1):
            if pressure[j, i] > 0.0:
                u_n += pressure[j, i] * _love_zz(x[i] - x[i0], y[j] - y[j0], 0.5 * dx, 0.5 * dy)
    u_n *= (1.0 - poisson_ratio) / (math.pi * shear_modulus_Pa)
    p_max = -h_min / u_n if u_n > 0.0 else 0.0
    total = 0.0
    for j in range(ny):
        for i in range(nx):
            pressure[j, i] *= p_max
            total += pressure[j, i]
            if not in_contact[j, i]:
                pressure[j, i] = 0.0
            elif not pressure[j, i] > 0.0:
                # an element at its strip's end (the strip of zero length when the deepest element sits on its row's
                # threshold, eps = 0): no pressure, so not in the contact area either
                in_contact[j, i] = False
    return total * dx * dy, p_max, curv_a, curv_b, y_mid, a, b, -h_min


@njit(cache=True)
def _hertz_force(curv_long, curv_lat, combined_modulus_Pa, approach_m):
    """(a, b, F_N) of Hertz's ellipse of h = A x^2 + B y^2 at approach q (as :func:`hertz_semi_axes`), m, m, N."""
    a_min = min(curv_long, curv_lat)
    p, _, _ = _shape(max(curv_long, curv_lat) / a_min, 1e-14, 60)
    k, d, _, _ = _kdbc(p)
    major = math.sqrt(approach_m * d / (k * a_min))
    force = 2.0 * math.pi * major * combined_modulus_Pa * approach_m / (3.0 * k)
    minor = major * math.sqrt(p)
    if curv_long <= curv_lat:
        return major, minor, force
    return minor, major, force


@njit(cache=True)
def _row_curvature(h, j, i, dx):
    """x-curvature of h at (j, i): least-squares parabola over i +- k, k grown while h stays below 0.3 h[j, i] < 0
    (at most 10), 1/m.
    """
    nx = h.shape[1]
    k = 1
    while True:
        if k >= 10 or i - k <= 0 or i + k >= nx - 1 or h[j, i] >= 0.0:
            break
        if max(h[j, i - k - 1], h[j, i + k + 1]) > 0.3 * h[j, i]:
            break
        k += 1
    s0 = 0.0
    s2 = 0.0
    s4 = 0.0
    b0 = 0.0
    b2 = 0.0
    for m in range(-k, k + 1):
        v = h[j, min(max(i + m, 0), nx - 1)]
        s0 += 1.0
        s2 += m * m
        s4 += m**4
        b0 += v
        b2 += v * m * m
    return (s0 * b2 - s2 * b0) / (s0 * s4 - s2 * s2) / (dx * dx)


@njit(cache=True)
def analyn_pressure(h, x, y, shear_modulus_Pa, poisson_ratio, pressure, in_contact):
    """ANALYN as CONTACT's B = 6 ("a modified ANALYN"; M. Sh. Sichani, R. Enblom, M. Berg, VSD 52 (2014) 1752-64):
    per row j, with pen = -min h, the row's deepest element i_j (x_c = x[i_j], gap g = h[j, i_j] + pen), local
    curvatures A_j (least-squares parabola along x, :func:`_row_curvature`) and B_j (second difference along y at
    i_j), both at least 1e-4 1/mm: Hertz's ellipse (a_j, b_j) of (A_j, B_j) at pen gives the shape factors
    alpha = pen/(A_j a_j^2), beta = pen/(B_j b_j^2); the row's local penetration pen_j = pen - beta g; where
    pen_j > 0 the row is in contact over |x - x_c| < l_j = sqrt(pen_j/(alpha A_j)) with the pressure
    p_j sqrt(1 - ((x - x_c)/l_j)^2), p_j = 3 F/(2 pi a b) of Hertz's ellipse of (A_j, B_j) at pen_j.

    Fills ``pressure`` (Pa) and ``in_contact`` (ny, nx); returns the normal force, N (0 when min h >= 0).
    """
    ny, nx = h.shape
    dx = x[1] - x[0] if nx > 1 else 1.0
    dy = y[1] - y[0] if ny > 1 else 1.0
    e_star = shear_modulus_Pa / (1.0 - poisson_ratio)
    pen = -h.min()
    total = 0.0
    for j in range(ny):
        for i in range(nx):
            pressure[j, i] = 0.0
            in_contact[j, i] = False
    if not pen > 0.0 or nx < 3 or ny < 3:
        return 0.0
    for j in range(ny):
        i0 = min(max(np.argmin(h[j]), 1), nx - 2)
        gap = h[j, i0] + pen
        curv_a = max(_row_curvature(h, j, i0, dx), MIN_LATERAL_CURVATURE_1_PER_M)
        jc = min(max(j, 1), ny - 2)
        curv_b = 0.5 * (h[jc + 1, i0] - 2.0 * h[jc, i0] + h[jc - 1, i0]) / (dy * dy)
        curv_b = max(curv_b, MIN_LATERAL_CURVATURE_1_PER_M)
        a, b, _ = _hertz_force(curv_a, curv_b, e_star, pen)
        alpha = pen / (curv_a * a * a)
        beta = pen / (curv_b * b * b)
        local = pen - beta * gap
        if local <= 1e-30:
            continue
        half = math.sqrt(local / (alpha * curv_a))
        a_l, b_l, force = _hertz_force(curv_a, curv_b, e_star, local)
        peak = 1.5 * force / (math.pi * a_l * b_l)
        for i in range(nx):
            u = (x[i] - x[i0]) / half
            if abs(u) < 1.0:
                in_contact[j, i] = True
                pressure[j, i] = peak * math.sqrt(max(0.0, 1.0 - u * u))
                total += pressure[j, i]
    return total * dx * dy


@njit(cache=True)
def simplified_flexibilities(in_contact, dx, dy, normal_force_N, shear_modulus_Pa, poisson_ratio, mu, xi, eta, phi):
    """Step 6 of the module docstring: (L1, L2, L3) in m/Pa and the equivalent ellipse (a, b) in m."""
    a, b = flexibility_ellipse(in_contact, dx, dy)
    if a == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    coef = np.empty((1, 4))
    _coefficients_many(np.array([a / b]), np.array([poisson_ratio]), coef)
    l1, l2, l3 = blended_flexibilities(
        (a, b), (coef[0, 0], coef[0, 1], coef[0, 2]), (normal_force_N, shear_modulus_Pa, mu), (xi, eta, phi)
    )
    return l1, l2, l3, a, b


@njit(cache=True, _nrt=False)
def flexibility_ellipse(in_contact, dx, dy):
    """Step 6's ellipse of the contact area: (a, b), m (zeros without contact)."""
    ny, nx = in_contact.shape
    count = 0
    i_lo, i_hi, j_lo, j_hi = nx, -1, ny, -1
    for j in range(ny):
        for i in range(nx):
            if in_contact[j, i]:
                count += 1
                i_lo = min(i_lo, i)
                i_hi = max(i_hi, i)
                j_lo = min(j_lo, j)
                j_hi = max(j_hi, j)
    if count == 0:
        return 0.0, 0.0
    area = count * dx * dy
    length = dx * max(1, i_hi - i_lo + 1)
    width = dy * max(1, j_hi - j_lo + 1)
    a = math.sqrt(area / math.pi) * math.sqrt(length / width)
    b = math.sqrt(area / math.pi) * math.sqrt(width / length)
    return a, b


@njit(cache=True, _nrt=False)
def blended_flexibilities(ellipse, kalker, load, creep):
    """Step 6's (L1, L2, L3), m/Pa, of the ellipse (a, b) with Kalker's (C11, C22, C23) for a/b, load = (F_N N,
    G Pa, mu) and creep = (xi, eta, phi).
    """
    a, b = ellipse
    c11, c22, c23 = kalker
    normal_force_N, g, mu = load
    xi, eta, phi = creep
    l1 = 8.0 * a / (3.0 * c11 * g)
    l2 = 8.0 * a / (3.0 * c22 * g)
    l3 = math.pi * a * math.sqrt(a / b) / (4.0 * c23 * g)
    c = math.sqrt(a * b)
    ch_xi = mu * normal_force_N / (c * c * g * c11)
    ch_eta = mu * normal_force_N / (c * c * g * c22)
    f = (math.pi * a * a / 4.0) / (8.0 * a / 3.0)
    num = xi * xi + eta * eta + (phi * f) ** 2
    den = xi * xi / l1 + eta * eta / l2 + (phi * f) ** 2 / l3
    l_c = num / max(den, 1e-300) if num > 0.0 else l1
    ratio = max(1e-10, math.sqrt((xi * xi + eta * eta) / (ch_xi * ch_xi + ch_eta * ch_eta)))
    w = min(1.0, max(0.0, ratio / 3.0))
    return (1.0 - w) * l1 + w * l_c, (1.0 - w) * l2 + w * l_c, (1.0 - w) * l3 + w * l_c


@njit(cache=True)
def fastsim_strips(normal, grid, creep, flexibilities, traction):
    """Step 5 of the module docstring: normal = (pressure Pa, in_contact) (ny, nx), grid = (x, y) m (element
    centres), creep = (mu, xi, eta, phi 1/m), flexibilities = (L1, L2, L3) m/Pa; fills traction = (tx, ty Pa,
    in_slip) (ny, nx); returns (Fx N, Fy N, Mz N m) on the wheel.

    Mz is the moment about the grid origin (the contact reference point) about the normal.
    """
    pressure, in_contact = normal
    x, y = grid
    mu, xi, eta, phi = creep
    l1, l2, l3 = flexibilities
    tx, ty, in_slip = traction
    ny, nx = pressure.shape
    dx = x[1] - x[0] if nx > 1 else 1.0
    dy = y[1] - y[0] if ny > 1 else 1.0
    offset = ROLLING_SLIP_OFFSET * dx
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for j in range(ny):
        ux = 0.0
        uy = 0.0
        wx = (xi - phi * l1 / l3 * y[j]) * dx
        for i in range(nx - 1, -1, -1):
            tx[j, i] = 0.0
            ty[j, i] = 0.0
            in_slip[j, i] = False
            if not in_contact[j, i]:
                ux = 0.0
                uy = 0.0
                continue
            ux = ux - wx
            uy = uy - (eta + phi * l2 / l3 * (x[i] + offset)) * dx
            qx = ux / l1
            qy = uy / l2
            bound = mu * pressure[j, i]
            qn = math.sqrt(qx * qx + qy * qy)
            if qn > bound:
                s = bound / qn if qn > 0.0 else 0.0
                qx *= s
                qy *= s
                ux = l1 * qx
                uy = l2 * qy
                in_slip[j, i] = True
            tx[j, i] = qx
            ty[j, i] = qy
            fx += qx
            fy += qy
            mz += x[i] * qy - y[j] * qx
    area = dx * dy
    return fx * area, fy * area, mz * area


@njit(cache=True)
def fastrip_strips(normal, grid, creep, flexibilities, traction, strip):
    """FaStrip per strip on the KPEC patch (CONTACT's "modified FaStrip", M = 5; Sichani, Enblom, Berg, VSD 54
    (2016) 748-764; strip theory as :mod:`.fastrip`'s docstring): :func:`fastsim_strips`'s arguments and the
    strip theory's data ``strip`` (:class:`~.fastrip.StripTheory`: a and p0 of the equivalent ellipse, nu, xi',
    eta', phi'); fills traction = (tx, ty Pa, in_slip); returns (Fx, Fy, Mz).

    First the FASTSIM pass of :func:`fastsim_strips` (its tractions give the slip directions). Then per row j with
    contact from x_s to x_e (element edges; half-length a_j, middle x_m): with the strip creepages xi', eta', phi'
    and p0 of the equivalent ellipse (a, p0 = 3 F_N/(2 pi a b); :func:`~.fastrip.strip_creepages`), k = xi' - phi'
    y/a, the slip-zone half-length d (the strip theory's root, full slip where there is none), l = eta' + phi' d/a,
    kappa, lambda = (k, l)/|(k, l)|, lambda' = lambda - phi': where u = x - x_m > -a_j + 2 d the strip adheres with
    t = mu p0/a (kappa (S_c - S_a), lambda S_c - lambda' S_a), S_c = sqrt(a_j^2 - u^2), S_a = sqrt((a_j - d)^2 - (u
    - d)^2); elsewhere it slides with mu p in FASTSIM's direction (p: the row's semi-ellipse p_j sqrt(1 - (u/a_j)^2)
    through its largest element pressure p_j, the KPEC row's own shape). A row whose strip traction would exceed mu
    p0 somewhere keeps FASTSIM's tractions (as CONTACT). Two departures from CONTACT (which has no published output
    of this combination): u is measured from the row's middle (CONTACT: from the contact reference point), and the
    tractions are integrated exactly over each element, split at the slip boundary (:mod:`.fastrip`'s closed form;
    sampled at the element centres, the adhesion traction's 1/sqrt peak at the slip boundary and the pressure there
    make the small-creepage force converge slowly: 5 % off Kalker's linear theory at 160 elements per side, against
    0.5 % at 40-160 here).
    """
    fastsim_strips(normal, grid, creep, flexibilities, traction)
    pressure, in_contact = normal
    x, y = grid
    mu = creep[0]
    tx, ty, in_slip = traction
    a, p0, nu, xi_s, eta_s, phi_s = strip
    ny, nx = pressure.shape
    dx = x[1] - x[0] if nx > 1 else 1.0
    dy = y[1] - y[0] if ny > 1 else 1.0
    one_m = 1.0 - phi_s * phi_s
    for j in range(ny):
        x_s = 1e300
        x_e = -1e300
        for i in range(nx):
            if in_contact[j, i]:
                x_s = min(x_s, x[i] - 0.5 * dx)
                x_e = max(x_e, x[i] + 0.5 * dx)
        if x_e < x_s:
            continue
        a_j = max(1e-12, 0.5 * (x_e - x_s))
        x_m = 0.5 * (x_s + x_e)
        k_s = xi_s - phi_s * y[j] / a
        d = 2.0 * a_j  # full slip unless the strip theory's root exists
        radicand = eta_s * eta_s + one_m * k_s * k_s
        if radicand >= 0.0:
            denom = math.sqrt(radicand) - eta_s * phi_s
            if denom > 0.0:
                d = min(2.0 * a_j, (eta_s * eta_s + k_s * k_s) / denom * a / (1.0 - nu))
        l_s = eta_s + phi_s * d / a
        norm = math.sqrt(max(k_s * k_s + l_s * l_s, 1e-40))
        kappa = k_s / norm
        lam = l_s / norm
        lam_p = lam - phi_s
        x_b = -a_j + 2.0 * d
        f_max = 0.0
        for i in range(nx):
            u = x[i] - x_m
            if in_contact[j, i] and u > x_b:
                s_c = math.sqrt(max(0.0, a_j * a_j - u * u)) / a
                s_a = math.sqrt(max(0.0, (a_j - d) ** 2 - (u - d) ** 2)) / a
                f_max = max(f_max, (kappa * (s_c - s_a)) ** 2 + (lam * s_c - lam_p * s_a) ** 2)
        if f_max > 1.0:
            continue
        scale = mu * p0 / a
        p_row = 0.0
        for i in range(nx):
            p_row = max(p_row, pressure[j, i])
        for i in range(nx):
            if not in_contact[j, i]:
                continue
            u_l = x[i] - x_m - 0.5 * dx
            u_r = u_l + dx
            qx = 0.0
            qy = 0.0
            if u_r > x_b:  # adhesion part of the element: the strip theory's traction integrated exactly
                lo = max(u_l, x_b)
                c_int = _circle_integral(a_j, 0.0, lo, u_r)
                a_int = _circle_integral(a_j - d, d, lo, u_r)
                qx += scale * kappa * (c_int - a_int)
                qy += scale * (lam * c_int - lam_p * a_int)
            if u_l < x_b:  # slip part: mu p in FASTSIM's direction, p the row's semi-ellipse
                part = mu * p_row / a_j * _circle_integral(a_j, 0.0, u_l, min(u_r, x_b))
                tn = math.sqrt(tx[j, i] ** 2 + ty[j, i] ** 2)
                if tn > 0.0:
                    qx += part * tx[j, i] / tn
                    qy += part * ty[j, i] / tn
                else:
                    qx += part * kappa
                    qy += part * lam
            tx[j, i] = qx / dx
            ty[j, i] = qy / dx
            in_slip[j, i] = x[i] - x_m < x_b
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for j in range(ny):
        for i in range(nx):
            fx += tx[j, i]
            fy += ty[j, i]
            mz += x[i] * ty[j, i] - y[j] * tx[j, i]
    area = dx * dy
    return fx * area, fy * area, mz * area
