"""``auto``'s BEM patches reused across right-hand sides within a trust region (compiled).

A patch auto gives to BEM is solved by the callback (BEM on the sampled gap, callback.PatchCallback) and that
solution is kept per candidate as an *anchor*: the cheap rung's value at the same input (FASTSIM on Hertz's ellipse
at the run's grid, compiled_laws._creep_law) and the BEM's departure from it, in the normalised form of
contact.creep_table (creep forces over mu N, spin moment over mu N sqrt(ab)) and as ratios of the normal force, the
semi-axes, the contact area and the max pressure to Hertz's. Later right-hand sides whose inputs stay within the
anchor's trust region are served by FASTSIM on the ellipse corrected by the stored departure (:func:`reuse_serve`)::

    N = N_Hertz r_N,    F = mu N (f_FASTSIM(c*, a/b) + (f_BEM - f_FASTSIM)_anchor)   (|F| <= mu N)

The inputs and their distance from the anchor (the largest of): the normalised creepages c* = (xi*, eta*, phi^)
(creep_table.normalised_creepages), |c* - c*_0| / (|c*_0| + ``creep_floor``); ln(a/b) and ln q (approach), each
as |change| (times a weight, :data:`DEFAULTS`); the contact point's lateral place on the wheel profile over the
anchor's lateral semi-axis |y_w - y_w0| / b_0 (a patch moving across the profile changes its sampled shape); and
when the patch's gap is sampled (patch_geometry "sampled"), what the quadric does not see of it: the change of the
overlap's volume relative to the quadric's, |change of ln(V / V_q)|, and the move of the overlap's centroid in the
quadric's semi-axes (:func:`gap_descriptor`), so that a flat or a polygon's facet passing under the patch leaves
the region although the curvatures at the contact point, and with them the ellipse, stay the same.
Leaving the region (distance above the candidate's radius), the patch is solved by the callback again and becomes
the new anchor.

The radius adapts to the error it causes, measured in the run: at each re-solve from inside twice the radius the
corrected value the old anchor would have served is compared with the fresh BEM solution (the correction's error at
the trust region's edge, where it is largest: the error grows with the distance): the creep force by the bench's
definition |F - F_BEM| / max(|F_BEM|, 0.01 mu N_BEM) and the normal force |N - N_BEM| / N_BEM, in the plane the
fresh solution was solved in (a formed patch's own, below; else the candidate's: :func:`_correction_errors`).
Above half the tolerance level the candidate's radius halves (down to ``radius_min``), below an eighth of it it
grows by half (up to ``radius_max``; :data:`DEFAULTS`). The run's largest observed errors, the served and solved
counts are kept in the store's last row (:data:`STATS` columns) and reported in summary.json
(callback.PatchCallback.stats, ``auto_reuse``).

A BEM patch formed as the static case forms it (formed_patches.py: solved in its own plane, its forces applied in
the candidate's frame) makes an anchor that also keeps the map from the candidate's frame to the formed patch's and
the formed patch's geometry as departures from the candidate's; a patch it serves is then recorded in that plane
(:func:`reuse_own`), as the patches the callback solves are, so that a run's record does not switch frames between
the samples the callback solved and those the anchor served (the forces applied are unchanged).

The store (:func:`reuse_store`) is an array of the run (compiled_laws.HertzKalkerTables.reuse): one row per
candidate (:data:`ANCHOR` columns), the statistics row last. Off (par.auto_reuse 0, scene key ``auto_reuse``; and
for a tolerance below every measured level, where auto asks for BEM on every patch): every BEM patch is solved by
the callback, as before.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rigid_dynamics.contact.creep_table import normalised_creepages
from rigid_dynamics.wheelset.compiled_laws import LAW_FASTSIM, _creep_law, _hertz_kalker, patch_friction
from rigid_dynamics.wheelset.layout import (
    G_APPROACH,
    G_CONTACT_ANGLE,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_ROLLING_RADIUS,
    G_WHEEL_LATERAL,
    N_FRAME_MAP,
    NOT_FORMED,
)

ANCHOR = (
    "valid", "creep_star_long", "creep_star_lat", "creep_star_spin", "log_ab", "log_approach", "wheel_lateral_m",
    "half_width_m", "radius", "normal_ratio", "force_long_departure", "force_lat_departure", "moment_departure",
    "semi_axis_long_ratio", "semi_axis_lat_ratio", "area_ratio", "max_pressure_ratio", "patch_geometry",
    "ellipticity_residual", "formed",
    *(f"frame_map_{k}" for k in range(N_FRAME_MAP)),
    "formed_creepage_long_rigid", "formed_creepage_lat_rigid", "formed_spin_departure_1_per_m",
    "formed_approach_departure_m", "formed_point_y_departure_m", "formed_wheel_lateral_departure_m",
    "formed_rolling_radius_departure_m", "formed_contact_angle_departure_rad",
    "gap_log_volume_ratio", "gap_centroid_long", "gap_centroid_lat",
)  # fmt: skip
"""Columns of a candidate's row: its anchor (valid 1/0), the anchor's inputs, the trust radius, the corrections,
the anchor's patch geometry code and ellipticity residual, and for an anchor that was a formed patch (``formed``
1/0; formed_patches.py) what records a served patch in that patch's plane (:func:`reuse_own`): the frame map
(formed_patches.frame_map), the rigid motion's part of the transported creepages (k_x, k_y and the spin's
departure), and the departures of the formed patch's approach, reference point y, wheel lateral coordinate,
rolling radius and contact angle from the candidate's."""
(
    R_VALID, R_XS, R_YS, R_PS, R_LOG_AB, R_LOG_Q, R_WHEEL_Y, R_HALF_WIDTH, R_RADIUS, R_NORMAL_RATIO, R_DFX, R_DFY,
    R_DMZ, R_A_RATIO, R_B_RATIO, R_AREA_RATIO, R_PMAX_RATIO, R_GEOMETRY, R_RESIDUAL, R_FORMED,
) = range(20)  # fmt: skip
R_MAP = R_FORMED + 1
"""The first of the frame map's columns (Q row by row, then w: formed_patches.frame_map)."""
MAP_Q22, MAP_W = 8, 9
"""Positions in a frame map (formed_patches.frame_map): Q[2][2] = n . n' and the first of w."""
F_XI, F_ETA, F_SPIN, F_APPROACH, F_POINT_Y, F_LATERAL, F_RADIUS, F_ANGLE = range(
    R_MAP + N_FRAME_MAP, R_MAP + N_FRAME_MAP + 8
)
"""Columns of the formed patch's departures from the candidate's: the transported creepages' rigid-motion parts
(k_x, k_y) and the spin's departure, then the approach, reference point y, wheel lateral coordinate, rolling radius
and contact angle."""
R_GAP = F_ANGLE + 1
"""The first of the sampled-gap descriptor's three columns (:func:`gap_descriptor`)."""
NO_GAP = (math.nan, math.nan, math.nan)
"""The descriptor of a patch whose geometry is the quadric's (no sampled gap)."""
STATS = (
    "served",
    "solved",
    "checked",
    "max_force_error",
    "max_normal_error",
    "max_force_error_t_s",
    "radius_shrunk",
    "radius_grown",
    "checked_above_tolerance",
)
"""Columns of the statistics row (the last): right-hand-side patches served by the correction, solved by the
callback, re-solves whose correction error was measured, the largest measured errors (creep force, bench
definition; normal force, relative) and the time of the largest, radius changes, measured errors above the tolerance
level."""
T_SERVED, T_SOLVED, T_CHECKED, T_MAX_FORCE, T_MAX_NORMAL, T_MAX_T, T_SHRUNK, T_GROWN, T_ABOVE = range(len(STATS))
SETTINGS = ("radius_start", "radius_min", "radius_max", "creep_floor", "approach_weight", "shape_weight",
            "place_weight", "gap_weight")  # fmt: skip
"""The trust region's settings, kept in the statistics row after :data:`STATS` (set by :func:`reuse_store` from
:data:`DEFAULTS`, so that a study can change them without recompiling): the radii, the creepage distance's floor and
the weights of |change of ln q|, |change of ln(a/b)|, of the lateral place and of the sampled gap's descriptor in
the distance."""
C_RADIUS_START, C_RADIUS_MIN, C_RADIUS_MAX, C_CREEP_FLOOR, C_APPROACH, C_SHAPE, C_PLACE, C_GAP = range(
    len(STATS), len(STATS) + len(SETTINGS)
)
N_REUSE = max(len(ANCHOR), len(STATS) + len(SETTINGS))

DEFAULTS = {
    "radius_start": 0.1,
    "radius_min": 0.0125,
    "radius_max": 0.4,
    "creep_floor": 0.1,
    "approach_weight": 1.0,
    "shape_weight": 1.0,
    "place_weight": 1.0,
    "gap_weight": 4.0,
}
"""The settings (:data:`SETTINGS`): a new anchor's radius, its bounds; the creep floor added to |c*_0| in the
creepage distance (near zero creepage the force is linear in c* and small; 0.1 is a tenth of the saturation
scale); the weights of the other distances. The sampled gap's weight was measured on wheel-flat's first impact
(0.0135 s, contact_tolerance 0.05; same-state departure from the loop's BEM at auto's output samples, bench
definition): weights 1 / 4 / 8 gave 390 / 676 / 986 BEM solves (always-BEM: 17904), a largest creep-force
departure of 52 / 14 / 10 % and 58 of 306 / 32 of 578 / 20 of 823 measured corrections above 5 %; the remaining
departures are at creep forces of 0.01-0.02 mu N, where two BEM runs through the same states differ by 9.5 %
(callback.LADDER_STEP) and the BEM's own grid-error estimate reaches 0.49 of the bench's creep-force scale."""


def reuse_store(candidates: int, settings: dict | None = None) -> np.ndarray:
    """A fresh store for ``candidates`` candidates (no anchor), the statistics row (zeros) and the settings
    (:data:`DEFAULTS`, updated by ``settings``).
    """
    values = {**DEFAULTS, **(settings or {})}
    store = np.zeros((candidates + 1, N_REUSE))
    store[:candidates, R_RADIUS] = values["radius_start"]
    for k, name in enumerate(SETTINGS):
        store[-1, len(STATS) + k] = values[name]
    return store


def reuse_stats(store: np.ndarray, tolerance: float | None) -> dict:
    """The statistics row of a run's store as a dict (summary.json ``auto_reuse``)."""
    row = store[-1]
    served, solved = int(row[T_SERVED]), int(row[T_SOLVED])
    checked = int(row[T_CHECKED])
    return {
        "served_by_correction": served,
        "solved_by_callback": solved,
        "share_served_by_correction": served / (served + solved) if served + solved else 0.0,
        "errors_measured": checked,
        "max_creep_force_error": float(row[T_MAX_FORCE]) if checked else None,
        "max_creep_force_error_t_s": float(row[T_MAX_T]) if checked else None,
        "max_normal_force_error": float(row[T_MAX_NORMAL]) if checked else None,
        "errors_above_tolerance": int(row[T_ABOVE]),
        "tolerance": tolerance,
        "radius_shrunk": int(row[T_SHRUNK]),
        "radius_grown": int(row[T_GROWN]),
        "settings": {name: float(row[len(STATS) + k]) for k, name in enumerate(SETTINGS)},
        "error_definition": (
            "the corrected FASTSIM value the old anchor would have served against the fresh BEM solution, at each "
            "re-solve from inside twice the trust radius: creep force |F - F_BEM| / max(|F_BEM|, 0.01 mu N_BEM), "
            "normal force |N - N_BEM| / N_BEM"
        ),
    }


@njit(cache=True, _nrt=False, inline="always")
def _enabled(par, store, c):
    """Whether candidate c may be reused: the run's switch (par.auto_reuse), a measured tolerance level (a tolerance
    below every level asks for BEM on every patch: no reuse) and a row in the store.
    """
    return par.auto_reuse > 0.0 and par.auto_level > 0.0 and c < store.shape[0] - 1


@njit(cache=True, _nrt=False)
def _cheap(par, tables, dummy, g, creep, where):
    """FASTSIM on Hertz's ellipse of the geometry row g at creep = (xi, eta, phi): ((N, a, b, mu N), (F_x, F_y, M_z)
    normalised by mu N and mu N sqrt(ab), c* (3-tuple), ln(a/b)); mu N = 0: no friction bound (forces 0).
    """
    patch = _hertz_kalker(par, tables, g[G_APPROACH], g[G_CURVATURE_LONG], g[G_CURVATURE_LAT])
    normal, sa, sb, c11, c22, c23, _ = patch
    friction = patch_friction(par, tables.friction, where)
    mu_n = friction.coefficient * normal
    if not mu_n > 0.0:
        return (normal, sa, sb, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), math.log(sa / sb)
    tx, ty, mz = _creep_law(par, LAW_FASTSIM, dummy, patch, creep, friction)
    star = normalised_creepages(par.shear_modulus_Pa, (sa, sb, c11, c22, c23), mu_n, creep)
    return (normal, sa, sb, mu_n), (tx / mu_n, ty / mu_n, mz / (mu_n * math.sqrt(sa * sb))), star, math.log(sa / sb)


@njit(cache=True, _nrt=False)
def gap_descriptor(xs, ys, gap, q, ca, cb):
    """What the trust region sees of a sampled gap (gap[j, i] = h(xs[i], ys[j]) - q, negative in the overlap, on a
    uniform grid; q the approach, ca, cb the quadric's coefficients of the same patch, 1/m): (ln(V / V_q), x_c / a_q,
    y_c / b_q) with V the overlap's volume (the integral of -gap where negative), V_q = pi q^2 / (2 sqrt(ca cb)) the
    quadric's, (x_c, y_c) the centroid of -gap over the overlap and a_q = sqrt(q / ca), b_q = sqrt(q / cb) the
    quadric's overlap semi-axes. A flat or a polygon's facet passing under the patch moves the centroid and changes
    the volume at an unchanged quadric; on a round wheel and rail the descriptor stays put. :data:`NO_GAP` when the
    grid, the approach or the quadric cannot define it or the sampled gap has no overlap.
    """
    if xs.shape[0] < 2 or ys.shape[0] < 2 or not (q > 0.0 and ca > 0.0 and cb > 0.0):
        return NO_GAP
    volume, moment_x, moment_y = 0.0, 0.0, 0.0
    for j in range(ys.shape[0]):
        for i in range(xs.shape[0]):
            depth = -gap[j, i]
            if depth > 0.0:
                volume += depth
                moment_x += depth * xs[i]
                moment_y += depth * ys[j]
    if not volume > 0.0:
        return NO_GAP
    cell = (xs[1] - xs[0]) * (ys[1] - ys[0])
    volume_q = math.pi * q * q / (2.0 * math.sqrt(ca * cb))
    return (
        math.log(volume * cell / volume_q),
        moment_x / volume / math.sqrt(q / ca),
        moment_y / volume / math.sqrt(q / cb),
    )


@njit(cache=True, _nrt=False)
def _gap_distance(row, shape):
    """The sampled gap's distance from the anchor's: the larger of |change of ln(V / V_q)| and the centroid's move
    (:func:`gap_descriptor`); 0 when neither was sampled, inf when one was and the other not.
    """
    here, there = math.isfinite(shape[0]), math.isfinite(row[R_GAP])
    if not here and not there:
        return 0.0
    if here != there:
        return math.inf
    moved = math.hypot(shape[1] - row[R_GAP + 1], shape[2] - row[R_GAP + 2])
    return max(abs(shape[0] - row[R_GAP]), moved)


@njit(cache=True, _nrt=False)
def _distance(row, star, log_ab, g, st, shape):
    """The distance of the inputs from the anchor in ``row`` (module docstring; st the statistics row: settings;
    shape the sampled gap's descriptor, :func:`gap_descriptor`).
    """
    xs, ys, ps = star
    ds = math.sqrt((xs - row[R_XS]) ** 2 + (ys - row[R_YS]) ** 2 + (ps - row[R_PS]) ** 2)
    s0 = math.sqrt(row[R_XS] ** 2 + row[R_YS] ** 2 + row[R_PS] ** 2)
    d = ds / (s0 + st[C_CREEP_FLOOR])
    d = max(d, st[C_SHAPE] * abs(log_ab - row[R_LOG_AB]))
    d = max(d, st[C_APPROACH] * abs(math.log(g[G_APPROACH]) - row[R_LOG_Q]))
    d = max(d, st[C_GAP] * _gap_distance(row, shape))
    return max(d, st[C_PLACE] * abs(g[G_WHEEL_LATERAL] - row[R_WHEEL_Y]) / row[R_HALF_WIDTH])


@njit(cache=True, _nrt=False)
def _corrected(row, hertz, forces):
    """(N, T_x, T_y, M_z, a, b, area, max pressure) of the anchor's correction applied to FASTSIM's normalised
    ``forces`` on the Hertz patch ``hertz`` = (N, a, b, mu N).
    """
    normal_h, sa, sb, mu_n = hertz
    fx, fy, mz = forces
    normal = normal_h * row[R_NORMAL_RATIO]
    mu_nc = mu_n * row[R_NORMAL_RATIO]
    gx, gy = fx + row[R_DFX], fy + row[R_DFY]
    size = math.hypot(gx, gy)
    if size > 1.0:  # Coulomb's bound on the corrected force
        gx, gy = gx / size, gy / size
    area_h = math.pi * sa * sb
    pmax_h = 1.5 * normal_h / area_h if area_h > 0.0 else math.nan
    return (
        normal, mu_nc * gx, mu_nc * gy, mu_nc * math.sqrt(sa * sb) * (mz + row[R_DMZ]), sa * row[R_A_RATIO],
        sb * row[R_B_RATIO], area_h * row[R_AREA_RATIO], pmax_h * row[R_PMAX_RATIO],
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def reuse_serve(par, tables, dummy, g, creep, where, c, shape):
    """Candidate c by its anchor's correction when the inputs are within its trust region: (served, N, T_x, T_y,
    M_z, a, b, area, max pressure, patch geometry code, ellipticity residual); served False: solve it (callback).
    shape: the sampled gap's descriptor (:func:`gap_descriptor`; :data:`NO_GAP` on the quadric).
    """
    store = tables.reuse
    if not _enabled(par, store, c) or store[c, R_VALID] <= 0.0 or not g[G_APPROACH] > 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, math.nan
    row = store[c]
    hertz, forces, star, log_ab = _cheap(par, tables, dummy, g, creep, where)
    mu_n = hertz[-1]
    if not mu_n > 0.0 or _distance(row, star, log_ab, g, store[-1], shape) > row[R_RADIUS]:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, math.nan
    n, tx, ty, mz, sa, sb, area, pmax = _corrected(row, hertz, forces)
    store[-1, T_SERVED] += 1.0
    return True, n, tx, ty, mz, sa, sb, area, pmax, int(row[R_GEOMETRY]), row[R_RESIDUAL]


@njit(cache=True, _nrt=False)
def _measure(st, radius, errors, level, t):
    """Count a measured correction error (errors = (creep, normal)) in the statistics row st and return the radius
    adapted to it (module docstring).
    """
    e_f, e_n = errors
    st[T_CHECKED] += 1.0
    if e_f > st[T_MAX_FORCE]:
        st[T_MAX_FORCE], st[T_MAX_T] = e_f, t
    st[T_MAX_NORMAL] = max(st[T_MAX_NORMAL], e_n)
    worst = max(e_f, e_n)
    if worst > level:
        st[T_ABOVE] += 1.0
    if worst > 0.5 * level and radius > st[C_RADIUS_MIN]:
        st[T_SHRUNK] += 1.0
        return max(0.5 * radius, st[C_RADIUS_MIN])
    if worst < 0.125 * level and radius < st[C_RADIUS_MAX]:
        st[T_GROWN] += 1.0
        return min(1.5 * radius, st[C_RADIUS_MAX])
    return radius


@njit(cache=True, _nrt=False, inline="always")
def _formed_components(m, vector):
    """Q^T v: the candidate-frame components ``vector`` (x, y, normal) in the formed patch's frame, Q the direction
    cosines at the start of the frame map ``m`` (formed_patches.frame_map, row by row).
    """
    x, y, z = 0.0, 0.0, 0.0
    for i, v in enumerate(vector):
        x += m[3 * i] * v
        y += m[3 * i + 1] * v
        z += m[3 * i + 2] * v
    return x, y, z


@njit(cache=True, _nrt=False)
def _keep_formed(row, creep, g, formed):
    """Keep in the anchor ``row`` what records a served patch in the formed patch's plane (:data:`ANCHOR`), from
    formed = (the formed patch's own quantities, layout.FORMED_PATCH_FIELDS' order; the frame map; the candidate's
    point y), or mark the anchor as not formed (own quantities NaN: the candidate served no formed patch).
    """
    own, fmap, point_y = formed
    if math.isnan(own[0]) or math.isnan(fmap[0]):
        row[R_FORMED] = 0.0
        return
    row[R_FORMED] = 1.0
    for k in range(N_FRAME_MAP):
        row[R_MAP + k] = fmap[k]
    _, _, _, _, xi_f, eta_f, spin_f, approach_f, point_y_f, lateral_f, radius_f, angle_f = own
    xi, eta, spin = creep
    xi_r, eta_r, _ = _formed_components(fmap, (xi, eta, 0.0))
    row[F_XI], row[F_ETA], row[F_SPIN] = xi_f - xi_r, eta_f - eta_r, spin_f - spin
    row[F_APPROACH], row[F_POINT_Y] = approach_f - g[G_APPROACH], point_y_f - point_y
    row[F_LATERAL], row[F_RADIUS] = lateral_f - g[G_WHEEL_LATERAL], radius_f - g[G_ROLLING_RADIUS]
    row[F_ANGLE] = angle_f - g[G_CONTACT_ANGLE]


@njit(cache=True, _nrt=False)
def reuse_own(store, c, forces, creep, g, point_y):
    """The own quantities (layout.FORMED_PATCH_FIELDS' order) of the formed patch candidate c serves by its anchor's
    correction, at the served ``forces`` (N, T_x, T_y, M_z in the candidate's frame), the candidate's ``creep`` =
    (xi, eta, phi), geometry row g and point y: the forces turned into the anchor's formed plane by the kept frame
    map (formed_patches.frame_map: (T_x', T_y', N') = Q^T (T_x, T_y, N), M_z' = (M_z - w . (T_x, T_y, N)) /
    Q[2][2], the inverse of what the loop applies), the creepages transported with the anchor's rigid-motion part,
    the geometry as the candidate's plus the anchor's departures. All NaN when the anchor was not a formed patch
    (the record keeps the candidate's). Recorded, not applied.
    """
    row = store[c]
    if row[R_FORMED] <= 0.0:
        return NOT_FORMED
    m = row[R_MAP : R_MAP + N_FRAME_MAP]
    normal, tx, ty, mz = forces
    own_x, own_y, own_n = _formed_components(m, (tx, ty, normal))
    arm = 0.0
    for k, component in enumerate((tx, ty, normal)):
        arm += m[MAP_W + k] * component
    xi, eta, spin = creep
    xi_r, eta_r, _ = _formed_components(m, (xi, eta, 0.0))
    return (
        own_n, own_x, own_y, (mz - arm) / m[MAP_Q22], xi_r + row[F_XI], eta_r + row[F_ETA], spin + row[F_SPIN],
        g[G_APPROACH] + row[F_APPROACH], point_y + row[F_POINT_Y], g[G_WHEEL_LATERAL] + row[F_LATERAL],
        g[G_ROLLING_RADIUS] + row[F_RADIUS], g[G_CONTACT_ANGLE] + row[F_ANGLE],
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def _correction_errors(served, fresh, mu_n, fmap):
    """(creep, normal) error of the ``served`` (N, T_x, T_y) against the ``fresh`` BEM solution (candidate's frame;
    mu_n: mu times the fresh N): the creep force by the bench's definition |F - F_BEM| / max(|F_BEM|, 0.01 mu N_BEM)
    and the normal force |N - N_BEM| / N_BEM, in the plane the patch was solved in: the formed patch's (both forces
    turned by its frame map ``fmap``, formed_patches.frame_map) when the fresh solution was one, else the
    candidate's. (On a conformal flange root the candidate's plane lies 0.26 rad off the formed patch's: there its
    creep force is mostly a component of the normal force, a few per cent of the patch's own, and an error of the
    normal force read as tens of times that error of the creep force.)
    """
    n, tx, ty = served
    n_b, tx_b, ty_b = fresh
    if not math.isnan(fmap[0]):
        tx_b, ty_b, n_f = _formed_components(fmap, (tx_b, ty_b, n_b))
        mu_n *= n_f / n_b
        n_b = n_f
        tx, ty, n = _formed_components(fmap, (tx, ty, n))
    e_f = math.hypot(tx - tx_b, ty - ty_b) / max(math.hypot(tx_b, ty_b), 0.01 * mu_n)
    return e_f, abs(n - n_b) / n_b


@njit(cache=True, _nrt=False)
def reuse_anchor(par, tables, dummy, g, creep, where, c, t, solved, formed, shape):
    """Candidate c solved by the callback at this input (solved = (N, T_x, T_y, M_z, a, b, area, max pressure,
    patch geometry code, ellipticity residual); formed = (the formed patch's own quantities, NaN if none; the frame
    map; the candidate's point y): :func:`_keep_formed`; shape: the sampled gap's descriptor, :func:`gap_descriptor`):
    measure the old anchor's correction against it when the input is within twice the old radius (adapting the
    radius), then make it the anchor (module docstring).
    """
    store = tables.reuse
    if not _enabled(par, store, c):
        return
    store[-1, T_SOLVED] += 1.0
    n_b, tx_b, ty_b, mz_b, sa_b, sb_b, area_b, pmax_b, geom, resid = solved
    row = store[c]
    if not (g[G_APPROACH] > 0.0 and n_b > 0.0):
        row[R_VALID] = 0.0
        return
    hertz, forces, star, log_ab = _cheap(par, tables, dummy, g, creep, where)
    normal_h, sa, sb, mu_n = hertz
    if not mu_n > 0.0:
        row[R_VALID] = 0.0
        return
    radius = row[R_RADIUS]
    if row[R_VALID] > 0.0 and _distance(row, star, log_ab, g, store[-1], shape) <= 2.0 * radius:
        n, tx, ty, _, _, _, _, _ = _corrected(row, hertz, forces)
        errors = _correction_errors((n, tx, ty), (n_b, tx_b, ty_b), mu_n * n_b / normal_h, formed[1])
        radius = _measure(store[-1], radius, errors, par.auto_level, t)
    ratio = n_b / normal_h
    mu_nb = mu_n * ratio
    fx, fy, mz = forces
    row[R_VALID] = 1.0
    row[R_XS], row[R_YS], row[R_PS] = star
    row[R_LOG_AB], row[R_LOG_Q], row[R_WHEEL_Y] = log_ab, math.log(g[G_APPROACH]), g[G_WHEEL_LATERAL]
    row[R_HALF_WIDTH] = sb
    row[R_RADIUS] = radius
    row[R_NORMAL_RATIO] = ratio
    row[R_DFX] = tx_b / mu_nb - fx
    row[R_DFY] = ty_b / mu_nb - fy
    row[R_DMZ] = mz_b / (mu_nb * math.sqrt(sa * sb)) - mz
    row[R_A_RATIO], row[R_B_RATIO] = sa_b / sa, sb_b / sb
    area_h = math.pi * sa * sb
    row[R_AREA_RATIO] = area_b / area_h if math.isfinite(area_b) else 1.0
    pmax_h = 1.5 * normal_h / area_h
    row[R_PMAX_RATIO] = pmax_b / pmax_h if math.isfinite(pmax_b) else 1.0
    row[R_GEOMETRY], row[R_RESIDUAL] = geom, resid
    row[R_GAP], row[R_GAP + 1], row[R_GAP + 2] = shape
    _keep_formed(row, creep, g, formed)
