"""Whole-process time of small contact commands (start-up: imports, loading numba kernels, the solve, the output).

Each command runs ``--runs`` times in a fresh process (warm: numba's disk cache filled by one untimed run first),
interleaved between the trees compared; wall and CPU time (user + system of the child) per run; medians. A tree
other than this one (``--compare DIR``, e.g. an earlier commit unpacked with ``git archive``) runs the same
commands for a before/after table.

Run: ``.venv/bin/python benchmarks/bench_startup.py [--runs 9] [--compare DIR --compare-label LABEL]`` ->
benchmarks/results/startup.json and .md.
"""

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

COMMANDS = {
    "contact hertz-quadric --json": ["-m", "wheelrail.cli", "contact", "hertz-quadric", "--json"],
    "contact hertz-quadric --method hertz --json": [
        "-m", "wheelrail.cli", "contact", "hertz-quadric", "--method", "hertz", "--json",
    ],
    "contact hertz-quadric --method linear --json": [
        "-m", "wheelrail.cli", "contact", "hertz-quadric", "--method", "linear", "--json",
    ],
    "contact hertz-quadric --method bem --json": [
        "-m", "wheelrail.cli", "contact", "hertz-quadric", "--method", "bem", "--json",
    ],
    "python -c pass": ["-c", "pass"],
    "python -c 'import numba, scipy.fft' (the floor with numba)": ["-c", "import numba, scipy.fft"],
    "python -c 'import numpy'": ["-c", "import numpy"],
    "one cached numba kernel (the floor of a compiled command)": [str(ROOT / "benchmarks" / "numba_floor_kernel.py")],
}  # fmt: skip


def run_once(tree: Path, argv: list[str]) -> tuple[float, float, int]:
    """(wall s, CPU s of the child, exit status) of one run of ``python argv`` with ``tree`` first on the path."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, *argv], cwd=tree, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, done.returncode


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=9)
    parser.add_argument("--compare", type=Path, default=None, help="another source tree to time the same way")
    parser.add_argument("--compare-label", default="before")
    parser.add_argument("--label", default="this tree")
    args = parser.parse_args(argv)
    trees = {args.label: ROOT}
    if args.compare is not None:
        trees[args.compare_label] = args.compare.resolve()
    samples = {(label, name): [] for label in trees for name in COMMANDS}
    statuses = {}
    for label, tree in trees.items():  # warm the numba caches and the file cache
        for name, command in COMMANDS.items():
            statuses[(label, name)] = run_once(tree, command)[2]
    load_start = os.getloadavg()
    for _ in range(args.runs):
        for name, command in COMMANDS.items():
            for label, tree in trees.items():
                wall, cpu, code = run_once(tree, command)
                samples[(label, name)].append((wall, cpu))
                statuses[(label, name)] = code
    load_end = os.getloadavg()
    rows = []
    for (label, name), values in samples.items():
        walls, cpus = [v[0] for v in values], [v[1] for v in values]
        rows.append({
            "tree": label,
            "command": name,
            "runs": len(values),
            "exit_status": statuses[(label, name)],
            "wall_median_s": statistics.median(walls),
            "wall_min_s": min(walls),
            "cpu_median_s": statistics.median(cpus),
        })  # fmt: skip
    machine = {
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_start": [round(v, 2) for v in load_start],
        "load_average_end": [round(v, 2) for v in load_end],
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    from rigid_dynamics.files import write_text

    out = ROOT / "benchmarks" / "results"
    write_text(out / "startup.json", json.dumps({"machine": machine, "rows": rows}, indent=2) + "\n")
    lines = [
        "# Whole-process start-up of small contact commands (benchmarks/bench_startup.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs, Python {machine['python']}; load average "
        f"{machine['load_average_start']} at the start, {machine['load_average_end']} at the end (shared machine); "
        f"{machine['date_utc']} UTC; {args.runs} runs per command and tree.",
        "",
        "| command | tree | wall median s | wall min s | CPU median s | exit |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| `{r['command']}` | {r['tree']} | {r['wall_median_s']:.3f} | {r['wall_min_s']:.3f} | "
            f"{r['cpu_median_s']:.3f} | {r['exit_status']} |"
        )
    write_text(out / "startup.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
