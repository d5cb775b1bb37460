"""Whole-process time of small contact commands (start-up: imports, loading numba kernels, the solve, the output).

Each command runs ``--runs`` times in a fresh process (warm: numba's disk cache and Python's bytecode cache filled by
one untimed run first), interleaved between the trees compared; wall and CPU time (user + system of the child) per
run; medians and minima. Python's bytecode goes to a cache of this run (``PYTHONPYCACHEPREFIX``, outside the trees),
as an installed copy has it; the row marked "no .pyc" runs with ``PYTHONDONTWRITEBYTECODE=1`` and no bytecode of the
project (every module of ours compiled from source, as in a session whose environment sets it). The floors (Python,
numpy, numba, one cached kernel) run once per round, with the first tree. A tree other than this one (``--compare
DIR``, e.g. an earlier commit unpacked with ``git archive``) runs the same commands for a before/after table.

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
import tempfile
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
    "contact hertz-quadric --json (no .pyc)": ["-m", "wheelrail.cli", "contact", "hertz-quadric", "--json"],
    "python -c pass": ["-c", "pass"],
    "python -c 'import numpy'": ["-c", "import numpy"],
    "python -c 'import numba'": ["-c", "import numba"],
    "python -c 'import numba, scipy.linalg'": ["-c", "import numba, scipy.linalg"],
    "python -c 'import numba, scipy.fft' (the floor with numba)": ["-c", "import numba, scipy.fft"],
    "one cached numba kernel (the floor of a compiled command)": [str(ROOT / "benchmarks" / "numba_floor_kernel.py")],
    "one cached numba kernel, collector frozen at exit (as wheelrail contact)": [
        str(ROOT / "benchmarks" / "numba_floor_kernel.py"), "--freeze-at-exit",
    ],
}  # fmt: skip
FLOORS = {name for name in COMMANDS if not name.startswith("contact")}
"""Commands that do not depend on the tree: run with the first tree only."""
NO_PYC = {name for name in COMMANDS if "(no .pyc)" in name}
"""Commands run with ``PYTHONDONTWRITEBYTECODE=1`` and no bytecode cache of the project."""
PYCACHE = Path(tempfile.mkdtemp(prefix="bench_startup_pycache_"))
NOTES_MARKER = "## Analysis (written by hand"


def run_once(tree: Path, argv: list[str], bytecode: bool = True) -> tuple[float, float, int]:
    """(wall s, CPU s of the child, exit status) of one run of ``python argv`` with ``tree`` first on the path;
    ``bytecode``: Python's bytecode cached (in this run's cache for the tree), else none of the project's."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "PYTHONPYCACHEPREFIX")}
    env["PYTHONPATH"] = str(tree)
    if bytecode:
        env["PYTHONPYCACHEPREFIX"] = str(PYCACHE)  # mirrors absolute paths: one cache serves every tree
    else:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
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
    first = next(iter(trees))
    pairs = [(label, name) for name in COMMANDS for label in trees if label == first or name not in FLOORS]
    samples = {pair: [] for pair in pairs}
    statuses = {}
    for label, name in pairs:  # warm the numba caches, the bytecode cache and the file cache
        statuses[(label, name)] = run_once(trees[label], COMMANDS[name], name not in NO_PYC)[2]
    load_start = os.getloadavg()
    for _ in range(args.runs):
        for label, name in pairs:
            wall, cpu, code = run_once(trees[label], COMMANDS[name], name not in NO_PYC)
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
    previous = (out / "startup.md").read_text() if (out / "startup.md").is_file() else ""
    if NOTES_MARKER in previous:  # the analysis written by hand below the table is kept (update it for the run)
        lines += ["", NOTES_MARKER + previous.split(NOTES_MARKER, 1)[1].rstrip()]
    write_text(out / "startup.md", "\n".join(lines) + "\n")
    print("\n".join(lines))
    import shutil

    shutil.rmtree(PYCACHE, ignore_errors=True)


if __name__ == "__main__":
    main()
