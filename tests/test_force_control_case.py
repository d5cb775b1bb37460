"""A contact case with the longitudinal force prescribed (CONTACT's F = 1): ``[loading] longitudinal_force_N``, the
longitudinal creepage solved by Brent's method (rigid_dynamics.contact.force_control). The solver itself is
checked against CONTACT in tests/test_contact_veldep.py."""

import json
import math
import re

from hardening_helpers import quadric_case, run

from rigid_dynamics.contact.kalker import kalker_coefficients
from rigid_dynamics.materials import STEEL

BEM = "[solver]\nnx = 24\nny = 24\ngrid_tolerance = 0.5\n"


def _case(force: str, creepage_long: bool = False) -> str:
    text = quadric_case(normal_force_N="1e5")
    if not creepage_long:
        text = re.sub(r"creepage_long = [^\n]+\n", "", text)
    return text.replace("normal_force_N = 1e5\n", f"normal_force_N = 1e5\nlongitudinal_force_N = {force}\n")


def test_small_traction_force_gives_kalkers_linear_creepage(tmp_path, capsys):
    """A force of 0.03 mu FN on the wheel (braking: F_x > 0 needs xi < 0): the solved creepage within 3 % of
    Kalker's linear theory xi = -F / (G a b C11) (the BEM on 24 x 24 elements is within about 2 % of it at small
    creepage), the residual within the stated tolerance, and the reported force that of the patch."""
    path = tmp_path / "case.toml"
    target = 0.03 * 0.3 * 1e5
    path.write_text(_case(repr(target)) + BEM)
    code, out, err = run(capsys, "contact", str(path), "--method", "bem", "--json", "--out", str(tmp_path / "o"))
    data = json.loads(out)
    control = data["case"]["force_control"]
    assert code == 0 and data["status"] == "ok" and control["status"] == "ok", control
    assert abs(control["residual_N"]) <= control["force_tolerance_N"]
    assert math.isclose(control["force_tolerance_N"], 1e-4 * 0.3 * data["patches"][0]["normal_force_N"], rel_tol=1e-6)
    patch = data["patches"][0]
    assert patch["creep_force_long_N"] == control["longitudinal_force_N"]
    a, b = patch["semi_axis_long_m"], patch["semi_axis_lat_m"]
    c11 = float(kalker_coefficients(a / b, STEEL.poisson_ratio).c11)
    linear = -target / (STEEL.shear_modulus_Pa * a * b * c11)
    assert math.isclose(control["solved_creepage_long"], linear, rel_tol=0.03), (control, linear)


def test_force_beyond_friction_is_a_status(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(_case("-4e4") + BEM)  # 1.33 mu FN
    code, out, err = run(capsys, "contact", str(path), "--method", "bem", "--json", "--out", str(tmp_path / "o"))
    data = json.loads(out)
    assert code == 1 and data["status"] == "not-attainable" and not data["success"], data["status"]
    assert "no creepage up to 0.2 transmits -40000 N" in data["message"]


def test_force_with_creepage_is_bad_input(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(_case("-1e3", creepage_long=True))
    code, out, err = run(capsys, "contact", str(path), "--method", "bem")
    assert code == 2 and err.strip().count("\n") == 0
    assert "key 'kinematics.creepage_long' = 0.001: not allowed with 'loading.longitudinal_force_N'" in err


def test_wheelset_case_to_a_traction_force(tmp_path, capsys):
    """A wheelset case with 4.8 kN of traction on the wheelset (0.1 mu of the two 80 kN wheel loads), FASTSIM: the
    pitch rate solved, the creep forces on the wheels sum to the target within the stated tolerance (1e-4 mu
    times the load), and the solved wheelset creepage 1 - omega/omega_0 is the patches' longitudinal creepage
    (negative: the wheels turn faster than in free rolling and pull)."""
    from hardening_helpers import wheelset_case

    path = tmp_path / "case.toml"
    text = wheelset_case("")
    path.write_text(text.replace("wheel_load_N = 8e4\n", "wheel_load_N = 8e4\nlongitudinal_force_N = 4800.0\n"))
    code, out, err = run(capsys, "contact", str(path), "--method", "fastsim", "--json", "--out", str(tmp_path / "o"))
    data = json.loads(out)
    control = data["case"]["force_control"]
    assert code == 0 and data["status"] == "ok" and control["status"] == "ok", (data["status"], control)
    total = sum(p["creep_force_long_N"] for p in data["patches"])
    assert abs(total - 4800.0) <= control["force_tolerance_N"]
    assert math.isclose(control["force_tolerance_N"], 1e-4 * 0.3 * 1.6e5, rel_tol=1e-3)
    xi = control["solved_creepage_long"]
    assert xi < 0 and all(math.isclose(p["creepage_long"], xi, rel_tol=0.01) for p in data["patches"])
    assert control["pitch_rate_rad_per_s"] < -control["free_rolling_spin_rate_rad_per_s"]


def test_wheelset_force_with_pitch_rate_is_bad_input(tmp_path, capsys):
    from hardening_helpers import wheelset_case

    path = tmp_path / "case.toml"
    text = wheelset_case("[kinematics]\npitch_rate_rad_per_s = -4.3\n")
    path.write_text(text.replace("wheel_load_N = 8e4\n", "wheel_load_N = 8e4\nlongitudinal_force_N = 4800.0\n"))
    code, out, err = run(capsys, "contact", str(path), "--method", "fastsim")
    assert code == 2 and "key 'kinematics.pitch_rate_rad_per_s' = -4.3: not allowed with" in err
