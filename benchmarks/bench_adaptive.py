"""Real-time factor against force error: fixed-step RK4 and the error-controlled embedded pairs (DP54, BS32) of the
compiled loop (rigid_dynamics/wheelset/compiled_loop.py) on the four embedded scenes.

Per scene, a converged reference (RK4 at a fine step; a second reference, DP54 at rtol 1e-7 and atol 1e-10, says
how well it is converged), then RK4 at several steps and DP54 / BS32 at several tolerances. Force error of a run,
relative to the static wheel load N0, from the samples after the scene's settling distance (the measures of
benchmarks/bench_dynamics_steps.py, which are insensitive to the timing of the S1002/UIC60 two-point-contact flips
that make a sample-by-sample comparison meaningless on polygonal-wheel):

* normal: per wheel, the settled peak normal force against the reference's;
* creep: per wheel, the settled mean longitudinal creep force and the settled peak |lateral creep force| against
  the reference's (the larger);
* error = the larger of the two.

Time: ``wall_time_s`` of the run in-process (integration and recording, the compiled code loaded; best of
``--repeat``), as a real-time factor (simulated / wall); and for the fastest run of each method within 1 % the whole
command ``python -m wheelrail.cli run SCENE --no-plots --set ...`` (a new process: imports, scene validation,
provider tables, numba cache load, writing the outputs).

Scenes as embedded (polygonal-wheel and wheel-flat and corrugation on the compiled 3-D search, the last two on the
lumped elastic track: wheel-flat's default is now the discretely supported beam, whose stiffest rail modes bound
every method's step near 0.03 ms; its results here were measured on the lumped track, which TRACKS keeps);
hunting-conical's own provider (conical) has no compiled path, so it runs here on the
contact-geometry tables of its cone (``contact_provider = "tables"``), which the compiled loop runs.
RK4 runs without the half-step check of runs with a wheel lift (``lift_half_step_check = false``: it reruns the
scene, and its cost is not the integrator's).

Run: ``.venv/bin/python benchmarks/bench_adaptive.py`` (``--scenes``, ``--repeat``, ``--render``);
writes benchmarks/results/adaptive.json and adaptive.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.files import write_text  # noqa: E402  (atomic)
from rigid_dynamics.wheelset import build_provider, simulate  # noqa: E402
from wheelrail.scenes import load_scene  # noqa: E402

sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_dynamics_steps import measures  # noqa: E402  (settled peaks per wheel, the step table's measures)

TOLERANCE = 0.01  # the target: force error within 1 % of the static wheel load
CASES = {
    # scene: (provider override, reference step, RK4 steps), s
    "polygonal-wheel": (None, 6.25e-5, (1.25e-4, 2.5e-4, 5e-4, 1e-3)),
    "wheel-flat": (None, 1.25e-5, (2.5e-5, 5e-5, 1e-4, 2e-4, 4e-4)),
    "corrugation": (None, 1.25e-5, (2.5e-5, 5e-5, 1e-4, 2e-4, 4e-4)),
    "hunting-conical": ("tables", 1.25e-4, (2.5e-4, 5e-4, 1e-3)),
}
TRACKS = {"wheel-flat": "lumped"}
"""Track models that differ from the scene's own (wheel-flat: the lumped track these results were measured on)."""
PAIR_TOLERANCES = {  # (relative_tolerance, absolute_tolerance)
    "DP54": ((1e-2, 1e-6), (1e-3, 1e-6), (1e-3, 1e-7), (1e-4, 1e-7), (1e-4, 1e-8), (1e-5, 1e-8), (1e-6, 1e-9)),
    "BS32": ((1e-2, 1e-6), (1e-3, 1e-6), (1e-3, 1e-7), (1e-4, 1e-7), (1e-4, 1e-8), (1e-5, 1e-8), (1e-6, 1e-9)),
}
REFERENCE_2 = ("DP54", 1e-7, 1e-10)


def errors(got, ref, load):
    """(normal, creep) errors relative to the static wheel load (None when a run has no settled samples)."""
    if got is None or ref is None:
        return None, None

    def diff(key):
        return max(abs(a - b) for a, b in zip(got[key], ref[key], strict=True)) / load

    return diff("peak_normal_force_N"), max(diff("mean_creep_force_long_N"), diff("peak_abs_creep_force_lat_N"))


def variant(scene, method, **changes):
    changes.setdefault("lift_half_step_check", False)
    integ = replace(scene.integrator, method=method, **changes)
    if method == "RK4":
        integ = replace(integ, output_step_s=max(integ.fixed_step_s, scene.integrator.output_step_s))
    return replace(scene, integrator=integ)


def best_of(scene, provider, repeat):
    best = None
    for _ in range(repeat):
        result = simulate(scene, provider=provider)
        if best is None or result.wall_time_s < best.wall_time_s:
            best = result
    return best


def whole_process(name, overrides):
    """Wall time of ``python -m wheelrail.cli run NAME --no-plots --set ...`` in a new process, s."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "wheelrail.cli", "run", name, "--no-plots", "--out", str(Path(tmp) / "out")]
        for key, value in overrides.items():
            cmd += ["--set", f"{key}={value}"]
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        start = time.perf_counter()
        done = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - start
        summary = json.loads((Path(tmp) / "out" / "summary.json").read_text()) if done.returncode in (0, 1) else {}
    return {"command": " ".join(cmd[2:4] + cmd[4:5] + cmd[5:6] + cmd[8:]), "exit": done.returncode, "wall_s": wall,
            "status": summary.get("status"), "run_wall_time_s": summary.get("wall_time_s")}  # fmt: skip


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="*", default=list(CASES))
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--render", action="store_true", help="rewrite the .md from the .json")
    parser.add_argument("--processes", action="store_true", help="redo the whole-process runs from the .json")
    args = parser.parse_args(argv)
    out = ROOT / "benchmarks" / "results"
    if args.render or args.processes:
        payload = json.loads((out / "adaptive.json").read_text())
        if args.processes:
            payload["processes"] = []
            for name in dict.fromkeys(r["scene"] for r in payload["runs"]):
                provider_name = CASES[name][0]
                payload["processes"] += whole_processes(payload["runs"], name, provider_name, load_scene(name))
        write(payload)
        return
    records, processes = [], []
    for name in args.scenes:
        provider_name, ref_step, steps = CASES[name]
        base = load_scene(name)
        if name in TRACKS:
            base = replace(base, track_dynamics=replace(base.track_dynamics, model=TRACKS[name]))
        if provider_name:
            base = replace(base, contact_provider=provider_name)
        provider = build_provider(base)
        load = base.static_wheel_load_N
        simulate(replace(variant(base, "DP54"), duration_s=0.01), provider=provider)  # load the compiled code
        reference = simulate(variant(base, "RK4", fixed_step_s=ref_step), provider=provider)
        ref = measures(reference)
        second = simulate(
            variant(base, REFERENCE_2[0], relative_tolerance=REFERENCE_2[1], absolute_tolerance=REFERENCE_2[2]),
            provider=provider,
        )
        runs = [("RK4", {"fixed_step_s": s}) for s in steps]
        for method, tols in PAIR_TOLERANCES.items():
            runs += [(method, {"relative_tolerance": r, "absolute_tolerance": a}) for r, a in tols]
        for method, changes in [("reference-2", None), *runs]:
            if method == "reference-2":
                result, method, changes = second, REFERENCE_2[0], {
                    "relative_tolerance": REFERENCE_2[1], "absolute_tolerance": REFERENCE_2[2]}  # fmt: skip
            else:
                result = best_of(variant(base, method, **changes), provider, args.repeat)
            normal, creep = errors(measures(result), ref, load)
            rec = {
                "scene": name,
                "provider": result.provider,
                "compiled": result.compiled,
                "method": method,
                "settings": changes,
                "reference_2": result is second,
                "status": result.status,
                "message": result.message,
                "normal_error": normal,
                "creep_error": creep,
                "error": None if normal is None else max(normal, creep),
                "rhs_evaluations": result.rhs_evaluations,
                "steps": result.steps,
                "wall_s": result.wall_time_s,
                "real_time_factor": result.real_time_factor,
                "duration_s": base.duration_s,
            }
            records.append(rec)
            print(
                f"{name} {method} {changes}: {rec['status']} normal {normal} creep {creep} RHS "
                f"{rec['rhs_evaluations']} RTF {rec['real_time_factor']:.3g}",
                flush=True,
            )
        processes += whole_processes(records, name, provider_name, base)
    load_avg = os.getloadavg()
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "load_average_at_end": [round(v, 2) for v in load_avg],
        "note": "one process on a 2-core machine shared with other jobs: timings scatter",
    }
    payload = {"benchmark": "adaptive vs fixed-step RK4", "machine": machine, "runs": records, "processes": processes}
    write(payload)


def fastest_within(records, scene, method):
    """The run of ``method`` on ``scene`` with the highest real-time factor among those that end "ok" with a force
    error within TOLERANCE (None when there is none): the setting a user would run and trust."""
    ok = [
        r
        for r in records
        if r["scene"] == scene and r["method"] == method and not r["reference_2"]
        and r["error"] is not None and r["error"] <= TOLERANCE and r["status"] == "ok"
    ]  # fmt: skip
    return max(ok, key=lambda r: r["real_time_factor"]) if ok else None


def whole_processes(records, name, provider_name, base):
    """The whole command for the fastest trusted run of each method on the scene ``name``."""
    processes = []
    for method in ("RK4", *PAIR_TOLERANCES):
        fastest = fastest_within(records, name, method)
        if fastest is None:
            continue
        overrides = {"integrator.method": f'"{method}"', "integrator.lift_half_step_check": "false"}
        if provider_name:
            overrides["contact_provider"] = f'"{provider_name}"'
        if name in TRACKS:
            overrides["track_dynamics.model"] = f'"{TRACKS[name]}"'
        for key, value in fastest["settings"].items():
            overrides[f"integrator.{key}"] = repr(value)
        if method == "RK4":
            overrides["integrator.output_step_s"] = repr(
                max(fastest["settings"]["fixed_step_s"], base.integrator.output_step_s)
            )
        proc = whole_process(name, overrides)
        proc.update(scene=name, method=method, settings=fastest["settings"], in_process_rtf=fastest["real_time_factor"])
        processes.append(proc)
        print(f"whole process {name} {method}: {proc}", flush=True)
    return processes


def write(payload):
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    machine, records, processes = payload["machine"], payload["runs"], payload["processes"]

    def fmt(v, spec=".3g"):
        return "-" if v is None else format(v, spec)

    def setting(r):
        s = r["settings"]
        if r["method"] == "RK4":
            return f"h = {s['fixed_step_s'] * 1e3:g} ms"
        return f"rtol {s['relative_tolerance']:g}, atol {s['absolute_tolerance']:g}"

    lines = [
        "# Real-time factor against force error: fixed-step RK4 and the embedded pairs DP54 / BS32 (compiled loop)",
        "",
        f"Machine: {machine['platform']} ({machine['processor']}), {machine['cpu_count']} CPUs, Python "
        f"{machine['python']}, numpy {machine['numpy']}; {machine['note']} (load average at the end "
        f"{machine['load_average_at_end']}). Script: benchmarks/bench_adaptive.py.",
        "",
        "Errors relative to the static wheel load against RK4 at the finest step (`reference-2`: DP54 at rtol 1e-7, "
        "atol 1e-10 against it, the reference's own uncertainty). normal: settled peak normal force per wheel; "
        "creep: settled mean longitudinal and peak |lateral| creep force per wheel; RTF: simulated time / in-process "
        "wall time (best of the repeats). hunting-conical runs on its cone's tables (its conical provider is not "
        "compiled). The pairs sample at the scene's output step; RK4 at the larger of its step and that (a coarser "
        "RK4 run samples its peaks more sparsely). RK4 runs without, and the pairs' runs without, the rerun of runs "
        "with a wheel lift (lift_half_step_check). 'Fastest': among the runs that end ok within 1 %.",
        "",
    ]
    for scene in dict.fromkeys(r["scene"] for r in records):
        rows = [r for r in records if r["scene"] == scene]
        lines += [
            f"## {scene} ({rows[0]['provider']}, {rows[0]['duration_s']:g} s simulated)",
            "",
            "| method | setting | status | normal error | creep error | RHS | steps | wall s | RTF | within 1 % |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in rows:
            method = "reference-2 (DP54)" if r["reference_2"] else r["method"]
            within = "-" if r["error"] is None else ("yes" if r["error"] <= TOLERANCE else "no")
            lines.append(
                f"| {method} | {setting(r)} | {r['status']} | {fmt(r['normal_error'])} | {fmt(r['creep_error'])} | "
                f"{r['rhs_evaluations']} | {r['steps']} | {r['wall_s']:.3f} | {fmt(r['real_time_factor'])} | "
                f"{within} |"
            )
        best = {m: fastest_within(records, scene, m) for m in ("RK4", *PAIR_TOLERANCES)}
        best = {m: r for m, r in best.items() if r is not None}
        lines += ["", "Fastest with status ok and within 1 %: " + "; ".join(
            f"{m} {setting(r)}: RTF {r['real_time_factor']:.3g}" for m, r in best.items()) + ".", ""]  # fmt: skip
    if processes:
        lines += [
            "## Whole process (the fastest setting of each method with status ok within 1 %)",
            "",
            "| scene | method | setting | command wall s | run wall_time_s | in-process RTF | status |",
            "|---|---|---|---|---|---|---|",
        ]
        for p in processes:
            setting_text = setting({"method": p["method"], "settings": p["settings"]})
            lines.append(
                f"| {p['scene']} | {p['method']} | {setting_text} | {p['wall_s']:.2f} | {fmt(p['run_wall_time_s'])} | "
                f"{fmt(p['in_process_rtf'])} | {p['status']} |"
            )
        lines.append("")
    for fname, text in (
        ("adaptive.json", json.dumps(payload, indent=2) + "\n"),
        ("adaptive.md", "\n".join(lines) + "\n"),
    ):
        write_text(out / fname, text)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
