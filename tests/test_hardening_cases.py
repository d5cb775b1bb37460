"""Bad contact cases, [solver] options included: one line naming key and value, exit status 2, before any work.

Also the declaration mechanism itself (rigid_dynamics.contact.options) and the flag on results that break
Coulomb's bound |F_t| <= mu N (exit status 1, a status that is not ok).
"""

import math
from pathlib import Path

import pytest
from hardening_helpers import QUADRIC, assert_error, run, write

from rigid_dynamics.contact.options import Option, OptionError, declare, declare_dataclass, validate_options
from rigid_dynamics.contact.registry import MODELS, get_model, model_options
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import STEEL

PROFILES = Path(__file__).resolve().parents[1] / "rigid_dynamics" / "geometry" / "data" / "profiles"


@pytest.mark.parametrize(
    ("method", "solver", "fragments"),
    [
        ("fastsim", "nx = -3", ["'solver.nx' = -3", "an integer from 1 to 1000", "'fastsim'"]),
        ("fastsim", "nx = 2.5", ["'solver.nx' = 2.5", "an integer"]),
        ("fastsim", 'nx = "ten"', ["'solver.nx' = 'ten'", "an integer"]),
        ("fastsim", 'flexibility = "many"', ["'solver.flexibility' = 'many'", "'single', 'three'"]),
        ("fastsim", "grid = 3", ["unknown key 'solver.grid' = 3", "expected one of nx, ny"]),
        ("bem", "difference_parameter = 0.7", ["'solver.difference_parameter' = 0.7", "< 0.5"]),
        ("bem", "nx = 0", ["'solver.nx' = 0", "'bem'"]),
        ("fea", 'formulation = "mortar"', ["'solver.formulation' = 'mortar'", "'rigid', 'two-body', 'profiles'"]),
        ("fea", "degree = 2\nformulation = 'two-body'", ["[solver]", "formulation 'rigid'"]),
        ("hertz", "nx = 40", ["unknown key 'solver.nx' = 40", "'hertz' takes no options"]),
        ("auto", "tolerance = -1.0", ["'solver.tolerance' = -1.0", "> 0"]),
        ("auto", "[solver.model_options.fastsim]\nnx = 0", ["'solver.model_options.fastsim.nx' = 0"]),
        ("auto", "[solver.model_options.fea]\nquick = true", ["'solver.model_options.fea'", "linear, vermeulen"]),
    ],
)
def test_bad_solver_option_of_a_quadric_case(capsys, tmp_path, method, solver, fragments):
    header = "" if solver.startswith("[") else "[solver]\n"
    case = write(tmp_path, QUADRIC + header + solver + "\n")
    code, _, err = run(capsys, "contact", case, "--method", method, "--out", tmp_path / "out")
    assert_error(code, err, *fragments)
    assert not (tmp_path / "out").exists()  # refused before any work: no output folder


@pytest.mark.parametrize(
    ("method", "solver", "fragments"),
    [
        ("bem", "[solver]\nnx = 3", ["unknown key 'solver.nx' = 3", "go in [solver.model]"]),
        ("bem", "[solver.model]\nnx = 3.5", ["'solver.model.nx' = 3.5", "'bem'"]),
        ("fastsim", "[solver.search]\nbogus = 1", ["unknown key 'solver.search.bogus' = 1", "alpha_points"]),
        ("fastsim", "[solver.search]\nalpha_points = 'a'", ["'solver.search.alpha_points' = 'a'", "an integer"]),
        ("fastsim", "[solver]\nspin_rate = 'x'", ["'solver.spin_rate' = 'x'", "'zero-axle-moment', 'nominal'"]),
        ("fea", "[solver.model]\nformulation = 'profiles'", ["[solver.model]", "wheel_profile and rail_profile"]),
    ],
)
def test_bad_solver_option_of_a_wheelset_case(capsys, tmp_path, method, solver, fragments):
    from wheelrail.cases import resolve_case_path

    text = resolve_case_path("manchester-a22").read_text().replace("[solver]\n", "")
    case = write(tmp_path, text + solver + "\n")
    code, _, err = run(capsys, "contact", case, "--method", method)
    assert_error(code, err, *fragments)


@pytest.mark.parametrize(
    ("old", "new", "fragments"),
    [
        ("creepage_long = 0.001", "creepage_long = 1e9", ["'kinematics.creepage_long' = 1000000000.0", "-1 to 1"]),
        ("rolling_speed_m_per_s = 20.0", "rolling_speed_m_per_s = 1e6", ["= 1000000.0", "0 to 200", "m/s"]),
        ("spin_creepage_1_per_m = 0.0", "spin_creepage_1_per_m = 1e4", ["'kinematics.spin_creepage_1_per_m'"]),
        ("shear_modulus_Pa = 82e9", "shear_modulus_Pa = 1.0", ["'material.shear_modulus_Pa' = 1.0", "1e+06"]),
        ("friction_coefficient = 0.3", "friction_coefficient = 50.0", ["'material.friction_coefficient' = 50.0"]),
        ("normal_force_N = 1e4", "normal_force_N = 1e12", ["'loading.normal_force_N' = 1000000000000.0"]),
        ("radius_lat_m = 0.3", "radius_lat_m = 1e-9", ["'geometry.radius_lat_m' = 1e-09"]),
    ],
)
def test_physically_absurd_case_values(capsys, tmp_path, old, new, fragments):
    assert old in QUADRIC
    case = write(tmp_path, QUADRIC.replace(old, new))
    code, _, err = run(capsys, "contact", case, "--method", "linear")
    assert_error(code, err, *fragments)


def test_unknown_method(capsys):
    code, _, err = run(capsys, "contact", "hertz-quadric", "--method", "kalker")
    assert_error(code, err, "--method 'kalker'", "hertz, linear")


def test_linear_theory_beyond_the_friction_bound_is_not_ok(capsys, tmp_path):
    """Creepage 0.5 with the linear theory: |F_t| = 240 mu N; reported, with a status that is not ok (exit 1)."""
    case = write(tmp_path, QUADRIC.replace("creepage_long = 0.001", "creepage_long = 0.5"))
    code, out, _ = run(capsys, "contact", case, "--method", "linear", "--json")
    assert code == 1
    assert '"status": "beyond-friction-limit"' in out and "outside its range" in out


def test_saturating_model_above_the_bound_fails():
    """FASTSIM on a 3 x 2 grid at full slip overshoots mu N by 19 % (strip sums): success False, says why."""
    geometry = ContactGeometry.quadric(0.46, 0.3, 0.0)
    coarse = get_model("fastsim").solve(
        geometry, Creepage(0.5, 0, 0), STEEL, normal_force_N=1e5, options={"nx": 3, "ny": 2}
    )
    assert not coarse.success and coarse.status == "friction-bound-exceeded"
    assert coarse.extra["friction_bound_ratio"] == pytest.approx(1.19, abs=0.01)
    fine = get_model("fastsim").solve(geometry, Creepage(0.5, 0, 0), STEEL, normal_force_N=1e5)
    assert fine.status == "ok" and fine.extra["friction_bound_ratio"] < 1.01
    vj = get_model("vermeulen-johnson").solve(geometry, Creepage(0.5, 0, 0), STEEL, normal_force_N=1e5)
    assert vj.status == "ok" and vj.extra["friction_bound_ratio"] == pytest.approx(1.0, abs=1e-12)
    # independent check of the bound: Coulomb, mu N
    assert math.hypot(vj.creep_force_long_N, vj.creep_force_lat_N) == pytest.approx(0.3 * 1e5, rel=1e-12)


def test_models_lists_every_declared_option(capsys):
    code, out, _ = run(capsys, "models")
    assert code == 0
    for name in MODELS:
        for option in model_options(name).values():
            assert option.describe() in out


@pytest.mark.parametrize("name", list(MODELS))
def test_every_model_declares_valid_defaults(name):
    declared = model_options(name)
    merged = validate_options(declared, {}, name)
    assert set(merged) == set(declared)
    with pytest.raises(OptionError, match=f"unknown {name} option 'no_such_option'"):
        validate_options(declared, {"no_such_option": 1}, name)


def test_option_types_and_ranges():
    declared = declare(
        Option("n", int, 2, "count", minimum=1, maximum=10),
        Option("x", float, 0.5, "fraction", minimum=0, maximum=1, exclusive_maximum=True),
        Option("kind", str, "a", "kind", choices=("a", "b")),
        Option("flag", bool, False, "flag"),
    )
    assert validate_options(declared, {"n": 3, "x": 0}, "toy") == {"n": 3, "x": 0.0, "kind": "a", "flag": False}
    for bad in ({"n": True}, {"n": 2.0}, {"n": 11}, {"x": 1.0}, {"x": math.nan}, {"kind": "c"}, {"flag": 1}):
        with pytest.raises(OptionError) as info:
            validate_options(declared, bad, "toy")
        ((key, value),) = bad.items()
        assert info.value.key == key and repr(value) in str(info.value)


def test_a_dataclass_field_without_declared_details_is_refused():
    from dataclasses import dataclass

    @dataclass(frozen=True)
    class Toy:
        n: int = 1
        name: str | None = None

    assert declare_dataclass(Toy, {"n": {"help": "n"}, "name": {"help": "a name"}})["name"].allow_none
    with pytest.raises(ValueError, match="Toy.name has no declared details"):
        declare_dataclass(Toy, {"n": {"help": "n"}})


@pytest.mark.parametrize("name", ["MBench_S1002_v3.prw", "MBench_UIC60_v3.prr", "MBench_UIC60_v3.ban", "avg_wheel.whl"])
def test_profile_file_with_a_byte_order_mark_reads_as_without(tmp_path, name):
    """A UTF-8 BOM (as some Windows editors write) is dropped by every reader, SIMPACK .prw/.prr included."""
    import numpy as np

    from rigid_dynamics.geometry.readers import read_profile

    source = PROFILES / name
    copy = tmp_path / name
    copy.write_bytes(b"\xef\xbb\xbf" + source.read_bytes())
    plain, with_bom = read_profile(source), read_profile(copy)
    assert with_bom.kind == plain.kind
    np.testing.assert_array_equal(with_bom.y_m, plain.y_m)
    np.testing.assert_array_equal(with_bom.z_m, plain.z_m)
