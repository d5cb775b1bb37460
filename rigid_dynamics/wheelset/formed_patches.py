"""The patches of the dynamics loop formed as the static wheelset case forms them (CONTACT's module 1,
rigid_dynamics.contact.wheelset_patches): which formed patch a compiled contact candidate serves, the creepages at
the formed patch's reference point, its forces in the candidate's contact frame (applied) and its own quantities
(recorded).

The compiled 3-D search gives each side's candidates at the local minima of the normal gap, with the contact plane
at the deepest point (at most two per side). The static case (equal to CONTACT) instead splits the vertical gap
along the contact locus into interpenetration regions, joins close ones (D_COMB) and solves each patch in the plane
of its weighted reference point and contact angle, with the undeformed distance evaluated exactly from the surfaces
(regions D_COMB < d <= D_SEP apart are sub-patches whose normal interaction the ``bem`` rung reduces as CONTACT does:
the formed patch's ``undeformed`` carries them, wheelset_patches.sub_patches, the same path as the static case).
For a gap-solving model (callback.PatchCallback with patches "contact") the side's patches are formed so at the
pose the candidate carries (once per side and pose) and

* a candidate serves the formed patch that holds its interpenetration region (the region whose lateral extent
  holds the candidate's contact point, or the nearest within ``MATCH_DISTANCE_M``) when that region is the patch's
  deepest; a candidate whose region was joined into a patch served by a deeper one gets no force (its region's
  pressure is in that patch); a candidate with no region within ``MATCH_DISTANCE_M`` is solved on its own plane
  (search.patch_undeformed_distance);
* the creepages at the formed patch's wheel point p' (normal n', frame e_x', e_y') follow from the candidate's
  (xi, eta, phi at p with n) by the wheel's rigid motion: v(p') = v(p) + omega x (p' - p) with v(p) = V (xi e_x +
  eta e_y) and omega ~ Omega a (a the axle, Omega = -V / r_roll), phi' = phi + Omega a . (n' - n) / V; the parts
  left out (the normal approach rate times the tilt of the plane, the yaw rate times the offset) are of the
  order of the creepage times 1e-2 for offsets of millimetres;
* the forces on the wheel (N', T_x', T_y' in the formed frame, spin moment M_z' about n' at p') are returned in
  the candidate's frame, and M_z is the moment about the candidate's normal through its point (the moment of the
  offset p' - p included). The components of that offset's moment about the candidate's tangents (at most the
  offset, millimetres, times the force) are left out: the compiled code applies a patch's force at its point;
* the record of the run (its per-patch columns, SimulationResult.patches; ContactState.record) holds the formed
  patch's own quantities (:func:`own_quantities`, layout.FORMED_PATCH_FIELDS): N', T_x', T_y' and M_z' in its own
  contact frame, the creepages transported to it, its approach, reference point (y, main frame; the point on the
  rail where CONTACT puts it), the wheel's lateral coordinate and rolling radius at its wheel point p', and its
  contact angle; the semi-axes, area, max pressure and ellipticity residual were always the formed patch's (the
  model's result on its gap). The compiled loop keeps the candidate's values in the patch record's first columns for
  what it does with them (the forces it applies, its contact switches, force checks and error estimate, the traction
  controller, the run's stops and its flange-contact event) and the formed patch's in columns of their own, which
  the record writers put in their place (:func:`recorded`: recorder.Recorder, for the compiled loop's tables,
  drivers.patch_tables, and the Python drivers' samples alike; WheelsetModel.contact's ContactState.record). So
  the forces the loop applies and the trajectory are those of before, and the record reads as the patch was
  solved: on curve-flange's conformal flange root (tests/test_loop_formed_record.py, against CONTACT's planar
  solution) the contact angle 0.81 rad and a creep force of 0.81 mu N, where the candidate's frame (0.55 rad) read
  a lateral creep force of -2.4 kN. A candidate whose region was joined into a deeper candidate's patch records no
  force (the joined patch is in that candidate's record); ``auto``'s BEM patches served by their anchor's
  correction (auto_reuse.py) are recorded in the formed plane of their anchor: the anchor keeps the map from the
  candidate's frame to the formed patch's (:func:`frame_map`) and the formed patch's geometry as departures from
  the candidate's (auto_reuse.reuse_own).
"""

from __future__ import annotations

import numpy as np

from rigid_dynamics.contact.types import Creepage
from rigid_dynamics.wheelset.layout import FORMED_PATCH_FIELDS, N_FORMED, PATCH_FIELDS

MATCH_DISTANCE_M = 5.0e-3
"""Largest lateral distance from a candidate's contact point to an interpenetration region it may serve, m."""


class PatchFormer:
    """The formed patches of each side at the last pose asked (cached: both candidates of a side share them)."""

    def __init__(self, surfaces):
        self.surfaces = surfaces
        self._last: dict = {}

    def patches(self, side: str, pose):
        """(formed patches, regions) of ``side`` at ``pose`` (contact.wheelset_patches.wheel_patches)."""
        from rigid_dynamics.contact.wheelset_patches import wheel_patches

        key = (pose.x_m, pose.y_m, pose.z_m, pose.yaw_rad, pose.roll_rad, pose.spin_rad)
        last = self._last.get(side)
        if last is not None and last[0] == key:
            return last[1]
        wheel, rail = self.surfaces.fast[side]
        formed, _ = wheel_patches(
            wheel, rail, pose, side, wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m,
            nominal_radius_m=self.surfaces.nominal_radius_m,
        )  # fmt: skip
        self._last[side] = (key, formed)
        return formed

    def last(self, side: str) -> list:
        """The formed patches of ``side`` at the last pose asked (empty before any)."""
        last = self._last.get(side)
        return [] if last is None else list(last[1])

    def served(self, side: str, pose, point_m):
        """The formed patch the candidate at ``point_m`` serves; None when its region is served by a deeper
        candidate; ``False`` when no region lies within MATCH_DISTANCE_M (module docstring).
        """
        formed = self.patches(side, pose)
        y = float(point_m[1])
        best, best_distance = None, MATCH_DISTANCE_M
        for patch in formed:
            for region in patch.regions:
                lo, hi = float(np.min(region.ends_m[:, 0])), float(np.max(region.ends_m[:, 0]))
                distance = max(lo - y, y - hi, 0.0)
                if distance < best_distance or (distance == 0.0 and best_distance == 0.0):
                    best, best_distance = (patch, region), distance
        if best is None:
            return False
        patch, region = best
        deepest = min(patch.regions, key=lambda r: r.min_gap_m)
        return patch if deepest is region else None


def transported_creepage(patch, creepage: Creepage, axle, target) -> Creepage:
    """The creepages at the formed patch ``target`` (a WheelPatch) from the candidate's (module docstring).

    ``patch``: the compiled_rhs.CallbackPatch; ``axle``: the wheelset's axle direction (main frame).
    """
    speed = float(creepage.rolling_speed_m_per_s)
    e_x, e_y, n = (np.asarray(v, float) for v in (patch.e_x, patch.e_y, patch.normal))
    omega = -speed / float(patch.rolling_radius_m) * np.asarray(axle, float)
    velocity = speed * (creepage.longitudinal * e_x + creepage.lateral * e_y)
    moved = velocity + np.cross(omega, np.asarray(target.wheel_point_m, float) - np.asarray(patch.point_m, float))
    frame = target.geometry.frame
    spin = creepage.spin_1_per_m + float(omega @ (frame[:, 2] - n)) / speed
    return Creepage(float(moved @ frame[:, 0]) / speed, float(moved @ frame[:, 1]) / speed, float(spin), speed)


def candidate_forces(patch, target, result) -> tuple[float, float, float, float]:
    """(N, T_x, T_y, M_z) on the wheel in the candidate's contact frame from the formed patch's ``result``."""
    frame = target.geometry.frame
    local = np.array([result.creep_force_long_N or 0.0, result.creep_force_lat_N or 0.0, result.normal_force_N or 0.0])
    force = frame @ local
    e_x, e_y, n = (np.asarray(v, float) for v in (patch.e_x, patch.e_y, patch.normal))
    offset = np.asarray(target.geometry.point_m, float) - np.asarray(patch.point_m, float)
    moment = (result.spin_moment_Nm or 0.0) * frame[:, 2] + np.cross(offset, force)
    return float(force @ n), float(force @ e_x), float(force @ e_y), float(moment @ n)


def frame_map(patch, target) -> tuple:
    """The map from the candidate's contact frame to the formed patch ``target``'s (layout.N_FRAME_MAP values):
    Q[i][j] = C_i . F_j row by row (C = the candidate's e_x, e_y, n; F = the formed patch's frame columns e_x', e_y',
    n'), then w_i = C_i . (n x o) with o the offset p' - p of the formed patch's point from the candidate's. So the
    forces of :func:`candidate_forces`, (T_x, T_y, N) = Q (T_x', T_y', N') and M_z = Q[2][2] M_z' + w . (T_x, T_y,
    N), turn back into the formed patch's own by Q's transpose (both frames orthonormal), and the creepages at the
    formed patch's point (:func:`transported_creepage`) are xi' = Q[0][0] xi + Q[1][0] eta + k_x, eta' = Q[0][1] xi
    + Q[1][1] eta + k_y with k the rigid motion's part, fixed by the pose (auto_reuse.reuse_own: a patch ``auto``
    serves by its anchor's correction is recorded in the formed plane of that anchor).
    """
    candidate = np.array([patch.e_x, patch.e_y, patch.normal], float)
    frame = np.asarray(target.geometry.frame, float)
    offset = np.asarray(target.geometry.point_m, float) - np.asarray(patch.point_m, float)
    q = candidate @ frame
    w = candidate @ np.cross(candidate[2], offset)
    return tuple(float(v) for v in q.ravel()) + tuple(float(v) for v in w)


def own_quantities(target, result, creepage: Creepage) -> tuple:
    """The formed patch ``target``'s own quantities in the order of layout.FORMED_PATCH_FIELDS (N', T_x', T_y', M_z'
    of the model's ``result`` in its own contact frame; the transported ``creepage``; its approach, reference
    point's y, the wheel's lateral coordinate and rolling radius at its wheel point, its contact angle).
    """
    geometry = target.geometry
    return (
        float(result.normal_force_N or 0.0),
        float(result.creep_force_long_N or 0.0),
        float(result.creep_force_lat_N or 0.0),
        float(result.spin_moment_Nm or 0.0),
        float(creepage.longitudinal),
        float(creepage.lateral),
        float(creepage.spin_1_per_m),
        float(geometry.approach_m),
        float(np.asarray(geometry.point_m, float)[1]),
        float(target.wheel_lateral_m),
        float(geometry.rolling_radius_m),
        float(geometry.contact_angle_rad),
    )


def recorded(table: dict) -> dict:
    """The record of a patch table (name -> array over samples / sides / slots / candidates, as the compiled
    record's columns: PATCH_FIELDS, AUTO_PATCH_FIELDS, FORMED_PATCH_FIELDS): where a candidate served a formed
    patch (``formed_normal_force_N`` finite) that patch's own quantities in place of the candidate's, and without
    the FORMED_PATCH_FIELDS. A table without them is returned as it is (a copy of the dict).
    """
    out = {name: value for name, value in table.items() if name not in FORMED_PATCH_FIELDS}
    own = table.get(FORMED_PATCH_FIELDS[0])
    if own is None:
        return out
    formed = np.isfinite(np.asarray(own, float))
    if not np.any(formed):
        return out
    for name, formed_name in zip(PATCH_FIELDS[:N_FORMED], FORMED_PATCH_FIELDS, strict=True):
        out[name] = np.where(formed, np.asarray(table[formed_name], float), np.asarray(table[name], float))
    return out
