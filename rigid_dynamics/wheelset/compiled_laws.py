"""The contact laws of the compiled right-hand side (numba): Hertz and Kalker's C_ij by tables, the creep laws, and
``auto``'s choice per patch.

* Hertz and Kalker (:func:`_hertz_kalker`): from the tables of :class:`TabulatedHertzKalker` (the record
  :class:`HertzKalkerTables`), the approach q and the relative curvatures A, B give N, the semi-axes and C11, C22,
  C23, C33.
* The creep laws (:func:`_creep_law`, the codes :data:`LAW_CODES` of the names that the contact models declare as
  their ``compiled_law``, contact/models.py): ``hertz`` (no creep force), ``linear`` (Kalker's linear theory, eq 50-52,
  contact.linear.linear_one), ``vermeulen-johnson`` (eq 53-58 with the cube, contact.vermeulen_johnson.saturate_one
  on the linear forces) and ``fastsim`` (contact.fastsim._fastsim_one with the flexibilities of
  contact.fastsim.flexibilities_one; options nx, ny, traction_bound, flexibility).
* ``table`` (:func:`_table_law`, contact.creep_table): FASTSIM's forces interpolated from its creep-force table over
  the normalised creepages and a/b (``HertzKalkerTables.creep``); a patch beyond the table's a/b is solved by FASTSIM.
* ``auto`` (:func:`_auto_choice`): the measured thresholds of contact/data/auto_thresholds.json in the parameter
  record; a patch auto gives to BEM goes through the callback (compiled_rhs._external).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact.auto import GEOMETRY_FLOOR
from rigid_dynamics.contact.creep_table import CreepTable, empty_table, table_creep_law, uniform_cell
from rigid_dynamics.contact.fastsim import (
    FastsimGrid,
    FastsimPatch,
    PatchFriction,
    StripFields,
    _fastsim_one,
    flexibilities_one,
)
from rigid_dynamics.contact.friction import (
    FRICTION_COULOMB,
    VARIES_NOWHERE,
    FrictionRecord,
    friction_coefficient,
    uniform,
)
from rigid_dynamics.contact.kpec import blended_flexibilities, fastsim_strips, flexibility_ellipse, kpec_pressure_into
from rigid_dynamics.contact.linear import linear_one
from rigid_dynamics.contact.vermeulen_johnson import saturate_one
from rigid_dynamics.wheelset.layout import (
    AUTO_BEM,
    AUTO_DECIDING_FEATURE,
    AUTO_DECIDING_THRESHOLD,
    AUTO_FASTSIM,
    AUTO_FEATURE_NAMES,
    AUTO_FEATURES,
    AUTO_LEVEL,
    AUTO_LINEAR,
    AUTO_RUNG,
    AUTO_RUNG_NAMES,
    AUTO_VERMEULEN_JOHNSON,
    N_FIELDS,
)

LAW_HERTZ, LAW_LINEAR, LAW_VERMEULEN_JOHNSON, LAW_FASTSIM, LAW_CALLBACK, LAW_AUTO, LAW_KPEC, LAW_TABLE = range(8)
LAW_BEM_CORRECTED = 8
"""The ``contact_law_code`` of an auto patch served by FASTSIM on the ellipse corrected by a stored BEM solution
(wheelset/auto_reuse.py); no model declares it."""
LAW_CODES = {
    "hertz": LAW_HERTZ,
    "linear": LAW_LINEAR,
    "vermeulen-johnson": LAW_VERMEULEN_JOHNSON,
    "fastsim": LAW_FASTSIM,
    "auto": LAW_AUTO,
    "kpec": LAW_KPEC,
    "table": LAW_TABLE,
}
"""The laws compiled into the loop, by the name a contact model declares (contact.models.HertzianModel.compiled_law);
LAW_CALLBACK: every patch through the callback (bem, fea, user models); LAW_AUTO: auto's rung chosen per patch
(linear, Vermeulen-Johnson and FASTSIM inline, BEM through the callback); LAW_KPEC: CONTACT's KPEC + FASTSIM per strip
on the patch's gap (:func:`_kpec_law`; the gap sampled by compiled_patch.py, or the quadric); LAW_TABLE: FASTSIM's
creep-force table (:func:`_table_law`)."""


class TabulatedHertzKalker:
    """Hertz (approach control) and Kalker's C_ij for many patches by look-up tables, for speed.

    Two smooth functions of one variable are tabulated once, on fine grids, from the project's own
    solvers and interpolated linearly:

    * the inverted axial function p = (b_minor/a_major)^2 of r = max(A, B)/min(A, B) and Kalker's
      elliptic functions K(p), D(p) (contact.hertz.ellipse_shape_from_curvature_ratio, elliptic_kdbc),
      on ``HERTZ_POINTS`` points of ln r in [0, ln 1e4];
    * C11, C22, C23, C33 (contact.kalker.kalker_coefficients at the material's nu) on ``KALKER_POINTS``
      points of ln(a/b) in [-ln 50, ln 50].

    The compiled right-hand side (compiled_laws._hertz_kalker) interpolates them: a_major = sqrt(q D / (K min(A, B))),
    N = 2 pi a_major E* q / (3 K), b_minor = a_major sqrt(p), E* = G/(1 - nu). Relative interpolation error < 1e-7
    (tests/test_wheelset_providers.py compares with hertz_solve_batch and kalker_coefficients); ratios outside the
    grids are clamped to their ends.
    """

    HERTZ_POINTS = 20001
    KALKER_POINTS = 8001

    def __init__(self, material):
        from rigid_dynamics.contact.hertz import ellipse_shape_from_curvature_ratio, elliptic_kdbc
        from rigid_dynamics.contact.kalker import kalker_coefficients

        self.shear = material.shear_modulus_Pa
        self.nu = material.poisson_ratio
        self.e_star = self.shear / (1.0 - self.nu)
        self.log_r = np.linspace(0.0, math.log(1e4), self.HERTZ_POINTS)
        p, _, _ = ellipse_shape_from_curvature_ratio(np.exp(self.log_r))
        k, d, _, _ = elliptic_kdbc(p)
        self.p, self.k, self.d = p, k, d
        self.log_ab = np.linspace(-math.log(50.0), math.log(50.0), self.KALKER_POINTS)
        coef = kalker_coefficients(np.exp(self.log_ab), self.nu)
        self.c = np.stack([coef.c11, coef.c22, coef.c23, coef.c33])


@lru_cache(maxsize=8)
def tables_for(shear_modulus_Pa: float, poisson_ratio: float) -> TabulatedHertzKalker:
    """TabulatedHertzKalker per material (built once per process: ~0.5 s)."""
    from rigid_dynamics.materials import Material

    return TabulatedHertzKalker(Material(shear_modulus_Pa, poisson_ratio, 0.0))


HERTZ_P, HERTZ_K, HERTZ_D = range(3)
"""Rows of HertzKalkerTables.hertz: the inverted axial function p = (b/a)^2 and Kalker's elliptic K(p), D(p)."""
KALKER_C11, KALKER_C22, KALKER_C23, KALKER_C33 = range(4)
"""Rows of HertzKalkerTables.kalker: Kalker's creep coefficients."""


class HertzKalkerTables(NamedTuple):
    """:class:`TabulatedHertzKalker` as the compiled code reads it: ``hertz`` (rows :data:`HERTZ_P`, ...) on a
    uniform grid of ln(max(A, B)/min(A, B)) from ``log_ratio_start`` by ``log_ratio_step``; ``kalker`` (rows
    :data:`KALKER_C11`, ...) on a uniform grid of ln(a/b); and the run's friction law ``friction``
    (contact.friction.FrictionRecord; one Coulomb law that varies nowhere: the parameter record's
    ``friction_coefficient`` serves, as before the laws existed); ``creep`` the run's creep-force table
    (contact.creep_table.CreepTable; an empty one when no law reads it); ``reuse`` auto's store of BEM anchors
    (auto_reuse.reuse_store: one row per candidate and a statistics row; written by the loop). The data of the
    compiled laws, passed per patch.
    """

    log_ratio_start: float
    log_ratio_step: float
    hertz: np.ndarray
    log_ab_start: float
    log_ab_step: float
    kalker: np.ndarray
    friction: FrictionRecord
    creep: CreepTable
    reuse: np.ndarray


def hertz_kalker_tables(tables, friction=None, creep=None, reuse=None) -> HertzKalkerTables:
    """The :class:`HertzKalkerTables` of a :class:`TabulatedHertzKalker`, a contact.friction.FrictionLaw (None:
    Coulomb with the parameter record's ``friction_coefficient``), a creep-force table (None: an empty one) and the
    run's store of auto's BEM anchors (auto_reuse.reuse_store; None: one with no candidate's row, nothing reused).
    """
    law = friction if friction is not None else uniform(0.0)
    return HertzKalkerTables(
        float(tables.log_r[0]),
        float(tables.log_r[1] - tables.log_r[0]),
        np.ascontiguousarray(np.stack([tables.p, tables.k, tables.d])),
        float(tables.log_ab[0]),
        float(tables.log_ab[1] - tables.log_ab[0]),
        np.ascontiguousarray(tables.c),
        law.record(),
        creep if creep is not None else empty_table(),
        reuse if reuse is not None else np.zeros((1, 1)),
    )


@njit(cache=True, _nrt=False, inline="always")
def _hertz_kalker(par, tables, q, ca, cb):
    """Hertz under approach control (tables of the axial function) and Kalker's C11, C22, C23, C33 (tables of a/b):
    (N, a, b, C11, C22, C23, C33).
    """
    amin, amax = min(ca, cb), max(ca, cb)
    hz = tables.hertz
    i, w = uniform_cell(math.log(amax / amin), tables.log_ratio_start, tables.log_ratio_step, hz.shape[1])
    pp = hz[HERTZ_P, i] * (1 - w) + hz[HERTZ_P, i + 1] * w
    kk_ = hz[HERTZ_K, i] * (1 - w) + hz[HERTZ_K, i + 1] * w
    dd = hz[HERTZ_D, i] * (1 - w) + hz[HERTZ_D, i + 1] * w
    major = math.sqrt(q * dd / (kk_ * amin))
    normal = 2.0 * math.pi * major * par.contact_modulus_Pa * q / (3.0 * kk_)
    minor = major * math.sqrt(pp)
    sa, sb = (major, minor) if ca <= cb else (minor, major)
    kk = tables.kalker
    i, w = uniform_cell(math.log(sa / sb), tables.log_ab_start, tables.log_ab_step, kk.shape[1])
    c11 = kk[KALKER_C11, i] * (1 - w) + kk[KALKER_C11, i + 1] * w
    c22 = kk[KALKER_C22, i] * (1 - w) + kk[KALKER_C22, i + 1] * w
    c23 = kk[KALKER_C23, i] * (1 - w) + kk[KALKER_C23, i + 1] * w
    c33 = kk[KALKER_C33, i] * (1 - w) + kk[KALKER_C33, i + 1] * w
    return normal, sa, sb, c11, c22, c23, c33


@njit(cache=True, _nrt=False, inline="always")
def patch_friction(par, law, where):
    """The friction of one patch (contact.fastsim.PatchFriction) at where = (place, rolling speed V, m/s): the law
    ``law`` (a FrictionRecord) at the patch's place (the variable of its nodes), its static coefficient mu_s = mu(0)
    there; a Coulomb law that varies nowhere: par.friction_coefficient.
    """
    place, speed = where
    if law.law_code == FRICTION_COULOMB and law.varies_code == VARIES_NOWHERE:
        return PatchFriction(law, place, par.friction_coefficient, speed)
    return PatchFriction(law, place, friction_coefficient(law, 0.0, place), speed)


@njit(cache=True, _nrt=False, inline="always")
def mean_slip_coefficient(friction, xi, eta):
    """The coefficient of an analytic law's patch: the law at the patch's mean rigid slip velocity
    V sqrt(xi^2 + eta^2) (the spin's rigid slip averages to zero over the patch), at its place; Coulomb: mu_s.
    """
    if friction.record.law_code == FRICTION_COULOMB:
        return friction.coefficient
    speed = friction.rolling_speed_m_per_s * math.sqrt(xi * xi + eta * eta)
    return friction_coefficient(friction.record, speed, friction.place)


@njit(cache=True, _nrt=False, inline="always")
def _creep_law(par, code, dummy, patch, creep, friction):
    """(T_x, T_y, M_z) of the compiled creep law ``code`` (layout.LAW_CODES) on a Hertz patch
    ``patch`` = (N, a, b, C11, C22, C23, C33) of :func:`_hertz_kalker`; creep = (xi, eta, phi); friction the
    patch's (:func:`patch_friction`). FASTSIM bounds each element by mu at its own slip velocity; Vermeulen-Johnson
    saturates at mu N with mu at the patch's mean slip velocity (:func:`mean_slip_coefficient`); the linear law has
    no bound.
    """
    normal, sa, sb, c11, c22, c23, c33 = patch
    xi, eta, spin = creep
    if code == LAW_HERTZ:
        return 0.0, 0.0, 0.0
    if code == LAW_FASTSIM:
        l1, l2, l3 = flexibilities_one(
            sa, sb, normal, xi, eta, spin, par.shear_modulus_Pa, friction.coefficient, (c11, c22, c23),
            int(par.flexibility_code),
        )  # fmt: skip
        fs = _fastsim_one(
            FastsimPatch(sa, sb, normal, xi, eta, spin), (l1, l2, l3), friction,
            FastsimGrid(int(par.fastsim_nx), int(par.fastsim_ny), par.fastsim_parabolic > 0),
            StripFields(dummy, dummy, dummy, dummy, False),
        )  # fmt: skip
        return fs[0], fs[1], fs[2]
    tx, ty, mz = linear_one(par.shear_modulus_Pa, sa, sb, c11, c22, c23, c33, xi, eta, spin)
    if code == LAW_VERMEULEN_JOHNSON:
        tx, ty = saturate_one(tx, ty, mean_slip_coefficient(friction, xi, eta) * normal)
        mz = 0.0
    return tx, ty, mz


@njit(cache=True, _nrt=False, inline="always")
def _table_law(par, tables, dummy, patch, creep, friction):
    """(T_x, T_y, M_z) of FASTSIM's creep-force table (tables.creep, contact.creep_table.table_creep_law) on a Hertz
    patch = (N, a, b, C11, C22, C23, C33) with the patch's Coulomb coefficient; FASTSIM itself
    (:func:`_creep_law`) where a/b is beyond the table.
    """
    normal, sa, sb, c11, c22, c23, _ = patch
    tx, ty, mz, inside = table_creep_law(
        tables.creep, par.shear_modulus_Pa, (sa, sb, c11, c22, c23), creep, friction.coefficient * normal
    )
    if inside:
        return tx, ty, mz
    return _creep_law(par, LAW_FASTSIM, dummy, patch, creep, friction)


@njit(cache=True, _nrt=False)
def _auto_threshold(par, rung, f):
    """Auto's threshold of feature f (layout.AUTO_FEATURE_NAMES) for rung (layout.AUTO_LINEAR, ...)."""
    if rung == AUTO_LINEAR:
        v = (par.auto_linear_saturation, par.auto_linear_spin_share, par.auto_linear_ellipticity_residual,
             par.auto_linear_curvature_change, par.auto_linear_second_patch_nearness)  # fmt: skip
    elif rung == AUTO_VERMEULEN_JOHNSON:
        v = (par.auto_vermeulen_johnson_saturation, par.auto_vermeulen_johnson_spin_share,
             par.auto_vermeulen_johnson_ellipticity_residual, par.auto_vermeulen_johnson_curvature_change,
             par.auto_vermeulen_johnson_second_patch_nearness)  # fmt: skip
    else:
        v = (par.auto_fastsim_saturation, par.auto_fastsim_spin_share, par.auto_fastsim_ellipticity_residual,
             par.auto_fastsim_curvature_change, par.auto_fastsim_second_patch_nearness)  # fmt: skip
    return v[f]


@njit(cache=True, _nrt=False)
def _auto_choice(par, feats):
    """auto.choose_rung in the loop: (rung as auto.AUTO_RUNGS, deciding feature index or -1, its threshold).
    The first of linear, Vermeulen-Johnson, FASTSIM (at the run's grid) whose measured box holds every feature;
    else BEM (layout.AUTO_BEM). The deciding feature: of the last rejected rung the feature furthest beyond its
    threshold; when the cheapest rung qualified, the feature closest to its threshold.
    """
    if math.isnan(par.auto_level):
        return AUTO_BEM, -1, np.nan
    last_f, last_t = -1, np.nan
    for rung in range(AUTO_BEM):
        if math.isnan(_auto_threshold(par, rung, 0)):
            continue  # no measured box at this level
        worst, worst_f = -1.0, -1
        for f in range(len(AUTO_FEATURE_NAMES)):
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
            for f in range(len(AUTO_FEATURE_NAMES)):
                box = _auto_threshold(par, rung, f)
                r = feats[f] / box if box > 0 else (0.0 if feats[f] <= 0 else 1.0)
                if r > best:
                    best, best_f = r, f
            return rung, best_f, _auto_threshold(par, rung, best_f)
        return rung, last_f, last_t
    return AUTO_BEM, last_f, last_t


@njit(cache=True, _nrt=False)
def _law(par, tables, dummy, geometry, creep, where, rec, c, record, shape=(0.0, 0.0, 0.0)):
    """The compiled contact law of one patch: (N, a, b, T_x, T_y, M_z, to_callback); to_callback: the patch is for
    the callback (``auto`` chose BEM, or its FASTSIM broke the friction bound as auto's does in contact.models).
    geometry = (q, A, B); creep = (xi, eta, phi); where = (place, rolling speed) of the friction law
    (:func:`patch_friction`; tables.friction); shape = auto's geometric features of the patch's sampled gap
    (ellipticity residual, curvature change, second-patch nearness: compiled_patch.sample_candidates; zeros for a
    quadric: nothing sampled).

    ``auto`` (par.model_code layout.LAW_AUTO): the features of contact.auto.patch_features (saturation
    w' = T_lin / (3 mu N), spin share G (ab)^1.5 C23 |phi| / max(T_lin, mu N) on Hertz's ellipse, and ``shape``,
    each below contact.auto.GEOMETRY_FLOOR taken as 0 as there), the rung by :func:`_auto_choice`, recorded (with
    ``record``) into rec[c] as layout.AUTO_PATCH_FIELDS; par.auto_fastsim_table 1: the FASTSIM rung served by the
    creep-force table. A rung served on the ellipse is one whose measured box holds the sampled gap's features too.
    """
    q, ca, cb = geometry
    xi, eta, spin = creep
    patch = _hertz_kalker(par, tables, q, ca, cb)
    normal, sa, sb, c11, c22, c23, c33 = patch
    code = int(par.model_code)
    friction = patch_friction(par, tables.friction, where)
    if code == LAW_TABLE:
        tx, ty, mz = _table_law(par, tables, dummy, patch, creep, friction)
        return normal, sa, sb, tx, ty, mz, False
    if code != LAW_AUTO:
        tx, ty, mz = _creep_law(par, code, dummy, patch, creep, friction)
        return normal, sa, sb, tx, ty, mz, False
    ab = sa * sb
    gab = par.shear_modulus_Pa * ab
    gab15 = gab * math.sqrt(ab)
    t_lin = math.hypot(-gab * c11 * xi, -gab * c22 * eta - gab15 * c23 * spin)
    mu_n = friction.coefficient * normal
    residual, change, nearness = shape
    feats = (
        t_lin / (3.0 * mu_n) if mu_n > 0 else np.inf,
        gab15 * c23 * abs(spin) / max(t_lin, mu_n) if max(t_lin, mu_n) > 0 else 0.0,
        residual if residual >= GEOMETRY_FLOOR else 0.0,
        change if change >= GEOMETRY_FLOOR else 0.0,
        nearness,
    )
    rung, deciding, threshold = _auto_choice(par, feats)
    to_callback = False
    tx, ty, mz = 0.0, 0.0, 0.0
    if rung == AUTO_FASTSIM and par.auto_fastsim_table > 0:  # the table serves auto's FASTSIM rung
        tx, ty, mz = _table_law(par, tables, dummy, patch, creep, friction)
    elif rung != AUTO_BEM:
        tx, ty, mz = _creep_law(par, rung + LAW_LINEAR, dummy, patch, creep, friction)
        if rung == AUTO_FASTSIM and math.hypot(tx, ty) > (1.0 + par.auto_friction_bound_tolerance) * mu_n:
            rung, to_callback = AUTO_BEM, True
    else:
        to_callback = True
    if record:
        rec[c, AUTO_RUNG], rec[c, AUTO_LEVEL], rec[c, AUTO_DECIDING_FEATURE] = rung, par.auto_level, deciding
        rec[c, AUTO_DECIDING_THRESHOLD] = threshold
        for f in range(len(AUTO_FEATURE_NAMES)):
            rec[c, AUTO_FEATURES + f] = feats[f]
    return normal, sa, sb, tx, ty, mz, to_callback


@njit(cache=True, _nrt=False)
def _kalker_c(tables, ratio):
    """Kalker's (C11, C22, C23) for a/b = ratio from the tables (:func:`_hertz_kalker`'s interpolation)."""
    kk = tables.kalker
    i, w = uniform_cell(math.log(ratio), tables.log_ab_start, tables.log_ab_step, kk.shape[1])
    return (
        kk[KALKER_C11, i] * (1 - w) + kk[KALKER_C11, i + 1] * w,
        kk[KALKER_C22, i] * (1 - w) + kk[KALKER_C22, i + 1] * w,
        kk[KALKER_C23, i] * (1 - w) + kk[KALKER_C23, i + 1] * w,
    )


@njit(cache=True, _nrt=False)
def _quadric_field(par, field, c, geometry):
    """The quadric gap A x'^2 + B y'^2 - q of geometry = (q, A, B, angle) on field's grid of candidate c: the box
    of the overlap ellipse's extent with the sampled grid's margin (kpec_margin of the extent and two spacings each
    side).
    """
    q, ca, cb, angle = geometry
    cs, sn = math.cos(angle), math.sin(angle)
    xs, ys, gap = field.xs[c], field.ys[c], field.gap[c]
    nx, ny = xs.shape[0], ys.shape[0]
    grow = 1.0 + 2.0 * par.kpec_margin
    hx = math.sqrt(q * (cs * cs / ca + sn * sn / cb)) * grow / max(1.0 - 4.0 / (nx - 1), 0.5)
    hy = math.sqrt(q * (sn * sn / ca + cs * cs / cb)) * grow / max(1.0 - 4.0 / (ny - 1), 0.5)
    for i in range(nx):
        xs[i] = -hx + 2.0 * hx * i / (nx - 1)
    for j in range(ny):
        ys[j] = -hy + 2.0 * hy * j / (ny - 1)
    for j in range(ny):
        for i in range(nx):
            xr, yr = cs * xs[i] + sn * ys[j], -sn * xs[i] + cs * ys[j]
            gap[j, i] = ca * xr * xr + cb * yr * yr - q


@njit(cache=True, _nrt=False)
def _kpec_law(par, tables, field, c, geometry, creep, mu):
    """CONTACT's KPEC + FASTSIM per strip (contact.kpec; the static semi_hertzian.KpecModel's steps) on candidate
    c's gap in ``field`` (compiled_patch.PatchScratch: sampled, else the quadric of geometry = (q, A, B, angle)
    filled here), approach-driven: the gap already holds -q at the contact point. creep = (xi, eta, phi); mu the
    patch's coefficient (compiled_rhs: the law at the patch's place and mean slip velocity, as the analytic laws).
    Kalker's C_ij of the flexibilities from the run's tables (relative error < 1e-7). Returns (N, a, b, T_x, T_y,
    M_z, area m^2, max pressure Pa); (a, b): the flexibilities' ellipse of the contact area; M_z about the contact
    point. N is NaN when the gap overlaps but KPEC puts pressure on no element (its equivalent ellipse misses the
    deepest row: seen where the overlap runs into grid rows whose normal misses a profile).
    """
    if field.sampled[c] == 0.0:
        _quadric_field(par, field, c, geometry)
    xs, ys, gap = field.xs[c], field.ys[c], field.gap[c]
    g_mod = par.shear_modulus_Pa
    nu = 1.0 - g_mod / par.contact_modulus_Pa
    pressure, contact = field.pressure, field.contact
    # fn_kpec: CONTACT's F_N of the flexibilities, the pressure before the in-row gaps are cleared
    fn_kpec, _, _, _, _, _, _, penetration = kpec_pressure_into(
        gap, xs, ys, (g_mod, nu), (pressure, contact), (field.first, field.last)
    )
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    total, count, pmax = 0.0, 0, 0.0
    for j in range(gap.shape[0]):
        for i in range(gap.shape[1]):
            total += pressure[j, i]
            pmax = max(pmax, pressure[j, i])
            if contact[j, i]:
                count += 1
    if count == 0:
        # no element carries pressure: no contact when the gap has no overlap, else KPEC failed on this gap (NaN:
        # compiled_rhs ends the run with layout.GAP_LAW_FAILED; a zero force would be a wrong number)
        if penetration > 0.0:
            return math.nan, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    a, b = flexibility_ellipse(contact, dx, dy)
    xi, eta, phi = creep
    l1, l2, l3 = blended_flexibilities((a, b), _kalker_c(tables, a / b), (fn_kpec, g_mod, mu), creep)
    fx, fy, mz = fastsim_strips(
        (pressure, contact), (xs, ys), (mu, xi, eta, phi), (l1, l2, l3), (field.tx, field.ty, field.slip)
    )
    return total * dx * dy, a, b, fx, fy, mz, count * dx * dy, pmax


@njit(cache=True)
def patch_forces(par, tables, q, ca, cb, xi, eta, spin, where=(0.0, 1.0)):
    """One patch through the compiled law of par.model_code (not the callback): (N, T_x, T_y, M_z, a, b,
    to_callback), for tests and inspection; where = (place, rolling speed m/s) of the friction law.
    """
    rec = np.zeros((1, N_FIELDS))
    normal, sa, sb, tx, ty, mz, st = _law(
        par, tables, np.zeros((1, 1)), (q, ca, cb), (xi, eta, spin), where, rec, 0, False
    )
    return normal, tx, ty, mz, sa, sb, st


def auto_parameters(par, tolerance: float, fastsim_grid) -> None:
    """Auto's thresholds (contact/data/auto_thresholds.json, contact.auto) into the parameter record: the level of
    ``tolerance`` (contact.auto.level_for; none: NaN, every patch BEM) and per rung (linear, Vermeulen-Johnson,
    FASTSIM at the run's grid by contact.auto.fastsim_rung) the feature box (NaN: no measured box).
    """
    from rigid_dynamics.contact.models import FRICTION_BOUND_TOLERANCE

    key, boxes = auto_boxes(tolerance, fastsim_grid)
    par["auto_friction_bound_tolerance"] = FRICTION_BOUND_TOLERANCE
    for rung in AUTO_RUNG_NAMES:
        for f in AUTO_FEATURE_NAMES:
            par[f"auto_{rung}_{f}"] = np.nan
    if key is None:
        par["auto_level"] = np.nan
        return
    par["auto_level"] = float(key)
    for rung, (_, box) in zip(AUTO_RUNG_NAMES, boxes, strict=True):
        if box is not None:
            for f in AUTO_FEATURE_NAMES:
                par[f"auto_{rung}_{f}"] = float(box[f])


def auto_boxes(tolerance: float, fastsim_grid) -> tuple:
    """(the level of ``tolerance`` or None, [(rung label, its feature box or None)] for the loop's compiled rungs
    linear, Vermeulen-Johnson and FASTSIM at the run's grid, in :data:`AUTO_RUNG_NAMES` order), from
    contact/data/auto_thresholds.json (contact.auto).
    """
    from rigid_dynamics.contact.auto import fastsim_rung, level_for, load_thresholds

    data = load_thresholds()
    key = level_for(tolerance, data)
    if key is None:
        return None, [(None, None)] * len(AUTO_RUNG_NAMES)
    level = data["levels"][key]
    labels = ("linear", "vermeulen-johnson", fastsim_rung(int(fastsim_grid[0]), int(fastsim_grid[1]), level))
    boxes = []
    for label in labels:
        entry = level.get(label) if label is not None else None
        boxes.append((label, None if entry is None else entry["thresholds"]))
    return key, boxes
