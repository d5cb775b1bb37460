"""Bad input to the CLI and the case/scene loaders: one clear message, exit status 2, no traceback."""

import pytest
from hardening_helpers import quadric_case

from wheelrail.cases import parse_case
from wheelrail.cli import main
from wheelrail.config import ConfigError

GOOD_QUADRIC = quadric_case(normal_force_N="1e5", creepage_long="0.0")


def run_cli(capsys, *argv):
    code = main(list(argv))
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return code, captured.out, captured.err


def write_case(tmp_path, text, name="case.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ("radius_lat_m = 0.3", "radius_lat_m = 0.3\nradius_later_m = 1.0", r"unknown key 'geometry.radius_later_m'"),
        ("radius_lat_m = 0.3", "", r"missing key 'geometry.radius_lat_m'"),
        ("radius_lat_m = 0.3", 'radius_lat_m = "big"', r"geometry.radius_lat_m' = 'big': expected a finite number"),
        ("radius_lat_m = 0.3", "radius_lat_m = -0.3", r"geometry.radius_lat_m' = -0.3: expected a number > 0"),
        ("poisson_ratio = 0.28", "poisson_ratio = 0.7", r"poisson_ratio. = 0.7: expected a value in \(-1, 0.5\)"),
        ("poisson_ratio = 0.28", "poisson_ratio = -1.5", r"poisson_ratio' = -1.5"),
        ("normal_force_N = 1e5", "normal_force_N = inf", r"loading.normal_force_N' = inf: expected a finite number"),
        ("normal_force_N = 1e5", "normal_force_N = nan", r"loading.normal_force_N' = nan: expected a finite number"),
        ("creepage_lat = 0.0", "creepage_lat = true", r"kinematics.creepage_lat' = True: expected a finite number"),
        ('kind = "quadric"', 'kind = "ellipsoid"', r"geometry.kind' = 'ellipsoid': expected 'quadric' or 'wheelset'"),
        ("normal_force_N = 1e5", "normal_force_N = 1e5\napproach_m = 1e-5", r"exactly one of 'normal_force_N'"),
        ("shear_modulus_Pa = 82e9", "shear_modulus_Pa = 82e9\nyoung_modulus_Pa = 210e9", r"exactly one of"),
        ("[kinematics]", "[kinematic]", r"unknown key 'kinematic'"),
    ],
)
def test_bad_quadric_case(tmp_path, capsys, old, new, pattern):
    assert old in GOOD_QUADRIC
    path = write_case(tmp_path, GOOD_QUADRIC.replace(old, new, 1))
    code, out, err = run_cli(capsys, "contact", str(path), "--method", "hertz", "--json")
    assert code == 2
    assert err.startswith("wheelrail: error: ")
    assert err.count("\n") == 1
    import re

    assert re.search(pattern, err), err


def test_malformed_toml_and_missing_file(tmp_path, capsys):
    path = write_case(tmp_path, "[material\nshear_modulus_Pa = 1")
    code, _, err = run_cli(capsys, "contact", str(path))
    assert code == 2 and "not valid TOML" in err
    code, _, err = run_cli(capsys, "contact", str(tmp_path / "absent.toml"))
    assert code == 2 and "no such file" in err


def test_unknown_method_and_scene(tmp_path, capsys):
    path = write_case(tmp_path, GOOD_QUADRIC)
    code, _, err = run_cli(capsys, "contact", str(path), "--method", "magic")
    assert code == 2 and "--method 'magic': expected one of hertz" in err
    code, _, err = run_cli(capsys, "run", "no-such-scene")
    assert code == 2 and "no embedded scene of that name" in err


def test_unknown_command_is_an_argparse_error(capsys):
    assert main(["fly"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error: argument COMMAND: invalid choice: 'fly'") and err.count("\n") == 1


def test_parse_case_builds_quadric_geometry():
    import tomllib

    case = parse_case(tomllib.loads(GOOD_QUADRIC))
    assert case.kind == "quadric"
    assert case.geometry.curvature_long_1_per_m == pytest.approx(0.5 / 0.46)
    assert case.geometry.curvature_lat_1_per_m == pytest.approx(0.5 / 0.3)
    assert case.normal_force_N == 1e5
    assert case.creepage.rolling_speed_m_per_s == 20.0
    assert case.material.young_modulus_Pa == pytest.approx(2 * 82e9 * 1.28)


def test_young_modulus_accepted():
    import tomllib

    doc = tomllib.loads(GOOD_QUADRIC.replace("shear_modulus_Pa = 82e9", "young_modulus_Pa = 210e9"))
    case = parse_case(doc)
    assert case.material.shear_modulus_Pa == pytest.approx(210e9 / 2.56)


def test_config_error_is_value_error():
    assert issubclass(ConfigError, ValueError)
