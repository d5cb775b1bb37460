"""``auto`` against always-BEM on embedded dynamics scenes: real-time factor and force departure.

For each scene (shortened: SCENES gives the duration) the run is made three times: ``contact_model = "auto"`` at the
scene's ``contact_tolerance`` with its BEM patches reused within a trust region (the default, ``auto_reuse``,
rigid_dynamics/wheelset/auto_reuse.py), the same without the reuse (every BEM patch solved by the callback) and
``contact_model = "bem"`` (BEM on the sampled gap, default BEM options), everything else as in the scene file except
curve-flange, started at the pose its FASTSIM run settles to (y = -6.28 mm, yaw -4.55 mrad: the left wheel on its
flange root; settling distance 0; benchmarks/bench_bem_loop_sampled.py). Each run in its own process (``--one``): the
whole-process time (interpreter start, imports, numba cache loading, scene set-up, run; less the same-state
comparison below, made after the run in that process) is measured from outside,
the in-process time is ``SimulationResult.wall_time_s`` (static equilibrium, integration, recording); real-time
factor = simulated seconds / wall seconds.

Force departure of auto from always-BEM, per patch (side, slot) and output sample in the patch's contact frame, max
over the run: |N_auto - N_bem| over the static wheel load; |F_t,auto - F_t,bem| (creep force vector) over the
run's largest BEM creep force, and over max(|F_t,bem|, 0.01 mu N_bem) (the bench's creep-force error, the number
``contact_tolerance`` bounds per patch). Both runs sample the same output grid; a run that does not end "ok" is
reported as such. The reuse's own error (its correction against a fresh BEM solve at each re-solve, measured in the
run) is reported from summary's ``callback.auto_reuse``.

Same state (:func:`same_state_departure`): the two runs' trajectories part (start-up transients, two-point contact
flips), so the departures above mix the contact models' difference with the states'. auto's recorded per-patch forces
are therefore also compared with always-BEM's at auto's own states (each output sample's state given to a BEM
WheelsetModel of the scene): the per-patch departure the tolerance is about, overall and per auto rung.

Writes benchmarks/results/auto_vs_bem.md and auto_vs_bem.json (time series in benchmarks/results/auto_vs_bem_runs/).
Run: PYTHONPATH=. .venv/bin/python benchmarks/bench_auto.py [SCENE ...] [--reuse-bem] [--whole]
(``--reuse-bem``: keep the always-BEM runs of the last report and their time series; only auto is run again;
``--whole``: also the whole scenes of WHOLE with auto alone; ``--whole-kept``: report their kept runs).
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

SCENES = {"polygonal-wheel": 0.04, "curve-flange": 0.02, "wheel-flat": 0.0135}
"""Embedded scene -> shortened duration, s (wheel-flat: through the first impact at 0.2 m, 12 ms)."""
OTHER_SCENES = {"hunting-conical": 0.1}
"""Scenes run when named on the command line."""
STARTS = {"curve-flange": {"lateral_displacement_m": -0.00628, "yaw_rad": -0.00455}}
"""Scenes started at a settled pose (settling distance 0): curve-flange on its flange root."""
VARIANTS = {"auto": ("auto", True), "auto-no-reuse": ("auto", False), "bem": ("bem", True)}
"""Run name -> (contact model, auto_reuse)."""
WHOLE = {"polygonal-wheel": 2.0, "curve-flange": 2.0}
"""Scenes also run whole (their own duration and start) with auto alone: always-BEM would take hours."""
OUT = ROOT / "benchmarks" / "results"


def run_one(scene_name: str, duration: float, variant: str, npz: Path) -> dict:
    """Run one scene with one variant (VARIANTS) in this process; save the time series; return the numbers."""
    from rigid_dynamics.wheelset.simulate import save_timeseries, simulate
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    whole = variant == "auto-whole"
    model, reuse = VARIANTS["auto" if whole else variant]
    path = resolve_scene_path(scene_name)
    doc = read_toml(path, "scene file")
    doc["duration_s"] = duration
    doc["contact_model"] = model
    doc["auto_reuse"] = reuse
    doc.setdefault("integrator", {})["max_wall_time_s"] = 7200.0  # always-BEM on the flat: minutes on a loaded machine
    if scene_name in STARTS and not whole:
        doc["settling_distance_m"] = 0.0
        doc["initial"] = {**doc.get("initial", {}), **STARTS[scene_name]}
    scene = parse_scene(doc, base_dir=path.parent)
    start = time.perf_counter()
    result = simulate(scene)
    wall = time.perf_counter() - start
    save_timeseries(result, npz)
    out = {
        "scene": scene_name,
        "variant": variant,
        "model": model,
        "real_time_factor": result.real_time_factor,  # simulated s reached / wall s (a stopped run: its part)
        "simulated_s": float(result.t[-1]) if len(result.t) else 0.0,
        "callback": result.callback_stats,
        "duration_s": duration,
        "status": result.status,
        "message": result.message,
        "wall_time_s": result.wall_time_s,
        "simulate_call_s": wall,
        "compiled": result.compiled,
        "steps": result.steps,
        "tolerance": scene.contact_tolerance,
        "static_wheel_load_N": scene.static_wheel_load_N,
        "mu": scene.material.friction_coefficient,
        "provider": result.provider,
    }
    if model == "auto" and not whole:
        out["same_state"] = same_state_departure(scene, result)
    if "auto_rung" in result.patches:
        from rigid_dynamics.contact.auto import AUTO_RUNGS

        codes = result.patches["auto_rung"]
        codes = codes[np.isfinite(codes)].astype(int)
        out["rung_share"] = {r: float(np.mean(codes == i)) if len(codes) else 0.0 for i, r in enumerate(AUTO_RUNGS)}
        out["rung_count"] = {r: int(np.sum(codes == i)) for i, r in enumerate(AUTO_RUNGS)}
    return out


def same_state_departure(scene, result) -> dict:
    """auto's per-patch forces against always-BEM's at auto's own states: each output sample's state (and elastic
    track) given to a BEM WheelsetModel of the same scene (WheelsetModel.contact: the loop's BEM on the sampled gap,
    patches formed as always-BEM forms them); per patch (side, slot) in contact in both, |N_auto - N_bem| / Q0,
    |N_auto - N_bem| / N_bem and the creep force's |F_auto - F_bem| / max(|F_bem|, 0.01 mu N_bem), the largest
    overall and per auto rung. Free of the trajectories' drifting apart: the number the tolerance is about.
    """
    from dataclasses import replace

    from rigid_dynamics.contact.auto import AUTO_RUNGS
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    start = time.perf_counter()
    bem_scene = replace(scene, contact_model="bem")
    model = WheelsetModel(
        bem_scene, build_provider(bem_scene), get_contact_model("bem"), model_options("bem", bem_scene)
    )
    model.frame_x0 = float(result.states[0, 0])
    q0, mu = scene.static_wheel_load_N, scene.material.friction_coefficient
    p = result.patches
    by_rung: dict = {}
    worst = {"normal_over_Q0": 0.0, "normal_relative": 0.0, "creep_bench": 0.0, "creep_bench_t_s": None}
    for k in range(len(result.t)):
        track = result.track_full_states[k] if result.track_full_states is not None else None
        cs = model.contact(result.states[k], record=True, track=track, keep_search_memory=True)
        rec = cs.record  # as a run records them: a formed patch's own values (its plane), not its candidate's
        for i, (side, slot) in enumerate(zip(cs.side, cs.slot, strict=True)):
            nb = float(np.nan_to_num(rec["normal_force_N"][i]))
            na = float(np.nan_to_num(p["normal_force_N"][k, side, slot]))
            if not (na > 0 and nb > 0):
                continue
            fb = np.hypot(rec["creep_force_long_N"][i], rec["creep_force_lat_N"][i])
            df = np.hypot(
                p["creep_force_long_N"][k, side, slot] - rec["creep_force_long_N"][i],
                p["creep_force_lat_N"][k, side, slot] - rec["creep_force_lat_N"][i],
            )
            creep = float(df / max(fb, 0.01 * mu * nb))
            rung = AUTO_RUNGS[int(p["auto_rung"][k, side, slot])]
            entry = by_rung.setdefault(rung, {"patches": 0, "max_creep_bench": 0.0, "max_normal_relative": 0.0})
            entry["patches"] += 1
            entry["max_creep_bench"] = max(entry["max_creep_bench"], creep)
            entry["max_normal_relative"] = max(entry["max_normal_relative"], abs(na - nb) / nb)
            worst["normal_over_Q0"] = max(worst["normal_over_Q0"], abs(na - nb) / q0)
            worst["normal_relative"] = max(worst["normal_relative"], abs(na - nb) / nb)
            if creep > worst["creep_bench"]:
                worst["creep_bench"], worst["creep_bench_t_s"] = creep, float(result.t[k])
    return {**worst, "by_rung": by_rung, "samples": len(result.t), "seconds": time.perf_counter() - start}


def compare(auto_npz: Path, bem_npz: Path, load_N: float, mu: float) -> dict:
    """auto's departure from always-BEM per patch (side, slot) and sample, contact frame (module docstring)."""
    a, b = np.load(auto_npz), np.load(bem_npz)
    n = min(len(a["t"]), len(b["t"]))
    same_grid = bool(np.allclose(a["t"][:n], b["t"][:n]))

    def patch(arrays, name):
        return np.nan_to_num(arrays[f"patch_{name}"][:n], nan=0.0)

    na, nb = patch(a, "normal_force_N"), patch(b, "normal_force_N")
    xa, xb = patch(a, "creep_force_long_N"), patch(b, "creep_force_long_N")
    ya, yb = patch(a, "creep_force_lat_N"), patch(b, "creep_force_lat_N")
    creep_b = np.hypot(xb, yb)
    creep_diff = np.hypot(xa - xb, ya - yb)
    both = (na > 0) & (nb > 0)
    peak = float(np.max(creep_b)) if creep_b.size else 0.0
    with np.errstate(divide="ignore", invalid="ignore"):  # 0 / 0 where neither run has contact
        bench_error = creep_diff / np.maximum(creep_b, 0.01 * mu * nb)
    return {
        "samples_compared": int(n),
        "same_time_grid": same_grid,
        "max_normal_diff_over_wheel_load": float(np.max(np.abs(na - nb)) / load_N) if n else None,
        "max_creep_diff_over_peak_bem_creep": float(np.max(creep_diff) / peak) if n and peak > 0 else None,
        "max_creep_error_bench_definition": float(np.max(bench_error[both])) if np.any(both) else None,
        "peak_bem_creep_force_N": peak,
        "patches_in_contact_in_one_run_only": int(np.count_nonzero((na > 0) != (nb > 0))),
    }


def run_variant(scene: str, variant: str, scratch: Path) -> dict:
    """One run in its own process (``--one``), its numbers kept beside its time series (scratch/scene-variant.json);
    variant "auto-whole": the scene's whole duration (WHOLE) from its own start.
    """
    from comparisons.bench import machine
    from rigid_dynamics.files import write_json

    npz = scratch / f"{scene}-{variant}.npz"
    duration = WHOLE[scene] if variant == "auto-whole" else {**SCENES, **OTHER_SCENES}[scene]
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, __file__, "--one", scene, str(duration), variant, str(npz)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    whole = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"{scene} {variant}: {proc.stderr.strip().splitlines()[-1]}")
    info = json.loads(proc.stdout.strip().splitlines()[-1])
    whole -= (info.get("same_state") or {}).get("seconds", 0.0)  # the comparison after the run is not the run's
    info["whole_process_s"] = whole
    info["whole_process_real_time_factor"] = duration / whole
    info["commit"] = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT
    ).stdout.strip()
    info["machine"] = machine()
    write_json(scratch / f"{scene}-{variant}.json", info)
    print(f"{scene} {variant}: {info['status']}, in-process {info['wall_time_s']:.1f} s, whole {whole:.1f} s")
    return info


def main() -> int:
    if len(sys.argv) >= 2 and sys.argv[1] == "--one":
        scene, duration, variant, npz = sys.argv[2], float(sys.argv[3]), sys.argv[4], Path(sys.argv[5])
        print(json.dumps(run_one(scene, duration, variant, npz)))
        return 0
    from comparisons.bench import machine
    from rigid_dynamics.files import write_json, write_text

    scratch = OUT / "auto_vs_bem_runs"
    scratch.mkdir(parents=True, exist_ok=True)
    args = sys.argv[1:]
    reuse_bem = "--reuse-bem" in args
    only = [a.split("=", 1)[1] for a in args if a.startswith("--only=")]
    names = [a for a in args if not a.startswith("--")] or list(SCENES)
    rows = []
    for scene in names:
        per = {}
        for variant in VARIANTS:
            kept = scratch / f"{scene}-{variant}.json"
            skip = (variant == "bem" and reuse_bem) or (only and variant not in only[0].split(","))
            if skip and kept.exists():
                per[variant] = {**json.loads(kept.read_text()), "reused": True}
                continue
            per[variant] = run_variant(scene, variant, scratch)
        errors = {}
        for variant in ("auto", "auto-no-reuse"):
            errors[variant] = compare(
                scratch / f"{scene}-{variant}.npz",
                scratch / f"{scene}-bem.npz",
                per["bem"]["static_wheel_load_N"],
                per[variant]["mu"],
            )
        rows.append({"scene": scene, "runs": per, "error": errors})
    whole = {}
    for scene in [n for n in WHOLE if n in names or "--whole-kept" in args]:
        kept = scratch / f"{scene}-auto-whole.json"
        if "--whole" in args and scene in names:
            whole[scene] = run_variant(scene, "auto-whole", scratch)
        elif "--whole-kept" in args and kept.exists():
            whole[scene] = json.loads(kept.read_text())
    write_json(OUT / "auto_vs_bem.json", {"machine": machine(), "rows": rows, "whole": whole})
    write_text(OUT / "auto_vs_bem.md", "\n".join(report(rows) + (whole_report(whole) if whole else NO_WHOLE)))
    print(f"written {OUT / 'auto_vs_bem.md'}")
    return 0


NO_WHOLE = [
    "## Whole scenes",
    "",
    "Not run (``--whole`` runs them): since auto decides on the sampled gap's geometry (commit 7aa8be7), the "
    "S1002/UIC60 treads of polygonal-wheel and curve-flange lie beyond every ellipse rung's measured box and go to the "
    "BEM or its reuse; last measured with --whole on 2026-11-30 (the trust region seeing the sampled gap): "
    "polygonal-wheel 0.0058x, curve-flange 0.030x in process.",
    "",
]
"""The report's closing section when the whole-scene runs were not made."""


def whole_report(whole: dict) -> list:
    """The lines of the whole-scene runs (auto alone)."""
    lines = [
        "## Whole scenes, auto alone",
        "",
        "Each scene at its own duration and start (curve-flange from its own start: the flange contact forms "
        "during the run), `auto` with the reuse; always-BEM is not run (hours).",
        "",
        "| scene | simulated | status | RTF in process | RTF whole process | rungs (patches in contact) | BEM solves "
        "| callback s (of which patch formation) | reuse: served / solved, measured correction error (creep, "
        "normal), count above tolerance |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scene, run in whole.items():
        cb = run.get("callback") or {}
        reuse = cb.get("auto_reuse") or {}
        share = ", ".join(f"{k} {100 * v:.0f} %" for k, v in run.get("rung_share", {}).items() if v > 0)
        lines.append(
            f"| {scene} | {run['duration_s']:g} s | {run['status']} | {run['real_time_factor']:.3g} | "
            f"{run['whole_process_real_time_factor']:.3g} | {share} | {cb.get('solves', '-')} | "
            f"{cb.get('seconds', 0.0):.1f} ({cb.get('sampling_seconds', 0.0):.1f}) | "
            f"{reuse.get('served_by_correction')} / {reuse.get('solved_by_callback')}, "
            f"{_pct(reuse.get('max_creep_force_error'))}, {_pct(reuse.get('max_normal_force_error'))}, "
            f"{reuse.get('errors_above_tolerance')} of {reuse.get('errors_measured')} |"
        )
    return [*lines, ""]


def _same_state_text(ss) -> str:
    if not ss:
        return "-"
    rungs = "; ".join(
        f"{k} {_pct(e['max_creep_bench'])}, {_pct(e['max_normal_relative'])} ({e['patches']})"
        for k, e in ss["by_rung"].items()
    )
    return f"{_pct(ss['normal_relative'])}, {_pct(ss['creep_bench'])}; {rungs}"


def verdict(departure: float, spread: float, tolerance: float) -> str:
    """auto's same-state departure from always-BEM judged against the tolerance with the reference's own spread
    (two always-BEM evaluations of the same states: auto-no-reuse's same-state departure): "within" when
    departure + spread <= tolerance, "beyond" when departure - spread > tolerance, else "undecided".
    """
    if departure + spread <= tolerance:
        return "within"
    if departure - spread > tolerance:
        return "beyond"
    return "undecided"


def verdict_lines(rows: list) -> list:
    """One line per scene: auto's same-state normal and creep-force departures judged by :func:`verdict`."""
    out = []
    for r in rows:
        auto = r["runs"].get("auto", {}).get("same_state")
        spread = r["runs"].get("auto-no-reuse", {}).get("same_state")
        if not auto or not spread:
            continue
        tol = r["runs"]["auto"]["tolerance"]
        parts = [
            f"{label} {_pct(auto[key])} against the reference's spread {_pct(spread[key])}: "
            f"{verdict(auto[key], spread[key], tol)}"
            for label, key in (("normal force", "normal_relative"), ("creep force", "creep_bench"))
        ]
        out.append(f"- {r['scene']}: " + "; ".join(parts) + f" (tolerance {_pct(tol)}).")
    return out


def _pct(v, digits=2):
    return "-" if v is None else f"{100 * v:.{digits}g} %"


def report(rows: list) -> list:
    """The markdown report's lines."""
    from comparisons.bench import machine

    lines = [
        "# `auto` against always-BEM on the sampled gap (benchmarks/bench_auto.py)",
        "",
        f"Machine: {machine()}. Command: `PYTHONPATH=. .venv/bin/python benchmarks/bench_auto.py`. Each run in its "
        "own process; in-process time = SimulationResult.wall_time_s (static equilibrium, integration, recording), "
        "whole process = interpreter start to exit (imports, numba cache, set-up); RTF = simulated s / wall s. "
        "Durations shortened so that always-BEM finishes in minutes; curve-flange started on its settled flange "
        "root (y = -6.28 mm, yaw -4.55 mrad, settling distance 0); everything else as in the scene file. "
        "Thresholds: rigid_dynamics/contact/data/auto_thresholds.json. auto: `auto_reuse = true` (the default: a "
        "BEM patch solved once and served as FASTSIM + the stored BEM departure within a trust region, "
        "rigid_dynamics/wheelset/auto_reuse.py); auto-no-reuse: every BEM patch solved by the callback.",
        "",
        "Runs: "
        + "; ".join(
            f"{r['scene']} " + ", ".join(f"{v} at {run.get('commit', '?')}" for v, run in r["runs"].items())
            for r in rows
        )
        + ".",
        "",
        "| scene | simulated | tolerance | run | status | RTF in process | RTF whole process | x always-BEM (in "
        "process) | max dN / Q0 | max dF_creep / peak BEM creep | max creep error (bench definition) | rungs "
        "(patches in contact) | BEM solves | reuse: served / solved, measured correction error (creep, normal), "
        "count above tolerance | same state: max dN / N_BEM, max creep error (bench definition); per rung: creep, "
        "normal |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        bem = r["runs"]["bem"]
        for variant, run in r["runs"].items():
            e = r["error"].get(variant)
            share = ", ".join(f"{k} {100 * v:.0f} %" for k, v in run.get("rung_share", {}).items() if v > 0)
            cb = run.get("callback") or {}
            reuse = cb.get("auto_reuse") or {}
            reuse_text = "-"
            if reuse.get("enabled"):
                reuse_text = (
                    f"{reuse['served_by_correction']} / {reuse['solved_by_callback']}, "
                    f"{_pct(reuse['max_creep_force_error'])}, {_pct(reuse['max_normal_force_error'])}, "
                    f"{reuse['errors_above_tolerance']} of {reuse['errors_measured']}"
                )
            lines.append(
                f"| {r['scene']} | {run['duration_s']:g} s | {run['tolerance']:g} | {variant} | {run['status']} | "
                f"{run['real_time_factor']:.3g} | {run['whole_process_real_time_factor']:.3g} | "
                f"{bem['wall_time_s'] / run['wall_time_s']:.3g} | "
                f"{_pct(e['max_normal_diff_over_wheel_load']) if e else '-'} | "
                f"{_pct(e['max_creep_diff_over_peak_bem_creep']) if e else '-'} | "
                f"{_pct(e['max_creep_error_bench_definition']) if e else '-'} | {share or '-'} | "
                f"{cb.get('solves', '-')} | {reuse_text} | {_same_state_text(run.get('same_state'))} |"
            )
    lines += [
        "",
        "Q0: static wheel load. Departures per patch (side, slot) and output sample, contact frame, max over the "
        "run: the normal force over Q0; the creep force vector over the run's largest BEM creep force; and with "
        "the bench's definition, |F_auto - F_bem| / max(|F_bem|, 0.01 mu N_bem) (the number `contact_tolerance` "
        "bounds per patch, on the cases measured). Neither run is exact: these are auto's departures from "
        "always-BEM (BEM on the sampled gap, the loop's grid), not errors against a reference; the two runs' "
        "states also drift apart. The reuse's measured correction error: at each re-solve from inside twice the "
        "trust radius, the value the old anchor would have served against the fresh BEM solution (bench "
        "definition for the creep force, relative for the normal force; summary.json `callback.auto_reuse`). Same "
        "state: auto's recorded per-patch forces against always-BEM's evaluated at auto's own state of each output "
        "sample (WheelsetModel.contact with the BEM: the same patches formed, the trajectories' parting removed), "
        "per patch in contact in both; per rung the largest and the number of patches. A run that stopped "
        "(budget-exceeded: the integrator's wall-time budget, 600 s before this bench raised it) is compared over "
        "the samples it reached, its RTF over the simulated time it reached.",
        "",
        "Verdicts (same state; the reference's spread: auto-no-reuse, i.e. always-BEM evaluated along another path, "
        "against always-BEM at the same states: its element sizes and warm starts differ by path; within when "
        "departure + spread <= tolerance, beyond when departure - spread > tolerance, else undecided):",
        "",
        *verdict_lines(rows),
        "",
    ]
    return lines


if __name__ == "__main__":
    sys.exit(main())
