"""Numerical-stability stress tests of the wheelset simulation.

A sweep varies one setting of a base scene at a time (step size of the fixed-step method, tolerance of an
adaptive method, speed through the critical speed, friction, irregularity amplitude, contact stiffness) and
runs each variant with :func:`rigid_dynamics.wheelset.simulate`. Every run ends with a status (never a hang:
the runs carry RHS-evaluation and wall-time caps; never NaN written silently: a failing run stops at its last
good sample with status and failure state). Per run the record holds:

* ``status``, ``success``, ``message``, ``failure_time_s``;
* ``energy_balance_relative``: max |(T + V_g)(t) - (T + V_g)(0) - W_contact(t) - W_exterior(t)| divided by the
  largest of the swing of T, |W_contact|, |W_exterior| and 1 J (the work of the contact and suspension forces
  against the change of kinetic and potential energy; 0 for exact integration);
* ``max_force_ratio``: the largest normal force over the static wheel load (the force anomaly measure;
  the run stops as "force-anomaly" above ``IntegratorSettings.max_force_factor``);
* ``max_approach_m``: the deepest interpenetration (the constraint measure of an elastic contact);
* ``max_abs_lateral_displacement_m``, ``real_time_factor``, ``rhs_evaluations``, ``wall_time_s``;
* ``force_error_estimate``: RK4 runs: the largest force error estimate after the settling distance, relative to
  the static wheel load (SimulationResult.summary); above the scene's ``force_tolerance`` the run ends with status
  ``"warning"``: it finished, but its forces move with the step.

Besides the statuses of ``simulate``, a record can end as ``"error"`` (the run raised; ``message`` holds the
exception) or, on dask, ``"worker-lost"`` (the worker process running it died): one bad run never stops the sweep.

Entry points: :func:`run_stress_sweep` (the CLI's: default sweep, files, summary), :func:`stress_sweep`
(records as a list of dicts), :func:`write_records` (CSV and JSON,
written atomically), :func:`default_sweeps` (the standard set for a scene), :func:`nonlinear_critical_speed`
(bisection over speed with short runs: decaying or growing lateral oscillation), :func:`local_dask_client`
(a ``dask.distributed`` cluster of single-threaded worker processes on this machine).

Runs are serial by default; with a ``dask.distributed`` client (``client=``, or ``workers >= 2`` in
:func:`run_stress_sweep`) they are mapped on its workers. dask is imported only then. The runs are
deterministic, so the records of both paths are identical except the timings (``wall_time_s``,
``real_time_factor``, and a ``budget-exceeded`` status if a run hits its wall-time cap); they come back in task
order either way.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager, suppress
from dataclasses import replace
from pathlib import Path

import numpy as np

from rigid_dynamics.files import write_text
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.simulate import SimulationResult, simulate

SWEEP_PARAMETERS = (
    "fixed_step_s",
    "relative_tolerance",
    "speed_m_per_s",
    "friction_coefficient",
    "irregularity_scale",
    "shear_modulus_Pa",
)
"""Names accepted by :func:`stress_sweep` (keys of its ``sweeps`` mapping)."""

RECORD_FIELDS = (
    "parameter",
    "value",
    "status",
    "success",
    "message",
    "simulated_time_s",
    "failure_time_s",
    "wall_time_s",
    "real_time_factor",
    "rhs_evaluations",
    "energy_balance_relative",
    "max_force_ratio",
    "max_approach_m",
    "max_abs_lateral_displacement_m",
    "force_error_estimate",
    "method",
    "provider",
    "contact_model",
)


def scene_variant(base: DynamicsScene, parameter: str, value: float) -> DynamicsScene:
    """The base scene with one setting changed (see SWEEP_PARAMETERS).

    ``fixed_step_s`` switches to RK4 with that step; ``relative_tolerance`` keeps the base method unless it is
    RK4 (then RK45), with absolute tolerance 1e-3 x rtol; ``irregularity_scale`` multiplies every amplitude.

    Raises:
        ValueError: unknown parameter or invalid value (from the dataclasses).
    """
    integ = base.integrator
    if parameter == "fixed_step_s":
        return replace(base, integrator=replace(integ, method="RK4", fixed_step_s=float(value)))
    if parameter == "relative_tolerance":
        method = integ.method if integ.method != "RK4" else "RK45"
        return replace(
            base,
            integrator=replace(
                integ, method=method, relative_tolerance=float(value), absolute_tolerance=1e-3 * float(value)
            ),
        )
    if parameter == "speed_m_per_s":
        return replace(base, speed_m_per_s=float(value))
    if parameter == "friction_coefficient":
        return replace(base, material=replace(base.material, friction_coefficient=float(value)))
    if parameter == "shear_modulus_Pa":
        return replace(base, material=replace(base.material, shear_modulus_Pa=float(value)))
    if parameter == "irregularity_scale":
        irr = base.irregularities
        return replace(
            base,
            irregularities=replace(
                irr,
                polygon_amplitude_m=irr.polygon_amplitude_m * value,
                flat_depth_m=irr.flat_depth_m * value,
                flat_length_m=irr.flat_length_m * math.sqrt(value) if irr.flat_depth_m == 0 else irr.flat_length_m,
                corrugation_amplitude_m=irr.corrugation_amplitude_m * value,
            ),
        )
    raise ValueError(f"parameter = {parameter!r}: expected one of {', '.join(SWEEP_PARAMETERS)}")


def run_record(result: SimulationResult, parameter: str = "", value: float = math.nan) -> dict:
    """The stress record of one finished run (module docstring)."""
    scene = result.scene
    n = len(result.t)
    if n:
        residual = np.abs(result.energy_residual_J)
        scale = max(
            float(np.ptp(result.kinetic_energy_J)),
            float(np.max(np.abs(result.work_contact_J))),
            float(np.max(np.abs(result.work_exterior_J))),
            1.0,
        )
        energy = float(np.max(residual)) / scale
        force_ratio = float(np.max(result.wheel_normal_force_N)) / scene.static_wheel_load_N
        approach = result.patches["approach_m"]
        max_approach = float(np.nanmax(approach)) if np.any(np.isfinite(approach)) else math.nan
        lateral = float(np.max(np.abs(result.states[:, 1])))
    else:
        energy = force_ratio = max_approach = lateral = math.nan

    def num(v):
        return None if v is None or not math.isfinite(v) else float(v)

    return {
        "parameter": parameter,
        "value": num(value),
        "status": result.status,
        "success": result.success,
        "message": result.message,
        "simulated_time_s": num(result.simulated_time_s),
        "failure_time_s": num(result.failure_time_s),
        "wall_time_s": num(result.wall_time_s),
        "real_time_factor": num(result.real_time_factor),
        "rhs_evaluations": int(result.rhs_evaluations),
        "energy_balance_relative": num(energy),
        "max_force_ratio": num(force_ratio),
        "max_approach_m": num(max_approach),
        "max_abs_lateral_displacement_m": num(lateral),
        "force_error_estimate": result.summary().get("force_error_estimate"),
        "method": result.method,
        "provider": result.provider,
        "contact_model": result.contact_model,
    }


def _failure_record(scene: DynamicsScene, parameter: str, value: float, status: str, message: str) -> dict:
    """The record of a run that produced no result (it raised, or its worker died): no measures."""
    record = dict.fromkeys(RECORD_FIELDS)
    record.update(
        parameter=parameter,
        value=value if math.isfinite(value) else None,
        status=status,
        success=False,
        message=message,
        method=scene.integrator.method,
        provider=scene.contact_provider,
        contact_model=scene.contact_model,
    )
    return record


def _run_one(task) -> dict:
    """Run one (scene, parameter, value) task and return its record (module-level: picklable for dask).

    ``simulate`` reports numerical trouble as a status; anything it raises all the same becomes an ``"error"``
    record, so that one run cannot end the sweep (serially or on a dask worker).
    """
    scene, parameter, value = task
    try:
        return run_record(simulate(scene), parameter, value)
    except Exception as exc:
        return _failure_record(scene, parameter, value, "error", f"{type(exc).__name__}: {exc}")


def _map_on_client(client, tasks: list, progress: Callable[[float], None] | None, function=None) -> list[dict]:
    """Run the tasks on a dask.distributed client; records in task order, progress as runs finish.

    ``function`` replaces :func:`_run_one` (for tests of a worker that dies).
    """
    from distributed import as_completed

    futures = client.map(function or _run_one, tasks, pure=False)
    position = {future.key: i for i, future in enumerate(futures)}
    records: list[dict | None] = [None] * len(tasks)
    try:
        for done, future in enumerate(as_completed(futures), start=1):
            i = position[future.key]
            try:
                records[i] = future.result()
            except Exception as exc:  # the task itself never raises (_run_one): its worker died or it was lost
                scene, parameter, value = tasks[i]
                records[i] = _failure_record(scene, parameter, value, "worker-lost", f"{type(exc).__name__}: {exc}")
            future.release()
            if progress is not None:
                progress(done / len(tasks))
    except BaseException:  # interrupted (Ctrl-C) or the client failed: do not leave the runs going
        with suppress(Exception):
            client.cancel(futures)
        raise
    return records


@contextmanager
def _workers_ignore_sigint() -> Iterator[None]:
    """SIGINT ignored while the cluster starts its worker processes, which inherit that across exec (and Python then
    installs no KeyboardInterrupt handler in them): a Ctrl-C in the terminal reaches the whole process group, and each
    worker would print a traceback. Only this process stops on it; closing the cluster ends the workers.

    The cost: a Ctrl-C during the cluster's start (a second or two) is lost. Blocking SIGINT instead does not reach
    the workers (they are spawned from dask's event-loop thread), and both together still lose it to that thread.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def _quiet_dask_logs() -> Iterator[None]:
    """Dask's own log lines at ERROR (workers: CRITICAL) and above only, here and in the workers started inside
    (they read ``DASK_LOGGING__DISTRIBUTED`` at start-up): a cancelled task or a worker stopped on Ctrl-C is not
    news to the user, whose sweep reports every point's status (a lost worker as ``worker-lost``) itself.
    """
    import logging
    import os

    logger = logging.getLogger("distributed")
    level, variable = logger.level, os.environ.get("DASK_LOGGING__DISTRIBUTED")
    logger.setLevel(logging.ERROR)
    os.environ["DASK_LOGGING__DISTRIBUTED"] = "critical"  # a worker stopped mid-heartbeat logs an ERROR
    try:
        yield
    finally:
        logger.setLevel(level)
        if variable is None:
            os.environ.pop("DASK_LOGGING__DISTRIBUTED", None)
        else:
            os.environ["DASK_LOGGING__DISTRIBUTED"] = variable


@contextmanager
def local_dask_client(workers: int) -> Iterator:
    """A ``dask.distributed`` Client of a LocalCluster of ``workers`` single-threaded worker processes.

    The cluster and client are closed on exit. No dashboard is started, and the scheduler's small HTTP server
    listens on a free port of 127.0.0.1 (not dask's default 8787, which a second cluster would contend for).

    Security: the scheduler, the nannies and the workers speak TLS with mutual authentication, on credentials made
    for this cluster alone (``distributed.security.Security.temporary()``: a fresh certificate held in memory and
    handed to the worker processes, never written to disk). Another local process that connects to the scheduler's
    port (``Client(address).run_on_scheduler(...)``) fails the handshake instead of running code in this process.

    Raises:
        ValueError: ``workers`` is not an integer >= 1.
        ImportError: dask.distributed is not installed.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers = {workers!r}: expected an integer >= 1")
    from distributed import Client, LocalCluster
    from distributed.security import Security

    from rigid_dynamics.files import ignore_sigpipe

    ignore_sigpipe()  # an earlier FEA run (dolfinx, gmsh) may have reset it: a closing TLS peer must not kill us
    security = Security.temporary()  # needs the package cryptography (a dependency of wheelrail)
    with _quiet_dask_logs(), _workers_ignore_sigint():  # Ctrl-C stops this process (which closes the cluster)
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            protocol="tls://",
            host="127.0.0.1",
            security=security,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
        )
    with _quiet_dask_logs(), cluster, Client(cluster, security=security) as client:
        yield client


def default_sweeps(base: DynamicsScene, critical_speed_m_per_s: float | None = None) -> dict[str, tuple]:
    """The standard sweep of a scene: steps from fine to unstable, tolerances, speeds through the critical
    speed (0.5 to 1.3 x, or 0.5 to 2 x the scene speed), friction 0.05-0.6, irregularities x0-x4, contact
    stiffness G x0.1-x10.
    """
    v = critical_speed_m_per_s or base.speed_m_per_s
    factors = (0.5, 0.8, 0.95, 1.05, 1.3) if critical_speed_m_per_s else (0.5, 1.0, 1.5, 2.0)
    sweeps = {
        "fixed_step_s": (1e-4, 5e-4, 2e-3, 1e-2),
        "relative_tolerance": (1e-3, 1e-5, 1e-7),
        "speed_m_per_s": tuple(v * f for f in factors),
        "friction_coefficient": (0.05, 0.3, 0.6),
        "shear_modulus_Pa": tuple(base.material.shear_modulus_Pa * f for f in (0.1, 1.0, 10.0)),
    }
    if base.irregularities.any:
        sweeps["irregularity_scale"] = (0.0, 1.0, 2.0, 4.0)
    return sweeps


def stress_sweep(
    base: DynamicsScene,
    sweeps: dict[str, Iterable[float]] | None = None,
    *,
    duration_s: float | None = None,
    max_wall_time_s: float | None = 120.0,
    progress: Callable[[float], None] | None = None,
    client=None,
) -> list[dict]:
    """Run every variant of ``base`` in ``sweeps`` (parameter -> values) and return one record per run.

    Args:
        base: the scene to vary.
        sweeps: parameter -> values (SWEEP_PARAMETERS); default :func:`default_sweeps`.
        duration_s: shorter simulated time for every run (default: the scene's).
        max_wall_time_s: wall-time cap per run (status "budget-exceeded" beyond), s; None keeps the scene's.
        progress: callable(fraction) after every finished run (on dask: in the order the runs finish).
        client: optional ``dask.distributed.Client``; the runs are mapped on its workers (records still in task
            order, identical to the serial ones except the timings).

    Raises:
        ValueError: unknown parameter or invalid value (before any run).
    """
    sweeps = default_sweeps(base) if sweeps is None else sweeps
    if duration_s is not None:
        base = replace(base, duration_s=float(duration_s))
    if max_wall_time_s is not None:
        base = replace(base, integrator=replace(base.integrator, max_wall_time_s=float(max_wall_time_s)))
    tasks = [(scene_variant(base, p, v), p, float(v)) for p, values in sweeps.items() for v in values]
    if client is not None:
        return _map_on_client(client, tasks, progress)
    records = []
    for i, task in enumerate(tasks):
        records.append(_run_one(task))
        if progress is not None:
            progress((i + 1) / len(tasks))
    return records


def nonlinear_critical_speed(
    scene: DynamicsScene,
    low_m_per_s: float,
    high_m_per_s: float,
    *,
    relative_tolerance: float = 0.01,
    duration_s: float = 1.5,
    skip_s: float = 0.2,
    max_runs: int = 12,
) -> dict:
    """Speed where the lateral oscillation of the nonlinear simulation turns from decaying to growing (bisection).

    The growth rate of a run is the slope of ln|y| through the extremes of y(t) after ``skip_s``. ``low`` must
    decay and ``high`` grow. Returns a dict with ``success``, ``status``, ``message``, ``speed_m_per_s`` and the
    ``runs`` (speed, growth rate 1/s, status).
    """
    runs = []

    def growth(speed):
        result = simulate(replace(scene, speed_m_per_s=float(speed), duration_s=duration_s))
        rate = math.nan
        if result.success:
            keep = result.t > skip_s
            t, y = result.t[keep], np.abs(result.states[keep, 1])
            peaks = [i for i in range(1, len(y) - 1) if y[i] >= y[i - 1] and y[i] >= y[i + 1] and y[i] > 0]
            if len(peaks) >= 3:
                rate = float(np.polyfit(t[peaks], np.log(y[peaks]), 1)[0])
        runs.append({"speed_m_per_s": float(speed), "growth_rate_1_per_s": rate, "status": result.status})
        return rate

    g_low, g_high = growth(low_m_per_s), growth(high_m_per_s)
    if not (g_low < 0 < g_high):
        return {
            "success": False,
            "status": "not-bracketed",
            "message": f"growth {g_low} 1/s at {low_m_per_s} m/s and {g_high} 1/s at {high_m_per_s} m/s",
            "speed_m_per_s": None,
            "runs": runs,
        }
    lo, hi = low_m_per_s, high_m_per_s
    while (hi - lo) > relative_tolerance * lo and len(runs) < max_runs:
        mid = 0.5 * (lo + hi)
        g = growth(mid)
        if not math.isfinite(g):
            break
        if g < 0:
            lo = mid
        else:
            hi = mid
    converged = (hi - lo) <= relative_tolerance * lo
    return {
        "success": converged,
        "status": "ok" if converged else "not-converged",
        "message": f"critical speed in [{lo:.4g}, {hi:.4g}] m/s after {len(runs)} runs",
        "speed_m_per_s": 0.5 * (lo + hi),
        "runs": runs,
    }


def summarize(records) -> dict:
    """``runs``, ``finished``, ``stopped``, ``statuses``, ``max_energy_balance_relative``, ``energy_suspect`` and
    ``warnings`` of a sweep's records (see :func:`run_stress_sweep`). Runs with status "ok" or "warning" count as
    finished; the warnings are listed with their messages.
    """
    statuses: dict[str, int] = {}
    for r in records:
        statuses[r["status"]] = statuses.get(r["status"], 0) + 1
    finished = [r for r in records if r["status"] in FINISHED_STATUSES]
    warnings = [
        {
            "parameter": r["parameter"],
            "value": r["value"],
            "force_error_estimate": r.get("force_error_estimate"),
            "message": r["message"],
        }
        for r in records
        if r["status"] == "warning"
    ]
    energies = [r["energy_balance_relative"] for r in finished if r["energy_balance_relative"] is not None]
    suspect = [
        {"parameter": r["parameter"], "value": r["value"], "energy_balance_relative": r["energy_balance_relative"]}
        for r in finished
        if r["energy_balance_relative"] is not None and r["energy_balance_relative"] > ENERGY_SUSPECT_RELATIVE
    ]
    return {
        "runs": records,
        "finished": len(finished),
        "stopped": len(records) - len(finished),
        "statuses": statuses,
        "max_energy_balance_relative": max(energies) if energies else None,
        "energy_suspect": suspect,
        "warnings": warnings,
    }


FINISHED_STATUSES = ("ok", "warning")
"""Statuses of runs that reached their end time ("warning": with a force error estimate above the tolerance)."""

ENERGY_SUSPECT_RELATIVE = 0.01
"""A finished run whose energy balance (module docstring) exceeds this is listed as suspect by run_stress_sweep:
1 % of the energy that moved is unaccounted for (e.g. RK4 at a step near the contact mode's stability limit)."""


def run_stress_sweep(
    scene: DynamicsScene,
    out_dir: str | Path | None = None,
    *,
    quick: bool = False,
    client=None,
    workers: int = 1,
    progress: Callable[[float], None] | None = None,
):
    """The standard stress sweep of a scene (the entry of ``wheelrail stress``).

    Runs :func:`default_sweeps` (``quick``: three values per parameter and at most 0.2 s simulated per run;
    otherwise the scene's duration capped at 2 s), writes ``stress.csv``, ``stress.json`` and ``stress.png`` into
    ``out_dir`` when given, and returns a summary dict: ``runs`` (the records), ``finished``, ``stopped``,
    ``statuses`` (status -> count), ``max_energy_balance_relative`` of the finished runs, ``energy_suspect``
    (the finished runs whose energy balance exceeds ENERGY_SUSPECT_RELATIVE: parameter, value, balance; a run
    can finish and still be too coarse to trust), ``workers``, ``files``.

    Args:
        scene: the base scene.
        out_dir: folder for the files (none written when None).
        quick: the small sweep.
        client: a ``dask.distributed.Client`` to run on (``workers`` is then ignored).
        workers: 1 runs serially; N >= 2 runs on a :func:`local_dask_client` of N worker processes, closed after.
        progress: callable(fraction) as runs finish.

    Raises:
        ValueError: ``workers`` is not an integer >= 1.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers = {workers!r}: expected an integer >= 1")
    sweeps = default_sweeps(scene)
    if quick:
        sweeps = {k: tuple(v)[:: max(1, len(v) // 3)][:3] for k, v in sweeps.items()}
    duration = min(scene.duration_s, 0.2 if quick else 2.0)
    if client is None and workers >= 2:
        with local_dask_client(workers) as local:
            records = stress_sweep(scene, sweeps, duration_s=duration, client=local, progress=progress)
    else:
        records = stress_sweep(scene, sweeps, duration_s=duration, client=client, progress=progress)
    files = []
    if out_dir is not None:
        paths = write_records(records, out_dir)
        files = [p.name for p in paths.values()]
        try:
            from comparisons.dynamics_plots import plot_stress

            files.append(plot_stress(records, Path(out_dir) / "stress.png").name)
        except ImportError:  # pragma: no cover (matplotlib missing)
            pass
    return {
        "scene": scene.name,
        **summarize(records),
        "workers": len(client.nthreads()) if client is not None else workers,
        "files": files,
    }


def write_records(records: list[dict], folder: str | Path, stem: str = "stress") -> dict[str, Path]:
    """Write records as ``<stem>.csv`` and ``<stem>.json`` into ``folder`` (each atomically). Returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = {"csv": folder / f"{stem}.csv", "json": folder / f"{stem}.json"}
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(RECORD_FIELDS), extrasaction="ignore")
    writer.writeheader()
    for record in records:
        writer.writerow({k: ("" if record.get(k) is None else record.get(k)) for k in RECORD_FIELDS})
    write_text(paths["csv"], buffer.getvalue())
    write_text(paths["json"], json.dumps(records, indent=2) + "\n")
    return paths


__all__ = [
    "RECORD_FIELDS",
    "SWEEP_PARAMETERS",
    "default_sweeps",
    "local_dask_client",
    "nonlinear_critical_speed",
    "run_record",
    "run_stress_sweep",
    "scene_variant",
    "stress_sweep",
    "write_records",
]
