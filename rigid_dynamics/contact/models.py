"""The analytic contact models of the registry: hertz, linear, vermeulen-johnson, fastsim, auto.

Each class implements :class:`rigid_dynamics.contact.registry.ContactModel`::

    solve(geometry, creepage, material, *, normal_force_N=None, options=None) -> ContactResult

Normal problem (all models): Hertz (:mod:`.hertz`, seed eq 32-38) for h = A x^2 + B y^2 - q with
A = ``geometry.curvature_long_1_per_m``, B = ``geometry.curvature_lat_1_per_m``. Force control
uses ``normal_force_N``; approach control uses ``geometry.approach_m`` (q <= 0: no contact,
``success=True``, ``status="no-contact"``, all forces 0). The ellipse is assumed aligned with the
rolling direction (semi-axis a along x); a non-zero ``geometry.ellipse_angle_rad`` is reported in
``extra["ellipse_angle_rad"]`` and the message but not otherwise used.

Tangential problem: ``hertz`` none (creep forces 0.0); ``linear`` Kalker's linear theory
(:mod:`.linear`, eq 50-52); ``vermeulen-johnson`` (:mod:`.vermeulen_johnson`, eq 53-58 with the
cube; no spin moment: None); ``fastsim`` (:mod:`.fastsim`). Forces act on the wheel, contact frame.

``auto`` picks, per patch, the cheapest rung whose error was measured below the option ``tolerance`` (default
0.05) on patches like this one (:mod:`rigid_dynamics.contact.auto`): the patch's features (saturation
w' = T_lin/(3 mu N), spin share, ellipticity residual of the sampled undeformed distance, curvature change across
the patch, nearness of a second patch) against the thresholds derived from the bench and a creep sweep
(``data/auto_thresholds.json``, with the bench run that produced them); the first of linear, vermeulen-johnson,
fastsim (at its configured grid) whose measured box holds the features, else ``bem`` (imported lazily; if it
cannot be imported the result has ``success=False``, ``status="unavailable"``). A cheaper rung whose own result
is not ok (e.g. FASTSIM above the friction bound) is replaced by ``bem`` too.

The result of ``auto`` is the chosen model's result (``method`` is its name) with ``extra`` keys
``selected_model``, ``selection_reason`` (features, thresholds, the rejected rungs), ``auto_features``,
``auto_rung`` (e.g. "fastsim 20x20"), ``auto_level`` (the tolerance level used), ``auto_deciding_feature`` and
``auto_deciding_threshold`` (the threshold that decided) and ``auto_thresholds`` (the identity of the data).

:func:`solve_batch` is the vectorised entry point for many patches at once (the dynamics):
Hertz + one law (or the auto choice per patch) on arrays, returning :class:`AnalyticBatch`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.hertz import HertzBatch, hertz_solve_batch
from rigid_dynamics.contact.options import Option, OptionError, declare, validate_options
from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

TRACTION_BOUNDS = ("elliptic", "parabolic")
FLEXIBILITIES = ("single", "three", "three-unblended")
"""FASTSIM's choices, as rigid_dynamics.contact.fastsim declares them (tests/test_import_hygiene.py checks that they
agree): written here so that this module, and a command using Hertz, linear or Vermeulen-Johnson, does not import
the FASTSIM kernels. The compiled models' modules are imported inside the functions that use them."""


def _options(options: Mapping | None, declared: Mapping[str, Option], model: str) -> dict:
    """The options merged with the declared defaults (OptionError, a ValueError, naming a bad one)."""
    return validate_options(declared, options, model)


FRICTION_BOUND_TOLERANCE = 0.01
"""Relative excess of |F_t| over mu N above which a saturating model's result is not ok.

Coulomb's law bounds every patch's creep force by mu N. A saturating law meets the bound up to its
discretisation: FASTSIM's strip sums overshoot it at full slip by 0.5 % at 20 x 20 and by 19 % at 3 x 2
(the discretised pressure does not integrate to N exactly); Vermeulen-Johnson meets it exactly.
"""


def _friction_bound(result: ContactResult, material: Material, saturating: bool) -> ContactResult:
    """Check |F_t| = hypot(F_x, F_y) against mu N; record the ratio and flag a result that breaks the bound.

    A saturating law (FASTSIM) above mu N by more than FRICTION_BOUND_TOLERANCE: ``success`` False,
    status "friction-bound-exceeded" (its discretisation is too coarse for the patch). The linear theory
    (full adhesion, no bound) above mu N: status "beyond-friction-limit", ``success`` True: the number is
    the linear theory's, but the theory is outside its range (use a saturating model).
    """
    fx, fy, normal = result.creep_force_long_N, result.creep_force_lat_N, result.normal_force_N
    if fx is None or fy is None or not normal or normal <= 0 or result.status != "ok":
        return result
    traction = math.hypot(fx, fy)
    bound = material.friction_coefficient * normal
    ratio = traction / bound if bound > 0 else (math.inf if traction > 0 else 0.0)
    result.extra["friction_bound_ratio"] = ratio
    if saturating and ratio > 1.0 + FRICTION_BOUND_TOLERANCE:
        return dataclasses.replace(
            result,
            success=False,
            status="friction-bound-exceeded",
            message=f"|F_t| = {traction:.4g} N exceeds mu N = {bound:.4g} N by {100 * (ratio - 1):.3g} % "
            f"(above {100 * FRICTION_BOUND_TOLERANCE:g} %): the discretisation is too coarse for this patch",
        )
    if not saturating and ratio > 1.0:
        return dataclasses.replace(
            result,
            status="beyond-friction-limit",
            message=f"|F_t| = {traction:.4g} N exceeds mu N = {bound:.4g} N ({ratio:.3g} x): the linear theory "
            "(full adhesion) is outside its range here; use a saturating model (vermeulen-johnson, fastsim, bem)",
        )
    return result


def _hertz(
    geometry: ContactGeometry, material: Material, normal_force_N: float | None
) -> tuple[HertzBatch | None, str]:
    """Hertz patch, or (None, reason) when there is no contact."""
    if normal_force_N is not None:
        if not math.isfinite(normal_force_N):
            raise ValueError(f"normal_force_N = {normal_force_N!r}: expected a finite number")
        if normal_force_N <= 0:
            return None, f"normal force {normal_force_N:g} N <= 0: no contact"
        load = {"normal_force_N": normal_force_N}
    else:
        if geometry.approach_m <= 0:
            return None, f"approach {geometry.approach_m:g} m <= 0: no contact"
        load = {"approach_m": geometry.approach_m}
    sol = hertz_solve_batch(
        geometry.curvature_long_1_per_m,
        geometry.curvature_lat_1_per_m,
        shear_modulus_Pa=material.shear_modulus_Pa,
        poisson_ratio=material.poisson_ratio,
        **load,
    )
    return sol, ""


def _base_result(name, geometry, creepage, hertz: HertzBatch | None, reason: str, start: float, **kw) -> ContactResult:
    extra = {"ellipse_angle_rad": float(geometry.ellipse_angle_rad)}
    note = ""
    if abs(math.sin(2.0 * geometry.ellipse_angle_rad)) > 1e-9:
        note = " (ellipse_angle_rad != 0: the ellipse is treated as aligned with the rolling direction)"
    if hertz is None:
        return ContactResult.no_contact(
            name,
            reason,
            creepage,
            approach_m=max(geometry.approach_m, 0.0) if reason.startswith("approach") else 0.0,
            wall_time_s=time.perf_counter() - start,
            semi_axis_long_m=0.0,
            semi_axis_lat_m=0.0,
            extra=extra,
        )
    a = float(hertz.semi_axis_long_m)
    b = float(hertz.semi_axis_lat_m)
    converged = bool(hertz.converged)
    fields = {
        "method": name,
        "success": converged,
        "status": "ok" if converged else "not-converged",
        "message": ("solved" if converged else "Hertz axial-function inversion did not converge") + note,
        "normal_force_N": float(hertz.normal_force_N),
        "max_pressure_Pa": float(hertz.max_pressure_Pa),
        "semi_axis_long_m": a,
        "semi_axis_lat_m": b,
        "contact_area_m2": math.pi * a * b,
        "approach_m": float(hertz.approach_m),
        "creepage": creepage,
        "iterations": int(hertz.iterations),
        "extra": extra,
    }
    fields.update(kw)
    fields["wall_time_s"] = time.perf_counter() - start
    return ContactResult(**fields)


class HertzianModel:
    """The registry's Hertzian models in one frame: options, the Hertz normal problem, then one tangential law.

    A subclass sets ``name``, ``description``, ``OPTIONS`` and ``SATURATING`` (True: a saturating law, False:
    full adhesion, None: no creep forces, so no friction-bound check; see :func:`_friction_bound`) and
    implements ``tangential(hertz, creepage, material, opts) -> (forces, extra)``: ``forces`` the keyword
    fields of :class:`~.types.ContactResult` it sets (creep forces, spin moment, fields), ``extra`` what it
    adds to ``result.extra``. Forces act on the wheel, contact frame.

    ``compiled_law``: the law the compiled dynamics loop runs in place of :meth:`solve` (a name of
    wheelset.layout.LAW_CODES: the same law on the same Hertz patch), None for a model the loop hands each patch to
    through its callback. A subclass keeps its parent's law; a subclass that changes the tangential law sets None.
    """

    name = ""
    description = ""
    compiled_law: str | None = None
    OPTIONS: dict = declare()
    SATURATING: bool | None = None
    MODELS_FRICTION_LAW = False
    """True: :meth:`tangential` applies the material's friction law itself (FASTSIM, element-wise); False: the
    law is reduced to one Coulomb coefficient per patch first (:func:`coulomb_for_patch`)."""

    def tangential(self, hertz: HertzBatch, creepage: Creepage, material: Material, opts: dict):
        raise NotImplementedError(f"{type(self).__name__} defines no tangential law")

    def solve(
        self,
        geometry: ContactGeometry,
        creepage: Creepage,
        material: Material,
        *,
        normal_force_N: float | None = None,
        options: Mapping | None = None,
    ) -> ContactResult:
        start = time.perf_counter()
        opts = _options(options, self.OPTIONS, self.name)
        hertz, reason = _hertz(geometry, material, normal_force_N)
        if hertz is None:
            return _base_result(self.name, geometry, creepage, None, reason, start)
        note = None
        if self.SATURATING is not None and not self.MODELS_FRICTION_LAW:
            material, note = coulomb_for_patch(geometry, creepage, material)
        forces, extra = self.tangential(hertz, creepage, material, opts)
        result = _base_result(self.name, geometry, creepage, hertz, reason, start, **forces)
        result.extra.update(extra)
        if note is not None:
            result = dataclasses.replace(result, message=f"{result.message}; {note}")
            result.extra["friction_coefficient_used"] = material.friction_coefficient
        if self.SATURATING is None:
            return result
        return _friction_bound(result, material, saturating=self.SATURATING)


def _patch_place(geometry: ContactGeometry, material: Material) -> float:
    """The place of a patch's reference point in the variable of the material's friction law (the contact angle,
    the rail-profile lateral coordinate of the contact point, or the track distance; as the BEM's for a patch
    without an element-wise place). Raises ValueError when the geometry has no such place.
    """
    varies_with = material.friction.varies_with
    value = {
        "surface_inclination": geometry.contact_angle_rad,
        "rail_lateral": geometry.contact_point_rail_m[0],
        "track_distance": geometry.track_distance_m,
    }[varies_with]
    if not math.isfinite(value):
        raise ValueError(f"friction varies_with = {varies_with!r}: the patch has no such place ({value!r})")
    return float(value)


def coulomb_for_patch(geometry: ContactGeometry, creepage: Creepage, material: Material) -> tuple[Material, str | None]:
    """The Coulomb material a rung without an element-wise friction law solves a patch with, and the sentence that
    says so (None when the material is Coulomb everywhere already).

    A law varying in place is taken at the patch's reference point (:func:`_patch_place`); a falling law at the
    patch's mean rigid slip velocity V sqrt(xi^2 + eta^2) (the spin's rigid slip averages to zero over the patch),
    as the compiled loop's analytic laws take it (``wheelset.compiled_laws.mean_slip_coefficient``). Exact for a
    Coulomb law that varies in place and for a falling law in full slip; in partial slip the slipping elements move
    slower than the rigid slip, so the coefficient is the law's at a higher speed than theirs (FASTSIM and the BEM
    bound every element at its own slip velocity).
    """
    law = material.friction
    if law is None or (law.is_coulomb and not law.varies):
        return material, None
    from rigid_dynamics.contact.fastsim import law_at_place

    one = law_at_place(law, _patch_place(geometry, material)) if law.varies else law
    if one.is_coulomb:
        mu = one.laws[0].static
        note = f"friction at the patch's reference point: Coulomb mu = {mu:.4g}"
    else:
        speed = creepage.rolling_speed_m_per_s * math.hypot(creepage.longitudinal, creepage.lateral)
        mu = one.coefficient(speed)
        note = (
            f"falling friction ({one.laws[0].law}) at the patch's mean rigid slip velocity {speed:.4g} m/s: mu = "
            f"{mu:.4g} (this rung applies one coefficient per patch; fastsim and bem bound each element at its own "
            "slip velocity)"
        )
    return Material(material.shear_modulus_Pa, material.poisson_ratio, mu), note


class HertzModel(HertzianModel):
    """Hertz normal contact only (seed eq 32-38); creep forces and spin moment 0.0."""

    name = "hertz"
    compiled_law = "hertz"
    description = "Hertz normal contact only; creep forces 0"

    def tangential(self, hertz, creepage, material, opts):
        return {"creep_force_long_N": 0.0, "creep_force_lat_N": 0.0, "spin_moment_Nm": 0.0}, {}


def _linear_forces(hertz, creepage, material):
    """Kalker's linear-theory (Fx, Fy, Mz) on the Hertz ellipse of one patch (eq 50-52)."""
    from rigid_dynamics.contact.linear import linear_creep_forces

    return linear_creep_forces(
        hertz.semi_axis_long_m,
        hertz.semi_axis_lat_m,
        creepage.longitudinal,
        creepage.lateral,
        creepage.spin_1_per_m,
        shear_modulus_Pa=material.shear_modulus_Pa,
        poisson_ratio=material.poisson_ratio,
    )


class LinearModel(HertzianModel):
    """Hertz + Kalker's linear theory (full adhesion; seed eq 50-52)."""

    name = "linear"
    compiled_law = "linear"
    description = "Hertz + Kalker's linear theory (full adhesion)"
    SATURATING = False

    def tangential(self, hertz, creepage, material, opts):
        fx, fy, mz = _linear_forces(hertz, creepage, material)
        return {"creep_force_long_N": float(fx), "creep_force_lat_N": float(fy), "spin_moment_Nm": float(mz)}, {}


class VermeulenJohnsonModel(HertzianModel):
    """Hertz + linear theory saturated by Vermeulen-Johnson's cubic law (seed eq 53-58, cube)."""

    name = "vermeulen-johnson"
    compiled_law = "vermeulen-johnson"
    description = "Hertz + Vermeulen-Johnson saturation (no spin)"
    SATURATING = True

    def tangential(self, hertz, creepage, material, opts):
        from rigid_dynamics.contact.vermeulen_johnson import vermeulen_johnson_saturation

        tx, ty, _ = _linear_forces(hertz, creepage, material)
        fx, fy = vermeulen_johnson_saturation(tx, ty, hertz.normal_force_N, material.friction_coefficient)
        return {"creep_force_long_N": float(fx), "creep_force_lat_N": float(fy), "spin_moment_Nm": None}, {}


class FastsimModel(HertzianModel):
    """Hertz + Kalker's FASTSIM (simplified theory), with traction and slip fields.

    Options: ``nx``, ``ny`` (elements per strip, strips; default 20 x 20), ``traction_bound``
    ("elliptic" | "parabolic"), ``flexibility`` ("single" | "three" | "three-unblended"),
    ``fields`` (bool, return :class:`~rigid_dynamics.contact.types.ContactFields`), ``tolerance`` (accepted
    relative creep-force error of the grid, default 0.05).

    Discretisation error: every solve is repeated on the grid of half the elements each way (a quarter of the
    cost); ``extra["discretisation_error_estimate"]`` = |F(nx, ny) - F(nx/2, ny/2)| / |F(nx, ny)| (creep-force
    vectors). Measured against a 200 x 200 grid (tests/test_hardening_results.py: longitudinal creepage small,
    mid and saturated, lateral with spin, pure spin; square grids 2-80): true error / estimate 0.1-1.0 for the
    creepage cases, 0.6-2.4 for pure spin (underestimated on coarse grids, where both are above 20 %). At the
    tolerances 0.5 %, 1 % and 5 % no measured grid whose true error is above the tolerance has an estimate below it.
    A result whose estimate exceeds ``tolerance`` has status ``warning`` (its numbers are there, but the grid is
    too coarse for the asked accuracy): e.g. 2 x 2 (estimate 0.5-0.8, true error 0.2-0.5), or pure spin at
    20 x 20 (estimate 0.22, true 0.26).
    """

    name = "fastsim"
    compiled_law = "fastsim"
    MODELS_FRICTION_LAW = True
    description = "Hertz + Kalker's FASTSIM (simplified theory)"
    SATURATING = True
    OPTIONS: dict = declare(
        Option("nx", int, 20, "elements per strip (along the rolling direction)", minimum=1, maximum=1000),
        Option("ny", int, 20, "strips across the patch", minimum=1, maximum=1000),
        Option("traction_bound", str, "elliptic", "shape of the traction bound mu p", choices=TRACTION_BOUNDS),
        Option("flexibility", str, "three", "Kalker's flexibility: one or three (L1, L2, L3)", choices=FLEXIBILITIES),
        Option("fields", bool, True, "return the traction and slip fields"),
        Option("tolerance", float, 0.05, "accepted relative creep-force error of the grid (estimated on half the "
               "grid)", minimum=0, exclusive_minimum=True),
    )  # fmt: skip
    OPTIONS_DEFAULTS = {"nx": 20, "ny": 20}

    def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None) -> ContactResult:
        if material.friction is not None and material.friction.varies:  # the law at the patch's reference point
            from rigid_dynamics.contact.fastsim import law_at_place

            material = material.with_friction(law_at_place(material.friction, _patch_place(geometry, material)))
        result = super().solve(geometry, creepage, material, normal_force_N=normal_force_N, options=options)
        return grid_warning(result, "FASTSIM's grid", "against the grid of half the elements")

    def tangential(self, hertz, creepage, material, opts):
        from rigid_dynamics.contact.fastsim import fastsim_fields

        friction = material.friction if material.friction is not None else material.friction_coefficient

        def run(nx, ny):  # the grid asked for and its companion of half the elements
            return fastsim_fields(
                float(hertz.semi_axis_long_m),
                float(hertz.semi_axis_lat_m),
                float(hertz.normal_force_N),
                creepage.longitudinal,
                creepage.lateral,
                creepage.spin_1_per_m,
                shear_modulus_Pa=material.shear_modulus_Pa,
                poisson_ratio=material.poisson_ratio,
                friction_coefficient=friction,
                rolling_speed_m_per_s=creepage.rolling_speed_m_per_s,
                nx=nx,
                ny=ny,
                traction_bound=opts["traction_bound"],
                flexibility=opts["flexibility"],
            )

        (fx, fy, mz, slip_fraction), fields = run(opts["nx"], opts["ny"])
        forces = {
            "creep_force_long_N": fx,
            "creep_force_lat_N": fy,
            "spin_moment_Nm": mz,
            "fields": fields if opts["fields"] else None,
        }
        (fx_half, fy_half, _, _), _ = run(max(1, opts["nx"] // 2), max(1, opts["ny"] // 2))
        size = math.hypot(fx, fy)
        estimate = math.hypot(fx - fx_half, fy - fy_half) / size if size > 0 else 0.0
        extra = {
            "discretisation_error_estimate": estimate if math.isfinite(estimate) else None,
            "tolerance": opts["tolerance"],
            "slip_fraction": slip_fraction,
            "nx": int(opts["nx"]),
            "ny": int(opts["ny"]),
            "traction_bound": opts["traction_bound"],
            "flexibility": opts["flexibility"],
        }
        return forces, extra


def grid_warning(result: ContactResult, grid: str, how: str) -> ContactResult:
    """``result`` with status ``warning`` when its ``extra["discretisation_error_estimate"]`` (relative creep-force
    error of the grid ``extra["nx"]`` x ``extra["ny"]``) exceeds ``extra["tolerance"]``; ``grid`` names the grid
    in the message ("FASTSIM's grid"), ``how`` says how the estimate was made.
    """
    estimate, tolerance = result.extra.get("discretisation_error_estimate"), result.extra.get("tolerance")
    if result.status == "ok" and estimate is not None and tolerance is not None and estimate > tolerance:
        return dataclasses.replace(
            result,
            status="warning",
            message=f"{result.message}; {grid} {result.extra['nx']} x {result.extra['ny']} has an estimated "
            f"creep-force error of {100 * estimate:.3g} % ({how}), above the tolerance {100 * tolerance:g} %: "
            "refine nx, ny",
        )
    return result


AUTO_CHOICES = ("linear", "vermeulen-johnson", "fastsim", "bem")
"""The models ``auto`` can choose."""


def _check_model_options(value: Mapping, key: str) -> None:
    """Validate auto's ``model_options``: a table per model ``auto`` can choose, each by that model's declaration."""
    from rigid_dynamics.contact.registry import model_options

    for name, options in value.items():
        if name not in AUTO_CHOICES:
            raise OptionError("auto", f"{key}.{name}", options, "a table named after one of " + ", ".join(AUTO_CHOICES))
        validate_options(model_options(name), options, name, prefix=f"{key}.{name}.")


def thresholds_identity(data: Mapping) -> str:
    """One line naming the thresholds data: when and from which bench run it was derived."""
    bench = data.get("sources", {}).get("bench", {})
    derived = data.get("derived", {})
    run = bench.get("csv") or bench.get("command", "?")
    return (
        f"derived {derived.get('date', '?')} at commit {str(derived.get('commit', '?'))[:12]} from the bench run "
        f"{run} ({bench.get('date', '?')}, commit {str(bench.get('commit', '?'))[:12]}) + creep sweep"
    )


class AutoModel:
    """The cheapest rung measured within ``tolerance`` on patches like this one (module docstring).

    Options: ``tolerance`` (relative force error, default 0.05; the thresholds of the largest measured level
    10/5/2/1 % not above it apply; below 1 %: bem) and ``model_options`` (a mapping name -> options passed to
    the chosen model, e.g. {"fastsim": {"nx": 40}, "bem": {"nx": 32, "ny": 32}}; FASTSIM's grid also selects
    the thresholds used for it).
    """

    name = "auto"
    compiled_law = "auto"
    description = "cheapest model meeting the tolerance for the patch"
    OPTIONS: dict = declare(
        Option("tolerance", float, 0.05, "accepted relative creep-force error", minimum=0, exclusive_minimum=True),
        Option(
            "model_options",
            dict,
            None,
            "options per model the choice may fall on, e.g. {fastsim = {nx = 40}}",
            allow_none=True,
            check=lambda value, key: _check_model_options(value, key),
        ),
    )

    def _choose(self, geometry, creepage, material, normal_force_N, opts):
        """(hertz, why, features, choice, thresholds' data); hertz None (and the rest None) without contact."""
        from rigid_dynamics.contact.auto import choose_rung, load_thresholds, patch_features

        hertz, why = _hertz(geometry, material, normal_force_N)
        if hertz is None:
            return hertz, why, None, None, None
        features = patch_features(geometry, creepage, material, hertz)
        fs_opts = {**FastsimModel.OPTIONS_DEFAULTS, **((opts["model_options"] or {}).get("fastsim") or {})}
        data = load_thresholds()
        choice = choose_rung(features, opts["tolerance"], fastsim_grid=(fs_opts["nx"], fs_opts["ny"]), data=data)
        return hertz, why, features, choice, data

    def chosen_model(self, geometry, creepage, material, *, normal_force_N=None, options=None) -> str:
        """The model :meth:`solve` would run for this patch ("hertz" without contact), without running it: the
        contact command warms up only that model's kernels (a chosen rung whose result is not ok falls back to bem
        inside the solve).
        """
        opts = _options(options, self.OPTIONS, self.name)
        hertz, _, _, choice, _ = self._choose(geometry, creepage, material, normal_force_N, opts)
        return "hertz" if hertz is None else choice["model"]

    def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None) -> ContactResult:
        start = time.perf_counter()
        opts = _options(options, self.OPTIONS, self.name)
        tol = opts["tolerance"]
        per_model = dict(opts["model_options"] or {})
        hertz, why, features, choice, data = self._choose(geometry, creepage, material, normal_force_N, opts)
        if hertz is None:
            result = _base_result(self.name, geometry, creepage, None, why, start)
            result.extra["selected_model"] = "hertz"
            return result
        record = {
            "selected_model": choice["model"],
            "selection_reason": choice["reason"],
            "auto_features": features,
            "auto_rung": choice["rung"],
            "auto_level": choice["level"],
            "auto_deciding_feature": choice["deciding_feature"],
            "auto_deciding_threshold": choice["deciding_threshold"],
            "auto_thresholds": thresholds_identity(data),
        }
        result = None
        if choice["model"] != "bem":
            model = {"linear": LinearModel, "vermeulen-johnson": VermeulenJohnsonModel, "fastsim": FastsimModel}[
                choice["model"]
            ]()
            result = model.solve(
                geometry, creepage, material, normal_force_N=normal_force_N, options=per_model.get(choice["model"])
            )
            if not result.success:
                record["selection_reason"] += f"; its result is not ok ({result.status}: {result.message}): bem instead"
                record["selected_model"] = record["auto_rung"] = "bem"
                result = None
        if result is None:
            try:
                from rigid_dynamics.contact.registry import get_model

                model = get_model("bem")
            except ImportError as exc:
                return ContactResult(
                    method=self.name,
                    success=False,
                    status="unavailable",
                    message=f"auto chose 'bem' ({record['selection_reason']}) but it cannot be imported: {exc}",
                    normal_force_N=0.0,
                    creepage=creepage,
                    wall_time_s=time.perf_counter() - start,
                    extra=record,
                )
            # the BEM's grid is held to auto's tolerance (a BEM grid coarser than that ends "warning")
            bem_options = {"grid_tolerance": tol, **(per_model.get("bem") or {})}
            result = model.solve(geometry, creepage, material, normal_force_N=normal_force_N, options=bem_options)
        result.extra.update(record)
        return dataclasses.replace(result, wall_time_s=time.perf_counter() - start)


@dataclass(frozen=True, eq=False)
class AnalyticBatch:
    """Results of :func:`solve_batch` for many elliptic patches (arrays of one shape).

    Forces act on the wheel, contact frame (x rolling, y lateral, z normal). ``method`` holds the
    model used per patch (for ``auto``: its choice, "bem" included; "none" where there is no contact).
    ``spin_moment_Nm`` is 0 for ``hertz`` and ``vermeulen-johnson`` (which have none).
    """

    normal_force_N: np.ndarray
    approach_m: np.ndarray
    semi_axis_long_m: np.ndarray
    semi_axis_lat_m: np.ndarray
    max_pressure_Pa: np.ndarray
    creep_force_long_N: np.ndarray
    creep_force_lat_N: np.ndarray
    spin_moment_Nm: np.ndarray
    method: np.ndarray
    converged: np.ndarray

    def to_dict(self) -> dict:
        """The arrays by name."""
        return {name: getattr(self, name) for name in self.__dataclass_fields__}

    def to_dataframe(self):
        """One row per patch (arrays flattened in C order), pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame({name: np.ravel(value) for name, value in self.to_dict().items()})


BATCH_METHODS = ("hertz", "linear", "vermeulen-johnson", "fastsim", "auto")


def solve_batch(
    method: str,
    curvature_long_1_per_m,
    curvature_lat_1_per_m,
    longitudinal,
    lateral,
    spin_1_per_m,
    material: Material,
    *,
    normal_force_N=None,
    approach_m=None,
    options: Mapping | None = None,
) -> AnalyticBatch:
    """Vectorised entry point for the dynamics: Hertz + the tangential law for many patches.

    Same physics as the registry models (module docstring), without per-patch Python objects.
    Exactly one of ``normal_force_N`` / ``approach_m``. Curvatures, creepages and the load are
    broadcast together (numpy rules; e.g. scalar curvatures with arrays of creepages), and every
    array of the result has the broadcast shape. Options: those of the chosen model (fastsim: nx, ny,
    traction_bound, flexibility; auto: tolerance and the fastsim options). ``auto`` chooses per patch as
    :class:`AutoModel` does (the geometric features are 0: quadric patches) and solves the patches it sends to
    ``bem`` one by one with the BEM model (default options; their semi-axes and max pressure are then BEM's).

    Raises:
        ValueError: unknown method or option, or bad input.
    """
    if method not in BATCH_METHODS:
        raise ValueError(f"method = {method!r}: expected one of {', '.join(BATCH_METHODS)}")
    from rigid_dynamics.contact.fastsim import fastsim_batch
    from rigid_dynamics.contact.kalker import CreepCoefficients, kalker_coefficients
    from rigid_dynamics.contact.linear import linear_creep_forces
    from rigid_dynamics.contact.vermeulen_johnson import vermeulen_johnson_saturation

    fastsim_options = {k: v for k, v in FastsimModel.OPTIONS.items() if k != "fields"}
    declared = {"fastsim": fastsim_options, "auto": {"tolerance": AutoModel.OPTIONS["tolerance"], **fastsim_options}}
    opts = _options(options, declared.get(method, {}), method)
    inputs = {
        "curvature_long_1_per_m": curvature_long_1_per_m,
        "curvature_lat_1_per_m": curvature_lat_1_per_m,
        "longitudinal": longitudinal,
        "lateral": lateral,
        "spin_1_per_m": spin_1_per_m,
        "normal_force_N": normal_force_N,
        "approach_m": approach_m,
    }
    try:
        shape = np.broadcast_shapes(*(np.shape(v) for v in inputs.values() if v is not None))
    except ValueError:
        shapes = ", ".join(f"{k} {np.shape(v)}" for k, v in inputs.items() if v is not None)
        raise ValueError(f"array shapes {shapes}: expected shapes that broadcast together") from None

    def full(value):
        return None if value is None else np.array(np.broadcast_to(np.asarray(value, dtype=float), shape))

    curv_a, curv_b = full(curvature_long_1_per_m), full(curvature_lat_1_per_m)
    hz = hertz_solve_batch(
        curv_a,
        curv_b,
        normal_force_N=full(normal_force_N),
        approach_m=full(approach_m),
        shear_modulus_Pa=material.shear_modulus_Pa,
        poisson_ratio=material.poisson_ratio,
    )
    xi, eta, phi = (full(v) for v in (longitudinal, lateral, spin_1_per_m))
    # Hertz's, except on the patches auto sends to bem (then the BEM solution's)
    patch_values = {
        name: np.array(getattr(hz, name), float) for name in ("semi_axis_long_m", "semi_axis_lat_m", "max_pressure_Pa")
    }
    contact = hz.normal_force_N > 0
    a = np.where(contact, hz.semi_axis_long_m, 1.0)
    b = np.where(contact, hz.semi_axis_lat_m, 1.0)
    fx = np.zeros(shape)
    fy = np.zeros(shape)
    mz = np.zeros(shape)
    used = np.full(shape, method if method != "auto" else "", dtype=object)
    if method != "hertz":
        coef = kalker_coefficients(a / b, material.poisson_ratio)
        tx, ty, tz = linear_creep_forces(
            a,
            b,
            xi,
            eta,
            phi,
            shear_modulus_Pa=material.shear_modulus_Pa,
            poisson_ratio=material.poisson_ratio,
            coefficients=coef,
        )
        vx, vy = vermeulen_johnson_saturation(tx, ty, hz.normal_force_N, material.friction_coefficient)
        fs_kw = (
            {k: opts[k] for k in ("nx", "ny", "traction_bound", "flexibility")} if method in ("fastsim", "auto") else {}
        )
        if method == "auto":
            from rigid_dynamics.contact.auto import FEATURES, batch_features, choose_rung, load_thresholds

            feats = batch_features(a, b, hz.normal_force_N, xi, eta, phi, material, coef)
            data = load_thresholds()
            grid = (opts["nx"], opts["ny"])
            used = np.full(shape, "", dtype=object)
            for idx in np.ndindex(shape):
                if contact[idx]:
                    choice = choose_rung(
                        {f: float(feats[f][idx]) for f in FEATURES}, opts["tolerance"], fastsim_grid=grid, data=data
                    )
                    used[idx] = choice["model"]
        if method == "linear":
            fx, fy, mz = tx, ty, tz
        elif method == "vermeulen-johnson":
            fx, fy = vx, vy
        elif method == "fastsim":
            r = fastsim_batch(
                a, b, hz.normal_force_N, xi, eta, phi, shear_modulus_Pa=material.shear_modulus_Pa,
                poisson_ratio=material.poisson_ratio, friction_coefficient=material.friction_coefficient,
                coefficients=coef, **fs_kw,
            )  # fmt: skip
            fx, fy, mz = r.creep_force_long_N, r.creep_force_lat_N, r.spin_moment_Nm
        else:
            lin = used == "linear"
            vj = used == "vermeulen-johnson"
            fx = np.where(lin, tx, np.where(vj, vx, 0.0))
            fy = np.where(lin, ty, np.where(vj, vy, 0.0))
            mz = np.where(lin, tz, 0.0)
            bem = (used == "bem") & contact
            if np.any(bem):
                from rigid_dynamics.contact.registry import get_model

                bem_model = get_model("bem")
                for idx in zip(*np.nonzero(bem), strict=True):
                    r = bem_model.solve(
                        ContactGeometry(float(curv_a[idx]), float(curv_b[idx]), float(hz.approach_m[idx])),
                        Creepage(float(xi[idx]), float(eta[idx]), float(phi[idx])),
                        material,
                        normal_force_N=float(hz.normal_force_N[idx]),
                        options={"grid_tolerance": opts["tolerance"]},
                    )
                    if not r.success:
                        raise ValueError(f"auto: bem failed on patch {idx}: {r.status}: {r.message}")
                    fx[idx], fy[idx], mz[idx] = r.creep_force_long_N, r.creep_force_lat_N, r.spin_moment_Nm or 0.0
                    for name in ("semi_axis_long_m", "semi_axis_lat_m", "max_pressure_Pa"):
                        patch_values[name][idx] = getattr(r, name)
            fs = used == "fastsim"
            if np.any(fs & contact):
                sel = fs & contact
                sub = CreepCoefficients(*(np.asarray(c)[sel] for c in (coef.c11, coef.c22, coef.c23, coef.c33)))
                r = fastsim_batch(
                    a[sel], b[sel], hz.normal_force_N[sel], xi[sel], eta[sel], phi[sel],
                    shear_modulus_Pa=material.shear_modulus_Pa, poisson_ratio=material.poisson_ratio,
                    friction_coefficient=material.friction_coefficient, coefficients=sub, **fs_kw,
                )  # fmt: skip
                fx[sel], fy[sel], mz[sel] = r.creep_force_long_N, r.creep_force_lat_N, r.spin_moment_Nm
    zero = np.zeros(shape)
    used = np.where(contact, used, "none")
    return AnalyticBatch(
        normal_force_N=hz.normal_force_N,
        approach_m=hz.approach_m,
        semi_axis_long_m=patch_values["semi_axis_long_m"],
        semi_axis_lat_m=patch_values["semi_axis_lat_m"],
        max_pressure_Pa=patch_values["max_pressure_Pa"],
        creep_force_long_N=np.where(contact, fx, zero),
        creep_force_lat_N=np.where(contact, fy, zero),
        spin_moment_Nm=np.where(contact, mz, zero),
        method=used,
        converged=hz.converged,
    )
