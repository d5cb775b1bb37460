"""The ``bench`` and ``compare`` commands (registered in :mod:`wheelrail.cli` by :func:`register`).

    wheelrail bench [--quick] [--cases NAME ...] [--models NAME ...] [--out DIR]
    wheelrail compare CASE [--models NAME ...] [--out DIR]

CASE / NAME: a named case of ``comparisons/cases/`` (``wheelrail bench --list``) or a folder holding
``case.toml`` and ``reference.toml``. Bad names end with ``wheelrail: error: ...`` (exit 2).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

from wheelrail.config import ConfigError

COMPARE_SUMMARIES = ("compare.json", "report.md", "report.html")
"""The files of a compare that say what the folder holds (removed before a new compare into the same folder)."""

DEMO_TOLERANCE = 0.1
"""auto's contact_tolerance in the demo's run: at the polygonal-wheel scene's own 0.05 the measured thresholds send
39 % of the patches (tread patches at saturation 0.08-0.16 and spin share 0.17-0.19) to BEM, and 2 s would take
7-12 minutes here (0.04 s took 8.9-14.5 s in-process) instead of about half a minute (README, demo)."""


DEMO_PATCH_GEOMETRY = "ellipse"
"""What the demo's run solves per patch (the scene key ``patch_geometry``): Hertz's ellipse at each contact point
(multi-Hertzian), the geometry auto's thresholds were measured on. With ``--patch-geometry sampled`` (the scenes'
default) auto decides on each patch's sampled gap too: polygonal-wheel's S1002/UIC60 treads (ellipticity residual
1-20 in the loop) lie beyond every ellipse rung's measured box (0.55 at 10 %), so every patch goes to the BEM or its
reuse and the 2 s run takes about 6 minutes in process (auto at 5 %: 0.0058x real time over the whole 2 s,
benchmarks/results/auto_vs_bem.md)."""

DEMO_FEA_OPTIONS = {"domain_factor": 40.0}
"""The demo's FEA (fea.model options): a block of 40 semi-axes instead of the default 20. Under load control the block's
truncation enters the max pressure at second order, stated as 0.5 % (20 / D)^2 (fea.refinement,
LOAD_CONTROL_BLOCK_ERROR): 0.125 % at 40 for about 2 % more unknowns (4878 against 4785 on the demo's coarse
locating solve)."""

PATCH_GEOMETRIES = ("sampled", "ellipse", "formed")
"""The values of ``--patch-geometry`` (rigid_dynamics.wheelset.parameters.PATCH_GEOMETRIES, not imported here: the
parser is built before the dynamics are)."""


def _positional_after_models(args, name: str, allowed, default: str | None = None) -> None:
    """``--models a b CASE``: argparse gives CASE to ``--models`` (nargs "+"); a trailing name that is not a model,
    with the positional ``name`` missing, is that positional (the order a user naturally writes).
    """
    models = list(args.models or ())
    if getattr(args, name) is None and models and models[-1] not in allowed:
        setattr(args, name, models.pop())
        args.models = models or None
    if getattr(args, name) is None:
        if default is not None:
            setattr(args, name, default)
            return
        raise ConfigError(f"{args.command}: the {name} is missing: expected {args.command} {name.upper()} [options]")


def _say(prefix: str):
    """A progress callback: one line ``prefix: text`` on stderr."""

    def say(text: str) -> None:
        print(f"{prefix}: {text}", file=sys.stderr, flush=True)

    return say


def _check_models(models, allowed) -> list[str]:
    models = list(models or allowed)
    for name in models:
        if name not in allowed:
            raise ConfigError(f"--models {name!r}: expected some of {', '.join(allowed)}")
    return models


class _NoBar:
    """Stands in for a tqdm bar off a terminal or without tqdm (the ``progress`` extra)."""

    n = 0

    def set_postfix_str(self, text, refresh=True):
        pass

    def update(self, n):
        self.n += n

    def close(self):
        pass


def _bar(total: int, label: str):
    """A tqdm bar on a terminal (a silent stand-in elsewhere, or without tqdm) and a callback advancing it."""
    try:
        from tqdm import tqdm
    except ImportError:  # the progress extra not installed: no bar
        bar = _NoBar()
    else:
        bar = tqdm(total=total, desc=label, unit="run", leave=False, disable=not sys.stderr.isatty())

    def update(done: int, total: int, text: str) -> None:
        bar.set_postfix_str(text[:40], refresh=False)
        bar.update(done - bar.n)

    return bar, update


def cmd_bench(args) -> int:
    from comparisons.bench import MODELS, bench_plan, run_bench, write_bench
    from wheelrail.named_cases import load_named_cases, named_case_names
    from wheelrail.output import output_folder

    if args.list:
        for name in named_case_names():
            print(name)
        return 0
    models = _check_models(args.models, MODELS)
    cases = load_named_cases(args.cases)
    summaries = ("bench.json", "bench.md", "bench.csv")
    with output_folder(args.out, "bench-quick" if args.quick else "bench", summaries=summaries) as out_dir:
        bar, update = _bar(len(bench_plan(cases, models, args.quick)), "bench")
        start = time.perf_counter()
        try:
            runs = run_bench(cases, models, args.quick, progress=update)
        finally:
            bar.close()
        summary = write_bench(runs, cases, out_dir, args.quick, time.perf_counter() - start)
    print(
        f"bench: status {summary['status']}: {len(runs)} runs over {len(cases)} cases"
        f" in {summary['wall_time_s']:.0f} s, {summary['runs_not_ok']} not ok"
        " (each a finding about its rung, with its message in bench.md)"
    )
    for case, row in summary["tolerance_table"].items():
        best = row["5%"]
        text = "none" if best is None else f"{best['model']} {best['resolution']} ({best['wall_time_s'] * 1e3:.3g} ms)"
        print(f"  {case:<22} fastest within 5 %: {text}")
    print(f"output written to {out_dir} (bench.md, bench.csv, time_vs_error-*.png)")
    return 0


def cmd_compare(args) -> int:
    from comparisons.compare import COMPARE_MODELS, run_compare
    from wheelrail.named_cases import load_named_case
    from wheelrail.output import copy_input, output_folder

    _positional_after_models(args, "case", COMPARE_MODELS)
    models = _check_models(args.models, COMPARE_MODELS)
    named = load_named_case(args.case)
    # locked (one compare per folder at a time); an earlier compare's report and compare.json are removed first
    with output_folder(args.out, f"compare-{named.name}", summaries=COMPARE_SUMMARIES) as out_dir:
        copy_input(named.case_path, out_dir, "case.toml")
        report = run_compare(named, out_dir, models=models, progress=_say("compare"))
    for line in report["headlines"]:
        print(line)
    print(f"report: {Path(out_dir) / 'report.md'} (and report.html)")
    return 0 if report["success"] else 1


def cmd_demo(args) -> int:
    """The default demo (``make demo``): polygonal-wheel run, compare at the peak normal force, report."""
    from comparisons.compare import COMPARE_MODELS
    from wheelrail.output import output_folder
    from wheelrail.scenes import load_scene, resolve_scene_path

    _positional_after_models(args, "scene", COMPARE_MODELS, default="polygonal-wheel")
    models = _check_models(args.models, COMPARE_MODELS)
    from dataclasses import replace

    from rigid_dynamics.contact.registry import model_names

    if not (math.isfinite(args.tolerance) and args.tolerance > 0):
        raise ConfigError(f"--tolerance {args.tolerance!r}: expected a finite number > 0")
    if args.contact_model not in (*model_names(), "auto"):
        raise ConfigError(f"--contact-model {args.contact_model!r}: expected one of {', '.join(model_names())}")
    source = resolve_scene_path(args.scene)
    scene = load_scene(source)
    if args.contact_model is not None:
        scene = replace(scene, contact_model=args.contact_model)
    if args.tolerance is not None:
        scene = replace(scene, contact_tolerance=args.tolerance)
    scene = replace(scene, patch_geometry=args.patch_geometry)
    with output_folder(args.out, f"demo-{source.stem}", summaries=("report.md", "report.html")) as out_dir:
        return _demo(scene, source, models, out_dir)


def _demo(scene, source, models, out_dir) -> int:
    """The work of :func:`cmd_demo` in its checked, locked folder."""
    from comparisons.compare import _html, run_compare
    from comparisons.demo import peak_patch_case
    from comparisons.named_cases import NamedCase
    from rigid_dynamics.files import write_text
    from rigid_dynamics.wheelset import simulate
    from wheelrail.output import subfolder
    from wheelrail.scenes import write_run_outputs

    start = time.perf_counter()
    law = scene.contact_model + (
        f" (contact_tolerance {scene.contact_tolerance:g})" if scene.contact_model == "auto" else ""
    )
    shape = "Hertz's ellipse per patch, multi-Hertzian" if scene.patch_geometry == "ellipse" else "sampled patches"
    print(f"demo 1/3: {source.stem}, {scene.duration_s:g} s with {law} (3-D contact search; {shape})")
    result = simulate(scene)
    summary = write_run_outputs(result, source, subfolder(out_dir, "run"))
    if not result.success:
        print(f"demo: the run ended with {result.status}: {result.message}")
        return 1
    patch = peak_patch_case(result)
    print(
        f"demo 2/3: peak normal force {patch.normal_force_N / 1e3:.1f} kN on the {patch.side} wheel at "
        f"t = {patch.time_s:.3f} s: re-solved by {', '.join(models)}"
    )
    note = (
        f"{source.stem}: the patch of the largest normal force of the run ({patch.side} wheel, slot {patch.slot}, "
        f"t = {patch.time_s:.3f} s, N = {patch.normal_force_N / 1e3:.2f} kN; the first quarter of the run, at most "
        "0.3 s, is left out: the transient from the static equilibrium), re-solved under that force"
    )
    named = NamedCase("peak-contact", out_dir, "none (no reference: the BEM is the most exact rung here)", "single",
                      {}, note=note, case=patch)  # fmt: skip
    compare = run_compare(
        named, subfolder(out_dir, "compare"), models=models, fea_options=DEMO_FEA_OPTIONS, progress=_say("demo 2/3")
    )
    print("demo 3/3: report")
    models = compare["models"]

    def p0(model):
        value = models.get(model, {}).get("values", {}).get("max_pressure_Pa")
        stated = (models.get(model, {}).get("stated_errors") or {}).get("max_pressure")
        text = "-" if value is None else f"{value / 1e6:.0f}"
        return text if value is None or stated is None else f"{text} +- {100 * stated:.2g} %"

    def grid(model):
        text = models.get(model, {}).get("resolution", "")
        return f" ({text})" if text and model != "hertz" else ""

    def creep(model):
        v = models.get(model, {}).get("values", {})
        fx, fy = v.get("creep_force_long_N"), v.get("creep_force_lat_N")
        return "-" if fx is None or fy is None else f"{math.hypot(fx, fy) / 1e3:.2f}"

    fea_vs_bem = _fea_vs_bem_headline(models.get("fea", {}))
    stresses = {s["source"]: s for s in compare["subsurface"]}
    with_t = stresses.get("BEM pressure + tractions, half-space", {})
    fea = next((v for k, v in stresses.items() if k.startswith("FEA")), {})
    headlines = [
        f"run: {result.simulated_time_s:g} s of {source.stem} in {summary['wall_time_s']:.1f} s wall "
        f"(real-time factor {summary['real_time_factor']:.2g}); peak wheel-rail normal force "
        f"{patch.normal_force_N / 1e3:.1f} kN at t = {patch.time_s:.3f} s ({patch.side} wheel)",
        f"at the peak, max pressure [MPa] Hertz {p0('hertz')}, FASTSIM{grid('fastsim')} {p0('fastsim')}, "
        f"BEM{grid('bem')} {p0('bem')}, FEA{grid('fea')} {p0('fea')}; creep force [kN] FASTSIM {creep('fastsim')}, "
        f"BEM {creep('bem')}",
        *fea_vs_bem,
        "subsurface max von Mises: "
        + (
            f"BEM + tractions (half-space) {with_t['max_von_mises_Pa'] / 1e6:.0f} MPa at "
            f"{with_t['max_von_mises_depth_m'] * 1e3:.2f} mm"
            if with_t.get("max_von_mises_Pa")
            else "n/a"
        )
        + (
            f", {fea['source']} {fea['max_von_mises_Pa'] / 1e6:.0f} MPa at {fea['max_von_mises_depth_m'] * 1e3:.2f} mm"
            if fea.get("max_von_mises_Pa")
            else ", FEA n/a"
        ),
    ]
    auto_lines = _auto_summary(result)
    run_pngs = sorted(p.name for p in (out_dir / "run").glob("*.png"))
    compare_md = (out_dir / "compare" / "report.md").read_text()
    compare_md = compare_md.replace("](", "](compare/").replace("# peak-contact", "## Contact at the peak", 1)
    lines = [
        f"# wheelrail demo: {source.stem}",
        "",
        *[f"- {h}" for h in headlines],
        "",
        f"Total wall time {time.perf_counter() - start:.0f} s. Run folder: run/ (scene.toml, summary.json, "
        "timeseries.npz); comparison folder: compare/.",
        "",
        *auto_lines,
        "## Time series",
        "",
        *[f"![{name}](run/{name})" for name in run_pngs],
        "",
        compare_md,
    ]
    text = "\n".join(lines) + "\n"
    write_text(out_dir / "report.md", text)
    write_text(out_dir / "report.html", _html(text, f"wheelrail demo: {source.stem}"))
    print(f"report: {out_dir / 'report.md'} (and report.html)")
    for line in headlines:
        print(line)
    if compare["success"]:
        return 0
    failed = {m: v for m, v in models.items() if v.get("status") not in (None, "ok")}
    print(
        "demo: ended with a rung short of its own tolerance or failed (exit 1): "
        + ", ".join(f"{m} {v.get('status')}{_why_not_ok(v.get('message', ''))}" for m, v in failed.items())
        + "; see the report's table"
    )
    return 1


def _why_not_ok(message: str) -> str:
    """The part of a rung's message that says by how much it missed its tolerance (the FEA's "discretisation error
    above mesh_tolerance = 0.02 (max_pressure 2.18% (mesh ..., window ..., block size ...)); the next level ...").
    """
    start = message.find("discretisation error above")
    return f" ({message[start:]})" if start >= 0 else ""


def _fea_vs_bem_headline(fea: dict) -> list[str]:
    """The demo's lines on the FEA against the BEM at the peak: each quantity with both stated errors and the
    verdict (comparisons.compare.verdict), and why; one line saying so when the FEA did not run or failed.
    """
    from comparisons.compare import agreement_sentence

    if not fea:
        return []
    agreement = fea.get("agreement_with_bem") or {}
    if not agreement:
        return [f"FEA vs BEM at the peak: no comparison (FEA {fea.get('status')}: {fea.get('message', '')[:160]})"]
    head = f"FEA ({fea.get('status')}; {fea.get('resolution', '')}) vs BEM at the peak: "
    return [head + "; ".join(agreement_sentence(n, a) for n, a in agreement.items()), fea.get("verdict_why", "")]


def _auto_summary(result) -> list:
    """Report lines on ``auto``'s choices in a run (none for other models): the share of each rung over the recorded
    patches in contact and how often each feature decided, with the tolerance level used.
    """
    import numpy as np

    from rigid_dynamics.contact.auto import AUTO_RUNGS, FEATURES

    if "auto_rung" not in result.patches:
        return []
    rung = np.asarray(result.patches["auto_rung"], float)
    touching = np.isfinite(rung) & (np.nan_to_num(np.asarray(result.patches["normal_force_N"], float)) > 0)
    codes = rung[touching].astype(int)
    if not len(codes):
        return ["## auto's choices", "", "No patch in contact was recorded.", ""]
    level = np.asarray(result.patches["auto_level"], float)[touching]
    deciding = np.asarray(result.patches["auto_deciding_feature"], float)[touching].astype(int)
    shares = ", ".join(f"{name} {np.mean(codes == i):.1%}" for i, name in enumerate(AUTO_RUNGS))
    decided = ", ".join(
        f"{FEATURES[f]} {np.mean(deciding == f):.0%}" for f in range(len(FEATURES)) if np.any(deciding == f)
    )
    lvl = f"{np.nanmax(level):.0%}" if np.any(np.isfinite(level)) else "none (every patch BEM)"
    return [
        "## auto's choices",
        "",
        f"Per recorded patch in contact ({len(codes)}), the rung auto chose in the compiled loop from the measured "
        f"thresholds (rigid_dynamics/contact/data/auto_thresholds.json) at the level {lvl} for the scene's "
        f"contact_tolerance {result.scene.contact_tolerance:g}: {shares}. The feature that decided: {decided}. "
        "Per patch and sample in run/timeseries.npz (patch_auto_rung, patch_auto_deciding_feature, "
        "patch_auto_deciding_threshold, the features).",
        "",
        _auto_geometry_line(result),
        "",
    ]


def _auto_geometry_line(result) -> str:
    """The report's sentence on auto's ellipse-served patches against their sampled gap (discretisation.auto_geometry,
    summary.json's ``auto.geometry``).
    """
    geometry = result.auto_geometry() or {}
    if not geometry.get("seen"):
        return (
            f"The loop's compiled rungs solved Hertz's ellipse at each contact point (patch_geometry "
            f"{result.scene.patch_geometry!r}); the patches' real gap was not sampled, so how far they depart from "
            "the ellipse, and so from the geometry auto's thresholds were measured on, is not known here "
            "(`--patch-geometry sampled` checks it)."
        )
    if not geometry.get("checked"):
        return (
            "auto decided on each patch's sampled gap (patch_geometry 'sampled'): no recorded patch was served on "
            "Hertz's ellipse; every one went to the BEM or its reuse."
        )
    return (
        f"auto decided on each patch's sampled gap (patch_geometry 'sampled'): {geometry['checked']} recorded patches "
        f"were served on Hertz's ellipse (largest ellipticity residual {geometry['largest_residual']:.3g}), "
        f"{geometry['outside_box']} of them beyond their rung's measured box (their error against the BEM on the "
        "sampled gap is not known)."
    )


def register(sub) -> None:
    """Add the ``bench``, ``compare`` and ``demo`` sub-commands to the CLI's subparsers."""
    from wheelrail.cli import out_path

    bench = sub.add_parser("bench", help="run time against error of every rung on the named cases")
    bench.add_argument("--quick", action="store_true", help="fewer resolutions (a few minutes on 2 cores)")
    bench.add_argument("--cases", nargs="+", metavar="NAME", help="named cases (default: all)")
    bench.add_argument("--models", nargs="+", metavar="NAME", help="models (default: all rungs)")
    bench.add_argument("--out", type=out_path, help="output folder (default: wheelrail-out/bench-<time>)")
    bench.add_argument("--list", action="store_true", help="list the named cases")
    bench.set_defaults(func=cmd_bench)

    compare = sub.add_parser("compare", help="one case through Hertz, FASTSIM, BEM and FEA side by side")
    compare.add_argument("case", nargs="?", help="named case (see `wheelrail cases`) or case folder")
    compare.add_argument("--models", nargs="+", metavar="NAME", help="models (default: hertz fastsim bem fea)")
    compare.add_argument("--out", type=out_path, help="output folder (default: wheelrail-out/compare-<case>-<time>)")
    compare.set_defaults(func=cmd_compare)

    demo = sub.add_parser("demo", help="the default demo: a run, the contact at its peak through every rung, report")
    demo.add_argument("scene", nargs="?", help="scene with the 3-D contact search (default: polygonal-wheel)")
    demo.add_argument("--out", type=out_path, help="output folder (default: wheelrail-out/demo-<scene>-<time>)")
    demo.add_argument("--models", nargs="+", metavar="NAME", help="models (default: hertz fastsim bem fea)")
    demo.add_argument(
        "--contact-model", default="auto", help="contact model of the run (default auto, overriding the scene file's)"
    )
    demo.add_argument(
        "--tolerance", type=float, default=DEMO_TOLERANCE,
        help=f"auto's contact_tolerance for the run (default {DEMO_TOLERANCE:g}; README: why not the scene's 0.05)",
    )  # fmt: skip
    demo.add_argument(
        "--patch-geometry", choices=PATCH_GEOMETRIES, default=DEMO_PATCH_GEOMETRY,
        help=f"what the run's contact models see per patch (default {DEMO_PATCH_GEOMETRY}: Hertz's ellipse, where "
        "auto's thresholds were measured; sampled: the real gap, on which auto then decides: on the S1002/UIC60 "
        "treads every patch goes to the BEM or its reuse: minutes)",
    )  # fmt: skip
    demo.set_defaults(func=cmd_demo)
