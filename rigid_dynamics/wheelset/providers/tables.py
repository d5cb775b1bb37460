"""Contact-geometry tables over lateral shift and roll for ideal geometry (:class:`TableProvider`), with the
running-direction irregularities added per pose; evaluated by the compiled look-up of the dynamics
(compiled_tables._table_geometry), also for inspection.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.irregular import applies_to
from rigid_dynamics.wheelset.parameters import Irregularities
from rigid_dynamics.wheelset.providers.patches import SIDES, ContactProvider, PatchSet, running_direction_only


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
        cache_parameters: (wheelset, track) that define ``section`` (as :func:`~rigid_dynamics.wheelset.simulate.
            build_provider` builds it, default section options): the tables are then loaded from / saved to the
            on-disk cache (providers/table_cache.py); :attr:`cache` says how (None without).
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
        cache_parameters: tuple | None = None,
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
        shape = (12, n, len(self.roll_grid), len(self.y_grid))
        self.cache = None
        if cache_parameters is None:
            self.table = self._build(section, shape)
        else:
            self.table = self._cached(
                section, shape, cache_parameters, (lateral_range_m, lateral_step_m, roll_range_rad, roll_points)
            )
        self.irregularities = running_direction_only(irregularities, self.name)
        if self.irregularities is not None:
            self._irr_sides = np.array([applies_to(self.irregularities, s) for s in SIDES])

    def _build(self, section: ContactProvider, shape: tuple) -> np.ndarray:
        """Sample ``section`` on the (roll, y) grid: the (12, candidates, roll, y) table."""
        # quantities: q, dq/dz, py, pz, ny, nz, A, B, radius, angle, y_d, merge approach (12)
        n = shape[1]
        table = np.empty(shape)
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
        return table

    def _cached(self, section: ContactProvider, shape: tuple, parameters: tuple, grid: tuple) -> np.ndarray:
        """The table from the on-disk cache when its file is whole, else built and saved (table_cache.py)."""
        from rigid_dynamics.wheelset.providers import table_cache

        key = table_cache.table_key(*parameters, type(section).__name__, grid)
        arrays, note = table_cache.load(key, shape)
        if (
            arrays is not None
            and np.array_equal(arrays["side"], self.side)
            and np.array_equal(arrays["slot"], self.slot)
        ):
            self.cache = table_cache.TableCacheResult("hit", table_cache.cache_dir() / f"tables-{key}.npz")
            return arrays["table"]
        if arrays is not None:
            note = "contact-table cache file with other candidates (side/slot): rebuilt"
        table = self._build(section, shape)
        path, save_note = table_cache.save(key, table, np.asarray(self.side), np.asarray(self.slot))
        notes = "; ".join(x for x in (note, save_note) if x)
        self.cache = table_cache.TableCacheResult("rebuilt" if note else "built", path, notes)
        return table

    def compiled_geometry(self) -> int:
        """The compiled right-hand side evaluates these tables itself (layout.GEOMETRY_TABLES; compiled_tables.py)."""
        from rigid_dynamics.wheelset.layout import GEOMETRY_TABLES

        return GEOMETRY_TABLES

    def _compiled(self):
        """(par, geometry) of the compiled look-up (compiled_tables.table_candidates), built once."""
        if getattr(self, "_packed", None) is None:
            from rigid_dynamics.wheelset.compiled_tables import irregularity_parameters, table_geometry
            from rigid_dynamics.wheelset.layout import new_parameters

            par = new_parameters()
            par["z_ref_m"], par["nominal_radius_m"] = self.z_ref, self.r0
            if self.irregularities is not None:
                irregularity_parameters(par, self.irregularities, self._irr_sides, self.r0)
            self._packed = (par, table_geometry(self))
        return self._packed

    def patches(self, centre_m, yaw_rad, roll_rad, spin_rad=0.0) -> PatchSet:
        """The candidates at a pose by the compiled look-up of the dynamics (compiled_tables._table_geometry:
        bilinear in (theta, y), q = q_ref + (z - z_ref) dq/dz, a merged second candidate dropped, the
        running-direction irregularities added by compiled_tables._irregularity).
        """
        from rigid_dynamics.wheelset import layout as lay
        from rigid_dynamics.wheelset.compiled_tables import table_candidates

        par, geometry = self._compiled()
        sides = np.asarray(self.side, np.int64)
        y = np.zeros(14)
        y[0:3] = np.asarray(centre_m, float)[:3]
        y[3], y[4], y[5] = yaw_rad, roll_rad, spin_rad
        cg = np.empty((len(sides), lay.N_GEO))
        table_candidates(y, par, geometry, sides, cg)
        return PatchSet(
            side=self.side,
            slot=self.slot,
            point_m=y[0:3] + cg[:, lay.G_LEVER : lay.G_LEVER + 3],
            normal=cg[:, lay.G_NORMAL : lay.G_NORMAL + 3].copy(),
            curvature_long_1_per_m=cg[:, lay.G_CURVATURE_LONG].copy(),
            curvature_lat_1_per_m=cg[:, lay.G_CURVATURE_LAT].copy(),
            approach_m=cg[:, lay.G_APPROACH].copy(),
            rolling_radius_m=cg[:, lay.G_ROLLING_RADIUS].copy(),
            contact_angle_rad=cg[:, lay.G_CONTACT_ANGLE].copy(),
            wheel_lateral_m=cg[:, lay.G_WHEEL_LATERAL].copy(),
        )
