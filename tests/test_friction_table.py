"""The ``[friction]`` table of contact case files: the law it gives, and bad values ending with one
``wheelrail: error:`` line and exit 2 (docs/files.md)."""

import re

import pytest
from hardening_helpers import quadric_case, run

from rigid_dynamics.contact.friction import friction_law_from_table
from wheelrail.cases import parse_case
from wheelrail.config import ConfigError

NO_MU = re.sub(r"friction_coefficient = [0-9.]+\n", "", quadric_case())


def _case(friction: str, base: str = NO_MU) -> dict:
    import tomllib

    return tomllib.loads(base + "[friction]\n" + friction)


def test_laws_from_the_table():
    """Each law's keys give the FallingLaw of rigid_dynamics.contact.friction (Polach's A, B converted as CONTACT's
    L = 5: mu_k = A mu_0, f1 = mu_0 - mu_k, s1 = ln 2 / B), and the material's one number is the largest static
    coefficient."""
    case = parse_case(_case('law = "polach"\nstatic = 0.55\npolach_a = 0.4\npolach_b_s_per_m = 0.6\n'))
    law = case.material.friction
    assert case.material.friction_coefficient == pytest.approx(0.55)
    assert law.coefficient(0.0) == pytest.approx(0.55) and law.coefficient(1e3) == pytest.approx(0.22)
    assert law.coefficient(2.0) == pytest.approx(0.55 * (0.6 * 2.718281828459045 ** (-1.2) + 0.4))
    law = friction_law_from_table(
        {"law": "rational", "kinetic": 0.2, "term_1": 0.1, "half_velocity_1_m_per_s": 0.5, "term_2": 0.05}
    )
    assert law.coefficient(0.5) == pytest.approx(0.2 + 0.1 / 2 + 0.05 / 1.25)  # s2 defaults to 1 m/s
    law = friction_law_from_table(
        {"law": "coulomb", "varies_with": "surface_inclination", "nodes_rad": [0.1, 0.3], "coefficient": [0.3, 0.1]}
    )
    assert law.coefficient(0.0, 0.2) == pytest.approx(0.2) and law.coefficient(5.0, 1.0) == pytest.approx(0.1)
    law = friction_law_from_table(
        {"law": "linear", "varies_with": "track_distance", "nodes_m": [0.0, 100.0], "kinetic": [0.2, 0.3],
         "term_1": 0.1, "half_velocity_1_m_per_s": 1.0}
    )  # fmt: skip
    assert law.coefficient(1.0, 50.0) == pytest.approx(0.25 + 0.05)


@pytest.mark.parametrize(
    ("friction", "pattern"),
    [
        ('law = "stribeck"\n', r"key 'friction.law' = 'stribeck': expected one of coulomb, linear, polach"),
        ('law = "coulomb"\n', r"key 'friction.coefficient' is missing: law = 'coulomb' needs coefficient"),
        ('law = "coulomb"\ncoefficient = -0.1\n', r"kinetic = -0.1: expected a finite number >= 0"),
        ('law = "coulomb"\ncoefficient = "high"\n', r"key 'friction.coefficient' = 'high': expected a number"),
        ('law = "coulomb"\ncoefficient = 0.3\nkinetic = 0.2\n', r"key 'friction.kinetic' = 0.2: not a key of law"),
        (
            'law = "exponential"\nkinetic = 0.2\nterm_1 = 0.1\nhalf_velocity_1_m_per_s = 0.0\n',
            r"half_velocity_1_m_per_s = 0.0: expected a finite number > 0 \(m/s\)",
        ),
        ('law = "polach"\nstatic = 0.4\npolach_a = 1.5\npolach_b_s_per_m = 0.6\n', r"polach_a = 1.5: expected"),
        (
            'coefficient = [0.3, 0.2]\nvaries_with = "surface_inclination"\nnodes_m = [0.1, 0.2]\n',
            r"key 'friction.nodes_m' = \[0.1, 0.2\]: not a key of law",
        ),
        (
            'coefficient = [0.3, 0.2]\nvaries_with = "rail_lateral"\nnodes_m = [0.2, 0.1]\n',
            r"key 'friction.nodes_m' = \[0.2, 0.1\]: expected strictly ascending values",
        ),
        (
            'coefficient = [0.3, 0.2, 0.1]\nvaries_with = "track_distance"\nnodes_m = [0.0, 10.0]\n',
            r"key 'friction.coefficient' = \[0.3, 0.2, 0.1\]: expected a number or a list of 2 numbers",
        ),
        ('coefficient = 0.3\nvaries_with = "speed"\n', r"key 'friction.varies_with' = 'speed': expected one of none"),
    ],
)
def test_bad_friction_tables(tmp_path, capsys, friction, pattern):
    path = tmp_path / "case.toml"
    path.write_text(NO_MU + "[friction]\n" + friction)
    code, out, err = run(capsys, "contact", str(path), "--method", "bem")
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("wheelrail: error: "), err
    assert re.search(pattern, lines[0]), lines[0]


def test_friction_table_with_material_coefficient_is_refused(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(quadric_case() + '[friction]\nlaw = "coulomb"\ncoefficient = 0.3\n')
    code, out, err = run(capsys, "contact", str(path), "--method", "bem")
    assert code == 2 and "key 'material.friction_coefficient' = 0.3: not allowed with a [friction] table" in err
    with pytest.raises(ConfigError, match="expected a table"):
        parse_case({**_case("coefficient = 0.3\n"), "friction": 0.3})
