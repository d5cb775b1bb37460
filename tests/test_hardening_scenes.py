"""Bad dynamics scenes: exit status 2 before any work (no output folder), one line naming key and value.

And numerical trouble below the driver (a huge suspension stiffness with RK4, a tiny shear modulus) ends as
a status of simulate(), never an exception.
"""

import dataclasses

import pytest
from hardening_helpers import assert_error, run, write

from rigid_dynamics.materials import Material
from wheelrail.scenes import load_scene, resolve_scene_path


def scene_text(name: str, *replacements: tuple[str, str]) -> str:
    text = resolve_scene_path(name).read_text(encoding="utf-8")
    for old, new in replacements:
        assert old in text, old
        text = text.replace(old, new)
    return text


@pytest.mark.parametrize(
    ("scene", "replacements", "fragments"),
    [
        ("hunting-conical", [('contact_model = "linear"', 'contact_model = "kalker"')], ["'contact_model' = 'kalker'"]),
        (
            "polygonal-wheel",
            [('contact_provider = "auto"', 'contact_provider = "conical"')],
            ["'contact_provider' = 'conical'", "'S1002' / 'UIC60'"],
        ),
        (
            "wheel-flat",
            [("flat_length_m = 0.05", "flat_length_m = 0.05\nflat_depth_m = 0.5")],
            ["'irregularities.flat_depth_m' = 0.5", "< r0 = 0.46"],
        ),
        (
            "wheel-flat",
            [("flat_length_m = 0.05", "flat_length_m = 3.0")],
            ["'irregularities.flat_length_m' = 3.0", "< 2 r0 = 0.92"],
        ),
        (
            "polygonal-wheel",
            [("polygon_amplitude_m = 3.0e-4", "polygon_amplitude_m = 0.5")],
            ["'irregularities.polygon_amplitude_m' = 0.5", "r0 / n^2"],
        ),
        ("hunting-conical", [("speed_m_per_s = 20.0", "speed_m_per_s = 1e6")], ["'speed_m_per_s' = 1000000.0", "200"]),
        ("hunting-conical", [("duration_s = 3.0", "duration_s = -1.0")], ["duration_s", "-1.0"]),
        (
            "hunting-conical",
            [('contact_provider = "tables"', 'contact_provider = "spline"')],
            ["contact_provider = 'spline'", "expected one of auto, conical, tables, search"],
        ),
        ("wheel-flat", [("gauge_m = 1.435", "gauge_m = 1e30")], ["'track.gauge_m' = 1e+30", "0.1 to 3"]),
        ("hunting-conical", [("output_step_s = 0.002", "output_step_s = 1e-30")], ["'integrator.output_step_s'"]),
        (
            "hunting-conical",
            [("lateral_displacement_m = 0.003", "lateral_displacement_m = 1e30")],
            ["'initial.lateral_displacement_m' = 1e+30", "flangeway"],
        ),
        (
            "curve-flange",
            [("[suspension]\n", "[suspension]\nframe_yaw_rad = 0.2\n")],
            ["frame_yaw_rad = 0.2", "|value| <= 0.1"],
        ),
    ],
)
def test_bad_scene_refused_before_work(capsys, tmp_path, scene, replacements, fragments):
    path = write(tmp_path, scene_text(scene, *replacements), "scene.toml")
    out = tmp_path / "out"
    code, stdout, err = run(capsys, "run", path, "--out", out, "--quiet")
    assert_error(code, err, *fragments)
    assert not out.exists() and stdout == ""


def test_unknown_model_leaves_no_default_output_folder(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write(tmp_path, scene_text("hunting-conical", ('contact_model = "linear"', 'contact_model = "x"')))
    code, _, err = run(capsys, "run", path, "--quiet")
    assert_error(code, err, "'contact_model' = 'x'")
    assert not (tmp_path / "wheelrail-out").exists()


def short(scene, **changes):
    return dataclasses.replace(scene, duration_s=0.05, **changes)


def test_huge_suspension_stiffness_with_rk4_is_a_status():
    """1e15 N/m with RK4 at 1 ms: the lateral mode (period ~2e-7 s) blows the fixed step up; a status, no raise."""
    from rigid_dynamics.wheelset import simulate

    scene = load_scene("hunting-conical")
    rk4 = dataclasses.replace(scene.integrator, method="RK4", fixed_step_s=1e-3, output_step_s=1e-3)
    stiff = dataclasses.replace(scene.suspension, lateral_stiffness_N_per_m=1e15)
    result = simulate(short(scene, integrator=rk4, suspension=stiff))
    assert not result.success and result.status == "step-unstable"  # the stiff spring's mode: stability.py
    assert result.message


def test_tiny_shear_modulus_is_a_status():
    """G = 1 Pa: no static equilibrium exists on the rails (the wheel sinks until the curvatures turn negative)."""
    from rigid_dynamics.wheelset import simulate

    scene = load_scene("hunting-conical")
    result = simulate(short(scene, material=Material(1.0, 0.28, 0.3)))
    assert result.status == "invalid-initial-state" and "no static equilibrium" in result.message


def test_tiny_shear_modulus_in_a_scene_file_is_bad_input(capsys, tmp_path):
    text = scene_text("hunting-conical")
    text += "" if "[material]" in text else "\n[material]\nshear_modulus_Pa = 82e9\npoisson_ratio = 0.28\n"
    text = text.replace("shear_modulus_Pa = 82.0e9", "shear_modulus_Pa = 1.0").replace(
        "shear_modulus_Pa = 82e9", "shear_modulus_Pa = 1.0"
    )
    code, _, err = run(capsys, "run", write(tmp_path, text), "--out", tmp_path / "o", "--quiet")
    assert_error(code, err, "'material.shear_modulus_Pa' = 1.0", "1e+06 to 1e+12")
