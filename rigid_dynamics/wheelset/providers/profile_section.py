"""ProfileSectionProvider (ideal geometry, the classic "contact table" method). In the track's (y, z) plane
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
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.parameters import TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers.patches import SIDE_SIGNS, SIDES, PatchSet
from rigid_dynamics.wheelset.providers.surfaces import ABSENT_GAP_M, MIN_LATERAL_CURVATURE_1_PER_M, build_surfaces


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
