"""Kalker's FASTSIM: the simplified theory of rolling contact on an elliptic patch.

Simplified theory (Kalker 1982, *Vehicle System Dynamics* 11, 1-13; Kalker 1990 ch. 3): the
elastic displacement difference is proportional to the local traction, u = L p (L in m/Pa). In
steady rolling a wheel particle enters the patch at the leading edge x = a(y) with zero traction
and travels towards x = -a(y); the slip (per rolling speed V) is s = w - du/dx with the rigid slip
w = (xi - phi y, eta + phi x). Where the traction stays below the traction bound
g = mu p_n(x, y) the particle adheres (s = 0, so p grows by -w dx / L); where it would exceed it,
it slides with p = -g s/|s| (Coulomb). Tractions act on the wheel and oppose the creepage.

Flexibilities (m/Pa; Kalker 1982) from the linear-theory coefficients C_ij (kalker.py), chosen so
that each creepage alone reproduces Kalker's linear theory as creepage -> 0::

    L1 = 8 a / (3 C11 G),   L2 = 8 a / (3 C22 G),   L3 = pi a sqrt(a/b) / (4 C23 G)

Variants (option ``flexibility``):

* ``"single"`` (Kalker 1982): one L = (L1 |xi| + L2 |eta| + L3 |phi| sqrt(ab)) / sqrt(xi^2 + eta^2 + ab phi^2).
* ``"three"``: xi, eta, phi are divided by their own L1, L2, L3 (exact linear slopes for every
  combination of creepages), blended towards one combined flexibility as the creepage grows, as
  proposed by Vollebregt & Voltr (VSD 61, 2023, 309-317) and implemented in the open-source
  CONTACT program (eve70a/CONTACT, ``src/m_hertz.f90``, ``simpflex``):
  L_c = (xi^2 + eta^2 + (c phi)^2) / (xi^2/L1 + eta^2/L2 + (c phi)^2/L3), c = 3 pi a / 32,
  weight w = min(1, f/3), f = |(xi, eta)| / |(xi_c, eta_c)| with the characteristic creepages
  xi_c = mu N/(G ab C11), eta_c = mu N/(G ab C22) (the spin is not in the weight, as in CONTACT: a weight with
  phi / phi_c beside them mixed 1/m with pure numbers; it made FASTSIM 1.4-1.9 % off CONTACT's converged FASTSIM in
  lateral force on the large-spin case, now 0.15-1.0 %, ``tests/test_fastsim.py``);
  L_i <- (1 - w) L_i + w L_c.
* ``"three-unblended"``: L1, L2, L3 without blending.

Traction bound (option ``traction_bound``): ``"elliptic"`` g = mu p0 sqrt(1 - x^2/a^2 - y^2/b^2)
with the Hertz p0 = 3 N / (2 pi a b); ``"parabolic"`` g = mu (2 N/(pi a b)) (1 - x^2/a^2 - y^2/b^2)
(Kalker's FASTSIM choice, same total N).

Discretisation (Kalker's strip layout): ny strips of width 2b/ny at y_j (midpoints); each strip is
divided into nx equal elements of length dx_j = 2 a(y_j)/nx, a(y) = a sqrt(1 - y^2/b^2). The
traction is computed at element midpoints x_k = a(y_j) - (k + 1/2) dx_j, integrating w exactly
(midpoint value of a linear function) from the previous point; forces are midpoint sums. The hot
loop is compiled with numba (cache=True) and allocates nothing. It exists twice: the plain loop
(``_fastsim_reference``, one strip at a time; also fills the surface fields) and the fast kernel used
for forces only (``_fastsim_one`` without fields: the strips at y and -y share a(y), dx and the bound,
two such pairs advance together, the bound is compared squared so adhering elements need no square
root). Both do the same IEEE arithmetic up to reordering and agree to ~1e-15 (tests/test_fastsim.py);
the fast one is ~3x quicker (benchmarks/results/fastsim_grid.md).

Friction (contact.friction; :class:`PatchFriction`): Coulomb's mu bounds every element by mu p. A falling law
bounds an element that slides by mu at its own slip velocity V |s| (V the rolling speed, s the element's slip per
rolling distance): with the trial traction t = p_prev - w dx and s = k (|t| - g), k = |(L1 t_x, L2 t_y)| / (|t| dx),
the bound g solves g = p mu(V k (|t| - g)) (:func:`_falling_bound`), adhesion holding while |t| <= mu_s p,
mu_s = mu(0): CONTACT's FASTSIM with falling friction written for the strip recursion (its friction memory not
modelled). A law that varies in place is taken at the patch's place (one place per patch). Falling laws run the
plain loop; Coulomb without fields the fast kernel (tests/test_fastsim_falling.py).

The kernels take records (:class:`FastsimPatch`, :class:`FastsimGrid`, :class:`StripFields`, :class:`PatchFriction`
and the flexibilities (L1, L2, L3)); the drivers :func:`fastsim_batch` and :func:`fastsim_fields` take arrays and
keywords.

Signs: Fx, Fy, Mz on the wheel, contact frame; Mz = sum (x p_y - y p_x) dA.

Known limitation: the flexibilities are fitted to C11, C22, C23 only, so the simplified theory's
spin moment does not follow Kalker's C32 = -C23 and C33: its small-creepage slopes dMz/deta and
dMz/dphi are 0.61 and 1.00 (a/b = 0.3), 0.73 and 0.85 (a/b = 1), 0.78 and 0.80 (a/b = 2), 0.81
and 0.73 (a/b = 5) of the linear theory's (nu = 0.28, 80 x 80; tests/test_fastsim.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact.friction import (
    FRICTION_COULOMB,
    FallingLaw,
    FrictionLaw,
    FrictionRecord,
    friction_coefficient,
    uniform,
)
from rigid_dynamics.contact.kalker import CreepCoefficients, kalker_coefficients
from rigid_dynamics.contact.types import ContactFields

TRACTION_BOUNDS = ("elliptic", "parabolic")
FLEXIBILITIES = ("single", "three", "three-unblended")


class FastsimPatch(NamedTuple):
    """One elliptic patch as FASTSIM's kernels take it (floats; arrays of one length for the batch kernel).

    Fields: semi-axes a (rolling direction) and b, m; normal force N, N; creepages xi, eta and spin phi, 1/m.
    """

    semi_axis_long_m: float
    semi_axis_lat_m: float
    normal_force_N: float
    longitudinal: float
    lateral: float
    spin_1_per_m: float


class FastsimGrid(NamedTuple):
    """FASTSIM's discretisation: nx elements per strip, ny strips, the traction bound's shape (parabolic or not)."""

    nx: int
    ny: int
    parabolic: bool


class StripFields(NamedTuple):
    """The strip fields (ny, nx) the plain loop fills when ``store``: tractions p_x, p_y (Pa), slip s_x, s_y (per
    rolling distance, 1) at the element midpoints; (1, 1) arrays when not stored.
    """

    px: np.ndarray
    py: np.ndarray
    sx: np.ndarray
    sy: np.ndarray
    store: bool


class PatchFriction(NamedTuple):
    """The friction one FASTSIM patch sees: the law's record (contact.friction.FrictionRecord), the place of the
    patch (the variable of its nodes, rad or m), the static coefficient there mu_s = mu(0) (the Coulomb bound and
    the blending's mu), and the rolling speed V (m/s) that turns the slip s (per rolling distance) into the slip
    velocity V |s| of a falling law. Floats for one patch; arrays (one per patch) for the batch kernel.
    """

    record: FrictionRecord
    place: float
    coefficient: float
    rolling_speed_m_per_s: float


class FrictionAt(NamedTuple):
    """A friction law at a place: ``friction_coefficient`` of :func:`fastsim_batch` / :func:`fastsim_fields` for a
    law that varies in place; ``place`` (rad or m, the variable of the law's nodes) a number or an array (one per
    patch).
    """

    law: FrictionLaw
    place: object = 0.0


def law_at_place(law: FrictionLaw, place: float) -> FrictionLaw:
    """The law ``law`` with its parameters at ``place`` (interpolated between its nodes as the compiled kernel does):
    one law that varies nowhere, for a patch that has one place (the static FASTSIM model: its reference point).
    """
    if not law.varies:
        return law
    rec = law.record()
    node = rec.node
    i = int(np.clip(np.searchsorted(node, place, side="right") - 1, 0, max(len(node) - 2, 0)))
    j = min(i + 1, len(node) - 1)
    w = 0.0 if j == i else float(np.clip((place - node[i]) / (node[j] - node[i]), 0.0, 1.0))
    fields = ("kinetic", "term_1", "half_velocity_1_m_per_s", "term_2", "half_velocity_2_m_per_s")
    values = [float((1.0 - w) * getattr(rec, f)[i] + w * getattr(rec, f)[j]) for f in fields]
    return FrictionLaw((FallingLaw(law.laws[0].law, *values),))


def no_fields() -> StripFields:
    """A :class:`StripFields` that stores nothing."""
    d = np.zeros((1, 1))
    return StripFields(d, d, d, d, False)


def coulomb_friction(coefficient: float, rolling_speed_m_per_s: float = 1.0) -> PatchFriction:
    """A :class:`PatchFriction` of Coulomb's law with ``coefficient`` (the record of contact.friction.uniform)."""
    return PatchFriction(uniform(max(float(coefficient), 0.0)).record(), 0.0, float(coefficient), rolling_speed_m_per_s)


@njit(cache=True)
def _strip_constants(patch, mu, flex, ny, parabolic):
    """(strip width dy, traction bound at the centre g0, xi/L1, eta/L2, phi/L3) of both strip loops."""
    a, b, fn = patch.semi_axis_long_m, patch.semi_axis_lat_m, patch.normal_force_N
    l1, l2, l3 = flex
    dy = 2.0 * b / ny
    if parabolic:
        g0 = mu * 2.0 * fn / (math.pi * a * b)
    else:
        g0 = mu * 3.0 * fn / (2.0 * math.pi * a * b)
    return dy, g0, patch.longitudinal / l1, patch.lateral / l2, patch.spin_1_per_m / l3


@njit(cache=True)
def _falling_bound(friction, pressure, trial, slip_per_excess):
    """The traction bound g of a sliding element under a falling law: the root of g = p mu(V k (|t| - g)) in
    (0, |t|), with p the pressure (Pa), |t| = ``trial`` the trial traction's magnitude (Pa) and k =
    ``slip_per_excess`` the slip per unit of traction excess, k = |(L1 t_x, L2 t_y)| / (|t| d) (1/Pa): the element's
    slip is s = k (|t| - g), its slip velocity V s. Bracketed: g = 0 gives -p mu < 0, g = |t| gives |t| - p mu_s > 0
    (the element slides). Regula falsi (Illinois) with bisection when it stalls, to 1e-13 |t|. When
    p |dmu/ds| V k >= 1 the equation can have several roots (a steeply falling law on a fine grid); the bracket
    returns one of them.
    """
    rec, place, speed = friction.record, friction.place, friction.rolling_speed_m_per_s
    lo, hi = 0.0, trial
    f_lo = -pressure * friction_coefficient(rec, speed * slip_per_excess * trial, place)
    f_hi = trial - pressure * friction_coefficient(rec, 0.0, place)
    side = 0
    g = hi
    for it in range(200):
        if it % 3 == 2:
            g = 0.5 * (lo + hi)
        else:
            g = hi - f_hi * (hi - lo) / (f_hi - f_lo)
            if not lo < g < hi:
                g = 0.5 * (lo + hi)
        f = g - pressure * friction_coefficient(rec, speed * slip_per_excess * (trial - g), place)
        if f > 0.0:
            hi, f_hi = g, f
            if side == 1:
                f_lo *= 0.5
            side = 1
        else:
            lo, f_lo = g, f
            if side == -1:
                f_hi *= 0.5
            side = -1
        if hi - lo <= 1e-13 * trial:
            break
    return g


@njit(cache=True)
def _fastsim_reference(patch, flex, friction, grid, fields):
    """FASTSIM for one patch, the plain strip loop (one strip, one element at a time, as in the module docstring).

    ``patch`` (:class:`FastsimPatch`), ``flex`` = (L1, L2, L3) (m/Pa), ``friction`` (:class:`PatchFriction`),
    ``grid`` (:class:`FastsimGrid`), ``fields`` (:class:`StripFields`). Returns (Fx, Fy, Mz, slip_area_fraction)
    and fills the strip fields if fields.store. Coulomb's law: the bound is mu_s p everywhere (friction.coefficient;
    the record is not read). A falling law: an element slides when |t| > mu_s p and then on the bound of
    :func:`_falling_bound` (mu at its own slip velocity). Used by fastsim_fields, by every falling-law patch, and as
    the reference that the fast kernel (_fastsim_one, Coulomb, no fields) must reproduce to round-off
    (tests/test_fastsim.py).
    """
    a, b, fn = patch.semi_axis_long_m, patch.semi_axis_lat_m, patch.normal_force_N
    l1, l2, _ = flex
    nx, ny, parabolic = grid.nx, grid.ny, grid.parabolic
    store = fields.store
    falling = friction.record.law_code != FRICTION_COULOMB
    mu = friction.coefficient
    fx = 0.0
    fy = 0.0
    mz = 0.0
    n_slip = 0
    if fn <= 0.0 or a <= 0.0 or b <= 0.0:
        return fx, fy, mz, 0.0
    dy, g0, cx, cy, cs = _strip_constants(patch, mu, flex, ny, parabolic)
    for j in range(ny):
        y = -b + (j + 0.5) * dy
        ay = a * math.sqrt(max(0.0, 1.0 - (y / b) ** 2))
        dx = 2.0 * ay / nx
        wx = cx - cs * y  # xi/L1 - phi y / L3 (constant along the strip)
        px = 0.0
        py = 0.0
        x_prev = ay
        for k in range(nx):
            x = ay - (k + 0.5) * dx
            d = x_prev - x
            xm = 0.5 * (x + x_prev)
            wy = cy + cs * xm
            tx = px - wx * d
            ty = py - wy * d
            rho = 1.0 - (x / a) ** 2 - (y / b) ** 2
            if rho < 0.0:
                rho = 0.0
            if parabolic:
                g = g0 * rho
            else:
                g = g0 * math.sqrt(rho)
            tn = math.sqrt(tx * tx + ty * ty)
            if tn > g:
                if falling and mu > 0.0:
                    k_slip = math.sqrt((l1 * tx) ** 2 + (l2 * ty) ** 2) / (tn * d)
                    g = _falling_bound(friction, g / mu, tn, k_slip)
                s = g / tn
                px = tx * s
                py = ty * s
                n_slip += 1
                slipping = True
            else:
                px = tx
                py = ty
                slipping = False
            if store:
                fields.px[j, k] = px
                fields.py[j, k] = py
                if slipping:
                    # s = L (p - p_trial) / d per component (L1, L2 for x, y)
                    fields.sx[j, k] = l1 * (px - tx) / d
                    fields.sy[j, k] = l2 * (py - ty) / d
                else:
                    fields.sx[j, k] = 0.0
                    fields.sy[j, k] = 0.0
            area = dx * dy
            fx += px * area
            fy += py * area
            mz += (x * py - y * px) * area
            x_prev = x
    return fx, fy, mz, n_slip / (nx * ny)


@njit(cache=True)
def _element(px, py, wxd, wyd, g2):
    """One element of one strip: trial traction t = p - w d; if |t|^2 > g^2 it slides, p = g t/|t| (one sqrt)."""
    tx = px - wxd
    ty = py - wyd
    tn2 = tx * tx + ty * ty
    if tn2 > g2:
        s = math.sqrt(g2 / tn2)
        return tx * s, ty * s, 1
    return tx, ty, 0


@njit(cache=True)
def _unit(u, ny, a, b, dyb, dxa, cx, cs):
    """Strip j = u at y < 0 and, if u < ny // 2, its mirror ny - 1 - u at -y: same a(y), dx, x_k and bound."""
    pair = u < ny // 2
    yb = -1.0 + (u + 0.5) * dyb if pair else 0.0  # y/b; the middle strip of an odd ny lies at y = 0
    ey = 1.0 - yb * yb  # (a(y)/a)^2
    if ey < 0.0:
        ey = 0.0
    ay = a * math.sqrt(ey)
    y = b * yb
    return pair, y, ey, ay, ay * dxa, cx - cs * y, cx + cs * y


@njit(cache=True)
def _unit_element(st, x, wxad, wxbd, wyd, ey, inv_a2, g0sq, parabolic, pair):
    """Element at x of a unit's strips; st = (px, py, sum px, sum py, sum x py) of the strip at y, then at -y."""
    pxa, pya, ax, ay, am, pxb, pyb, bx, by, bm = st
    rho = ey - x * x * inv_a2
    if rho < 0.0:
        rho = 0.0
    g2 = g0sq * rho * rho if parabolic else g0sq * rho  # squared traction bound, shared by the two strips
    pxa, pya, n = _element(pxa, pya, wxad, wyd, g2)
    ax += pxa
    ay += pya
    am += x * pya
    if pair:
        pxb, pyb, nb = _element(pxb, pyb, wxbd, wyd, g2)
        bx += pxb
        by += pyb
        bm += x * pyb
        n += nb
    return (pxa, pya, ax, ay, am, pxb, pyb, bx, by, bm), n


@njit(cache=True)
def _fastsim_fast(patch, flex, mu, nx, ny, parabolic):
    """The strip loop of _fastsim_reference rearranged for speed (Coulomb's law mu, forces only; same results to
    round-off).

    * the strips at y and -y share a(y), dx, the element midpoints and the traction bound (computed once);
    * two such pairs are advanced together (four independent recurrences keep the divide/sqrt unit busy while a
      slipping strip waits for its previous element);
    * the bound is compared squared, |t|^2 > g^2, so an adhering element needs no square root;
    * per-strip constants are hoisted: after the first (half-length) element w_y d is c + cs dx x, w_x d constant;
    * traction sums per strip, times the element area dx dy once per strip.
    Plain IEEE arithmetic (no fastmath): contraction to FMA would give ~20 % but results that depend on the CPU.
    """
    a, b, fn = patch.semi_axis_long_m, patch.semi_axis_lat_m, patch.normal_force_N
    fx = 0.0
    fy = 0.0
    mz = 0.0
    n_slip = 0
    if fn <= 0.0 or a <= 0.0 or b <= 0.0:
        return fx, fy, mz, 0.0
    dy, g0, cx, cy, cs = _strip_constants(patch, mu, flex, ny, parabolic)
    g0sq = g0 * g0
    inv_a2 = 1.0 / (a * a)
    dyb = 2.0 / ny
    dxa = 2.0 / nx
    n_units = (ny + 1) // 2
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for u0 in range(0, n_units, 2):
        two = u0 + 1 < n_units
        u1 = u0 + 1 if two else u0
        pair0, y0, ey0, ay0, dx0, wxa0, wxb0 = _unit(u0, ny, a, b, dyb, dxa, cx, cs)
        pair1, y1, ey1, ay1, dx1, wxa1, wxb1 = _unit(u1, ny, a, b, dyb, dxa, cx, cs)
        # first element: from the leading edge x = a(y) to its midpoint, length dx/2, w_y at a(y) - dx/4
        d0 = 0.5 * dx0
        wyd0 = (cy + cs * (ay0 - 0.5 * d0)) * d0
        st0, n = _unit_element(zero, ay0 - d0, wxa0 * d0, wxb0 * d0, wyd0, ey0, inv_a2, g0sq, parabolic, pair0)
        n_slip += n
        st1 = zero
        if two:
            d1 = 0.5 * dx1
            wyd1 = (cy + cs * (ay1 - 0.5 * d1)) * d1
            st1, n = _unit_element(zero, ay1 - d1, wxa1 * d1, wxb1 * d1, wyd1, ey1, inv_a2, g0sq, parabolic, pair1)
            n_slip += n
        # then midpoint to midpoint, length dx, w_y at x + dx/2: (cy + cs (x + dx/2)) dx = c + cs dx x
        wxad0, wxbd0, c0, csd0 = wxa0 * dx0, wxb0 * dx0, (cy + cs * 0.5 * dx0) * dx0, cs * dx0
        wxad1, wxbd1, c1, csd1 = wxa1 * dx1, wxb1 * dx1, (cy + cs * 0.5 * dx1) * dx1, cs * dx1
        kh = 0.5
        for _ in range(1, nx):
            kh += 1.0  # k + 1/2, exact
            x0 = ay0 - kh * dx0
            st0, n = _unit_element(st0, x0, wxad0, wxbd0, c0 + csd0 * x0, ey0, inv_a2, g0sq, parabolic, pair0)
            n_slip += n
            if two:
                x1 = ay1 - kh * dx1
                st1, n = _unit_element(st1, x1, wxad1, wxbd1, c1 + csd1 * x1, ey1, inv_a2, g0sq, parabolic, pair1)
                n_slip += n
        area = dx0 * dy
        fx += (st0[2] + st0[7]) * area
        fy += (st0[3] + st0[8]) * area
        mz += (st0[4] + st0[9] - y0 * (st0[2] - st0[7])) * area
        if two:
            area = dx1 * dy
            fx += (st1[2] + st1[7]) * area
            fy += (st1[3] + st1[8]) * area
            mz += (st1[4] + st1[9] - y1 * (st1[2] - st1[7])) * area
    return fx, fy, mz, n_slip / (nx * ny)


@njit(cache=True)
def _fastsim_one(patch, flex, friction, grid, fields):
    """FASTSIM for one patch (:class:`FastsimPatch`, flexibilities (L1, L2, L3), :class:`PatchFriction`,
    :class:`FastsimGrid`, :class:`StripFields`). Returns (Fx, Fy, Mz, slip_area_fraction); fills the strip fields if
    fields.store.

    Coulomb's law without fields: the fast kernel, specialised for the traction bound; otherwise (fields, or a
    falling law) the plain loop _fastsim_reference (the two agree to round-off, ~1e-15 relative, for Coulomb).
    """
    if fields.store or friction.record.law_code != FRICTION_COULOMB:
        return _fastsim_reference(patch, flex, friction, grid, fields)
    if grid.parabolic:
        return _fastsim_fast(patch, flex, friction.coefficient, grid.nx, grid.ny, True)
    return _fastsim_fast(patch, flex, friction.coefficient, grid.nx, grid.ny, False)


@njit(cache=True)
def _fastsim_many(patches, flex, friction, grid, out):
    """:func:`_fastsim_one` over patches: ``patches`` a :class:`FastsimPatch` of (n,) arrays, flex (L1, L2, L3) of
    (n,) arrays, ``friction`` a :class:`PatchFriction` whose place, coefficient and rolling speed are (n,) arrays;
    out (n, 4).
    """
    fields = StripFields(np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), False)
    l1, l2, l3 = flex
    for i in range(patches.semi_axis_long_m.shape[0]):
        patch = FastsimPatch(
            patches.semi_axis_long_m[i], patches.semi_axis_lat_m[i], patches.normal_force_N[i],
            patches.longitudinal[i], patches.lateral[i], patches.spin_1_per_m[i],
        )  # fmt: skip
        one = PatchFriction(
            friction.record, friction.place[i], friction.coefficient[i], friction.rolling_speed_m_per_s[i]
        )
        r = _fastsim_one(patch, (l1[i], l2[i], l3[i]), one, grid, fields)
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]
        out[i, 3] = r[3]


def kalker_flexibilities(a, b, shear_modulus_Pa, coefficients: CreepCoefficients):
    """(L1, L2, L3) in m/Pa (Kalker 1982): L1 = 8a/(3 C11 G), L2 = 8a/(3 C22 G), L3 = pi a sqrt(a/b)/(4 C23 G)."""
    l1 = 8.0 * a / (3.0 * coefficients.c11 * shear_modulus_Pa)
    l2 = 8.0 * a / (3.0 * coefficients.c22 * shear_modulus_Pa)
    l3 = math.pi * a * np.sqrt(a / b) / (4.0 * coefficients.c23 * shear_modulus_Pa)
    return l1, l2, l3


FLEXIBILITY_CODES = {"three": 0, "single": 1, "three-unblended": 2}
"""The flexibility variants as the compiled kernels take them (:func:`flexibilities_one`)."""


@njit(cache=True, _nrt=False, inline="always")
def flexibilities_one(a, b, normal_force_N, xi, eta, phi, shear_modulus_Pa, friction_coefficient, c, flexibility):
    """Flexibilities (L1, L2, L3) of one patch by the variant ``flexibility`` (:data:`FLEXIBILITY_CODES`; module
    docstring), c = (C11, C22, C23): the one implementation (the batch :func:`effective_flexibilities` and the
    compiled dynamics loop call it).
    """
    c11, c22, c23 = c
    g = shear_modulus_Pa
    l1 = 8.0 * a / (3.0 * c11 * g)
    l2 = 8.0 * a / (3.0 * c22 * g)
    l3 = math.pi * a * math.sqrt(a / b) / (4.0 * c23 * g)
    if flexibility == 2:  # three-unblended
        return l1, l2, l3
    ab = a * b
    if flexibility == 1:  # single
        num = l1 * abs(xi) + l2 * abs(eta) + l3 * abs(phi) * math.sqrt(ab)
        den = math.sqrt(xi**2 + eta**2 + ab * phi**2)
        single = num / den if den > 0 else l1
        return single, single, single
    # "three": blending of Vollebregt & Voltr (2023)
    cc = 3.0 * math.pi * a / 32.0
    cp2 = (cc * phi) ** 2
    num = xi**2 + eta**2 + cp2
    den = xi**2 / l1 + eta**2 / l2 + cp2 / l3
    l_comb = num / den if den > 0 else l1
    force = friction_coefficient * normal_force_N
    ch2 = (force / (g * ab * c11)) ** 2 + (force / (g * ab * c22)) ** 2
    f_crp = math.sqrt((xi**2 + eta**2) / ch2) if ch2 > 0 else np.inf
    w = min(max(f_crp / 3.0, 0.0), 1.0)
    return (1 - w) * l1 + w * l_comb, (1 - w) * l2 + w * l_comb, (1 - w) * l3 + w * l_comb


@njit(cache=True)
def _flexibilities_many(a, b, normal_force_N, creep, shear_modulus_Pa, friction_coefficient, c, flexibility, out):
    """:func:`flexibilities_one` over flat arrays; creep = (xi, eta, phi), c = (C11, C22, C23) arrays; out (3, n)."""
    xi, eta, phi = creep
    c11, c22, c23 = c
    for k in range(a.shape[0]):
        out[0, k], out[1, k], out[2, k] = flexibilities_one(
            a[k], b[k], normal_force_N[k], xi[k], eta[k], phi[k], shear_modulus_Pa, friction_coefficient[k],
            (c11[k], c22[k], c23[k]), flexibility,
        )  # fmt: skip


def effective_flexibilities(
    a, b, normal_force_N, xi, eta, phi, *, shear_modulus_Pa, friction_coefficient, coefficients, flexibility
):
    """Flexibilities (L1, L2, L3) actually used for each patch by the chosen variant (module docstring;
    :func:`flexibilities_one` per patch).
    """
    if flexibility not in FLEXIBILITIES:
        raise ValueError(f"flexibility = {flexibility!r}: expected one of {', '.join(FLEXIBILITIES)}")
    values = (a, b, normal_force_N, xi, eta, phi, friction_coefficient, coefficients.c11, coefficients.c22)
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (*values, coefficients.c23)))
    shape = arrays[0].shape
    flat = [np.ascontiguousarray(v).ravel() for v in arrays]
    out = np.empty((3, flat[0].size))
    _flexibilities_many(
        flat[0], flat[1], flat[2], (flat[3], flat[4], flat[5]), float(shear_modulus_Pa), flat[6],
        (flat[7], flat[8], flat[9]), FLEXIBILITY_CODES[flexibility], out,
    )  # fmt: skip
    if not shape:
        return float(out[0, 0]), float(out[1, 0]), float(out[2, 0])
    return out[0].reshape(shape), out[1].reshape(shape), out[2].reshape(shape)


@dataclass(frozen=True, eq=False)
class FastsimBatch:
    """FASTSIM results for a batch of patches (arrays of one shape).

    Attributes:
        creep_force_long_N, creep_force_lat_N: Fx, Fy on the wheel, N.
        spin_moment_Nm: Mz on the wheel, N m.
        slip_fraction: fraction of the grid elements in slip (0 = full adhesion).
    """

    creep_force_long_N: np.ndarray
    creep_force_lat_N: np.ndarray
    spin_moment_Nm: np.ndarray
    slip_fraction: np.ndarray


GRID_DEFAULTS = {"nx": 20, "ny": 20, "traction_bound": "elliptic", "flexibility": "three"}
"""FASTSIM's discretisation options (keywords of :func:`fastsim_batch`, :func:`fastsim_fields`) and defaults."""


def _grid_options(options) -> tuple[FastsimGrid, str]:
    """(:class:`FastsimGrid`, flexibility) of the keyword options nx, ny, traction_bound, flexibility (validated)."""
    unknown = sorted(set(options) - set(GRID_DEFAULTS))
    if unknown:
        raise ValueError(
            f"{unknown[0]} = {options[unknown[0]]!r}: unknown option, expected one of {', '.join(GRID_DEFAULTS)}"
        )
    opts = {**GRID_DEFAULTS, **options}
    traction_bound, flexibility = opts["traction_bound"], opts["flexibility"]
    if traction_bound not in TRACTION_BOUNDS:
        raise ValueError(f"traction_bound = {traction_bound!r}: expected one of {', '.join(TRACTION_BOUNDS)}")
    if flexibility not in FLEXIBILITIES:
        raise ValueError(f"flexibility = {flexibility!r}: expected one of {', '.join(FLEXIBILITIES)}")
    for name in ("nx", "ny"):
        n = opts[name]
        if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 1:
            raise ValueError(f"{name} = {n!r}: expected an integer >= 1")
    return FastsimGrid(int(opts["nx"]), int(opts["ny"]), traction_bound == "parabolic"), flexibility


def _friction_arrays(friction, rolling_speed_m_per_s, shape):
    """(record, place, mu_s, V) as flat arrays of ``shape``: ``friction`` a number or array (Coulomb), a
    contact.friction.FrictionLaw (at place 0) or a :class:`FrictionAt`.
    """
    if isinstance(friction, FrictionLaw):
        friction = FrictionAt(friction)
    if isinstance(friction, FrictionAt):
        law, place = friction
        places = np.broadcast_to(np.asarray(place, dtype=float), shape).ravel().copy()
        if not np.all(np.isfinite(places)):
            raise ValueError(f"place = {place!r}: expected finite values")
        record = law.record()
        mu = np.array([friction_coefficient(record, 0.0, v) for v in places])
    else:
        mu = np.array(np.broadcast_to(np.asarray(friction, dtype=float), shape).ravel())
        if not (np.all(np.isfinite(mu)) and np.all(mu >= 0)):
            raise ValueError(f"friction_coefficient = {friction!r}: expected finite values >= 0")
        record = uniform(0.0).record()
        places = np.zeros(mu.shape)
    speed = np.array(np.broadcast_to(np.asarray(rolling_speed_m_per_s, dtype=float), shape).ravel())
    if not (np.all(np.isfinite(speed)) and np.all(speed >= 0)):
        raise ValueError(f"rolling_speed_m_per_s = {rolling_speed_m_per_s!r}: expected finite values >= 0")
    return PatchFriction(record, places, mu, speed)


def _prepare(patch: FastsimPatch, elastic, friction, options, coefficients):
    """Validated flat inputs of the drivers: (shape, :class:`FastsimPatch` of arrays, (L1, L2, L3) arrays,
    :class:`PatchFriction` of arrays, :class:`FastsimGrid`). ``elastic`` = (G, nu); ``friction`` = (friction
    coefficient, law or FrictionAt; rolling speed); ``options`` the grid keywords; ``coefficients`` the C_ij or None.
    """
    shear_modulus_Pa, poisson_ratio = elastic
    grid, flexibility = _grid_options(options)
    if not (math.isfinite(shear_modulus_Pa) and shear_modulus_Pa > 0):
        raise ValueError(f"shear_modulus_Pa = {shear_modulus_Pa!r}: expected a finite number > 0")
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in patch))
    shape = arrays[0].shape
    a, b, fn, xi, eta, phi = (np.array(v.ravel(), dtype=float) for v in arrays)
    if not (np.all(np.isfinite(a)) and np.all(a > 0) and np.all(np.isfinite(b)) and np.all(b > 0)):
        raise ValueError("semi_axis_long_m, semi_axis_lat_m: expected finite values > 0")
    law, speed = friction
    patch_friction = _friction_arrays(law, speed, shape)
    for name, v in (("normal_force_N", fn), ("longitudinal", xi), ("lateral", eta), ("spin_1_per_m", phi)):
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name}: expected finite values")
    coef = coefficients if coefficients is not None else kalker_coefficients(a / b, poisson_ratio)
    if coefficients is not None:
        coef = CreepCoefficients(
            *(np.broadcast_to(np.asarray(c, float), shape).ravel() for c in (coef.c11, coef.c22, coef.c23, coef.c33))
        )
    l1, l2, l3 = effective_flexibilities(
        a,
        b,
        fn,
        xi,
        eta,
        phi,
        shear_modulus_Pa=shear_modulus_Pa,
        friction_coefficient=patch_friction.coefficient,
        coefficients=coef,
        flexibility=flexibility,
    )
    flex = tuple(np.array(np.broadcast_to(v, a.shape), dtype=float) for v in (l1, l2, l3))
    return shape, FastsimPatch(a, b, fn, xi, eta, phi), flex, patch_friction, grid


def fastsim_batch(
    semi_axis_long_m,
    semi_axis_lat_m,
    normal_force_N,
    longitudinal,
    lateral,
    spin_1_per_m,
    *,
    shear_modulus_Pa: float,
    poisson_ratio: float,
    friction_coefficient,
    rolling_speed_m_per_s=1.0,
    coefficients: CreepCoefficients | None = None,
    **grid,
) -> FastsimBatch:
    """FASTSIM creep forces and spin moment for many elliptic patches (compiled loop over patches).

    Args:
        semi_axis_long_m: a (along rolling x), m; arrays broadcast together.
        semi_axis_lat_m: b, m.
        normal_force_N: N, N (patches with N <= 0 give zero forces).
        longitudinal: xi; lateral: eta; spin_1_per_m: phi (1/m).
        shear_modulus_Pa: G; poisson_ratio: nu (C_ij).
        friction_coefficient: mu (scalar or array: Coulomb), or a contact.friction.FrictionLaw (falling: each
            element's bound is mu at its own slip velocity), or a :class:`FrictionAt` (a law that varies in place, at
            the patches' places: its parameters there).
        rolling_speed_m_per_s: V, which turns the slip (per rolling distance) into the slip velocity of a falling law.
        coefficients: precomputed C_ij (else from Kalker's table).
        **grid: nx, ny (elements per strip and number of strips, default 20), traction_bound ("elliptic" or
            "parabolic"), flexibility ("single", "three" or "three-unblended"); :data:`GRID_DEFAULTS`.

    Returns:
        :class:`FastsimBatch`.

    Raises:
        ValueError: bad option or input (the message names it).
    """
    patch = FastsimPatch(semi_axis_long_m, semi_axis_lat_m, normal_force_N, longitudinal, lateral, spin_1_per_m)
    shape, patches, flex, friction, fgrid = _prepare(
        patch, (shear_modulus_Pa, poisson_ratio), (friction_coefficient, rolling_speed_m_per_s), grid,
        coefficients,
    )  # fmt: skip
    out = np.empty((patches.semi_axis_long_m.size, 4))
    _fastsim_many(patches, flex, friction, fgrid, out)
    return FastsimBatch(*(out[:, i].reshape(shape) for i in range(4)))


def fastsim_fields(
    semi_axis_long_m: float,
    semi_axis_lat_m: float,
    normal_force_N: float,
    longitudinal: float,
    lateral: float,
    spin_1_per_m: float,
    *,
    shear_modulus_Pa: float,
    poisson_ratio: float,
    friction_coefficient,
    rolling_speed_m_per_s: float = 1.0,
    **grid,
) -> tuple[tuple[float, float, float, float], ContactFields]:
    """FASTSIM for one patch with surface fields (arguments as :func:`fastsim_batch`, scalars).

    The traction is computed on Kalker's strip grid (nx elements per strip) and resampled by
    linear interpolation along each strip onto a regular grid x_i = -a + (i + 1/2) 2a/nx (same
    strips y_j), with zero traction at the leading edge and projected onto the traction bound mu_s p
    (interpolation between points on a concave bound can overshoot it; a falling law's bound is lower in slip, so
    the projection onto mu_s p is a bound, not the law); the slip flag and slip speed (V |s|, m/s) are taken from
    the nearest strip element. The forces returned are those of the strip grid (the resampled fields integrate to
    them only to O(dx)).

    Returns:
        ((Fx, Fy, Mz, slip_fraction), ContactFields) with fields[j, i] at (x_m[i], y_m[j]).
    """
    patch = FastsimPatch(semi_axis_long_m, semi_axis_lat_m, normal_force_N, longitudinal, lateral, spin_1_per_m)
    _, patches, flex, friction, fgrid = _prepare(
        patch, (shear_modulus_Pa, poisson_ratio), (friction_coefficient, rolling_speed_m_per_s), grid, None
    )
    if patches.semi_axis_long_m.size != 1:
        raise ValueError("fastsim_fields: expected scalar inputs (one patch)")
    nx, ny = fgrid.nx, fgrid.ny
    px = np.zeros((ny, nx))
    py = np.zeros((ny, nx))
    sx = np.zeros((ny, nx))
    sy = np.zeros((ny, nx))
    one = FastsimPatch(*(float(v[0]) for v in patches))
    res = _fastsim_one(
        one,
        (float(flex[0][0]), float(flex[1][0]), float(flex[2][0])),
        PatchFriction(friction.record, float(friction.place[0]), float(friction.coefficient[0]),
                      float(friction.rolling_speed_m_per_s[0])),
        fgrid,
        StripFields(px, py, sx, sy, True),
    )  # fmt: skip
    a, b, fn, mu = patches.semi_axis_long_m, patches.semi_axis_lat_m, patches.normal_force_N, friction.coefficient
    a0, b0 = a[0], b[0]
    x_m = -a0 + (np.arange(nx) + 0.5) * 2.0 * a0 / nx
    y_m = -b0 + (np.arange(ny) + 0.5) * 2.0 * b0 / ny
    tx = np.zeros((ny, nx))
    ty = np.zeros((ny, nx))
    slip = np.zeros((ny, nx))
    in_slip = np.zeros((ny, nx), dtype=bool)
    rho = 1.0 - (x_m[None, :] / a0) ** 2 - (y_m[:, None] / b0) ** 2
    in_contact = rho > 0
    if fn[0] > 0:
        p0 = 3.0 * fn[0] / (2.0 * math.pi * a0 * b0)
        pressure = p0 * np.sqrt(np.clip(rho, 0.0, None))
    else:
        pressure = np.zeros((ny, nx))
        in_contact[:] = False
    for j in range(ny):
        ay = a0 * math.sqrt(max(0.0, 1.0 - (y_m[j] / b0) ** 2))
        if ay <= 0:
            continue
        dx = 2.0 * ay / nx
        xs = ay - (np.arange(nx) + 0.5) * dx  # descending
        xk = np.concatenate([[ay], xs])[::-1]  # ascending incl. the leading edge
        inside = np.abs(x_m) < ay
        tx[j, inside] = np.interp(x_m[inside], xk, np.concatenate([[0.0], px[j]])[::-1])
        ty[j, inside] = np.interp(x_m[inside], xk, np.concatenate([[0.0], py[j]])[::-1])
        nearest = np.clip(np.rint((ay - x_m[inside]) / dx - 0.5).astype(int), 0, nx - 1)
        speed = rolling_speed_m_per_s * np.hypot(sx[j, nearest], sy[j, nearest])
        slip[j, inside] = speed
        in_slip[j, inside] = speed > 0
    # linear interpolation of a traction that sits on a concave bound can overshoot it: project back
    bound = mu[0] * pressure
    t_abs = np.hypot(tx, ty)
    over = t_abs > bound
    scale = np.where(over, bound / np.where(over, t_abs, 1.0), 1.0)
    tx *= scale
    ty *= scale
    fields = ContactFields(
        x_m=x_m,
        y_m=y_m,
        pressure_Pa=pressure,
        traction_long_Pa=tx,
        traction_lat_Pa=ty,
        slip_m_per_s=slip,
        in_contact=in_contact,
        in_slip=in_slip & in_contact,
    )
    return (float(res[0]), float(res[1]), float(res[2]), float(res[3])), fields
