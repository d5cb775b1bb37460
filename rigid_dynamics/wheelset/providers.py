"""Contact-geometry providers: where the patches of a wheelset pose come from.

The equations of motion ask a *provider* for the contact patches of a pose and do not care how they
were found. A provider has a ``name`` and one method::

    provider.patches(centre_m, yaw_rad, roll_rad, spin_rad) -> PatchSet

returning every contact *candidate* of both wheels (also those with a gap, approach < 0, so that
wheel lift can be detected). Providers here:

* :class:`ConicalProvider` — exact analytic contact of a conical wheel on a circular rail head
  (derivation below), with optional running-direction irregularities. Used for Klingel and
  stability verification.
* :class:`TableProvider` — contact-geometry tables over lateral shift and roll, precomputed from any
  section provider for ideal (irregularity-free) geometry; the usual practice of multibody codes.
* :class:`SearchProvider` — the 3-D contact search of rigid_dynamics.contact.search (real profiles,
  irregularities) when it is available.

Conical wheel on a circular rail head (derivation). Wheel of side s (-1 left, +1 right) in the
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

Running-direction irregularities (R_irr(alpha) of the wheel, N_irr(x) of the rail; irregular.py) are
added by a section in the rolling plane: the wheel point at beta from the lowest point (material angle
alpha = pi/2 + beta - phi, kinematics.py) has radius r(beta) = R + R_irr(alpha) and reaches
(r cos(beta) - R) further down than the ideal lowest point, at x offset -r sin(beta); the approach is
q(beta) = q0 + [r cos(beta) - R - N_irr(x + x_offset)] cos(gamma), maximised over beta (grid, then Newton;
the bracket is the extra vertical overlap, projected on the contact normal of contact angle gamma). The
normal is the rail's, (N_irr', N_y, -1) normalised; A is built from the polar curvature of r(beta)
and N_irr''. Where a flat makes the wheel locally concave, A is floored at ``MIN_LONGITUDINAL_CURVATURE_FRACTION``
times its nominal value (a Hertzian stand-in for what is a two-point, non-Hertzian contact).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from rigid_dynamics.wheelset.irregular import applies_to, dip_depth_m, rail_irregularity, wheel_radius_irregularity
from rigid_dynamics.wheelset.parameters import Irregularities, TrackGeometry, WheelsetParameters

SIDES = ("left", "right")
SIDE_SIGNS = np.array([-1.0, 1.0])
MIN_LONGITUDINAL_CURVATURE_FRACTION = 0.1
"""Floor of the longitudinal relative curvature A, as a fraction of 1/(2 r0) (concave flat regions)."""


@dataclass(eq=False)
class PatchSet:
    """Contact candidates of both wheels of one pose; arrays of length n (one entry per candidate).

    Attributes:
        side: 0 = left, 1 = right.
        slot: candidate number on its side (0 tread, 1 flange or second patch).
        point_m: contact point on the wheel, main frame, (n, 3), m.
        normal: unit normal from the rail into the wheel, main frame, (n, 3).
        curvature_long_1_per_m, curvature_lat_1_per_m: A, B of h = A x^2 + B y^2 - q, (n,), 1/m.
        approach_m: q, (n,), m (> 0 in contact, < 0 a gap).
        rolling_radius_m: wheel radius at the contact, (n,), m.
        contact_angle_rad: angle of the normal to the vertical, positive towards the track centre, (n,).
        wheel_lateral_m: y_d of the contact point on the wheel (wheelset frame), (n,), m.
        geometries: optional ContactGeometry per candidate (a search gives sampled gap fields).
        merge_approach_m: optional, per candidate: overlap of the rise of the gap between this candidate and
            the deepest one of its side (-inf for the deepest); > 0 means both lie in one connected contact
            region and this candidate is not a separate patch (profiles.ProfileSectionProvider).
    """

    side: np.ndarray
    slot: np.ndarray
    point_m: np.ndarray
    normal: np.ndarray
    curvature_long_1_per_m: np.ndarray
    curvature_lat_1_per_m: np.ndarray
    approach_m: np.ndarray
    rolling_radius_m: np.ndarray
    contact_angle_rad: np.ndarray
    wheel_lateral_m: np.ndarray
    geometries: list | None = None
    merge_approach_m: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.side)


def _running_direction_only(irregularities: Irregularities | None, provider: str) -> Irregularities | None:
    """The irregularities an analytic provider evaluates (irregular.py), None if there are none.

    Raises:
        ValueError: harmonics or measured grids, which only the 3-D search evaluates.
    """
    if irregularities is None or not irregularities.any:
        return None
    if irregularities.needs_search:
        raise ValueError(
            f"contact_provider = {provider!r} with irregularities harmonics / wheel_grid_file / corrugation_file: "
            "expected contact_provider 'search' or 'auto' (only the 3-D search evaluates them)"
        )
    return irregularities


@runtime_checkable
class ContactProvider(Protocol):
    """What the equations of motion need from a contact-geometry source."""

    name: str

    def patches(self, centre_m: np.ndarray, yaw_rad: float, roll_rad: float, spin_rad: float) -> PatchSet: ...


def _running_irregularity(patches: PatchSet, sides_mask, centre_m, spin_rad, irr: Irregularities, r0: float):
    """Add R_irr(alpha), N_irr(x) to the candidates of the sides in ``sides_mask`` (module docstring).

    Vectorised over the candidates; candidates with a gap larger than twice the irregularity amplitude are
    left alone (the irregularity cannot close it).
    """
    wheel_on = (irr.polygon_order > 0 and irr.polygon_amplitude_m > 0) or irr.flat_length_m > 0
    rail_on = irr.corrugation_amplitude_m > 0 or irr.joint_dip_angle_rad > 0
    reach = 2.0 * (irr.polygon_amplitude_m + irr.corrugation_amplitude_m + dip_depth_m(irr)) + 1e-4
    half = 0.02
    if irr.flat_length_m > 0:
        from rigid_dynamics.wheelset.irregular import flat_depth_m

        reach += 2.0 * flat_depth_m(irr, r0)
        half = max(half, 1.5 * irr.flat_length_m / r0)
    if irr.corrugation_amplitude_m > 0:
        half = max(half, 0.6 * irr.corrugation_wavelength_m / r0)
    sel = np.flatnonzero(sides_mask[patches.side] & (patches.approach_m > -reach))
    if len(sel) == 0:
        return patches
    radius = patches.rolling_radius_m[sel][:, None]
    x0 = patches.point_m[sel, 0][:, None]

    def parts(beta):
        if wheel_on:
            rv, r1, r2 = wheel_radius_irregularity(irr, r0, 0.5 * math.pi + beta - spin_rad)
        else:
            rv = r1 = r2 = np.zeros_like(beta)
        r = radius + rv
        sb, cb = np.sin(beta), np.cos(beta)
        xo = -r * sb
        x1 = -(r1 * sb + r * cb)
        x2 = -(r2 * sb + 2 * r1 * cb - r * sb)
        if rail_on:
            n0, n1, n2 = rail_irregularity(irr, x0 + xo)
        else:
            n0 = n1 = n2 = np.zeros_like(r)
        q = r * cb - radius - n0
        q1 = r1 * cb - r * sb - n1 * x1
        q2 = r2 * cb - 2 * r1 * sb - r * cb - n2 * x1 * x1 - n1 * x2
        return q, q1, q2, r, r1, r2, xo, n1, n2

    grid = np.linspace(-half, half, 81)[None, :]
    q = parts(np.broadcast_to(grid, (len(sel), grid.shape[1])))[0]
    beta = grid[0, np.argmax(q, axis=1)][:, None]
    step_size = 2 * half / 80
    for _ in range(3):
        _, q1, q2, *_ = parts(beta)
        ok = q2 < 0
        step = np.where(ok, -q1 / np.where(ok, q2, -1.0), 0.0)
        beta = np.clip(beta + np.clip(step, -step_size, step_size), -half, half)
    qv, _, _, r, r1, r2, xo, n1, n2 = (np.asarray(v)[:, 0] for v in parts(beta))
    beta = beta[:, 0]
    kappa_w = (r * r + 2 * r1 * r1 - r * r2) / (r * r + r1 * r1) ** 1.5
    # scale the wheel's polar curvature like the ideal one (cone: cos(gamma_w) = 2 A R)
    scale = 2.0 * patches.curvature_long_1_per_m[sel] * radius[:, 0]
    a_long = 0.5 * (kappa_w * scale + n2 / (1 + n1 * n1) ** 1.5)
    normal = patches.normal[sel]
    slope_y = normal[:, 1] / -normal[:, 2]
    new_normal = np.stack([n1, slope_y, -np.ones_like(n1)], axis=-1)
    new_normal /= np.linalg.norm(new_normal, axis=1, keepdims=True)
    floor = MIN_LONGITUDINAL_CURVATURE_FRACTION * 0.5 / r0
    # qv is the extra overlap measured vertically; the approach is along the normal (cos(gamma) = -n_z)
    patches.approach_m[sel] = patches.approach_m[sel] + qv * -normal[:, 2]
    patches.point_m[sel, 0] += xo
    patches.point_m[sel, 2] += r * np.cos(beta) - radius[:, 0]
    patches.normal[sel] = new_normal
    patches.rolling_radius_m[sel] = r
    patches.curvature_long_1_per_m[sel] = np.maximum(a_long, floor)
    return patches


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
        self.irregularities = _running_direction_only(irregularities, self.name)
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
            _running_irregularity(patches, self._irr_sides, centre_m, spin_rad, self.irregularities, r0)
        return patches


class TableProvider:
    """Contact-geometry tables over lateral shift y and roll theta for ideal geometry.

    Built by sampling a *section* provider (any provider whose patches do not depend on x, yaw, spin)
    at the nominal centre height z_ref = -r0 on a (theta, y) grid. For each side and candidate slot it
    stores the approach q_ref, dq/dz = cos(gamma) = -n_z (exact for the conical provider and for the
    profile section, whose approach is the vertical overlap times cos(gamma)), the contact point (y, z
    relative to the centre), the normal,
    the curvatures, rolling radius, contact angle and wheel lateral position. At run time all
    quantities are interpolated bilinearly and q = q_ref + (z - z_ref) dq/dz. Yaw enters only the
    kinematics (creepages) and the x offset of the contact point, -sin(psi) y_d. A second candidate whose
    tabulated merge approach (PatchSet.merge_approach_m, shifted with z like q) is positive lies in the same
    connected contact region as the first and is dropped.

    Args:
        section: the provider to tabulate.
        nominal_radius_m: r0 (z_ref = -r0).
        lateral_range_m: the table covers y in [-range, range].
        lateral_step_m: grid spacing in y.
        roll_range_rad, roll_points: theta grid.
        irregularities: running-direction irregularities applied on top (optional).
    """

    name = "tables"

    def __init__(
        self,
        section: ContactProvider,
        nominal_radius_m: float,
        *,
        lateral_range_m: float = 0.02,
        lateral_step_m: float = 2.5e-4,
        roll_range_rad: float = 0.01,
        roll_points: int = 11,
        irregularities: Irregularities | None = None,
    ):
        for name, value in (
            ("lateral_range_m", lateral_range_m),
            ("lateral_step_m", lateral_step_m),
            ("roll_range_rad", roll_range_rad),
        ):
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        if roll_points < 2:
            raise ValueError(f"roll_points = {roll_points!r}: expected an integer >= 2")
        self.r0 = nominal_radius_m
        self.z_ref = -nominal_radius_m
        self.y_grid = np.arange(-lateral_range_m, lateral_range_m + 0.5 * lateral_step_m, lateral_step_m)
        self.roll_grid = np.linspace(-roll_range_rad, roll_range_rad, roll_points)
        probe = section.patches(np.array([0.0, 0.0, self.z_ref]), 0.0, 0.0, 0.0)
        self.side = probe.side.copy()
        self.slot = probe.slot.copy()
        n = len(probe)
        # quantities: q, dq/dz, py, pz, ny, nz, A, B, radius, angle, y_d, merge approach (12)
        table = np.empty((12, n, len(self.roll_grid), len(self.y_grid)))
        for i, theta in enumerate(self.roll_grid):
            for j, y in enumerate(self.y_grid):
                p = section.patches(np.array([0.0, y, self.z_ref]), 0.0, theta, 0.0)
                if len(p) != n:
                    raise ValueError(f"section provider {section.name!r} changed its number of candidates")
                table[0, :, i, j] = p.approach_m
                table[1, :, i, j] = -p.normal[:, 2]
                table[2, :, i, j] = p.point_m[:, 1] - y
                table[3, :, i, j] = p.point_m[:, 2] - self.z_ref
                table[4, :, i, j] = p.normal[:, 1]
                table[5, :, i, j] = p.normal[:, 2]
                table[6, :, i, j] = p.curvature_long_1_per_m
                table[7, :, i, j] = p.curvature_lat_1_per_m
                table[8, :, i, j] = p.rolling_radius_m
                table[9, :, i, j] = p.contact_angle_rad
                table[10, :, i, j] = p.wheel_lateral_m
                merge = p.merge_approach_m if p.merge_approach_m is not None else np.full(n, -np.inf)
                table[11, :, i, j] = np.maximum(merge, -1.0)  # finite, for the interpolation
        self.table = table
        self.irregularities = _running_direction_only(irregularities, self.name)
        if self.irregularities is not None:
            self._irr_sides = np.array([applies_to(self.irregularities, s) for s in SIDES])

    def patches(self, centre_m, yaw_rad, roll_rad, spin_rad=0.0) -> PatchSet:
        x_c, y_c, z_c = float(centre_m[0]), float(centre_m[1]), float(centre_m[2])
        yg, rg = self.y_grid, self.roll_grid
        fy = (min(max(y_c, yg[0]), yg[-1]) - yg[0]) / (yg[1] - yg[0])
        j = min(int(fy), len(yg) - 2)
        wy = fy - j
        fr = (min(max(roll_rad, rg[0]), rg[-1]) - rg[0]) / (rg[1] - rg[0])
        i = min(int(fr), len(rg) - 2)
        wr = fr - i
        t = self.table
        v = (1 - wr) * ((1 - wy) * t[:, :, i, j] + wy * t[:, :, i, j + 1]) + wr * (
            (1 - wy) * t[:, :, i + 1, j] + wy * t[:, :, i + 1, j + 1]
        )
        approach = v[0] + (z_c - self.z_ref) * v[1]
        merged = v[11] + (z_c - self.z_ref) * v[1] > 0
        approach = np.where(merged & (self.slot > 0), -0.01, approach)
        n_y, n_z = v[4], v[5]
        norm = np.sqrt(n_y * n_y + n_z * n_z)
        normal = np.stack([np.zeros_like(n_y), n_y / norm, n_z / norm], axis=-1)
        x_off = -math.sin(yaw_rad) * v[10]
        point = np.stack([x_c + x_off, y_c + v[2], z_c + v[3]], axis=-1)
        patches = PatchSet(
            side=self.side,
            slot=self.slot,
            point_m=point,
            normal=normal,
            curvature_long_1_per_m=v[6].copy(),
            curvature_lat_1_per_m=v[7].copy(),
            approach_m=approach,
            rolling_radius_m=v[8].copy(),
            contact_angle_rad=v[9].copy(),
            wheel_lateral_m=v[10].copy(),
        )
        if self.irregularities is not None:
            _running_irregularity(patches, self._irr_sides, centre_m, spin_rad, self.irregularities, self.r0)
        return patches
