"""CONTACT wheel slices files (.slcw): the reader recovers a parametric flat written as slices.

Reference: the rounded flat's closed form (WheelFlat). The slices are written the way CONTACT's example
``S1002_flat.slcw`` is laid out (header, angles in rad, one profile file per slice, sparse slices round the wheel
and dense ones over the flat), with the profile's z pointing up (the reader must detect it from the base slice and
apply the same transform to every slice, keeping the flat's depth at the tape circle).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.geometry import WheelFlat, load_profile
from rigid_dynamics.geometry.slices import read_wheel_slices

R0 = 0.46
THETA_FLAT = 0.6  # CONTACT's theta_wc of the flat's centre


def _write(tmp_path, flat, header=None):
    profile = load_profile("S1002", "wheel")
    y_mm, z_mm = profile.y_m * 1e3, -profile.z_m * 1e3  # z up in the files
    sparse = np.linspace(-3.1, 3.1, 63)
    theta = np.concatenate([sparse[sparse < 0.45], np.linspace(0.5, 0.7, 101), sparse[sparse > 0.75]])
    (tmp_path / "slices").mkdir()
    lines = header or ["% synthetic flat", "0.0  1.0   TH_OFFSET, TH_SCALE", f"{theta.size}   NSLC", "0 0 0", "2"]
    for k, th in enumerate(theta):
        r_irr = float(flat.evaluate(0.5 * math.pi - th, 0.0)[0])
        name = f"slices/s_{k}.txt"
        rows = "\n".join(f"{y:.6f} {z - 1e3 * r_irr:.9f}" for y, z in zip(y_mm, z_mm, strict=True))
        (tmp_path / name).write_text("% y z [mm]\n" + rows + "\n")
        lines.append(f"{th:.6f}  '{name}'   % slice")
    path = tmp_path / "wheel.slcw"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_slices_reader_recovers_a_parametric_flat(tmp_path):
    flat = WheelFlat(0.05, R0, centre_angle_rad=0.5 * math.pi - THETA_FLAT)
    slices = read_wheel_slices(_write(tmp_path, flat))
    assert slices.base.name and slices.theta_rad[0] == pytest.approx(-3.1)
    alpha = 0.5 * math.pi - THETA_FLAT + np.linspace(-0.08, 0.08, 161)
    for y in (-0.02, 0.0, 0.03):
        got = slices.irregularity.evaluate(alpha, np.full_like(alpha, y))[0]
        want = flat.evaluate(alpha, y)[0]
        np.testing.assert_allclose(got, want, atol=3e-6)
    # the depth at the centre and nothing away from the flat
    centre = slices.irregularity.evaluate(0.5 * math.pi - THETA_FLAT, 0.0)[0]
    assert float(centre) == pytest.approx(-flat.depth, abs=1e-7)
    assert abs(float(slices.irregularity.evaluate(0.5 * math.pi + 2.0, 0.0)[0])) < 1e-7


@pytest.mark.parametrize(
    ("header", "pattern"),
    [
        (["0.0 1.0", "3", "0 0 0", "2"], r"NSLC = 3: expected at least 4 slices"),
        (["0.0 1.0", "x", "0 0 0", "2"], r"expected NSLC"),
        (["0.0 1.0", "160", "2 0 0", "2"], r"NFEAT = 2: expected 0"),
    ],
)
def test_bad_slices_files_raise(tmp_path, header, pattern):
    flat = WheelFlat(0.05, R0)
    with pytest.raises(ValueError, match=pattern):
        read_wheel_slices(_write(tmp_path, flat, header=list(header)))
    with pytest.raises(ValueError, match="no such file"):
        read_wheel_slices(tmp_path / "missing.slcw")


def test_case_key_reads_a_slices_file(tmp_path):
    from hardening_helpers import wheelset_case

    from wheelrail.cases import load_case
    from wheelrail.config import ConfigError

    flat = WheelFlat(0.05, R0, centre_angle_rad=0.5 * math.pi - THETA_FLAT)
    _write(tmp_path, flat)
    text = wheelset_case('[irregularities]\nwheel_slices_file = "wheel.slcw"\nside = "right"\n')
    (tmp_path / "case.toml").write_text(text)
    case = load_case(tmp_path / "case.toml").wheelset
    (irr,) = case.wheel_irregularities_right
    assert float(irr.evaluate(0.5 * math.pi - THETA_FLAT, 0.0)[0]) == pytest.approx(-flat.depth, abs=1e-7)
    (tmp_path / "bad.toml").write_text(text.replace("wheel.slcw", "nothere.slcw"))
    with pytest.raises(ConfigError, match=r"key 'irregularities.wheel_slices_file' = .*nothere.slcw.*no such file"):
        load_case(tmp_path / "bad.toml")


def test_cli_contact_reads_a_relative_slices_file_from_another_folder(tmp_path, monkeypatch, capsys):
    """``wheelrail contact case/case.toml`` run from elsewhere: the case's relative ``wheel_slices_file`` refers to
    the case's folder (the one case loader, also behind ``--set``), and a missing one is a one-line error."""
    from hardening_helpers import assert_error, run, wheelset_case

    folder = tmp_path / "case"
    folder.mkdir()
    _write(folder, WheelFlat(0.05, R0, centre_angle_rad=0.5 * math.pi - THETA_FLAT))
    text = wheelset_case('[irregularities]\nwheel_slices_file = "wheel.slcw"\nside = "right"\n')
    (folder / "case.toml").write_text(text)
    (folder / "bad.toml").write_text(text.replace("wheel.slcw", "nothere.slcw"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    code, out, err = run(capsys, "contact", "../case/case.toml", "--set", "loading.wheel_load_N=7e4")
    assert code == 0, err
    assert out.strip()
    code, out, err = run(capsys, "contact", "../case/bad.toml")
    assert_error(code, err, "irregularities.wheel_slices_file", "nothere.slcw", "no such file")
    assert list(elsewhere.iterdir()) == []
