"""Cold compile of the dynamics kernels before and after the friction laws entered them (issue 26).

The compiled loop carries every law (the law is chosen at run time), so one short run compiles them all: a
Coulomb scene (hunting-conical on the contact tables with FASTSIM, 0.02 s) in a fresh process with an empty numba
cache (NUMBA_CACHE_DIR a new temporary folder), then once more with the cache filled (warm). The tree compared
(``--compare DIR``, e.g. the commit before, unpacked with ``git archive``) runs the same. Wall and CPU time (user +
system of the child process).

Run: ``.venv/bin/python benchmarks/bench_friction_compile.py --compare DIR [--compare-label LABEL]`` ->
benchmarks/results/friction_compile.json and .md.
"""

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.files import write_text  # noqa: E402

CODE = """
from dataclasses import replace
from wheelrail.scenes import load_scene
from rigid_dynamics.wheelset import simulate
scene = replace(load_scene("hunting-conical"), contact_provider="tables", contact_model="fastsim", duration_s=0.02)
result = simulate(scene)
assert result.status == "ok", result.message
print(repr(float(result.states[-1, 1])))
"""


def timed(tree: Path, cache: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=cache)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", CODE], cwd=tree, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall_s": wall, "cpu_s": cpu, "final_lateral_m": float(out.stdout.strip().splitlines()[-1])}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--compare", type=Path, required=True)
    parser.add_argument("--compare-label", default="before")
    args = parser.parse_args()
    rows = {}
    for label, tree in ((args.compare_label, args.compare.resolve()), ("this tree", ROOT)):
        with tempfile.TemporaryDirectory(prefix="numba_cold_") as cache:
            rows[label] = {"cold": timed(tree, cache), "warm": timed(tree, cache)}
        print(label, rows[label], flush=True)
    data = {
        "rows": rows,
        "machine": {"platform": platform.platform(), "cpu_count": os.cpu_count(), "python": platform.python_version(),
                    "load_average_1min_end": os.getloadavg()[0]},
    }  # fmt: skip
    out = ROOT / "benchmarks" / "results"
    write_text(out / "friction_compile.json", json.dumps(data, indent=2) + "\n")
    lines = [
        "# Cold compile of the dynamics kernels with the friction laws (benchmarks/bench_friction_compile.py)",
        "",
        "hunting-conical on the tables with FASTSIM, 0.02 s, in a fresh process: cold (empty numba cache) and warm "
        "(cache filled). The same final lateral displacement in both trees shows the same physics (Coulomb).",
        "",
        "| tree | cold wall (s) | cold CPU (s) | warm wall (s) | warm CPU (s) | final y (m) |",
        "|---|---|---|---|---|---|",
    ]
    for label, r in rows.items():
        c, w = r["cold"], r["warm"]
        lines.append(
            f"| {label} | {c['wall_s']:.1f} | {c['cpu_s']:.1f} | {w['wall_s']:.1f} | {w['cpu_s']:.1f} | "
            f"{c['final_lateral_m']!r} |"
        )
    m = data["machine"]
    lines += [
        "",
        f"Machine: {m['platform']}, {m['cpu_count']} CPUs, Python {m['python']}; shared with other jobs (1-min load "
        f"average {m['load_average_1min_end']:.2f} at the end): the two trees ran one after the other, not "
        "interleaved, so their ratio carries the machine's noise.",
        "",
    ]
    write_text(out / "friction_compile.md", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
