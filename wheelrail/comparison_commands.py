"""The ``bench`` and ``compare`` commands (registered in :mod:`wheelrail.cli` by :func:`register`).

    wheelrail bench [--quick] [--cases NAME ...] [--models NAME ...] [--out DIR]
    wheelrail compare CASE [--models NAME ...] [--out DIR]

CASE / NAME: a named case of ``comparisons/cases/`` (``wheelrail bench --list``) or a folder holding
``case.toml`` and ``reference.toml``. Bad names end with ``wheelrail: error: ...`` (exit 2).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from wheelrail.config import ConfigError


def _check_models(models, allowed) -> list[str]:
    models = list(models or allowed)
    for name in models:
        if name not in allowed:
            raise ConfigError(f"--models {name!r}: expected some of {', '.join(allowed)}")
    return models


def _bar(total: int, label: str):
    """A tqdm bar on a terminal (None elsewhere) and a callback advancing it."""
    from tqdm import tqdm

    bar = tqdm(total=total, desc=label, unit="run", leave=False, disable=not sys.stderr.isatty())

    def update(done: int, total: int, text: str) -> None:
        bar.set_postfix_str(text[:40], refresh=False)
        bar.update(done - bar.n)

    return bar, update


def cmd_bench(args) -> int:
    from comparisons.bench import MODELS, bench_plan, run_bench, write_bench
    from wheelrail.named_cases import load_named_cases, named_case_names
    from wheelrail.output import new_output_dir

    if args.list:
        for name in named_case_names():
            print(name)
        return 0
    models = _check_models(args.models, MODELS)
    cases = load_named_cases(args.cases)
    out_dir = new_output_dir(args.out, "bench-quick" if args.quick else "bench")
    bar, update = _bar(len(bench_plan(cases, models, args.quick)), "bench")
    start = time.perf_counter()
    try:
        runs = run_bench(cases, models, args.quick, progress=update)
    finally:
        bar.close()
    summary = write_bench(runs, cases, out_dir, args.quick, time.perf_counter() - start)
    failed = [r for r in runs if r.status != "ok"]
    print(f"bench: {len(runs)} runs over {len(cases)} cases in {summary['wall_time_s']:.0f} s, {len(failed)} not ok")
    for case, row in summary["tolerance_table"].items():
        best = row["5%"]
        text = "none" if best is None else f"{best['model']} {best['resolution']} ({best['wall_time_s'] * 1e3:.3g} ms)"
        print(f"  {case:<22} fastest within 5 %: {text}")
    print(f"output written to {out_dir} (bench.md, bench.csv, time_vs_error-*.png)")
    return 0


def cmd_compare(args) -> int:
    from comparisons.compare import COMPARE_MODELS, run_compare
    from wheelrail.named_cases import load_named_case
    from wheelrail.output import copy_input, new_output_dir

    models = _check_models(args.models, COMPARE_MODELS)
    named = load_named_case(args.case)
    out_dir = new_output_dir(args.out, f"compare-{named.name}")
    copy_input(named.case_path, out_dir, "case.toml")
    report = run_compare(named, out_dir, models=models)
    for line in report["headlines"]:
        print(line)
    print(f"report: {Path(out_dir) / 'report.md'} (and report.html)")
    return 0 if report["success"] else 1


def register(sub) -> None:
    """Add the ``bench`` and ``compare`` sub-commands to the CLI's subparsers."""
    bench = sub.add_parser("bench", help="run time against error of every rung on the named cases")
    bench.add_argument("--quick", action="store_true", help="fewer resolutions (a few minutes on 2 cores)")
    bench.add_argument("--cases", nargs="+", metavar="NAME", help="named cases (default: all)")
    bench.add_argument("--models", nargs="+", metavar="NAME", help="models (default: all rungs)")
    bench.add_argument("--out", type=Path, help="output folder (default: wheelrail-out/bench-<time>)")
    bench.add_argument("--list", action="store_true", help="list the named cases")
    bench.set_defaults(func=cmd_bench)

    compare = sub.add_parser("compare", help="one case through Hertz, FASTSIM, BEM and FEA side by side")
    compare.add_argument("case", help="named case (see `wheelrail bench --list`) or case folder")
    compare.add_argument("--models", nargs="+", metavar="NAME", help="models (default: hertz fastsim bem fea)")
    compare.add_argument("--out", type=Path, help="output folder (default: wheelrail-out/compare-<case>-<time>)")
    compare.set_defaults(func=cmd_compare)
