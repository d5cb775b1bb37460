"""The one right-hand side of the wheelset simulation (numba): candidate geometry, contact laws or the callback,
equations of motion.

Every integrator ends here: the compiled loop (compiled_loop.py: RK4 and the embedded pairs DP54/BS32) and the
scipy methods through wheelset_model.WheelsetModel.derivative, which calls :func:`rhs_once` / :func:`rhs_given`.
The run's arrays come as one record, compiled_records.PackedRun (``run``: the parameter record ``run.par``, the
Hertz/Kalker tables, the candidates' sides and slots, the geometry mode and its record), the scratch as another
(:class:`Workspace`); rows and columns are named in layout.py.

* Contact geometry (:func:`_geometry`, ``run.mode``): layout.GEOMETRY_TABLES the tables of a TableProvider with the
  running-direction irregularities (compiled_tables.py); layout.GEOMETRY_SEARCH the compiled 3-D search
  (compiled_search.py); layout.GEOMETRY_GIVEN given by the caller (a provider the compiled code does not evaluate:
  the conical one, the search on measured grids or harmonics, user providers, and the search outside the compiled
  loop).
* Creepages and the equations of motion (compiled_motion.py), the contact laws (compiled_laws.py).
* The callback boundary (:func:`_external`): contact models that are not compiled (bem, fea, user models; BEM when
  ``auto`` chooses it) get each patch (:class:`CallbackPatch`) handed out to one Python dispatcher
  (callback.PatchCallback) and give the forces back.

Elastic track: the candidate geometry is evaluated with the wheelset centre raised by that side's rail deflection
(tables: q = q_ref + (z - z_r - z_ref) dq/dz; search: the side's search at the raised centre), the creepages and
the contact power use the velocity relative to the rail.

Status codes: layout.STATUS (the one table).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, objmode

from rigid_dynamics.contact.friction import VARIES_ALONG_TRACK, VARIES_WITH_INCLINATION
from rigid_dynamics.wheelset.auto_reuse import NO_GAP, gap_descriptor, reuse_anchor, reuse_own, reuse_serve
from rigid_dynamics.wheelset.compiled_laws import (
    LAW_AUTO,
    LAW_BEM_CORRECTED,
    LAW_CALLBACK,
    LAW_KPEC,
    LAW_LINEAR,
    LAW_TABLE,
    _kpec_law,
    _law,
    mean_slip_coefficient,
    patch_friction,
)
from rigid_dynamics.wheelset.compiled_motion import _assemble, _patch_creepages, _rotation
from rigid_dynamics.wheelset.compiled_patch import patch_scratch, sample_candidates
from rigid_dynamics.wheelset.compiled_search import search_geometry, search_geometry_on_track
from rigid_dynamics.wheelset.compiled_tables import _table_geometry, table_scratch
from rigid_dynamics.wheelset.layout import (
    APPROACH,
    AUTO_BEM_CORRECTED,
    AUTO_FASTSIM,
    AUTO_RUNG,
    CALLBACK_FAILED,
    CONTACT_ANGLE,
    CONTACT_AREA,
    CONTACT_LAW,
    CONTACT_POINT_Y,
    CREEP_FORCE_LAT,
    CREEP_FORCE_LONG,
    CREEPAGE_LAT,
    CREEPAGE_LONG,
    CREEPAGES_UNDEFINED,
    ELLIPTICITY_RESIDUAL,
    FORMED,
    G_APPROACH,
    G_CONTACT_ANGLE,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_ELLIPSE_ANGLE,
    G_LEVER,
    G_NORMAL,
    G_ROLLING_RADIUS,
    G_WHEEL_LATERAL,
    GAP_LAW_FAILED,
    GEOMETRY_SEARCH,
    GEOMETRY_TABLES,
    MAX_PRESSURE,
    N_FIELDS,
    N_FORMED,
    N_GEO,
    N_SCRATCH,
    NORMAL_FORCE,
    NOT_FORMED,
    NOT_MAPPED,
    OK,
    PATCH_ELLIPSE,
    PATCH_GEOMETRY,
    PATCH_SAMPLED,
    ROLLING_RADIUS,
    S_EX,
    S_EY,
    S_LEVER,
    S_NORMAL,
    S_OMEGA,
    S_OMEGA_ABSOLUTE,
    S_PATCH_FORCE,
    S_PATCH_MOMENT,
    S_POINT_VELOCITY,
    S_ROTATION,
    S_SEARCH_CENTRE,
    S_SIDE_FORCE,
    S_TOTAL_FORCE,
    S_TOTAL_MOMENT,
    SEMI_AXIS_LAT,
    SEMI_AXIS_LONG,
    SPIN_CREEPAGE,
    SPIN_MOMENT,
    WHEEL_LATERAL,
)
from rigid_dynamics.wheelset.state import ROLL, SPIN, X_VELOCITY, Y_VELOCITY, YAW, Z_VELOCITY, X, Y, Z
from rigid_dynamics.wheelset.track import rail_lateral_under_wheel, rail_under_wheel


class Workspace(NamedTuple):
    """Scratch of the right-hand side (no allocation in the loop): the tables mode's (compiled_tables.TableScratch),
    the patch record (candidates + 2, layout.N_FIELDS), the candidate geometry (candidates, layout.N_GEO), the
    scratch rows (layout.SCRATCH_ROWS, 3), an empty field array for FASTSIM's kernel and the sampled patches
    (compiled_patch.PatchScratch) of the gap-solving laws.
    """

    tables: tuple
    rec: np.ndarray
    cg: np.ndarray
    scratch: np.ndarray
    dummy: np.ndarray
    patch: tuple


class CallbackPatch(NamedTuple):
    """One patch handed to the callback (Python side): candidate c of ``side`` at time t_s, its approach and
    relative curvatures, creepages and rolling speed, contact point and contact frame (e_x, e_y, n; main frame),
    rolling radius, contact angle and the wheel's lateral coordinate of the point, and the wheelset's pose (centre,
    main frame, m; yaw, roll and spin angle, rad: state.STATE_NAMES' first six) from which the callback can sample
    the real surfaces' undeformed distance around the patch.
    """

    candidate: int
    side: int
    t_s: float
    approach_m: float
    curvature_long_1_per_m: float
    curvature_lat_1_per_m: float
    creepage_long: float
    creepage_lat: float
    spin_creepage_1_per_m: float
    rolling_speed_m_per_s: float
    point_m: tuple
    normal: tuple
    e_x: tuple
    e_y: tuple
    rolling_radius_m: float
    contact_angle_rad: float
    wheel_lateral_m: float
    centre_m: tuple
    yaw_rad: float
    roll_rad: float
    spin_rad: float


class CallbackOutcome(NamedTuple):
    """What the callback gives back per patch (callback.PatchCallback.solve): forces on the wheel in the
    contact frame (N, T_x, T_y: N; M_z: N m), the semi-axes (or the equivalent ellipse's) a, b (m), contact area
    (m^2), max pressure (Pa), the geometry the model saw (layout.PATCH_ELLIPSE / PATCH_SAMPLED) and its ellipticity
    residual (NaN for an ellipse), the status (0 solved, 1 failed: the callback keeps its message), and ``own``: for
    a candidate that served a formed patch, that patch's own quantities in the order of layout.FORMED_PATCH_FIELDS
    (recorded, not applied: the forces above are the candidate's), else layout.NOT_FORMED; ``frame_map``: then the
    map from the candidate's frame to the formed patch's (formed_patches.frame_map; kept by ``auto``'s anchors),
    else layout.NOT_MAPPED.
    """

    normal_force_N: float
    creep_force_long_N: float
    creep_force_lat_N: float
    spin_moment_Nm: float
    semi_axis_long_m: float
    semi_axis_lat_m: float
    contact_area_m2: float
    max_pressure_Pa: float
    patch_geometry: int
    ellipticity_residual: float
    status: int
    own: tuple
    frame_map: tuple = NOT_MAPPED


_CALLBACK = [None]
"""The Python object that solves the patches of the non-compiled contact models (callback.PatchCallback),
set by :func:`use_callback` before a compiled run or right-hand side."""


def use_callback(callback) -> None:
    """Make ``callback`` the one the compiled code hands its patches to (see :func:`_external`)."""
    _CALLBACK[0] = callback


def _dispatch(patch: CallbackPatch):
    """The callback boundary's Python side: the patch to the callback in use (callback.PatchCallback.solve)."""
    return _CALLBACK[0].solve(patch)


@njit(cache=True, _nrt=False)
def _external(t, y, c, side, g, creep, frame):
    """The one callback boundary: candidate c of ``side`` at time t (its geometry row g, layout.GEOMETRY_FIELDS;
    creep = (rolling speed, xi, eta, spin); frame = (e_x, e_y) of the contact frame, main frame) handed to Python
    (numba objmode) as a :class:`CallbackPatch` and a :class:`CallbackOutcome`'s values taken back (N, T_x, T_y,
    M_z, a, b, area, max pressure, patch geometry code, ellipticity residual, status, the formed patch's own
    quantities and the frame map); status != 0: the contact model failed (the callback keeps its message). Overhead
    measured here: 2.0-2.1 us per objmode call of a trivial Python function; 25 us per patch through
    callback.PatchCallback with a model returning constant forces (its ContactGeometry and Creepage built per
    patch); a BEM patch at 40 x 40 takes about 20 ms.
    """
    speed, xi, eta, spin = creep
    ex, ey = frame
    q, ca, cb = g[G_APPROACH], g[G_CURVATURE_LONG], g[G_CURVATURE_LAT]
    point = (y[X] + g[G_LEVER], y[Y] + g[G_LEVER + 1], y[Z] + g[G_LEVER + 2])
    normal = (g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2])
    e_x, e_y = (ex[0], ex[1], ex[2]), (ey[0], ey[1], ey[2])
    radius, angle, lateral = g[G_ROLLING_RADIUS], g[G_CONTACT_ANGLE], g[G_WHEEL_LATERAL]
    centre = (y[X], y[Y], y[Z])
    yaw, roll, turn = y[YAW], y[ROLL], y[SPIN]
    # own: the formed patch's own quantities, layout.N_FORMED (12) of them, fmap: layout.N_FRAME_MAP (12) (literals:
    # numba reads the types)
    with objmode(normal_force="float64", tx="float64", ty="float64", mz="float64", sa="float64", sb="float64",
                 area="float64", pmax="float64", geom="int64", resid="float64", st="int64",
                 own="UniTuple(float64, 12)", fmap="UniTuple(float64, 12)"):  # fmt: skip
        normal_force, tx, ty, mz, sa, sb, area, pmax, geom, resid, st, own, fmap = _dispatch(
            CallbackPatch(
                c, side, t, q, ca, cb, xi, eta, spin, speed, point, normal, e_x, e_y, radius, angle, lateral,
                centre, yaw, roll, turn,
            )
        )  # fmt: skip
    return normal_force, tx, ty, mz, sa, sb, area, pmax, geom, resid, st, own, fmap


@njit(cache=True, _nrt=False)
def _auto_bem(t, y, c, side, g, creep, frame, laws, shape):
    """A patch ``auto`` gave to BEM: served by its stored BEM anchor's correction of FASTSIM within the trust
    region (auto_reuse.reuse_serve; recorded as rung layout.AUTO_BEM_CORRECTED, law compiled_laws.LAW_BEM_CORRECTED),
    else solved by the callback (:func:`_external`) and made the candidate's anchor (auto_reuse.reuse_anchor).
    Arguments as :func:`_external`'s; laws = (par, tables, dummy, where, rec, record); shape: the sampled gap's
    descriptor (auto_reuse.gap_descriptor; auto_reuse.NO_GAP on the quadric). Returns _external's values
    (without the frame map) and the law code; a served patch whose anchor was a formed patch gives the formed
    patch's own quantities at the served forces (auto_reuse.reuse_own; when ``record``), else layout.NOT_FORMED.
    """
    par, tables, dummy, where, rec, record = laws
    _, xi, eta, spin = creep
    point_y = y[Y] + g[G_LEVER + 1]
    served, normal, tx, ty, mz, sa, sb, area, pmax, geom, resid = reuse_serve(
        par, tables, dummy, g, (xi, eta, spin), where, c, shape
    )
    if served:
        own = NOT_FORMED
        if record:
            rec[c, AUTO_RUNG] = AUTO_BEM_CORRECTED
            own = reuse_own(tables.reuse, c, (normal, tx, ty, mz), (xi, eta, spin), g, point_y)
        return normal, tx, ty, mz, sa, sb, area, pmax, geom, resid, 0, own, LAW_BEM_CORRECTED
    normal, tx, ty, mz, sa, sb, area, pmax, geom, resid, st, own, fmap = _external(t, y, c, side, g, creep, frame)
    if st == 0:
        solved = (normal, tx, ty, mz, sa, sb, area, pmax, geom, resid)
        reuse_anchor(par, tables, dummy, g, (xi, eta, spin), where, c, t, solved, (own, fmap, point_y), shape)
    return normal, tx, ty, mz, sa, sb, area, pmax, geom, resid, st, own, LAW_CALLBACK


@njit(cache=True, _nrt=False)
def _served_law(par, rec, c, record):
    """The compiled law that served candidate c (compiled_laws.LAW_CODES): the run's, or for ``auto`` the rung it
    chose (recorded in rec[c, AUTO_RUNG] when ``record``; NaN otherwise, then LAW_AUTO; its FASTSIM rung served by
    the creep-force table: LAW_TABLE).
    """
    code = int(par.model_code)
    if code != LAW_AUTO:
        return code
    if record and not math.isnan(rec[c, AUTO_RUNG]):
        if int(rec[c, AUTO_RUNG]) == AUTO_FASTSIM and par.auto_fastsim_table > 0:
            return LAW_TABLE
        return int(rec[c, AUTO_RUNG]) + LAW_LINEAR
    return LAW_AUTO


@njit(cache=True, _nrt=False, inline="always")
def _friction_place(varies_code, y, g):
    """The place of a patch in the friction law's variable (contact.friction.VARIES_NAMES): the rail surface's
    inclination at the contact point (the contact angle, rad, positive towards the gauge face), or the distance
    along the track of the contact point (x of the centre plus the lever's x, m); 0 when the law varies nowhere.
    (The rail profile's lateral coordinate is not available in the loop: compiled_records.pack rejects it.)
    """
    if varies_code == VARIES_WITH_INCLINATION:
        return g[G_CONTACT_ANGLE]
    if varies_code == VARIES_ALONG_TRACK:
        return y[X] + g[G_LEVER]
    return 0.0


@njit(cache=True, _nrt=False)
def _forces(t, y, par, tables, sides, cg, rec, sc, dummy, field, record, out):
    """d/dt of the full state into ``out`` from the candidate geometry cg (ncand, layout.N_GEO) (a candidate with
    q = NaN is absent: recorded as NaN); fills the patch record rec (ncand + 2, layout.N_FIELDS) and the side
    forces when ``record``; sc: the scratch rows (layout.SCRATCH_ROWS, 3); dummy: FASTSIM's empty field array;
    field: the sampled patches (compiled_patch.PatchScratch) of LAW_KPEC and LAW_AUTO (auto's geometric features;
    the ellipticity residual recorded beside the ellipse auto's compiled rungs served).
    Returns the status (layout.STATUS). (The run's and the workspace's arrays are passed apart, not as their
    records: a record argument is passed field by field, and this runs for every right-hand side.)
    """
    n, lever, vel, ex, ey = sc[S_NORMAL], sc[S_LEVER], sc[S_POINT_VELOCITY], sc[S_EX], sc[S_EY]
    fc, mc = sc[S_PATCH_FORCE], sc[S_PATCH_MOMENT]
    force, moment, side_force = sc[S_TOTAL_FORCE], sc[S_TOTAL_MOMENT], sc[S_SIDE_FORCE : S_SIDE_FORCE + 2]
    om, rzx = sc[S_OMEGA], sc[S_ROTATION : S_ROTATION + 3]
    force[:] = 0.0
    moment[:] = 0.0
    side_force[:, :] = 0.0
    yc = y[Y]
    vx, vy, vz = y[X_VELOCITY], y[Y_VELOCITY], y[Z_VELOCITY]
    _rotation(y, om, rzx)
    # in a curve (track_frame): the creepages take the absolute angular velocity omega + Omega and the centre's
    # absolute velocity (x' h, y', z') (compiled_motion._assemble_curve); the contact power stays that on the
    # relative motion
    curve = par.track_frame > 0
    oma, vxa = om, vx
    w_1, w_2 = 0.0, 0.0
    if curve:
        oma = sc[S_OMEGA_ABSOLUTE]
        w_1 = par.curvature_1_per_m * vx * par.cant_sin
        w_2 = par.curvature_1_per_m * vx * par.cant_cos
        oma[0], oma[1], oma[2] = om[0], om[1] + w_1, om[2] + w_2
        vxa = vx * (1.0 + par.curvature_1_per_m * (par.cant_sin * y[Z] - par.cant_cos * yc))
    p_con = 0.0
    rail_vz = (rail_under_wheel(par, y, 0)[1], rail_under_wheel(par, y, 1)[1])
    rail_vy = (rail_lateral_under_wheel(par, y, 0)[1], rail_lateral_under_wheel(par, y, 1)[1])
    rail_f0, rail_f1, rail_fy0, rail_fy1 = 0.0, 0.0, 0.0, 0.0
    ncand = cg.shape[0]
    for c in range(ncand):
        g = cg[c]
        q = g[G_APPROACH]
        lever[0], lever[1], lever[2] = g[G_LEVER], g[G_LEVER + 1], g[G_LEVER + 2]
        n[0], n[1], n[2] = g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2]
        ca, cb = g[G_CURVATURE_LONG], g[G_CURVATURE_LAT]
        if record:
            for f in range(N_FIELDS):
                rec[c, f] = np.nan
            if not math.isnan(q):
                rec[c, NORMAL_FORCE] = 0.0
                rec[c, APPROACH] = q
                rec[c, CONTACT_POINT_Y] = yc + lever[1]
                rec[c, WHEEL_LATERAL] = g[G_WHEEL_LATERAL]
                rec[c, ROLLING_RADIUS] = g[G_ROLLING_RADIUS]
                rec[c, CONTACT_ANGLE] = g[G_CONTACT_ANGLE]
        if not q > 0.0:
            continue
        side = sides[c]
        # creepages relative to the rail (0: rigid track)
        speed, xi, eta, spin = _patch_creepages(lever, n, oma, vxa, vy, vz, rail_vy[side], rail_vz[side], vel, ex, ey)
        if not speed > 0.0:
            return CREEPAGES_UNDEFINED
        where = (_friction_place(tables.friction.varies_code, y, g), speed)
        own = NOT_FORMED
        if par.model_code == LAW_CALLBACK:
            normal, tx, ty, mz, sa, sb, area, pmax, geom, resid, st, own, _ = _external(
                t, y, c, side, g, (speed, xi, eta, spin), (ex, ey)
            )
            law = LAW_CALLBACK
            if st != 0:
                return CALLBACK_FAILED
        elif par.model_code == LAW_KPEC:
            angle = g[G_ELLIPSE_ANGLE] if math.isfinite(g[G_ELLIPSE_ANGLE]) else 0.0
            mu = mean_slip_coefficient(patch_friction(par, tables.friction, where), xi, eta)
            normal, sa, sb, tx, ty, mz, area, pmax = _kpec_law(
                par, tables, field, c, (q, ca, cb, angle), (xi, eta, spin), mu
            )
            if normal != normal:
                return GAP_LAW_FAILED
            sampled = field.sampled[c] > 0.0
            geom = PATCH_SAMPLED if sampled else PATCH_ELLIPSE
            resid = field.residual[c] if sampled else math.nan
            law = LAW_KPEC
        else:
            shape = (0.0, 0.0, 0.0)  # auto's geometric features: those of the sampled gap, else the quadric's
            if field.sampled[c] > 0.0:
                shape = (field.residual[c], field.curvature_change[c], field.nearness[c])
            normal, sa, sb, tx, ty, mz, to_callback = _law(
                par, tables, dummy, (q, ca, cb), (xi, eta, spin), where, rec, c, record, shape
            )
            # a compiled law sees the quadric: Hertz's ellipse, its area and max pressure
            area = math.pi * sa * sb
            pmax = 1.5 * normal / area if area > 0.0 else math.nan
            geom, resid = PATCH_ELLIPSE, math.nan
            if record and field.sampled[c] > 0.0:  # auto: the sampled gap's departure from the ellipse it served
                resid = field.residual[c]
            law = _served_law(par, rec, c, record)
            if to_callback:  # auto chose BEM (or FASTSIM broke the friction bound): its anchor or the callback
                gap_shape = NO_GAP
                if field.sampled[c] > 0.0:
                    gap_shape = gap_descriptor(field.xs[c], field.ys[c], field.gap[c], q, ca, cb)
                normal, tx, ty, mz, sa, sb, area, pmax, geom, resid, st, own, law = _auto_bem(
                    t,
                    y,
                    c,
                    side,
                    g,
                    (speed, xi, eta, spin),
                    (ex, ey),
                    (par, tables, dummy, where, rec, record),
                    gap_shape,
                )
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
            p1, p2 = yc + lever[1], y[Z] + lever[2]
            vel[0] -= w_1 * p2 - w_2 * p1
            vel[1] -= w_2 * lever[0]
            vel[2] -= -w_1 * lever[0]
        p_con += fc[0] * vel[0] + fc[1] * vel[1] + fc[2] * vel[2] + mc[0] * om[0] + mc[1] * om[1] + mc[2] * om[2]
        if side == 0:
            rail_f0 -= fc[2]
            rail_fy0 -= fc[1]
        else:
            rail_f1 -= fc[2]
            rail_fy1 -= fc[1]
        if record:
            for k in range(3):
                side_force[side, k] += fc[k]
            rec[c, NORMAL_FORCE] = normal
            rec[c, CREEP_FORCE_LONG] = tx
            rec[c, CREEP_FORCE_LAT] = ty
            rec[c, SPIN_MOMENT] = mz
            rec[c, CREEPAGE_LONG] = xi
            rec[c, CREEPAGE_LAT] = eta
            rec[c, SPIN_CREEPAGE] = spin
            rec[c, SEMI_AXIS_LONG] = sa
            rec[c, SEMI_AXIS_LAT] = sb
            rec[c, CONTACT_AREA] = area
            rec[c, MAX_PRESSURE] = pmax
            rec[c, PATCH_GEOMETRY] = geom
            rec[c, ELLIPTICITY_RESIDUAL] = resid
            rec[c, CONTACT_LAW] = law
            if not math.isnan(own[0]):  # a formed patch: its own quantities beside the candidate's (recorded)
                for k in range(N_FORMED):
                    rec[c, FORMED + k] = own[k]
    _assemble(t, y, par, force, moment, p_con, (rail_f0, rail_f1, rail_fy0, rail_fy1), om, rzx, out)
    if record:
        for sd in range(2):
            for k in range(3):
                rec[ncand + sd, k] = side_force[sd, k]
    return OK


@njit(cache=True, _nrt=False, inline="always")
def _rhs(t, y, run, ws, record, full, out):
    """d/dt of the full state: the candidate geometry (:func:`_geometry`; ``full``: the search with its lateral
    scan; mode layout.GEOMETRY_GIVEN: ws.cg as the caller filled it), then :func:`_forces`. Returns the status.
    Inlined (numba IR) at each call site, as :func:`_geometry`: a call would pass the run and workspace records field
    by field (some 430 scalars), which made the compiled loop's RK4 step 40 % dearer than the former RK4 loop's
    (benchmarks/results/compile_and_speed_issue25.md).
    """
    _geometry(y, run, ws, full)
    # KPEC solves the sampled gap; auto decides on its geometric features (ellipticity residual, curvature change,
    # second-patch nearness: a patch whose real gap is beyond a rung's measured box goes further up the ladder)
    code = run.par.model_code
    if code == LAW_KPEC or code == LAW_AUTO:
        if run.mode == GEOMETRY_SEARCH and run.par.patch_sampled > 0:
            sample_candidates(y, run, ws.cg, ws.patch, ws.scratch[S_SEARCH_CENTRE])
        else:
            ws.patch.sampled[:] = 0.0
    return _forces(t, y, run.par, run.tables, run.sides, ws.cg, ws.rec, ws.scratch, ws.dummy, ws.patch, record, out)


@njit(cache=True, _nrt=False, inline="always")
def _geometry(y, run, ws, full):
    """The candidate geometry at the state y into ws.cg (tables or search; given: left alone)."""
    par = run.par
    if run.mode == GEOMETRY_TABLES:
        _table_geometry(y, par, run.geometry, run.sides, ws.tables, ws.cg)
    elif run.mode == GEOMETRY_SEARCH:
        if par.elastic_track > 0:
            rails = (
                rail_under_wheel(par, y, 0)[0],
                rail_under_wheel(par, y, 1)[0],
                rail_lateral_under_wheel(par, y, 0)[0],
                rail_lateral_under_wheel(par, y, 1)[0],
            )
            search_geometry_on_track(y, rails, run.search, full, ws.cg, ws.scratch[S_SEARCH_CENTRE])
        else:
            search_geometry(y, run.search, full, ws.cg)


@njit(cache=True)
def workspace(run, rec):
    """A :class:`Workspace` for the run's candidates around the patch record ``rec`` (candidates + 2,
    layout.N_FIELDS).
    """
    ncand = run.sides.shape[0]
    return Workspace(
        table_scratch(run.par, ncand), rec, np.zeros((ncand, N_GEO)), np.zeros((N_SCRATCH, 3)), np.zeros((1, 1)),
        patch_scratch(run.par, ncand),
    )  # fmt: skip


@njit(cache=True)
def geometry_once(y, run, cg):
    """The candidate geometry alone (no contact law: the static equilibrium's approaches) into cg (tables or
    search).
    """
    ws = workspace(run, np.zeros((run.sides.shape[0] + 2, N_FIELDS)))
    _geometry(y, run, ws, True)
    cg[:, :] = ws.cg


@njit(cache=True)
def rhs_once(t, y, run, out, rec):
    """One right-hand side (with the lateral scan in the search mode) into out, its candidates into rec
    (ncand + 2, layout.N_FIELDS). Returns the status (for the static equilibrium before a compiled run).
    """
    return _rhs(t, y, run, workspace(run, rec), True, True, out)


@njit(cache=True)
def contact_once(t, y, run, out, rec, cg):
    """:func:`rhs_once` that also returns the candidate geometry into cg (ncand, layout.N_GEO) (for inspection: the
    contact frames and forces of wheelset_model.WheelsetModel.contact). Mode given: cg is the given geometry.
    """
    if run.mode != GEOMETRY_TABLES and run.mode != GEOMETRY_SEARCH:
        return rhs_given(t, y, run.par, run.tables, run.sides, cg, out, rec, True)
    ws = workspace(run, rec)
    st = _rhs(t, y, run, ws, True, True, out)
    cg[:, :] = ws.cg
    return st


@njit(cache=True)
def rhs_given(t, y, par, tables, sides, cg, out, rec, record):
    """The right-hand side on a given candidate geometry cg (ncand, layout.N_GEO) (a provider the compiled code
    does not evaluate): the compiled laws, the callback, the equations of motion, as in the loop. (The run's
    parameter record, Hertz/Kalker tables and sides only: called from Python per right-hand side, where every
    array of a record costs its unboxing.)
    """
    field = patch_scratch(par, sides.shape[0])  # no surfaces here: a gap-solving law sees the quadric
    return _forces(t, y, par, tables, sides, cg, rec, np.zeros((N_SCRATCH, 3)), np.zeros((1, 1)), field, record, out)


@njit(cache=True, _nrt=False)
def side_forces(rec, sides, out):
    """Per side (left, right) the sums of normal force, longitudinal and lateral creep force of the patches in
    contact (the patch record's first three columns, NaN or 0 for candidates out of contact) into out (2, 3), N.
    """
    out[:, :] = 0.0
    for c in range(sides.shape[0]):
        if rec[c, NORMAL_FORCE] > 0.0:
            for k in range(3):
                out[sides[c], k] += rec[c, k]


@njit(cache=True, _nrt=False)
def force_difference(f4, f3):
    """The largest |f4 - f3| over both sides' normal, longitudinal and lateral contact forces (two side_forces
    results, (2, 3)), N; inf when one is NaN (forces not computable at one of the two states). The force error
    estimate of every compiled loop (the propagated solution against the embedded lower-order one).
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
