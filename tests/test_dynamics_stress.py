"""Stress harness and plots of the dynamics (regression/smoke tests of the tooling, not physics).

The harness must finish every run with a status (an oversized fixed step must stop as a force anomaly or blow-up,
not hang or write NaN), report a small energy residual for the accurate runs, and write its records atomically.
On a dask.distributed cluster of worker processes the records must equal the serial ones (the runs are
deterministic; only the timings differ), come back in task order, report progress as runs finish, and a run that
raises or whose worker dies must end as a record, not end the sweep.
"""

import csv
import json
import os
from dataclasses import replace

import pytest

from comparisons.dynamics_plots import plot_dynamics, plot_stress
from comparisons.stress import (
    RECORD_FIELDS,
    _map_on_client,
    _run_one,
    local_dask_client,
    scene_variant,
    stress_sweep,
    write_records,
)
from rigid_dynamics.wheelset.parameters import DynamicsScene, InitialConditions, SuspensionParameters, TrackGeometry
from wheelrail.cli import main

BASE = DynamicsScene(
    track=TrackGeometry(rail_head_radius_m=0.05),
    contact_model="linear",
    speed_m_per_s=20.0,
    duration_s=0.05,
    suspension=SuspensionParameters(longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5),
    initial=InitialConditions(lateral_displacement_m=0.002),
)


def test_sweep_statuses_and_files(tmp_path):
    seen = []
    records = stress_sweep(
        BASE,
        {"fixed_step_s": (2e-4, 2e-2), "relative_tolerance": (1e-7,), "shear_modulus_Pa": (8.2e9,)},
        progress=seen.append,
    )
    assert seen[-1] == 1.0 and len(records) == 4
    by = {(r["parameter"], r["value"]): r for r in records}
    assert by[("fixed_step_s", 2e-4)]["success"]
    assert by[("fixed_step_s", 2e-4)]["energy_balance_relative"] < 1e-6
    unstable = by[("fixed_step_s", 2e-2)]
    assert not unstable["success"] and unstable["status"] == "step-unstable"  # beyond RK4's stability limit
    assert unstable["failure_time_s"] is not None
    assert by[("relative_tolerance", 1e-7)]["energy_balance_relative"] < 1e-5
    paths = write_records(records, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stress.csv", "stress.json"]
    assert json.loads(paths["json"].read_text()) == records
    with open(paths["csv"], newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [r["status"] for r in rows] == [r["status"] for r in records]
    assert plot_stress(records, tmp_path / "stress.png").exists()


def test_summary_lists_finished_runs_whose_energy_does_not_balance():
    from comparisons.stress import ENERGY_SUSPECT_RELATIVE, summarize

    def record(parameter, value, success, energy):
        return {"parameter": parameter, "value": value, "status": "ok" if success else "blow-up", "success": success,
                "energy_balance_relative": energy}  # fmt: skip

    records = [
        record("fixed_step_s", 2e-3, True, 0.99),
        record("fixed_step_s", 5e-4, True, 2e-4),
        record("fixed_step_s", 2e-2, False, 0.9),  # stopped: reported by its status, not as suspect
        record("relative_tolerance", 1e-3, True, None),
    ]
    report = summarize(records)
    assert report["energy_suspect"] == [{"parameter": "fixed_step_s", "value": 2e-3, "energy_balance_relative": 0.99}]
    assert report["statuses"] == {"ok": 3, "blow-up": 1} and report["finished"] == 3
    assert report["max_energy_balance_relative"] == 0.99 and ENERGY_SUSPECT_RELATIVE == 0.01


def test_variants_and_bad_parameter():
    assert scene_variant(BASE, "fixed_step_s", 1e-4).integrator.method == "RK4"
    assert scene_variant(BASE, "friction_coefficient", 0.1).material.friction_coefficient == 0.1
    with pytest.raises(ValueError, match="parameter = 'gauge': expected one of fixed_step_s"):
        scene_variant(BASE, "gauge", 1.0)
    with pytest.raises(ValueError, match="fixed_step_s = -1.0: expected a number > 0"):
        stress_sweep(BASE, {"fixed_step_s": (-1.0,)})


def test_plot_dynamics_writes_png(tmp_path):
    from rigid_dynamics.wheelset.simulate import simulate

    path = plot_dynamics(simulate(BASE), tmp_path / "run")
    assert path.name == "run.png" and path.stat().st_size > 1000


def test_cli_entry_points(tmp_path):
    """The functions ``wheelrail run`` / ``wheelrail stress`` call (regression of their contract)."""
    from comparisons.dynamics_plots import plot_simulation
    from comparisons.stress import ENERGY_SUSPECT_RELATIVE, run_stress_sweep
    from rigid_dynamics.wheelset import simulate, timeseries_arrays

    result = simulate(BASE)
    arrays = timeseries_arrays(result)
    assert arrays["states"].shape == (len(result.t), 12) and "patch_normal_force_N" in arrays
    assert [p.name for p in plot_simulation(result, tmp_path)] == ["dynamics.png"]
    quick = DynamicsScene(**{**BASE.__dict__, "duration_s": 0.01})
    report = run_stress_sweep(quick, out_dir=tmp_path / "stress", quick=True)
    assert report["finished"] + report["stopped"] == len(report["runs"]) > 5
    assert sorted(report["files"]) == ["stress.csv", "stress.json", "stress.png"]
    # finished runs whose energy does not balance are listed, and only those
    limit = ENERGY_SUSPECT_RELATIVE
    listed = {(r["parameter"], r["value"]) for r in report["energy_suspect"]}
    expected = {
        (r["parameter"], r["value"])
        for r in report["runs"]
        if r["status"] in ("ok", "warning")  # finished runs (comparisons.stress.FINISHED_STATUSES)
        and r["energy_balance_relative"] is not None
        and r["energy_balance_relative"] > limit
    }
    assert listed == expected


# --- dask.distributed ---------------------------------------------------------------------------

TIMINGS = ("wall_time_s", "real_time_factor")


def untimed(records):
    return [{k: v for k, v in r.items() if k not in TIMINGS} for r in records]


@pytest.fixture(scope="module")
def dask_client():
    """Two single-threaded worker processes (about 1 s to start and close)."""
    with local_dask_client(2) as client:
        yield client


def test_dask_sweep_equals_serial(dask_client):
    sweeps = {"fixed_step_s": (2e-4, 2e-2), "relative_tolerance": (1e-7,)}
    serial = stress_sweep(BASE, sweeps)
    seen = []
    parallel = stress_sweep(BASE, sweeps, client=dask_client, progress=seen.append)
    workers = dask_client.run(os.getpid)
    assert len(set(workers.values())) == 2 and os.getpid() not in workers.values()  # really other processes
    assert [list(r) for r in parallel] == [list(r) for r in serial] == [list(RECORD_FIELDS)] * 3
    assert [(r["parameter"], r["value"]) for r in parallel] == [
        ("fixed_step_s", 2e-4),
        ("fixed_step_s", 2e-2),
        ("relative_tolerance", 1e-7),
    ]
    assert untimed(parallel) == untimed(serial)
    assert seen == pytest.approx([1 / 3, 2 / 3, 1.0])
    assert parallel[0]["success"] and not parallel[1]["success"] and parallel[1]["failure_time_s"] is not None


def test_raising_run_is_a_record_serially_and_on_dask(dask_client):
    bad = replace(BASE, contact_model="nonexistent")
    tasks = [(BASE, "speed_m_per_s", 20.0), (bad, "speed_m_per_s", 20.0), (BASE, "speed_m_per_s", 20.0)]
    serial = [_run_one(task) for task in tasks]
    parallel = _map_on_client(dask_client, tasks, None)
    assert untimed(parallel) == untimed(serial)
    error = parallel[1]
    assert list(error) == list(RECORD_FIELDS)
    assert error["status"] == "error" and error["success"] is False
    assert error["message"].startswith("ValueError: contact model = 'nonexistent'")
    assert error["contact_model"] == "nonexistent" and error["energy_balance_relative"] is None
    assert parallel[0]["status"] == parallel[2]["status"] == "ok"


def _exit_on_nan(task):
    """A task function that kills its worker process when the value is NaN (runs in the worker)."""
    import math
    import os

    from comparisons.stress import _run_one

    if math.isnan(task[2]):
        os._exit(3)
    return _run_one(task)


def test_dead_worker_is_a_record_not_the_end_of_the_sweep():
    import dask
    import distributed  # noqa: F401 (imported before the config.set: a set of a distributed.* key before distributed's
    # first import removes the whole distributed section when it exits, and a later Client fails with KeyError)

    tasks = [(BASE, "speed_m_per_s", 20.0), (BASE, "speed_m_per_s", float("nan"))]
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), local_dask_client(1) as client:
        records = _map_on_client(client, tasks, None, function=_exit_on_nan)
    # the task that was on the worker when it died may be lost too (allowed-failures 0): either way, a record
    assert records[0]["status"] in ("ok", "worker-lost") and records[0]["value"] == 20.0
    assert records[1]["status"] == "worker-lost" and "KilledWorker" in records[1]["message"]
    assert records[1]["value"] is None and list(records[1]) == list(RECORD_FIELDS)


def short_scene(tmp_path):
    from wheelrail.scenes import resolve_scene_path

    text = resolve_scene_path("hunting-conical").read_text()
    assert "duration_s = 3.0" in text
    path = tmp_path / "short.toml"
    path.write_text(text.replace("duration_s = 3.0", "duration_s = 0.02"))
    return path


def test_cli_stress_workers_2_equals_serial(tmp_path, capsys):
    from comparisons.stress import run_stress_sweep
    from wheelrail.scenes import load_scene

    scene = short_scene(tmp_path)
    assert main(["stress", str(scene), "--quick", "--out", str(tmp_path / "two"), "--workers", "2"]) == 0
    assert " runs (" in capsys.readouterr().out.splitlines()[0].partition("on 2 workers")[0]
    two = json.loads((tmp_path / "two" / "summary.json").read_text())
    one = run_stress_sweep(load_scene(scene), quick=True)
    assert (one["workers"], two["workers"]) == (1, 2)
    assert len(two["runs"]) > 5 and untimed(two["runs"]) == untimed(one["runs"])
    assert sorted(two["files"]) == ["stress.csv", "stress.json", "stress.png"]


@pytest.mark.parametrize("value", ["0", "-2", "two", "2.5", ""])
def test_cli_stress_bad_workers(tmp_path, capsys, value):
    code = main(["stress", "--quick", "--workers", value, "--out", str(tmp_path / "out")])
    captured = capsys.readouterr()
    assert code == 2 and "Traceback" not in captured.err
    assert captured.err == f"wheelrail: error: --workers {value!r}: expected an integer >= 1\n"
    assert not (tmp_path / "out").exists()  # fails before any work


def test_axis_labels_read_as_quantities_with_units():
    """Plots label columns as quantities in the units an engineer reads: mm, MPa, mrad (not raw column names)."""
    from comparisons.style import label_of

    assert label_of("energy_balance_relative") == ("relative energy residual", 1.0)
    assert label_of("fixed_step_s") == ("fixed step [s]", 1.0)
    assert label_of("irregularities.flat_depth_m") == ("flat depth [mm]", 1e3)
    assert label_of("max_pressure_Pa") == ("max pressure [MPa]", 1e-6)
    assert label_of("speed_m_per_s") == ("speed [m/s]", 1.0)
