"""BEM options through the CLI's ``[solver]`` table: bad values end with one ``wheelrail: error:`` line, exit 2."""

import re

import pytest
from hardening_helpers import quadric_case

from wheelrail.cli import main

CASE = quadric_case(normal_force_N="1e5", creepage_long="0.0") + "[solver]\n"


@pytest.mark.parametrize(
    ("solver", "pattern"),
    [
        ("element_size_m = -0.001", r"element_size_m' = -0.001: expected a finite number > 0"),
        ("element_size_m = 1e-9", r"element_size_m = 1e-09 gives \d+ x \d+ = \d+ elements: expected at most 4000000"),
        # a huge grid inside nx's declared range is refused up front with its memory and time estimate (it ran for
        # many minutes without a budget)
        (
            "nx = 3000\nny = 3000",
            r"nx, ny = \(3000, 3000\) gives 3000 x 3000 = 9000000 elements: expected at most "
            r"4000000 \(this grid needs about 2.3 GB of FFT work arrays and at least 4 minutes\)",
        ),
        ("element_size_m = 0.001\nnx = 20", r"element_size_m = 0.001 together with nx: expected either"),
        ('norm_method = "fast"', r"norm_method' = 'fast': expected one of 'normcg', 'polonsky-keer'"),
        # the grid-error options (issue 27)
        ("grid_tolerance = 0.0", r"grid_tolerance' = 0.0: expected a finite number > 0"),
        ("grid_tolerance = -0.02", r"grid_tolerance' = -0.02: expected a finite number > 0"),
        ('grid_tolerance = "tight"', r"grid_tolerance' = 'tight': expected a finite number > 0"),
        ("grid_tolerance = nan", r"grid_tolerance' = nan: expected a finite number"),
        ("max_refinements = -1", r"max_refinements' = -1: expected an integer from 0 to 5"),
        ("max_refinements = 6", r"max_refinements' = 6: expected an integer from 0 to 5"),
        ("dx_m = 0.0", r"dx_m' = 0.0: expected a finite number > 0 and <= 0.1"),
        ("dy_m = -1e-4\ndx_m = 1e-4", r"dy_m' = -0.0001: expected a finite number > 0 and <= 0.1"),
        ("dy_m = 1e-4", r"option dy_m = 0.0001 without dx_m"),
        ("dx_m = 1e-4\nnx = 20", r"option dx_m = 0.0001 together with nx"),
    ],
)
def test_bad_bem_solver_options(tmp_path, capsys, solver, pattern):
    path = tmp_path / "case.toml"
    path.write_text(CASE + solver + "\n")
    code = main(["contact", str(path), "--method", "bem", "--json"])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert err.startswith("wheelrail: error: ") and err.count("\n") == 1, err
    assert re.search(pattern, err), err


def test_element_size_through_the_cli(tmp_path, capsys):
    """A case with ``element_size_m`` runs: the grid in the JSON output has that element size and its grid-error
    estimate; the named grid (17 x 13 elements) is coarser than the default ``grid_tolerance`` asks: status
    ``warning``, exit 1, the estimate in the message; with ``grid_tolerance = 0.1`` it is ``ok``, exit 0."""
    import json

    path = tmp_path / "case.toml"
    path.write_text(CASE + "element_size_m = 1e-3\n")
    code = main(["contact", str(path), "--method", "bem", "--json", "--out", str(tmp_path / "out")])
    data = json.loads(capsys.readouterr().out)
    patch = data["patches"][0]
    assert code == 1 and patch["status"] == "warning", patch
    message = patch["message"]
    assert "estimated grid error above grid_tolerance 0.02 (2.00%)" in message and "contact area" in message
    grid = patch["diagnostics"]["grid_error"]
    assert 0.02 < grid["largest_relative"] == patch["diagnostics"]["grid_error_estimate"] < 0.1
    assert patch["diagnostics"]["dx_m"] == pytest.approx(1e-3) and grid["refinements"] == 0
    path.write_text(CASE + "element_size_m = 1e-3\ngrid_tolerance = 0.1\n")
    code = main(["contact", str(path), "--method", "bem", "--json", "--out", str(tmp_path / "out2")])
    data = json.loads(capsys.readouterr().out)
    assert code == 0 and data["success"] and data["patches"][0]["status"] == "ok", data


def test_shift_problem_through_the_cli(tmp_path, capsys):
    """A quadric case solved as Cattaneo's shift problem from the [solver] table, its friction from [friction]."""
    import json

    path = tmp_path / "case.toml"
    solver = 'nx = 24\nny = 24\nproblem = "shift"\nshift_long_m = 1e-3\n'
    solver += "grid_tolerance = 0.1\n"  # 24 x 24: area estimate ~3 %
    text = re.sub(r"friction_coefficient = [0-9.]+\n", "", CASE)
    path.write_text(text + solver + '[friction]\nlaw = "coulomb"\ncoefficient = 0.25\n')
    code = main(["contact", str(path), "--method", "bem", "--json", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 0, out
    data = json.loads(out)
    patch = data["patches"][0]
    # a shift of 1 mm is far beyond full slip: the force on the wheel is -mu F_N
    assert data["success"] and abs(patch["creep_force_long_N"] / -0.25e5 - 1) < 1e-6, patch


def test_withdrawn_kinetic_friction_coefficient(tmp_path, capsys):
    """The withdrawn option ends with one line naming its replacement (CONTACT v23.1 on: one coefficient)."""
    path = tmp_path / "case.toml"
    path.write_text(CASE + "kinetic_friction_coefficient = 0.25\n")
    code = main(["contact", str(path), "--method", "bem"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert "kinetic_friction_coefficient = 0.25: withdrawn" in err[0] and "[friction] table" in err[0], err


def test_transient_problem_through_the_cli(tmp_path, capsys):
    """problem = 'transient' from the [solver] table runs and reports a rising force (forces on the wheel)."""
    import json

    path = tmp_path / "case.toml"
    text = CASE.replace("creepage_long = 0.0", "creepage_long = 1e-3")
    path.write_text(text + 'nx = 12\nny = 12\nproblem = "transient"\ntransient_steps = 4\ngrid_tolerance = 0.5\n')
    code = main(["contact", str(path), "--method", "bem", "--json", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 0, out
    data = json.loads(out)
    assert data["success"] and data["patches"][0]["creep_force_long_N"] < 0


def test_printed_verdict_agrees_with_the_exit_status(capsys):
    """A BEM grid coarser than its tolerance: the printed table says warning (not ok) with the patch's message, the
    exit status is 1, and the JSON's patch status is "warning"."""
    import json

    code = main(["contact", "hertz-quadric", "--method", "bem", "--set", "solver.nx=20", "--set", "solver.ny=20"])
    out = capsys.readouterr().out
    assert code == 1 and out.startswith("method bem: warning - ") and "single: warning" in out, out
    code = main(["contact", "hertz-quadric", "--method", "bem", "--set", "solver.nx=20", "--set", "solver.ny=20",
                 "--json"])  # fmt: skip
    data = json.loads(capsys.readouterr().out)
    assert code == 1 and data["patches"][0]["status"] == "warning"
    assert main(["contact", "hertz-quadric", "--method", "bem"]) == 0
    assert capsys.readouterr().out.startswith("method bem: ok - ")
