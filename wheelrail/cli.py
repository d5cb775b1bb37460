"""The ``wheelrail`` command line: a thin front over the library's dataclasses.

Commands:
    wheelrail scenes                 list the embedded dynamics scenes
    wheelrail cases                  list the embedded contact cases
    wheelrail models                 list the contact models
    wheelrail run [SCENE]            run a dynamics scene (embedded name or TOML path)
    wheelrail contact CASE           solve a contact case (embedded name or TOML path)
    wheelrail conicity               equivalent conicity of a wheel/rail pair (EN 15302 method)
    wheelrail manchester             the Manchester Contact Benchmark case A-2.2 sweep
    wheelrail stress                 numerical-stability stress sweep of a scene
    wheelrail bench                  run time against error of every rung on the named cases
    wheelrail compare CASE           one named case through the rungs side by side (maps, stresses, report)

Bad input ends with one line ``wheelrail: error: ...`` on stderr naming the key, the value and
what was expected, and exit status 2; a numerical failure is reported in the results with its
status (exit status 1).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from wheelrail.config import ConfigError

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


MPI_RANK_VARIABLES = ("PMI_RANK", "OMPI_COMM_WORLD_RANK", "PMIX_RANK")


def _under_mpi() -> bool:
    """Whether this process was started by mpiexec (MPICH, Open MPI or PMIx launchers)."""
    return any(var in os.environ for var in MPI_RANK_VARIABLES)


def _mpi_rank() -> int:
    """Rank of this process under mpiexec (0 when not under MPI), from the launcher's environment."""
    for var in MPI_RANK_VARIABLES:
        if var in os.environ:
            try:
                return int(os.environ[var])
            except ValueError:
                return 0
    return 0


def _print(*args, **kwargs) -> None:
    if _mpi_rank() == 0:
        print(*args, **kwargs)


# --- listings -----------------------------------------------------------------------------


def cmd_models(args) -> int:
    from rigid_dynamics.contact.registry import MODELS

    width = max(len(n) for n in MODELS)
    for name, (_, description) in MODELS.items():
        _print(f"{name:<{width}}  {description}")
    return EXIT_OK


def cmd_scenes(args) -> int:
    from wheelrail.scenes import embedded_scenes, scene_description

    scenes = embedded_scenes()
    width = max((len(n) for n in scenes), default=0)
    for name, path in scenes.items():
        _print(f"{name:<{width}}  {scene_description(path)}")
    return EXIT_OK


def cmd_cases(args) -> int:
    from wheelrail.cases import embedded_cases
    from wheelrail.config import read_toml

    cases = embedded_cases()
    width = max((len(n) for n in cases), default=0)
    for name, path in cases.items():
        _print(f"{name:<{width}}  {read_toml(path).get('description', '')}")
    return EXIT_OK


# --- contact ------------------------------------------------------------------------------


def cmd_contact(args) -> int:
    from rigid_dynamics.contact.registry import MODELS
    from wheelrail.cases import load_case, resolve_case_path, solution_record, solve_case
    from wheelrail.output import copy_input, new_output_dir, to_json, write_json

    if args.method not in MODELS:
        raise ConfigError(f"--method {args.method!r}: expected one of {', '.join(MODELS)}")
    case = load_case(args.case)
    if args.method == "fea" and (args.out is not None or args.plot):
        case = _with_fea_output(case, args)
    solution = solve_case(case, args.method)
    record = solution_record(solution)
    out_dir = None
    if args.out is not None or args.plot:
        if _mpi_rank() == 0:
            out_dir = new_output_dir(args.out, f"contact-{case.name or 'case'}")
            copy_input(resolve_case_path(args.case), out_dir, "case.toml")
            write_json(out_dir / "summary.json", record)
            if args.plot:
                record["plots"] = _plot_patches(solution, out_dir)
                write_json(out_dir / "summary.json", record)
    if args.json:
        _print(to_json(record))
    else:
        _print(_contact_table(record))
        if out_dir is not None:
            _print(f"output written to {out_dir}")
    return EXIT_OK if solution.success else EXIT_FAILED


def _with_fea_output(case, args):
    """Ask the FEA model to write its XDMF and stress maps into ``<out>/fea`` (one sub-folder per patch)."""
    import dataclasses

    if args.out is None and _under_mpi():
        raise ConfigError("--method fea with --plot under mpiexec: give --out DIR so every rank writes to one folder")
    if args.out is None:
        args.out = new_output_dir_for(case)
    fea_dir = str(Path(args.out) / "fea")
    options = dict(case.solver_options)
    if case.kind == "quadric":
        options["output_dir"] = fea_dir
    else:
        options["model"] = dict(options.get("model") or {}, output_dir=fea_dir)
    return dataclasses.replace(case, solver_options=options)


def new_output_dir_for(case) -> Path:
    from wheelrail.output import new_output_dir

    return new_output_dir(None, f"contact-{case.name or 'case'}")


def _plot_patches(solution, out_dir: Path) -> list[str]:
    from comparisons.contact_plots import plot_contact_fields

    written = []
    for index, (side, _geometry, _creepage, result) in enumerate(solution.patches):
        if result.fields is None:
            continue
        path = out_dir / f"fields-{side}-{index}.png"
        plot_contact_fields(result, path)
        written.append(path.name)
    return written


def _contact_table(record: dict) -> str:
    lines = [f"method {record['method']}: {'ok' if record['success'] else 'FAILED'} - {record['message']}"]
    keys = [
        ("normal_force_N", "N [N]", 1.0),
        ("creep_force_long_N", "Fx [N]", 1.0),
        ("creep_force_lat_N", "Fy [N]", 1.0),
        ("spin_moment_Nm", "Mz [N m]", 1.0),
        ("max_pressure_Pa", "p0 [MPa]", 1e-6),
        ("semi_axis_long_m", "a [mm]", 1e3),
        ("semi_axis_lat_m", "b [mm]", 1e3),
        ("contact_angle_rad", "angle [deg]", 57.29577951308232),
    ]
    lines.append("side    " + "".join(f"{label:>13}" for _, label, _ in keys))
    for patch in record["patches"]:
        cells = []
        for key, _, scale in keys:
            value = patch.get(key)
            cells.append(f"{'-':>13}" if value is None else f"{value * scale:13.5g}")
        lines.append(f"{patch['side']:<8}" + "".join(cells))
    lines.append(f"wall time {record['wall_time_s']:.3g} s")
    return "\n".join(lines)


# --- dynamics -----------------------------------------------------------------------------


def cmd_run(args) -> int:
    from wheelrail.scenes import DEFAULT_SCENE, load_scene, resolve_scene_path, write_run_outputs

    source = resolve_scene_path(args.scene or DEFAULT_SCENE)
    scene = load_scene(source)
    from rigid_dynamics.wheelset import simulate
    from wheelrail.output import new_output_dir

    out_dir = new_output_dir(args.out, f"run-{source.stem}")
    progress, close = _progress_bar(args.quiet, f"{source.stem}")
    try:
        result = simulate(scene, progress=progress)
    finally:
        close()
    summary = write_run_outputs(result, source, out_dir, plots=not args.no_plots)
    _print(
        f"{source.stem}: {summary['status']} - {summary['message']}; simulated {summary['simulated_time_s']:.3g} s "
        f"in {summary['wall_time_s']:.3g} s (real-time factor {summary['real_time_factor']:.3g})"
    )
    _print(f"output written to {out_dir}")
    return EXIT_OK if summary.get("success", summary["status"] == "ok") else EXIT_FAILED


def _progress_bar(quiet: bool, label: str):
    """A tqdm bar driven by fraction callbacks; off when quiet or not on a terminal."""
    if quiet or not sys.stderr.isatty():
        return None, lambda: None
    from tqdm import tqdm

    bar = tqdm(total=1000, desc=label, unit="‰", leave=False, mininterval=0.5, delay=2.0)
    state = {"last": 0}

    def update(fraction: float) -> None:
        target = int(1000 * min(max(fraction, 0.0), 1.0))
        if target > state["last"]:
            bar.update(target - state["last"])
            state["last"] = target

    return update, bar.close


def cmd_stress(args) -> int:
    import importlib.util

    from wheelrail.output import copy_input, new_output_dir, write_json
    from wheelrail.scenes import DEFAULT_STRESS_SCENE, load_scene, resolve_scene_path

    try:
        workers = int(args.workers)
    except ValueError:
        workers = 0
    if workers < 1:
        raise ConfigError(f"--workers {args.workers!r}: expected an integer >= 1")
    if workers > 1 and importlib.util.find_spec("distributed") is None:
        raise ConfigError(f"--workers {args.workers!r}: needs dask.distributed (pip install 'dask[distributed]')")
    source = resolve_scene_path(args.scene or DEFAULT_STRESS_SCENE)
    scene = load_scene(source)
    from comparisons.stress import ENERGY_SUSPECT_RELATIVE, run_stress_sweep

    out_dir = new_output_dir(args.out, f"stress-{source.stem}")
    copy_input(source, out_dir, "scene.toml")
    update, close = _progress_bar(False, f"stress {source.stem}")
    try:
        report = run_stress_sweep(scene, out_dir=out_dir, quick=args.quick, workers=workers, progress=update)
    finally:
        close()
    write_json(out_dir / "summary.json", report if isinstance(report, dict) else {"runs": report})
    _print(
        f"stress sweep of {source.stem}: {len(report['runs'])} runs ({report['finished']} finished, "
        f"{report['stopped']} stopped) on {workers} worker{'s' if workers > 1 else ''}"
    )
    for run in report.get("energy_suspect", []):
        _print(
            f"stress sweep of {source.stem}: {run['parameter']} = {run['value']:g} finished with an energy balance "
            f"of {run['energy_balance_relative']:.3g} (above {ENERGY_SUSPECT_RELATIVE:g}: check the step or tolerance)"
        )
    _print(f"stress sweep of {source.stem}: output written to {out_dir}")
    return EXIT_OK


# --- geometry studies ---------------------------------------------------------------------


def cmd_conicity(args) -> int:
    from rigid_dynamics.contact.conicity import equivalent_conicity_from_names
    from rigid_dynamics.geometry import load_profile

    profiles = {}
    for option, value, kind in (("--wheel", args.wheel, "wheel"), ("--rail", args.rail, "rail")):
        try:
            profiles[kind] = load_profile(value, kind)
        except ValueError as exc:
            raise ConfigError(f"{option} {value!r}: {exc}") from None
    for option in ("gauge_m", "flange_back_distance_m", "nominal_radius_m", "amplitude_m"):
        value = getattr(args, option)
        if not (value > 0 and value < float("inf")):
            raise ConfigError(f"--{option.replace('_', '-')} {value!r}: expected a finite number > 0")
    result = equivalent_conicity_from_names(
        wheel_profile=profiles["wheel"],
        rail_profile=profiles["rail"],
        gauge_m=args.gauge_m,
        gauge_height_m=args.gauge_height_m,
        flange_back_distance_m=args.flange_back_distance_m,
        nominal_radius_m=args.nominal_radius_m,
        rail_inclination_rad=args.rail_inclination_rad,
        amplitude_m=args.amplitude_m,
    )
    if args.json:
        from wheelrail.output import to_json

        _print(to_json(result))
    else:
        _print(
            f"equivalent conicity {result['equivalent_conicity']:.4f} at amplitude "
            f"{1e3 * result['amplitude_m']:.2f} mm ({args.wheel} on {args.rail})"
        )
    return EXIT_OK


def cmd_manchester(args) -> int:
    from comparisons.manchester import run_manchester_a22
    from wheelrail.output import new_output_dir

    out_dir = new_output_dir(args.out, "manchester-a22")
    run_manchester_a22(out_dir, method=args.method)
    _print(f"Manchester A-2.2: output written to {out_dir}")
    return EXIT_OK


# --- parser -------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    from wheelrail import __version__

    parser = argparse.ArgumentParser(prog="wheelrail", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"wheelrail {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    sub.add_parser("scenes", help="list the embedded dynamics scenes").set_defaults(func=cmd_scenes)
    sub.add_parser("cases", help="list the embedded contact cases").set_defaults(func=cmd_cases)
    sub.add_parser("models", help="list the contact models").set_defaults(func=cmd_models)

    run = sub.add_parser("run", help="run a dynamics scene")
    run.add_argument("scene", nargs="?", help="embedded scene name or TOML file (default: the default scene)")
    run.add_argument("--out", type=Path, help="output folder (default: wheelrail-out/run-<scene>-<time>)")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument("--no-plots", action="store_true", help="do not write PNG plots")
    run.set_defaults(func=cmd_run)

    contact = sub.add_parser("contact", help="solve a contact case")
    contact.add_argument("case", help="embedded case name or TOML file")
    contact.add_argument("--method", default="auto", help="contact model (see `wheelrail models`)")
    contact.add_argument("--json", action="store_true", help="print one JSON object")
    contact.add_argument("--plot", action="store_true", help="write PNG maps of the patch fields")
    contact.add_argument("--out", type=Path, help="output folder for summary and plots")
    contact.set_defaults(func=cmd_contact)

    conicity = sub.add_parser("conicity", help="equivalent conicity (EN 15302 method)")
    conicity.add_argument("--wheel", default="MBench_S1002_v3", help="wheel profile: built-in name or file")
    conicity.add_argument("--rail", default="MBench_UIC60_v3", help="rail profile: built-in name or file")
    conicity.add_argument("--gauge-m", type=float, default=1.435)
    conicity.add_argument("--gauge-height-m", type=float, default=0.014)
    conicity.add_argument("--flange-back-distance-m", type=float, default=1.360)
    conicity.add_argument("--nominal-radius-m", type=float, default=0.46)
    conicity.add_argument("--rail-inclination-rad", type=float, default=None, help="cant of the rail (default: 1:40)")
    conicity.add_argument("--amplitude-m", type=float, default=0.003, help="wheelset amplitude (EN 15302: 3 mm)")
    conicity.add_argument("--json", action="store_true")
    conicity.set_defaults(func=cmd_conicity)

    manchester = sub.add_parser("manchester", help="Manchester Contact Benchmark case A-2.2 sweep")
    manchester.add_argument("--out", type=Path)
    manchester.add_argument("--method", default="fastsim")
    manchester.set_defaults(func=cmd_manchester)

    stress = sub.add_parser("stress", help="numerical-stability stress sweep")
    stress.add_argument("scene", nargs="?", help="embedded scene name or TOML file (default: hunting-conical)")
    stress.add_argument("--out", type=Path, help="output folder (default: wheelrail-out/stress-<scene>-<time>)")
    stress.add_argument("--quick", action="store_true", help="a small sweep")
    stress.add_argument(
        "--workers",
        default="1",
        metavar="N",
        help="1: run serially (default); N >= 2: on a local dask.distributed cluster of N single-threaded processes",
    )
    stress.set_defaults(func=cmd_stress)

    from wheelrail.comparison_commands import register

    register(sub)  # bench, compare
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``wheelrail`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    start = time.perf_counter()
    try:
        return args.func(args)
    except ConfigError as exc:
        print(f"wheelrail: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"wheelrail: interrupted after {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
