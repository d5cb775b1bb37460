"""The candidate geometry from the contact-geometry tables and the running-direction irregularities (numba).

* Tables (:func:`_table_geometry`): the candidates of providers.TableProvider, bilinear in (roll, lateral shift)
  (:func:`_lookup`), the approach at the centre's height q = q_ref + (z - z_r - z_ref) dq/dz (z_r: the side's rail
  deflection), a merged second candidate dropped; with the lateral track one look-up per side (the wheelset at
  y - u relative to a rail moved by u). The table's rows are layout.TABLE_FIELDS, the candidates' columns
  layout.GEOMETRY_FIELDS.
* Running-direction irregularities (:func:`_irregularity`): polygonal wheel R_irr = A cos(n alpha + phase), rounded
  flat, rail corrugation N_irr(x), dipped joint (irregular.py has the same formulas in numpy); a section in the
  rolling plane maximising the extra overlap over the angle beta from the lowest point, an :data:`IRR_GRID`-point
  grid then :data:`IRR_NEWTON` limited Newton steps, the extra overlap projected on the normal, the normal tilted
  by N_irr', the longitudinal curvature from the polar curvature of r(beta), floored for a concave flat;
  candidates whose gap exceeds the reach are left alone. The only implementation: providers.TableProvider.patches
  and providers.ConicalProvider's irregularities call :func:`table_candidates` and :func:`irregular_candidates`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.wheelset.layout import (
    G_APPROACH,
    G_CONTACT_ANGLE,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_LEVER,
    G_NORMAL,
    G_ROLLING_RADIUS,
    G_WHEEL_LATERAL,
    I_APPROACH,
    I_CURVATURE_LONG,
    I_NORMAL_X,
    I_NORMAL_Y,
    I_NORMAL_Z,
    I_OFFSET_X,
    I_OFFSET_Z,
    I_ROLLING_RADIUS,
    N_SECTION,
    N_TABLE_ROWS,
    T_APPROACH,
    T_APPROACH_PER_HEIGHT,
    T_CONTACT_ANGLE,
    T_CURVATURE_LAT,
    T_CURVATURE_LONG,
    T_MERGE_GAP,
    T_NORMAL_Y,
    T_NORMAL_Z,
    T_POINT_Y,
    T_POINT_Z,
    T_ROLLING_RADIUS,
    T_WHEEL_LATERAL,
)
from rigid_dynamics.wheelset.state import ROLL, SPIN, YAW, X, Y, Z
from rigid_dynamics.wheelset.track import rail_lateral_under_wheel, rail_under_wheel

IRR_GRID = 81
"""Grid points of the running-direction section over beta."""
IRR_NEWTON = 3
"""Limited Newton steps after the grid."""
MIN_LONG_CURV_FRACTION = 0.1
"""The longitudinal curvature A is floored at this fraction of the ideal wheel's 1 / (2 r0) (a concave flat;
providers.MIN_LONGITUDINAL_CURVATURE_FRACTION)."""
B_ANGLE, B_SIN, B_COS = range(3)
"""Rows of the section's angle grid: beta, sin beta, cos beta."""


class TableGeometry(NamedTuple):
    """The tables mode's record: providers.TableProvider's table (layout.TABLE_FIELDS, candidates, roll,
    lateral shift) on its uniform grids and the candidates' slots.
    """

    table: np.ndarray
    lateral_start_m: float
    lateral_step_m: float
    lateral_points: int
    roll_start_rad: float
    roll_step_rad: float
    roll_points: int
    slots: np.ndarray


class TableScratch(NamedTuple):
    """Scratch of the tables mode: the looked-up rows (layout.TABLE_FIELDS, candidates), one section's result
    (layout.SECTION_FIELDS) and the section's angle grid (:data:`B_ANGLE`, :data:`B_SIN`, :data:`B_COS`).
    """

    work: np.ndarray
    section: np.ndarray
    beta_grid: np.ndarray


def table_geometry(provider) -> TableGeometry:
    """The :class:`TableGeometry` of a providers.TableProvider."""
    yg, rg = provider.y_grid, provider.roll_grid
    return TableGeometry(
        np.ascontiguousarray(provider.table),
        float(yg[0]),
        float(yg[1] - yg[0]),
        len(yg),
        float(rg[0]),
        float(rg[1] - rg[0]),
        len(rg),
        np.asarray(provider.slot, np.int64),
    )


def no_table_geometry(slots) -> TableGeometry:
    """A :class:`TableGeometry` of the right types for the modes that do not read it."""
    return TableGeometry(np.zeros((N_TABLE_ROWS, 4, 2, 2)), 0.0, 1.0, 2, 0.0, 1.0, 2, slots)


@njit(cache=True)
def table_scratch(par, ncand):
    """A :class:`TableScratch` for ``ncand`` candidates (the angle grid from the parameter record's half angle)."""
    bg = np.empty((3, IRR_GRID))
    step_b = 2.0 * par.section_half_angle_rad / (IRR_GRID - 1)
    for g in range(IRR_GRID):
        bg[B_ANGLE, g] = g * step_b - par.section_half_angle_rad
        bg[B_SIN, g] = math.sin(bg[B_ANGLE, g])
        bg[B_COS, g] = math.cos(bg[B_ANGLE, g])
    return TableScratch(np.empty((N_TABLE_ROWS, ncand)), np.empty(N_SECTION), bg)


@njit(cache=True, _nrt=False)
def _lookup(geometry, y, roll, out):
    """The table's rows of every candidate at (roll, y), bilinear, clamped to the grid, into out (rows, ncand)."""
    table = geometry.table
    y0, dy, ny = geometry.lateral_start_m, geometry.lateral_step_m, geometry.lateral_points
    r0, dr, nr = geometry.roll_start_rad, geometry.roll_step_rad, geometry.roll_points
    fy = (min(max(y, y0), y0 + (ny - 1) * dy) - y0) / dy
    j = min(int(fy), ny - 2)
    wy = fy - j
    fr = (min(max(roll, r0), r0 + (nr - 1) * dr) - r0) / dr
    i = min(int(fr), nr - 2)
    wr = fr - i
    nq, nc = table.shape[0], table.shape[1]
    for q in range(nq):
        for c in range(nc):
            out[q, c] = (1 - wr) * ((1 - wy) * table[q, c, i, j] + wy * table[q, c, i, j + 1]) + wr * (
                (1 - wy) * table[q, c, i + 1, j] + wy * table[q, c, i + 1, j + 1]
            )


@njit(cache=True, _nrt=False)
def _dip(par, x):
    """The dipped joint's N_irr(x) and two derivatives (irregular.rail_irregularity, same formula)."""
    alpha = 0.5 * par.dip_angle_rad
    u = x - par.dip_position_m
    length = par.dip_ramp_length_m
    n0, n1, n2 = 0.0, 0.0, 0.0
    for k in range(3):
        if k == 0:
            shift, weight, e = length, 0.5, par.dip_entry_rounding_m
        elif k == 1:
            shift, weight, e = -length, 0.5, par.dip_entry_rounding_m
        else:
            shift, weight, e = 0.0, -1.0, par.dip_rounding_m
        v = u - shift
        root = math.sqrt(v * v + e * e)
        n0 += alpha * weight * root
        n1 += alpha * weight * v / root
        n2 += alpha * weight * e * e / root**3
    return n0, n1, n2


@njit(cache=True, _nrt=False)
def _irr_parts(par, radius, x0, spin, beta):
    """The running-direction section's parts for one candidate and one beta: (q, q', q'', r, r', r'', x offset,
    N_irr', N_irr'').
    """
    rv, r1, r2 = 0.0, 0.0, 0.0
    alpha = 0.5 * math.pi + beta - spin
    if par.polygon_order > 0 and par.polygon_amplitude_m > 0:
        n, amp = par.polygon_order, par.polygon_amplitude_m
        arg = n * alpha + par.polygon_phase_rad
        rv += amp * math.cos(arg)
        r1 += -amp * n * math.sin(arg)
        r2 += -amp * n * n * math.cos(arg)
    if par.flat_length_m > 0:
        length, depth, r0 = par.flat_length_m, par.flat_depth_m, par.nominal_radius_m
        u = alpha - par.flat_angle_rad + math.pi
        s = r0 * ((u - 2 * math.pi * math.floor(u / (2 * math.pi))) - math.pi)
        if abs(s) < 0.5 * length:
            k = 2 * math.pi / length
            rv += -0.5 * depth * (1 + math.cos(k * s))
            r1 += 0.5 * depth * k * math.sin(k * s) * r0
            r2 += 0.5 * depth * k * k * math.cos(k * s) * r0 * r0
    r = radius + rv
    sb, cb = math.sin(beta), math.cos(beta)
    xo = -r * sb
    x1 = -(r1 * sb + r * cb)
    x2 = -(r2 * sb + 2 * r1 * cb - r * sb)
    n0, n1, n2 = 0.0, 0.0, 0.0
    if par.corrugation_amplitude_m > 0:
        kc, amp = 2 * math.pi / par.corrugation_wavelength_m, par.corrugation_amplitude_m
        xx = x0 + xo
        n0, n1, n2 = amp * math.cos(kc * xx), -amp * kc * math.sin(kc * xx), -amp * kc * kc * math.cos(kc * xx)
    if par.dip_angle_rad > 0:
        d0, d1, d2 = _dip(par, x0 + xo)
        n0 += d0
        n1 += d1
        n2 += d2
    q = r * cb - radius - n0
    q1 = r1 * cb - r * sb - n1 * x1
    q2 = r2 * cb - 2 * r1 * sb - r * cb - n2 * x1 * x1 - n1 * x2
    return q, q1, q2, r, r1, r2, xo, n1, n2


@njit(cache=True, _nrt=False)
def _irr_q(par, radius, x0, spin, beta, sin_beta, cos_beta):
    """The extra overlap q(beta) of _irr_parts alone (the same arithmetic; for the grid stage, whose sin and cos
    of beta are tabulated once).
    """
    rv = 0.0
    alpha = 0.5 * math.pi + beta - spin
    if par.polygon_order > 0 and par.polygon_amplitude_m > 0:
        rv += par.polygon_amplitude_m * math.cos(par.polygon_order * alpha + par.polygon_phase_rad)
    if par.flat_length_m > 0:
        length, depth, r0 = par.flat_length_m, par.flat_depth_m, par.nominal_radius_m
        u = alpha - par.flat_angle_rad + math.pi
        s = r0 * ((u - 2 * math.pi * math.floor(u / (2 * math.pi))) - math.pi)
        if abs(s) < 0.5 * length:
            rv += -0.5 * depth * (1 + math.cos(2 * math.pi / length * s))
    r = radius + rv
    n0 = 0.0
    if par.corrugation_amplitude_m > 0:
        n0 = par.corrugation_amplitude_m * math.cos(2 * math.pi / par.corrugation_wavelength_m * (x0 - r * sin_beta))
    if par.dip_angle_rad > 0:
        n0 += _dip(par, x0 - r * sin_beta)[0]
    return r * cos_beta - radius - n0


@njit(cache=True, _nrt=False)
def _irregularity(par, work, c, q, x0, spin, geo, bg):
    """Running-direction irregularity of candidate c (its table rows in ``work``, approach q, contact point at x0;
    a grid of IRR_GRID angles, then IRR_NEWTON limited Newton steps; derivation in the module docstring): fills geo
    (layout.SECTION_FIELDS). bg: the grid angles (as np.linspace(-half, half, IRR_GRID)), their sines and cosines.
    """
    half = par.section_half_angle_rad
    radius = work[T_ROLLING_RADIUS, c]
    best, beta = -np.inf, 0.0
    for g in range(IRR_GRID):
        qb = _irr_q(par, radius, x0, spin, bg[B_ANGLE, g], bg[B_SIN, g], bg[B_COS, g])
        if qb > best:
            best, beta = qb, bg[B_ANGLE, g]
    step_size = 2 * half / (IRR_GRID - 1)
    for _ in range(IRR_NEWTON):
        _, q1, q2, _, _, _, _, _, _ = _irr_parts(par, radius, x0, spin, beta)
        step = -q1 / q2 if q2 < 0 else 0.0
        beta = min(max(beta + min(max(step, -step_size), step_size), -half), half)
    qv, _, _, r, r1, r2, xo, n1, n2 = _irr_parts(par, radius, x0, spin, beta)
    kappa_w = (r * r + 2 * r1 * r1 - r * r2) / (r * r + r1 * r1) ** 1.5
    scale = 2.0 * work[T_CURVATURE_LONG, c] * radius
    a_long = 0.5 * (kappa_w * scale + n2 / (1 + n1 * n1) ** 1.5)
    ny_, nz_ = work[T_NORMAL_Y, c], work[T_NORMAL_Z, c]
    nn = math.sqrt(ny_ * ny_ + nz_ * nz_)
    slope_y = (ny_ / nn) / (-nz_ / nn)
    norm = math.sqrt(n1 * n1 + slope_y * slope_y + 1.0)
    geo[I_APPROACH] = q + qv * (-nz_ / nn)
    geo[I_OFFSET_X] = xo
    geo[I_OFFSET_Z] = r * math.cos(beta) - radius
    geo[I_NORMAL_X], geo[I_NORMAL_Y], geo[I_NORMAL_Z] = n1 / norm, slope_y / norm, -1.0 / norm
    geo[I_ROLLING_RADIUS] = r
    geo[I_CURVATURE_LONG] = max(a_long, MIN_LONG_CURV_FRACTION * 0.5 / par.nominal_radius_m)


@njit(cache=True, _nrt=False)
def _table_geometry(y, par, geometry, sides, scratch, cg):
    """Candidate geometry from the tables (providers.TableProvider) and the running-direction irregularities,
    into cg (ncand, layout.N_GEO).
    """
    rails = (rail_under_wheel(par, y, 0)[0], rail_under_wheel(par, y, 1)[0])
    lat0, _ = rail_lateral_under_wheel(par, y, 0)
    lat1, _ = rail_lateral_under_wheel(par, y, 1)
    passes = 2 if par.lateral_track > 0.5 else 1
    for sweep in range(passes):
        # a rail moved laterally by u: the wheelset at y - u relative to that rail (one look-up per side)
        _lookup(geometry, y[Y] - (0.0 if passes == 1 else (lat0 if sweep == 0 else lat1)), y[ROLL], scratch.work)
        _table_candidates(y, par, geometry.slots, sides, scratch, rails, sweep if passes == 2 else -1, cg)


@njit(cache=True, _nrt=False)
def _table_candidates(y, par, slots, sides, scratch, rails, only_side, cg):
    """The candidates of _table_geometry from one look-up in ``scratch.work``: all of them (``only_side`` -1) or
    those of side ``only_side`` (the lateral track: one look-up per side). rails: the rail deflections (left,
    right).
    """
    work = scratch.work
    xc, zc = y[X], y[Z]
    sps = math.sin(y[YAW])
    zref = par.z_ref_m
    for c in range(cg.shape[0]):
        if only_side >= 0 and sides[c] != only_side:
            continue
        zs = zc - rails[sides[c]]  # the rail lowered by w: the centre raised for this side
        q = work[T_APPROACH, c] + (zs - zref) * work[T_APPROACH_PER_HEIGHT, c]
        if slots[c] > 0 and work[T_MERGE_GAP, c] + (zs - zref) * work[T_APPROACH_PER_HEIGHT, c] > 0:
            q = -0.01
        ny_, nz_ = work[T_NORMAL_Y, c], work[T_NORMAL_Z, c]
        nn = math.sqrt(ny_ * ny_ + nz_ * nz_)
        g = cg[c]
        g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2] = 0.0, ny_ / nn, nz_ / nn
        g[G_LEVER] = -sps * work[T_WHEEL_LATERAL, c]
        g[G_LEVER + 1], g[G_LEVER + 2] = work[T_POINT_Y, c], work[T_POINT_Z, c]
        g[G_CURVATURE_LONG], g[G_CURVATURE_LAT] = work[T_CURVATURE_LONG, c], work[T_CURVATURE_LAT, c]
        g[G_ROLLING_RADIUS] = work[T_ROLLING_RADIUS, c]
        g[G_WHEEL_LATERAL], g[G_CONTACT_ANGLE] = work[T_WHEEL_LATERAL, c], work[T_CONTACT_ANGLE, c]
        if (
            par.irregular > 0
            and q > -par.irregularity_reach_m
            and (par.irregular_right if sides[c] == 1 else par.irregular_left) > 0
        ):
            geo = scratch.section
            _irregularity(par, work, c, q, xc + g[G_LEVER], y[SPIN], geo, scratch.beta_grid)
            q = geo[I_APPROACH]
            g[G_LEVER] += geo[I_OFFSET_X]
            g[G_LEVER + 2] += geo[I_OFFSET_Z]
            g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2] = geo[I_NORMAL_X], geo[I_NORMAL_Y], geo[I_NORMAL_Z]
            g[G_ROLLING_RADIUS], g[G_CURVATURE_LONG] = geo[I_ROLLING_RADIUS], geo[I_CURVATURE_LONG]
        g[G_APPROACH] = q


@njit(cache=True)
def table_candidates(y, par, geometry, sides, cg):
    """The tables' candidates (with the running-direction irregularities of par) at the pose in y into cg
    (ncand, layout.N_GEO): :func:`_table_geometry` for providers.TableProvider.patches (inspection, tests).
    """
    _table_geometry(y, par, geometry, sides, table_scratch(par, sides.shape[0]), cg)


@njit(cache=True)
def irregular_candidates(par, work, sides, x0, spin, cg):
    """The running-direction irregularities (:func:`_irregularity`) added to candidates given as table rows ``work``
    (layout.TABLE_FIELDS; the approach, the normal's y and z, A and the rolling radius are read) at contact points
    x0 (ncand), the spin angle ``spin``: into cg (ncand, layout.N_SECTION); rows of candidates left alone (side not
    irregular, gap beyond the reach) are NaN. For providers.ConicalProvider.
    """
    bg = table_scratch(par, sides.shape[0]).beta_grid
    for c in range(sides.shape[0]):
        cg[c, :] = np.nan
        q = work[T_APPROACH, c]
        if q > -par.irregularity_reach_m and (par.irregular_right if sides[c] == 1 else par.irregular_left) > 0:
            _irregularity(par, work, c, q, x0[c], spin, cg[c], bg)


def irregularity_parameters(par, irr, sides_mask, r0: float) -> None:
    """The running-direction irregularities ``irr`` (polygon, rounded flat, corrugation, dipped joint) on the sides of
    ``sides_mask`` (left, right) into the parameter record, with the section's reach and half angle.
    """
    from rigid_dynamics.wheelset.irregular import dip_depth_m, flat_depth_m

    par["nominal_radius_m"] = r0
    par["irregular"] = 1.0
    par["irregular_left"], par["irregular_right"] = (float(v) for v in sides_mask)
    par["polygon_order"], par["polygon_amplitude_m"], par["polygon_phase_rad"] = (
        irr.polygon_order,
        irr.polygon_amplitude_m,
        irr.polygon_phase_rad,
    )
    reach = 2.0 * (irr.polygon_amplitude_m + irr.corrugation_amplitude_m) + 1e-4
    half = 0.02
    if irr.flat_length_m > 0:
        depth = flat_depth_m(irr, r0)
        par["flat_length_m"], par["flat_depth_m"], par["flat_angle_rad"] = irr.flat_length_m, depth, irr.flat_angle_rad
        reach += 2.0 * depth
        half = max(half, 1.5 * irr.flat_length_m / r0)
    if irr.corrugation_amplitude_m > 0:
        par["corrugation_wavelength_m"] = irr.corrugation_wavelength_m
        par["corrugation_amplitude_m"] = irr.corrugation_amplitude_m
        half = max(half, 0.6 * irr.corrugation_wavelength_m / r0)
    if irr.joint_dip_angle_rad > 0:
        par["dip_angle_rad"], par["dip_position_m"] = irr.joint_dip_angle_rad, irr.joint_position_m
        par["dip_ramp_length_m"] = irr.joint_ramp_length_m
        par["dip_entry_rounding_m"], par["dip_rounding_m"] = irr.joint_entry_rounding_m, irr.joint_rounding_m
        reach += 2.0 * dip_depth_m(irr)
    par["irregularity_reach_m"], par["section_half_angle_rad"] = reach, half
