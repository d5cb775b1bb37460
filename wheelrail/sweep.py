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
profile pairs (``track.wheel_profile``, ``geometry.rail_profile``). Each point is validated like a file
(a bad value is a point with status ``invalid-input``), run on a worker, and recorded as one row.

Outputs in the folder: ``points/<id>.json`` per finished point (written as it finishes, atomically), the
tidy table ``sweep.csv`` and ``sweep.parquet`` (one row per point: ``point``, the parameters by their dotted
keys, ``status``, ``message``, ``success`` and every scalar result with its unit in the name), ``sweep.png``
(each metric against each varied numeric parameter; failed points marked) and ``summary.json``.

Resume: a rerun into the same folder skips the points that have a file in ``points/`` (a point's id is a hash
of its parameters, so an extended grid runs only its new points). A numerical failure is a finished point
(its status and message are kept); a point whose worker was lost is recorded as ``worker-lost`` but not
kept, so a rerun tries it again. Runs on a dask.distributed LocalCluster of ``--workers`` single-threaded
processes (default 2), or on the cluster at ``--scheduler ADDRESS``.
"""

from __future__ import annotations

import hashlib
import itertools
import json
from collections.abc import Callable
from contextlib import suppress
from pathlib import Path

from wheelrail.config import ConfigError, check_keys, read_toml

SWEEP_KEYS = {"description", "name", "scene", "case", "method", "metrics", "set", "grid", "points"}
DEFAULT_METRICS = {
    "scene": ("max_abs_lateral_displacement_m", "left_peak_normal_force_N"),
    "case": ("patch0_creep_force_long_N", "patch0_max_pressure_Pa"),
}
RETRIED_STATUSES = ("worker-lost",)
"""Statuses of points that are not kept as finished (a rerun runs them again)."""


def point_id(parameters: dict) -> str:
    """A stable 12-hex-digit id of a point's parameters."""
    text = json.dumps(parameters, sort_keys=True, default=str)
    return hashlib.sha1(text.encode("utf-8")).hexdigest()[:12]


def load_sweep(path: str | Path) -> dict:
    """Read and check a sweep file; returns the spec (kind, base path, base document, method, points, metrics).

    Raises:
        ConfigError: bad keys or values (the message names the key).
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
    base_doc = apply_overrides(read_toml(base_path, f"{kind} file"), _flatten(fixed))
    points = _points(doc)
    metrics = doc.get("metrics", list(DEFAULT_METRICS[kind]))
    if not (isinstance(metrics, list) and all(isinstance(m, str) for m in metrics)):
        raise ConfigError(f"key 'metrics' = {metrics!r}: expected a list of column names")
    return {
        "kind": kind,
        "base_path": base_path,
        "base_doc": base_doc,
        "method": method,
        "points": points,
        "metrics": metrics,
        "set": _flatten(fixed),
        "description": str(doc.get("description", "")),
    }


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
    points = [dict(zip(grid, combo, strict=True)) for combo in itertools.product(*grid.values())] if grid else []
    explicit = doc.get("points", [])
    if not (isinstance(explicit, list) and all(isinstance(p, dict) for p in explicit)):
        raise ConfigError(f"key 'points' = {explicit!r}: expected [[points]] tables")
    points += [_flatten(p) for p in explicit]
    if not points:
        raise ConfigError("sweep file: expected a [grid] table or [[points]] tables (no point to run)")
    return points


def run_point(task: dict) -> dict:
    """Run one point (module-level: runs on a dask worker). Never raises: trouble is a status in the record."""
    from wheelrail.overrides import apply_overrides

    parameters = task["parameters"]
    record = {"point": task["id"], **parameters}
    try:
        values = dict(parameters)
        method = values.pop("method", task["method"]) if task["kind"] == "case" else None
        doc = apply_overrides(task["base_doc"], values)
        if task["kind"] == "scene":
            from rigid_dynamics.wheelset import simulate
            from wheelrail.scenes import parse_scene

            scene = parse_scene(doc, base_dir=Path(task["base_dir"]))
            result = simulate(scene)
            numbers = result.summary()
        else:
            from wheelrail.cases import parse_case, solution_record, solve_case

            case = parse_case(doc, name=task["name"])
            numbers = _case_numbers(solution_record(solve_case(case, method)), method)
    except ConfigError as exc:
        return {**record, "status": "invalid-input", "success": False, "message": str(exc)}
    except Exception as exc:
        return {**record, "status": "error", "success": False, "message": f"{type(exc).__name__}: {exc}"}
    for key, value in _scalars(numbers).items():
        record.setdefault(key, value)
    record.setdefault("success", record.get("status") == "ok")
    return record


def _case_numbers(record: dict, method: str) -> dict:
    out = {
        "status": record["status"],  # the case's one status, as `contact` prints it and exits with
        "message": record["message"],
        "method": method,
        "wall_time_s": record["wall_time_s"],
        "success": record["success"],
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
    out = Path(out_dir)
    (out / "points").mkdir(parents=True, exist_ok=True)
    tasks, kept = [], []
    for parameters in spec["points"]:
        pid = point_id(parameters)
        stored = out / "points" / f"{pid}.json"
        if stored.is_file():
            kept.append(json.loads(stored.read_text(encoding="utf-8")))
            continue
        tasks.append(
            {
                "id": pid,
                "kind": spec["kind"],
                "parameters": parameters,
                "base_doc": spec["base_doc"],
                "base_dir": str(spec["base_path"].parent),
                "name": spec["base_path"].stem,
                "method": spec["method"],
            }
        )
    new_records = []
    if tasks:
        if client is not None:
            new_records = _run_on(client, tasks, out, on_record)
        else:
            from distributed import Client

            if scheduler:
                with Client(scheduler) as remote:
                    new_records = _run_on(remote, tasks, out, on_record)
            else:
                from comparisons.stress import local_dask_client

                with local_dask_client(workers) as local:
                    new_records = _run_on(local, tasks, out, on_record)
    order = {point_id(p): i for i, p in enumerate(spec["points"])}
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


def _plot(frame, spec: dict, path: Path):
    """Each metric against each varied numeric parameter; failed points as red crosses at the bottom."""
    import numpy as np

    parameters = [
        p
        for p in dict.fromkeys(k for point in spec["points"] for k in point)
        if p in frame.columns and frame[p].dtype.kind in "if" and frame[p].nunique() > 1
    ]
    metrics = [m for m in spec["metrics"] if m in frame.columns and frame[m].dtype.kind in "if"]
    if not parameters or not metrics:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wheelrail.output import atomic_write

    ok = frame["status"] == "ok"
    fig, axes = plt.subplots(
        len(metrics), len(parameters), figsize=(4.2 * len(parameters), 3.2 * len(metrics)), squeeze=False
    )
    for i, metric in enumerate(metrics):
        for j, parameter in enumerate(parameters):
            ax = axes[i][j]
            others = [p for p in parameters if p != parameter]
            groups = frame[ok].groupby(others) if others else [((), frame[ok])]
            for label, group in groups:
                group = group.sort_values(parameter)
                text = ", ".join(f"{p}={v:g}" for p, v in zip(others, np.atleast_1d(label), strict=False))
                ax.plot(group[parameter], group[metric], "o-", ms=4, label=text or None)
            failed = frame[~ok]
            if len(failed):
                floor = frame.loc[ok, metric].min() if ok.any() else 0.0
                ax.plot(failed[parameter], np.full(len(failed), floor), "rx", ms=8, label="failed")
            ax.set_xlabel(parameter)
            ax.set_ylabel(metric)
            if others or len(failed):
                ax.legend(fontsize=7)
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)
    return path


# --- command line -------------------------------------------------------------------------------


def cmd_sweep(args) -> int:
    """``wheelrail sweep``: run a sweep file (module docstring)."""
    import importlib.util

    from wheelrail.output import copy_input, output_folder
    from wheelrail.overrides import parse_sets

    try:
        workers = int(args.workers)
    except ValueError:
        workers = 0
    if workers < 1:
        raise ConfigError(f"--workers {args.workers!r}: expected an integer >= 1")
    if importlib.util.find_spec("distributed") is None:
        raise ConfigError("wheelrail sweep needs dask.distributed (pip install 'dask[distributed]')")
    path = Path(args.sweep)
    if not path.is_file():
        raise ConfigError(f"sweep file {str(path)!r}: not found (expected a TOML file)")
    spec = load_sweep(path)
    overrides = parse_sets(args.set)
    if overrides:
        from wheelrail.overrides import apply_overrides

        spec["base_doc"] = apply_overrides(spec["base_doc"], overrides)
        spec["set"] = {**spec["set"], **overrides}

    def report(record, done, total):
        if not args.quiet:
            print(f"[{done}/{total}] point {record['point']}: {record['status']}", flush=True)

    with output_folder(args.out, f"sweep-{path.stem}") as out_dir:  # checked and locked: one sweep per folder
        copy_input(path, out_dir, "sweep.toml")
        summary = run_sweep(spec, out_dir, workers=workers, scheduler=args.scheduler, on_record=report)
    counts = ", ".join(f"{n} {status}" for status, n in sorted(summary["statuses"].items()))
    print(
        f"sweep {path.stem}: {summary['points']} points ({counts}); ran {summary['ran']}, "
        f"skipped {summary['skipped']} already finished"
    )
    print(f"output written to {out_dir}")
    return 0 if all(s == "ok" for s in summary["statuses"]) else 1


def register(sub) -> None:
    """Add the ``sweep`` sub-command to the CLI's sub-parsers."""
    parser = sub.add_parser("sweep", help="parameter study over a scene or case on dask.distributed")
    parser.add_argument("sweep", help="sweep TOML file")
    parser.add_argument("--out", type=Path, help="output folder (reuse one to resume; default: wheelrail-out/...)")
    parser.add_argument("--workers", default="2", metavar="N", help="LocalCluster worker processes (default 2)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="run on the dask scheduler at ADDRESS instead")
    parser.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a base key (repeatable)")
    parser.add_argument("--quiet", action="store_true", help="no line per finished point")
    parser.set_defaults(func=cmd_sweep)
