"""``wheelrail critical-speed``: linear (eigenvalue) and nonlinear (limit-cycle continuation) critical speed.

The scene (tests/data/limit_cycle_scene.toml): S1002 on UIC60 1:40, ideal geometry, soft primary suspension,
Vermeulen-Johnson, compiled RK4 on contact tables. Above the linear estimate the wheelset hunts on a flange-contact
limit cycle of about 7 mm; followed down in speed the cycle shrinks. Checks: the search starts on a cycle, the
bracket it returns has a cycle at its upper end and none at its lower end, the cycle amplitude grows with speed
along the branch (Polach 2006; Iwnicki 2006, ch. 9), and a start below the linear speed from a small
disturbance finds no cycle. The linear speed of a conical scene is that of rigid_dynamics' eigenvalue analysis
(regression against the function it wraps).
"""

import dataclasses
import json
from functools import partial
from pathlib import Path

import pytest

from comparisons.limit_cycle import limit_cycle_search
from rigid_dynamics.wheelset import build_provider, critical_speed, linear_model_for_scene, simulate
from rigid_dynamics.wheelset.linear import creep_coefficients
from wheelrail.cli import main
from wheelrail.critical import linear_critical_speed
from wheelrail.scenes import load_scene

SCENE_PATH = Path(__file__).parent / "data" / "limit_cycle_scene.toml"


@pytest.fixture(scope="module")
def scene_and_simulate():
    scene = load_scene(SCENE_PATH)
    return scene, partial(simulate, provider=build_provider(scene))


def test_limit_cycle_is_followed_down_in_speed(scene_and_simulate):
    scene, run = scene_and_simulate
    out = limit_cycle_search(scene, 60.0, 25.0, speed_steps=3, duration_s=1.5, bisections=1, simulate=run)
    assert out["success"], out["message"]
    assert out["runs"][0]["cycle"] and out["runs"][0]["amplitude_m"] > 0.004  # flange-contact cycle at 60 m/s
    lower, upper = out["bracket_m_per_s"]
    assert 25.0 <= lower < upper == out["speed_m_per_s"] < 60.0
    by_speed = {r["speed_m_per_s"]: r for r in out["runs"]}
    assert by_speed[upper]["cycle"] and not by_speed[lower]["cycle"]
    amplitudes = [b["amplitude_m"] for b in out["branch"]]  # sorted by speed
    assert amplitudes == sorted(amplitudes)


def test_no_cycle_below_the_linear_speed_from_a_small_disturbance(scene_and_simulate):
    scene, run = scene_and_simulate
    out = limit_cycle_search(scene, 20.0, 10.0, duration_s=1.0, disturbance_m=0.001, simulate=run)
    assert not out["success"] and out["status"] == "no-cycle-at-start" and out["speed_m_per_s"] is None


def test_linear_speed_of_a_conical_scene_is_the_eigenvalue_analysis():
    scene = load_scene("hunting-conical")
    scene = dataclasses.replace(
        scene,
        suspension=dataclasses.replace(
            scene.suspension, longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5
        ),
    )
    ours = linear_critical_speed(scene)
    direct = critical_speed(linear_model_for_scene(scene, *creep_coefficients(scene)))
    assert ours["success"] and ours["speed_m_per_s"] == pytest.approx(direct.speed_m_per_s, rel=1e-12)
    assert ours["model"] == "conical track"


def test_cli_writes_summary_and_plot(tmp_path, capsys):
    """Plumbing on the (fast) conical scene with a suspension; its physics is checked above."""
    out = tmp_path / "cs"
    sets = [
        "--set",
        "suspension.longitudinal_stiffness_N_per_m=5e5",
        "--set",
        "suspension.lateral_stiffness_N_per_m=5e5",
    ]
    code = main(["critical-speed", "hunting-conical", "--out", str(out), "--high", "20", "--duration", "0.3", *sets])
    text = capsys.readouterr().out
    assert "linear critical speed" in text and "nonlinear critical speed" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["linear"]["success"] and summary["linear"]["model"] == "conical track"
    assert summary["overrides"]["suspension.lateral_stiffness_N_per_m"] == 5e5
    assert (out / "critical_speed.png").stat().st_size > 0
    # far below the linear speed the disturbance decays: no cycle, said so, exit status 1 (no number)
    assert summary["nonlinear"]["status"] == "no-cycle-at-start" and summary["nonlinear"]["speed_m_per_s"] is None
    assert code == 1


@pytest.mark.parametrize(
    ("extra", "pattern"), [(["--high", "-1"], "--high -1.0: expected"), (["--threshold-mm", "0"], "--threshold-mm 0.0")]
)
def test_cli_bad_options(tmp_path, capsys, extra, pattern):
    assert main(["critical-speed", str(SCENE_PATH), "--out", str(tmp_path / "x"), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error:") and pattern in err, err


def test_branch_plot_shows_the_deciding_persistence_and_failed_runs(tmp_path):
    """The amplitude plot labels each run with the persistence ratio that decided it and draws a run without an
    amplitude (NaN: a failed run) instead of dropping it."""
    import math

    from PIL import Image

    from comparisons.limit_cycle import plot_branch

    runs = [
        {"speed_m_per_s": 60.0, "amplitude_m": 5e-3, "persistence": 0.99, "cycle": True, "status": "ok"},
        {"speed_m_per_s": 50.0, "amplitude_m": 6e-3, "persistence": 0.7, "cycle": False, "status": "ok"},
        {"speed_m_per_s": 45.0, "amplitude_m": math.nan, "persistence": math.nan, "cycle": False, "status": "blow-up"},
    ]
    outcome = {"runs": runs, "branch": [{"speed_m_per_s": 60.0, "amplitude_m": 5e-3}], "speed_m_per_s": 55.0}
    path = plot_branch(outcome, tmp_path / "branch.png", 70.0, persist_ratio=0.9)
    assert Image.open(path).size[0] > 400


def test_linear_speed_takes_the_rungs_slopes_at_zero_creepage():
    """The creep coefficients of the linear model are the rung's sensitivities at zero creepage on the static patch:
    Kalker's G a b C11, G a b C22 exactly for the linear rung (analytic), FASTSIM's slope on the scene's 20 x 20
    grid for fastsim (its grid error against Kalker, measured: +0.125 % in c11 and c22, within 0.3 %)."""
    from rigid_dynamics.contact.kalker import kalker_coefficients
    from rigid_dynamics.wheelset.linear import creep_sensitivities_at_rest

    scene = load_scene("hunting-conical")
    nu = scene.material.poisson_ratio
    for sens in creep_sensitivities_at_rest(scene, "linear"):
        kalker = kalker_coefficients(sens.semi_axis_long_m / sens.semi_axis_lat_m, nu)
        assert sens.kind == "analytic"
        assert sens.coefficients().c11 == pytest.approx(float(kalker.c11), rel=1e-12)
        assert sens.coefficients().c22 == pytest.approx(float(kalker.c22), rel=1e-12)
    for sens in creep_sensitivities_at_rest(scene, "fastsim"):
        kalker = kalker_coefficients(sens.semi_axis_long_m / sens.semi_axis_lat_m, nu)
        assert sens.kind == "central-difference" and sens.error_estimate[0, 0] <= 1e-9 * abs(sens.jacobian[0, 0])
        assert sens.coefficients().c11 == pytest.approx(float(kalker.c11), rel=3e-3)
        assert sens.coefficients().c22 == pytest.approx(float(kalker.c22), rel=3e-3)
    out = linear_critical_speed(dataclasses.replace(scene, contact_model="fastsim"))
    assert out["creep_coefficients"]["rung"] == "fastsim" and out["creep_coefficients"]["kind"] == "central-difference"


def test_a_conicity_that_is_not_ok_makes_the_linear_speed_a_warning(monkeypatch):
    """The real-profile proxy takes the EN 15302 conicity; when that result is not ok (here made "not-converged":
    a rigid-contact solve of its table failed), the linear speed computed from it is not reported ok."""
    import rigid_dynamics.contact.conicity as conicity

    real = conicity.equivalent_conicity_from_names

    def failing(*args, **kwargs):
        out = real(*args, **kwargs)
        return {**out, "success": False, "status": "not-converged", "message": "rigid contact failed at 1 shift(s)"}

    monkeypatch.setattr(conicity, "equivalent_conicity_from_names", failing)
    linear = linear_critical_speed(load_scene("polygonal-wheel"))
    assert linear["status"] == "warning" and not linear["success"]
    assert "the equivalent conicity is not-converged: rigid contact failed at 1 shift(s)" in linear["message"]
    assert linear["speed_m_per_s"] > 0 and "+- 0.08 % from its table" in linear["model"]
