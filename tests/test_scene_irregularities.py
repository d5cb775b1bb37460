"""Irregularities from TOML: several out-of-roundness harmonics, a measured wheel grid, a measured corrugation grid.

Checks against closed forms: the wheel surface built from the scene carries R_irr = sum A_k cos(n_k alpha + phi_k)
(harmonics) and the grid's spline reproduces a smooth sampled function to its interpolation error; a short
run with two harmonics on the 3-D search matches the run of the same harmonic given as the polygon on the
analytic conical provider (a second code path). Bad grid files fail before any work with the key named.
"""

import math

import numpy as np
import pytest

from rigid_dynamics.geometry.measured import write_grid_csv
from rigid_dynamics.wheelset import simulate
from rigid_dynamics.wheelset.providers import build_surfaces, geometry_irregularities
from wheelrail.cli import main
from wheelrail.scenes import embedded_scenes, load_scene

BASE = embedded_scenes()["hunting-conical"].read_text()


def _scene(tmp_path, extra: str, *, duration="0.01", provider="auto", method="RK4"):
    text = BASE.replace("duration_s = 3.0", f"duration_s = {duration}")
    text = text.replace('contact_provider = "tables"', f'contact_provider = "{provider}"')
    text = text.replace('method = "DP54"', f'method = "{method}"\nfixed_step_s = 0.001')
    path = tmp_path / "scene.toml"
    path.write_text(text + "\n" + extra)
    return path


HARMONICS = """
[irregularities]
[[irregularities.harmonics]]
order = 3
amplitude_m = 2.0e-4
[[irregularities.harmonics]]
order = 7
amplitude_m = 5.0e-5
phase_rad = 0.5
"""


def test_harmonics_sum_on_the_wheel_surface(tmp_path):
    scene = load_scene(_scene(tmp_path, HARMONICS))
    assert len(scene.irregularities.harmonics) == 2 and scene.irregularities.needs_search
    track = build_surfaces(scene.wheelset, scene.track, scene.irregularities)
    ideal = build_surfaces(scene.wheelset, scene.track, None)
    alpha = np.linspace(0, 2 * math.pi, 50)
    y = np.full_like(alpha, 0.75)
    r_irr = track.wheels["right"].evaluate(alpha, y)[0] - ideal.wheels["right"].evaluate(alpha, y)[0]
    expected = 2e-4 * np.cos(3 * alpha) + 5e-5 * np.cos(7 * alpha + 0.5)
    np.testing.assert_allclose(r_irr, expected, atol=1e-15)


def test_measured_wheel_grid_and_corrugation_from_csv(tmp_path):
    angle = np.linspace(0, 2 * math.pi, 64, endpoint=False)
    y_p = np.linspace(-0.06, 0.06, 7)
    write_grid_csv(tmp_path / "oor.csv", "angle_rad", angle, y_p, np.outer(1e-4 * np.cos(2 * angle), np.ones(7)))
    x = np.linspace(0.0, 2.0, 201)
    y_r = np.linspace(-0.03, 0.03, 5)
    write_grid_csv(tmp_path / "corr.csv", "x_m", x, y_r, np.outer(3e-5 * np.sin(2 * math.pi * x / 0.05), np.ones(5)))
    extra = '[irregularities]\nwheel_grid_file = "oor.csv"\ncorrugation_file = "corr.csv"\n'
    scene = load_scene(_scene(tmp_path, extra))  # relative paths: next to the scene file
    wheel, rail = geometry_irregularities(scene.irregularities, scene.wheelset.nominal_radius_m)
    (oor,) = wheel["right"]
    (corrugation,) = rail["left"]
    a = np.linspace(0.1, 6.0, 40)
    np.testing.assert_allclose(oor.evaluate(a, np.zeros_like(a))[0], 1e-4 * np.cos(2 * a), atol=2e-7)
    np.testing.assert_allclose(oor.evaluate(a, np.full_like(a, 0.1))[0], 0.0)  # outside the measured width
    xs = np.linspace(0.1, 1.9, 37)
    n_irr = corrugation.evaluate(xs, np.zeros_like(xs))[0]
    np.testing.assert_allclose(n_irr, 3e-5 * np.sin(2 * math.pi * xs / 0.05), atol=3e-7)
    # the wheel and rail surfaces of the run carry them
    track = build_surfaces(scene.wheelset, scene.track, scene.irregularities)
    assert [type(i).__name__ for i in track.wheels["right"].irregularities] == ["MeasuredWheelIrregularity"]
    assert [type(i).__name__ for i in track.rails["left"].irregularities] == ["MeasuredRailIrregularity"]


def test_two_harmonics_run_on_the_search_matches_the_polygon_on_the_analytic_provider(tmp_path):
    harmonic = "[irregularities]\n[[irregularities.harmonics]]\norder = 3\namplitude_m = 2.0e-4\n"
    polygon = "[irregularities]\npolygon_order = 3\npolygon_amplitude_m = 2.0e-4\n"
    scene_h = load_scene(_scene(tmp_path, harmonic, method="RK4"))
    scene_p = load_scene(_scene(tmp_path, polygon, provider="conical", method="RK4"))
    run_h, run_p = simulate(scene_h), simulate(scene_p)
    assert run_h.success and run_p.success, (run_h.message, run_p.message)
    assert run_h.provider == "search" and run_p.provider == "conical"
    force_h, force_p = run_h.wheel_normal_force_N, run_p.wheel_normal_force_N
    assert np.abs(force_h - force_p).max() < 1e-3 * force_p.max()
    np.testing.assert_allclose(run_h.states[:, 1], run_p.states[:, 1], atol=1e-8)


@pytest.mark.parametrize(
    ("extra", "pattern"),
    [
        ('[irregularities]\nwheel_grid_file = "missing.csv"\n', r"'irregularities.wheel_grid_file' = 'missing.csv'"),
        ("[irregularities]\ncorrugation_file = 3\n", r"'irregularities.corrugation_file' = 3: expected the path"),
        (
            "[irregularities]\n[[irregularities.harmonics]]\norder = 0\namplitude_m = 1e-4\n",
            r"order = 0: expected an integer >= 1",
        ),
    ],
)
def test_bad_irregularities_fail_before_work(tmp_path, capsys, extra, pattern):
    import re

    path = _scene(tmp_path, extra)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error:") and re.search(pattern, err), err
    assert len(err.strip().splitlines()) == 1


def test_analytic_provider_refuses_harmonics(tmp_path, capsys):
    path = _scene(tmp_path, HARMONICS, provider="conical")
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "contact_provider = 'conical' with irregularities harmonics" in err
    assert "expected contact_provider 'search' or 'auto'" in err
