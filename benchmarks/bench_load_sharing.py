"""Load sharing of the wheelset case with the ``bem`` model: Hertz's split of the wheel load vs the BEM's own.

Manchester benchmark A-2.2 steps (S1002 on UIC60 1:40, 10 kN per wheel, shift k x 0.5 mm, yaw k x 1.2 mrad;
Shackleton & Iwnicki, VSD 46 (2008) 129-149), bem at 40 x 40 elements on the search's default gap field.
For each step, ``solve_wheelset_case`` with ``load_sharing = "hertz"`` (each patch under force control with its
Hertz share) and ``"model"`` (the patches' normal forces from the BEM under approach control, the pose
iterated until each wheel carries W; module docstring of rigid_dynamics/contact/wheelset_case.py):

* wall time of the whole case (search, equilibrium, NORM + TANG per patch), model-phase iterations, roll, and
  the vertical position relative to Hertz sharing (main z points down: + = deeper into the rails);
* error: the equilibrium residual max |sum_k N_k (-n_z,k) / W - 1| over the wheels with the final patches;
* per patch: contact angle, vertical load under both sharings, and (Hertz sharing) the BEM's approach under
  force control relative to the search's rigid approach (0 under model sharing by construction).

Writes benchmarks/results/load_sharing.json and load_sharing.md. Run: .venv/bin/python benchmarks/bench_load_sharing.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from comparisons.manchester import MATERIAL, a22_case  # noqa: E402
from rigid_dynamics.contact.track import build_track  # noqa: E402
from rigid_dynamics.contact.wheelset_case import solve_wheelset_case  # noqa: E402

STEPS = (0, 6, 10, 12, 13, 14, 20)
SHARINGS = ("hertz", "model")


def run() -> dict:
    track = build_track(a22_case(0))
    solve_wheelset_case(a22_case(10), MATERIAL, "bem", track=track)  # compile the numba kernels first
    rows = []
    for step in STEPS:
        case = a22_case(step)
        entry = {"step": step, "lateral_shift_m": case.lateral_shift_m, "yaw_rad": case.yaw_rad}
        solutions = {}
        for sharing in SHARINGS:
            t0 = time.perf_counter()
            sol = solve_wheelset_case(case, MATERIAL, "bem", {"load_sharing": sharing}, track=track)
            elapsed = time.perf_counter() - t0
            solutions[sharing] = sol
            loads = {s: sum(p.vertical_force_N for p in sol.patches if p.side == s) for s in ("left", "right")}
            entry[sharing] = {
                "success": sol.success,
                "message": sol.message,
                "wall_time_s": elapsed,
                "model_iterations": sol.model_iterations,
                "equilibrium_residual": max(abs(v / case.wheel_load_N - 1.0) for v in loads.values()),
                "roll_rad": sol.roll_rad,
                "vertical_position_m": sol.vertical_position_m,
            }
        patches = []
        hertz, model = solutions["hertz"].patches, solutions["model"].patches
        if len(hertz) == len(model) and all(a.side == b.side for a, b in zip(hertz, model, strict=True)):
            for a, b in zip(hertz, model, strict=True):
                patches.append(
                    {
                        "side": a.side,
                        "contact_angle_rad": b.geometry.contact_angle_rad,
                        "is_elliptic": bool(b.geometry.is_elliptic),
                        "vertical_load_hertz_N": a.vertical_force_N,
                        "vertical_load_model_N": b.vertical_force_N,
                        "bem_approach_mismatch_hertz": a.result.approach_m / a.geometry.approach_m - 1.0,
                        "bem_approach_mismatch_model": b.result.approach_m / b.geometry.approach_m - 1.0,
                    }
                )
        else:
            entry["note"] = "the two sharings found different patch sets"
        entry["patches"] = patches
        rows.append(entry)
    return {
        "source": "Manchester A-2.2 steps, bem 40 x 40, default search field; see the script's docstring",
        "machine": {"platform": platform.platform(), "cpu_count": os.cpu_count(), "python": platform.python_version()},
        "steps": rows,
    }


def markdown(result: dict) -> str:
    lines = [
        "# Wheelset-case load sharing with bem: Hertz's split vs the BEM's own (benchmarks/bench_load_sharing.py)",
        "",
        f"Machine: {result['machine']['platform']}, {result['machine']['cpu_count']} CPUs. {result['source']}.",
        "Time: whole case (search + equilibrium + NORM/TANG per patch). Error: max over the wheels of",
        "|sum of the final patches' vertical forces / W - 1|.",
        "",
        "| step | shift mm | sharing | ok | time s | model its | error | roll mrad | z - z(hertz) um |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for e in result["steps"]:
        for s in SHARINGS:
            r = e[s]
            lines.append(
                f"| {e['step']} | {1e3 * e['lateral_shift_m']:.1f} | {s} | {'yes' if r['success'] else 'NO'} | "
                f"{r['wall_time_s']:.3f} | {r['model_iterations']} | {r['equilibrium_residual']:.1e} | "
                f"{1e3 * r['roll_rad']:.4f} | "
                f"{1e6 * (r['vertical_position_m'] - e['hertz']['vertical_position_m']):+.3f} |"
            )
    lines += [
        "",
        "Per patch: vertical load (N) under Hertz and model sharing; the BEM's approach under force control",
        "(Hertz sharing) relative to the search's rigid approach of the wheel.",
        "",
        "| step | side | angle deg | elliptic | Hertz N | model N | model - Hertz N | BEM approach mismatch (Hertz) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for e in result["steps"]:
        for p in e["patches"]:
            lines.append(
                f"| {e['step']} | {p['side']} | {math.degrees(p['contact_angle_rad']):.1f} | "
                f"{'yes' if p['is_elliptic'] else 'no'} | {p['vertical_load_hertz_N']:.1f} | "
                f"{p['vertical_load_model_N']:.1f} | {p['vertical_load_model_N'] - p['vertical_load_hertz_N']:+.1f} | "
                f"{p['bem_approach_mismatch_hertz']:+.2e} |"
            )
        if "note" in e:
            lines.append(f"| {e['step']} | {e['note']} | | | | | | |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    result = run()
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    (out / "load_sharing.json").write_text(json.dumps(result, indent=2))
    (out / "load_sharing.md").write_text(markdown(result))
    print(markdown(result))
