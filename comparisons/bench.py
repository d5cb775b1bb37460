"""Run time against error for every named case and every applicable rung at several resolutions.

For each named case (:mod:`comparisons.named_cases`) and each model of the ladder at each of its resolutions
(FASTSIM grid, BEM elements per side, FEA elements per semi-axis) the case is solved once (fast runs are
repeated up to 5 times within 0.2 s and the shortest wall time kept) and compared with the case's reference:

* relative errors of the normal force, the max pressure and the contact area: |v / v_ref - 1|;
* the creep-force error |F - F_ref| / max(|F_ref|, 0.01 mu N_ref) with F = (Fx, Fy) (None where the model gives
  no creep forces: the FEA where its rolling series gives none, see :data:`FEA_CREEP_STATUS`; the FEA's creep
  forces of a quadric patch with longitudinal or lateral creepage and no spin come from its rolling mesh series with
  a stated error, fea.model "Creep forces", and are judged like every rung's);
* the pressure-field error ||p - p_ref||_2 / ||p_ref||_2 on the reference's grid (model field bilinear, 0
  outside its grid) where both fields exist and the side has one patch;
* ``error``: the largest of these (field excluded) over the quantities the reference has; None when the model
  cannot give one of them (then the run meets no tolerance);
* ``normal_error``: the largest of the normal-force, max-pressure and area errors (the quantities every rung,
  the FEA included, solves and states): the FEA's error on a creep case where its creep forces are a status
  (``creep_status``: ``error-not-stated (<the series' status>)``, e.g. "unresolved" in the linear range or
  "not-solved" with spin), shown in the tolerance table's FEA column and in the plots (hollow markers, off the
  front);
* ``result_status``: the status of the model's own result(s) on the side ("ok", or e.g. the FEA's
  "mesh-tolerance-not-met" when its stated error is above the run's mesh tolerance within its budget, the BEM's
  "warning" when its grid error is above its grid tolerance): the run's ``status`` says the solve succeeded and its
  numbers are used, this one whether the model met its own tolerance (both in the row);
* ``stated_check``: for a model that states its error, whether the error against the reference is within the
  stated error plus the reference's own, per quantity, the creep force (as the vector error above, against the
  creep-force error the model states) included (an understated error is named, never hidden); ``stated`` the
  largest stated error over the quantities the reference has.

A wheelset case is solved as a whole (search, equilibrium, both wheels; the time is the whole case's) and
compared on the reference's side (:mod:`comparisons.named_cases` on patch sums). A run that raises or does not
succeed keeps its status and message; its numbers are not used as a result (no error, no tolerance).

Outputs (:func:`write_bench`): ``bench.csv``, ``bench.md`` (per-case tables, the tolerance table: for 10, 5,
2, 1 % the fastest run meeting it), ``bench.json`` and ``time_vs_error-<case>.png`` (log-log, one line per
model, the Pareto front marked).
"""

from __future__ import annotations

import math
import os
import platform
import time
from dataclasses import dataclass, field

import numpy as np

MODELS = ("hertz", "linear", "vermeulen-johnson", "fastsim", "bem", "fea")
TANGENTIAL_MODELS = ("linear", "vermeulen-johnson", "fastsim")
NORMAL_ONLY_MODELS = ("hertz",)
"""Rungs that solve the normal problem only (no creep forces)."""
RESOLUTIONS: dict[str, list[tuple[str, dict]]] = {
    "hertz": [("-", {})],
    "linear": [("-", {})],
    "vermeulen-johnson": [("-", {})],
    "fastsim": [(f"{n}x{n}", {"nx": n, "ny": n}) for n in (5, 10, 20, 40)],
    "bem": [(f"{n}x{n}", {"nx": n, "ny": n}) for n in (16, 32, 64)],
    "fea": [(f"tol{round(100 * t)}%", {"mesh_tolerance": t, "stresses": False}) for t in (0.05, 0.02)],
}
"""model -> [(resolution label, model options)], full bench. FEA without the subsurface stresses (the bench compares
forces, max pressure and area only; the stresses are ``wheelrail compare``'s), at two mesh tolerances: each run
refines its mesh until its stated discretisation error meets the tolerance (fea.refinement) and carries that error
(column ``stated``)."""
QUICK_RESOLUTIONS = {"fastsim": ("10x10", "20x20"), "bem": ("16x16", "32x32"), "fea": ("tol5%",)}
"""model -> labels kept by ``--quick`` (models not listed keep all)."""
TOLERANCES = (0.10, 0.05, 0.02, 0.01)
QUANTITIES = ("normal_force_N", "creep_force_long_N", "creep_force_lat_N", "max_pressure_Pa", "contact_area_m2")
ERROR_KEYS = ("err_normal_force", "err_creep_force", "err_max_pressure", "err_area")
NORMAL_ERROR_KEYS = {"err_normal_force": "normal_force", "err_max_pressure": "max_pressure", "err_area": "contact_area"}
"""bench error key -> stated-error quantity (comparisons.stated_errors) of the normal problem."""
REFERENCE_KEYS = {
    "normal_force": "normal_force_N",
    "max_pressure": "max_pressure_Pa",
    "contact_area": "contact_area_m2",
}
"""stated-error quantity -> the named case's reference / uncertainty key."""
FEA_CREEP_STATUS = "error-not-stated"
"""The status of the FEA's creep forces on a case with a creep-force reference where the FEA gives none, followed by
the reason in parentheses, the status of its ``extra["tangential"]`` (:func:`fea_creep_status`). The FEA's creep
forces come from its rolling mesh series (fea.rolling_series via fea.model "Creep forces": a quadric patch under load
control with longitudinal or lateral creepage, no spin), with a stated first-order Richardson error; where that
series gives none they are None: "unresolved" (the slip zone narrower than a cell on a level of the series, e.g. the
linear range, creep-long-small), "irregular", "not-converged", or "not-solved" (spin: the series is measured against
the BEM at pure xi and eta only; a sampled patch; a wheelset case under approach control). Such a run's error is
stated on N, p max and area only (``normal_error``)."""
CREEP_ERROR_NAMES = ("creep_force_long", "creep_force_lat")
"""Stated-error quantities (comparisons.stated_errors) of the creep force; the bench's creep error is the vector's."""


def fea_creep_status(results) -> str:
    """``FEA_CREEP_STATUS`` with the reason the FEA's results give no creep forces (their ``extra["tangential"]``
    statuses), e.g. "error-not-stated (unresolved)".
    """
    reasons = []
    for result in results:
        tangential = (result.extra or {}).get("tangential")
        reason = tangential.get("status") if isinstance(tangential, dict) else None
        reasons.append(reason or "not-solved")
    return f"{FEA_CREEP_STATUS} ({', '.join(dict.fromkeys(reasons))})" if reasons else FEA_CREEP_STATUS


@dataclass
class BenchRun:
    """One (case, model, resolution) run: status, wall time, the compared values and their errors."""

    case: str
    source: str
    model: str
    resolution: str
    status: str
    message: str
    wall_time_s: float
    n_patches: int = 0
    values: dict = field(default_factory=dict)
    errors: dict = field(default_factory=dict)
    error: float | None = None
    grid_error_estimate: float | None = None
    stated: dict | None = None
    stated_error: float | None = None
    normal_error: float | None = None
    creep_status: str | None = None
    result_status: str = "ok"
    stated_check: dict | None = None

    def row(self) -> dict:
        out = {
            "case": self.case,
            "source": self.source,
            "model": self.model,
            "resolution": self.resolution,
            "status": self.status,
            "wall_time_s": self.wall_time_s,
            "n_patches": self.n_patches,
        }
        out.update({k: self.values.get(k) for k in QUANTITIES})
        out.update({k: self.errors.get(k) for k in (*ERROR_KEYS, "err_field")})
        out["error"] = self.error
        out["grid_error_estimate"] = self.grid_error_estimate  # the model's own estimate (bem), relative
        out["stated_error"] = self.stated_error
        out["stated_errors"] = self.stated
        out["normal_error"] = self.normal_error
        out["creep_status"] = self.creep_status
        out["result_status"] = self.result_status
        out["stated_check"] = self.stated_check
        out["message"] = self.message
        return out


def solve_contact_case(case, model: str, options: dict):
    """Solve a validated contact case (``wheelrail.cases.ContactCase``) with ``model`` and extra model options.

    Returns:
        (patches, success, message): patches as (side, geometry, creepage, result) tuples.
    """
    from rigid_dynamics.contact.registry import get_model

    if case.kind == "quadric":
        opts = {**case.solver_options, **options}
        result = get_model(model).solve(
            case.geometry, case.creepage, case.material, normal_force_N=case.normal_force_N, options=opts or None
        )
        return [("single", case.geometry, case.creepage, result)], result.success, result.message
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case

    case_options = dict(case.solver_options)
    case_options["model"] = {**(case_options.get("model") or {}), **options} or None
    # no bench-specific force tolerance: the equilibrium accepts the load at a model's stated force error (the
    # FEA's, which scatters between remeshed evaluations; wheelset_case._load_tolerance)
    solution = solve_wheelset_case(case.wheelset, case.material, model, options=case_options)
    patches = [(p.side, p.geometry, p.creepage, p.result) for p in solution.patches]
    return patches, solution.success, solution.message


def side_values(patches, side: str) -> dict:
    """N, Fx, Fy summed over the side's patches, the largest max pressure and the summed area (None if absent)."""
    results = [p[3] for p in patches if p[0] == side]

    def total(name):
        values = [getattr(r, name) for r in results]
        return None if not values or any(v is None for v in values) else float(sum(values))

    pressures = [r.max_pressure_Pa for r in results]
    return {
        "normal_force_N": total("normal_force_N"),
        "creep_force_long_N": total("creep_force_long_N"),
        "creep_force_lat_N": total("creep_force_lat_N"),
        "max_pressure_Pa": None if not pressures or None in pressures else float(max(pressures)),
        "contact_area_m2": total("contact_area_m2"),
    }


def case_errors(named, values: dict) -> tuple[dict, float | None]:
    """Relative errors against the named case's reference (module docstring) and the headline error."""
    ref = named.reference
    errors: dict = {}
    for key, name in (
        ("normal_force_N", "err_normal_force"),
        ("max_pressure_Pa", "err_max_pressure"),
        ("contact_area_m2", "err_area"),
    ):
        if key in ref:
            value = values.get(key)
            errors[name] = None if value is None else abs(value / ref[key] - 1.0)
    if "creep_force_long_N" in ref and "creep_force_lat_N" in ref:
        fx, fy = values.get("creep_force_long_N"), values.get("creep_force_lat_N")
        if fx is None or fy is None:
            errors["err_creep_force"] = None
        else:
            mu = named.case.material.friction_coefficient
            scale = max(
                math.hypot(ref["creep_force_long_N"], ref["creep_force_lat_N"]), 0.01 * mu * ref["normal_force_N"]
            )
            errors["err_creep_force"] = (
                math.hypot(fx - ref["creep_force_long_N"], fy - ref["creep_force_lat_N"]) / scale
            )
    headline = None if any(v is None for v in errors.values()) or not errors else max(errors.values())
    return errors, headline


def stated_check(named, errors: dict, stated: dict | None) -> dict | None:
    """Whether a model's stated errors hold against the reference: per quantity of the normal problem,
    {"error": against the reference, "allowed": stated + the reference's own, "holds": error <= allowed}; None when
    the model states none. An understated error is a defect of the estimator, named in the report.
    """
    if not stated:
        return None
    out = {}
    for key, name in NORMAL_ERROR_KEYS.items():
        error, own = errors.get(key), stated.get(name)
        if error is None or own is None:
            continue
        allowed = own + named.uncertainty.get(REFERENCE_KEYS[name], 0.0)
        out[name] = {"error": error, "allowed": allowed, "holds": error <= allowed * (1 + 1e-9) + 1e-12}
    error = errors.get("err_creep_force")
    own = [stated[n] for n in CREEP_ERROR_NAMES if n in stated]
    if error is not None and own:
        # the vector error |F - F_ref| / max(|F_ref|, 0.01 mu N) against the model's stated creep-force error (the
        # BEM and the FEA state the vector's, on the same scale) plus the reference's own
        reference = max(named.uncertainty.get(k, 0.0) for k in ("creep_force_long_N", "creep_force_lat_N"))
        allowed = max(own) + reference
        out["creep_force"] = {"error": error, "allowed": allowed, "holds": error <= allowed * (1 + 1e-9) + 1e-12}
    return out or None


def field_error(named, patches) -> float | None:
    """||p - p_ref|| / ||p_ref|| on the reference grid (one patch on the side, both fields present), else None."""
    on_side = [p[3] for p in patches if p[0] == named.side]
    if len(on_side) != 1 or on_side[0].fields is None:
        return None
    grid = named.reference_grid()
    if grid is None:
        return None
    from comparisons.named_cases import grid_interpolate

    xx, yy = np.meshgrid(*grid)
    p_ref = named.reference_pressure(xx, yy)
    f = on_side[0].fields
    p = grid_interpolate(f.x_m, f.y_m, np.asarray(f.pressure_Pa, float), xx, yy)
    norm = float(np.linalg.norm(p_ref))
    return float(np.linalg.norm(p - p_ref) / norm) if norm > 0 else None


def applicable(named, model: str) -> bool:
    """Tangential rungs (linear, VJ, FASTSIM) only where the reference has creep forces (else they equal hertz)."""
    if model in TANGENTIAL_MODELS:
        return "creep_force_long_N" in named.reference
    return True


def run_one(named, model: str, resolution: str, options: dict) -> BenchRun:
    """Solve one named case with one model at one resolution and compare it with the reference."""
    elapsed = []
    patches, success, message = [], False, ""
    try:
        while True:
            start = time.perf_counter()
            patches, success, message = solve_contact_case(named.case, model, options)
            elapsed.append(time.perf_counter() - start)
            if len(elapsed) >= 5 or sum(elapsed) > 0.2 or not success:
                break
    except Exception as exc:  # a numerical failure is a status (the bench goes on with the next run)
        return BenchRun(
            named.name,
            named.source,
            model,
            resolution,
            "error",
            f"{type(exc).__name__}: {exc}",
            sum(elapsed) if elapsed else math.nan,
        )
    run = BenchRun(
        named.name,
        named.source,
        model,
        resolution,
        "ok" if success else "failed",
        message,
        min(elapsed),
        n_patches=sum(1 for p in patches if p[0] == named.side),
    )
    if not success:
        return run
    from comparisons.stated_errors import largest, side_stated_errors

    side_results = [p[3] for p in patches if p[0] == named.side]
    run.result_status = next((r.status for r in side_results if r.status != "ok"), "ok")
    run.values = side_values(patches, named.side)
    run.errors, run.error = case_errors(named, run.values)
    run.stated = side_stated_errors([p[3] for p in patches if p[0] == named.side])
    creep_case = "err_creep_force" in run.errors
    run.stated_error = largest(
        run.stated, ("normal_force", "max_pressure", "contact_area", *(CREEP_ERROR_NAMES if creep_case else ()))
    )
    normal = [run.errors[k] for k in NORMAL_ERROR_KEYS if k in run.errors]
    run.normal_error = None if not normal or None in normal else max(normal)
    if creep_case and run.errors["err_creep_force"] is None and model == "fea":
        run.creep_status = fea_creep_status(side_results)
    run.stated_check = stated_check(named, run.errors, run.stated)
    run.errors["err_field"] = field_error(named, patches)
    estimates = [p[3].extra.get("grid_error_estimate") for p in patches if p[0] == named.side]
    estimates = [e for e in estimates if e is not None]
    run.grid_error_estimate = max(estimates) if estimates else None
    return run


def bench_plan(cases, models=MODELS, quick: bool = False) -> list[tuple]:
    """[(named case, model, resolution label, options)] in run order."""
    plan = []
    for named in cases:
        for model in models:
            if not applicable(named, model):
                continue
            for label, options in RESOLUTIONS[model]:
                if quick and model in QUICK_RESOLUTIONS and label not in QUICK_RESOLUTIONS[model]:
                    continue
                plan.append((named, model, label, options))
    return plan


def warm_up(model: str) -> None:
    """Solve one small quadric patch with ``model`` untimed: loads numba's cache / JIT-compiles the FEA forms, so
    that the first timed run measures the solve and not the compilation.
    """
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    options = {"fea": {"quick": True}, "bem": {"nx": 8, "ny": 8}, "fastsim": {"nx": 5, "ny": 5}}.get(model)
    get_model(model).solve(
        ContactGeometry.quadric(0.46, 0.30),
        Creepage(1e-4, 0.0, 0.1),
        Material(82e9, 0.28, 0.3),
        normal_force_N=1e4,
        options=options,
    )


def run_bench(cases, models=MODELS, quick: bool = False, progress=None) -> list[BenchRun]:
    """Run the plan; ``progress(done, total, label)`` is called after each run (e.g. a tqdm bar)."""
    plan = bench_plan(cases, models, quick)
    for model in dict.fromkeys(p[1] for p in plan):
        warm_up(model)
    runs = []
    for i, (named, model, label, options) in enumerate(plan):
        runs.append(run_one(named, model, label, options))
        if progress is not None:
            progress(i + 1, len(plan), f"{named.name} {model} {label}")
    return runs


def machine() -> str:
    """One line on the machine (platform, CPUs, Python, load average)."""
    load = os.getloadavg() if hasattr(os, "getloadavg") else ("n/a",)
    return (
        f"{platform.platform()}, {platform.machine()}, {os.cpu_count()} CPUs (one process, shared machine), "
        f"Python {platform.python_version()}; load average {tuple(round(v, 2) for v in load)}"
    )


def tolerance_table(runs: list[BenchRun]) -> dict:
    """The tolerance table: case -> {tolerance: fastest successful run with error <= tolerance (or None)}."""
    table: dict = {}
    for run in runs:
        table.setdefault(run.case, {t: None for t in TOLERANCES})
        if run.status != "ok" or run.error is None:
            continue
        for tol in TOLERANCES:
            best = table[run.case][tol]
            if run.error <= tol and (best is None or run.wall_time_s < best.wall_time_s):
                table[run.case][tol] = run
    return table


def fea_tolerance_table(runs: list[BenchRun]) -> dict:
    """The FEA's column of the tolerance table: case -> {tolerance: fastest successful FEA run whose error on the
    normal problem (``normal_error``: N, p max, area, the quantities it solves and states) is <= tolerance, or None}.
    On a case without creep forces this is its ``error``; on a creep case its creep forces are a status.
    """
    table: dict = {}
    for run in runs:
        if run.model != "fea":
            continue
        table.setdefault(run.case, {t: None for t in TOLERANCES})
        if run.status != "ok" or run.normal_error is None:
            continue
        for tol in TOLERANCES:
            best = table[run.case][tol]
            if run.normal_error <= tol and (best is None or run.wall_time_s < best.wall_time_s):
                table[run.case][tol] = run
    return table


def _fea_cell(runs: list[BenchRun], case: str, row: dict | None) -> str:
    """The tolerance table's FEA cell: the smallest tolerance its normal problem meets (fastest such run), its
    error, stated error and whether that holds, and the status of its creep forces; or why there is none.
    """
    fea = [r for r in runs if r.case == case and r.model == "fea"]
    if not fea:
        return "not run"
    met = [(t, r) for t, r in (row or {}).items() if r is not None]
    if not met:
        best = min((r for r in fea if r.status == "ok" and r.normal_error is not None), default=None,
                   key=lambda r: r.normal_error)  # fmt: skip
        if best is None:
            return "; ".join(f"{r.resolution}: {r.status}" for r in fea)
        text = f"none ({best.resolution}: {_pct(best.normal_error)} in {_time(best.wall_time_s)}"
    else:
        tol, best = min(met, key=lambda item: item[0])
        text = f"{int(round(100 * tol))} %: {best.resolution} {_pct(best.normal_error)} in {_time(best.wall_time_s)}"
    if best.result_status != "ok":
        text += f" ({best.result_status})"
    text += f", stated {_stated(best)}{_check_word(best)}" + ("" if met else ")")
    if best.creep_status:
        text += f"; creep forces: {best.creep_status}"
    elif best.errors.get("err_creep_force") is not None:
        creep = (best.stated_check or {}).get("creep_force")
        stated = "not stated" if creep is None else f"stated {_pct(creep['allowed'])} with the reference's own"
        text += f"; creep forces {_pct(best.errors['err_creep_force'])} ({stated})"
    return text


def _check_word(run: BenchRun) -> str:
    """' holds' / ' UNDERSTATED (quantity)' after a stated error, '' when there is nothing to check."""
    if not run.stated_check:
        return ""
    bad = [name.replace("_", " ") for name, c in run.stated_check.items() if not c["holds"]]
    return " UNDERSTATED (" + ", ".join(bad) + ")" if bad else " holds"


def pareto_front(runs: list[BenchRun]) -> list[BenchRun]:
    """Runs with an error not beaten by any faster run (sorted by time)."""
    ok = sorted((r for r in runs if r.status == "ok" and r.error is not None), key=lambda r: (r.wall_time_s, r.error))
    front, best = [], math.inf
    for run in ok:
        if run.error < best:
            front.append(run)
            best = run.error
    return front


def _fmt(value, scale=1.0, digits=4) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value * scale:.{digits}g}"


def _pct(value) -> str:
    if value is None:
        return "-"
    return f"{100 * value:.2g} %" if value >= 1e-4 else "<0.01 %"


def _stated(run: BenchRun) -> str:
    if run.status != "ok":
        return "-"
    return "not stated" if run.stated_error is None else _pct(run.stated_error)


def _row_status(run: BenchRun) -> str:
    """The status cell of a per-case row: the run's status (with its message when not ok) and, for the FEA on a
    creep case, the status of its creep forces.
    """
    text = run.status if run.status == "ok" else f"{run.status}: {run.message[:60]}"
    if run.status == "ok" and run.result_status != "ok":
        text += f" ({run.result_status})"
    return text + (f"; creep forces {run.creep_status}" if run.creep_status else "")


def _time(seconds) -> str:
    if seconds is None or not math.isfinite(seconds):
        return "-"
    return f"{seconds * 1e3:.3g} ms" if seconds < 1 else f"{seconds:.3g} s"


def markdown(runs: list[BenchRun], cases, quick: bool, wall_s: float, plots: dict) -> str:
    """The bench report (tolerance table first, then one table per case)."""
    lines = [
        "# Contact bench: run time against error",
        "",
        f"{'Quick' if quick else 'Full'} run, {len(runs)} runs in {wall_s:.0f} s. Machine: {machine()}.",
        "",
        "Errors against each case's reference (closed form; `contact-converged`: CONTACT run here on refined "
        "elements, its finest grid, the A-2.2 cases' published 0.2 mm numbers being grid-dependent; or the BEM "
        "Richardson limit: column `source`); a reference's own error estimate is stated under its case. `error` is "
        "the largest of the normal-force, creep-force, max-pressure and area "
        "errors; `-` where a model gives no such number (Hertz has no creep forces: 100 %; the FEA's creep forces, "
        "from its rolling mesh series on a quadric patch with longitudinal or lateral creepage and no spin, are "
        f"`{FEA_CREEP_STATUS} (reason)` where that series states no error, its error on N, p max and area then in the "
        "FEA column and as hollow markers in the plots). "
        "Times are wall times of one case solve (a wheelset case includes the contact search and equilibrium). "
        "`stated`: the largest relative discretisation error the model states for its own normal force, max pressure "
        "and area, and creep force on a creep case (the FEA's, from its refinement series, fea.refinement, and its "
        "rolling series, fea.rolling_series; `not stated` for a model that states none); "
        "a run's `error` against the reference should be within its stated error plus the reference's own.",
        "",
        *(
            ["![every case: error against time, one colour and marker per rung](overview.png)", ""]
            if "overview" in plots
            else []
        ),
        "## Tolerance table: the fastest run meeting each tolerance",
        "",
        "Column FEA: the FEA on the normal problem (N, p max, area; its creep forces, where the case has them, "
        f"follow: their error and stated error, or `{FEA_CREEP_STATUS} (reason)`, see comparisons/bench.py "
        "FEA_CREEP_STATUS): the smallest tolerance met by the fastest such run, its error, its "
        "stated error and whether the stated error holds against the reference (error <= stated + the reference's "
        "own).",
        "",
        "| case | source | " + " | ".join(f"{int(t * 100)} %" for t in TOLERANCES) + " | FEA (N, p max, area) |",
        "|---|---|" + "---|" * len(TOLERANCES) + "---|",
    ]
    table = tolerance_table(runs)
    fea_table = fea_tolerance_table(runs)
    sources = {c.name: c.source for c in cases}
    for case, row in table.items():
        cells = []
        for tol in TOLERANCES:
            run = row[tol]
            cells.append("none" if run is None else f"{run.model} {run.resolution} ({_time(run.wall_time_s)})")
        cells.append(_fea_cell(runs, case, fea_table.get(case)))
        lines.append(f"| {case} | {sources.get(case, '')} | " + " | ".join(cells) + " |")
    lines += ["", "## Per case", ""]
    for named in cases:
        case_runs = [r for r in runs if r.case == named.name]
        if not case_runs:
            continue
        lines += [f"### {named.name}", "", f"{named.note} (reference: {named.source}).", ""]
        if named.uncertainty:
            own = ", ".join(f"{k} {_pct(v)}" for k, v in named.uncertainty.items() if v > 1e-9)
            lines += [f"The reference's own error estimate: {own or 'below 1e-9'}.", ""]
        if named.name in plots:
            lines += [f"![time vs error]({plots[named.name]})", ""]
        lines += [
            "| model | res | status | time | N [N] | Fx [N] | Fy [N] | p max [MPa] | area [mm2] | err N | err F "
            "| err p | err area | err field | error | stated |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        ref = named.reference
        lines.append(
            f"| reference | | {named.source} | | {_fmt(ref.get('normal_force_N'))} | "
            f"{_fmt(ref.get('creep_force_long_N'))} | {_fmt(ref.get('creep_force_lat_N'))} | "
            f"{_fmt(ref.get('max_pressure_Pa'), 1e-6)} | {_fmt(ref.get('contact_area_m2'), 1e6)} | | | | | | | |"
        )
        for r in case_runs:
            v, e = r.values, r.errors
            status = _row_status(r)
            lines.append(
                f"| {r.model} | {r.resolution} | {status} | {_time(r.wall_time_s)} | {_fmt(v.get('normal_force_N'))} | "
                f"{_fmt(v.get('creep_force_long_N'))} | {_fmt(v.get('creep_force_lat_N'))} | "
                f"{_fmt(v.get('max_pressure_Pa'), 1e-6)} | {_fmt(v.get('contact_area_m2'), 1e6)} | "
                f"{_pct(e.get('err_normal_force'))} | {_pct(e.get('err_creep_force'))} | "
                f"{_pct(e.get('err_max_pressure'))} | {_pct(e.get('err_area'))} | {_pct(e.get('err_field'))} | "
                f"{_pct(r.error)} | {_stated(r)}{_check_word(r)} |"
            )
        lines.append("")
    return "\n".join(lines) + "\n"


def plot_case(runs: list[BenchRun], case: str, path) -> bool:
    """Log-log wall time vs error for one case: one line per model, the Pareto front marked. False if no data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rigid_dynamics.files import save_figure

    floor = 1e-6
    ok = [r for r in runs if r.case == case and _plotted(r)]
    if not ok:
        return False
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    _draw_case(ax, ok, floor, annotate=True)
    ax.set_xlabel("wall time of one case solve [s]")
    ax.set_ylabel("error against the reference (largest of N, F, p max, area)")
    ax.set_title(case)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110, metadata={"Description": "error [%] against wall time [s]"})
    plt.close(fig)
    return True


def _plotted(run: BenchRun) -> bool:
    """Drawn in the time-vs-error plots: an ok run with an error, or the FEA on a creep case with its error on the
    normal problem (drawn hollow, off the Pareto front: :func:`_draw_case`).
    """
    return run.status == "ok" and (
        run.error is not None or (run.creep_status is not None and run.normal_error is not None)
    )


def answers_question(run: BenchRun) -> bool:
    """Whether the run's rung answers its case's question: a normal-contact rung (Hertz: no creep forces) does not
    on a case with a creep-force reference, where its 100 % says nothing of its accuracy.
    """
    return not (run.model in NORMAL_ONLY_MODELS and "err_creep_force" in run.errors)


def _draw_case(ax, ok: list[BenchRun], floor: float, annotate: bool) -> None:
    """One case's runs (one colour and marker per rung), its Pareto front over the rungs that answer the case's
    question, and the tolerance lines, on log axes with the error in %.
    """
    from comparisons.style import percent_axis, rung_style, seconds_axis

    partial = [r for r in ok if r.error is None]  # the FEA on a creep case: N, p max, area only
    ok = [r for r in ok if r.error is not None]
    for model in MODELS:
        pts = [(r.wall_time_s, max(r.error, floor), r.resolution) for r in ok if r.model == model]
        hollow = [(r.wall_time_s, max(r.normal_error, floor), r.resolution) for r in partial if r.model == model]
        for series, style in ((pts, {}), (hollow, {"markerfacecolor": "none", "ls": ":"})):
            if not series:
                continue
            series.sort()
            kwargs = {**rung_style(model), "ls": "-", **style}
            if style:
                kwargs["label"] = f"{model} (N, p, area; creep {FEA_CREEP_STATUS})"
            ax.plot([p[0] for p in series], [p[1] for p in series], **kwargs)
            if annotate:
                for t, e, label in series:
                    if label != "-":
                        ax.annotate(label, (t, e), fontsize=7, xytext=(3, 3), textcoords="offset points")
    front = pareto_front([r for r in ok if answers_question(r)])
    ax.plot(
        [r.wall_time_s for r in front], [max(r.error, floor) for r in front], "k--", marker="o",
        markerfacecolor="none", markersize=11, label="Pareto front",
    )  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    for tol in TOLERANCES:
        ax.axhline(tol, color="0.75", lw=0.8, zorder=0)
        ax.annotate(
            f"{100 * tol:g} %", (0.0, tol), xycoords=("axes fraction", "data"), fontsize=6, color="0.45",
            xytext=(2, 1), textcoords="offset points", ha="left", va="bottom",
        )  # fmt: skip
    percent_axis(ax.yaxis)
    times = [r.wall_time_s for r in ok + partial]
    seconds_axis(ax.xaxis, min(times), max(times))
    ax.grid(True, which="major", alpha=0.3)


def plot_overview(runs: list[BenchRun], path) -> bool:
    """Every case in one figure: a panel per case, error [%] against time, the same colour and marker per rung."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rigid_dynamics.files import save_figure

    floor = 1e-6
    cases = [c for c in dict.fromkeys(r.case for r in runs) if any(
        r.case == c and _plotted(r) for r in runs)]  # fmt: skip
    if not cases:
        return False
    cols = min(4, len(cases))
    rows = -(-len(cases) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 2.9 * rows), squeeze=False, sharey=True)
    for ax, case in zip(axes.flat, cases, strict=False):
        _draw_case(ax, [r for r in runs if r.case == case and _plotted(r)], floor, False)
        ax.set_title(case, fontsize=9)
        ax.tick_params(labelsize=7)
    for ax in axes.flat[len(cases) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("error [%]")
    for ax in axes[-1, :]:
        ax.set_xlabel("wall time [s]")
    handles, labels = {}, {}
    for ax in axes.flat[: len(cases)]:
        for h, label in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(label, h)
    labels = list(handles)
    fig.legend([handles[k] for k in labels], labels, loc="lower center", ncol=min(len(labels), 7), fontsize=8)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    save_figure(fig, path, dpi=100, metadata={"Description": "error [%] against wall time [s], every case"})
    plt.close(fig)
    return True


def _run_brief(run: BenchRun | None) -> dict | None:
    if run is None:
        return None
    return {"model": run.model, "resolution": run.resolution, "wall_time_s": run.wall_time_s, "error": run.error}


def write_bench(runs: list[BenchRun], cases, out_dir, quick: bool, wall_s: float) -> dict:
    """Write bench.csv, bench.json, bench.md and the per-case plots into ``out_dir``; return the summary."""
    import csv
    import io
    from pathlib import Path

    from rigid_dynamics.files import write_json, write_text

    out_dir = Path(out_dir)
    rows = [r.row() for r in runs]
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]) if rows else ["case"])
    writer.writeheader()
    writer.writerows(rows)
    write_text(out_dir / "bench.csv", buffer.getvalue())
    plots = {}
    if plot_overview(runs, out_dir / "overview.png"):
        plots["overview"] = "overview.png"
    for named in cases:
        name = f"time_vs_error-{named.name}.png"
        if plot_case(runs, named.name, out_dir / name):
            plots[named.name] = name
    from comparisons.claims import claims_markdown, evaluate_claims

    claims = evaluate_claims(runs, {c.name: max(c.uncertainty.values(), default=0.0) for c in cases})
    table = tolerance_table(runs)
    not_ok = sum(1 for run in runs if run.status != "ok")
    summary = {
        # the bench's own status: it measured every (case, model, resolution) it was asked for; a run that is not ok
        # (e.g. FASTSIM's coarse grids breaking the friction bound) is a finding about its rung, listed per row
        "status": "ok",
        "message": f"{len(runs)} runs measured, {not_ok} not ok (each a finding about its rung: see its row)",
        "runs_not_ok": not_ok,
        "quick": quick,
        "machine": machine(),
        "wall_time_s": wall_s,
        "runs": rows,
        "tolerance_table": {
            case: {f"{int(t * 100)}%": _run_brief(r) for t, r in row.items()} for case, row in table.items()
        },
        "plots": plots,
        "claims": [{k: v for k, v in c.items()} for c in claims],
    }
    write_json(out_dir / "bench.json", summary)
    text = markdown(runs, cases, quick, wall_s, plots)
    head, sep, rest = text.partition("## Per case")
    write_text(out_dir / "bench.md", head + claims_markdown(claims) + "\n" + sep + rest)
    return summary
