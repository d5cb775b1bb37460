"""`wheelrail run` and `wheelrail stress` end to end, and bad scenes (examples are tests).

The physics of the runs is verified in tests/test_dynamics_*.py (Klingel wavelength etc.); here the
front's contract is checked: the output folder holds the scene, summary.json with the required keys
and atomically written data, and a bad scene fails before any work with the key named.
"""

import json

import numpy as np
import pytest
from hardening_helpers import assert_bad_scene

from wheelrail.cli import main
from wheelrail.scenes import embedded_scenes, load_scene

SUMMARY_KEYS = {
    "status",
    "message",
    "simulated_time_s",
    "wall_time_s",
    "real_time_factor",
    "peak_normal_force_N",
    "max_abs_lateral_displacement_m",
    "dominant_lateral_wavelength_m",
}


def test_every_embedded_scene_validates():
    names = set(embedded_scenes())
    assert {"hunting-conical", "polygonal-wheel", "wheel-flat", "corrugation"} <= names
    for name in names:
        load_scene(name)


def test_run_short_scene_writes_folder(tmp_path, capsys):
    scene = (embedded_scenes()["hunting-conical"]).read_text()
    scene = scene.replace("duration_s = 3.0", "duration_s = 0.3")
    path = tmp_path / "short.toml"
    path.write_text(scene)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    assert "output written to" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert SUMMARY_KEYS <= set(summary)
    assert set(summary["peak_normal_force_N"]) == {"left", "right"}
    assert (out / "scene.toml").read_text() == scene
    with np.load(out / "timeseries.npz") as data:
        assert np.all(np.isfinite(data["t"]))
    assert not list(out.glob("*.part"))
    assert any(p.suffix == ".png" for p in out.iterdir())


SCENE_ERRORS = [
    ("speed_m_per_s = 20.0", "speed_m_per_s = -20.0", r"speed_m_per_s"),
    ("speed_m_per_s = 20.0", "speed_m_per_s = 20.0\nsped = 1", r"unknown key 'sped' at the top level"),
    ("mass_kg = 1813.0", "mass_kg = 'heavy'", r"'wheelset.mass_kg' = 'heavy': expected a finite number"),
    ("duration_s = 3.0", "", r"missing key 'duration_s'"),
    ("poisson_ratio = 0.28", "poisson_ratio = 0.5", r"poisson_ratio"),
    ("nominal_radius_m = 0.46", "nominal_radius_m = -0.46", r"nominal_radius_m"),
    ("duration_s = 3.0", "duration_s = nan", r"'duration_s' = nan: expected a finite number"),
    ("speed_m_per_s = 20.0", "speed_m_per_s = 20.0\nfastsim_strips = 0", r"fastsim_strips = 0: expected an integer"),
    ("speed_m_per_s = 20.0", "speed_m_per_s = 20.0\nfastsim_strips = 2.5", r"'fastsim_strips' = 2.5"),
    ("speed_m_per_s = 20.0", "speed_m_per_s = 20.0\nkpec_points = 4", r"kpec_points = 4: expected an integer from 8"),
    ("speed_m_per_s = 20.0", "speed_m_per_s = 20.0\nkpec_points = 2.5", r"'kpec_points' = 2.5"),
    (
        'wheel_profile = "conical"',
        'wheel_profile = "/no/such/wheel.prw"',
        r"'track.wheel_profile' = '/no/such/wheel.prw'",
    ),
]


@pytest.mark.parametrize(("old", "new", "pattern"), SCENE_ERRORS)
def test_bad_scene_fails_before_work(tmp_path, capsys, old, new, pattern):
    assert_bad_scene(tmp_path, capsys, "hunting-conical", old, new, pattern)


def test_unreadable_profile_file_in_case(tmp_path, capsys):
    from wheelrail.cases import embedded_cases

    text = embedded_cases()["manchester-a22"].read_text()
    bad = tmp_path / "garbage.prw"
    bad.write_text("this is not a profile\n1 2 3\n")
    path = tmp_path / "case.toml"
    path.write_text(text.replace('wheel_profile = "MBench_S1002_v3"', f'wheel_profile = "{bad}"'))
    assert main(["contact", str(path), "--method", "hertz"]) == 2
    err = capsys.readouterr().err
    assert "'geometry.wheel_profile'" in err and "garbage.prw" in err
