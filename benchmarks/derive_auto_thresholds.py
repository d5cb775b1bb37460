"""Regenerate ``auto``'s thresholds (rigid_dynamics/contact/data/auto_thresholds.json).

Reads the bench run of ``--bench-csv`` (default: benchmarks/results/bench/bench.csv, the full ``wheelrail bench``
whose tables the README shows), computes the named cases' features, runs the creep sweep (about 20 s) and writes
the thresholds with the identity of the bench run and of this run (comparisons.auto_thresholds).
``--run-bench [--quick]`` runs the tangential rungs of the bench now instead of reading a CSV.

Run: PYTHONPATH=. .venv/bin/python benchmarks/derive_auto_thresholds.py [--bench-csv PATH | --run-bench [--quick]]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from comparisons.auto_thresholds import thresholds_document  # noqa: E402
from rigid_dynamics.contact.auto import THRESHOLDS_PATH  # noqa: E402
from rigid_dynamics.files import write_json  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bench-csv", type=Path, default=ROOT / "benchmarks" / "results" / "bench" / "bench.csv")
    parser.add_argument("--run-bench", action="store_true", help="run the tangential rungs of the bench now")
    parser.add_argument("--quick", action="store_true", help="with --run-bench and for the sweep: the quick grids")
    parser.add_argument("--out", type=Path, default=THRESHOLDS_PATH)
    args = parser.parse_args(argv)
    if not args.run_bench and not args.bench_csv.is_file():
        print(f"wheelrail: error: --bench-csv = {args.bench_csv}: expected a bench CSV file", file=sys.stderr)
        return 2
    csv_arg = None if args.run_bench else args.bench_csv
    if csv_arg is not None:
        try:
            csv_arg = csv_arg.resolve().relative_to(ROOT)
        except ValueError:
            pass
    command = "benchmarks/derive_auto_thresholds.py " + " ".join(argv if argv is not None else sys.argv[1:])
    doc = thresholds_document(csv_arg, quick=args.quick, command=command.strip())
    write_json(args.out, doc)
    levels = doc["levels"]
    for level, rungs in levels.items():
        qualified = [r for r, e in rungs.items() if e["thresholds"] is not None]
        print(f"{float(level):.0%}: " + (", ".join(qualified) or "no rung"))
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
