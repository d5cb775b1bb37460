"""Providers for real wheel and rail profiles: a 2-D profile section (for the tables) and the 3-D search.

Both take the wheel and rail *surfaces* of both sides (duck-typed as in rigid_dynamics.contact.search:
``wheel.evaluate(alpha, y_d) -> (R, R_a, R_y, R_aa, R_ay, R_yy)``, ``rail.evaluate(x, y) -> (N, N_x, N_y,
N_xx, N_xy, N_yy)``, both with ``y_range_m``), by default built from the scene's profiles with
rigid_dynamics.contact.track.build_track.

ProfileSectionProvider (ideal geometry, the classic "contact table" method). In the track's (y, z) plane
the wheel's lowest points (alpha = pi/2) of a wheelset with roll theta (yaw and x ignored) lie on

    P(y_d) = (y_c + y_d cos(theta) - R(y_d) sin(theta),  z_c + y_d sin(theta) + R(y_d) cos(theta)),

and the vertical gap to the rail is g(y_d) = N(P_y) - P_z (> 0: gap). Candidate 0 is the global minimum of
g (continuous in the pose, so the approach interpolates well in a table); candidate 1 is the deepest other
local minimum separated from it by a rise of g (two-point contact: tread and flange), else a gap of
``ABSENT_GAP_M``. When the rise between the two minima also overlaps (its gap < 0) the bodies touch in one
connected region, which is kept as one patch (candidate 1 dropped), as the 3-D search merges such minima;
the overlap of the rise is reported as ``merge_approach_m`` so that the tables can apply the same rule.
Minima are refined by a parabola through three samples. At a candidate:
normal n = (0, N_y, -1)/|.| (the rail's normal, which equals the wheel's at a tangency), approach
q = -g cos(gamma) (vertical penetration projected on the normal, exact for locally straight profiles),
A = 1/(2 R sqrt(1 + R_y^2)) (normal curvature of the wheel along the rolling direction; the rail is straight),
B = (N_yy/(1 + N_y^2)^1.5 - R_yy/(1 + R_y^2)^1.5)/2, floored at ``MIN_LATERAL_CURVATURE_1_PER_M`` (nearly
conformal contacts are not Hertzian; the floor keeps the ellipse finite).

SearchProvider: the 3-D contact search (rigid_dynamics.contact.search, eq 5-11) per side and pose, with
irregularities; patches ordered by contact angle (slot 0 the tread side), at most two per side; a side with
no patch gets a gap candidate (approach = -smallest gap) so that wheel lift is seen.

Reuse of the last search (SearchProvider ``reuse_m``): a pose identical to the last one searched (the RK4 output
sample and the next step's first stage) returns the last patches unchanged (exact). With ``reuse_m`` > 0 a pose
within ``reuse_m`` of the last one (max of |delta centre| and r0 |delta angle|; e.g. the two RK4 stages at
t + h/2, which differ by h^2/4 times the accelerations) reuses the last patches with the rigid-body correction
of first order: the contact point moves with the wheel as a material point, p' = c' + C' C^T (p - c), and the
approach changes by the normal component of that displacement, q' = q - n . (p' - p) (n from rail into wheel).
For a polygonal wheel the tilt of the normal by the irregularity's slope makes this first-order exact for the
spin too. Normal, curvatures and the other patch data are kept (their change is of the order of the pose
change). The error is second order in the pose change; benchmarks/bench_dynamics.py measures it.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from rigid_dynamics.wheelset.parameters import Irregularities, TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers import SIDE_SIGNS, SIDES, PatchSet

ABSENT_GAP_M = 0.01
MIN_LATERAL_CURVATURE_1_PER_M = 0.05


def build_surfaces(wheelset: WheelsetParameters, track: TrackGeometry, irregularities: Irregularities | None = None):
    """Wheel and rail surfaces of both sides from the scene's profiles (contact.track.build_track).

    A conical track (wheel_profile "conical", rail_profile "circular") is built by :func:`conical_track`,
    placed exactly as the analytic ConicalProvider places it (contact points at +-e0, radius r0).

    Returns:
        The WheelsetTrack (``wheels``, ``rails`` dicts by side, ``search(pose, side, options)``).
    """
    from rigid_dynamics.contact.track import build_track

    if track.is_conical:
        return conical_track(wheelset, track, irregularities)
    case = SimpleNamespace(
        wheel_profile=track.wheel_profile,
        rail_profile=track.rail_profile,
        gauge_m=track.gauge_m,
        gauge_height_m=track.gauge_height_m,
        flange_back_distance_m=track.flange_back_distance_m,
        nominal_radius_m=wheelset.nominal_radius_m,
        rail_inclination_rad=track.rail_inclination_rad,
    )
    wheel_irr, rail_irr = {}, {}
    if irregularities is not None and irregularities.any:
        wheel_irr, rail_irr = geometry_irregularities(irregularities, wheelset.nominal_radius_m)
    return build_track(case, wheel_irregularities=wheel_irr, rail_irregularities=rail_irr)


class ConicalWheelSurface:
    """Conical wheel of side ``sign`` (-1 left, +1 right): R(alpha, y_d) = r0 + lambda (e0 - sign y_d) + R_irr(alpha).

    Duck-typed like rigid_dynamics.geometry.WheelSurface: ``evaluate(alpha, y_d)`` returns R and its partial
    derivatives (R, R_a, R_y, R_aa, R_ay, R_yy); ``y_range_m`` is the tread, e0 +- ``half_width_m``.
    """

    def __init__(self, sign, nominal_radius_m, contact_half_distance_m, conicity, irregularities=(), half_width_m=0.07):
        self.sign, self.r0, self.e0, self.lam = float(sign), nominal_radius_m, contact_half_distance_m, conicity
        self.irregularities = tuple(irregularities)
        lo, hi = self.e0 - half_width_m, self.e0 + half_width_m
        self.y_range_m = (lo, hi) if sign > 0 else (-hi, -lo)

    def evaluate(self, angle_rad, y_d_m):
        alpha, y_d = np.broadcast_arrays(np.asarray(angle_rad, float), np.asarray(y_d_m, float))
        r = self.r0 + self.lam * (self.e0 - self.sign * y_d)
        zero = np.zeros_like(r)
        out = [r, zero.copy(), np.full_like(r, -self.sign * self.lam), zero.copy(), zero.copy(), zero.copy()]
        for item in self.irregularities:
            for k, v in enumerate(item.evaluate(alpha, y_d)):
                out[k] = out[k] + v
        return tuple(out)


class CircularRailSurface:
    """Rail head of side ``sign``: a circle of radius R_r in the (y, z) plane, straight along x (z down).

    N(x, y) = z_c - sqrt(R_r^2 - (y - y_c)^2) + N_irr(x, y), with the centre (y_c, z_c) of ConicalProvider.
    """

    def __init__(self, sign, centre_y_m, centre_z_m, radius_m, irregularities=(), half_width_m=0.03):
        self.yc, self.zc, self.rr, self.sign = centre_y_m, centre_z_m, radius_m, float(sign)
        self.irregularities = tuple(irregularities)
        self.y_range_m = (centre_y_m - half_width_m, centre_y_m + half_width_m)

    def evaluate(self, x_m, y_m):
        x, y = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        u = y - self.yc
        w = np.sqrt(self.rr**2 - u**2)
        zero = np.zeros_like(w)
        out = [self.zc - w, zero.copy(), u / w, zero.copy(), zero.copy(), self.rr**2 / w**3]
        for item in self.irregularities:
            # rail irregularities take the lateral coordinate relative to the rail-head centre
            for k, v in enumerate(item.evaluate(x, self.sign * u)):
                out[k] = out[k] + (self.sign * v if k in (2, 4) else v)
        return tuple(out)


def conical_track(wheelset: WheelsetParameters, track: TrackGeometry, irregularities: Irregularities | None = None):
    """WheelsetTrack (contact.track) of conical wheels on circular rail heads, placed as ConicalProvider does."""
    from rigid_dynamics.contact.track import WheelsetTrack

    lam, r0, e0, rail_r = (
        track.conicity,
        wheelset.nominal_radius_m,
        wheelset.contact_half_distance_m,
        track.rail_head_radius_m,
    )
    root = math.sqrt(1 + lam * lam)
    wheel_irr, rail_irr = {}, {}
    if irregularities is not None and irregularities.any:
        wheel_irr, rail_irr = geometry_irregularities(irregularities, r0)
    wheels, rails = {}, {}
    for side, sign in zip(SIDES, SIDE_SIGNS, strict=True):
        wheels[side] = ConicalWheelSurface(sign, r0, e0, lam, wheel_irr.get(side, ()))
        rails[side] = CircularRailSurface(
            sign, sign * (e0 + rail_r * lam / root), rail_r / root, rail_r, rail_irr.get(side, ())
        )
    return WheelsetTrack(wheels=wheels, rails=rails, nominal_radius_m=r0, half_wheel_distance_m=e0)


def geometry_irregularities(irregularities: Irregularities, nominal_radius_m: float):
    """Map the scene's irregularities to rigid_dynamics.geometry irregularity objects per side.

    Returns:
        (wheel side -> tuple, rail side -> tuple).

    The rounded flat, the polygon and the corrugation are the same functions as in
    rigid_dynamics.wheelset.irregular (which the analytic providers use): geometry.WheelFlat "rounded",
    HarmonicOutOfRoundness, RailCorrugation (A cos(2 pi x / wavelength), over the rail head's central band).
    Further harmonics are more HarmonicOutOfRoundness objects; measured grids are read from their CSV files
    (rigid_dynamics.geometry.measured).
    """
    from rigid_dynamics import geometry as geo
    from rigid_dynamics.wheelset.irregular import applies_to

    wheel, rail = [], []
    irr = irregularities
    if irr.polygon_order > 0 and irr.polygon_amplitude_m > 0:
        wheel.append(
            geo.HarmonicOutOfRoundness(
                order=irr.polygon_order, amplitude_m=irr.polygon_amplitude_m, phase_rad=irr.polygon_phase_rad
            )
        )
    if irr.flat_length_m > 0:
        wheel.append(
            geo.WheelFlat(
                length_m=irr.flat_length_m,
                wheel_radius_m=nominal_radius_m,
                depth_m=irr.flat_depth_m if irr.flat_depth_m > 0 else None,
                centre_angle_rad=irr.flat_angle_rad,
                shape="rounded",
            )
        )
    if irr.corrugation_amplitude_m > 0:
        rail.append(
            geo.RailCorrugation(wavelength_m=irr.corrugation_wavelength_m, amplitude_m=irr.corrugation_amplitude_m)
        )
    for harmonic in irr.harmonics:
        if harmonic.amplitude_m > 0:
            wheel.append(geo.HarmonicOutOfRoundness(harmonic.order, harmonic.amplitude_m, harmonic.phase_rad))
    if irr.wheel_grid_file or irr.corrugation_file:
        from rigid_dynamics.geometry.measured import read_rail_grid_csv, read_wheel_grid_csv

        if irr.wheel_grid_file:
            wheel.append(read_wheel_grid_csv(irr.wheel_grid_file))
        if irr.corrugation_file:
            rail.append(read_rail_grid_csv(irr.corrugation_file))
    sides_w = {s: tuple(wheel) for s in SIDES if applies_to(irr, s)}
    sides_r = {s: tuple(rail) for s in SIDES if applies_to(irr, s)}
    return sides_w, sides_r


class ProfileSectionProvider:
    """2-D profile-section contact of ideal wheels and rails (module docstring); two candidates per side.

    Args:
        wheelset, track: scene parameters (profiles, gauge, ...).
        surfaces: optional prebuilt WheelsetTrack-like object with ``wheels`` and ``rails`` by side.
        lateral_step_m: sampling step of the wheel profile along the axle, m.
    """

    name = "section"

    def __init__(
        self,
        wheelset: WheelsetParameters,
        track: TrackGeometry,
        surfaces=None,
        *,
        lateral_step_m: float = 2.5e-4,
    ):
        if not math.isfinite(lateral_step_m) or lateral_step_m <= 0:
            raise ValueError(f"lateral_step_m = {lateral_step_m!r}: expected a finite number > 0")
        self.surfaces = surfaces if surfaces is not None else build_surfaces(wheelset, track)
        self.r0 = wheelset.nominal_radius_m
        self._wheel = []
        for side in SIDES:
            wheel = self.surfaces.wheels[side]
            lo, hi = wheel.y_range_m
            y_d = np.arange(lo, hi + 0.5 * lateral_step_m, lateral_step_m)
            y_d = y_d[(y_d >= lo) & (y_d <= hi)]
            values = wheel.evaluate(np.full_like(y_d, 0.5 * math.pi), y_d)
            self._wheel.append((y_d, np.asarray(values[0]), np.asarray(values[2]), np.asarray(values[5])))

    def _side(self, i: int, y_c: float, z_c: float, roll: float):
        y_d, radius, r_y, r_yy = self._wheel[i]
        cth, sth = math.cos(roll), math.sin(roll)
        p_y = y_c + y_d * cth - radius * sth
        p_z = z_c + y_d * sth + radius * cth
        rail = self.surfaces.rails[SIDES[i]]
        lo, hi = rail.y_range_m
        inside = (p_y >= lo) & (p_y <= hi)
        n_val = np.full_like(p_y, np.inf)
        if np.any(inside):
            n_val[inside] = np.asarray(rail.evaluate(np.zeros(int(inside.sum())), p_y[inside])[0])
        gap = n_val - p_z
        k0 = int(np.argmin(gap))
        found = [k0]
        interior = (gap[1:-1] < gap[:-2]) & (gap[1:-1] <= gap[2:])
        minima = np.flatnonzero(interior) + 1
        best, best_gap, best_hump = None, math.inf, math.inf
        for k in minima:
            if abs(k - k0) < 2 or not math.isfinite(gap[k]):
                continue
            lo_k, hi_k = min(k, k0), max(k, k0)
            hump = np.max(gap[lo_k : hi_k + 1])
            if hump > max(gap[k], gap[k0]) + 1e-6 and gap[k] < best_gap:
                best, best_gap, best_hump = k, gap[k], hump
        if best is not None:
            found.append(best)
        out = []
        humps = [math.inf, best_hump]
        for slot, k in enumerate(found):
            k = min(max(k, 1), len(gap) - 2)
            g0, g1, g2 = gap[k - 1], gap[k], gap[k + 1]
            denom = g0 - 2 * g1 + g2
            shift = 0.5 * (g0 - g2) / denom if np.isfinite(denom) and denom > 0 else 0.0
            shift = float(np.clip(shift, -1.0, 1.0))
            yd = float(np.interp(k + shift, np.arange(len(y_d)), y_d))
            rad = float(np.interp(yd, y_d, radius))
            ry = float(np.interp(yd, y_d, r_y))
            ryy = float(np.interp(yd, y_d, r_yy))
            py = y_c + yd * cth - rad * sth
            pz = z_c + yd * sth + rad * cth
            vals = rail.evaluate(np.array([0.0]), np.array([min(max(py, lo), hi)]))
            n_rail, n_y, n_yy = float(vals[0][0]), float(vals[2][0]), float(vals[5][0])
            g = n_rail - pz
            normal = np.array([0.0, n_y, -1.0]) / math.sqrt(1 + n_y * n_y)
            cos_gamma = -normal[2]
            curv_a = 0.5 / (rad * math.sqrt(1 + ry * ry))
            curv_b = 0.5 * (n_yy / (1 + n_y * n_y) ** 1.5 - ryy / (1 + ry * ry) ** 1.5)
            out.append(
                (
                    -g * cos_gamma,
                    np.array([0.0, py, pz]),
                    normal,
                    curv_a,
                    max(curv_b, MIN_LATERAL_CURVATURE_1_PER_M),
                    rad,
                    math.atan2(-SIDE_SIGNS[i] * normal[1], -normal[2]),
                    yd,
                    -humps[slot] * cos_gamma,
                )
            )
        if len(out) == 1:
            q, point, normal, ca, cb, rad, ang, yd, _ = out[0]
            # no second minimum: mark it as merged too, so that a table interpolating between cells with and
            # without a second minimum keeps it off rather than inventing a patch
            out.append((-ABSENT_GAP_M, point.copy(), normal.copy(), ca, cb, rad, ang, yd, ABSENT_GAP_M))
        return out

    def patches(self, centre_m, yaw_rad=0.0, roll_rad=0.0, spin_rad=0.0) -> PatchSet:
        rows = []
        for i in range(2):
            for candidate in self._side(i, float(centre_m[1]), float(centre_m[2]), roll_rad):
                rows.append((i, *candidate))
        point = np.array([r[2] for r in rows])
        point[:, 0] = float(centre_m[0])
        merge = np.array([r[9] for r in rows])
        approach = np.array([r[1] for r in rows])
        # a second minimum whose hump also overlaps belongs to the same (connected) patch: drop it
        approach = np.where(merge > 0, -ABSENT_GAP_M, approach)
        return PatchSet(
            side=np.array([r[0] for r in rows]),
            slot=np.array([0, 1, 0, 1]),
            point_m=point,
            normal=np.array([r[3] for r in rows]),
            curvature_long_1_per_m=np.array([r[4] for r in rows]),
            curvature_lat_1_per_m=np.array([r[5] for r in rows]),
            approach_m=approach,
            rolling_radius_m=np.array([r[6] for r in rows]),
            contact_angle_rad=np.array([r[7] for r in rows]),
            wheel_lateral_m=np.array([r[8] for r in rows]),
            merge_approach_m=merge,
        )


class SearchProvider:
    """3-D contact search per side (rigid_dynamics.contact.search) for every pose (module docstring).

    Args:
        wheelset, track: scene parameters.
        irregularities: the scene's irregularities (mapped to rigid_dynamics.geometry objects).
        surfaces: optional prebuilt WheelsetTrack (then ``irregularities`` is ignored).
        options: contact-search options (search.DEFAULT_OPTIONS); by default the undeformed-distance
            field is not sampled (``field=False``) unless a model needs it.
        reuse_m: pose change (m; angles times r0) up to which the last search is reused with the first-order
            rigid-body correction (module docstring); 0 = only an identical pose reuses it (exact).
    """

    name = "search"

    def __init__(
        self,
        wheelset: WheelsetParameters,
        track: TrackGeometry,
        irregularities: Irregularities | None = None,
        surfaces=None,
        options: dict | None = None,
        reuse_m: float = 0.0,
    ):
        if not math.isfinite(reuse_m) or reuse_m < 0:
            raise ValueError(f"reuse_m = {reuse_m!r}: expected a finite number >= 0")
        self.reuse_m = float(reuse_m)
        self._last = None
        self.reused = 0
        self.surfaces = surfaces if surfaces is not None else build_surfaces(wheelset, track, irregularities)
        self.options = {"field": False}
        if options:
            self.options.update(options)
        self.r0 = wheelset.nominal_radius_m
        self.searches = 0

    def patches(self, centre_m, yaw_rad, roll_rad, spin_rad=0.0) -> PatchSet:
        key = np.array([*np.asarray(centre_m, float)[:3], yaw_rad, roll_rad, spin_rad], float)
        if self._last is not None:
            last_key, last = self._last
            if np.array_equal(key, last_key):
                self.reused += 1
                return last
            change = np.abs(key - last_key)
            if self.reuse_m > 0 and max(change[:3].max(), self.r0 * change[3:].max()) <= self.reuse_m:
                self.reused += 1
                return self._moved(last_key, last, key)
        found = self._search(centre_m, yaw_rad, roll_rad, spin_rad)
        self._last = (key, found)
        return found

    def _moved(self, old_key, old: PatchSet, key) -> PatchSet:
        """The patches of the pose ``old_key`` carried to the pose ``key`` to first order (module docstring)."""
        from dataclasses import replace

        from rigid_dynamics.kinematics import wheelset_rotation

        turn = wheelset_rotation(*key[3:6]) @ wheelset_rotation(*old_key[3:6]).T
        point = key[:3] + (old.point_m - old_key[:3]) @ turn.T
        approach = old.approach_m - np.einsum("ij,ij->i", old.normal, point - old.point_m)
        geometries = None
        if old.geometries is not None:
            geometries = [
                replace(g, approach_m=float(q), point_m=p)
                for g, q, p in zip(old.geometries, approach, point, strict=True)
            ]
        return PatchSet(
            side=old.side,
            slot=old.slot,
            point_m=point,
            normal=old.normal,
            curvature_long_1_per_m=old.curvature_long_1_per_m,
            curvature_lat_1_per_m=old.curvature_lat_1_per_m,
            approach_m=approach,
            rolling_radius_m=old.rolling_radius_m,
            contact_angle_rad=old.contact_angle_rad,
            wheel_lateral_m=old.wheel_lateral_m,
            geometries=geometries,
        )

    def _search(self, centre_m, yaw_rad, roll_rad, spin_rad) -> PatchSet:
        from rigid_dynamics.contact.search import WheelsetPose

        pose = WheelsetPose(
            float(centre_m[0]), float(centre_m[1]), float(centre_m[2]), float(yaw_rad), float(roll_rad), float(spin_rad)
        )
        side_idx, slot, geometries, lateral = [], [], [], []
        for i, side in enumerate(SIDES):
            result = self.surfaces.search(pose, side, self.options)
            self.searches += 1
            found = sorted(
                zip(result.patches, result.wheel_parameters[:, 1] if len(result.patches) else [], strict=False),
                key=lambda p: p[0].approach_m,
                reverse=True,
            )[:2]
            found.sort(key=lambda p: p[0].contact_angle_rad)
            if not found:
                from rigid_dynamics.contact.types import ContactGeometry

                s = SIDE_SIGNS[i]
                gap = result.min_gap_m if math.isfinite(result.min_gap_m) else ABSENT_GAP_M
                point = np.asarray(centre_m, float) + np.array([0.0, 0.0, self.r0])
                point[1] += s * 0.75
                found = [
                    (
                        ContactGeometry(
                            0.5 / self.r0, 0.5 / 0.3, -float(gap), side=side, point_m=point,
                            frame=np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]]), rolling_radius_m=self.r0,
                        ),
                        s * 0.75,
                    )
                ]  # fmt: skip
            for k, (geometry, y_d) in enumerate(found):
                side_idx.append(i)
                slot.append(k)
                geometries.append(geometry)
                lateral.append(y_d)
        return PatchSet(
            side=np.array(side_idx),
            slot=np.array(slot),
            point_m=np.array([g.point_m for g in geometries], float),
            normal=np.array([g.frame[:, 2] for g in geometries], float),
            curvature_long_1_per_m=np.array([g.curvature_long_1_per_m for g in geometries]),
            curvature_lat_1_per_m=np.array([g.curvature_lat_1_per_m for g in geometries]),
            approach_m=np.array([g.approach_m for g in geometries]),
            rolling_radius_m=np.array([g.rolling_radius_m for g in geometries]),
            contact_angle_rad=np.array([g.contact_angle_rad for g in geometries]),
            wheel_lateral_m=np.array(lateral, float),
            geometries=geometries,
        )
