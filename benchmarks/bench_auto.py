"""``auto`` against always-BEM on embedded dynamics scenes: wall time and force error.

For each scene (shortened: SCENES gives the duration) the run is made twice, with ``contact_model = "auto"``
(the scene's ``contact_tolerance``) and with ``contact_model = "bem"`` (default BEM options), everything else as
in the scene file. Each run is made in its own process (``--one``): the whole-process time (interpreter start,
imports, numba cache loading, scene set-up, run) is measured from outside, the in-process time is
``SimulationResult.wall_time_s`` (static equilibrium, integration, recording).

Force error of auto relative to BEM, per patch (side, slot) and output sample in the patch's contact frame, max
over the run: |N_auto - N_bem| over the static wheel load; |F_t,auto - F_t,bem| (creep force vector) over the
run's largest BEM creep force, and over max(|F_t,bem|, 0.01 mu N_bem) (the bench's creep-force error). Both runs
sample the same output grid (same scene, fixed-step RK4 or the same adaptive tolerances); a run that does not end
"ok" is reported as such.

Writes benchmarks/results/auto_vs_bem.md and auto_vs_bem.json (time series in benchmarks/results/auto_vs_bem_runs/).
Run: PYTHONPATH=. .venv/bin/python benchmarks/bench_auto.py [SCENE ...] [--reuse-bem]
(``--reuse-bem``: keep the always-BEM runs of the last report and their time series; only auto is run again).
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

SCENES = {"hunting-conical": 0.1, "polygonal-wheel": 0.04, "wheel-flat": 0.0135}
"""Embedded scene -> shortened duration, s (wheel-flat: through the first impact at 0.2 m, 12 ms)."""
OUT = ROOT / "benchmarks" / "results"


def run_one(scene_name: str, duration: float, model: str, npz: Path) -> dict:
    """Run one scene with one contact model in this process; save the time series; return the numbers."""
    from rigid_dynamics.wheelset.simulate import save_timeseries, simulate
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    path = resolve_scene_path(scene_name)
    doc = read_toml(path, "scene file")
    doc["duration_s"] = duration
    doc["contact_model"] = model
    scene = parse_scene(doc, base_dir=path.parent)
    start = time.perf_counter()
    result = simulate(scene)
    wall = time.perf_counter() - start
    save_timeseries(result, npz)
    out = {
        "scene": scene_name,
        "model": model,
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
    if "auto_rung" in result.patches:
        from rigid_dynamics.contact.auto import AUTO_RUNGS

        codes = result.patches["auto_rung"]
        codes = codes[np.isfinite(codes)].astype(int)
        out["rung_share"] = {r: float(np.mean(codes == i)) if len(codes) else 0.0 for i, r in enumerate(AUTO_RUNGS)}
    return out


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


def main() -> int:
    if len(sys.argv) >= 2 and sys.argv[1] == "--one":
        scene, duration, model, npz = sys.argv[2], float(sys.argv[3]), sys.argv[4], Path(sys.argv[5])
        print(json.dumps(run_one(scene, duration, model, npz)))
        return 0
    from comparisons.bench import machine
    from rigid_dynamics.files import write_json, write_text

    scratch = OUT / "auto_vs_bem_runs"
    scratch.mkdir(parents=True, exist_ok=True)
    args = sys.argv[1:]
    reuse_bem = "--reuse-bem" in args
    names = [a for a in args if a != "--reuse-bem"] or list(SCENES)
    previous = {}
    if reuse_bem:
        # the always-BEM runs of the last report (the BEM path does not read auto's thresholds)
        previous = {r["scene"]: r["bem"] for r in json.loads((OUT / "auto_vs_bem.json").read_text())["rows"]}
    rows = []
    for scene in names:
        per = {}
        for model in ("auto", "bem"):
            npz = scratch / f"{scene}-{model}.npz"
            if model == "bem" and scene in previous and npz.exists():
                per[model] = {**previous[scene], "reused": True}
                continue
            start = time.perf_counter()
            proc = subprocess.run(
                [sys.executable, __file__, "--one", scene, str(SCENES[scene]), model, str(npz)],
                capture_output=True,
                text=True,
                env={**os.environ, "PYTHONPATH": str(ROOT)},
            )
            whole = time.perf_counter() - start
            if proc.returncode != 0:
                raise SystemExit(f"{scene} {model}: {proc.stderr.strip().splitlines()[-1]}")
            info = json.loads(proc.stdout.strip().splitlines()[-1])
            info["whole_process_s"] = whole
            info["commit"] = subprocess.run(
                ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT
            ).stdout.strip()
            info["machine"] = machine()
            per[model] = info
            print(f"{scene} {model}: {info['status']}, in-process {info['wall_time_s']:.1f} s, whole {whole:.1f} s")
        err = compare(
            scratch / f"{scene}-auto.npz",
            scratch / f"{scene}-bem.npz",
            per["bem"]["static_wheel_load_N"],
            per["auto"]["mu"],
        )
        rows.append({"scene": scene, "auto": per["auto"], "bem": per["bem"], "error": err})
    write_json(OUT / "auto_vs_bem.json", {"machine": machine(), "rows": rows})
    lines = [
        "# `auto` against always-BEM on embedded scenes",
        "",
        f"Machine: {machine()}. Command: `PYTHONPATH=. .venv/bin/python benchmarks/bench_auto.py` "
        "(benchmarks/bench_auto.py). Each run in its own process; in-process time = SimulationResult.wall_time_s "
        "(equilibrium, integration, recording), whole-process = interpreter start to exit (imports, numba cache, "
        "set-up). Durations shortened so that always-BEM finishes in minutes; everything else as in the scene file. "
        "Thresholds: rigid_dynamics/contact/data/auto_thresholds.json.",
        "",
        "Runs: "
        + "; ".join(
            f"{r['scene']} auto at {r['auto'].get('commit', '?')}, BEM at {r['bem'].get('commit', '?')}"
            + (" (reused from the previous report: `--reuse-bem`)" if r["bem"].get("reused") else "")
            for r in rows
        )
        + ".",
        "",
        "| scene | duration | tolerance | driver | auto status | BEM status | auto in-process | BEM in-process | "
        "ratio | auto whole | BEM whole | ratio | max dN / Q0 | max dF_creep / peak BEM creep | max creep error "
        "(bench definition) | auto's rungs |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        a, b, e = r["auto"], r["bem"], r["error"]
        share = ", ".join(f"{k} {100 * v:.0f} %" for k, v in a.get("rung_share", {}).items() if v > 0)

        def driver(run):
            return (
                f"compiled RK4 loop ({run['provider']})" if run["compiled"] else f"scipy / Python ({run['provider']})"
            )

        def pct(v, digits=2):
            return "-" if v is None else f"{100 * v:.{digits}g} %"

        lines.append(
            f"| {r['scene']} | {a['duration_s']:g} s | {a['tolerance']:g} | {driver(a)} | {a['status']} | "
            f"{b['status']} | "
            f"{a['wall_time_s']:.2f} s | {b['wall_time_s']:.2f} s | {a['wall_time_s'] / b['wall_time_s']:.3f} | "
            f"{a['whole_process_s']:.1f} s | {b['whole_process_s']:.1f} s | "
            f"{a['whole_process_s'] / b['whole_process_s']:.3f} | {pct(e['max_normal_diff_over_wheel_load'])} | "
            f"{pct(e['max_creep_diff_over_peak_bem_creep'])} | {pct(e['max_creep_error_bench_definition'])} | "
            f"{share} |"
        )
    lines += [
        "",
        "Q0: static wheel load. Differences per patch (side, slot) and output sample, contact frame, max over the "
        "run: the normal force over Q0; the creep force vector over the run's largest BEM creep force; and with the "
        "bench's definition, |F_auto - F_bem| / max(|F_bem|, 0.01 mu N_bem) (the number `contact_tolerance` "
        "bounds per patch, on the cases measured). Neither run is exact: these are auto's departures from "
        "always-BEM (default BEM grid), not errors against a reference; the two runs' states also drift apart.",
        "",
        "Both runs take the same path: one compiled right-hand side (rigid_dynamics/wheelset/compiled_rhs.py) with "
        "the contact geometry compiled (tables, 3-D search) or given by the provider (conical), auto's choice per "
        "patch and step in the compiled code, linear / Vermeulen-Johnson / FASTSIM inline and BEM through the one "
        "callback (compiled_rhs._external); driver: the compiled RK4 loop for RK4 scenes, scipy's RK45 calling the "
        "same function for hunting-conical.",
        "",
    ]
    write_text(OUT / "auto_vs_bem.md", "\n".join(lines))
    print(f"written {OUT / 'auto_vs_bem.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
