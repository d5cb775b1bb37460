"""The one right-hand side of the wheelset simulation (numba), its fixed-step RK4 loop and the callback boundary.

Every integrator ends here: the compiled RK4 loop (:func:`rk4_run`), the compiled DP54/BS32 pairs
(compiled_adaptive.py), and the scipy methods and the Python RK4 through equations.WheelsetModel.derivative, which
calls :func:`rhs_once` / :func:`rhs_given`.

* Contact geometry (:func:`_rhs`, the ``mode`` of :func:`geometry_mode`): 0 the tables of a TableProvider
  (:func:`_table_geometry`) with the running-direction irregularities (:func:`_irregularity`: polygonal wheel
  R_irr = A cos(n alpha + phase), rounded flat, rail corrugation N_irr(x), dipped joint; irregular.py; a section in
  the rolling plane maximising the extra overlap over the angle beta from the lowest point, 81-point grid then 3
  limited Newton steps, the extra overlap projected on the normal, the normal tilted by N_irr', the longitudinal
  curvature from the polar curvature of r(beta), floored for a concave flat; candidates whose gap exceeds the reach
  are left alone); 1 the compiled 3-D search (compiled_search.py); 2 given by the caller (a provider the compiled
  code does not evaluate: the conical one, the search on measured grids or harmonics, user providers, and the
  search outside the compiled loop). TableProvider.patches and ConicalProvider's irregularities use these same
  functions (:func:`table_candidates`, :func:`irregular_candidates`).
* Creepages (:func:`_patch_creepages`, eq 39-49).
* Contact laws (:func:`_law`): Hertz and Kalker's C_ij from the tables of equations.TabulatedHertzKalker, and the
  registry's ``hertz`` (no creep force), ``linear`` (Kalker's linear theory, eq 50-52), ``vermeulen-johnson``
  (eq 53-58 with the cube) and ``fastsim`` (the contact package's strip kernel contact.fastsim._fastsim_one with the
  flexibilities of contact.fastsim.effective_flexibilities; options nx, ny, traction_bound, flexibility), and
  ``auto``'s choice per patch (:func:`_auto_choice`, the measured thresholds of contact/data/auto_thresholds.json
  in the parameter record).
* The callback boundary (:func:`_external`): contact models that are not compiled (bem, fea, user models; BEM when
  ``auto`` chooses it) get the patch geometry and creepages handed out patch-wise to one Python dispatcher
  (equations.PatchCallback) and give the forces back.
* The equations of motion (eq 59-71 with the gyroscopic term), the suspension and the track (:func:`_assemble`;
  the track's equations, data and parameter fields are those of :mod:`rigid_dynamics.wheelset.track`: a track model
  is added there, in state.py's layout and in :func:`_assemble`'s call).

Elastic track (scene ``track_dynamics.model = "lumped"``): the 8 track states follow the two work integrals
(state.TRACK); the candidate geometry is evaluated with the wheelset centre raised by that side's rail
deflection (tables: q = q_ref + (z - z_r - z_ref) dq/dz; search: the side's search at the raised centre), the
creepages and the contact power use the velocity relative to the rail, and the track's equations are those of
:func:`rigid_dynamics.wheelset.track.track_rates`.

Curves and cant (scene ``[track] curve_direction``, ``curve_radius_m``, ``cant_m``; ``par.track_frame``): the states
are relative to a frame following the track; :func:`_assemble_curve` adds the frame's terms to Newton and Euler and
:func:`_forces` takes the creepages from the absolute velocities (straight track without cant: bit-identical code
path to before).

Parameters: one record with named fields (:data:`PARAMETERS`, a numpy structured dtype that numba compiles;
``par.mass_kg``), built by :func:`pack`. Chosen by measured overhead: a kernel reading 16 parameters, called 2e7
times in a compiled loop, took 49.8 ns per call with the former float vector and index constants, 49.2 ns with the
structured record, 48.2 ns with a jitclass and 51.7 ns with a structref (one session, noise ~5 %): no difference.
The record keeps numba's on-disk cache working (with a jitclass or structref argument every new process missed the
cache, recompiled and appended a cache entry: numba 0.68, measured here) and is a plain numpy array (set from
Python as ``par["frame_x0_m"] = ...``). The state is indexed by the names of state.py (``y[RAIL_VELOCITY + side]``).

Status codes of the loop: 0 ok, 1 non-finite state (blow-up), 2 force anomaly, 3 derailed, 4 creepages undefined,
5 the contact model behind the callback failed (its message in the callback).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, objmode

from rigid_dynamics.contact.fastsim import _fastsim_one
from rigid_dynamics.wheelset import track
from rigid_dynamics.wheelset.compiled_search import N_GEO, search_geometry, search_geometry_on_track
from rigid_dynamics.wheelset.state import (
    WORK_CONTACT,
    WORK_EXTERIOR,
    n_states,
)
from rigid_dynamics.wheelset.track import rail_lateral_under_wheel, rail_under_wheel
from rigid_dynamics.wheelset.track import track_rates as _track_rates

MODEL_CODES = {"hertz": 0, "linear": 1, "vermeulen-johnson": 2, "fastsim": 3}
"""The creep laws written here (registry names -> ``model_code``)."""
CALLBACK_CODE = 4
"""``model_code`` of a contact model that is not compiled (bem, fea, user models): every patch through the callback."""
AUTO_CODE = 5
"""``model_code`` of ``auto``: the rung chosen per patch in the loop; linear, Vermeulen-Johnson and FASTSIM inline,
BEM through the callback."""
CALLBACK_FAILED = 5
"""Status of the right-hand side when the contact model behind the callback failed (its message: the callback's)."""
FLEX_CODES = {"three": 0, "single": 1, "three-unblended": 2}
N_PATCH = 14  # equations.PATCH_FIELDS, in that order
N_AUTO = 9  # equations.AUTO_PATCH_FIELDS, in that order, after them
N_FIELDS = N_PATCH + N_AUTO
AUTO_FEATURE_NAMES = ("saturation", "spin_share", "ellipticity_residual", "curvature_change", "second_patch_nearness")
AUTO_RUNG_NAMES = ("linear", "vermeulen_johnson", "fastsim")

PARAMETER_FIELDS = (
    ("mass_kg", "wheelset mass"),
    ("inertia_transverse_kg_m2", "roll/yaw moment of inertia (body frame)"),
    ("inertia_axial_kg_m2", "spin moment of inertia"),
    ("gravity_m_per_s2", "gravity, z down"),
    ("suspension_kx_N_per_m", "primary stiffness x per side"),
    ("suspension_ky_N_per_m", "primary stiffness y per side"),
    ("suspension_kz_N_per_m", "primary stiffness z per side"),
    ("suspension_cx_N_s_per_m", "primary damping x per side"),
    ("suspension_cy_N_s_per_m", "primary damping y per side"),
    ("suspension_cz_N_s_per_m", "primary damping z per side"),
    ("yaw_stiffness_N_m_per_rad", "yaw stiffness per side"),
    ("yaw_damping_N_m_s_per_rad", "yaw damping per side"),
    ("suspension_half_spacing_m", "lateral half spacing of the springs"),
    ("frame_z_m", "frame height (spring attachment)"),
    ("frame_x0_m", "frame x at t = 0 (moves at speed_m_per_s)"),
    ("speed_m_per_s", "running speed"),
    ("axle_load_N", "axle load, z down"),
    ("torque_N_m", "driving/braking torque about the axle"),
    ("shear_modulus_Pa", "combined shear modulus G"),
    ("contact_modulus_Pa", "E* of Hertz"),
    ("friction_coefficient", "friction coefficient"),
    ("model_code", "MODEL_CODES value"),
    ("z_ref_m", "table reference centre height"),
    ("max_force_N", "force anomaly limit"),
    ("max_lateral_m", "derailment limit |y|"),
    ("fastsim_nx", "FASTSIM elements per strip"),
    ("fastsim_ny", "FASTSIM strips"),
    ("fastsim_parabolic", "1: parabolic traction bound"),
    ("flexibility_code", "FLEX_CODES value"),
    ("irregular", "1: running-direction irregularities on"),
    ("nominal_radius_m", "nominal rolling radius"),
    ("polygon_order", "polygon order"),
    ("polygon_amplitude_m", "polygon amplitude"),
    ("polygon_phase_rad", "polygon phase"),
    ("flat_length_m", "flat length"),
    ("flat_depth_m", "flat depth"),
    ("flat_angle_rad", "flat position"),
    ("corrugation_wavelength_m", "corrugation wavelength"),
    ("corrugation_amplitude_m", "corrugation amplitude"),
    ("irregular_left", "1: left side irregular"),
    ("irregular_right", "1: right side irregular"),
    ("irregularity_reach_m", "gap beyond which a candidate is left alone"),
    ("section_half_angle_rad", "half range of the running-direction section"),
    *track.PARAMETER_FIELDS,
    ("dip_angle_rad", "joint dip angle"),
    ("dip_position_m", "joint position"),
    ("dip_ramp_length_m", "joint ramp length"),
    ("dip_entry_rounding_m", "joint entry rounding"),
    ("dip_rounding_m", "joint rounding"),
    ("track_frame", "1: curve or cant: the track-following frame's terms (_assemble, _forces) are on"),
    ("curvature_1_per_m", "signed curvature of the centreline, +1/R right curve"),
    ("cant_sin", "sin of the signed cant angle (> 0: left rail higher)"),
    ("cant_cos", "cos of the cant angle"),
    ("carried_mass_kg", "axle load / g: the mass whose quasi-static gravity and centrifugal load acts at the axle"),
    ("auto_level", "auto: the tolerance level whose thresholds apply (NaN: below every level, always BEM)"),
    ("auto_friction_bound_tolerance", "auto: FASTSIM above (1 + this) mu N is replaced by BEM (models.py)"),
    *(
        (f"auto_{r}_{f}", f"auto: threshold of {f} for {r} (NaN: no measured box)")
        for r in AUTO_RUNG_NAMES
        for f in AUTO_FEATURE_NAMES
    ),
)
"""The parameter record of the compiled right-hand side: (field, meaning); every field float64, SI units."""

PARAMETERS = np.dtype([(n, np.float64) for n, _ in PARAMETER_FIELDS])
"""numpy structured dtype of the parameter record: numba compiles ``par.mass_kg`` to a load at a fixed offset
(measured: no slower than the former index constants into a float vector; see :func:`new_parameters`)."""


def new_parameters():
    """A zeroed parameter record (a numpy record of :data:`PARAMETERS`; set fields as ``par["mass_kg"] = ...``)."""
    return np.zeros(1, PARAMETERS)[0]


IRR_GRID = 81  # grid points of the running-direction section
IRR_NEWTON = 3  # Newton steps after the grid
MIN_LONG_CURV_FRACTION = 0.1  # providers.MIN_LONGITUDINAL_CURVATURE_FRACTION


@njit(cache=True, _nrt=False)
def _lookup(table, y0, dy, ny, r0, dr, nr, y, roll, out):
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
def _uniform(x, x0, step, n):
    f = (x - x0) / step
    if f < 0.0:
        f = 0.0
    if f > n - 1.0:
        f = n - 1.0
    i = min(int(f), n - 2)
    return i, f - i


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
def _irr_parts(par, radius, x0, spin, beta, res):
    """The running-direction section's parts for one candidate and one beta, into res[0:9]:
    (q, q', q'', r, r', r'', x offset, N_irr', N_irr'').
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
    res[0] = r * cb - radius - n0
    res[1] = r1 * cb - r * sb - n1 * x1
    res[2] = r2 * cb - 2 * r1 * sb - r * cb - n2 * x1 * x1 - n1 * x2
    res[3], res[4], res[5], res[6], res[7], res[8] = r, r1, r2, xo, n1, n2


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
def _irregularity(par, work, c, q, x0, spin, res, geo, bg):
    """Running-direction irregularity of one candidate (a grid of IRR_GRID angles, then IRR_NEWTON limited Newton
    steps; derivation in the module docstring; the only implementation: the conical and table providers use it
    too). Fills geo = (q, x offset, z offset, n_x, n_y, n_z,
    rolling radius, A) for the candidate. bg: the grid angles (as np.linspace(-half, half, IRR_GRID)), their sines
    and cosines (3, IRR_GRID).
    """
    half = par.section_half_angle_rad
    radius = work[8, c]
    best, beta = -np.inf, 0.0
    for g in range(IRR_GRID):
        qb = _irr_q(par, radius, x0, spin, bg[0, g], bg[1, g], bg[2, g])
        if qb > best:
            best, beta = qb, bg[0, g]
    step_size = 2 * half / (IRR_GRID - 1)
    for _ in range(IRR_NEWTON):
        _irr_parts(par, radius, x0, spin, beta, res)
        step = -res[1] / res[2] if res[2] < 0 else 0.0
        beta = min(max(beta + min(max(step, -step_size), step_size), -half), half)
    _irr_parts(par, radius, x0, spin, beta, res)
    qv, r, r1, r2, xo, n1, n2 = res[0], res[3], res[4], res[5], res[6], res[7], res[8]
    kappa_w = (r * r + 2 * r1 * r1 - r * r2) / (r * r + r1 * r1) ** 1.5
    scale = 2.0 * work[6, c] * radius
    a_long = 0.5 * (kappa_w * scale + n2 / (1 + n1 * n1) ** 1.5)
    ny_, nz_ = work[4, c], work[5, c]
    nn = math.sqrt(ny_ * ny_ + nz_ * nz_)
    slope_y = (ny_ / nn) / (-nz_ / nn)
    norm = math.sqrt(n1 * n1 + slope_y * slope_y + 1.0)
    geo[0] = q + qv * (-nz_ / nn)
    geo[1] = xo
    geo[2] = r * math.cos(beta) - radius
    geo[3], geo[4], geo[5] = n1 / norm, slope_y / norm, -1.0 / norm
    geo[6] = r
    geo[7] = max(a_long, MIN_LONG_CURV_FRACTION * 0.5 / par.nominal_radius_m)


@njit(cache=True, _nrt=False)
def _flexibilities(par, a, b, normal, xi, eta, spin, c11, c22, c23):
    """fastsim.effective_flexibilities for one patch (variants three / single / three-unblended)."""
    g = par.shear_modulus_Pa
    l1 = 8.0 * a / (3.0 * c11 * g)
    l2 = 8.0 * a / (3.0 * c22 * g)
    l3 = math.pi * a * math.sqrt(a / b) / (4.0 * c23 * g)
    flex = par.flexibility_code
    if flex == 2:
        return l1, l2, l3
    ab = a * b
    if flex == 1:
        num = l1 * abs(xi) + l2 * abs(eta) + l3 * abs(spin) * math.sqrt(ab)
        den = math.sqrt(xi**2 + eta**2 + ab * spin**2)
        single = num / den if den > 0 else l1
        return single, single, single
    cc = 3.0 * math.pi * a / 32.0
    cp2 = (cc * spin) ** 2
    num = xi**2 + eta**2 + cp2
    den = xi**2 / l1 + eta**2 / l2 + cp2 / l3
    l_comb = num / den if den > 0 else l1
    force = par.friction_coefficient * normal
    ch2 = (force / (g * ab * c11)) ** 2 + (force / (g * ab * c22)) ** 2 + (force / (g * ab**1.5 * c23)) ** 2
    f_crp = math.sqrt((xi**2 + eta**2 + spin**2) / ch2) if ch2 > 0 else np.inf
    w = min(max(f_crp / 3.0, 0.0), 1.0)
    return (1 - w) * l1 + w * l_comb, (1 - w) * l2 + w * l_comb, (1 - w) * l3 + w * l_comb


@njit(cache=True, _nrt=False)
def _table_geometry(y, par, table, grid, slots, sides, work, res, geo, bg, cg):
    """Candidate geometry from the tables (providers.TableProvider) and the running-direction irregularities,
    into cg (ncand, N_GEO) (q, lever, normal, A, B, rolling radius, wheel lateral, contact angle).
    """
    yc = y[1]
    sps = math.sin(y[3])
    zref = par.z_ref_m
    rail0, _ = rail_under_wheel(par, y, 0)
    rail1, _ = rail_under_wheel(par, y, 1)
    lat0, _ = rail_lateral_under_wheel(par, y, 0)
    lat1, _ = rail_lateral_under_wheel(par, y, 1)
    passes = 2 if par.lateral_track > 0.5 else 1
    for sweep in range(passes):
        # a rail moved laterally by u: the wheelset at y - u relative to that rail (one look-up per side)
        _lookup(
            table, grid[0], grid[1], int(grid[2]), grid[3], grid[4], int(grid[5]),
            yc - (0.0 if passes == 1 else (lat0 if sweep == 0 else lat1)), y[4], work,
        )  # fmt: skip
        _table_candidates(y, par, slots, sides, work, res, geo, bg, cg, sps, zref, rail0, rail1, sweep, passes)


@njit(cache=True, _nrt=False)
def _table_candidates(y, par, slots, sides, work, res, geo, bg, cg, sps, zref, rail0, rail1, sweep, passes):
    """The candidates of _table_geometry from one look-up in ``work``: all of them (``passes`` 1) or those of side
    ``sweep`` (the lateral track: one look-up per side).
    """
    xc, zc = y[0], y[2]
    for c in range(cg.shape[0]):
        if passes == 2 and sides[c] != sweep:
            continue
        zs = zc - (rail0 if sides[c] == 0 else rail1)  # the rail lowered by w: the centre raised for this side
        q = work[0, c] + (zs - zref) * work[1, c]
        if slots[c] > 0 and work[11, c] + (zs - zref) * work[1, c] > 0:
            q = -0.01
        ny_, nz_ = work[4, c], work[5, c]
        nn = math.sqrt(ny_ * ny_ + nz_ * nz_)
        g = cg[c]
        g[4], g[5], g[6] = 0.0, ny_ / nn, nz_ / nn
        g[1], g[2], g[3] = -sps * work[10, c], work[2, c], work[3, c]
        g[7], g[8], g[9] = work[6, c], work[7, c], work[8, c]
        g[10], g[11] = work[10, c], work[9, c]
        if (
            par.irregular > 0
            and q > -par.irregularity_reach_m
            and (par.irregular_right if sides[c] == 1 else par.irregular_left) > 0
        ):
            _irregularity(par, work, c, q, xc + g[1], y[5], res, geo, bg)
            q = geo[0]
            g[1] += geo[1]
            g[3] += geo[2]
            g[4], g[5], g[6] = geo[3], geo[4], geo[5]
            g[9], g[7] = geo[6], geo[7]
        g[0] = q


@njit(cache=True, _nrt=False)
def _patch_creepages(lever, n, om, vx, vy, vz, rail_vy, rail_vz, vel, ex, ey):
    """Contact frame and creepages of one patch (eq 39-49; the formulas of contact.creepage): e_x = v_p/|v_p| with
    v_p the rolling velocity [x', 0, 0] projected on the contact plane, e_y = n x e_x; V = |v_p|; xi = v_w . e_x / V,
    eta = v_w . e_y / V, spin = omega . n / V with v_w = x_t' + omega x r_con (eq 44) less the rail's vertical
    velocity ``rail_vz`` and lateral velocity ``rail_vy``. Fills vel (v_w), ex, ey; returns (V, xi, eta, spin); V
    not > 0: creepages undefined
    (xi, eta, spin 0, ex, ey not set).
    """
    vel[0] = vx + om[1] * lever[2] - om[2] * lever[1]
    vel[1] = vy + om[2] * lever[0] - om[0] * lever[2]
    vel[2] = vz + om[0] * lever[1] - om[1] * lever[0]
    vel[1] -= rail_vy
    vel[2] -= rail_vz
    nv = n[0] * vx
    vp0, vp1, vp2 = vx - nv * n[0], 0.0 - nv * n[1], 0.0 - nv * n[2]
    speed = math.sqrt(vp0**2 + vp1**2 + vp2**2)
    if not speed > 0.0:
        return speed, 0.0, 0.0, 0.0
    ex[0], ex[1], ex[2] = vp0 / speed, vp1 / speed, vp2 / speed
    ey[0] = n[1] * ex[2] - n[2] * ex[1]
    ey[1] = n[2] * ex[0] - n[0] * ex[2]
    ey[2] = n[0] * ex[1] - n[1] * ex[0]
    xi = (vel[0] * ex[0] + vel[1] * ex[1] + vel[2] * ex[2]) / speed
    eta = (vel[0] * ey[0] + vel[1] * ey[1] + vel[2] * ey[2]) / speed
    spin = (om[0] * n[0] + om[1] * n[1] + om[2] * n[2]) / speed
    return speed, xi, eta, spin


@njit(cache=True)
def patch_creepages(lever, normal, om, v_c, rail_vy, rail_vz, frames, out):
    """:func:`_patch_creepages` of n patches for the Python right-hand side: lever, normal (n, 3), angular velocity
    om (3), centre velocity v_c (3), rail lateral and vertical velocity per patch (n); frames (n, 3, 3) get the
    columns e_x, e_y, n, out (4, n) the rows V, xi, eta, spin (NaN where V is not > 0).
    """
    vel, ex, ey = np.empty(3), np.empty(3), np.empty(3)
    for k in range(lever.shape[0]):
        speed, xi, eta, spin = _patch_creepages(
            lever[k], normal[k], om, v_c[0], v_c[1], v_c[2], rail_vy[k], rail_vz[k], vel, ex, ey
        )
        if not speed > 0.0:
            xi = eta = spin = ex[0] = ex[1] = ex[2] = ey[0] = ey[1] = ey[2] = np.nan
        out[0, k], out[1, k], out[2, k], out[3, k] = speed, xi, eta, spin
        for i in range(3):
            frames[k, i, 0], frames[k, i, 1], frames[k, i, 2] = ex[i], ey[i], normal[k, i]


@njit(cache=True, _nrt=False)
def _j_times(rzx, jb0, jb1, jb2, v0, v1, v2):
    """J v with J = R J_body R^T (R = R_z R_x, J_body = diag(jb0, jb1, jb2))."""
    b0 = rzx[0, 0] * v0 + rzx[1, 0] * v1 + rzx[2, 0] * v2
    b1 = rzx[0, 1] * v0 + rzx[1, 1] * v1 + rzx[2, 1] * v2
    b2 = rzx[0, 2] * v0 + rzx[1, 2] * v1 + rzx[2, 2] * v2
    return (
        rzx[0, 0] * jb0 * b0 + rzx[0, 1] * jb1 * b1 + rzx[0, 2] * jb2 * b2,
        rzx[1, 0] * jb0 * b0 + rzx[1, 1] * jb1 * b1 + rzx[1, 2] * jb2 * b2,
        rzx[2, 0] * jb0 * b0 + rzx[2, 1] * jb1 * b1 + rzx[2, 2] * jb2 * b2,
    )


@njit(cache=True, _nrt=False)
def _assemble_curve(y, par, force, moment, fe0, fe1, fe2, me0, me1, me2, om, rzx, p_ext):
    """Newton and Euler in the track-following frame of a curve with cant (scene [track] curve_*, cant_m): the
    translational and angular accelerations relative to that frame, and ``p_ext`` plus the power the frame's terms
    add (returned: acc0, acc1, acc2, al0, al1, al2, p_ext).

    The frame F(x) sits at the arc length x of the track centreline (rail level), axes t (along the track), n (in the
    canted track plane, to the right), b (normal to it, down); the states are relative to it (x: arc length; y, z:
    the centre's offset from the centreline point in F; yaw, roll: Euler angles relative to F). The true vertical
    (down) in F is e_V = (0, sin c, cos c) with c the signed cant angle (> 0: left rail higher). F turns about e_V at
    Omega = kappa x' e_V (kappa = +-1/R, > 0 for a right curve). With r_c = (0, y, z) the centre's velocity is
    v = (x' h, y', z'), h = 1 + kappa (e_Vy z - e_Vz y) (the centre's own radius against the centreline's), and its
    acceleration (F components) a = (x'' h + 2 kappa x' (e_Vy z' - e_Vz y'), y'' + kappa h x'^2 e_Vz,
    z'' - kappa h x'^2 e_Vy): Newton m a = F gives the centrifugal terms. Gravity is m g e_V (the cant's lateral
    component), and the axle load becomes the quasi-static load of the carried mass M_c = axle_load / g at the
    frame's speed V: M_c (g e_V - kappa V^2 e_n,horizontal) = M_c (0, g sin c - kappa V^2 cos c,
    g cos c + kappa V^2 sin c) (its centrifugal force balanced by the cant at the balancing speed, as the wheelset's
    own). Euler with the absolute angular velocity omega_a = omega + Omega (omega relative to F, from the Euler
    rates): J omega' = M - omega_a x J omega_a + J (omega x Omega) - J Omega', Omega' = kappa x'' e_V: the
    gyroscopic couple of the spin with the frame's yaw rate V/R is in omega_a x J omega_a. The suspension (in
    _assemble) acts between the wheelset and a frame that follows the track (relative positions and velocities), the
    yaw springs about the track's tangent.

    Energy: the kinetic energy and potential of the checks are those relative to F with gravity along b (T of the
    relative velocities, -m g z); the power of everything this function changes against the straight track (the
    frame's inertial terms, gravity's cant component, the carried mass's load) is added to ``p_ext``, so that
    d(T + V_g)/dt = P_contact + P_exterior holds as on straight track.
    """
    kap, s_, c_ = par.curvature_1_per_m, par.cant_sin, par.cant_cos
    g, m, speed = par.gravity_m_per_s2, par.mass_kg, par.speed_m_per_s
    yc, zc = y[1], y[2]
    vx, vy, vz = y[6], y[7], y[8]
    h = 1.0 + kap * (s_ * zc - c_ * yc)
    mc = par.carried_mass_kg
    fs0 = force[0] + fe0
    fs1 = force[1] + fe1
    fs2 = force[2] + fe2 + m * g  # the straight track's forces (axle load along z, gravity along z)
    f0 = fs0
    f1 = force[1] + fe1 + mc * (g * s_ - kap * speed * speed * c_) + m * g * s_
    f2 = force[2] + fe2 - par.axle_load_N + mc * (g * c_ + kap * speed * speed * s_) + m * g * c_
    acc0 = (f0 / m - 2.0 * kap * vx * (s_ * vz - c_ * vy)) / h
    acc1 = f1 / m - kap * h * vx * vx * c_
    acc2 = f2 / m + kap * h * vx * vx * s_
    p_ext += m * (vx * acc0 + vy * acc1 + vz * acc2) - (vx * fs0 + vy * fs1 + vz * fs2)
    jb0, jb1, jb2 = par.inertia_transverse_kg_m2, par.inertia_axial_kg_m2, par.inertia_transverse_kg_m2
    w = kap * vx
    wd = kap * acc0
    o1, o2 = w * s_, w * c_  # Omega (its x component is 0)
    wa0, wa1, wa2 = om[0], om[1] + o1, om[2] + o2
    jw0, jw1, jw2 = _j_times(rzx, jb0, jb1, jb2, wa0, wa1, wa2)
    t0 = moment[0] + me0 - (wa1 * jw2 - wa2 * jw1)
    t1 = moment[1] + me1 - (wa2 * jw0 - wa0 * jw2)
    t2 = moment[2] + me2 - (wa0 * jw1 - wa1 * jw0)
    c0 = (rzx[0, 0] * t0 + rzx[1, 0] * t1 + rzx[2, 0] * t2) / jb0
    c1 = (rzx[0, 1] * t0 + rzx[1, 1] * t1 + rzx[2, 1] * t2) / jb1
    c2 = (rzx[0, 2] * t0 + rzx[1, 2] * t1 + rzx[2, 2] * t2) / jb2
    # + omega x Omega - Omega'
    al0 = rzx[0, 0] * c0 + rzx[0, 1] * c1 + rzx[0, 2] * c2 + (om[1] * o2 - om[2] * o1)
    al1 = rzx[1, 0] * c0 + rzx[1, 1] * c1 + rzx[1, 2] * c2 + (0.0 - om[0] * o2) - wd * s_
    al2 = rzx[2, 0] * c0 + rzx[2, 1] * c1 + rzx[2, 2] * c2 + (om[0] * o1 - 0.0) - wd * c_
    ja0, ja1, ja2 = _j_times(rzx, jb0, jb1, jb2, al0, al1, al2)
    p_ext += (
        om[0] * ja0
        + om[1] * ja1
        + om[2] * ja2
        - (om[0] * (moment[0] + me0) + om[1] * (moment[1] + me1) + om[2] * (moment[2] + me2))
    )
    return acc0, acc1, acc2, al0, al1, al2, p_ext


@njit(cache=True, _nrt=False)
def _assemble(t, y, par, force, moment, p_con, rail_f0, rail_f1, rail_fy0, rail_fy1, om, rzx, out):
    """The equations of motion (eq 59-71 with the gyroscopic term), the suspension and the track: d/dt of the full
    state into ``out`` from the summed contact force and moment about the centre (main frame, N and N m), the
    contact power ``p_con`` (W), the vertical and lateral contact forces on the rails (left, right; elastic track) and
    the angular velocity ``om`` and rotation R_z R_x ``rzx`` of :func:`_rotation`. The one implementation: every
    right-hand side (the RK4 loop, the DP54/BS32 pairs, and equations.WheelsetModel.derivative for scipy's
    methods) ends here through :func:`_forces`.
    """
    xc, yc, zc = y[0], y[1], y[2]
    yaw, roll = y[3], y[4]
    vx, vy, vz = y[6], y[7], y[8]
    yr, rr, sr = y[9], y[10], y[11]
    cps, sps, cth, sth = math.cos(yaw), math.sin(yaw), math.cos(roll), math.sin(roll)
    # exterior forces: axle load, primary suspension to the frame moving at the speed, yaw springs, torque
    fe0, fe1, fe2 = 0.0, 0.0, par.axle_load_N
    me0, me1, me2 = 0.0, 0.0, 0.0
    p_ext = par.axle_load_N * vz
    ax0, ax1, ax2 = -sps * cth, cps * cth, sth
    x_frame = par.frame_x0_m + par.speed_m_per_s * t
    for s in (-1.0, 1.0):
        sb_ = s * par.suspension_half_spacing_m
        a0, a1, a2 = ax0 * sb_, ax1 * sb_, ax2 * sb_
        v0 = vx + om[1] * a2 - om[2] * a1
        v1 = vy + om[2] * a0 - om[0] * a2
        v2 = vz + om[0] * a1 - om[1] * a0
        f0 = -par.suspension_kx_N_per_m * (xc + a0 - x_frame) - par.suspension_cx_N_s_per_m * (v0 - par.speed_m_per_s)
        f1 = -par.suspension_ky_N_per_m * (yc + a1 - sb_) - par.suspension_cy_N_s_per_m * (v1 - 0.0)
        f2 = -par.suspension_kz_N_per_m * (zc + a2 - par.frame_z_m) - par.suspension_cz_N_s_per_m * (v2 - 0.0)
        fe0 += f0
        fe1 += f1
        fe2 += f2
        me0 += a1 * f2 - a2 * f1
        me1 += a2 * f0 - a0 * f2
        me2 += a0 * f1 - a1 * f0
        p_ext += f0 * v0 + f1 * v1 + f2 * v2
    myaw = -2.0 * (par.yaw_stiffness_N_m_per_rad * yaw + par.yaw_damping_N_m_s_per_rad * yr)
    me2 += myaw
    p_ext += myaw * om[2]
    if par.torque_N_m != 0.0:
        mt0, mt1, mt2 = -par.torque_N_m * ax0, -par.torque_N_m * ax1, -par.torque_N_m * ax2
        me0 += mt0
        me1 += mt1
        me2 += mt2
        p_ext += mt0 * om[0] + mt1 * om[1] + mt2 * om[2]
    jb0, jb1, jb2 = par.inertia_transverse_kg_m2, par.inertia_axial_kg_m2, par.inertia_transverse_kg_m2
    if par.track_frame > 0:
        acc0, acc1, acc2, al0, al1, al2, p_ext = _assemble_curve(
            y, par, force, moment, fe0, fe1, fe2, me0, me1, me2, om, rzx, p_ext
        )
    else:
        acc0 = (force[0] + fe0) / par.mass_kg
        acc1 = (force[1] + fe1) / par.mass_kg
        acc2 = (force[2] + fe2) / par.mass_kg + par.gravity_m_per_s2
        # J = R J_body R^T with R = R_z R_x orthogonal: J omega and J^-1 torque = R J_body^-1 R^T torque (no solve)
        b0 = rzx[0, 0] * om[0] + rzx[1, 0] * om[1] + rzx[2, 0] * om[2]
        b1 = rzx[0, 1] * om[0] + rzx[1, 1] * om[1] + rzx[2, 1] * om[2]
        b2 = rzx[0, 2] * om[0] + rzx[1, 2] * om[1] + rzx[2, 2] * om[2]
        jw0 = rzx[0, 0] * jb0 * b0 + rzx[0, 1] * jb1 * b1 + rzx[0, 2] * jb2 * b2
        jw1 = rzx[1, 0] * jb0 * b0 + rzx[1, 1] * jb1 * b1 + rzx[1, 2] * jb2 * b2
        jw2 = rzx[2, 0] * jb0 * b0 + rzx[2, 1] * jb1 * b1 + rzx[2, 2] * jb2 * b2
        t0 = moment[0] + me0 - (om[1] * jw2 - om[2] * jw1)
        t1 = moment[1] + me1 - (om[2] * jw0 - om[0] * jw2)
        t2 = moment[2] + me2 - (om[0] * jw1 - om[1] * jw0)
        c0 = (rzx[0, 0] * t0 + rzx[1, 0] * t1 + rzx[2, 0] * t2) / jb0
        c1 = (rzx[0, 1] * t0 + rzx[1, 1] * t1 + rzx[2, 1] * t2) / jb1
        c2 = (rzx[0, 2] * t0 + rzx[1, 2] * t1 + rzx[2, 2] * t2) / jb2
        al0 = rzx[0, 0] * c0 + rzx[0, 1] * c1 + rzx[0, 2] * c2
        al1 = rzx[1, 0] * c0 + rzx[1, 1] * c1 + rzx[1, 2] * c2
        al2 = rzx[2, 0] * c0 + rzx[2, 1] * c1 + rzx[2, 2] * c2
    out[0], out[1], out[2] = vx, vy, vz
    out[3], out[4], out[5] = yr, rr, sr
    out[6], out[7], out[8] = acc0, acc1, acc2
    out[9] = (al0 * sps * sth - al1 * cps * sth + al2 * cth + yr * rr * sth + rr * sr) / cth
    out[11] = (al0 * sps - al1 * cps + yr * rr + rr * sr * sth) / cth
    out[10] = al0 * cps + al1 * sps - yr * sr * cth
    if par.elastic_track > 0:
        p_ext = _track_rates(par, y, rail_f0, rail_f1, rail_fy0, rail_fy1, out, p_ext)
    out[WORK_CONTACT], out[WORK_EXTERIOR] = p_con, p_ext


@njit(cache=True, _nrt=False)
def _rotation(y, om, rzx):
    """R_z(yaw) R_x(roll) into ``rzx`` (3, 3) and the angular velocity (main frame, eq 68-70) into ``om`` (3)."""
    yaw, roll = y[3], y[4]
    yr, rr, sr = y[9], y[10], y[11]
    cps, sps, cth, sth = math.cos(yaw), math.sin(yaw), math.cos(roll), math.sin(roll)
    rzx[0, 0], rzx[0, 1], rzx[0, 2] = cps, -sps * cth, sps * sth
    rzx[1, 0], rzx[1, 1], rzx[1, 2] = sps, cps * cth, -cps * sth
    rzx[2, 0], rzx[2, 1], rzx[2, 2] = 0.0, sth, cth
    om[0], om[1], om[2] = rr * cps + sr * sps * cth, rr * sps - sr * cps * cth, yr - sr * sth


@njit(cache=True)
def track_rates(par, y, rail_force, out):
    """:func:`_track_rates` alone (full state ``y`` with the track; rates into ``out``) under ``rail_force``
    (vertical left, right[, lateral left, right]); returns the dampers' power.
    """
    fy0, fy1 = (rail_force[2], rail_force[3]) if rail_force.shape[0] > 2 else (0.0, 0.0)
    return _track_rates(par, y, rail_force[0], rail_force[1], fy0, fy1, out, 0.0)


@njit(cache=True, _nrt=False, inline="always")
def _hertz_kalker(par, hz, kk, q, ca, cb):
    """Hertz under approach control (tables of the axial function) and Kalker's C11, C22, C23, C33 (tables of a/b):
    (N, a, b, C11, C22, C23, C33).
    """
    amin, amax = min(ca, cb), max(ca, cb)
    i, w = _uniform(math.log(amax / amin), hz[0, 0], hz[0, 1], hz.shape[1])
    pp = hz[1, i] * (1 - w) + hz[1, i + 1] * w
    kk_ = hz[2, i] * (1 - w) + hz[2, i + 1] * w
    dd = hz[3, i] * (1 - w) + hz[3, i + 1] * w
    major = math.sqrt(q * dd / (kk_ * amin))
    normal = 2.0 * math.pi * major * par.contact_modulus_Pa * q / (3.0 * kk_)
    minor = major * math.sqrt(pp)
    sa, sb = (major, minor) if ca <= cb else (minor, major)
    i, w = _uniform(math.log(sa / sb), kk[0, 0], kk[0, 1], kk.shape[1])
    c11 = kk[1, i] * (1 - w) + kk[1, i + 1] * w
    c22 = kk[2, i] * (1 - w) + kk[2, i + 1] * w
    c23 = kk[3, i] * (1 - w) + kk[3, i + 1] * w
    c33 = kk[4, i] * (1 - w) + kk[4, i + 1] * w
    return normal, sa, sb, c11, c22, c23, c33


@njit(cache=True, _nrt=False, inline="always")
def _creep_law(par, code, dummy, normal, sa, sb, c11, c22, c23, c33, xi, eta, spin):
    """(T_x, T_y, M_z) of the compiled creep law ``code`` (MODEL_CODES) on a Hertz patch."""
    tx, ty, mz = 0.0, 0.0, 0.0
    if code >= 1:
        ab = sa * sb
        gab = par.shear_modulus_Pa * ab
        gab15 = gab * math.sqrt(ab)
        if code == 3:
            l1, l2, l3 = _flexibilities(par, sa, sb, normal, xi, eta, spin, c11, c22, c23)
            fs = _fastsim_one(
                sa, sb, par.friction_coefficient, normal, xi, eta, spin, l1, l2, l3, int(par.fastsim_nx),
                int(par.fastsim_ny), par.fastsim_parabolic > 0, dummy, dummy, dummy, dummy, False,
            )  # fmt: skip
            tx, ty, mz = fs[0], fs[1], fs[2]
        else:
            tx = -gab * c11 * xi
            ty = -gab * c22 * eta - gab15 * c23 * spin
            mz = gab15 * c23 * eta - gab * ab * c33 * spin
        if code == 2:
            tt = math.hypot(tx, ty)
            limit = par.friction_coefficient * normal
            if tt > 0.0:
                wprime = tt / (3.0 * limit) if limit > 0 else np.inf
                one = max(1.0 - wprime, 0.0)
                scale = limit * (1.0 - one**3) / tt
                tx *= scale
                ty *= scale
            mz = 0.0
    return tx, ty, mz


@njit(cache=True, _nrt=False)
def _auto_threshold(par, rung, f):
    """Auto's threshold of feature f (AUTO_FEATURE_NAMES) for rung (0 linear, 1 Vermeulen-Johnson, 2 FASTSIM)."""
    if rung == 0:
        v = (par.auto_linear_saturation, par.auto_linear_spin_share, par.auto_linear_ellipticity_residual,
             par.auto_linear_curvature_change, par.auto_linear_second_patch_nearness)  # fmt: skip
    elif rung == 1:
        v = (par.auto_vermeulen_johnson_saturation, par.auto_vermeulen_johnson_spin_share,
             par.auto_vermeulen_johnson_ellipticity_residual, par.auto_vermeulen_johnson_curvature_change,
             par.auto_vermeulen_johnson_second_patch_nearness)  # fmt: skip
    else:
        v = (par.auto_fastsim_saturation, par.auto_fastsim_spin_share, par.auto_fastsim_ellipticity_residual,
             par.auto_fastsim_curvature_change, par.auto_fastsim_second_patch_nearness)  # fmt: skip
    return v[f]


@njit(cache=True, _nrt=False)
def _auto_choice(par, feats):
    """auto.choose_rung in the loop: (rung 0-3 as auto.AUTO_RUNGS, deciding feature index or -1, its threshold).
    The first of linear, Vermeulen-Johnson, FASTSIM (at the run's grid) whose measured box holds every feature;
    else BEM (3). The deciding feature: of the last rejected rung the feature furthest beyond its threshold; when the
    cheapest rung qualified, the feature closest to its threshold.
    """
    if math.isnan(par.auto_level):
        return 3, -1, np.nan
    last_f, last_t = -1, np.nan
    for rung in range(3):
        if math.isnan(_auto_threshold(par, rung, 0)):
            continue  # no measured box at this level
        worst, worst_f = -1.0, -1
        for f in range(5):
            box = _auto_threshold(par, rung, f)
            if not feats[f] <= box:
                ratio = feats[f] / box if box > 0 else np.inf
                if ratio > worst:
                    worst, worst_f = ratio, f
        if worst_f >= 0:
            last_f, last_t = worst_f, _auto_threshold(par, rung, worst_f)
            continue
        if last_f < 0:
            best, best_f = -1.0, 0
            for f in range(5):
                box = _auto_threshold(par, rung, f)
                r = feats[f] / box if box > 0 else (0.0 if feats[f] <= 0 else 1.0)
                if r > best:
                    best, best_f = r, f
            return rung, best_f, _auto_threshold(par, rung, best_f)
        return rung, last_f, last_t
    return 3, last_f, last_t


@njit(cache=True, _nrt=False)
def _law(par, hz, kk, dummy, q, ca, cb, xi, eta, spin, rec, c, record):
    """The compiled contact law of one patch: (N, a, b, T_x, T_y, M_z, status); status 1: the patch is for the
    callback (``auto`` chose BEM, or its FASTSIM broke the friction bound as auto's does in contact.models).

    ``auto`` (par.model_code AUTO_CODE): the features of contact.auto.patch_features that a quadric patch has
    (saturation w' = T_lin / (3 mu N), spin share G (ab)^1.5 C23 |phi| / max(T_lin, mu N); the geometric features
    are 0: the compiled geometry is a quadric), the rung by :func:`_auto_choice`, recorded (with ``record``) into
    rec[c, N_PATCH:] as equations.AUTO_PATCH_FIELDS.
    """
    normal, sa, sb, c11, c22, c23, c33 = _hertz_kalker(par, hz, kk, q, ca, cb)
    code = int(par.model_code)
    if code != AUTO_CODE:
        tx, ty, mz = _creep_law(par, code, dummy, normal, sa, sb, c11, c22, c23, c33, xi, eta, spin)
        return normal, sa, sb, tx, ty, mz, 0
    ab = sa * sb
    gab = par.shear_modulus_Pa * ab
    gab15 = gab * math.sqrt(ab)
    t_lin = math.hypot(-gab * c11 * xi, -gab * c22 * eta - gab15 * c23 * spin)
    mu_n = par.friction_coefficient * normal
    feats = (
        t_lin / (3.0 * mu_n) if mu_n > 0 else np.inf,
        gab15 * c23 * abs(spin) / max(t_lin, mu_n) if max(t_lin, mu_n) > 0 else 0.0,
        0.0,
        0.0,
        0.0,
    )
    rung, deciding, threshold = _auto_choice(par, feats)
    st = 0
    tx, ty, mz = 0.0, 0.0, 0.0
    if rung < 3:
        tx, ty, mz = _creep_law(par, rung + 1, dummy, normal, sa, sb, c11, c22, c23, c33, xi, eta, spin)
        if rung == 2 and math.hypot(tx, ty) > (1.0 + par.auto_friction_bound_tolerance) * mu_n:
            rung, st = 3, 1
    else:
        st = 1
    if record:
        rec[c, N_PATCH], rec[c, N_PATCH + 1], rec[c, N_PATCH + 2] = rung, par.auto_level, deciding
        rec[c, N_PATCH + 3] = threshold
        for f in range(5):
            rec[c, N_PATCH + 4 + f] = feats[f]
    return normal, sa, sb, tx, ty, mz, st


@njit(cache=True)
def patch_forces(par, hz, kk, q, ca, cb, xi, eta, spin):
    """One patch through the compiled law of par.model_code (not the callback): (N, T_x, T_y, M_z, a, b, status),
    for tests and inspection.
    """
    rec = np.zeros((1, N_FIELDS))
    normal, sa, sb, tx, ty, mz, st = _law(par, hz, kk, np.zeros((1, 1)), q, ca, cb, xi, eta, spin, rec, 0, False)
    return normal, tx, ty, mz, sa, sb, st


_CALLBACK = [None]
"""The Python object that solves the patches of the non-compiled contact models (equations.PatchCallback), set by
:func:`use_callback` before a compiled run or right-hand side."""


def use_callback(callback) -> None:
    """Make ``callback`` the one the compiled code hands its patches to (see :func:`_external`)."""
    _CALLBACK[0] = callback


def _dispatch(c, side, t, q, ca, cb, xi, eta, spin, speed, point, normal, ex, ey, radius, angle, lateral):
    """The callback boundary's Python side: the patch to the callback in use (equations.PatchCallback.solve)."""
    return _CALLBACK[0].solve(
        c, side, t, q, ca, cb, xi, eta, spin, speed, point, normal, ex, ey, radius, angle, lateral
    )


@njit(cache=True, _nrt=False)
def _external(c, side, t, q, ca, cb, xi, eta, spin, speed, px, py, pz, n, ex, ey, radius, angle, lateral):
    """The one callback boundary: a patch (candidate c of ``side`` at time t: approach, curvatures, creepages,
    rolling speed, contact point and contact frame e_x, e_y, n in the main frame, rolling radius, contact angle,
    wheel lateral position) handed to Python (numba objmode) and (N, T_x, T_y, M_z, a, b, status) taken back;
    status != 0: the contact model failed (the callback keeps its message). Overhead measured here: 2.0-2.1 us per
    objmode call of a trivial Python function; 25 us per patch through equations.PatchCallback with a model returning
    constant forces (its ContactGeometry and Creepage built per patch); a BEM patch at 40 x 40 takes about 20 ms.
    """
    n0, n1, n2 = n[0], n[1], n[2]
    x0, x1, x2, y0, y1, y2 = ex[0], ex[1], ex[2], ey[0], ey[1], ey[2]
    with objmode(normal="float64", tx="float64", ty="float64", mz="float64", sa="float64", sb="float64", st="int64"):
        normal, tx, ty, mz, sa, sb, st = _dispatch(
            c, side, t, q, ca, cb, xi, eta, spin, speed, (px, py, pz), (n0, n1, n2), (x0, x1, x2), (y0, y1, y2),
            radius, angle, lateral,
        )  # fmt: skip
    return normal, tx, ty, mz, sa, sb, st


@njit(cache=True, _nrt=False)
def _forces(t, y, par, cg, sides, hz, kk, rec, record, dummy, sc, out):
    """d/dt of the 14-state into ``out`` from the candidate geometry cg (ncand, N_GEO) (see _table_geometry;
    a candidate with q = NaN is absent: recorded as NaN); fills rec (ncand + 2, N_FIELDS) and the side forces
    when ``record``. Returns the status.
    """
    # scratch rows (no allocation in the loop): normal, lever, point velocity, e_x, e_y, force, moment,
    # total force, total moment, side forces (2), omega, R_z R_x (3 rows); row 15: the elastic search's centre;
    # row 16: the absolute angular velocity in a curve
    n, lever, vel, ex, ey, fc, mc = sc[0], sc[1], sc[2], sc[3], sc[4], sc[5], sc[6]
    force, moment, side_force = sc[7], sc[8], sc[9:11]
    om, rzx = sc[11], sc[12:15]
    force[:] = 0.0
    moment[:] = 0.0
    side_force[:, :] = 0.0
    yc = y[1]
    vx, vy, vz = y[6], y[7], y[8]
    _rotation(y, om, rzx)
    # in a curve (track_frame): the creepages take the absolute angular velocity omega + Omega and the centre's
    # absolute velocity (x' h, y', z') (_assemble_curve); the contact power stays that on the relative motion
    curve = par.track_frame > 0
    oma, vxa = om, vx
    w_1, w_2 = 0.0, 0.0
    if curve:
        oma = sc[16]
        w_1 = par.curvature_1_per_m * vx * par.cant_sin
        w_2 = par.curvature_1_per_m * vx * par.cant_cos
        oma[0], oma[1], oma[2] = om[0], om[1] + w_1, om[2] + w_2
        vxa = vx * (1.0 + par.curvature_1_per_m * (par.cant_sin * y[2] - par.cant_cos * yc))
    p_con = 0.0
    _, rail_v0 = rail_under_wheel(par, y, 0)
    _, rail_v1 = rail_under_wheel(par, y, 1)
    _, rail_vy0 = rail_lateral_under_wheel(par, y, 0)
    _, rail_vy1 = rail_lateral_under_wheel(par, y, 1)
    rail_f0, rail_f1, rail_fy0, rail_fy1 = 0.0, 0.0, 0.0, 0.0
    ncand = cg.shape[0]
    for c in range(ncand):
        g = cg[c]
        q = g[0]
        lever[0], lever[1], lever[2] = g[1], g[2], g[3]
        n[0], n[1], n[2] = g[4], g[5], g[6]
        ca, cb, radius = g[7], g[8], g[9]
        if record:
            for f in range(N_FIELDS):
                rec[c, f] = np.nan
            if not math.isnan(q):
                rec[c, 0] = 0.0
                rec[c, 7] = q
                rec[c, 8] = yc + lever[1]
                rec[c, 9] = g[10]
                rec[c, 10] = radius
                rec[c, 11] = g[11]
        if not q > 0.0:
            continue
        rail_vz = rail_v0 if sides[c] == 0 else rail_v1  # creepages relative to the rail (0: rigid track)
        rail_vy = rail_vy0 if sides[c] == 0 else rail_vy1
        speed, xi, eta, spin = _patch_creepages(lever, n, oma, vxa, vy, vz, rail_vy, rail_vz, vel, ex, ey)
        if not speed > 0.0:
            return 4
        if par.model_code == CALLBACK_CODE:
            normal, tx, ty, mz, sa, sb, st = _external(
                c, sides[c], t, q, ca, cb, xi, eta, spin, speed, y[0] + lever[0], yc + lever[1], y[2] + lever[2], n,
                ex, ey, radius, g[11], g[10],
            )  # fmt: skip
            if st != 0:
                return CALLBACK_FAILED
        else:
            normal, sa, sb, tx, ty, mz, st = _law(par, hz, kk, dummy, q, ca, cb, xi, eta, spin, rec, c, record)
            if st == 1:  # auto chose BEM (or FASTSIM broke the friction bound): the callback solves the patch
                normal, tx, ty, mz, sa, sb, st = _external(
                    c, sides[c], t, q, ca, cb, xi, eta, spin, speed, y[0] + lever[0], yc + lever[1], y[2] + lever[2],
                    n, ex, ey, radius, g[11], g[10],
                )  # fmt: skip
                if st != 0:
                    return CALLBACK_FAILED
        for k in range(3):
            fc[k] = ex[k] * tx + ey[k] * ty + n[k] * normal
            mc[k] = n[k] * mz
            force[k] += fc[k]
        moment[0] += lever[1] * fc[2] - lever[2] * fc[1] + mc[0]
        moment[1] += lever[2] * fc[0] - lever[0] * fc[2] + mc[1]
        moment[2] += lever[0] * fc[1] - lever[1] * fc[0] + mc[2]
        if curve:  # the slip velocity less Omega x (r_c + lever): the point's velocity relative to the frame
            p1, p2 = yc + lever[1], y[2] + lever[2]
            vel[0] -= w_1 * p2 - w_2 * p1
            vel[1] -= w_2 * lever[0]
            vel[2] -= -w_1 * lever[0]
        p_con += fc[0] * vel[0] + fc[1] * vel[1] + fc[2] * vel[2] + mc[0] * om[0] + mc[1] * om[1] + mc[2] * om[2]
        if sides[c] == 0:
            rail_f0 -= fc[2]
            rail_fy0 -= fc[1]
        else:
            rail_f1 -= fc[2]
            rail_fy1 -= fc[1]
        if record:
            for k in range(3):
                side_force[sides[c], k] += fc[k]
            rec[c, 0] = normal
            rec[c, 1] = tx
            rec[c, 2] = ty
            rec[c, 3] = mz
            rec[c, 4] = xi
            rec[c, 5] = eta
            rec[c, 6] = spin
            rec[c, 12] = sa
            rec[c, 13] = sb
    _assemble(t, y, par, force, moment, p_con, rail_f0, rail_f1, rail_fy0, rail_fy1, om, rzx, out)
    if record:
        for sd in range(2):
            for k in range(3):
                rec[ncand + sd, k] = side_force[sd, k]
    return 0


@njit(cache=True, _nrt=False)
def _rhs(t, y, par, hz, kk, sides, mode, targs, sargs, ws, record, full, out):
    """d/dt of the 14-state: the candidate geometry from the tables (mode 0, _table_geometry), the 3-D search
    (mode 1, compiled_search.search_geometry; ``full``: with the lateral scan) or given by the caller in ws[7]
    (mode 2: a provider the compiled code does not evaluate, equations.WheelsetModel fills it), then _forces.
    Returns the status.
    """
    _geometry(y, par, sides, mode, targs, sargs, ws, full)
    return _forces(t, y, par, ws[7], sides, hz, kk, ws[1], record, ws[4], ws[5], out)


@njit(cache=True, _nrt=False)
def _geometry(y, par, sides, mode, targs, sargs, ws, full):
    """The candidate geometry at the state y into ws[7] (mode 0 tables, 1 search; mode 2: given, left alone)."""
    work, res, geo, bg, cg = ws[0], ws[2], ws[3], ws[6], ws[7]
    if mode == 0:
        table, grid, slots = targs
        _table_geometry(y, par, table, grid, slots, sides, work, res, geo, bg, cg)
    elif mode == 1:
        sp, tabs, irrs, mem, n_mem, cand, order, vb, rot = sargs
        if par.elastic_track > 0:
            rail0, _ = rail_under_wheel(par, y, 0)
            rail1, _ = rail_under_wheel(par, y, 1)
            lat0, _ = rail_lateral_under_wheel(par, y, 0)
            lat1, _ = rail_lateral_under_wheel(par, y, 1)
            search_geometry_on_track(
                y, rail0, rail1, lat0, lat1, sp, tabs, irrs, mem, n_mem, full, cand, order, vb, rot, cg, ws[5][15]
            )
        else:
            search_geometry(y, sp, tabs, irrs, mem, n_mem, full, cand, order, vb, rot, cg)


@njit(cache=True)
def geometry_once(y, par, sides, mode, targs, sargs, cg):
    """The candidate geometry alone (no contact law: the static equilibrium's approaches) into cg (mode 0 or 1)."""
    ws = _workspace(par, targs[0].shape[0], sides.shape[0], np.zeros((sides.shape[0] + 2, N_FIELDS)))
    _geometry(y, par, sides, mode, targs, sargs, ws, True)
    cg[:, :] = ws[7]


@njit(cache=True)
def _workspace(par, n_rows, ncand, rec):
    """Scratch arrays of _rhs: (table work, rec, res, geo, dummy, scratch rows, beta grid, candidate geometry).
    The beta grid holds the running-direction section's angles (np.linspace(-half, half, IRR_GRID)), their sines
    and cosines.
    """
    bg = np.empty((3, IRR_GRID))
    step_b = 2.0 * par.section_half_angle_rad / (IRR_GRID - 1)
    for g in range(IRR_GRID):
        bg[0, g] = g * step_b - par.section_half_angle_rad
        bg[1, g] = math.sin(bg[0, g])
        bg[2, g] = math.cos(bg[0, g])
    return (
        np.empty((n_rows, ncand)), rec, np.empty(9), np.empty(8), np.zeros((1, 1)), np.zeros((17, 3)), bg,
        np.zeros((ncand, N_GEO)),
    )  # fmt: skip


@njit(cache=True)
def rhs_once(t, y, par, hz, kk, sides, mode, targs, sargs, out, rec):
    """One right-hand side (with the lateral scan in the search mode) into out (14), its candidates into rec
    (ncand + 2, N_FIELDS). Returns the status (for the static equilibrium before a compiled run).
    """
    ws = _workspace(par, targs[0].shape[0], sides.shape[0], rec)
    return _rhs(t, y, par, hz, kk, sides, mode, targs, sargs, ws, True, True, out)


@njit(cache=True)
def contact_once(t, y, par, hz, kk, sides, mode, targs, sargs, out, rec, cg):
    """:func:`rhs_once` that also returns the candidate geometry into cg (ncand, N_GEO) (for inspection: the
    contact frames and forces of equations.WheelsetModel.contact). Mode 2: cg is the given geometry.
    """
    if mode == 2:
        return rhs_given(t, y, par, hz, kk, sides, cg, out, rec, True)
    ws = _workspace(par, targs[0].shape[0], sides.shape[0], rec)
    st = _rhs(t, y, par, hz, kk, sides, mode, targs, sargs, ws, True, True, out)
    cg[:, :] = ws[7]
    return st


@njit(cache=True)
def rhs_given(t, y, par, hz, kk, sides, cg, out, rec, record):
    """The right-hand side on a given candidate geometry cg (ncand, N_GEO) (mode 2: a provider the compiled code
    does not evaluate): the compiled laws, the callback, the equations of motion, as in the loop.
    """
    return _forces(t, y, par, cg, sides, hz, kk, rec, record, np.zeros((1, 1)), np.zeros((16, 3)), out)


@njit(cache=True, _nrt=False)
def _side_forces(rec, sides, out):
    """Per side (left, right) the sums of normal force, longitudinal and lateral creep force of the patches in
    contact (rec columns 0-2, NaN or 0 for candidates out of contact) into out (2, 3), N.
    """
    out[:, :] = 0.0
    for c in range(sides.shape[0]):
        if rec[c, 0] > 0.0:
            for k in range(3):
                out[sides[c], k] += rec[c, k]


@njit(cache=True, _nrt=False)
def _force_difference(f4, f3):
    """The largest |f4 - f3| over both sides' normal, longitudinal and lateral contact forces (two _side_forces
    results, (2, 3)), N; inf when one is NaN (forces not computable at one of the two states). The force error
    estimate of RK4 (against its embedded third-order solution) and of the DP54/BS32 pairs.
    """
    worst = 0.0
    for sd in range(2):
        for k in range(3):
            d = abs(f4[sd, k] - f3[sd, k])
            if d != d:
                return np.inf
            if d > worst:
                worst = d
    return worst


@njit(cache=True)
def rk4_run(
    y, t0, h, n_steps, out_every, check_every, par, hz, kk, sides, mode, targs, sargs, states, recs, errs, out_start
):
    """Advance ``n_steps`` RK4 steps from (t0, y); record every ``out_every`` steps into states/recs from
    index ``out_start``. mode 0: tables (targs = (table, grid, slots)); mode 1: 3-D search (sargs =
    compiled_search's (sp, tabs, irrs) + workspace, whose memory carries over between calls; the lateral scan
    runs at each step's first stage and at the recorded samples). Returns (status, steps done, next output
    index, t, y, rhs evaluations).

    Error estimate (into errs, N, per recorded sample): at every recorded sample and every ``check_every`` steps
    the step that ends there is also advanced by the third-order formula embedded in the classical RK4 stages and
    the derivative at the step's end, k5 = f(t + h, y4) (which is the next step's k1): y3 = y + h (k1/6 + k2/3 +
    k3/3 + k5/6), so y4 - y3 = h/6 (k4 - k5) (Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., section II.4,
    "embedded formulas" of order 4(3)). The estimate is the largest difference of the per-wheel contact forces
    (normal, longitudinal and lateral creep force) at y4 and y3: the force error of one step of the third-order
    formula, an upper estimate of RK4's own (one extra right-hand side per check; two between recorded samples).
    A sample carries the largest estimate of the checks since the previous sample (inf when the third-order
    state's right-hand side failed).
    """
    ncand = sides.shape[0]
    ws = _workspace(par, targs[0].shape[0], ncand, np.empty((ncand + 2, N_FIELDS)))
    rec = ws[1]
    nst = y.shape[0]
    y = y.copy()
    k1, k2, k3, k4 = np.empty(nst), np.empty(nst), np.empty(nst), np.empty(nst)
    k5, k6 = np.empty(nst), np.empty(nst)
    ys, y_new = np.empty(nst), np.empty(nst)
    f4, f3 = np.empty((2, 3)), np.empty((2, 3))
    pending = np.nan
    t = t0
    k_out = out_start
    evals = 0
    fmax, ymax = par.max_force_N, par.max_lateral_m
    have_k1 = False  # k1 of the next step is the recorded sample's derivative (same t and y)
    for step in range(n_steps):
        if not have_k1:
            st = _rhs(t, y, par, hz, kk, sides, mode, targs, sargs, ws, False, True, k1)
            evals += 1
            if st != 0:
                return st, step, k_out, t, y, evals
        have_k1 = False
        for i in range(nst):
            ys[i] = y[i] + 0.5 * h * k1[i]
        st = _rhs(t + 0.5 * h, ys, par, hz, kk, sides, mode, targs, sargs, ws, False, False, k2)
        if st != 0:
            return st, step, k_out, t, y, evals
        for i in range(nst):
            ys[i] = y[i] + 0.5 * h * k2[i]
        st = _rhs(t + 0.5 * h, ys, par, hz, kk, sides, mode, targs, sargs, ws, False, False, k3)
        if st != 0:
            return st, step, k_out, t, y, evals
        for i in range(nst):
            ys[i] = y[i] + h * k3[i]
        st = _rhs(t + h, ys, par, hz, kk, sides, mode, targs, sargs, ws, False, False, k4)
        evals += 3
        if st != 0:
            return st, step, k_out, t, y, evals
        finite = True
        for i in range(nst):
            y_new[i] = y[i] + (h / 6.0) * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            if not np.isfinite(y_new[i]):
                finite = False
        if not finite:
            return 1, step, k_out, t, y, evals
        y, y_new = y_new, y  # y_new now holds the step's start
        t = t0 + (step + 1) * h
        output = (step + 1) % out_every == 0 and k_out < states.shape[0]
        if output or (step + 1) % check_every == 0:
            st = _rhs(t, y, par, hz, kk, sides, mode, targs, sargs, ws, True, True, k5)
            evals += 1
            if st != 0:
                return st, step + 1, k_out, t, y, evals
            if output:
                states[k_out, :] = y
                recs[k_out, :, :] = rec
            _side_forces(rec, sides, f4)
            # the embedded third-order solution and its contact forces
            for i in range(nst):
                ys[i] = y_new[i] + h * (k1[i] / 6.0 + k2[i] / 3.0 + k3[i] / 3.0 + k5[i] / 6.0)
            st = _rhs(t, ys, par, hz, kk, sides, mode, targs, sargs, ws, True, False, k6)
            evals += 1
            worst = np.inf
            if st == 0:
                _side_forces(rec, sides, f3)
                worst = _force_difference(f4, f3)
            if not pending >= worst:  # also when pending is NaN
                pending = worst
            for i in range(nst):
                k1[i] = k5[i]
            have_k1 = True
            if output:
                errs[k_out] = pending
                pending = np.nan
                k_out += 1
                for sd in range(2):
                    if f4[sd, 0] > fmax:
                        return 2, step + 1, k_out, t, y, evals
                if abs(y[1]) > ymax:
                    return 3, step + 1, k_out, t, y, evals
    return 0, n_steps, k_out, t, y, evals


def load(packed) -> None:
    """Load (from numba's cache, or compile) rk4_run and rhs_once for the types of ``packed`` (pack's result):
    zero steps, and one right-hand side at the zero state (no wheel near a rail there: no candidate enters the
    search memory, whose warm starts are its only state).
    """
    par, hz, kk, sides, _, mode, targs, sargs = packed
    y = np.zeros(n_states(int(par["track_positions"])))
    rec = np.zeros((len(sides) + 2, N_FIELDS))
    rk4_run(
        y,
        0.0,
        1e-3,
        0,
        1,
        1,
        par,
        hz,
        kk,
        sides,
        mode,
        targs,
        sargs,
        np.zeros((0, len(y))),
        np.zeros((0, len(sides) + 2, N_FIELDS)),
        np.zeros(0),
        0,
    )
    rhs_once(0.0, y, par, hz, kk, sides, mode, targs, sargs, np.zeros(len(y)), rec)


def geometry_mode(provider) -> int:
    """How the right-hand side gets the contact geometry of ``provider``: 0 the compiled tables (a TableProvider,
    with or without running-direction irregularities), 1 the compiled 3-D search (a SearchProvider on tabulated
    surfaces: ideal profiles with polygon, flats or corrugation), 2 given by Python (any other provider: the conical
    one, the search on measured grids or harmonics, user providers; equations.WheelsetModel fills the candidates).
    """
    from rigid_dynamics.contact.search import TabulatedRail, TabulatedWheel
    from rigid_dynamics.wheelset.providers import SearchProvider, TableProvider

    if type(provider) is TableProvider:
        return 0
    if type(provider) is SearchProvider:
        fast = getattr(provider.surfaces, "fast", None)
        if fast is not None and all(
            isinstance(w, TabulatedWheel) and isinstance(r, TabulatedRail) for w, r in fast.values()
        ):
            return 1
    return 2


def supported(scene, provider, model) -> bool:
    """Whether the compiled RK4 loop can run this combination: method RK4 and a provider whose geometry is compiled
    (:func:`geometry_mode` 0 or 1). Any contact model: the compiled laws inline, ``auto``'s choice inline, the
    others (bem, fea, user models) through the callback.
    """
    return scene.integrator.method == "RK4" and geometry_mode(provider) < 2


def model_code(model) -> int:
    """``model_code`` of a contact model instance: MODEL_CODES for the registry's compiled laws, AUTO_CODE for its
    ``auto``, CALLBACK_CODE for everything else (bem, fea, user models, subclasses).
    """
    name = getattr(model, "name", None)
    if type(model).__module__ == "rigid_dynamics.contact.models":
        if name in MODEL_CODES:
            return MODEL_CODES[name]
        if name == "auto":
            return AUTO_CODE
    return CALLBACK_CODE


def auto_parameters(par, tolerance: float, fastsim_grid) -> None:
    """Auto's thresholds (contact/data/auto_thresholds.json, contact.auto) into the parameter record: the level of
    ``tolerance`` (contact.auto.level_for; none: NaN, every patch BEM) and per rung (linear, Vermeulen-Johnson,
    FASTSIM at the run's grid by contact.auto.fastsim_rung) the feature box (NaN: no measured box).
    """
    from rigid_dynamics.contact.auto import fastsim_rung, level_for, load_thresholds
    from rigid_dynamics.contact.models import FRICTION_BOUND_TOLERANCE

    data = load_thresholds()
    key = level_for(tolerance, data)
    par["auto_friction_bound_tolerance"] = FRICTION_BOUND_TOLERANCE
    for rung in AUTO_RUNG_NAMES:
        for f in AUTO_FEATURE_NAMES:
            par[f"auto_{rung}_{f}"] = np.nan
    if key is None:
        par["auto_level"] = np.nan
        return
    par["auto_level"] = float(key)
    level = data["levels"][key]
    labels = ("linear", "vermeulen-johnson", fastsim_rung(int(fastsim_grid[0]), int(fastsim_grid[1]), level))
    for rung, label in zip(AUTO_RUNG_NAMES, labels, strict=True):
        entry = level.get(label) if label is not None else None
        box = None if entry is None else entry["thresholds"]
        if box is not None:
            for f in AUTO_FEATURE_NAMES:
                par[f"auto_{rung}_{f}"] = float(box[f])


def model_parameters(model_wheelset):
    """The parameter record's fields of the equations of motion, the suspension, the run's limits and the elastic
    track, from a WheelsetModel (the contact fields stay zero: :func:`pack` adds them for the compiled loop).
    """
    m = model_wheelset
    scene = m.scene
    par = new_parameters()
    par["mass_kg"], par["inertia_transverse_kg_m2"], par["inertia_axial_kg_m2"] = m.mass, m.j_body[0, 0], m.j_body[1, 1]
    par["gravity_m_per_s2"] = m.gravity
    par["suspension_kx_N_per_m"], par["suspension_ky_N_per_m"], par["suspension_kz_N_per_m"] = m.k
    par["suspension_cx_N_s_per_m"], par["suspension_cy_N_s_per_m"], par["suspension_cz_N_s_per_m"] = m.c
    par["yaw_stiffness_N_m_per_rad"], par["yaw_damping_N_m_s_per_rad"] = m.k_yaw, m.c_yaw
    par["suspension_half_spacing_m"], par["frame_z_m"], par["frame_x0_m"], par["speed_m_per_s"] = (
        m.half_spacing,
        m.z_frame,
        m.frame_x0,
        m.speed,
    )
    par["axle_load_N"], par["torque_N_m"] = m.axle_load, m.torque
    par["max_force_N"] = scene.integrator.max_force_factor * scene.static_wheel_load_N
    par["max_lateral_m"] = scene.integrator.max_lateral_displacement_m
    geometry = scene.track
    if geometry.curved:
        par["track_frame"] = 1.0
        par["curvature_1_per_m"] = geometry.curvature_1_per_m
        par["cant_sin"], par["cant_cos"] = math.sin(geometry.cant_rad), math.cos(geometry.cant_rad)
        par["carried_mass_kg"] = m.axle_load / m.gravity
    track.pack_parameters(par, scene.track_dynamics, track.travel_m(scene))
    return par


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


@njit(cache=True)
def table_candidates(y, par, table, grid, slots, sides, cg):
    """The tables' candidates (with the running-direction irregularities of par) at the pose in y into cg
    (ncand, N_GEO): :func:`_table_geometry` for providers.TableProvider.patches (inspection, tests).
    """
    ws = _workspace(par, table.shape[0], sides.shape[0], np.zeros((sides.shape[0] + 2, N_FIELDS)))
    _table_geometry(y, par, table, grid, slots, sides, ws[0], ws[2], ws[3], ws[6], cg)


@njit(cache=True)
def irregular_candidates(par, work, sides, x0, spin, cg):
    """The running-direction irregularities (:func:`_irregularity`) added to candidates given as table rows ``work``
    (rows 4, 5: normal y, z; 6: A; 8: rolling radius; 0: approach) at contact points x0 (ncand), the spin angle
    ``spin``: into cg (ncand, 8) = (q, x offset, z offset, n_x, n_y, n_z, rolling radius, A); rows of candidates left
    alone (side not irregular, gap beyond the reach) are NaN. For providers.ConicalProvider.
    """
    ws = _workspace(par, work.shape[0], sides.shape[0], np.zeros((sides.shape[0] + 2, N_FIELDS)))
    res, bg = ws[2], ws[6]
    for c in range(sides.shape[0]):
        cg[c, :] = np.nan
        q = work[0, c]
        if q > -par.irregularity_reach_m and (par.irregular_right if sides[c] == 1 else par.irregular_left) > 0:
            _irregularity(par, work, c, q, x0[c], spin, res, cg[c], bg)


def pack(model_wheelset, provider, tables, model, options=None, tolerance=0.05, python_geometry=False):
    """Arguments of rk4_run / rhs_once from a WheelsetModel, its provider, the Hertz / Kalker tables and the contact
    model instance: (par, hz, kk, sides, slots, mode, targs, sargs). ``options``: FASTSIM's (nx, ny, traction_bound,
    flexibility) for ``fastsim`` and ``auto``; ``tolerance``: auto's; ``python_geometry``: mode 2 for any provider.
    """
    mode = 2 if python_geometry else geometry_mode(provider)
    search = mode == 1
    m = model_wheelset
    scene = m.scene
    par = model_parameters(m)
    par["shear_modulus_Pa"] = scene.material.shear_modulus_Pa
    par["contact_modulus_Pa"] = tables.e_star
    par["friction_coefficient"] = scene.material.friction_coefficient
    code = model_code(model)
    par["model_code"] = code
    par["z_ref_m"] = provider.z_ref if mode == 0 else 0.0
    opts = {"nx": 20, "ny": 20, "traction_bound": "elliptic", "flexibility": "three"}
    opts.update({k: v for k, v in (options or {}).items() if k in opts})
    par["fastsim_nx"], par["fastsim_ny"] = int(opts["nx"]), int(opts["ny"])
    par["fastsim_parabolic"] = 1.0 if opts["traction_bound"] == "parabolic" else 0.0
    par["flexibility_code"] = FLEX_CODES[opts["flexibility"]]
    if code == AUTO_CODE:
        auto_parameters(par, tolerance, (opts["nx"], opts["ny"]))
    hz = np.vstack([np.zeros(len(tables.log_r)), tables.p, tables.k, tables.d])
    hz[0, 0], hz[0, 1] = tables.log_r[0], tables.log_r[1] - tables.log_r[0]
    kk = np.vstack([np.zeros(len(tables.log_ab)), tables.c])
    kk[0, 0], kk[0, 1] = tables.log_ab[0], tables.log_ab[1] - tables.log_ab[0]
    if mode == 2:
        par["nominal_radius_m"] = getattr(provider, "r0", scene.wheelset.nominal_radius_m)
        sides = np.array([0, 0, 1, 1], np.int64)
        slots = np.array([0, 1, 0, 1], np.int64)
        return par, hz, kk, sides, slots, 2, (np.zeros((1, 4, 2, 2)), np.zeros(6), slots), _dummy_search()
    par["nominal_radius_m"] = provider.r0
    if not search and provider.irregularities is not None:
        irregularity_parameters(par, provider.irregularities, provider._irr_sides, provider.r0)
    if search:
        from rigid_dynamics.wheelset import compiled_search as cs

        sides = np.array([0, 0, 1, 1], np.int64)
        slots = np.array([0, 1, 0, 1], np.int64)
        targs = (np.zeros((1, 4, 2, 2)), np.zeros(6), slots)
        sargs = (*cs.pack_search(provider, provider.options), *cs.workspace())
        return par, hz, kk, sides, slots, 1, targs, sargs
    yg, rg = provider.y_grid, provider.roll_grid
    grid = np.array([yg[0], yg[1] - yg[0], len(yg), rg[0], rg[1] - rg[0], len(rg)], float)
    table = np.ascontiguousarray(provider.table)
    slots = np.asarray(provider.slot, np.int64)
    sides = np.asarray(provider.side, np.int64)
    return par, hz, kk, sides, slots, 0, (table, grid, slots), _dummy_search()


def _dummy_search():
    """The search arguments of the tables mode (never read; of the search mode's types)."""
    from rigid_dynamics.wheelset import compiled_search as cs

    tab = np.zeros((3, 2))
    irr = np.zeros((0, 7))
    return (np.zeros((2, cs.SP_LEN)), (tab, tab, tab, tab), (irr, irr, irr, irr), *cs.workspace())
