"""``wheelrail sweep SWEEP.toml``: a parameter study over a scene or a contact case, each point a dask task.

A sweep file::

    description = "speed and friction"
    scene = "hunting-conical"          # or: case = "hertz-quadric" (an embedded name or a path next to this file)
    method = "fastsim"                 # contact model of a case (a parameter "method" varies it)
    metrics = ["max_abs_lateral_displacement_m"]   # columns drawn in sweep.png (optional)

    [set]                              # dotted keys applied to every point (as --set)
    duration_s = 0.5

    [grid]                             # every combination of these values
    speed_m_per_s = [10.0, 20.0, 30.0]
    "material.friction_coefficient" = [0.2, 0.4]

    [[points]]                         # and/or explicit points
    speed_m_per_s = 40.0

Any key of the scene or case can be a parameter: speed, friction, irregularity amplitude or wavelength
(``irregularities.polygon_amplitude_m``), ``contact_model``, lateral shift (``geometry.lateral_shift_m``),
profile pairs (``track.wheel_profile``, ``geometry.rail_profile``). Every point is validated like a file before
any worker starts (a bad value in ``[grid]``, ``[set]``, ``[[points]]`` or ``--set``, an unknown method or model:
exit status 2 naming the point and the key, nothing written), then run on a worker and recorded as one row. A
case point's status is the one ``wheelrail contact`` gives on the same input (``beyond-friction-limit`` is not ok).

Outputs in the folder: ``points/<id>.json`` per finished point (written as it finishes, atomically), the
tidy table ``sweep.csv`` and ``sweep.parquet`` (one row per point: ``point``, the parameters by their dotted
keys, ``status``, ``message``, ``success`` and every scalar result with its unit in the name), ``sweep.png``
(each metric against each varied numeric parameter; failed points marked) and ``summary.json``.

Resume: a rerun into the same folder skips the points that have a file in ``points/``. A point's id is a hash of
the whole resolved point (the base file's content with ``[set]``, ``--set`` and the point's parameters applied, the
method, the folder its relative file names refer to), so an extended grid runs only its new points and a changed
setting or method runs every point again instead of reusing numbers of other settings. A numerical failure is a
finished point (its status and message are kept); a point whose worker was lost is recorded as ``worker-lost`` but
not kept, so a rerun tries it again. Runs on a dask.distributed LocalCluster of ``--workers`` single-threaded
processes (default 2; TLS on credentials made for it alone, see comparisons.stress.local_dask_client: no other
local process can run code in it), or on the cluster at ``--scheduler ADDRESS`` (trusted: see the README).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from collections.abc import Callable
from contextlib import suppress
from pathlib import Path

from wheelrail.config import ConfigError, check_keys, read_toml

SWEEP_KEYS = {"description", "name", "scene", "case", "method", "metrics", "set", "grid", "points"}
DEFAULT_METRICS = {
    "scene": ("max_abs_lateral_displacement_m", "left_peak_normal_force_N"),
    "case": ("patch0_creep_force_long_N", "patch0_max_pressure_Pa"),
}
MAX_POINTS = 100_000
"""Points of one sweep at most (a grid of 1000 x 1000 values is refused before anything is built)."""
VALIDATION_S_PER_POINT = 5.5e-3
"""Time to validate one point before the work (hunting-conical, measured on the shared 2-core machine)."""
RETRIED_STATUSES = ("worker-lost",)
"""Statuses of points that are not kept as finished (a rerun runs them again)."""


SCHEDULER_TIMEOUT_S = 10.0
"""Seconds to reach a ``--scheduler`` (connection and handshake) before giving up with one line."""


def point_id(parameters: dict) -> str:
    """A stable 12-hex-digit id of a JSON-able mapping (a point's resolved description, :func:`resolved_point`)."""
    text = json.dumps(parameters, sort_keys=True, default=str)
    return hashlib.sha1(text.encode("utf-8")).hexdigest()[:12]


def resolved_point(spec: dict, parameters: dict) -> dict:
    """The whole description of one point (what its id hashes): kind, resolved document, method, base folder.

    Raises:
        ConfigError: a bad value or an unknown key, method or model (naming the point's parameters and the key).
    """
    from wheelrail.overrides import apply_overrides

    values = dict(parameters)
    method = values.pop("method", spec["method"]) if spec["kind"] == "case" else None
    base_dir = spec["base_path"].parent
    try:
        doc = apply_overrides(spec["base_doc"], values)
        if spec["kind"] == "scene":
            from wheelrail.scenes import parse_scene

            parse_scene(doc, base_dir=base_dir)
        else:
            from wheelrail.cases import check_solver_options, parse_case

            if not isinstance(method, str):
                raise ConfigError(f"key 'method' = {method!r}: expected a contact model name")
            check_solver_options(parse_case(doc, name=spec["base_path"].stem, base_dir=base_dir), method)
    except ConfigError as exc:
        shown = ", ".join(f"{k} = {v!r}" for k, v in parameters.items())
        raise ConfigError(f"sweep point ({shown}): {exc}".replace("--method", "method")) from None
    return {"kind": spec["kind"], "doc": doc, "method": method, "base_dir": str(base_dir)}


def load_sweep(path: str | Path, overrides: dict | None = None) -> dict:
    """Read and check a sweep file and every one of its points; returns the spec (kind, base path, base document,
    method, points, metrics).

    ``overrides``: dotted keys applied to every point after the file's ``[set]`` (the CLI's ``--set``).

    Raises:
        ConfigError: bad keys or values, in the file or in any point (the message names the key).
    """
    from wheelrail.overrides import apply_overrides

    path = Path(path)
    doc = read_toml(path, "sweep file")
    check_keys(doc, SWEEP_KEYS, "")
    if ("scene" in doc) == ("case" in doc):
        raise ConfigError("sweep file: expected exactly one of the keys 'scene' and 'case'")
    kind = "scene" if "scene" in doc else "case"
    base = doc[kind]
    if not isinstance(base, str):
        raise ConfigError(f"key {kind!r} = {base!r}: expected an embedded {kind} name or a file path")
    if kind == "scene":
        from wheelrail.scenes import resolve_scene_path as resolve
    else:
        from wheelrail.cases import resolve_case_path as resolve
    candidate = path.parent / base
    base_path = resolve(candidate if candidate.is_file() else base)
    method = doc.get("method", "auto")
    if kind == "scene" and "method" in doc:
        raise ConfigError("key 'method': a scene's model is its key 'contact_model' (vary it in [grid])")
    if not isinstance(method, str):
        raise ConfigError(f"key 'method' = {method!r}: expected a contact model name")
    fixed = doc.get("set", {})
    if not isinstance(fixed, dict):
        raise ConfigError(f"key 'set' = {fixed!r}: expected a table of dotted keys")
    settings = {**_flatten(fixed), **(overrides or {})}
    base_doc = apply_overrides(read_toml(base_path, f"{kind} file"), settings)
    points = _points(doc)
    metrics = doc.get("metrics", list(DEFAULT_METRICS[kind]))
    if not (isinstance(metrics, list) and all(isinstance(m, str) for m in metrics)):
        raise ConfigError(f"key 'metrics' = {metrics!r}: expected a list of column names")
    spec = {
        "kind": kind,
        "base_path": base_path,
        "base_doc": base_doc,
        "method": method,
        "points": points,
        "metrics": metrics,
        "set": settings,
        "description": str(doc.get("description", "")),
    }
    point_ids(spec)  # every point validated here, before any work
    return spec


def point_ids(spec: dict) -> list[str]:
    """The id of every point of ``spec`` (each validated: ConfigError on the first bad one)."""
    return [point_id(resolved_point(spec, parameters)) for parameters in spec["points"]]


def _flatten(table: dict, prefix: str = "") -> dict:
    """Nested tables -> dotted keys (a quoted dotted key stays as it is)."""
    out = {}
    for key, value in table.items():
        dotted = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict):
            out.update(_flatten(value, dotted))
        else:
            out[dotted] = value
    return out


def _points(doc: dict) -> list[dict]:
    grid = doc.get("grid", {})
    if not isinstance(grid, dict):
        raise ConfigError(f"key 'grid' = {grid!r}: expected a table of value lists")
    grid = _flatten(grid)
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise ConfigError(f"key 'grid.{key}' = {values!r}: expected a non-empty list of values")
    explicit = doc.get("points", [])
    if not (isinstance(explicit, list) and all(isinstance(p, dict) for p in explicit)):
        raise ConfigError(f"key 'points' = {explicit!r}: expected [[points]] tables")
    count = math.prod(len(values) for values in grid.values()) if grid else 0
    if count + len(explicit) > MAX_POINTS:
        sizes = " x ".join(str(len(values)) for values in grid.values()) or "0"
        raise ConfigError(
            f"table [grid] ({sizes} = {count} points) and {len(explicit)} [[points]]: expected at most {MAX_POINTS} "
            f"points in one sweep (each is a run; validating them alone would take about "
            f"{(count + len(explicit)) * VALIDATION_S_PER_POINT / 60:.3g} minutes before the first run starts); "
            "split the study into several sweeps"
        )
    points = [dict(zip(grid, combo, strict=True)) for combo in itertools.product(*grid.values())] if grid else []
    points += [_flatten(p) for p in explicit]
    if not points:
        raise ConfigError("sweep file: expected a [grid] table or [[points]] tables (no point to run)")
    return points


def run_point(task: dict) -> dict:
    """Run one point (module-level: runs on a dask worker). Never raises: trouble is a status in the record."""
    parameters = task["parameters"]
    record = {"point": task["id"], **parameters}
    try:
        doc, method = task["doc"], task["method"]
        if task["kind"] == "scene":
            from rigid_dynamics.wheelset import simulate
            from wheelrail.scenes import parse_scene

            scene = parse_scene(doc, base_dir=Path(task["base_dir"]))
            result = simulate(scene)
            numbers = result.summary()
        else:
            from wheelrail.cases import parse_case, solution_record, solve_case

            case = parse_case(doc, name=task["name"], base_dir=Path(task["base_dir"]))
            numbers = _case_numbers(solution_record(solve_case(case, method)), method)
    except ConfigError as exc:
        return {**record, "status": "invalid-input", "success": False, "message": str(exc)}
    except Exception as exc:
        return {**record, "status": "error", "success": False, "message": f"{type(exc).__name__}: {exc}"}
    finally:
        from rigid_dynamics.files import ignore_sigpipe

        ignore_sigpipe()  # an FEA point (dolfinx, gmsh) resets it: the worker's closing connection must not kill it
    for key, value in _scalars(numbers).items():
        record.setdefault(key, value)
    record.setdefault("success", record.get("status") == "ok")
    return record


def _case_numbers(record: dict, method: str) -> dict:
    status = record["status"]  # the case's one status, as `contact` prints it and exits with
    out = {
        "status": status,
        "message": record["message"],
        "method": method,
        "wall_time_s": record["wall_time_s"],
        "success": status == "ok",
    }
    for k, patch in enumerate(record["patches"]):
        for key, value in patch.items():
            if key != "diagnostics":
                out[f"patch{k}_{key}"] = value
    for key, value in (record.get("case") or {}).items():
        out[f"case_{key}"] = value
    return out


def _scalars(numbers: dict, prefix: str = "") -> dict:
    """Scalar entries of a (nested) summary; nested {left: x} under key k_N -> left_k_N."""
    out = {}
    for key, value in numbers.items():
        name = f"{prefix}_{key}" if prefix else key
        if isinstance(value, dict):
            for sub, inner in value.items():
                if isinstance(inner, (int, float, str, bool)) or inner is None:
                    out[f"{sub}_{name}"] = inner
        elif isinstance(value, (list, tuple)):
            if len(value) <= 3 and all(isinstance(v, (int, float)) or v is None for v in value):
                for i, v in enumerate(value):
                    out[f"{name}[{i}]"] = v
        elif isinstance(value, (int, float, str, bool)) or value is None:
            out[name] = value
    return out


def run_sweep(
    spec: dict,
    out_dir: str | Path,
    *,
    client=None,
    workers: int = 2,
    scheduler: str | None = None,
    on_record: Callable[[dict, int, int], None] | None = None,
) -> dict:
    """Run the points of ``spec`` (:func:`load_sweep`) that ``out_dir/points`` does not hold; write the outputs.

    Args:
        spec: a loaded sweep.
        out_dir: output folder (resumed if it holds points).
        client: a ``dask.distributed.Client`` to use (``workers`` and ``scheduler`` are then ignored).
        workers: size of the LocalCluster started when neither ``client`` nor ``scheduler`` is given.
        scheduler: address of a running scheduler.
        on_record: callable(record, done, total) after each point (e.g. progress).

    Returns:
        The summary (also written to ``summary.json``): ``points``, ``ran``, ``skipped``, ``statuses``, ``files``.
    """
    from wheelrail.output import subfolder

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    points_dir = subfolder(out, "points")  # never a planted link: a point file lands inside the folder
    resolved = [resolved_point(spec, parameters) for parameters in spec["points"]]
    ids = [point_id(point) for point in resolved]
    tasks, kept = [], []
    for pid, parameters, point in zip(ids, spec["points"], resolved, strict=True):
        stored = points_dir / f"{pid}.json"
        if stored.is_file() and not stored.is_symlink():
            kept.append(_stored_record(stored, pid))
            continue
        tasks.append({"id": pid, "parameters": parameters, "name": spec["base_path"].stem, **point})
    new_records = []
    if tasks:
        if client is not None:
            new_records = _run_on(client, tasks, out, on_record)
        else:
            with sweep_client(workers, scheduler) as chosen:
                new_records = _run_on(chosen, tasks, out, on_record)
    order = {pid: i for i, pid in enumerate(ids)}
    records = sorted(kept + new_records, key=lambda r: order.get(r["point"], len(order)))
    files = _write_outputs(records, spec, out)
    statuses: dict[str, int] = {}
    for record in records:
        statuses[record["status"]] = statuses.get(record["status"], 0) + 1
    summary = {
        "description": spec["description"],
        spec["kind"]: str(spec["base_path"]),
        "set": spec["set"],
        "points": len(records),
        "ran": len(new_records),
        "skipped": len(kept),
        "statuses": statuses,
        "files": files,
    }
    from wheelrail.output import write_json

    write_json(out / "summary.json", summary)
    return summary


def _stored_record(path: Path, pid: str) -> dict:
    """The record of a finished point (a point file that does not parse is a user's edit: WriteError-free refusal)."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise ConfigError(f"sweep resume: the point file {str(path)!r} cannot be read ({exc}); remove it") from None
    if not isinstance(record, dict) or record.get("point") != pid or "status" not in record:
        raise ConfigError(f"sweep resume: the point file {str(path)!r} is not a record of point {pid}; remove it")
    return record


def check_scheduler(address) -> str:
    """A ``--scheduler`` address (``[tcp|tls]://HOST:PORT`` or ``HOST:PORT``), checked; ConfigError naming it."""
    import re

    text = "" if address is None else str(address)
    match = re.fullmatch(r"(?:(tcp|tls)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):([0-9]{1,5})", text.strip())
    if not match or not 1 <= int(match.group(3)) <= 65535:
        raise ConfigError(
            f"--scheduler {text!r}: expected the address of a running dask scheduler, [tcp|tls]://HOST:PORT or "
            "HOST:PORT with a port 1-65535 (leave the option out to run on a local cluster)"
        )
    return text.strip()


def sweep_client(workers: int, scheduler: str | None = None):
    """A context manager giving the dask Client of a sweep: the cluster at ``scheduler`` (reached within
    :data:`SCHEDULER_TIMEOUT_S`; ConfigError naming ``--scheduler`` if it cannot be reached), else a local TLS
    cluster of ``workers`` processes (comparisons.stress.local_dask_client).
    """
    from contextlib import contextmanager

    @contextmanager
    def remote(address):
        import threading

        import dask
        from distributed import Client

        # dask's own timeout does not bound a port that accepts and never answers: the connection is made in a
        # thread given the timeout (left behind, as a daemon, if it hangs)
        outcome: dict = {}

        def connect():
            try:
                with dask.config.set({"distributed.comm.timeouts.connect": f"{SCHEDULER_TIMEOUT_S}s"}):
                    outcome["client"] = Client(address, timeout=f"{SCHEDULER_TIMEOUT_S}s", set_as_default=False)
            except Exception as exc:  # reported below in one line
                outcome["error"] = exc

        thread = threading.Thread(target=connect, name="wheelrail-scheduler-connect", daemon=True)
        thread.start()
        thread.join(SCHEDULER_TIMEOUT_S + 1.0)
        if "client" not in outcome:
            exc = outcome.get("error")
            reason = (
                "no answer" if exc is None else f"{type(exc).__name__}: {(str(exc) or 'no answer').splitlines()[0]}"
            )
            raise ConfigError(
                f"--scheduler {address!r}: no dask scheduler answered within {SCHEDULER_TIMEOUT_S:g} s ({reason})"
            )
        with outcome["client"] as client:
            yield client

    if scheduler is not None:
        return remote(check_scheduler(scheduler))
    from comparisons.stress import local_dask_client

    return local_dask_client(workers)


def _run_on(client, tasks: list[dict], out: Path, on_record) -> list[dict]:
    from distributed import as_completed

    from wheelrail.output import write_json

    futures = client.map(run_point, tasks, pure=False)
    index = {future.key: i for i, future in enumerate(futures)}
    records = []
    try:
        for done, future in enumerate(as_completed(futures), start=1):
            task = tasks[index[future.key]]
            try:
                record = future.result()
            except Exception as exc:  # run_point never raises: the worker died or the task was lost
                record = {
                    "point": task["id"],
                    **task["parameters"],
                    "status": "worker-lost",
                    "success": False,
                    "message": f"{type(exc).__name__}: {exc}",
                }
            if record["status"] not in RETRIED_STATUSES:
                write_json(out / "points" / f"{task['id']}.json", record)
            records.append(record)
            future.release()
            if on_record is not None:
                on_record(record, done, len(tasks))
    except BaseException:
        with suppress(Exception):
            client.cancel(futures)
        raise
    return records


def _write_outputs(records: list[dict], spec: dict, out: Path) -> list[str]:
    import pandas as pd

    from wheelrail.output import atomic_write

    frame = pd.DataFrame(records)
    for column in frame.columns:  # mixed None/number columns stay numeric; text columns stay text
        if frame[column].dtype == object:
            converted = pd.to_numeric(frame[column], errors="coerce")
            if converted.notna().sum() == frame[column].notna().sum():
                frame[column] = converted
    files = []
    atomic_write(out / "sweep.csv", lambda tmp: frame.to_csv(tmp, index=False))
    files.append("sweep.csv")
    text_columns = [c for c in frame.columns if frame[c].dtype == object]
    parquet = frame.astype({c: "string" for c in text_columns})
    atomic_write(out / "sweep.parquet", lambda tmp: parquet.to_parquet(tmp, index=False, engine="pyarrow"))
    files.append("sweep.parquet")
    png = _plot(frame, spec, out / "sweep.png")
    if png is not None:
        files.append(png.name)
    return files


def _value_text(name: str, value) -> str:
    """``name = value`` for a legend, numbers in the label's units (``flat depth [mm] = 0.5``)."""
    from comparisons.style import label_of

    label, scale = label_of(name)
    return f"{label} = {value * scale:g}" if isinstance(value, (int, float)) else f"{label} = {value}"


def _plot(frame, spec: dict, path: Path):
    """Each metric against each varied numeric parameter, labelled as quantities in an engineer's units (mm, MPa;
    comparisons.style.label_of); points that are not ok (or whose metric is NaN) as crosses at the bottom, named by
    their status.
    """
    import numpy as np

    varied = [
        p for p in dict.fromkeys(k for point in spec["points"] for k in point)
        if p in frame.columns and frame[p].nunique() > 1
    ]  # fmt: skip
    parameters = [p for p in varied if frame[p].dtype.kind in "if"]  # the x axes; every varied key is a curve
    metrics = [m for m in spec["metrics"] if m in frame.columns and frame[m].dtype.kind in "if"]
    if not parameters or not metrics:
        return None
    from matplotlib.figure import Figure

    from comparisons.style import label_of
    from wheelrail.output import atomic_write

    fig = Figure(figsize=(4.2 * len(parameters), 3.2 * len(metrics)), layout="constrained")
    axes = fig.subplots(len(metrics), len(parameters), squeeze=False)
    for i, metric in enumerate(metrics):
        ylabel, yscale = label_of(metric)
        good = (frame["status"] == "ok") & np.isfinite(frame[metric].astype(float))
        for j, parameter in enumerate(parameters):
            ax = axes[i][j]
            xlabel, xscale = label_of(parameter)
            others = [p for p in varied if p != parameter]
            groups = frame[good].groupby(others) if others else [((), frame[good])]
            for label, group in groups:
                group = group.sort_values(parameter)
                text = ", ".join(_value_text(p, v) for p, v in zip(others, np.atleast_1d(label), strict=False))
                ax.plot(group[parameter] * xscale, group[metric] * yscale, "o-", ms=4, label=text or None)
            failed = frame[~good]
            if len(failed):
                floor = frame.loc[good, metric].min() * yscale if good.any() else 0.0
                for status, rows in failed.groupby("status"):
                    name = "ok, no value" if status == "ok" else status
                    ax.plot(rows[parameter] * xscale, np.full(len(rows), floor), "x", ms=8, label=name)
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            if others or len(failed):
                ax.legend(fontsize=7)
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    return path


# --- command line -------------------------------------------------------------------------------


def cmd_sweep(args) -> int:
    """``wheelrail sweep``: run a sweep file (module docstring)."""
    import importlib.util

    from wheelrail.cli import positive_int_option
    from wheelrail.output import copy_input, output_folder
    from wheelrail.overrides import parse_sets

    workers = positive_int_option("--workers", args.workers)
    scheduler = None if args.scheduler is None else check_scheduler(args.scheduler)
    if importlib.util.find_spec("distributed") is None:
        raise ConfigError("wheelrail sweep needs dask.distributed (pip install 'dask[distributed]')")
    path = Path(args.sweep)
    if not path.is_file():
        raise ConfigError(f"sweep file {str(path)!r}: not found (expected a TOML file)")
    spec = load_sweep(path, parse_sets(args.set))  # every point validated: bad input found before any work
    if scheduler is None:
        from wheelrail.cli import check_local_workers

        check_local_workers("--workers", workers)

    def report(record, done, total):
        if not args.quiet:
            print(f"[{done}/{total}] point {record['point']}: {record['status']}", flush=True)

    with output_folder(args.out, f"sweep-{path.stem}") as out_dir:  # checked and locked: one sweep per folder
        with sweep_client(workers, scheduler) as client:  # an unreachable --scheduler: one line, nothing written
            copy_input(path, out_dir, "sweep.toml")
            summary = run_sweep(spec, out_dir, client=client, on_record=report)
    counts = ", ".join(f"{n} {status}" for status, n in sorted(summary["statuses"].items()))
    print(
        f"sweep {path.stem}: {summary['points']} points ({counts}); ran {summary['ran']}, "
        f"skipped {summary['skipped']} already finished"
    )
    print(f"output written to {out_dir}")
    return 0 if all(s == "ok" for s in summary["statuses"]) else 1


def register(sub) -> None:
    """Add the ``sweep`` sub-command to the CLI's sub-parsers."""
    from wheelrail.cli import out_path

    parser = sub.add_parser("sweep", help="parameter study over a scene or case on dask.distributed")
    parser.add_argument("sweep", help="sweep TOML file")
    parser.add_argument("--out", type=out_path, help="output folder (reuse one to resume; default: wheelrail-out/...)")
    parser.add_argument("--workers", default="2", metavar="N", help="LocalCluster worker processes (default 2)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run on the dask scheduler at ADDRESS instead")
    parser.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a base key (repeatable)")
    parser.add_argument("--quiet", action="store_true", help="no line per finished point")
    parser.set_defaults(func=cmd_sweep)
