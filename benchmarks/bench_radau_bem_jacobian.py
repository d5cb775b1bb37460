"""Radau with the BEM: the Jacobian's velocity columns by forward differences against the creep-force sensitivities.

hunting-conical (its initial lateral offset, 20 m/s, rigid straight track) with ``contact_model = "bem"`` and
``integrator.method = "Radau"`` for ``DURATION_S``: once with every column of drivers.state_jacobian by forward
differences (drivers.sensitivity_velocity_columns switched off for the run), once as the drivers now run it (the six
velocity columns from wheelset.creep_jacobian). Same tolerances; the runs' right-hand-side counts, steps and wall
times side by side, and the difference of their final states against the tolerance (both are Radau solutions to
the same tolerances: the Jacobian changes Newton's convergence, not the solution beyond the tolerance).

Writes benchmarks/results/radau_bem_jacobian.json and .md (about 5 minutes here).
Run: .venv/bin/python benchmarks/bench_radau_bem_jacobian.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import dataclasses  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.files import atomic_write  # noqa: E402
from rigid_dynamics.wheelset import drivers  # noqa: E402
from rigid_dynamics.wheelset.simulate import simulate  # noqa: E402
from wheelrail.scenes import load_scene  # noqa: E402

DURATION_S = 0.01


def run(columns_on: bool) -> dict:
    scene = load_scene("hunting-conical")
    settings = dataclasses.replace(scene.integrator, method="Radau", output_step_s=DURATION_S / 4)
    scene = dataclasses.replace(scene, contact_model="bem", duration_s=DURATION_S, integrator=settings)
    original = drivers.sensitivity_velocity_columns
    if not columns_on:
        drivers.sensitivity_velocity_columns = lambda model: None
    try:
        start = time.perf_counter()
        result = simulate(scene)
        elapsed = time.perf_counter() - start
    finally:
        drivers.sensitivity_velocity_columns = original
    return {
        "velocity_columns": "sensitivities" if columns_on else "forward differences",
        "status": result.status,
        "rhs_evaluations": result.rhs_evaluations,
        "steps": result.steps,
        "wall_time_s": elapsed,
        "run_wall_time_s": result.wall_time_s,
        "final_state": [float(v) for v in result.states[-1][:12]],
        "rtol": settings.relative_tolerance,
        "atol": settings.absolute_tolerance,
    }


def main() -> None:
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "note": "machine shared with other jobs (2 cores, 8 sessions); one run each",
    }
    runs = [run(False), run(True)]
    a, b = (np.array(r["final_state"]) for r in runs)
    scale = runs[0]["atol"] + runs[0]["rtol"] * np.maximum(np.abs(a), np.abs(b))
    ratio = np.abs(a - b) / scale
    spread = float(np.max(ratio))
    worst = int(np.argmax(ratio))
    from rigid_dynamics.wheelset.state import STATE_NAMES

    result = {"machine": machine, "duration_s": DURATION_S, "runs": runs}
    result["final_state_difference_in_tolerances"] = spread
    result["largest_difference"] = {"state": STATE_NAMES[worst], "values": [float(a[worst]), float(b[worst])]}
    out_dir = ROOT / "benchmarks" / "results"
    atomic_write(out_dir / "radau_bem_jacobian.json", lambda p: p.write_text(json.dumps(result, indent=2) + "\n"))
    lines = [
        "# Radau with the BEM: velocity columns by differences or from the creep sensitivities",
        "",
        'Written by `benchmarks/bench_radau_bem_jacobian.py` (hunting-conical, `contact_model = "bem"`, Radau, '
        f"{DURATION_S} s).",
        f"Machine: {machine['platform']}, {machine['processor']}, os.cpu_count() = {machine['cpu_count']}, "
        f"Python {machine['python']}; {machine['note']}.",
        "",
        "| velocity columns | status | right-hand sides | steps | run's wall time [s] | with set-up [s] |",
        "|---|---|---|---|---|---|",
    ]
    for r in runs:
        lines.append(f"| {r['velocity_columns']} | {r['status']} | {r['rhs_evaluations']} | {r['steps']} | "
                     f"{r['run_wall_time_s']:.1f} | {r['wall_time_s']:.1f} |")  # fmt: skip
    w = result["largest_difference"]
    lines += ["", f"Final states differ by {spread:.3g} x (atol + rtol |y|) at most (state by state): "
              f"{w['state']} {w['values'][0]:.6g} against {w['values'][1]:.6g}; the BEM's own tolerance (1e-6 of its "
              "forces) and warm starts make its right-hand side noisy at about that level.",
              "The right-hand-side count excludes the sensitivities' own BEM solves (their time is in the wall "
              "time)."]  # fmt: skip
    atomic_write(out_dir / "radau_bem_jacobian.md", lambda p: p.write_text("\n".join(lines) + "\n"))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
