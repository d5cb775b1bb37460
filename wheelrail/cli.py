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
    wheelrail sweep SWEEP.toml       parameter study on dask.distributed (wheelrail.sweep)
    wheelrail critical-speed SCENE   linear and nonlinear (limit-cycle) critical speed (wheelrail.critical)
    wheelrail bench                  run time against error of every rung on the named cases
    wheelrail compare CASE           one named case through the rungs side by side (maps, stresses, report)
    wheelrail demo                   the default demo (make demo): a run, its peak contact through every rung

Exit statuses (README, "What a run tells you"): 0 every result ok; 1 the work ran but a result is not ok
(its status and message say why; the outputs are written), or the work failed on an error that is not bad input
(one line ``wheelrail: error: the work failed: ...``); 2 bad input, found before any work: one line
``wheelrail: error: ...`` on stderr naming the key or option, the value and what was expected; 3 an output
could not be written (one line naming the file; no summary is written); 130 interrupted (Ctrl-C), 143
terminated (SIGTERM). No traceback for any of these.

A subcommand is a function ``cmd_<name>(args) -> int`` and a function adding its parser, registered in
:data:`COMMANDS` (or, from another module, with :func:`register`). Shared validation helpers for subcommands:
:func:`positive_int_option`, ``wheelrail.config`` (ConfigError, physical ranges), ``wheelrail.output``
(:func:`~wheelrail.output.output_folder`, atomic writes).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import os
import sys
import time
from pathlib import Path

from wheelrail.config import ConfigError

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_OUTPUT_FAILED = 0, 1, 2, 3
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143


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
    from rigid_dynamics.contact.registry import MODELS, model_options

    width = max(len(n) for n in MODELS)
    for name, (_, description) in MODELS.items():
        _print(f"{name:<{width}}  {description}")
        for option in model_options(name).values():
            _print(f"{'':<{width}}    {option.describe()}")
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
    _print(f"{'case':<{width}}  {'reference':<17}  description")
    for name, path in cases.items():
        ref = path.parent / "reference.toml"
        source = read_toml(ref).get("source", "?") if ref.is_file() else "none"
        _print(f"{name:<{width}}  {source:<17}  {read_toml(path).get('description', '')}")
    _print("every command takes these names (contact, compare, bench --cases); bench and compare state errors only "
           "against a reference")  # fmt: skip
    return EXIT_OK


# --- contact ------------------------------------------------------------------------------


def _skip_collection_at_exit(model: str) -> None:
    """Freeze Python's cyclic garbage collector's objects when the interpreter exits (``atexit``; once per process),
    except for ``model`` "fea", whose PETSc/MPI objects are left to their own collections and shutdown.

    After numba has loaded a kernel the process tracks about 120,000 objects (numba's typing and lowering
    registries, scipy's and numpy's modules), and the interpreter's shutdown runs several full collections over them:
    0.2-0.25 s of CPU for nothing, a fifth of ``wheelrail contact <quadric case> --json``
    (benchmarks/results/startup.md); 0.3 s of ``wheelrail run polygonal-wheel`` over 0.2 s (2.0-2.2 against
    1.7-1.8 s CPU, four interleaved pairs). ``gc.freeze()`` at exit leaves those objects to the end of the process
    (their memory returns to the OS with it). The atexit handlers registered before this one still run after it,
    and every file the command writes is closed before it returns (atomic writes), so nothing waits on a
    collection at exit; a caller that goes on (a test calling :func:`main`) is untouched until its own exit.
    """
    if model != "fea":
        _freeze_at_exit()


@functools.cache
def _freeze_at_exit() -> None:
    """Register ``gc.freeze`` with ``atexit``, once per process (:func:`_skip_collection_at_exit`)."""
    import atexit
    import gc

    atexit.register(gc.freeze)


YOUNG_COLLECTION_THRESHOLD = 20_000
"""Allocations of container objects between two young-generation collections while ``wheelrail contact`` runs
(Python's default: 700). Importing numba and loading its kernels creates about 120,000 long-lived objects; at the
default the collector runs some 250 times over them during the command (0.05-0.07 s CPU of its 0.9 s, measured in
fresh processes), at 20,000 a few times (0.05 s saved; benchmarks/results/startup.md)."""


@contextlib.contextmanager
def _fewer_collections():
    """Python's young-generation threshold raised to :data:`YOUNG_COLLECTION_THRESHOLD` inside, restored after."""
    import gc

    before = gc.get_threshold()
    gc.set_threshold(max(before[0], YOUNG_COLLECTION_THRESHOLD), *before[1:])
    try:
        yield
    finally:
        gc.set_threshold(*before)


def cmd_contact(args) -> int:
    _skip_collection_at_exit(args.method)
    if args.method == "fea":  # as for the collection at exit: fea's PETSc/MPI objects are left alone
        return _contact(args)
    with _fewer_collections():
        return _contact(args)


def _contact(args) -> int:
    from contextlib import ExitStack

    from wheelrail.cases import resolve_case_path, solution_record, solve_case
    from wheelrail.output import copy_input, output_folder, safe_name, to_json, write_json
    from wheelrail.overrides import load_case_with

    # checks --method and [solver] against the model's options; --set overrides before validation
    case, _, overrides = load_case_with(args.case, args.set, method=args.method)
    if args.sensitivities and args.method == "fea":
        raise ConfigError("--sensitivities with --method 'fea': expected a model other than fea (its central "
                          "differences would take 17 FEA solves per patch)")  # fmt: skip
    wants_output = args.out is not None or args.plot
    if wants_output and args.out is None and _under_mpi():
        raise ConfigError("--plot under mpiexec: give --out DIR so every rank writes to one folder")
    with ExitStack() as stack:
        out_dir, refused = None, None
        if wants_output and _mpi_rank() == 0:
            try:
                out_dir = stack.enter_context(output_folder(args.out, f"contact-{safe_name(case.name)}"))
            except ConfigError as exc:
                refused = exc
        elif wants_output:
            out_dir = Path(args.out)  # rank > 0: rank 0 checked and holds the folder
        if wants_output and _under_mpi() and _mpi_broadcast(refused is not None) and refused is None:
            return EXIT_BAD_INPUT  # rank > 0 of a refused folder: rank 0 prints the one line
        if refused is not None:
            raise refused
        if args.method == "fea" and out_dir is not None:
            case = _with_fea_output(case, out_dir)
        solution = solve_case(case, args.method, progress=_progress_line if args.method == "fea" else None)
        record = solution_record(solution)
        if args.sensitivities:
            _add_sensitivities(record, case, solution, args.method)
        if overrides:
            record["overrides"] = overrides
        if out_dir is not None and _mpi_rank() == 0:
            from wheelrail.contact_files import write_solution_files

            copy_input(resolve_case_path(args.case), out_dir, "case.toml")
            record["field_files"] = write_solution_files(solution, out_dir)  # NPZ + VTU per patch
            if args.plot:
                record["plots"] = _plot_patches(solution, out_dir) + _fea_views(solution, out_dir)
            write_json(out_dir / "summary.json", record)  # last: a summary exists only when every output does
    if args.json:
        _print(to_json(record))
    else:
        _print(_contact_table(record))
        if args.sensitivities:
            _print(_sensitivity_table(record))
        if out_dir is not None:
            _print(f"output written to {out_dir}")
    return EXIT_OK if record["status"] == "ok" else EXIT_FAILED


def _add_sensitivities(record: dict, case, solution, method: str) -> None:
    """``--sensitivities``: every patch's d(Fx, Fy, Mz)/d(xi, eta, phi, N) (rigid_dynamics.contact.sensitivities)
    into its record; a patch whose sensitivities failed makes the record's status "sensitivities-failed".
    """
    from rigid_dynamics.contact.sensitivities import OperatingPoint, creep_sensitivities

    options = case.solver_options if case.kind == "quadric" else (case.solver_options or {}).get("model")
    failed = []
    for patch, (side, geometry, creepage, result) in zip(record["patches"], solution.patches, strict=True):
        if result.status == "no-contact" or not result.normal_force_N:
            patch["sensitivities"] = None
            continue
        point = OperatingPoint(geometry, creepage, case.material, float(result.normal_force_N), options)
        sens = creep_sensitivities(method, point)
        patch["sensitivities"] = sens.to_dict()
        if not sens.success:
            failed.append(f"{side}: {sens.status}: {sens.message}")
    if failed and record["status"] == "ok":
        record["status"], record["success"] = "sensitivities-failed", False
        record["message"] = f"{record['message']}; sensitivities failed ({'; '.join(failed)})"


def _sensitivity_table(record: dict) -> str:
    """The sensitivities of every patch: one line per force, the four derivatives (units in the header)."""
    lines = ["sensitivities   d/dxi [N]    d/deta [N]  d/dphi [N m]    d/dN [-]  (Mz row: N m, N m, N m^2, m)"]
    for patch in record["patches"]:
        sens = patch.get("sensitivities")
        if not sens:
            continue
        lines.append(f"{patch['side']}: {sens['method']} {sens['kind']} ({sens['status']})")
        for row, label in (("creep_force_long_N", "Fx"), ("creep_force_lat_N", "Fy"), ("spin_moment_Nm", "Mz")):
            values = sens["jacobian"][row].values()
            lines.append(f"  {label:<12}" + "".join("         n/a" if v is None else f"{v:12.4g}" for v in values))
    return "\n".join(lines)


def _progress_line(text: str) -> None:
    """One line of progress on stderr (rank 0 only): a slow model (the FEA) reports each wheel evaluation."""
    if _mpi_rank() == 0:
        print(f"wheelrail: {text}", file=sys.stderr, flush=True)


def _mpi_broadcast(value):
    """Rank 0's ``value`` on every rank (so that a folder refused on rank 0 stops every rank, none waits forever)."""
    import dolfinx_solver  # noqa: F401  (must precede mpi4py)
    from mpi4py import MPI

    return MPI.COMM_WORLD.bcast(value, root=0)


def _with_fea_output(case, out_dir: Path):
    """Ask the FEA model to write its VTU grid and stress maps into ``<out>/fea`` (one sub-folder per patch)."""
    import dataclasses

    from wheelrail.output import subfolder

    fea_dir = str(subfolder(Path(out_dir), "fea"))
    options = dict(case.solver_options)
    if case.kind == "quadric":
        options["output_dir"] = fea_dir
    else:
        options["model"] = dict(options.get("model") or {}, output_dir=fea_dir)
    return dataclasses.replace(case, solver_options=options)


def _plot_patches(solution, out_dir: Path) -> list[str]:
    """PNG per patch: the model's fields, or for an analytic model Hertz's ellipse and pressure."""
    from wheelrail.contact_files import plot_patch

    written = []
    for index, (side, _geometry, _creepage, result) in enumerate(solution.patches):
        path = plot_patch(result, out_dir / f"fields-{side}-{index}.png")
        if path is not None:
            written.append(path.name)
    return written


def _fea_views(solution, out_dir: Path) -> list[str]:
    """3-D von Mises views (pyvista) of the FEA grids (``fea_von_mises_3d.png`` next to each ``fea_solution.vtu``)."""
    from comparisons.fea_views import render_stress_view

    written = []
    for _side, _geometry, _creepage, result in solution.patches:
        vtu = (result.extra.get("files") or {}).get("vtu")
        if vtu:
            png = Path(vtu).with_name("fea_von_mises_3d.png")
            try:
                render_stress_view(vtu, png)
            except Exception as exc:  # a VTK that cannot render off screen: the data files are written all the same
                print(f"wheelrail: 3-D view not drawn ({type(exc).__name__}: {exc})", file=sys.stderr)
                continue
            written.append(str(png.relative_to(out_dir)))
    return written


def _contact_table(record: dict) -> str:
    from wheelrail.cases import OK_PATCH_STATUSES

    lines = [f"method {record['method']}: {record['status']} - {record['message']}"]  # as the exit status says
    for patch in record["patches"]:
        if patch["status"] not in OK_PATCH_STATUSES:
            said = "" if patch["message"] == record["message"] else f" - {patch['message']}"
            lines.append(f"  {patch['side']}: {patch['status']}{said}")
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
    control = record.get("case", {}).get("force_control")
    if control is not None:
        solved = control["solved_creepage_long"]
        lines.append(
            f"force control: {control['status']}, longitudinal force {control['target_longitudinal_force_N']:.6g} N "
            f"prescribed, creepage {'-' if solved is None else format(solved, '.6g')} solved, residual "
            f"{'-' if control['residual_N'] is None else format(control['residual_N'], '.3g')} N "
            f"(tolerance {control['force_tolerance_N']:.3g} N, {control['evaluations']} evaluations)"
        )
    lines.append(f"wall time {record['wall_time_s']:.3g} s (set-up, compiled-code loading {record['setup_s']:.2g} s)")
    return "\n".join(lines)


# --- dynamics -----------------------------------------------------------------------------


def cmd_run(args) -> int:
    from wheelrail.output import output_folder
    from wheelrail.overrides import load_scene_with
    from wheelrail.scenes import DEFAULT_SCENE, write_run_outputs

    scene, source, overrides = load_scene_with(args.scene or DEFAULT_SCENE, args.set)
    _skip_collection_at_exit(scene.contact_model)  # 0.3 s CPU of a 2 s `run polygonal-wheel` (test_import_hygiene)
    from rigid_dynamics.wheelset import simulate

    with output_folder(args.out, f"run-{source.stem}") as out_dir:
        progress, close = _progress_bar(args.quiet, f"{source.stem}")
        before = time.perf_counter()
        try:
            result = simulate(scene, progress=progress)
        finally:
            close()
        _check_terminated()
        timing = {  # wall_time_s is the model's own work; what came before it is reported apart
            "startup_s": before - getattr(args, "started_at", before),
            "setup_s": time.perf_counter() - before - result.wall_time_s,
        }
        extra = {"overrides": overrides, **timing}
        summary = write_run_outputs(result, source, out_dir, plots=not args.no_plots, extra=extra)
    _print(
        f"{source.stem}: {summary['status']} - {summary['message']}; simulated {summary['simulated_time_s']:.3g} s "
        f"in {summary['wall_time_s']:.3g} s (real-time factor {summary['real_time_factor']:.3g}); "
        f"start-up {timing['startup_s']:.2g} s, set-up and compiled-code loading {timing['setup_s']:.2g} s"
    )
    if summary.get("discretisation_errors"):
        from rigid_dynamics.wheelset.discretisation import describe

        _print(describe(summary["discretisation_errors"]))
    for line in patch_summary_lines(summary) + event_lines(summary):
        _print(line)
    _print(f"output written to {out_dir}")
    return EXIT_OK if summary.get("success", summary["status"] == "ok") and summary["status"] == "ok" else EXIT_FAILED


EVENTS_PRINTED = 12
"""The events a run prints (the first ones; summary.json holds all)."""


def event_lines(summary: dict) -> list[str]:
    """The run's events (SimulationResult.events, in time order) as one line, e.g. "events: adhesion-limit left at
    0.045 s, wheel-slide left at 0.059 s", the first :data:`EVENTS_PRINTED` with the count of the rest; and the
    traction controller's last sample, if the scene has one.
    """
    lines = []
    events = summary.get("events") or []
    if events:
        shown = ", ".join(
            f"{e['kind']} {e['side']}" + (f" at {e['time_s']:.4g} s" if e.get("time_s") is not None else "")
            for e in events[:EVENTS_PRINTED]
        )
        more = len(events) - EVENTS_PRINTED
        lines.append(f"events: {shown}" + (f" and {more} more (summary.json)" if more > 0 else ""))
    traction = summary.get("traction")
    if traction:
        last = traction["last_sample"]
        demand = (
            f"force {traction['force_demand_N']:g} N"
            if traction["mode"] == "force"
            else f"adhesion {traction['adhesion_demand']:g} of the normal force"
        )
        names = ("traction_torque_N_m", "traction_demand_N", "traction_measured_force_N")
        numbers = [last.get(name) for name in names]
        if all(v is not None for v in numbers):
            lines.append(
                f"traction controller ({demand}): at the end torque {numbers[0]:.5g} N m, demand {numbers[1]:.5g} N, "
                f"longitudinal creep force {numbers[2]:.5g} N"
            )
    return lines


def patch_summary_lines(summary: dict) -> list[str]:
    """One line per patch slot in contact (SimulationResult.patch_summary) and one for the BEM warm start, e.g.
    "left flange patch (slot tread): sampled (bem), ellipticity residual 0.51 (max 3.7), max pressure 2345 MPa, area
    164.5 mm^2 (largest over the run)".
    """
    lines = []
    for name, entry in (summary.get("patch_summary") or {}).items():
        geometry = ", ".join(
            g if share == 1.0 else f"{g} {100 * share:.0f} %" for g, share in entry["geometry"].items()
        )  # fmt: skip
        side, slot = name.split(" ", 1)
        text = f"{side} {entry['contact']} patch (slot {slot}): {geometry} ({', '.join(entry['law'])})"
        residual = entry.get("ellipticity_residual")
        if residual:
            text += f", ellipticity residual {residual['median']:.2g} (max {residual['max']:.2g})"
        if entry.get("max_pressure_Pa") is not None:
            text += f", max pressure {entry['max_pressure_Pa'] / 1e6:.4g} MPa"
        if entry.get("contact_area_m2") is not None:
            text += f", area {entry['contact_area_m2'] * 1e6:.4g} mm^2"
        lines.append(text + " (largest over the run)")
    callback = summary.get("callback") or {}
    bem = callback.get("bem")
    if bem:
        lines.append(
            f"bem: {bem['solves']} solves, {bem['warm_solves']} warm-started, {bem['iterations']} NORM + TANG "
            f"iterations; patch sampling {callback['sampling_seconds']:.3g} s of {callback['seconds']:.3g} s"
        )
    grid = (summary.get("discretisation_errors") or {}).get("contact_grid") or {}
    grid = grid if "largest_all_quantities" in grid else grid.get("bem") or {}  # the model's own estimate, if any
    if grid.get("estimate") is not None:
        name = "bem" if bem else callback.get("model", "contact")
        lines.append(
            f"{name} grid error: largest estimate {100 * grid['estimate']:.2f} % of the patch forces (all quantities "
            f"{100 * grid['largest_all_quantities']:.2f} %), {grid['solves_above_grid_tolerance']} of "
            f"{grid['solves_estimated']} solves above grid_tolerance {grid['grid_tolerance']:g}"
        )
    return lines


def _progress_bar(quiet: bool, label: str):
    """A tqdm bar driven by fraction callbacks (off when quiet or not on a terminal), and the check for a swallowed
    termination at every report (:func:`_check_terminated`).
    """
    try:
        from tqdm import tqdm
    except ImportError:  # the progress extra not installed: no bar
        quiet = True
    if quiet or not sys.stderr.isatty():
        return lambda fraction: _check_terminated(), lambda: None

    bar = tqdm(total=1000, desc=label, unit="‰", leave=False, mininterval=0.5, delay=2.0)
    state = {"last": 0}

    def update(fraction: float) -> None:
        _check_terminated()
        target = int(1000 * min(max(fraction, 0.0), 1.0))
        if target > state["last"]:
            bar.update(target - state["last"])
            state["last"] = target

    return update, bar.close


def cmd_stress(args) -> int:
    import importlib.util

    from wheelrail.output import copy_input, output_folder, write_json
    from wheelrail.scenes import DEFAULT_STRESS_SCENE, load_scene, resolve_scene_path

    workers = check_local_workers("--workers", positive_int_option("--workers", args.workers))
    if workers > 1 and importlib.util.find_spec("distributed") is None:
        raise ConfigError(f"--workers {args.workers!r}: needs dask.distributed (pip install 'dask[distributed]')")
    source = resolve_scene_path(args.scene or DEFAULT_STRESS_SCENE)
    scene = load_scene(source)
    from comparisons.stress import ENERGY_SUSPECT_RELATIVE, run_stress_sweep

    with output_folder(args.out, f"stability-{source.stem}") as out_dir:
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
    for run in report.get("warnings", []):
        _print(f"stress sweep of {source.stem}: {run['parameter']} = {run['value']:g}: warning - {run['message']}")
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
    from wheelrail.config import check_physical_range

    for option in ("gauge_m", "flange_back_distance_m", "nominal_radius_m", "amplitude_m", "shift_step_m", "tolerance"):
        value = getattr(args, option)
        if value is None:  # shift_step_m: automatic
            continue
        if not (value > 0 and value < float("inf")):
            raise ConfigError(f"--{option.replace('_', '-')} {value!r}: expected a finite number > 0")
    for option in ("gauge_m", "gauge_height_m", "flange_back_distance_m", "nominal_radius_m", "amplitude_m"):
        check_physical_range(f"--{option.replace('_', '-')}", getattr(args, option), option)
    if args.rail_inclination_rad is not None:
        check_physical_range("--rail-inclination-rad", args.rail_inclination_rad, "rail_inclination_rad")
    result = equivalent_conicity_from_names(
        wheel_profile=profiles["wheel"],
        rail_profile=profiles["rail"],
        gauge_m=args.gauge_m,
        gauge_height_m=args.gauge_height_m,
        flange_back_distance_m=args.flange_back_distance_m,
        nominal_radius_m=args.nominal_radius_m,
        rail_inclination_rad=args.rail_inclination_rad,
        amplitude_m=args.amplitude_m,
        shift_step_m=args.shift_step_m,
        tolerance=args.tolerance,
    )
    if args.json:
        from wheelrail.output import to_json

        _print(to_json(result))
    else:
        _print(
            f"{result['status']}: equivalent conicity {result['equivalent_conicity']:.4f} "
            f"(+- {100 * result['discretisation_error_estimate']:.2g} %, table spacing "
            f"{1e3 * result['shift_step_m']:g} mm) at amplitude {1e3 * result['amplitude_m']:.2f} mm "
            f"({args.wheel} on {args.rail}); {result['message']}"
        )
    return EXIT_OK if result["status"] == "ok" else EXIT_FAILED


def cmd_manchester(args) -> int:
    from comparisons.manchester import run_manchester_a22
    from rigid_dynamics.contact.registry import MODELS
    from wheelrail.output import output_folder

    if args.method not in MODELS:
        raise ConfigError(f"--method {args.method!r}: expected one of {', '.join(MODELS)}")
    with output_folder(args.out, "manchester-a22", summaries=("manchester_a22_summary.json",)) as out_dir:
        summary = run_manchester_a22(out_dir, method=args.method, kinematics=args.kinematics)
    comparison = summary["contact_comparison"]
    for key, item in comparison["largest_difference"].items():
        unit = " mm" if key == "contact_y_rail" else " %"
        scale = 1e3 if key == "contact_y_rail" else 100.0
        _print(f"  largest difference to CONTACT, {key}: {scale * item['value']:.3g}{unit} (step {item['step']})")
    if comparison["patch_count_mismatch_steps"]:
        _print(f"  patch count differs from CONTACT at steps {comparison['patch_count_mismatch_steps']}")
    verdict = "within" if comparison["within_tolerance"] else "NOT within"
    _print(
        f"Manchester A-2.2 ({args.method}, {args.kinematics}): {verdict} the tolerances against CONTACT; "
        f"output written to {out_dir}"
    )
    return EXIT_OK if summary["all_converged"] else EXIT_FAILED


# --- shared helpers for subcommands -------------------------------------------------------


def positive_int_option(option: str, value) -> int:
    """An integer >= 1 given on the command line (ConfigError naming the option and the value otherwise)."""
    try:
        number = int(str(value))
    except ValueError:
        number = 0
    if number < 1:
        raise ConfigError(f"{option} {value!r}: expected an integer >= 1")
    return number


WORKER_MEMORY_BYTES = 400 * 2**20
"""Resident memory of one local dask worker process running a sweep point or a stress run: a hunting-conical point
peaked at 294 MiB (numpy, scipy, numba, dask and the compiled core loaded); rounded up. A lower bound for points of
the 3-D search or FEA, which need more."""


def _available_memory_bytes() -> int | None:
    """MemAvailable of /proc/meminfo (None where there is none)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def check_local_workers(option: str, workers: int) -> int:
    """``workers`` local worker processes, refused (ConfigError with the estimate) when their memory
    (:data:`WORKER_MEMORY_BYTES` each) exceeds the available memory, or when they are more than 8 per core.
    """
    cores = os.cpu_count() or 1
    need = workers * WORKER_MEMORY_BYTES
    available = _available_memory_bytes()
    if available is not None and need > available:
        raise ConfigError(
            f"{option} {workers!r}: {workers} worker processes need about {need / 2**30:.3g} GiB "
            f"({WORKER_MEMORY_BYTES / 2**20:.0f} MiB each), {available / 2**30:.3g} GiB is available; "
            f"expected at most {max(1, available // WORKER_MEMORY_BYTES)}"
        )
    if workers > 8 * cores:
        raise ConfigError(
            f"{option} {workers!r}: expected at most {8 * cores} (8 per core; this machine has {cores}): more "
            "single-threaded workers than that only contend for the cores"
        )
    return workers


def out_path(text: str) -> Path:
    """The argparse ``type`` of every ``--out``: a non-empty path (``--out ""`` would mean the current folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected a folder path (an empty path would mean the current folder)"
        )
    return Path(text)


def finite_float(option: str):
    """An argparse ``type`` for a finite number; the error names the option and the value (exit status 2)."""

    def parse(text: str) -> float:
        import math

        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text!r}: expected a finite number")
        return value

    parse.__name__ = option
    return parse


# --- parser -------------------------------------------------------------------------------


def _add_listings(sub) -> None:
    sub.add_parser("scenes", help="list the embedded dynamics scenes").set_defaults(func=cmd_scenes)
    sub.add_parser("cases", help="list the embedded contact cases").set_defaults(func=cmd_cases)
    sub.add_parser("models", help="list the contact models and their options").set_defaults(func=cmd_models)


def _add_run(sub) -> None:
    run = sub.add_parser("run", help="run a dynamics scene")
    run.add_argument("scene", nargs="?", help="embedded scene name or TOML file (default: the default scene)")
    run.add_argument("--out", type=out_path, help="output folder (default: wheelrail-out/run-<scene>-<time>)")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument("--no-plots", action="store_true", help="do not write PNG plots")
    run.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene key (repeatable)")
    run.set_defaults(func=cmd_run)


def _add_contact(sub) -> None:
    contact = sub.add_parser("contact", help="solve a contact case")
    contact.add_argument("case", help="embedded case name or TOML file")
    contact.add_argument("--method", default="auto", help="contact model (see `wheelrail models`)")
    contact.add_argument("--json", action="store_true", help="print one JSON object")
    contact.add_argument("--plot", action="store_true", help="write PNG maps of the patch fields")
    contact.add_argument("--out", type=out_path, help="output folder for summary, field files and plots")
    contact.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a case key (repeatable)")
    contact.add_argument(
        "--sensitivities",
        action="store_true",
        help="also d(Fx, Fy, Mz)/d(xi, eta, phi, N) per patch (analytic: linear, vermeulen-johnson; else central "
        "differences with their error)",
    )
    contact.set_defaults(func=cmd_contact)


def _add_conicity(sub) -> None:
    conicity = sub.add_parser("conicity", help="equivalent conicity (EN 15302 method)")
    conicity.add_argument(
        "--wheel", default="S1002", help="wheel profile: built-in name or file (default S1002, as the scenes)"
    )
    conicity.add_argument(
        "--rail", default="UIC60", help="rail profile: built-in name or file (default UIC60, as the scenes)"
    )
    number = finite_float
    conicity.add_argument("--gauge-m", type=number("--gauge-m"), default=1.435)
    conicity.add_argument("--gauge-height-m", type=number("--gauge-height-m"), default=0.014)
    conicity.add_argument("--flange-back-distance-m", type=number("--flange-back-distance-m"), default=1.360)
    conicity.add_argument("--nominal-radius-m", type=number("--nominal-radius-m"), default=0.46)
    conicity.add_argument(
        "--rail-inclination-rad",
        type=number("--rail-inclination-rad"),
        default=None,
        help="cant of the rail (default: 1:40)",
    )
    conicity.add_argument(
        "--amplitude-m", type=number("--amplitude-m"), default=0.003, help="wheelset amplitude (EN 15302: 3 mm)"
    )
    conicity.add_argument(
        "--shift-step-m",
        type=number("--shift-step-m"),
        default=None,
        help="spacing of the Delta r table, m (default: min(0.1 mm, amplitude / 30), halved up to 3 times until the "
        "tolerance is met)",
    )
    conicity.add_argument(
        "--tolerance",
        type=number("--tolerance"),
        default=0.01,
        help="accepted relative change of the conicities on a table twice as coarse (exit 1 above it)",
    )
    conicity.add_argument("--json", action="store_true")
    conicity.set_defaults(func=cmd_conicity)


def _add_manchester(sub) -> None:
    manchester = sub.add_parser("manchester", help="Manchester Contact Benchmark case A-2.2 sweep")
    manchester.add_argument("--out", type=out_path)
    manchester.add_argument("--method", default="bem", help="contact model (default bem, on CONTACT's 0.2 mm grid)")
    manchester.add_argument(
        "--kinematics",
        choices=("deck", "equilibrium"),
        default="deck",
        help="deck: CONTACT's roll and pitch rate per step (default); equilibrium: roll and pitch rate solved",
    )
    manchester.set_defaults(func=cmd_manchester)


def _add_stress(sub) -> None:
    stress = sub.add_parser(
        "stability", aliases=["stress"], help="numerical-stability sweep of a scene (steps, stiffness, tolerances; "
        "alias: stress)",
    )  # fmt: skip
    stress.add_argument("scene", nargs="?", help="embedded scene name or TOML file (default: hunting-conical)")
    stress.add_argument("--out", type=out_path, help="output folder (default: wheelrail-out/stability-<scene>-<time>)")
    stress.add_argument("--quick", action="store_true", help="a small sweep")
    stress.add_argument(
        "--workers",
        default="1",
        metavar="N",
        help="1: run serially (default); N >= 2: on a local dask.distributed cluster of N single-threaded processes",
    )
    stress.set_defaults(func=cmd_stress)


COMMANDS: list = [_add_listings, _add_run, _add_contact, _add_conicity, _add_manchester, _add_stress]
"""Functions ``add(subparsers)`` that add one or more subcommands (each sets ``func`` to its ``cmd_*``).

A new subcommand in its own module: write ``cmd_x(args) -> int`` and ``add_x(sub)`` there, and add
``"package.module:add_x"`` to :data:`COMMAND_MODULES` (imported only when the parser is built)."""

COMMAND_MODULES: list[str] = [
    "wheelrail.sweep:register",
    "wheelrail.critical:register",
    "wheelrail.comparison_commands:register",  # bench, compare, demo
]
"""``"module:function"`` strings of subcommands defined in other modules (see :data:`COMMANDS`)."""


def register(add) -> None:
    """Register a function ``add(subparsers)`` that adds a subcommand (for modules imported before the parser)."""
    COMMANDS.append(add)


class _HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """``--help`` with each option's default (where it has one and its help does not already say it) and the
    command's examples kept as written.
    """

    def _get_help_string(self, action):
        text = action.help or ""
        default = action.default
        if (
            "default" in text
            or default in (None, False, argparse.SUPPRESS)
            or not action.option_strings
            or isinstance(default, list)
        ):
            return text
        return f"{text} (default: {default})"


EXAMPLES = {
    "run": ["wheelrail run polygonal-wheel --out out/poly", 'wheelrail run curve-flange --set contact_model="bem"',
            "wheelrail run wheel-flat --set speed_m_per_s=20 --no-plots"],
    "contact": ["wheelrail contact hertz-quadric --method fastsim --json",
                "wheelrail contact manchester-a22 --method bem --plot --out out/a22",
                "wheelrail contact large-spin --method bem --set solver.grid_tolerance=0.01"],
    "conicity": ["wheelrail conicity", "wheelrail conicity --wheel worn_high_mileage.prw --rail site_b_hr.prr"],
    "manchester": ["wheelrail manchester --method bem --out out/a22"],
    "stability": ["wheelrail stability polygonal-wheel --quick", "wheelrail stability curve --workers 2"],
    "bench": ["wheelrail bench --quick", "wheelrail bench --cases a22-flange large-spin --models fastsim bem"],
    "compare": ["wheelrail compare a22-flange", "wheelrail compare large-spin --models hertz fastsim bem"],
    "demo": ["wheelrail demo", "wheelrail demo curve-flange --models hertz fastsim bem"],
    "sweep": ["wheelrail sweep study.toml --workers 2 --out out/study"],
    "critical-speed": ["wheelrail critical-speed hunting-conical", "wheelrail critical-speed curve --high 60"],
}  # fmt: skip
"""Command -> example command lines shown by ``wheelrail COMMAND --help``."""


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: ``wheelrail: error: ...`` and exit status 2 (no usage block)."""

    def error(self, message: str):
        command = self.prog.removeprefix("wheelrail").strip()
        raise ConfigError(f"{command}: {message}" if command else message)


def build_parser() -> argparse.ArgumentParser:
    import importlib

    from wheelrail import __version__

    parser = _Parser(
        prog="wheelrail",
        description="Railway wheelset dynamics and wheel-rail contact with a verified ladder of contact models.",
        epilog="start with:\n  wheelrail demo\n  wheelrail contact hertz-quadric --method fastsim\n"
        "  wheelrail run polygonal-wheel\n`wheelrail COMMAND --help` gives each command's options, defaults and "
        "examples.",
        formatter_class=_HelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"wheelrail {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for add in COMMANDS:
        add(sub)
    for target in COMMAND_MODULES:
        module_name, function = target.split(":")
        getattr(importlib.import_module(module_name), function)(sub)
    for name, command in sub.choices.items():  # defaults and examples in every command's --help
        command.formatter_class = _HelpFormatter
        examples = EXAMPLES.get(name) or EXAMPLES.get(command.prog.removeprefix("wheelrail ").strip(), [])
        if examples and command.epilog is None:
            command.epilog = "examples:\n" + "\n".join(f"  {line}" for line in examples)
    return parser


_TERMINATION = {"requested": False, "redeliver": None}


def _forget_termination() -> None:
    """The run is over: no request kept, and no pending redelivery that could outlive the handler."""
    timer = _TERMINATION["redeliver"]
    if timer is not None:
        timer.cancel()
    _TERMINATION.update(requested=False, redeliver=None)


_NATIVE_OWNERS = ("numba", "llvmlite")  # packages whose Python code hands objects to C++ that frees them itself
_REDELIVER_S = 0.05


def _unwinding_is_unsafe(frame) -> bool:
    """True while an exception raised here could corrupt native state: numba compiling or loading a kernel from its
    cache (its compiler lock is held), or any frame of numba/llvmlite on the stack (an exception between llvmlite's
    transfer of a module to LLVM and its Python bookkeeping frees the module twice: "free(): double free detected",
    SIGABRT, seen in CI), or a finalizer of theirs (where the exception would be printed and swallowed).
    """
    lock_module = sys.modules.get("numba.core.compiler_lock")
    if lock_module is not None and lock_module.global_compiler_lock.is_locked():
        return True
    while frame is not None:
        package = frame.f_globals.get("__name__", "").partition(".")[0]
        if package in _NATIVE_OWNERS:
            return True
        frame = frame.f_back
    return False


def _redeliver_later(signum) -> None:
    import threading

    timer = threading.Timer(_REDELIVER_S, os.kill, (os.getpid(), signum))
    timer.daemon = True
    _TERMINATION["redeliver"] = timer
    timer.start()


def _terminate(signum, frame):
    """SIGTERM: unwind like Ctrl-C (temporary files removed, lock released, exit status 143). Inside numba's or
    llvmlite's code the unwinding waits: the request is kept, and the signal is sent again shortly (and the run's
    next progress report raises it too, :func:`_check_terminated`), until it lands in the toolkit's own code.
    """
    _TERMINATION["requested"] = True
    if _unwinding_is_unsafe(frame):
        _redeliver_later(signum)
        return
    raise SystemExit(EXIT_TERMINATED)


def _interrupt(signum, frame):
    """SIGINT (Ctrl-C): KeyboardInterrupt as Python's own handler raises it, but, like SIGTERM, not inside numba's
    or llvmlite's code (there it waits and the signal is sent again shortly).
    """
    if _unwinding_is_unsafe(frame):
        _redeliver_later(signum)
        return
    raise KeyboardInterrupt


def _check_terminated() -> None:
    """Raise the termination again if SIGTERM came and the run goes on: a signal handler's exception that lands in a
    finalizer or weakref callback (numba's type cache has one) is printed as "Exception ignored" and swallowed.
    Called at every progress report of a run and before its outputs are written.
    """
    if _TERMINATION["requested"]:
        raise SystemExit(EXIT_TERMINATED)


def _unreadable_cache_files(exc: BaseException) -> list[Path]:
    """The numba cache files (index ``.nbi``, data ``.nbc``) whose loading raised ``exc`` (empty if it came from
    elsewhere): read from the frames of numba's cache loader in the traceback.
    """
    files = []
    tb = exc.__traceback__
    while tb is not None:
        frame = tb.tb_frame
        if frame.f_code.co_filename.replace("\\", "/").endswith("numba/core/caching.py"):
            owner = frame.f_locals.get("self")
            for candidate in (getattr(owner, "_index_path", None), frame.f_locals.get("path")):
                if isinstance(candidate, str) and candidate.endswith((".nbi", ".nbc")):
                    files.append(Path(candidate))
        tb = tb.tb_next
    return list(dict.fromkeys(files))


def _run_rebuilding_cache(args) -> int:
    """``args.func(args)``; a numba cache file that cannot be read (corrupted: UnpicklingError, EOFError, ...) is
    removed with a one-line note and the command runs once more, compiling the kernel again (its cache is rewritten).
    """
    try:
        return args.func(args)
    except Exception as exc:
        files = _unreadable_cache_files(exc)
        if not files:
            raise
        for path in files:
            try:
                path.unlink(missing_ok=True)
            except OSError:
                raise exc from None  # cannot repair it: the original error
        names = ", ".join(str(p) for p in files)
        print(
            f"wheelrail: note: the compiled-code cache {names} could not be read ({type(exc).__name__}: {exc}); "
            "removed, compiling again (this run takes longer)",
            file=sys.stderr,
        )
    return args.func(args)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``wheelrail`` console script; returns the exit status (module docstring)."""
    import signal
    import threading

    from rigid_dynamics.files import WriteError

    start = time.perf_counter()
    previous = previous_int = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _terminate)
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # (left alone when SIGINT is ignored)
            previous_int = signal.signal(signal.SIGINT, _interrupt)
    try:
        args = build_parser().parse_args(argv)
        args.started_at = start
        return _run_rebuilding_cache(args)
    except ConfigError as exc:
        print(f"wheelrail: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except WriteError as exc:
        print(
            f"wheelrail: error: cannot write {exc.filename!r}: {exc.strerror} "
            "(the run's outputs are incomplete; no summary.json was written)",
            file=sys.stderr,
        )
        return EXIT_OUTPUT_FAILED
    except BrokenPipeError:  # the reader of stdout went away (| head): nothing left to say
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_FAILED
    except KeyboardInterrupt:
        print(f"wheelrail: interrupted after {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return EXIT_INTERRUPTED
    except ValueError as exc:
        # Bad input is a ConfigError, raised by the checks that run before any work (above: exit 2). Any other
        # ValueError came from the work itself (a library check that failed mid-run): a failure of the work, not
        # bad input. One line, exit 1; WHEELRAIL_DEBUG=1 shows the traceback.
        if os.environ.get("WHEELRAIL_DEBUG"):
            raise
        print(f"wheelrail: error: the work failed: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_FAILED
    finally:
        _forget_termination()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if previous_int is not None:
            signal.signal(signal.SIGINT, previous_int)


if __name__ == "__main__":
    sys.exit(main())
