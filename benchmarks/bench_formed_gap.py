"""The formed patches' undeformed distance on the solvers' element grids: the strip sampler against plane_gap.

A formed patch (rigid_dynamics/contact/wheelset_patches.py, CONTACT's module 1: the static wheelset case's patches,
and the loop's for a gap-solving model) carries its gap as an exact function of the plane point. The BEM and KPEC
evaluate it at their element centres, a regular grid: since 2026-11-30 that grid goes through the loop's strip
sampler (``_grid_gap``: _gap_kernels.sample_grid, each root chained from its neighbour's), other points through
plane_gap's per-point Newton solves. Both solve the same roots; this measures the cost of each and the largest
difference, on every formed patch (both wheels) of ``STATES`` states of curve-flange's held-yaw runs
(benchmarks/bench_flange_rungs.py: frame held at 0, -8 and -12.5 mrad) at grids of 24 and 64 points per side over
the patch's potential contact area (process time, each evaluation repeated ``REPEATS`` times, the first call of each
path excluded: numba's cache loaded).

Whole runs (``wheelrail run curve-flange`` with ``patch_geometry = "formed"``) are compared by the paired
whole-process timings written by hand below the table (farm-bench, the two commits in turn).

Run: PYTHONPATH=. .venv/bin/python benchmarks/bench_formed_gap.py  (writes benchmarks/results/formed_gap.md/.json)
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
OUT = ROOT / "benchmarks" / "results"
ANGLES_RAD = (0.0, -0.008, -0.0125)
STATES = 6
GRIDS = (24, 64)
REPEATS = 3
ANALYSIS_MARK = "## Whole runs"


def measure() -> list[dict]:
    import bench_flange_rungs as rungs

    from rigid_dynamics.contact.search import WheelsetPose
    from rigid_dynamics.wheelset.formed_patches import PatchFormer
    from rigid_dynamics.wheelset.simulate import build_provider

    rows = []
    for frame_yaw in ANGLES_RAD:
        _, states, _ = rungs.flanging_states(frame_yaw, STATES)
        former = PatchFormer(build_provider(rungs.scene_at(frame_yaw, "bem")).surfaces)
        for n in GRIDS:
            totals = {"grid_s": 0.0, "points_s": 0.0, "max_diff_m": 0.0, "finite_mismatch": 0, "patches": 0,
                      "points": 0}  # fmt: skip
            for state in states:
                pose = WheelsetPose(*(float(v) for v in state[:6]))
                for side in ("left", "right"):
                    for patch in former.patches(side, pose):
                        und = patch.geometry.undeformed
                        x0, x1, y0, y1 = und.potential_area_m
                        gx, gy = np.meshgrid(np.linspace(x0, x1, n), np.linspace(y0, y1, n))
                        und.evaluate(gx, gy), und.evaluate(gx[:1].ravel(), gy[:1].ravel())  # caches loaded
                        start = time.process_time()
                        for _ in range(REPEATS):
                            grid = und.evaluate(gx, gy)  # a regular grid: the strip sampler
                        totals["grid_s"] += (time.process_time() - start) / REPEATS
                        start = time.process_time()
                        for _ in range(REPEATS):
                            points = und.evaluate(gx.ravel(), gy.ravel()).reshape(gx.shape)  # plane_gap per point
                        totals["points_s"] += (time.process_time() - start) / REPEATS
                        finite = np.isfinite(grid) & np.isfinite(points)
                        if finite.any():
                            diff = float(np.max(np.abs(grid[finite] - points[finite])))
                            totals["max_diff_m"] = max(totals["max_diff_m"], diff)
                        totals["finite_mismatch"] += int(np.sum(np.isfinite(grid) != np.isfinite(points)))
                        totals["patches"] += 1
                        totals["points"] += n * n
            rows.append({"frame_yaw_rad": frame_yaw, "grid_points": n, **totals})
            print(json.dumps(rows[-1]), flush=True)
    return rows


def write(rows: list[dict]) -> None:
    from rigid_dynamics.files import write_json, write_text

    machine = (f"{platform.node()}, {os.cpu_count()} cores (shared), Python {platform.python_version()}, load "
               f"average {os.getloadavg()[0]:.1f}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")  # fmt: skip
    lines = [
        "# Formed patches' gap on the element grid: strip sampler against plane_gap (benchmarks/bench_formed_gap.py)",
        "",
        (__doc__ or "").split("\n\nRun:")[0],
        "",
        f"Machine: {machine}.",
        "",
        "| held frame yaw | points per side | patches | strip sampler us/point | plane_gap us/point | ratio |"
        " largest difference m | finite at different points |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        per = 1e6 / r["points"]
        lines.append(
            f"| {r['frame_yaw_rad'] * 1e3:.2f} mrad | {r['grid_points']} | {r['patches']} | {r['grid_s'] * per:.3f} | "
            f"{r['points_s'] * per:.3f} | {r['points_s'] / r['grid_s']:.1f} | {r['max_diff_m']:.1e} | "
            f"{r['finite_mismatch']} |"
        )
    path = OUT / "formed_gap.md"
    kept = ""
    if path.exists() and ANALYSIS_MARK in path.read_text(encoding="utf-8"):
        kept = path.read_text(encoding="utf-8").split(ANALYSIS_MARK, 1)[1]
    text = "\n".join(lines) + "\n" + (f"\n{ANALYSIS_MARK}{kept}" if kept else "")
    write_text(path, text)
    write_json(OUT / "formed_gap.json", {"machine": machine, "rows": rows})


if __name__ == "__main__":
    write(measure())
