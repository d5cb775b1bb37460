"""Contact patches of one wheel on its rail formed as CONTACT's wheel-rail module forms them.

The 3-D search (search.py) gives one patch per local minimum of the normal distance, with the contact plane
at the deepest point. CONTACT's module 1 (E.A.H. Vollebregt, J.J. Kalker; open source, user guide sec.
"Identification of contact patches", Vollebregt 2020 "Detailed wheel/rail geometry processing") instead:

1. takes the *vertical* gap g(y) = z_rail(y) - z_wheel(y) between the rail surface and the wheel's contact locus
   (the line on the wheel where its surface is horizontal along the track, i.e. its lowest points seen along
   the track; with yaw it leaves the plane x = 0) as a function of the track's lateral coordinate y;
2. splits {g < 0} into interpenetration regions (intervals of y);
3. joins regions that lie close: regions whose distance d (between their end points on the rail surface, in the
   y-z plane) is at most D_SEP and whose contact angles differ by at most A_SEP are solved as one patch, with
   their elastic interaction: in full for regions at most D_COMB apart, reduced by the factor
   f = ((D_SEP - d)/(D_SEP - D_COMB))^0.8 between sub-patches D_COMB < d <= D_SEP apart ("blended", CONTACT's
   IPLAN = 4: :func:`sub_patches`, carried by the geometry's ``undeformed``; the ``bem`` rung's option
   ``subpatch_interaction = "full"`` joins them fully instead); regions further apart are separate patches;
4. places each patch's *contact reference point* at the interpenetration's weighted centre and its contact plane
   at the weighted contact angle, turned towards a neighbouring patch's when the two lie between D_SEP and D_TURN
   apart (:func:`turned_angles`; a small patch beside a large one takes most of the large one's angle). With the
   gap along x approximated as g(x, y) = g(y) + a x^2, a = 1/(2 r0), the weight of a lateral position is (the
   integral of the squared interpenetration along x)

       w(y) = int (c - a x^2)^2 dx over |x| < t0 = 16/15 c^2 t0,   c = -g(y) > 0,  t0 = sqrt(c / a),

   and y_cp = int y w dy / int w dy (likewise x_cp along the locus, and the angle delta_cp); the reference point
   is the rail surface point at (x_cp, y_cp);
5. solves the patch in the plane through the reference point whose normal is the track's vertical rolled by
   delta_cp (x along the track), on a potential contact area covering the patch's regions.

The undeformed distance on that plane is evaluated *exactly* at any point from the surfaces themselves (no
interpolation of a sampled grid): from a plane point p, the distance t to the rail along the plane normal n
(z = N(x, y) by Newton) and s to the wheel (wheel point x_w(alpha, y_d) = p + s n by Newton in (alpha, y_d, s)),
gap = s - t (:func:`plane_gap`). The BEM rung calls it at its element centres, so its pressure converges with
the grid. A coarse sample of the same function (``field_points`` per direction) sizes the potential area.

Frames and signs as in search.py: main frame x along the track, y to the right, z down; n from the rail into
the wheel; contact frame e_x = rolling direction projected on the plane, e_y = n x e_x; the contact angle is
positive when n tilts towards the track centre (CONTACT prints it with the opposite sign on the right side).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.curvature import curvature_tensor, principal_relative_curvature, relative_curvature
from rigid_dynamics.contact.search import WheelsetPose, _SideGeometry, ellipticity_error
from rigid_dynamics.contact.types import ContactGeometry, UndeformedDistance

DEFAULT_PATCH_OPTIONS: dict = {
    "angle_separation_rad": 0.5 * math.pi,  # A_SEP of CONTACT (90 degrees)
    "distance_separation_m": 8.0e-3,  # D_SEP
    "distance_combination_m": 4.0e-3,  # D_COMB
    "distance_turning_m": None,  # D_TURN; None: CONTACT's default 2 D_SEP - D_COMB
    "locus_step_m": 5.0e-5,  # spacing of the contact locus along the axle
    "field_points": 25,  # coarse sample of the plane gap per direction (sizes the potential area)
    "field_margin": 0.3,  # margin of the sampled box around the interpenetration, fraction of its extent
    "ellipticity_tolerance": 0.2,  # single-region patches: is_elliptic when ellipticity_error <= this
    "rolling_direction": (1.0, 0.0, 0.0),
}
"""Options of :func:`wheel_patches` (CONTACT's A_SEP, D_SEP, D_COMB, D_TURN with CONTACT's defaults)."""


@dataclass(frozen=True, eq=False)
class ContactLocus:
    """The wheel's contact locus on one side and the vertical gap to the rail below it.

    Attributes:
        alpha_rad, lateral_m: wheel parameters (alpha, y_d) of each locus point, shape (n,).
        point_m: locus points in the main frame, shape (n, 3).
        gap_m: vertical gap z_rail - z_wheel at the locus points (negative: interpenetration), m; +inf off the rail.
        rail_z_m: rail surface height N(x, y) below each point, m.
        angle_rad: contact angle of the rail surface there (search.py's convention), rad.
        weight_line_m3, weighted_x_m, overlap_x_m: out-of-round wheels only (None for a round one, whose weight is
            the closed form of the module docstring): int c^2 dx along the wheel's surface curve of each y_d (m^3),
            its x-centroid (m) and the x range where the vertical gap is negative (shape (n, 2), m; nan without).
    """

    alpha_rad: np.ndarray
    lateral_m: np.ndarray
    point_m: np.ndarray
    gap_m: np.ndarray
    rail_z_m: np.ndarray
    angle_rad: np.ndarray
    weight_line_m3: np.ndarray | None = None
    weighted_x_m: np.ndarray | None = None
    overlap_x_m: np.ndarray | None = None


def contact_locus(geo: _SideGeometry, step_m: float = 5.0e-5, iterations: int = 6) -> ContactLocus:
    """Points of the wheel whose surface is horizontal along the track, and the vertical gap to the rail.

    For each y_d the angle alpha solves f(alpha) = t_a,z t_y,y - t_y,z t_a,y = 0 (z stationary along the
    surface curve of constant track y; Newton with the analytic second derivatives), starting at the lowest
    point alpha = pi/2 - phi.
    """
    y_lo, y_hi = geo.y_range
    # only the part of the wheel above its rail: y_d of the rail's ends (the wheelset frame's y at the axle height)
    ends = (np.array(geo.rail_range)[:, None] - geo.centre[1]) / geo.rot[1, 1]
    y_lo, y_hi = max(y_lo, float(ends.min()) - 5e-3), min(y_hi, float(ends.max()) + 5e-3)
    n = max(int(math.ceil((y_hi - y_lo) / step_m)) + 1, 3)
    lat = np.linspace(y_lo, y_hi, n)
    alpha_start = 0.5 * math.pi - geo.pose.spin_rad
    if _out_of_round(geo):
        return _out_of_round_locus(geo, lat, alpha_start)
    if _compiled(geo):
        from rigid_dynamics.contact import _patch_kernels as kern

        alpha, point = np.empty(n), np.empty((n, 3))
        gap, rail_z, angle = np.empty(n), np.empty(n), np.empty(n)
        kern.contact_locus(
            lat, alpha_start, geo.rot, geo.centre, _surfaces(geo), geo.side == "right", iterations,
            kern.Locus(alpha, point, gap, rail_z, angle),
        )  # fmt: skip
        return ContactLocus(alpha, lat, point, gap, rail_z, angle)
    alpha = np.full(n, alpha_start)
    for _ in range(iterations):
        _, _, _, (t_a, t_y, x_aa, x_ay, _), _ = geo.wheel_point(alpha, lat, second=True)
        f = t_a[:, 2] * t_y[:, 1] - t_y[:, 2] * t_a[:, 1]
        df = x_aa[:, 2] * t_y[:, 1] + t_a[:, 2] * x_ay[:, 1] - x_ay[:, 2] * t_a[:, 1] - t_y[:, 2] * x_aa[:, 1]
        step = np.where(np.abs(df) > 1e-12, f / np.where(np.abs(df) > 1e-12, df, 1.0), 0.0)
        alpha = alpha - np.clip(step, -0.05, 0.05)
    point = geo.wheel_point(alpha, lat)[0]
    r_lo, r_hi = geo.rail_range
    on_rail = (point[:, 1] >= r_lo) & (point[:, 1] <= r_hi) & np.all(np.isfinite(point), axis=1)
    big_n, n_x, n_y = (
        np.asarray(v, float) for v in geo.rail.evaluate(point[:, 0], np.clip(point[:, 1], r_lo, r_hi))[:3]
    )
    gap = np.where(on_rail & np.isfinite(big_n), big_n - point[:, 2], np.inf)
    # rail normal (N_x, N_y, -1)/norm points out of the rail (up); contact angle as in search._patch
    norm = np.sqrt(n_x**2 + n_y**2 + 1.0)
    normal_y, normal_z = n_y / norm, -1.0 / norm
    tilt = -normal_y if geo.side == "right" else normal_y
    angle = np.arctan2(tilt, -normal_z)
    return ContactLocus(alpha, lat, point, gap, np.where(on_rail, big_n, np.nan), angle)


OUT_OF_ROUND_WINDOW_RAD = 0.2
"""Half width of the wheel-angle window scanned around the lowest point of an out-of-round wheel (as CONTACT's
compute_oor_whl, which meshes the wheel over -pitch +- 0.2 rad)."""
OUT_OF_ROUND_SCAN_POINTS = 161  # 2.5e-3 rad apart: 1.15 mm along a 0.46 m wheel
OUT_OF_ROUND_INTEGRATION_POINTS = 65
OUT_OF_ROUND_COARSE_STRIDE = 8
"""The compiled scan evaluates every 8th angle first, then every angle only where a bound of the gap's curvature
lets it dip below the smallest gap found or below 0 (_patch_kernels.out_of_round_locus): the same minimum and overlap
ends as the full scan."""
OUT_OF_ROUND_SCREEN_M = 2.0e-4
"""Only the y_d whose round-wheel gap is below the irregularity's largest radius increase plus this are scanned
(elsewhere the gap is the round one minus that increase: a lower bound, far from contact)."""


def _out_of_round(geo: _SideGeometry) -> bool:
    """Whether the wheel has irregularities of the rolling angle (its lowest points need the scan)."""
    rows = getattr(geo.wheel, "irregularity_rows", None)
    if rows is not None:
        return rows.shape[0] > 0
    return bool(getattr(geo.wheel, "irregularities", ()))


_RISES: dict = {}
"""The largest radius increase of each irregularity set met (:func:`_largest_rise`), by its rows' bytes."""


def _largest_rise(wheel) -> float:
    """The irregularities' largest radius increase over 4097 angles of the turn (>= 0), m; the same for every pose,
    so computed once per set of irregularity rows (a tabulated wheel's closed forms).
    """
    from rigid_dynamics.contact.search import _irregularity_sum

    key = wheel.irregularity_rows.tobytes()
    rise = _RISES.get(key)
    if rise is None:
        turns = np.linspace(-math.pi, math.pi, 4097)
        rise = max(float(_irregularity_sum(wheel.irregularities, turns, np.zeros_like(turns))[0].max()), 0.0)
        if len(_RISES) < 64:
            _RISES[key] = rise
    return rise


def _out_of_round_locus(geo: _SideGeometry, lat: np.ndarray, alpha_start: float) -> ContactLocus:
    """Contact locus of an out-of-round wheel (CONTACT meshes such a wheel in 3-D, compute_oor_whl, instead of
    assuming a surface of revolution): for each y_d the wheel angle of the smallest vertical gap over a window
    of the wheel's angle, and the squared interpenetration integrated along x (the weight of the weighted centre,
    and the overlap's x range that sizes the potential area) -- along a flat the wheel is straight, not a circle
    of radius r0, and a rounded flat touches at two points along x with a hump between.
    """
    n = lat.size
    half, scan, m = OUT_OF_ROUND_WINDOW_RAD, OUT_OF_ROUND_SCAN_POINTS, OUT_OF_ROUND_INTEGRATION_POINTS
    if _compiled(geo):
        from rigid_dynamics.contact import _patch_kernels as kern

        # the round wheel's locus screens the y_d that can touch
        alpha, point = np.empty(n), np.empty((n, 3))
        gap, rail_z, angle = np.empty(n), np.empty(n), np.empty(n)
        surf = _surfaces(geo)
        kern.contact_locus(
            lat, alpha_start, geo.rot, geo.centre, surf._replace(wheel_irr=np.zeros((0, 7))), geo.side == "right", 6,
            kern.Locus(alpha, point, gap, rail_z, angle),
        )  # fmt: skip
        gap = gap - _largest_rise(geo.wheel)
        near = np.flatnonzero(np.isfinite(gap) & (gap < OUT_OF_ROUND_SCREEN_M))
        weight, weighted_x = np.zeros(n), np.full(n, np.nan)
        overlap = np.full((n, 2), np.nan)
        k = near.size
        if k:
            out = [np.empty(k), np.empty((k, 3)), np.empty(k), np.empty(k), np.empty(k), np.empty(k), np.empty(k),
                   np.empty((k, 2))]  # fmt: skip
            fast = kern.FastScan(OUT_OF_ROUND_COARSE_STRIDE, True)
            kern.out_of_round_locus(
                np.ascontiguousarray(lat[near]), alpha_start, half, scan, m, fast, geo.rot, geo.centre, surf,
                geo.side == "right", kern.Locus(*out[:5]), kern.OverlapLine(*out[5:]),
            )  # fmt: skip
            for target, value in zip((alpha, point, gap, rail_z, angle, weight, weighted_x, overlap), out, strict=True):
                target[near] = value
        return ContactLocus(alpha, lat, point, gap, rail_z, angle, weight, weighted_x, overlap)
    # numpy path (measured irregularity grids): the same scan, refinement and integral, vectorised over y_d
    r_lo, r_hi = geo.rail_range

    def vertical_gap(a, y):
        p = geo.wheel_point(a, y)[0]
        on = (p[..., 1] >= r_lo) & (p[..., 1] <= r_hi) & np.all(np.isfinite(p), axis=-1)
        big_n = np.asarray(geo.rail.evaluate(p[..., 0], np.clip(p[..., 1], r_lo, r_hi))[0], float)
        return np.where(on & np.isfinite(big_n), big_n - p[..., 2], np.inf), p

    step = 2.0 * half / (scan - 1)
    grid = alpha_start - half + step * np.arange(scan)
    g_scan, _ = vertical_gap(np.broadcast_to(grid, (n, scan)), np.broadcast_to(lat[:, None], (n, scan)))
    kbest = np.argmin(g_scan, axis=1)
    lo = alpha_start - half + np.maximum(kbest - 1, 0) * step
    hi = alpha_start - half + np.minimum(kbest + 1, scan - 1) * step
    golden = 0.5 * (math.sqrt(5.0) - 1.0)
    c1, c2 = hi - golden * (hi - lo), lo + golden * (hi - lo)
    g1, g2 = vertical_gap(c1, lat)[0], vertical_gap(c2, lat)[0]
    for _ in range(30):
        left = g1 <= g2
        hi = np.where(left, c2, hi)
        lo = np.where(left, lo, c1)
        new_c1 = np.where(left, hi - golden * (hi - lo), c2)
        new_c2 = np.where(left, c1, lo + golden * (hi - lo))
        new_g1 = np.where(left, np.nan, g2)
        new_g2 = np.where(left, g1, np.nan)
        fresh = vertical_gap(np.where(left, new_c1, new_c2), lat)[0]
        g1, g2 = np.where(left, fresh, new_g1), np.where(left, new_g2, fresh)
        c1, c2 = new_c1, new_c2
    alpha = 0.5 * (lo + hi)
    gap, point = vertical_gap(alpha, lat)
    worse = g_scan[np.arange(n), kbest] < gap
    alpha = np.where(worse, grid[kbest], alpha)
    gap, point = vertical_gap(alpha, lat)
    rail_values = geo.rail.evaluate(point[:, 0], np.clip(point[:, 1], r_lo, r_hi))[:3]
    big_n, n_x, n_y = (np.asarray(v, float) for v in rail_values)
    norm = np.sqrt(n_x**2 + n_y**2 + 1.0)
    tilt = -n_y / norm if geo.side == "right" else n_y / norm
    finite = np.isfinite(gap)
    angle = np.where(finite, np.arctan2(tilt, 1.0 / norm), np.nan)
    rail_z = np.where(finite, big_n, np.nan)
    inside = g_scan < 0
    any_in = inside.any(axis=1)
    first = np.where(any_in, np.argmax(inside, axis=1), kbest)
    last = np.where(any_in, scan - 1 - np.argmax(inside[:, ::-1], axis=1), kbest)
    a_lo = np.minimum(alpha - step, alpha_start - half + (first - 1) * step)
    a_hi = np.maximum(alpha + step, alpha_start - half + (last + 1) * step)
    a_int = a_lo[:, None] + (a_hi - a_lo)[:, None] * np.linspace(0.0, 1.0, m)
    g_int, p_int = vertical_gap(a_int, np.broadcast_to(lat[:, None], a_int.shape))
    c = np.where(g_int < 0, -g_int, 0.0)
    x = p_int[..., 0]
    dx = np.abs(np.diff(x, axis=1))
    weight = np.sum(0.5 * (c[:, 1:] ** 2 + c[:, :-1] ** 2) * dx, axis=1)
    moment = np.sum(0.5 * (x[:, 1:] * c[:, 1:] ** 2 + x[:, :-1] * c[:, :-1] ** 2) * dx, axis=1)
    touching = gap < 0
    weight = np.where(touching, weight, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        weighted_x = np.where(touching & (weight > 0), moment / weight, np.where(touching, point[:, 0], np.nan))
    over = c > 0
    x_lo = np.where(over, x, np.inf).min(axis=1)
    x_hi = np.where(over, x, -np.inf).max(axis=1)
    g0, g1 = g_int[:, :-1], g_int[:, 1:]
    flips = np.isfinite(g0) & np.isfinite(g1) & ((g0 < 0) != (g1 < 0))
    with np.errstate(invalid="ignore", divide="ignore"):
        xc = x[:, :-1] + g0 / (g0 - g1) * (x[:, 1:] - x[:, :-1])  # zero crossings, linearly
    x_lo = np.minimum(x_lo, np.where(flips, xc, np.inf).min(axis=1))
    x_hi = np.maximum(x_hi, np.where(flips, xc, -np.inf).max(axis=1))
    x_lo = np.where(touching & (x_lo <= x_hi), x_lo, np.where(touching, point[:, 0], np.nan))
    x_hi = np.where(touching & np.isfinite(x_lo), np.maximum(x_hi, x_lo), np.nan)
    return ContactLocus(alpha, lat, point, gap, rail_z, angle, weight, weighted_x, np.stack([x_lo, x_hi], -1))


def _compiled(geo: _SideGeometry) -> bool:
    """Whether both surfaces are search.py's tabulated stand-ins (the compiled kernels apply)."""
    from rigid_dynamics.contact.search import TabulatedRail, TabulatedWheel

    return isinstance(geo.wheel, TabulatedWheel) and isinstance(geo.rail, TabulatedRail)


def _surfaces(geo: _SideGeometry):
    """The _search_kernels.Surfaces record of a side with tabulated surfaces (:func:`_compiled`)."""
    from rigid_dynamics.contact._search_kernels import Surfaces

    return Surfaces(
        geo.wheel.table_tuple, geo.rail.table_tuple, geo.wheel.irregularity_rows, geo.rail.irregularity_rows,
        geo.rail.lateral_map, np.array(geo.y_range), np.array(geo.rail_range),
    )  # fmt: skip


@dataclass(frozen=True, eq=False)
class InterpenetrationRegion:
    """One interval of the locus with interpenetration, and its weighted centre (module docstring, step 4).

    Attributes:
        start, stop: index range [start, stop) into the locus.
        weight: int w dy, m^5.
        centre_m: weighted (x, y) of the locus points, m. angle_rad: weighted contact angle, rad.
        ends_m: rail-surface (y, z) of the two zero crossings, shape (2, 2), m.
        min_gap_m: smallest vertical gap (< 0), m. deepest_index: index of it in the locus.
    """

    start: int
    stop: int
    weight: float
    centre_m: tuple[float, float]
    angle_rad: float
    ends_m: np.ndarray
    min_gap_m: float
    deepest_index: int


def _crossing(locus: ContactLocus, i: int, j: int) -> np.ndarray:
    """Rail-surface (y, z) where the gap changes sign between locus points i (g >= 0) and j (g < 0)."""
    g_i, g_j = locus.gap_m[i], locus.gap_m[j]
    if not np.isfinite(g_i):
        t = 1.0
    else:
        t = g_i / (g_i - g_j)
    y = locus.point_m[i, 1] + t * (locus.point_m[j, 1] - locus.point_m[i, 1])
    z = locus.rail_z_m[i] + t * (locus.rail_z_m[j] - locus.rail_z_m[i]) if np.isfinite(g_i) else locus.rail_z_m[j]
    return np.array([y, z])


def interpenetration_regions(locus: ContactLocus, nominal_radius_m: float) -> list[InterpenetrationRegion]:
    """The intervals of negative vertical gap, ordered along the axle, with their weighted centres."""
    a = 0.5 / nominal_radius_m
    inside = np.isfinite(locus.gap_m) & (locus.gap_m < 0)
    if not inside.any():
        return []
    edges = np.diff(np.concatenate([[0], inside.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    c = np.where(inside, -locus.gap_m, 0.0)
    if locus.weight_line_m3 is not None:
        w_line = np.where(inside, locus.weight_line_m3, 0.0)  # out-of-round: integrated along x
        x_line = np.where(inside, locus.weighted_x_m, 0.0)
    else:
        w_line = 16.0 / 15.0 * c**2 * np.sqrt(c / a)
        x_line = locus.point_m[:, 0]
    y = locus.point_m[:, 1]
    dy = np.abs(np.gradient(y))
    regions = []
    for start, stop in zip(starts, stops, strict=True):
        sl = slice(start, stop)
        w = w_line[sl] * dy[sl]
        total = float(w.sum())
        if total <= 0:
            continue
        x_c = float((x_line[sl] * w).sum() / total)
        y_c = float((y[sl] * w).sum() / total)
        angle = float((locus.angle_rad[sl] * w).sum() / total)
        first = _crossing(locus, start - 1, start) if start > 0 else np.array([y[start], locus.rail_z_m[start]])
        last = _crossing(locus, stop, stop - 1) if stop < len(y) else np.array([y[stop - 1], locus.rail_z_m[stop - 1]])
        deepest = start + int(np.argmin(locus.gap_m[sl]))
        regions.append(
            InterpenetrationRegion(
                int(start), int(stop), total, (x_c, y_c), angle, np.stack([first, last]),
                float(locus.gap_m[deepest]), deepest,
            )
        )  # fmt: skip
    return regions


def group_regions(regions: list[InterpenetrationRegion], options) -> list[tuple[list[int], str]]:
    """Indices of the regions forming each patch, and how they were joined ("single", "combined", "blended").

    Neighbouring regions (along the axle) are joined when their contact angles differ by at most A_SEP and the
    distance between the end of one and the start of the next is at most D_SEP (module docstring, step 3).
    """
    groups: list[tuple[list[int], str]] = []
    for k, region in enumerate(regions):
        if groups:
            prev = regions[groups[-1][0][-1]]
            d = float(np.hypot(*(region.ends_m[0] - prev.ends_m[1])))
            # the angle of the group so far (weighted) against this region's
            members = [regions[i] for i in groups[-1][0]]
            w = sum(m.weight for m in members)
            angle = sum(m.angle_rad * m.weight for m in members) / w
            if (
                abs(region.angle_rad - angle) <= options["angle_separation_rad"]
                and d <= options["distance_separation_m"]
            ):
                how = "combined" if d <= options["distance_combination_m"] else "blended"
                previous = groups[-1][1]
                kind = "blended" if "blended" in (how, previous) else how
                groups[-1] = (groups[-1][0] + [k], kind)
                continue
        groups.append(([k], "single"))
    return groups


def turning_distance_m(options) -> float:
    """D_TURN of the options: ``distance_turning_m``, or CONTACT's default 2 D_SEP - D_COMB when it is None."""
    value = options.get("distance_turning_m")
    if value is None:
        return 2.0 * options["distance_separation_m"] - options["distance_combination_m"]
    return float(value)


def turned_angles(groups: list[list[InterpenetrationRegion]], options) -> list[tuple[float, float]]:
    """Each patch's contact reference angle and the turn in it, (angle, turn) in rad (module docstring, step 4).

    A patch's own angle is its regions' weighted angle. Two neighbouring patches (along the axle) whose distance d
    (between the end of one's last region and the start of the next one's first, rail surface, y-z plane) lies in
    [D_SEP, D_TURN] and whose angles differ by at most A_SEP are turned towards their common weighted angle
    (delta_1 w_1 + delta_2 w_2) / (w_1 + w_2) by the fraction f = (D_TURN - d) / (D_TURN - D_SEP) of the
    difference: full joining's angle at D_SEP, none at D_TURN, so the patches' planes do not jump where the regions
    stop being joined (CONTACT's "turning", user guide sec. "Identification of contact patches"). The turns of a
    patch with two such neighbours add; each is taken from the angles before turning. No turning when
    D_TURN <= D_SEP.
    """
    weights = [sum(r.weight for r in group) for group in groups]
    own = [sum(r.angle_rad * r.weight for r in group) / w for group, w in zip(groups, weights, strict=True)]
    turn = [0.0] * len(groups)
    d_sep, d_turn = options["distance_separation_m"], turning_distance_m(options)
    if d_turn > d_sep:
        for k in range(len(groups) - 1):
            d = float(np.hypot(*(groups[k + 1][0].ends_m[0] - groups[k][-1].ends_m[1])))
            if abs(own[k] - own[k + 1]) > options["angle_separation_rad"] or not d_sep <= d <= d_turn:
                continue
            common = (own[k] * weights[k] + own[k + 1] * weights[k + 1]) / (weights[k] + weights[k + 1])
            fraction = (d_turn - d) / (d_turn - d_sep)
            turn[k] += fraction * (common - own[k])
            turn[k + 1] += fraction * (common - own[k + 1])
    return [(a + t, t) for a, t in zip(own, turn, strict=True)]


SUB_PATCH_MARGIN = 0.4
"""Margin of a sub-patch's rectangle around its interpenetration, in D_COMB (CONTACT's safety 0.4 D_COMB)."""


def _region_x_range(region: InterpenetrationRegion, locus: ContactLocus, a_long: float) -> tuple[float, float]:
    """Track-x range of a region's interpenetration: x_i -+ sqrt(c_i / a) over its locus points (or the
    out-of-round overlap's own rows).
    """
    sl = slice(region.start, region.stop)
    if locus.overlap_x_m is not None:
        rows = locus.overlap_x_m[sl]
        rows = rows[np.all(np.isfinite(rows), axis=1)]
        if len(rows):
            return float(rows[:, 0].min()), float(rows[:, 1].max())
    c = np.clip(-locus.gap_m[sl], 0.0, None)
    half = np.sqrt(c / a_long)
    x = locus.point_m[sl, 0]
    return float((x - half).min()), float((x + half).max())


def sub_patches(group, locus, a_long: float, origin, frame, options):
    """CONTACT's sub-patches of a patch (module docstring, step 3): (rectangles (n, 4), factors (n, n)), or
    (None, None) when all its regions lie within D_COMB of their neighbours (one sub-patch, joined fully).

    Regions within D_COMB of each other form one sub-patch; neighbouring sub-patches lie D_COMB < d <= D_SEP
    apart. Each sub-patch's rectangle on the plane is its interpenetration's extent (x: _region_x_range less the
    origin's x; y: its regions' end points projected on e_y) widened by SUB_PATCH_MARGIN D_COMB on each side; the
    factor between sub-patches i and j is f = (max(0, D_SEP - d) / (D_SEP - D_COMB))^0.8 with d the distance
    between their bounding boxes (track x of the interpenetration; rail-surface y, z of the facing end points),
    as CONTACT's m_wr_locatecp forms them.
    """
    d_comb, d_sep = options["distance_combination_m"], options["distance_separation_m"]
    subs = [[group[0]]]
    for prev, region in zip(group[:-1], group[1:], strict=True):
        if float(np.hypot(*(region.ends_m[0] - prev.ends_m[1]))) <= d_comb:
            subs[-1].append(region)
        else:
            subs.append([region])
    if len(subs) == 1:
        return None, None
    pad = SUB_PATCH_MARGIN * d_comb
    limits, boxes = [], []
    for sub in subs:
        x_ranges = [_region_x_range(r, locus, a_long) for r in sub]
        x0, x1 = min(r[0] for r in x_ranges), max(r[1] for r in x_ranges)
        ends = np.concatenate([r.ends_m for r in sub])
        lat = (ends[:, 0] - origin[1]) * frame[1, 1] + (ends[:, 1] - origin[2]) * frame[2, 1]
        limits.append((x0 - origin[0] - pad, x1 - origin[0] + pad, float(lat.min()) - pad, float(lat.max()) + pad))
        boxes.append((x0, x1, sub[0].ends_m[0], sub[-1].ends_m[1]))
    n = len(subs)
    factors = np.ones((n, n))
    for i in range(n):
        for j in range(i + 1, n):
            dx = max(0.0, boxes[j][0] - boxes[i][1], boxes[i][0] - boxes[j][1])
            dy, dz = boxes[j][2] - boxes[i][3]
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            factors[i, j] = factors[j, i] = (max(0.0, d_sep - d) / (d_sep - d_comb)) ** 0.8
    return np.array(limits), factors


PLANE_GAP_ITERATIONS = 10
"""Newton iterations of :func:`plane_gap`'s and :func:`_grid_gap`'s roots."""


def plane_gap(geo: _SideGeometry, locus: ContactLocus, origin, frame, x_m, y_m, iterations: int = PLANE_GAP_ITERATIONS):
    """Undeformed distance along the plane normal at points (x, y) of the plane (origin, frame), m.

    Returns (gap, alpha, y_d): gap = s - t with the rail at origin + x e_x + y e_y + t n and the wheel at
    + s n; +inf where either Newton iteration did not converge or the point is off a surface. alpha, y_d are the
    wheel parameters found (start: the locus point at the same track y).
    """
    x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    shape = x_m.shape
    x, y = np.ascontiguousarray(x_m.ravel()), np.ascontiguousarray(y_m.ravel())
    if _compiled(geo):
        from rigid_dynamics.contact import _patch_kernels as kern

        order = np.argsort(locus.point_m[:, 1])
        gap, alpha, lat = np.empty(x.size), np.empty(x.size), np.empty(x.size)
        starts = kern.SortedLocus(
            np.ascontiguousarray(locus.point_m[order, 1]), locus.lateral_m[order], locus.alpha_rad[order],
            np.ascontiguousarray(locus.point_m[order, 0]),
        )  # fmt: skip
        kern.plane_gap(
            x, y, np.asarray(origin, float), np.ascontiguousarray(frame), starts, geo.rot, geo.centre, _surfaces(geo),
            iterations, kern.PlaneGap(gap, alpha, lat),
        )  # fmt: skip
        return gap.reshape(shape), alpha.reshape(shape), lat.reshape(shape)
    e_x, e_y, n = frame[:, 0], frame[:, 1], frame[:, 2]
    base = origin + x[:, None] * e_x + y[:, None] * e_y
    t_rail = geo._distance_along(base, n, iterations)
    order = np.argsort(locus.point_m[:, 1])
    ly = locus.point_m[order, 1]
    lat = np.interp(base[:, 1], ly, locus.lateral_m[order])
    alpha = np.interp(base[:, 1], ly, locus.alpha_rad[order])
    radius = geo.wheel.evaluate(alpha, lat)[0]
    alpha = alpha + (base[:, 0] - np.interp(base[:, 1], ly, locus.point_m[order, 0])) / radius
    s = n @ (geo.wheel_point(alpha, lat)[0] - base).T
    residual = np.full(x.shape, np.inf)
    for _ in range(iterations):
        point, _, _, (t_a, t_y, *_), _ = geo.wheel_point(alpha, lat, second=True)
        res = point - base - s[:, None] * n
        residual = np.linalg.norm(res, axis=1)
        if np.all(residual < 1e-12):
            break
        jac = np.stack([t_a, t_y, np.broadcast_to(-n, t_a.shape)], -1)
        delta = np.linalg.solve(jac, -res[..., None])[..., 0]
        alpha, lat, s = alpha + delta[:, 0], lat + delta[:, 1], s + delta[:, 2]
    point = geo.wheel_point(alpha, lat)[0]
    residual = np.linalg.norm(point - base - s[:, None] * n, axis=1)
    ok = (residual < 1e-10) & (lat >= geo.y_range[0]) & (lat <= geo.y_range[1]) & np.isfinite(t_rail)
    gap = np.where(ok, s - t_rail, np.inf)
    return gap.reshape(shape), alpha.reshape(shape), lat.reshape(shape)


GRID_SAMPLER_MIN_POINTS = 3
"""Points per direction from which :func:`_grid_gap` samples a regular grid strip by strip."""


def _grid_gap(geo: _SideGeometry, origin, frame, start, x_m, y_m):
    """The undeformed distance on a regular grid of the plane by the loop's strip sampler (_gap_kernels.sample_grid,
    the same roots as :func:`plane_gap`'s per-point Newton solves to 1e-12 m), or None where it does not apply
    (surfaces not tabulated, points not a regular grid of at least GRID_SAMPLER_MIN_POINTS per direction).

    The solvers evaluate the gap at their element centres, a regular grid: strip by strip the sampler chains each
    root from its neighbour's, 10-35 times cheaper per point than plane_gap on curve-flange's formed flange patch
    (40 x 40 and 80 x 80 points; max difference 1.0e-12 m, no point finite in one and not the other;
    tests/test_wheelset_patches_grid_gap.py). ``start``: the wheel parameters (alpha, y_d) of the plane's origin.
    """
    if not _compiled(geo):
        return None
    x, y = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    if x.ndim != 2 or min(x.shape) < GRID_SAMPLER_MIN_POINTS:
        return None
    xs, ys = x[0], y[:, 0]
    if not (
        np.array_equal(x, np.broadcast_to(xs, x.shape)) and np.array_equal(y, np.broadcast_to(ys[:, None], y.shape))
    ):
        return None
    dx, dy = np.diff(xs), np.diff(ys)
    if not (dx[0] > 0 and dy[0] > 0 and np.allclose(dx, dx[0], rtol=1e-9, atol=0)
            and np.allclose(dy, dy[0], rtol=1e-9, atol=0)):  # fmt: skip
        return None
    from rigid_dynamics.contact import _gap_kernels as kern

    frame = np.asarray(frame, float)
    patch = kern.GapPatch(
        geo.rot, np.asarray(geo.centre, float), tuple(float(v) for v in origin), tuple(frame[:, 0]),
        tuple(frame[:, 1]), tuple(frame[:, 2]), float(start[0]), float(start[1]), PLANE_GAP_ITERATIONS,
    )  # fmt: skip
    gap = np.empty(x.shape)
    grid_x, grid_y = np.empty(x.shape[1]), np.empty(x.shape[0])
    columns = np.empty((x.shape[1], kern.COLUMN_SCRATCH))
    kern.sample_grid(_surfaces(geo), patch, (xs[0], xs[-1], ys[0], ys[-1]), grid_x, grid_y, gap, columns)
    return gap


@dataclass(frozen=True, eq=False)
class WheelPatch:
    """A patch of one wheel: the geometry handed to a contact model and how it was formed.

    Attributes:
        geometry: :class:`ContactGeometry` at the contact reference point (undeformed distance exact).
        regions: the interpenetration regions joined in it.
        combination: "single", "combined" (d <= D_COMB) or "blended" (D_COMB < d <= D_SEP: sub-patches
            with reduced interaction, :func:`sub_patches`).
        deepest_point_m: main-frame point of the largest vertical interpenetration (on the rail), m.
        deepest_point_rail_m: (y, z) of it in rail-profile coordinates, m.
        min_vertical_gap_m: the largest vertical interpenetration (negative), m.
        wheel_point_m: the wheel's surface point on the normal through the reference point (main frame), m:
            the material point whose velocity gives the creepages (CONTACT's rolling radius is the wheel's).
        angle_turn_rad: how far the contact angle was turned towards a neighbouring patch's (D_SEP <= d <=
            D_TURN, :func:`turned_angles`), rad; 0 when not turned.
        wheel_lateral_m: the wheel surface's lateral coordinate y_d of ``wheel_point_m`` (the search's
            ``wheel_lateral_m``), m.
    """

    geometry: ContactGeometry
    regions: list[InterpenetrationRegion]
    combination: str
    deepest_point_m: np.ndarray
    deepest_point_rail_m: tuple[float, float]
    min_vertical_gap_m: float
    wheel_point_m: np.ndarray
    angle_turn_rad: float = 0.0
    wheel_lateral_m: float = math.nan


def _curvatures(geo_exact: _SideGeometry, alpha0: float, y0: float, rail_xy, frame):
    a_arr, y_arr = np.array([alpha0]), np.array([y0])
    _, _, _, (t_a, t_y, x_aa, x_ay, x_yy), radius = geo_exact.wheel_point(a_arr, y_arr, second=True)
    e_x, e_y, n = frame[:, 0], frame[:, 1], frame[:, 2]
    k_w = curvature_tensor(t_a[0], t_y[0], x_aa[0], x_ay[0], x_yy[0], n, e_x, e_y)
    _, n_dx, n_dy, n_xx, n_xy, n_yy = (
        v[0] for v in geo_exact.rail.evaluate(np.array([rail_xy[0]]), np.array([rail_xy[1]]))
    )
    k_r = curvature_tensor(
        np.array([1.0, 0.0, n_dx]), np.array([0.0, 1.0, n_dy]), np.array([0.0, 0.0, n_xx]),
        np.array([0.0, 0.0, n_xy]), np.array([0.0, 0.0, n_yy]), n, e_x, e_y,
    )  # fmt: skip
    a_rel, b_rel, angle = principal_relative_curvature(relative_curvature(k_w, k_r))
    return float(a_rel), float(b_rel), float(angle), float(radius[0])


def _overlap_ellipse(xs, ys, field, approach: float):
    """Curvatures (A, B, 0) of the quadric A x^2 + B y^2 - q whose rigid overlap has the sampled overlap's extents
    (an equivalent ellipse for joined or conformal patches); None when nothing overlaps.
    """
    over = np.isfinite(field) & (field < 0)
    if not over.any() or approach <= 0:
        return None
    cols, rows = np.flatnonzero(over.any(axis=0)), np.flatnonzero(over.any(axis=1))
    hx = 0.5 * (xs[min(cols[-1] + 1, xs.size - 1)] - xs[max(cols[0] - 1, 0)])
    hy = 0.5 * (ys[min(rows[-1] + 1, ys.size - 1)] - ys[max(rows[0] - 1, 0)])
    return approach / hx**2, approach / hy**2, 0.0


def _box_minimum(gap_of, x0, y0, hx, hy, points: int = 7, passes: int = 3):
    """Smallest gap near (x0, y0) by successively finer small grids, and where it is."""
    best = (math.inf, x0, y0)
    for _ in range(passes):
        xs = x0 + np.linspace(-hx, hx, points)
        ys = y0 + np.linspace(-hy, hy, points)
        gx, gy = np.meshgrid(xs, ys)
        g = gap_of(gx, gy)
        k = int(np.argmin(g))
        if g.flat[k] < best[0]:
            best = (float(g.flat[k]), float(gx.flat[k]), float(gy.flat[k]))
        x0, y0 = best[1], best[2]
        hx, hy = 2.0 * hx / (points - 1), 2.0 * hy / (points - 1)
    return best


def wheel_patches(
    wheel, rail, pose: WheelsetPose, side: str, *, wheel_lateral_range_m, rail_lateral_range_m,
    nominal_radius_m: float, options=None,
) -> tuple[list[WheelPatch], ContactLocus]:  # fmt: skip
    """Patches of one wheel formed as CONTACT's module 1 forms them (module docstring), and the contact locus.

    Args:
        wheel, rail: the side's surfaces (search.py's duck type; tabulated stand-ins keep ``.exact``).
        pose: wheelset pose. side: "left" or "right".
        wheel_lateral_range_m, rail_lateral_range_m: where the surfaces are defined, m.
        nominal_radius_m: r0 (the weight's longitudinal curvature a = 1/(2 r0)), m.
        options: :data:`DEFAULT_PATCH_OPTIONS` keys.

    Returns:
        (patches ordered along the axle, the locus). No patch when the wheel does not touch its rail.

    Raises:
        ValueError: unknown option.
    """
    opts = dict(DEFAULT_PATCH_OPTIONS)
    for key, value in (options or {}).items():
        if key not in DEFAULT_PATCH_OPTIONS:
            raise ValueError(f"patch option {key!r}: expected one of {', '.join(DEFAULT_PATCH_OPTIONS)}")
        opts[key] = value
    geo = _SideGeometry(wheel, rail, pose, side, tuple(wheel_lateral_range_m), tuple(rail_lateral_range_m))
    exact_wheel, exact_rail = getattr(wheel, "exact", wheel), getattr(rail, "exact", rail)
    geo_exact = _SideGeometry(exact_wheel, exact_rail, pose, side, geo.y_range, geo.rail_range, geo.rot)
    locus = contact_locus(geo, opts["locus_step_m"])
    regions = interpenetration_regions(locus, nominal_radius_m)
    a_long = 0.5 / nominal_radius_m
    patches = []
    grouped = group_regions(regions, opts)
    angles = turned_angles([[regions[k] for k in members] for members, _ in grouped], opts)
    for (members, how), (delta, turn) in zip(grouped, angles, strict=True):
        group = [regions[k] for k in members]
        weight = sum(r.weight for r in group)
        x_c = sum(r.centre_m[0] * r.weight for r in group) / weight
        y_c = sum(r.centre_m[1] * r.weight for r in group) / weight
        z_c = float(geo.rail.evaluate(np.array([x_c]), np.array([y_c]))[0][0])
        origin = np.array([x_c, y_c, z_c])
        sgn = -1.0 if side == "right" else 1.0
        n = np.array([0.0, sgn * math.sin(delta), -math.cos(delta)])
        rolling = np.asarray(opts["rolling_direction"], float)
        e_x = rolling - np.dot(rolling, n) * n
        e_x /= np.linalg.norm(e_x)
        frame = np.stack([e_x, np.cross(n, e_x), n], -1)

        def exact_of(x, y, origin=origin, frame=frame):
            return plane_gap(geo, locus, origin, frame, x, y)[0]

        # box of the sampled field: the regions' extents projected on e_y, the longest x-extent, a margin
        ends = np.concatenate([r.ends_m for r in group])
        lat = (ends[:, 0] - y_c) * frame[1, 1] + (ends[:, 1] - z_c) * frame[2, 1]
        depth = max(-r.min_gap_m for r in group)
        if locus.overlap_x_m is not None:
            # out-of-round: the overlap's own x range (a flat's overlap is longer than the circle's sqrt(depth/a))
            rows = np.concatenate([locus.overlap_x_m[r.start : r.stop] for r in group])
            rows = rows[np.all(np.isfinite(rows), axis=1)]
            x_lo, x_hi = float(rows[:, 0].min()) - x_c, float(rows[:, 1].max()) - x_c
            half_x = max(-x_lo, x_hi, math.sqrt(depth / a_long) * 0.1)
        else:
            half_x = math.sqrt(depth / a_long)
        y_lo, y_hi = float(lat.min()), float(lat.max())
        pad_y = opts["field_margin"] * (y_hi - y_lo) + 2.0e-4
        pad_x = (1.0 + opts["field_margin"]) * half_x + 2.0e-4
        npts = int(opts["field_points"])
        xs = x_c - origin[0] + np.linspace(-pad_x, pad_x, npts)
        ys = np.linspace(y_lo - pad_y, y_hi + pad_y, npts)
        gx, gy = np.meshgrid(xs, ys)
        # one call: the sampled field and the plane origin (whose wheel parameters give the curvatures)
        values, alphas, lats = plane_gap(
            geo, locus, origin, frame, np.append(gx.ravel(), 0.0), np.append(gy.ravel(), 0.0)
        )
        field = values[:-1].reshape(gx.shape)
        alpha0, lat0 = float(alphas[-1]), float(lats[-1])
        k = int(np.argmin(field))
        jj, ii = divmod(k, npts)
        q_min, _, _ = _box_minimum(exact_of, xs[ii], ys[jj], xs[1] - xs[0], ys[1] - ys[0], passes=2)
        approach = max(-q_min, 0.0)
        if not (math.isfinite(alpha0) and math.isfinite(lat0)):
            alpha0 = float(np.interp(y_c, locus.point_m[:, 1], locus.alpha_rad))
            lat0 = float(np.interp(y_c, locus.point_m[:, 1], locus.lateral_m))

        def gap_of(x, y, origin=origin, frame=frame, start=(alpha0, lat0)):
            grid = _grid_gap(geo, origin, frame, start, x, y)
            return plane_gap(geo, locus, origin, frame, x, y)[0] if grid is None else grid

        a_rel, b_rel, ell_angle, radius = _curvatures(geo_exact, alpha0, lat0, origin[:2], frame)
        over = np.isfinite(field) & (field < 0)
        if over.any():
            cols, rows = np.flatnonzero(over.any(axis=0)), np.flatnonzero(over.any(axis=1))
            i0, i1 = max(cols[0] - 1, 0), min(cols[-1] + 1, npts - 1)
            j0, j1 = max(rows[0] - 1, 0), min(rows[-1] + 1, npts - 1)
            area = (float(xs[i0]), float(xs[i1]), float(ys[j0]), float(ys[j1]))
        else:
            area = None
        subs, factors = sub_patches(group, locus, a_long, origin, frame, opts)
        undeformed = UndeformedDistance(
            x_m=xs, y_m=ys, distance_m=field, exact=gap_of, potential_area_m=area, sub_patches_m=subs,
            sub_patch_factors=factors,
        )  # fmt: skip
        convex = a_rel > 0 and b_rel > 0
        if not convex or len(group) > 1:
            # the curvatures at one point do not describe a joined or conformal patch: the analytic rungs get the
            # quadric with the same rigid-overlap extents (an equivalent ellipse; is_elliptic False)
            fitted = _overlap_ellipse(xs, ys, field, approach)
            if fitted is not None:
                a_rel, b_rel, ell_angle = fitted
        a_use, b_use = max(a_rel, 1e-6), max(b_rel, 1e-6)
        elliptic = convex and len(group) == 1
        if elliptic:
            elliptic = ellipticity_error(undeformed, a_use, b_use, ell_angle, approach) <= opts["ellipticity_tolerance"]
        rail_profile = (math.nan, math.nan)
        if hasattr(exact_rail, "to_profile_coordinates"):
            rail_profile = tuple(float(v) for v in exact_rail.to_profile_coordinates(y_c, z_c))
        wheel_profile = (math.nan, math.nan)
        if hasattr(exact_wheel, "to_profile_coordinates"):
            wheel_profile = tuple(float(v) for v in exact_wheel.to_profile_coordinates(lat0, radius))
        geometry = ContactGeometry(
            curvature_long_1_per_m=a_use,
            curvature_lat_1_per_m=b_use,
            approach_m=approach,
            side=side,
            point_m=origin,
            frame=frame,
            contact_angle_rad=float(delta),
            contact_point_rail_m=rail_profile,
            contact_point_wheel_m=wheel_profile,
            rolling_radius_m=radius,
            ellipse_angle_rad=ell_angle,
            undeformed=undeformed,
            is_elliptic=bool(elliptic),
        )
        deepest = min(group, key=lambda r: r.min_gap_m)
        p_deep = locus.point_m[deepest.deepest_index].copy()
        p_deep[2] = locus.rail_z_m[deepest.deepest_index]
        deep_profile = (math.nan, math.nan)
        if hasattr(exact_rail, "to_profile_coordinates"):
            deep_profile = tuple(float(v) for v in exact_rail.to_profile_coordinates(p_deep[1], p_deep[2]))
        wheel_point = geo.wheel_point(np.array([alpha0]), np.array([lat0]))[0][0]
        patches.append(
            WheelPatch(
                geometry, group, how, p_deep, deep_profile, deepest.min_gap_m, wheel_point, float(turn), float(lat0)
            )
        )
    return patches, locus
