"""Stress harness and plots of the dynamics (regression/smoke tests of the tooling, not physics).

The harness must finish every run with a status (an oversized fixed step must stop as a force anomaly or blow-up,
not hang or write NaN), report a small energy residual for the accurate runs, and write its records atomically.
"""

import csv
import json

import pytest

from comparisons.dynamics_plots import plot_dynamics, plot_stress
from comparisons.stress import scene_variant, stress_sweep, write_records
from rigid_dynamics.wheelset.parameters import DynamicsScene, InitialConditions, SuspensionParameters, TrackGeometry

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
    assert not unstable["success"] and unstable["status"] in ("force-anomaly", "blow-up", "contact-failed", "derailed")
    assert unstable["failure_time_s"] is not None
    assert by[("relative_tolerance", 1e-7)]["energy_balance_relative"] < 1e-5
    paths = write_records(records, tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stress.csv", "stress.json"]
    assert json.loads(paths["json"].read_text()) == records
    with open(paths["csv"], newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [r["status"] for r in rows] == [r["status"] for r in records]
    assert plot_stress(records, tmp_path / "stress.png").exists()


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
    from comparisons.stress import run_stress_sweep
    from rigid_dynamics.wheelset import simulate, timeseries_arrays

    result = simulate(BASE)
    arrays = timeseries_arrays(result)
    assert arrays["states"].shape == (len(result.t), 12) and "patch_normal_force_N" in arrays
    assert [p.name for p in plot_simulation(result, tmp_path)] == ["dynamics.png"]
    quick = DynamicsScene(**{**BASE.__dict__, "duration_s": 0.01})
    report = run_stress_sweep(quick, out_dir=tmp_path / "stress", quick=True)
    assert report["finished"] + report["stopped"] == len(report["runs"]) > 5
    assert sorted(report["files"]) == ["stress.csv", "stress.json", "stress.png"]
