"""SearchProvider: the 3-D contact search (rigid_dynamics.contact.search, eq 5-11) per side and pose, with
irregularities; patches ordered by contact angle (slot 0 the tread side), at most two per side; a side with
no patch gets a gap candidate (approach = -smallest gap) so that wheel lift is seen. The lateral relative
curvature B is floored at MIN_LATERAL_CURVATURE_1_PER_M as the profile section's (conformal contacts, e.g. the
R13 flange root of S1002 on the R13 gauge corner of UIC60, have B ~ 0: Hertz's force would be unbounded; the
patch's ContactGeometry keeps the search's own value).

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

import numpy as np

from rigid_dynamics.wheelset.parameters import Irregularities, TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers.patches import SIDE_SIGNS, SIDES, PatchSet
from rigid_dynamics.wheelset.providers.surfaces import ABSENT_GAP_M, MIN_LATERAL_CURVATURE_1_PER_M, build_surfaces


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

    def compiled_geometry(self) -> int:
        """How the compiled right-hand side gets this provider's geometry: its own 3-D search
        (layout.GEOMETRY_SEARCH, compiled_search.py) when every surface is tabulated (ideal profiles with polygon,
        flats or corrugation), else from this provider's :meth:`patches` (layout.GEOMETRY_GIVEN: measured grids,
        harmonics).
        """
        from rigid_dynamics.contact.search import TabulatedRail, TabulatedWheel
        from rigid_dynamics.wheelset.layout import GEOMETRY_GIVEN, GEOMETRY_SEARCH

        fast = getattr(self.surfaces, "fast", None)
        if fast is not None and all(
            isinstance(w, TabulatedWheel) and isinstance(r, TabulatedRail) for w, r in fast.values()
        ):
            return GEOMETRY_SEARCH
        return GEOMETRY_GIVEN

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
            # floored as the profile section's B (MIN_LATERAL_CURVATURE_1_PER_M): conformal contacts (equal radii of
            # flange root and gauge corner) have B ~ 0, whose Hertz stiffness is unbounded
            curvature_lat_1_per_m=np.maximum(
                [g.curvature_lat_1_per_m for g in geometries], MIN_LATERAL_CURVATURE_1_PER_M
            ),
            approach_m=np.array([g.approach_m for g in geometries]),
            rolling_radius_m=np.array([g.rolling_radius_m for g in geometries]),
            contact_angle_rad=np.array([g.contact_angle_rad for g in geometries]),
            wheel_lateral_m=np.array(lateral, float),
            geometries=geometries,
        )
