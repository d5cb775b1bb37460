"""CONTACT wheel slices files (.slcw): the reader recovers a parametric flat written as slices.

Reference: the rounded flat's closed form (WheelFlat). The slices are written the way CONTACT's example
``S1002_flat.slcw`` is laid out (header, angles in rad, one profile file per slice, sparse slices round the wheel
and dense ones over the flat), with the profile's z pointing up (the reader must detect it from the base slice and
apply the same transform to every slice, keeping the flat's depth at the tape circle).
"""

import json
import math

import numpy as np
import pytest

from rigid_dynamics.geometry import WheelFlat, load_profile
from rigid_dynamics.geometry.slices import read_wheel_slices

R0 = 0.46
THETA_FLAT = 0.6  # CONTACT's theta_wc of the flat's centre


def _write(tmp_path, flat, header=None, th_intpol=1):
    profile = load_profile("S1002", "wheel")
    y_mm, z_mm = profile.y_m * 1e3, -profile.z_m * 1e3  # z up in the files
    sparse = np.linspace(-3.1, 3.1, 63)
    theta = np.concatenate([sparse[sparse < 0.45], np.linspace(0.5, 0.7, 101), sparse[sparse > 0.75]])
    (tmp_path / "slices").mkdir()
    lines = header or [
        "% synthetic flat",
        "0.0  1.0   TH_OFFSET, TH_SCALE",
        f"{theta.size}   NSLC",
        "0 0 0",
        str(th_intpol),
    ]
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


class _Parabola:
    """R_irr = c (theta - theta_0)^2 within 0.1 rad of theta_0 (the dense slices), constant beyond (continuous)."""

    c = 0.1  # m / rad^2

    def evaluate(self, alpha, y):
        theta = 0.5 * math.pi - np.asarray(alpha, float)
        return (self.c * np.minimum((theta - THETA_FLAT) ** 2, 0.01),)


def test_approximating_slices_read_as_contacts_b_spline(tmp_path):
    """TH_INTPOL 2: the slices are the control points of a cubic B-spline along the angle (CONTACT's approximating
    spline). Reference, closed form: on uniform knots h a cubic B-spline whose control points lie on c theta^2 is
    c (theta^2 + h^2 / 3) (the B-spline reproduces quadratics shifted by c h^2 / 3), here 1.33e-7 m on the 2 mrad
    dense slices; TH_INTPOL 1 passes through the slices. The base slice lies on the constant part (c 0.01 = 1 mm
    of material at the tape circle): the reader re-zeroes the base profile there and keeps that offset in R_irr
    (``origin_offset_m``), so the wheel is the files' at every angle, as CONTACT reads them."""
    parabola = _Parabola()
    (tmp_path / "a").mkdir()
    (tmp_path / "i").mkdir()
    approx = read_wheel_slices(_write(tmp_path / "a", parabola, th_intpol=2))
    interp = read_wheel_slices(_write(tmp_path / "i", parabola, th_intpol=1))
    assert (approx.th_intpol, interp.th_intpol) == (2, 1)
    assert approx.origin_offset_m == pytest.approx(parabola.c * 0.01, abs=1e-12)
    assert float(approx.base.z_m[np.argmin(np.abs(approx.base.y_m))]) == pytest.approx(0.0, abs=1e-9)
    h = 0.2 / 100
    theta = THETA_FLAT + h * np.arange(-30, 31)
    alpha = 0.5 * math.pi - theta
    for y in (-0.02, 0.0, 0.03):
        ys = np.full_like(alpha, y)
        want = parabola.c * (theta - THETA_FLAT) ** 2  # the files' wheel: the base's offset kept
        np.testing.assert_allclose(interp.irregularity.evaluate(alpha, ys)[0], want, atol=1e-11)
        np.testing.assert_allclose(approx.irregularity.evaluate(alpha, ys)[0], want + parabola.c * h**2 / 3, atol=1e-11)


@pytest.mark.parametrize(
    ("header", "pattern"),
    [
        (["0.0 1.0", "160", "0 0 0", "3"], r"TH_INTPOL = 3: expected 1 \(interpolating\) or 2"),
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
    the case's folder (the one case loader, also behind ``--set``), and a missing one is a one-line error.

    Checks that the file is found (exit 0, status ok) and applied: with the wheels turned by ``THETA_FLAT`` the
    flat of the right wheel's slices is at its contact, so its Hertz patch is longer and its p0 lower than the round
    left wheel's (measured 15.4 against 7.15 mm, 860 against 1460 MPa). Hertz is the method: the claim is the path
    and the geometry read, not a contact model (the default ``auto`` sends the patches to the BEM: 7.5 s against
    5.3 s for this test); the ``--set`` load is checked on both wheels' equilibrium.
    """
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
    argv = ["--method", "hertz", "--json", "--set", "loading.wheel_load_N=7e4"]
    code, out, err = run(
        capsys, "contact", "../case/case.toml", *argv, "--set", f"kinematics.wheel_rotation_rad={THETA_FLAT}"
    )
    assert code == 0, err
    record = json.loads(out)
    assert record["status"] == "ok" and record["success"], record["message"]
    loads = record["case"]["wheel_vertical_load_N"]
    assert loads["left"] == pytest.approx(7e4, rel=1e-5) and loads["right"] == pytest.approx(7e4, rel=1e-5)
    patches = {p["side"]: p for p in record["patches"]}
    assert patches["right"]["max_pressure_Pa"] < 0.7 * patches["left"]["max_pressure_Pa"]
    assert patches["right"]["semi_axis_long_m"] > 1.5 * patches["left"]["semi_axis_long_m"]
    code, out, err = run(capsys, "contact", "../case/bad.toml")
    assert_error(code, err, "irregularities.wheel_slices_file", "nothere.slcw", "no such file")
    assert list(elsewhere.iterdir()) == []
