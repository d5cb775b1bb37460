"""The Python side of the compiled code's one callback boundary (compiled_rhs._external): :class:`PatchCallback`
solves one patch of the loop with a contact model that is not compiled (bem, fea, user models; BEM for ``auto``)
and answers with a compiled_rhs.CallbackOutcome.
"""

from __future__ import annotations

import math
import time

import numpy as np

from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.wheelset.compiled_rhs import CallbackOutcome
from rigid_dynamics.wheelset.formed_patches import (
    PatchFormer,
    candidate_forces,
    frame_map,
    own_quantities,
    transported_creepage,
)
from rigid_dynamics.wheelset.layout import NOT_FORMED, NOT_MAPPED, PATCH_ELLIPSE, PATCH_SAMPLED
from rigid_dynamics.wheelset.providers import SIDES


class PatchCallback:
    """The Python side of the compiled code's one callback boundary (compiled_rhs._external): a contact model that is
    not compiled (bem, fea, user models; BEM for ``auto``) solves one patch from its geometry and creepages.

    The geometry is the quadric of the compiled candidate (curvatures, approach, contact point and frame, rolling
    radius, contact angle), or the provider's (``geometries``, candidate index -> ContactGeometry; set per
    right-hand side by WheelsetModel for providers evaluated in Python). With ``surfaces`` (a WheelsetTrack, or a
    callable building it once on first use) a model that solves a gap (bem, fea, models declaring
    ``solves_undeformed_distance``) gets the undeformed distance sampled from the real surfaces at the pose the
    patch carries (search.patch_undeformed_distance: the static wheelset search's own sampling, with the box fitted
    to the rigid overlap, so the element size of a solver that fills the box follows the patch), unless the
    provider gave one. The side's patches are formed as the static wheelset case forms them (``patches``
    "contact", the default: CONTACT's module 1, formed_patches.py: interpenetration regions joined or split, each
    patch solved in the plane of its weighted reference point, the forces returned in the candidate's frame and the
    patch's own quantities beside them for the record: CallbackOutcome.own) or
    (``patches`` "search", and on an elastic track) each candidate on its own plane at its deepest point
    (search.patch_undeformed_distance); ``patches`` "auto" (auto's BEM rung: the other candidates keep their own
    rungs) forms the patch as "contact" when it holds the candidate's region alone, else samples the candidate on
    its own plane as "search". On an elastic track (``elastic``) the pose is moved along the track's
    vertical by the rail displacement under the wheel that the candidate's approach implies (one correction: the
    sampled approach equals the candidate's to second order; the rail's lateral displacement is not sampled
    separately).

    BEM in the loop (``warm_start``, default True): each candidate (side, slot) keeps a bem.BemWarmStart, the
    last solve on each grid starting the next one on the same grid; a sampled patch is solved on square elements
    of a size chosen from a ladder (powers of 2^(1/4)) to give about ``BEM_ELEMENTS``^2 elements over the
    patch's potential area, kept while the size the box asks for stays within one step of it (:data:`LADDER_STEP`),
    so the grid and its influence numbers repeat from step to step.
    ``calls`` and ``seconds`` count the solves; ``message`` holds the last failure.
    """

    warm_start = True
    """Class default of the BEM warm start (benchmarks/bench_bem_loop_sampled.py switches it off to measure it)."""

    def __init__(self, model, options, material, surfaces=None, elastic=False):
        self.model = model
        self.options = options
        self.material = material
        self.geometries: dict = {}
        self.calls = 0
        self.seconds = 0.0
        self.message = ""
        self._surfaces = surfaces
        self.elastic = bool(elastic)
        self.sample = surfaces is not None and _solves_gap(model)
        self.bem = getattr(model, "name", "") == "bem"
        self.warm: dict = {}
        self.sizes: dict = {}
        self.sampling_seconds = 0.0
        self.patches = "contact"
        self.former = None
        self.reuse = None  # auto: (its anchor store, tolerance level, enabled), set by WheelsetModel
        self.grid_error = {"estimated": 0, "not_estimated": 0, "above_tolerance": 0, "largest_force": 0.0,
                           "largest": 0.0, "tolerance": None, "t_s": None}  # fmt: skip

    @property
    def surfaces(self):
        """The WheelsetTrack the patches are sampled from (built on first use when given as a callable)."""
        if callable(self._surfaces) and not hasattr(self._surfaces, "wheels"):
            self._surfaces = self._surfaces()
        return self._surfaces

    def stats(self) -> dict:
        """What the callback did over the run (SimulationResult.callback_stats): solves and seconds, the seconds
        spent sampling patches, whether patches were sampled and the BEM warm start's counts (:meth:`warm_counts`).
        """
        return {
            "model": getattr(self.model, "name", str(self.model)),
            "solves": int(self.calls),
            "seconds": float(self.seconds),
            "sampled_patches": bool(self.sample),
            "sampling_seconds": float(self.sampling_seconds),
            "bem_warm_start": bool(self.bem and self.warm_start),
            **({"bem": self.warm_counts(), "bem_grid_error": dict(self.grid_error)} if self.bem else {}),
            # another callback model that states its grid error per solve (kpec through "formed" patches)
            **({"grid_error": dict(self.grid_error)} if not self.bem and self.grid_error["estimated"] else {}),
            **({"auto_reuse": self.reuse_stats()} if self.reuse is not None else {}),
        }

    def reuse_stats(self) -> dict:
        """``auto``'s reuse of its BEM patches over the run (auto_reuse.reuse_stats of the run's store; ``enabled``
        False when the scene switched it off).
        """
        from rigid_dynamics.wheelset.auto_reuse import reuse_stats

        store, tolerance, enabled = self.reuse
        return {"enabled": bool(enabled), **reuse_stats(store, tolerance)}

    def _record_grid_error(self, result, t_s: float) -> None:
        """Keep the run's largest grid-error estimate of a model that states one per solve (``extra["grid_error"]``:
        the BEM's bem.model.grid_error_estimate, KPEC's the same on its own companion grids) of the forces (normal
        and creep force, relative as the model states them) and of all its quantities, and count the solves above
        their ``grid_tolerance`` and those not estimated (summary.json ``discretisation_errors``). A user model's
        ``grid_error`` in another form counts as not estimated.
        """
        grid = (result.extra or {}).get("grid_error")
        if not isinstance(grid, dict) or result.status == "no-contact":
            return
        rel = grid.get("relative")
        stated = isinstance(rel, dict) and "normal_force_N" in rel and "creep_force_N" in rel
        if not (grid.get("estimated") and stated and "tolerance" in grid and "largest_relative" in grid):
            self.grid_error["not_estimated"] += 1
            return
        record = self.grid_error
        record["estimated"] += 1
        record["tolerance"] = grid["tolerance"]
        force = max(rel["normal_force_N"], rel["creep_force_N"])
        if force > record["largest_force"]:
            record["largest_force"], record["t_s"] = float(force), float(t_s)
        record["largest"] = max(record["largest"], float(grid["largest_relative"]))
        record["above_tolerance"] += int(grid["largest_relative"] > grid["tolerance"])

    def warm_counts(self) -> dict:
        """BEM solves, warm-started solves and NORM + TANG iterations over the run (all candidates)."""
        totals = {"solves": 0, "warm_solves": 0, "iterations": 0}
        for warm in self.warm.values():
            totals["solves"] += warm.solves
            totals["warm_solves"] += warm.warm_solves
            totals["iterations"] += warm.iterations
        return totals

    def solve(self, patch):
        """N, T_x, T_y, M_z, a, b and a status (0 solved, 1 failed: :attr:`message`) of one patch of the loop
        (compiled_rhs.CallbackPatch) by the model.
        """
        start = time.perf_counter()
        self.calls += 1
        t = patch.t_s
        target = False
        try:
            creepage = Creepage(
                float(patch.creepage_long),
                float(patch.creepage_lat),
                float(patch.spin_creepage_1_per_m),
                float(patch.rolling_speed_m_per_s),
            )
            geometry = self.geometries.get(patch.candidate)
            if self.sample and (geometry is None or geometry.undeformed is None):
                target = self._formed(patch) if self.patches in ("contact", "auto") and not self.elastic else False
                if self.patches == "auto" and (target is None or (target is not False and len(target.regions) > 1)):
                    target = False  # auto: a patch joining other candidates' regions: the candidate on its own plane
                if target is None:  # its region is in a patch served by a deeper candidate
                    return _JOINED
                if target is False:
                    geometry = self._sampled(patch, geometry)
                else:
                    geometry = target.geometry
                    creepage = transported_creepage(patch, creepage, self._axle(patch), target)
            elif geometry is None:
                frame = np.array([patch.e_x, patch.e_y, patch.normal], float).T
                geometry = ContactGeometry(
                    curvature_long_1_per_m=float(patch.curvature_long_1_per_m),
                    curvature_lat_1_per_m=float(patch.curvature_lat_1_per_m),
                    approach_m=float(patch.approach_m),
                    side=SIDES[int(patch.side)],
                    point_m=np.array(patch.point_m, float),
                    frame=frame,
                    contact_angle_rad=float(patch.contact_angle_rad),
                    rolling_radius_m=float(patch.rolling_radius_m),
                )
            result = self._solve(patch, geometry, creepage)
        except Exception as exc:  # noqa: BLE001 (any failure of a user model is reported as the run's status)
            self.message = f"contact model {getattr(self.model, 'name', self.model)!r} raised at t = {t:.6g} s: {exc}"
            return _FAILED
        finally:
            self.seconds += time.perf_counter() - start
        self._record_grid_error(result, t)
        if not result.success and result.status != "no-contact":
            self.message = f"contact model {result.method!r} failed at t = {t:.6g} s: {result.status}: {result.message}"
            return _FAILED
        sampled = geometry.undeformed is not None
        residual = np.nan
        if sampled:
            from rigid_dynamics.contact.search import ellipticity_error

            residual = ellipticity_error(
                geometry.undeformed, geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m,
                geometry.ellipse_angle_rad, geometry.approach_m,
            )  # fmt: skip
        forces = (result.normal_force_N, result.creep_force_long_N, result.creep_force_lat_N, result.spin_moment_Nm)
        own, mapped = NOT_FORMED, NOT_MAPPED
        if target is not False:  # recorded in its own frame; applied in the candidate's
            own = own_quantities(target, result, creepage)
            mapped = frame_map(patch, target)
            if result.status != "no-contact":
                forces = candidate_forces(patch, target, result)
        return CallbackOutcome(
            *(float(v or 0.0) for v in forces),
            _number(result.semi_axis_long_m),
            _number(result.semi_axis_lat_m),
            _number(result.contact_area_m2),
            _number(result.max_pressure_Pa),
            PATCH_SAMPLED if sampled else PATCH_ELLIPSE,
            float(residual),
            0,
            own,
            mapped,
        )

    def _formed(self, patch):
        """The formed patch (formed_patches.PatchFormer.served) this candidate serves at its pose."""
        from rigid_dynamics.contact.search import WheelsetPose

        start = time.perf_counter()
        if self.former is None:
            self.former = PatchFormer(self.surfaces)
        pose = WheelsetPose(*(float(v) for v in patch.centre_m), float(patch.yaw_rad), float(patch.roll_rad),
                            float(patch.spin_rad))  # fmt: skip
        served = self.former.served(SIDES[int(patch.side)], pose, patch.point_m)
        self.sampling_seconds += time.perf_counter() - start
        return served

    @staticmethod
    def _axle(patch) -> np.ndarray:
        from rigid_dynamics.kinematics import wheelset_rotation

        return wheelset_rotation(float(patch.yaw_rad), float(patch.roll_rad), float(patch.spin_rad))[:, 1]

    def _sampled(self, patch, given):
        """The patch's ContactGeometry with the undeformed distance sampled from the real surfaces at its pose."""
        from dataclasses import replace

        from rigid_dynamics.contact.search import WheelsetPose, patch_undeformed_distance

        start = time.perf_counter()
        side = SIDES[int(patch.side)]
        frame = np.array([patch.e_x, patch.e_y, patch.normal], float).T
        if given is None:
            given = ContactGeometry(
                curvature_long_1_per_m=float(patch.curvature_long_1_per_m),
                curvature_lat_1_per_m=float(patch.curvature_lat_1_per_m),
                approach_m=float(patch.approach_m), side=side, point_m=np.array(patch.point_m, float), frame=frame,
                contact_angle_rad=float(patch.contact_angle_rad), rolling_radius_m=float(patch.rolling_radius_m),
            )  # fmt: skip
        wheel, rail = self.surfaces.fast[side]
        centre = np.array(patch.centre_m, float)
        curvatures = (given.curvature_long_1_per_m, given.curvature_lat_1_per_m)
        q = float(patch.approach_m)

        def field_at(c):
            pose = WheelsetPose(*(float(v) for v in c), float(patch.yaw_rad), float(patch.roll_rad),
                                float(patch.spin_rad))  # fmt: skip
            return patch_undeformed_distance(
                wheel, rail, pose, side, given.point_m, given.frame, patch.wheel_lateral_m, q, curvatures
            )

        field = field_at(centre)
        if self.elastic:
            finite = field.distance_m[np.isfinite(field.distance_m)]
            sampled_q = -float(finite.min()) if finite.size else q
            vertical = abs(float(given.frame[2, 2]))
            if vertical > 0.1 and abs(sampled_q - q) > 1e-9:
                centre[2] -= (sampled_q - q) / vertical  # the rail lowered by w: the wheelset raised by w
                field = field_at(centre)
        self.sampling_seconds += time.perf_counter() - start
        return replace(given, undeformed=field, is_elliptic=False)

    def _solve(self, patch, geometry, creepage):
        """The model's solve; BEM with its warm start and, on a sampled patch, the element-size ladder."""
        if not self.bem:
            return self.model.solve(geometry, creepage, self.material, options=self.options)
        from rigid_dynamics.contact.bem.model import BemWarmStart

        key = (int(patch.side), int(patch.candidate))
        warm = self.warm.setdefault(key, BemWarmStart(enabled=self.warm_start))
        options = self.options
        named = options and any(k in options for k in ("nx", "ny", "element_size_m", "dx_m", "dy_m"))
        if geometry.undeformed is not None and not named:
            size = self.sizes.get(key)
            wanted = ladder_element_size(geometry.undeformed)
            if size is None or abs(math.log(size / wanted, LADDER_STEP)) > 1.0 + 1e-6:
                size = wanted
                self.sizes[key] = size
            options = dict(options or {}, element_size_m=size)
        return self.model.solve(geometry, creepage, self.material, options=options, warm_start=warm)


def ladder_element_size(undeformed) -> float:
    """The BEM element size of a sampled patch in the loop: the sampled box's geometric-mean side over
    BEM_ELEMENTS, halved (the box is about twice the contact's extent), rounded to the ladder 2^(k/4) m.
    """
    extent = math.sqrt(float(np.ptp(undeformed.x_m)) * float(np.ptp(undeformed.y_m)))
    return 0.5 * 2.0 ** (round(4.0 * math.log2(extent / BEM_ELEMENTS)) / 4.0)


LADDER_STEP = 2.0**0.25
"""The ladder's ratio between neighbouring element sizes. A patch keeps its element size while the size its box
asks for is at most one step away (the kept size at most one step coarser or finer than asked: no flapping between
two sizes at a rung's boundary). The window was a factor 2 each way until session 23, so that two runs through the
same states could solve a patch on elements up to twice as large or small, depending on the path. Measured on the
wheel flat's impact (benchmarks/results/auto_vs_bem.md, auto without reuse against always-BEM at the same states):
9.9 % apart in the creep force (bench definition) with the factor-2 window, 9.5 % with one step. What remains is
the grid's own error at these patches (creep forces near 0.01 mu N; the BEM's estimate there is up to 0.49 of
that scale): one step apart moves it that much."""

BEM_ELEMENTS = 40
"""Elements of the ladder's size across the sampled box (geometric mean of its sides), before the halving: the box
is about twice the contact's extent, so about BEM_ELEMENTS^2 elements cover the BEM's potential area."""


def _solves_gap(model) -> bool:
    """Whether a contact model solves an undeformed distance (bem, fea, or declared ``solves_undeformed_distance``): the
    static wheelset case's rule (wheelset_case._solves_undeformed_distance), so both form patches for the same models.
    """
    from rigid_dynamics.contact.wheelset_case import _solves_undeformed_distance

    return _solves_undeformed_distance(model)


_FAILED = CallbackOutcome(0.0, 0.0, 0.0, 0.0, np.nan, np.nan, np.nan, np.nan, PATCH_ELLIPSE, np.nan, 1, NOT_FORMED)
"""The callback's answer for a patch whose contact model failed (its message kept in PatchCallback.message)."""
_JOINED = CallbackOutcome(0.0, 0.0, 0.0, 0.0, np.nan, np.nan, np.nan, np.nan, PATCH_SAMPLED, np.nan, 0, NOT_FORMED)
"""The answer for a candidate whose interpenetration region is joined into a patch a deeper candidate serves."""


def _number(value) -> float:
    """A result's optional number as a float (NaN when the model gives none)."""
    return np.nan if value is None else float(value)
