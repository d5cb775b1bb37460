"""Real-time factors of the README's dynamics speed table ("Cost against accuracy"), for a before/after comparison.

Cases: the polygonal-wheel scene on ideal geometry with contact-geometry tables, 2 s, RK4 at 0.5 ms in the compiled
loop with FASTSIM 20 x 20, FASTSIM 15 x 10 and Vermeulen-Johnson; the compiled 3-D search on the polygonal-wheel
scene (0.5 s, 0.5 ms); hunting-conical on scipy's RK45 (Python right-hand side, 1 s). Each case is run once to load
the compiled code, then ``--repeat`` times; the best real-time factor is printed (the machine is shared: the best
is the least disturbed).

Run against another tree (e.g. ``git archive <commit> | tar -x -C /tmp/before``) with ``--root /tmp/before``;
alternate the two trees in one session to compare (benchmarks/results/dynamics_speed_issue15.md).
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from dataclasses import replace
from pathlib import Path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parents[1], help="tree to import")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
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
        best = None
        for _ in range(args.repeat):
            result = simulate(scene, provider=provider)
            if best is None or result.real_time_factor > best.real_time_factor:
                best = result
        per_rhs = 1e6 * best.wall_time_s / best.rhs_evaluations
        print(
            f"{name:40s} real-time factor {best.real_time_factor:8.2f}  {best.rhs_evaluations} RHS  "
            f"{per_rhs:8.2f} us/RHS  compiled={best.compiled} {best.status}",
            flush=True,
        )


if __name__ == "__main__":
    main()
