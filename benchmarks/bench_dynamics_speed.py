"""Real-time factors of the README's dynamics speed table ("Cost against accuracy"), for a before/after comparison.

Cases: the polygonal-wheel scene on ideal geometry with contact-geometry tables, 2 s, RK4 at 0.5 ms in the compiled
loop with FASTSIM 20 x 20, FASTSIM 15 x 10 and Vermeulen-Johnson; the compiled 3-D search on the polygonal-wheel
scene (0.5 s, 0.5 ms); hunting-conical on scipy's RK45 (Python right-hand side, 1 s). Each case is run once to load
the compiled code, then ``--repeat`` times; the best real-time factor is printed (the machine is shared: the best
is the least disturbed), with the CPU time of the run (``time.process_time``), which a loaded machine disturbs
less than the wall time.

``--trees A B C --rounds N``: run this script once per tree and round, the trees interleaved (A B C, B C A, ...),
and print each case's best CPU time per tree and its ratio to the first tree's (the machine's load is printed per
round); ``--cold``: before the rounds, a cold compile of each tree (``python -m wheelrail.warmup`` with the tree's
numba cache removed), its user CPU time (benchmarks/results/compile_and_speed_issue25.md).

Run against another tree (e.g. ``git archive <commit> | tar -x -C /tmp/before``) with ``--root /tmp/before``;
alternate the two trees in one session to compare (benchmarks/results/dynamics_speed_issue15.md).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time
import tomllib
from dataclasses import replace
from pathlib import Path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parents[1], help="tree to import")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--trees", type=Path, nargs="+", help="compare these trees, interleaved (first: reference)")
    parser.add_argument("--rounds", type=int, default=3, help="rounds of --trees")
    parser.add_argument("--cold", action="store_true", help="with --trees: a cold compile of each tree first")
    args = parser.parse_args(argv)
    if args.trees:
        return compare(args.trees, args.rounds, args.repeat, args.cold)
    sys.path.insert(0, str(args.root))
    from rigid_dynamics.wheelset import DynamicsScene, Irregularities, build_provider, simulate
    from wheelrail.config import build_dataclass

    def load(name):
        with open(args.root / "wheelrail" / "scenes" / f"{name}.toml", "rb") as handle:
            return build_dataclass(DynamicsScene, tomllib.load(handle))

    polygon, hunting = load("polygonal-wheel"), load("hunting-conical")
    ideal = replace(polygon, irregularities=Irregularities(), duration_s=2.0)
    tables = build_provider(replace(ideal, contact_provider="tables"))
    cases = [
        ("tables-ideal fastsim 20x20 0.5 ms", ideal, tables),
        ("tables-ideal fastsim 15x10 0.5 ms", replace(ideal, fastsim_elements_per_strip=15, fastsim_strips=10), tables),
        ("tables-ideal vermeulen-johnson 0.5 ms", replace(ideal, contact_model="vermeulen-johnson"), tables),
        ("search-compiled fastsim 0.5 ms (0.5 s)", replace(polygon, duration_s=0.5), None),
        ("hunting-conical RK45 Python (1 s)", replace(hunting, duration_s=1.0), None),
    ]
    for name, scene, provider in cases:
        simulate(replace(scene, duration_s=0.01), provider=provider)
        best, best_cpu = None, float("inf")
        for _ in range(args.repeat):
            start = time.process_time()
            result = simulate(scene, provider=provider)
            best_cpu = min(best_cpu, time.process_time() - start)
            if best is None or result.real_time_factor > best.real_time_factor:
                best = result
        per_rhs = 1e6 * best.wall_time_s / best.rhs_evaluations
        print(
            f"{name:40s} real-time factor {best.real_time_factor:8.2f}  {best.rhs_evaluations} RHS  "
            f"{per_rhs:8.2f} us/RHS  cpu {best_cpu:.4f} s  compiled={best.compiled} {best.status}",
            flush=True,
        )


def _cold_compile(tree: Path) -> float:
    """User CPU seconds of ``python -m wheelrail.warmup`` in ``tree`` with its numba cache removed."""
    for folder in (tree / "rigid_dynamics", tree / "wheelrail"):
        for path in folder.rglob("*.nb[ic]"):
            path.unlink()
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    env = dict(os.environ, PYTHONPATH=str(tree))
    subprocess.run([sys.executable, "-m", "wheelrail.warmup"], cwd=tree, env=env, check=True, capture_output=True)
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def compare(trees, rounds, repeat, cold):
    """This script on each tree in turn (rotated each round), best CPU time per case and tree, ratios to trees[0]."""
    if cold:
        for tree in trees:
            cpu = _cold_compile(tree)
            print(f"cold compile {tree}: {cpu:.1f} s user CPU, load {os.getloadavg()[0]:.1f}", flush=True)
    best = {}
    for k in range(rounds):
        for tree in trees[k % len(trees) :] + trees[: k % len(trees)]:
            print(f"round {k} {tree} load {os.getloadavg()[0]:.1f}", flush=True)
            run = subprocess.run(
                [sys.executable, __file__, "--root", str(tree), "--repeat", str(repeat)],
                capture_output=True,
                text=True,
                check=True,
            )
            for line in run.stdout.splitlines():
                print("  " + line, flush=True)
                name, cpu = line[:40].strip(), float(line.split(" cpu ")[1].split()[0])
                best.setdefault(name, {}).setdefault(tree, []).append(cpu)
    print(f"{'case':40s} " + " ".join(f"{t.name:>22s}" for t in trees) + "  (best CPU s [worst round's best]; ratio)")
    for name, per_tree in best.items():
        ref = min(per_tree[trees[0]])
        cells = [f"{min(v):.4f} [{max(v):.4f}] {min(v) / ref:.3f}" for v in (per_tree[t] for t in trees)]
        print(f"{name:40s} " + " ".join(f"{c:>22s}" for c in cells), flush=True)


if __name__ == "__main__":
    main()
