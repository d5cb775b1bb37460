"""``wheelrail sweep`` on a 2-worker dask LocalCluster: statuses kept, a killed worker survived, resume, --set.

The numbers of each point are those of ``simulate`` on the same scene (regression of the sweep's plumbing
against a direct run); the physics is verified in the dynamics tests.
"""

import json
import os
import signal

import pandas as pd
import pytest

from comparisons.stress import local_dask_client
from wheelrail.cli import main
from wheelrail.config import ConfigError
from wheelrail.overrides import apply_overrides, parse_set
from wheelrail.sweep import load_sweep, point_ids, run_sweep

SWEEP = """
description = "two speeds, two frictions, one point over its budget"
scene = "hunting-conical"
metrics = ["max_abs_lateral_displacement_m"]
[set]
duration_s = 0.2  # long enough that a worker is still busy when the first point is recorded
[grid]
speed_m_per_s = [10.0, 30.0]
"material.friction_coefficient" = [0.2, 0.4]
[[points]]
speed_m_per_s = 20.0
"integrator.max_rhs_evaluations" = 20
contact_provider = "conical"  # the Python path checks the budget at every evaluation (the compiled loop per chunk)
"integrator.method" = "RK45"
"""


@pytest.fixture(scope="module")
def client():
    with local_dask_client(2) as dask_client:
        yield dask_client


@pytest.fixture
def sweep_file(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(SWEEP)
    return path


def test_sweep_on_local_cluster_keeps_statuses_survives_a_killed_worker_and_resumes(client, sweep_file, tmp_path):
    spec = load_sweep(sweep_file)
    assert len(spec["points"]) == 5
    out = tmp_path / "out"
    killed = []

    def kill_a_busy_worker(record, done, total):
        if killed:
            return
        busy = [address for address, keys in client.processing().items() if keys]
        pids = client.run(os.getpid)
        if busy:
            os.kill(pids[busy[0]], signal.SIGKILL)
            killed.append(busy[0])

    summary = run_sweep(spec, out, client=client, on_record=kill_a_busy_worker)
    assert killed, "no worker was busy after the first point"
    assert summary["points"] == 5 and summary["ran"] == 5
    assert summary["statuses"] == {"ok": 4, "budget-exceeded": 1}
    table = pd.read_csv(out / "sweep.csv")
    assert list(table["point"]) == point_ids(spec)
    over = table[table["status"] == "budget-exceeded"].iloc[0]
    assert not over["success"] and over["message"]
    assert pd.read_parquet(out / "sweep.parquet").shape == table.shape
    assert (out / "sweep.png").stat().st_size > 0

    # a point's numbers are those of a direct run of the same scene
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import parse_scene

    doc = apply_overrides(spec["base_doc"], {"speed_m_per_s": 30.0, "material.friction_coefficient": 0.4})
    direct = simulate(parse_scene(doc)).summary()
    row = table[(table["speed_m_per_s"] == 30.0) & (table["material.friction_coefficient"] == 0.4)].iloc[0]
    assert row["max_abs_lateral_displacement_m"] == pytest.approx(direct["max_abs_lateral_displacement_m"], rel=1e-12)

    # resume: nothing to run; an extended grid runs its new point only
    again = run_sweep(spec, out, client=None, workers=1)
    assert again["ran"] == 0 and again["skipped"] == 5
    spec["points"].append({"speed_m_per_s": 15.0})
    more = run_sweep(spec, out, client=client)
    assert more["ran"] == 1 and more["skipped"] == 5 and more["points"] == 6
    assert json.loads((out / "summary.json").read_text())["points"] == 6


def test_cli_sweep_with_set_and_bad_input(sweep_file, tmp_path, capsys):
    sweep_file.write_text(SWEEP.split("[[points]]")[0].replace("[10.0, 30.0]", "[10.0]"))
    out = tmp_path / "cli"
    code = main(["sweep", str(sweep_file), "--out", str(out), "--workers", "1", "--quiet", "--set", "duration_s=0.01"])
    assert code == 0
    assert "2 points (2 ok); ran 2" in capsys.readouterr().out
    table = pd.read_csv(out / "sweep.csv")
    assert list(table["simulated_time_s"]) == pytest.approx([0.01, 0.01])  # --set wins over [set]
    assert (out / "sweep.toml").read_text() == sweep_file.read_text()

    for argv, pattern in (
        (["sweep", str(sweep_file), "--workers", "0"], "--workers '0': expected an integer >= 1"),
        (["sweep", str(tmp_path / "none.toml")], "not found"),
        (["sweep", str(sweep_file), "--set", "nokey"], "--set 'nokey': expected KEY=VALUE"),
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("wheelrail: error:") and pattern in err, err


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ('scene = "hunting-conical"\ncase = "hertz-quadric"\n[grid]\nx = [1]\n', "exactly one of the keys"),
        ('scene = "hunting-conical"\n', "no point to run"),
        ('scene = "hunting-conical"\n[grid]\nspeed_m_per_s = 3\n', "'grid.speed_m_per_s' = 3: expected a non-empty"),
        ('scene = "hunting-conical"\nmethod = "bem"\n[grid]\nspeed_m_per_s = [3]\n', "contact_model"),
        ('scene = "no-such-scene"\n[grid]\nspeed_m_per_s = [3]\n', "no-such-scene"),
        ('scen = "x"\n', "unknown key 'scen'"),
    ],
)
def test_bad_sweep_files(tmp_path, text, pattern):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=pattern):
        load_sweep(path)


def test_case_sweep_over_models(client, tmp_path):
    path = tmp_path / "case.toml"
    path.write_text('case = "hertz-quadric"\n[grid]\nmethod = ["hertz", "linear", "fastsim"]\n')
    summary = run_sweep(load_sweep(path), tmp_path / "o", client=client)
    # the linear theory gives |F_t| = 1.1 mu N on hertz-quadric: the point's status is contact's, not ok
    assert summary["statuses"] == {"ok": 2, "beyond-friction-limit": 1}
    table = pd.read_csv(tmp_path / "o" / "sweep.csv")
    assert list(table["method"]) == ["hertz", "linear", "fastsim"]
    assert list(table["status"]) == ["ok", "beyond-friction-limit", "ok"]
    assert table["patch0_normal_force_N"].nunique() == 1  # same Hertz problem under every model
    assert table.loc[1, "patch0_creep_force_long_N"] != table.loc[0, "patch0_creep_force_long_N"]


def test_parse_set_values():
    assert parse_set("a.b=0.3") == ("a.b", 0.3)
    assert parse_set("track.wheel_profile=S1002") == ("track.wheel_profile", "S1002")
    assert parse_set('x="y"') == ("x", "y")
    assert parse_set("flag=true") == ("flag", True)
    with pytest.raises(ConfigError, match="is not a table"):
        apply_overrides({"a": 1}, {"a.b": 2})
