"""The BEM's in-process time on Manchester A-2.2 before and after a change, with the change in the results.

Work: ``comparisons.manchester.sweep("bem")`` (21 steps x 2 wheels, CONTACT's 0.2 mm elements, the vertical
position balanced, the final patches with their grid-error estimate), timed in process after a warm-up
(``sweep("bem", steps=[0, 10])``), one thread. Each code version is a checkout given by its root (the
``before`` and ``after`` roots on the command line); the runs alternate (before, after, before, ...) so that the
ratio of one pair sees the same load on the shared machine. Error: the largest relative difference over every
float the sweep records (forces, creepages, pressures, areas, positions) between the two versions' rows.

Run: ``python benchmarks/bench_bem_speed_a22.py BEFORE_ROOT AFTER_ROOT [PAIRS]`` ->
benchmarks/results/bem_speed_a22.json and .md.
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"

CHILD = r"""
import json, os, sys, time
from comparisons.manchester import sweep
sweep("bem", steps=[0, 10])
t0, c0 = time.perf_counter(), time.process_time()
rows = sweep("bem")
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
floats = [[k, r[k]] for r in rows for k in sorted(r) if isinstance(r[k], float)]
json.dump({"wall_s": wall, "cpu_s": cpu, "floats": floats, "load": os.getloadavg()[0]}, open(sys.argv[1], "w"))
"""


def run(root: Path, out: Path) -> dict:
    env = dict(os.environ)
    env.update({k: "1" for k in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS")})
    env["PYTHONPATH"] = str(root)
    subprocess.run([sys.executable, "-c", CHILD, str(out)], cwd=root, env=env, check=True)
    return json.loads(out.read_text())


def commit(root: Path) -> str:
    return subprocess.run(
        ["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()


def largest_difference(a: list, b: list) -> float:
    if len(a) != len(b) or any(x[0] != y[0] for x, y in zip(a, b, strict=True)):
        return math.inf
    worst = 0.0
    for (_, x), (_, y) in zip(a, b, strict=True):
        if math.isnan(x) and math.isnan(y):
            continue
        scale = max(abs(x), abs(y))
        if scale > 0:
            worst = max(worst, abs(x - y) / scale)
    return worst


def main() -> None:
    before, after = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
    pairs = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    tmp = Path(tempfile.mkdtemp(prefix="bem-speed-"))
    rows = []
    for i in range(pairs):
        b = run(before, tmp / f"b{i}.json")
        a = run(after, tmp / f"a{i}.json")
        rows.append({"before": b, "after": a})
        print(
            f"pair {i}: before {b['cpu_s']:.2f} s CPU, after {a['cpu_s']:.2f} s CPU (load {a['load']:.1f})", flush=True
        )
    diff = max(largest_difference(r["before"]["floats"], r["after"]["floats"]) for r in rows)
    summary = {
        "before": {"root": str(before), "commit": commit(before)},
        "after": {"root": str(after), "commit": commit(after)},
        "pairs": [
            {side: {k: r[side][k] for k in ("wall_s", "cpu_s", "load")} for side in ("before", "after")} for r in rows
        ],
        "cpu_ratio_median": statistics.median(r["after"]["cpu_s"] / r["before"]["cpu_s"] for r in rows),
        "largest_relative_difference": diff,
        "floats_compared": len(rows[0]["after"]["floats"]),
        "cpu_count": os.cpu_count(),
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "bem_speed_a22.json").write_text(json.dumps(summary, indent=2) + "\n")
    lines = [
        "# BEM in process on Manchester A-2.2: before / after (benchmarks/bench_bem_speed_a22.py)",
        "",
        "`sweep('bem')` (21 steps x 2 wheels, 0.2 mm elements, vertical position balanced, final patches with "
        "their grid-error estimate) in process after a warm-up, one thread, alternating runs of the two versions "
        f"on a shared 2-core machine. before = {summary['before']['commit']}, after = {summary['after']['commit']}.",
        "",
        "| pair | before CPU s | after CPU s | after / before | load (1 min) |",
        "|---|---|---|---|---|",
    ]
    for i, p in enumerate(summary["pairs"]):
        lines.append(
            f"| {i} | {p['before']['cpu_s']:.2f} | {p['after']['cpu_s']:.2f} | "
            f"{p['after']['cpu_s'] / p['before']['cpu_s']:.2f} | {p['after']['load']:.1f} |"
        )
    lines += [
        "",
        f"Median CPU ratio after / before: {summary['cpu_ratio_median']:.2f}. Error: the largest relative "
        f"difference over the {summary['floats_compared']} recorded floats is {diff:.1e} (0: bit-identical).",
    ]
    (RESULTS / "bem_speed_a22.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
