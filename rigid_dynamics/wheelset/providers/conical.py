"""Conical wheel on a circular rail head (derivation). Wheel of side s (-1 left, +1 right) in the
wheelset frame: radius R(y_d) = r0 + lambda (e0 - s y_d) (radius growing towards the flange, i.e. the
track centre). For a yaw psi and roll theta the wheel's lowest points (spatial angle alpha = pi/2,
maximum z of every wheel circle, kinematics.py) form, in the track's (y, z) plane, the straight line

    P(y_d) = (y_c + cos(psi) (y_d cos(theta) - R sin(theta)),  z_c + y_d sin(theta) + R cos(theta)),

with direction d = (cos(psi) (cos(theta) + s lambda sin(theta)), sin(theta) - s lambda cos(theta)).
The rail head of side s is a circle of radius R_r whose centre C_s is placed so that the centred,
unrolled wheelset at z_c = -r0 touches it at y = s e0, z = 0:
C_s = (s (e0 + R_r lambda / sqrt(1 + lambda^2)), R_r / sqrt(1 + lambda^2)). A straight line and a circle
touch at the foot of the perpendicular from the centre: with n_l the unit normal of the line pointing
to the rail side and delta = (C_s - P) . n_l the distance, the approach (interpenetration) is
q = R_r - delta, exactly. The rail contact point is C_s - R_r n_l, the point whose rail slope equals the
cone's slope, whatever the rail radius: with theta = 0 a lateral shift y moves the wheel contact by
-s y along the cone, so the rolling radius is r0 + s lambda y exactly. (With roll the normal turns by
theta, the rail contact point moves by R_r theta, and the effective conicity becomes
lambda / (1 - lambda R_r / e0) to first order: use a small R_r for an exactly linear wheelset.)
Relative curvatures (Hertz, h = A x^2 + B y^2): the cone's normal curvature along the rolling direction
is cos(gamma_w)/R with gamma_w = atan(lambda), its curvature along the generator is 0, the rail is
straight along x: A = 1/(2 R sqrt(1 + lambda^2)), B = 1/(2 R_r). Approximation: with yaw, the point of
a cone whose normal is perpendicular to the rail axis moves off the lowest line by O(psi lambda); this
shift is neglected (the contact point is taken on the lowest line).
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.irregular import applies_to
from rigid_dynamics.wheelset.parameters import Irregularities, TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers.patches import SIDE_SIGNS, SIDES, PatchSet, running_direction_only


class ConicalProvider:
    """Exact contact of conical wheels on circular rail heads (module docstring), one patch per wheel.

    Args:
        wheelset: r0 = nominal_radius_m, e0 = contact_half_distance_m.
        track: conicity lambda, rail_head_radius_m R_r.
        irregularities: optional running-direction irregularities.
    """

    name = "conical"

    def __init__(
        self, wheelset: WheelsetParameters, track: TrackGeometry, irregularities: Irregularities | None = None
    ):
        self.r0 = wheelset.nominal_radius_m
        self.e0 = wheelset.contact_half_distance_m
        self.conicity = track.conicity
        self.rail_radius = track.rail_head_radius_m
        lam = self.conicity
        root = math.sqrt(1 + lam * lam)
        self.rail_centre_y = SIDE_SIGNS * (self.e0 + self.rail_radius * lam / root)
        self.rail_centre_z = np.full(2, self.rail_radius / root)
        self.irregularities = running_direction_only(irregularities, self.name)
        if self.irregularities is not None:
            self._irr_sides = np.array([applies_to(self.irregularities, s) for s in SIDES])

    def patches(self, centre_m, yaw_rad, roll_rad, spin_rad=0.0) -> PatchSet:
        x_c, y_c, z_c = float(centre_m[0]), float(centre_m[1]), float(centre_m[2])
        cps, sps = math.cos(yaw_rad), math.sin(yaw_rad)
        cth, sth = math.cos(roll_rad), math.sin(roll_rad)
        lam, r0, e0, rail_r = self.conicity, self.r0, self.e0, self.rail_radius
        rows = []
        for i, s in enumerate((-1.0, 1.0)):
            yd0 = s * e0
            p_y = y_c + cps * (yd0 * cth - r0 * sth)
            p_z = z_c + yd0 * sth + r0 * cth
            d_y = cps * (cth + s * lam * sth)
            d_z = sth - s * lam * cth
            length = math.hypot(d_y, d_z)
            u_y, u_z = d_y / length, d_z / length
            nl_y, nl_z = -u_z, u_y
            c_y, c_z = self.rail_centre_y[i], self.rail_centre_z[i]
            delta = (c_y - p_y) * nl_y + (c_z - p_z) * nl_z
            foot_y, foot_z = c_y - delta * nl_y, c_z - delta * nl_z
            y_d = yd0 + ((foot_y - p_y) * u_y + (foot_z - p_z) * u_z) / length
            radius = r0 + lam * (e0 - s * y_d)
            x_off = -sps * (y_d * cth - radius * sth)
            rows.append(
                (
                    rail_r - delta,
                    (x_c + x_off, foot_y, foot_z),
                    (0.0, u_z, -u_y),
                    radius,
                    math.atan2(-s * u_z, u_y),
                    y_d,
                )
            )
        radius = np.array([rows[0][3], rows[1][3]])
        patches = PatchSet(
            side=np.array([0, 1]),
            slot=np.array([0, 0]),
            point_m=np.array([rows[0][1], rows[1][1]]),
            normal=np.array([rows[0][2], rows[1][2]]),
            curvature_long_1_per_m=0.5 / (radius * math.sqrt(1 + lam * lam)),
            curvature_lat_1_per_m=np.full(2, 0.5 / rail_r),
            approach_m=np.array([rows[0][0], rows[1][0]]),
            rolling_radius_m=radius,
            contact_angle_rad=np.array([rows[0][4], rows[1][4]]),
            wheel_lateral_m=np.array([rows[0][5], rows[1][5]]),
        )
        if self.irregularities is not None:
            self._add_irregularities(patches, spin_rad)
        return patches

    def _add_irregularities(self, patches: PatchSet, spin_rad: float) -> None:
        """The running-direction irregularities by the compiled section of the dynamics (compiled_tables._irregularity:
        the wheel point at beta from the lowest point, the extra overlap maximised over beta, projected on the normal;
        the normal tilted by N_irr'; A from the polar curvature of r(beta), floored for a concave flat).
        """
        from rigid_dynamics.wheelset import layout as lay
        from rigid_dynamics.wheelset.compiled_tables import irregular_candidates, irregularity_parameters

        if getattr(self, "_par", None) is None:
            self._par = lay.new_parameters()
            irregularity_parameters(self._par, self.irregularities, self._irr_sides, self.r0)
        n = len(patches)
        work = np.zeros((lay.N_TABLE_ROWS, n))
        work[lay.T_APPROACH] = patches.approach_m
        work[lay.T_NORMAL_Y], work[lay.T_NORMAL_Z] = patches.normal[:, 1], patches.normal[:, 2]
        work[lay.T_CURVATURE_LONG] = patches.curvature_long_1_per_m
        work[lay.T_ROLLING_RADIUS] = patches.rolling_radius_m
        geo = np.empty((n, lay.N_SECTION))
        sides = np.asarray(patches.side, np.int64)
        irregular_candidates(self._par, work, sides, np.ascontiguousarray(patches.point_m[:, 0]), spin_rad, geo)
        for k in np.flatnonzero(~np.isnan(geo[:, lay.I_APPROACH])):
            patches.approach_m[k] = geo[k, lay.I_APPROACH]
            patches.point_m[k, 0] += geo[k, lay.I_OFFSET_X]
            patches.point_m[k, 2] += geo[k, lay.I_OFFSET_Z]
            patches.normal[k] = geo[k, lay.I_NORMAL_X : lay.I_NORMAL_Z + 1]
            patches.rolling_radius_m[k] = geo[k, lay.I_ROLLING_RADIUS]
            patches.curvature_long_1_per_m[k] = geo[k, lay.I_CURVATURE_LONG]
