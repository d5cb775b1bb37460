"""FASTSIM's creep-force table against FASTSIM itself (benchmarks/results/creep_table.md|json).

1. The table: built into an empty cache folder (build time, size, the file), loaded back from the file.
2. A seeded random sample of patches and creepages (rigid_dynamics.contact.creep_table.sample_patches: |c*| log-uniform
   in [0.01, 10] in Kalker's normalisation with its direction uniform on the sphere, a/b log-uniform in [0.1, 10],
   sqrt(ab) 2-15 mm, N 10-150 kN, mu 0.1-0.6): the table's departure from FASTSIM at the same grid (20 x 20,
   elliptic bound, blended flexibilities), max and rms of |F_table - F_fastsim| / (mu N) and of the spin moment's
   |M_table - M_fastsim| / (mu N sqrt(ab)); the time per evaluation of each (best of 5 passes over the sample, one
   process).
3. Dynamics: scenes run with contact_model "fastsim" and "table" in one process (the compiled loop; each run twice,
   the faster kept): real-time factors and their ratio; the departure of the per-wheel contact forces (main frame)
   between the two runs relative to the static wheel load: the max over the run (the start-up's two-point contact
   flips part the runs as a change of step does) and the max and rms after the scene's settling distance; and the
   table's departure from FASTSIM on the table run's own settled patches (wheelset.discretisation.contact_grid_error:
   FASTSIM re-evaluated on the recorded patches).

Run: PYTHONPATH=. .venv/bin/python benchmarks/bench_creep_table.py [--points 500] [--seed 1]
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

from rigid_dynamics.files import write_text  # noqa: E402

SCENES = (("polygonal-wheel", 2.0), ("curve", 6.0))
"""(scene, simulated seconds) of the dynamics comparison: the compiled 3-D search and the compiled geometry tables."""


def table_part(points: int, seed: int) -> dict:
    from rigid_dynamics.contact import creep_table as ct

    with tempfile.TemporaryDirectory() as folder:
        os.environ["WHEELRAIL_CACHE_DIR"] = folder
        built = ct.creep_table(0.28)
        ct._creep_table.cache_clear()
        start = time.perf_counter()
        loaded = ct.creep_table(0.28)
        load_s = time.perf_counter() - start
        file_bytes = loaded.path.stat().st_size if loaded.path else 0
    del os.environ["WHEELRAIL_CACHE_DIR"]
    sample = ct.sample_patches(points, seed, 0.28)
    errors = ct.compare_with_source(loaded.table, ct.SourceOptions(), sample, repeats=5)
    return {
        "grid": dict(ct.GRID._asdict()),
        "nodes": int(np.prod(loaded.table.values.shape[:4])),
        "build_status": built.status,
        "build_time_s": built.build_time_s,
        "load_status": loaded.status,
        "load_time_s": load_s,
        "values_bytes": loaded.size_bytes,
        "file_bytes": file_bytes,
        "points": points,
        "seed": seed,
        "max_force_error_rel_mu_N": errors.max_force_error,
        "rms_force_error_rel_mu_N": errors.rms_force_error,
        "p99_force_error_rel_mu_N": float(np.quantile(errors.force_error, 0.99)),
        "max_relative_force_error": errors.max_relative_force_error,
        "rms_relative_force_error": errors.rms_relative_force_error,
        "p99_relative_force_error": float(np.quantile(errors.relative_force_error, 0.99)),
        "max_moment_error_rel_mu_N_sqrt_ab": errors.max_moment_error,
        "rms_moment_error_rel_mu_N_sqrt_ab": errors.rms_moment_error,
        "fastsim_us_per_evaluation": 1e6 * errors.source_time_s,
        "table_us_per_evaluation": 1e6 * errors.table_time_s,
    }


def dynamics_part(name: str, duration: float) -> dict:
    from rigid_dynamics.wheelset.discretisation import contact_grid_error
    from rigid_dynamics.wheelset.simulate import simulate
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = replace(load_scene(resolve_scene_path(name)), duration_s=duration)
    runs = {}
    for _ in range(2):
        for model in ("fastsim", "table"):
            r = simulate(replace(scene, contact_model=model), compiled=True, companions=False)
            if model not in runs or r.wall_time_s < runs[model].wall_time_s:
                runs[model] = r
    fs, tb = runs["fastsim"], runs["table"]
    q0 = scene.static_wheel_load_N
    n = min(len(fs.t), len(tb.t))
    diff = np.abs(tb.contact_force_N[:n] - fs.contact_force_N[:n]) / q0
    grid = contact_grid_error(tb)
    return {
        "scene": name,
        "duration_s": duration,
        "status_fastsim": fs.status,
        "status_table": tb.status,
        "real_time_factor_fastsim": fs.real_time_factor,
        "real_time_factor_table": tb.real_time_factor,
        "rtf_ratio_table_over_fastsim": tb.real_time_factor / fs.real_time_factor,
        "max_wheel_force_departure_rel_Q0": float(np.max(diff)),
        "max_wheel_force_departure_at_s": float(tb.t[int(np.argmax(np.max(diff, axis=(1, 2))))]),
        "settled_max_wheel_force_departure_rel_Q0": float(np.max(diff[tb.settled[:n]])),
        "settled_rms_wheel_force_departure_rel_Q0": float(np.sqrt(np.mean(diff[tb.settled[:n]] ** 2))),
        "table_departure_same_patches_rel_Q0": grid.get("table_departure"),
        "same_patch_samples": grid.get("samples"),
        "fastsim_grid_estimate_rel_Q0": grid.get("estimate"),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=500)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    table = table_part(args.points, args.seed)
    print(json.dumps(table), flush=True)
    rows = []
    for name, duration in SCENES:
        rows.append(dynamics_part(name, duration))
        print(json.dumps(rows[-1]), flush=True)
    write(table, rows)
    return 0


def write(table: dict, rows: list) -> None:
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "load_1min": os.getloadavg()[0],
    }
    summary = {"commit": commit.stdout.strip(), "machine": machine, "table": table, "dynamics": rows}
    out = ROOT / "benchmarks" / "results"
    write_text(out / "creep_table.json", json.dumps(summary, indent=2) + "\n")
    t = table
    g = t["grid"]
    lines = [
        "# FASTSIM's creep-force table against FASTSIM (benchmarks/bench_creep_table.py)",
        "",
        f"Commit {summary['commit']}; machine: {machine['platform']}, {machine['processor']}, {machine['cpu_count']} "
        f"cores shared with other work (load {machine['load_1min']:.1f}), Python {machine['python']}, one thread. "
        "Times are noisy here: compare the ratios measured in one run.",
        "",
        "## The table",
        "",
        f"Source: FASTSIM 20 x 20, elliptic bound, blended flexibilities, nu = 0.28, Coulomb friction. Grid: "
        f"{g['magnitude_points']} (s = 1 - sqrt(1 - rho), rho = r/(1+r)) x {g['longitude_points']} (longitude) x "
        f"{g['latitude_points']} (latitude) x {g['shape_points']} (ln a/b in +-{g['max_log_ratio']:.3g}) = "
        f"{t['nodes']} nodes; "
        f"values {t['values_bytes'] / 1e6:.1f} MB (float32), file {t['file_bytes'] / 1e6:.1f} MB. "
        f"Build {t['build_time_s']:.1f} s (status {t['build_status']}, numba's compiled kernels from its cache); "
        f"load from the file {t['load_time_s']:.2f} s.",
        "",
        "## Interpolation error (the table against FASTSIM at the same grid)",
        "",
        f"{t['points']} random points (seed {t['seed']}; the sample of the script's docstring):",
        "",
        "| quantity | max | 99 % | rms |",
        "|---|---|---|---|",
        f"| creep-force vector / (mu N) | {t['max_force_error_rel_mu_N']:.4f} | {t['p99_force_error_rel_mu_N']:.4f} | "
        f"{t['rms_force_error_rel_mu_N']:.4f} |",
        f"| creep-force vector / max(F, 0.01 mu N) (relative) | {t['max_relative_force_error']:.4f} | "
        f"{t['p99_relative_force_error']:.4f} | {t['rms_relative_force_error']:.4f} |",
        f"| spin moment / (mu N sqrt(ab)) | {t['max_moment_error_rel_mu_N_sqrt_ab']:.4f} | | "
        f"{t['rms_moment_error_rel_mu_N_sqrt_ab']:.4f} |",
        "",
        f"Time per evaluation (the whole patch: normalisation, interpolation, scaling back): table "
        f"{t['table_us_per_evaluation']:.3f} us, FASTSIM {t['fastsim_us_per_evaluation']:.3f} us "
        f"(ratio {t['fastsim_us_per_evaluation'] / t['table_us_per_evaluation']:.1f}).",
        "",
        '## Dynamics (contact_model "table" against "fastsim", compiled RK4 loop, one process)',
        "",
        "| scene | simulated s | status fastsim / table | RTF fastsim | RTF table | ratio | wheel-force departure / "
        "Q0: max over the run; max, rms after the settling distance | table vs FASTSIM on the table run's patches / Q0 "
        "| FASTSIM grid estimate "
        "+ table / Q0 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        same = r["table_departure_same_patches_rel_Q0"]
        est = r["fastsim_grid_estimate_rel_Q0"]
        same_text = "n/a" if same is None else f"{same:.3g} ({r['same_patch_samples']} patches)"
        lines.append(
            f"| {r['scene']} | {r['duration_s']:g} | {r['status_fastsim']} / {r['status_table']} | "
            f"{r['real_time_factor_fastsim']:.3g} | {r['real_time_factor_table']:.3g} | "
            f"{r['rtf_ratio_table_over_fastsim']:.2f} | {r['max_wheel_force_departure_rel_Q0']:.3g} "
            f"(t = {r['max_wheel_force_departure_at_s']:.3g} s); "
            f"{r['settled_max_wheel_force_departure_rel_Q0']:.3g}, "
            f"{r['settled_rms_wheel_force_departure_rel_Q0']:.3g} | "
            f"{same_text} | "
            f"{'n/a' if est is None else f'{est:.3g}'} |"
        )
    lines += [
        "",
        "RTF: simulated seconds per wall second of the loop (SimulationResult.real_time_factor, the faster of two "
        "runs). The table speeds up the contact law only; in these scenes the contact geometry (3-D search, "
        "tables) and the integrator take most of a right-hand side, which bounds the ratio. The max over the run is in "
        "the start-up (the first 10 m), where the two runs' two-point contact flips part them for a while "
        "(polygonal-wheel: by more than 10 % of Q0 over t = 0.1-0.27 s), as a change of step does there "
        "(benchmarks/results/step_sensitivity.md); after the settling distance they agree as the next columns say.",
    ]
    write_text(out / "creep_table.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
