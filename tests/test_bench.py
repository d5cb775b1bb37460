"""wheelrail bench on a tiny plan (two cases, cheap rungs): files, errors, tolerance table, bad input.

The error metrics are checked on synthetic numbers; the bench run itself is a smoke/regression test of the
driver (its physics is the models', verified in their own tests).
"""

import csv
import json
import math

import pytest

from comparisons import bench
from comparisons.bench import BenchRun, case_errors, pareto_front, tolerance_table
from wheelrail.cli import main
from wheelrail.named_cases import load_named_case


def test_case_errors_on_synthetic_numbers():
    named = load_named_case("creep-long-mid")
    ref = named.reference
    values = dict(ref)
    values["max_pressure_Pa"] = ref["max_pressure_Pa"] * 1.03
    values["creep_force_long_N"] = ref["creep_force_long_N"] * 0.9
    errors, headline = case_errors(named, values)
    assert errors["err_max_pressure"] == pytest.approx(0.03)
    assert errors["err_creep_force"] == pytest.approx(0.1)
    assert headline == pytest.approx(0.1)
    values["creep_force_lat_N"] = None  # a frictionless model meets no tolerance on a creep case
    assert case_errors(named, values)[1] is None


def test_pareto_front_and_tolerance_table():
    runs = [
        BenchRun("c", "s", "a", "-", "ok", "", 1e-3, error=0.2),
        BenchRun("c", "s", "b", "1", "ok", "", 1e-2, error=0.04),
        BenchRun("c", "s", "b", "2", "ok", "", 2e-2, error=0.05),
        BenchRun("c", "s", "c", "-", "ok", "", 1e-1, error=0.005),
        BenchRun("c", "s", "d", "-", "failed", "", 1e-4, error=None),
    ]
    assert [r.model + r.resolution for r in pareto_front(runs)] == ["a-", "b1", "c-"]
    table = tolerance_table(runs)["c"]
    assert table[0.10].resolution == "1" and table[0.05].resolution == "1"
    assert table[0.02].model == "c" and table[0.01].model == "c"


def test_tiny_bench_writes_csv_markdown_plots(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(bench.RESOLUTIONS, "bem", [("8x8", {"nx": 8, "ny": 8}), ("16x16", {"nx": 16, "ny": 16})])
    monkeypatch.setitem(bench.RESOLUTIONS, "fastsim", [("5x5", {"nx": 5, "ny": 5})])
    code = main(
        ["bench", "--cases", "hertz-ab-1", "creep-long-mid", "--models", "hertz", "vermeulen-johnson", "fastsim",
         "bem", "--out", str(tmp_path)]
    )  # fmt: skip
    assert code == 0
    rows = list(csv.DictReader(open(tmp_path / "bench.csv")))
    assert {r["model"] for r in rows} == {"hertz", "vermeulen-johnson", "fastsim", "bem"}
    # tangential rungs only where the reference has creep forces
    assert not [r for r in rows if r["case"] == "hertz-ab-1" and r["model"] == "fastsim"]
    assert all(r["status"] == "ok" for r in rows)
    hertz = next(r for r in rows if r["case"] == "hertz-ab-1" and r["model"] == "hertz")
    assert float(hertz["error"]) < 1e-9  # Hertz against its closed form
    summary = json.loads((tmp_path / "bench.json").read_text())
    assert summary["tolerance_table"]["hertz-ab-1"]["1%"]["model"] == "hertz"
    # printed status, JSON status and exit code agree (rows not ok are findings about their rung, counted)
    assert summary["status"] == "ok" and summary["runs_not_ok"] == 0
    text = (tmp_path / "bench.md").read_text()
    assert "Tolerance table" in text and "| creep-long-mid |" in text
    assert (tmp_path / "time_vs_error-creep-long-mid.png").stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "fastest within 5 %" in printed and "bench: status ok:" in printed


@pytest.mark.parametrize(
    "argv, match",
    [
        (["bench", "--cases", "nope"], "case 'nope': expected one of"),
        (["bench", "--models", "magic"], "--models 'magic': expected some of"),
        (["compare", "nope"], "case 'nope': expected one of"),
        (["compare", "hertz-ab-1", "--models", "linear2"], "--models 'linear2'"),
    ],
)
def test_bad_input_is_one_line_exit_2(argv, match, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error:") and match in err and "Traceback" not in err


def test_failed_run_is_a_status_not_a_number(monkeypatch):
    named = load_named_case("hertz-ab-1")

    def boom(*args, **kwargs):
        raise FloatingPointError("diverged")

    monkeypatch.setattr(bench, "solve_contact_case", boom)
    run = bench.run_one(named, "bem", "8x8", {})
    assert run.status == "error" and "diverged" in run.message and run.error is None and not run.values
    assert math.isnan(run.wall_time_s) or run.wall_time_s >= 0


def test_plots_one_style_per_rung_percent_axis_overview_and_front_over_answering_rungs(tmp_path):
    """The Pareto front leaves out a normal-contact rung (Hertz, 100 % on a creep case: no creep forces); every plot
    draws a rung in one colour and marker, the error axis in %, and an overview of all cases is written."""
    from PIL import Image

    from comparisons.style import RUNG_COLOURS

    hertz = BenchRun("creep", "s", "hertz", "-", "ok", "", 1e-5, errors={"err_creep_force": 1.0}, error=1.0)
    assert not bench.answers_question(hertz)
    assert bench.answers_question(BenchRun("hertz-case", "s", "hertz", "-", "ok", "", 1e-5, errors={}, error=0.0))
    runs = [
        hertz,
        BenchRun("creep", "s", "fastsim", "10x10", "ok", "", 1e-3, errors={"err_creep_force": 0.05}, error=0.05),
        BenchRun("creep", "s", "bem", "16x16", "ok", "", 1e-2, errors={"err_creep_force": 0.01}, error=0.01),
        BenchRun("other", "s", "bem", "16x16", "ok", "", 1e-2, errors={}, error=0.02),
    ]
    assert bench.plot_overview(runs, tmp_path / "overview.png")
    assert bench.plot_case(runs, "creep", tmp_path / "creep.png")
    for name in ("overview.png", "creep.png"):
        info = Image.open(tmp_path / name).info
        assert "%" in info["Description"] and "[s]" in info["Description"]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    bench._draw_case(ax, runs[:3], 1e-6, annotate=False)
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert lines["bem"].get_color() == RUNG_COLOURS["bem"]
    front = lines["Pareto front"]
    assert 1e-5 not in list(front.get_xdata())  # Hertz not on the front
    assert ax.yaxis.get_major_formatter()(0.05, 0) == "5 %"
    plt.close(fig)


def test_fea_on_a_creep_case_has_a_creep_status_its_normal_error_and_a_checked_stated_error(monkeypatch):
    """The FEA on a creep case: no creep-force number (a status), its error on N, p max and area against the
    reference, and its stated error checked against that error (synthetic FEA result, no solve)."""
    from rigid_dynamics.contact.types import ContactResult

    named = load_named_case("creep-long-mid")
    ref = named.reference

    def fake_solve(case, model, options):
        result = ContactResult(
            method="fea",
            success=True,
            normal_force_N=ref["normal_force_N"],
            creep_force_long_N=None,
            creep_force_lat_N=None,
            spin_moment_Nm=None,
            max_pressure_Pa=ref["max_pressure_Pa"] * 1.03,
            contact_area_m2=ref["contact_area_m2"] * 0.99,
            status="mesh-tolerance-not-met",
            message="",
            extra={"discretisation_error": {"relative_error": {"normal_force": 0.0, "max_pressure": 0.01,
                                                               "contact_area": 0.02}}},
        )  # fmt: skip
        return [("single", case.geometry, case.creepage, result)], True, ""

    monkeypatch.setattr(bench, "solve_contact_case", fake_solve)
    run = bench.run_one(named, "fea", "tol2%", {})
    assert run.status == "ok" and run.creep_status == f"{bench.FEA_CREEP_STATUS} (not-solved)"  # no reason given
    assert run.error is None  # it does not answer the case's creep-force question
    assert run.normal_error == pytest.approx(0.03)
    check = run.stated_check
    assert check["contact_area"]["holds"] and not check["max_pressure"]["holds"]  # 3 % > 1 % + the ref's own
    assert "UNDERSTATED (max pressure)" in bench._check_word(run)
    # the tolerance table's FEA column and the plots take it on its normal problem; the front does not
    fea_table = bench.fea_tolerance_table([run])
    assert fea_table["creep-long-mid"][0.05] is run and fea_table["creep-long-mid"][0.02] is None
    cell = bench._fea_cell([run], "creep-long-mid", fea_table["creep-long-mid"])
    assert cell.startswith("5 %: tol2%") and "creep forces: error-not-stated" in cell and "UNDERSTATED" in cell
    assert bench._plotted(run) and bench.pareto_front([run]) == []
    assert "(mesh-tolerance-not-met); creep forces error-not-stated" in bench._row_status(run)
    assert run.result_status == "mesh-tolerance-not-met" and "(mesh-tolerance-not-met)" in cell


def _fea_creep_result(ref, creep_force_long_N, tangential, relative_creep=None):
    """A synthetic FEA result on creep-long-mid: the reference's normal numbers, the given creep forces."""
    from rigid_dynamics.contact.types import ContactResult

    relative = {"normal_force": 0.0, "max_pressure": 0.01, "contact_area": 0.01}
    if relative_creep is not None:
        relative.update(creep_force_long=relative_creep, creep_force_lat=relative_creep)
    return ContactResult(
        method="fea", success=True, normal_force_N=ref["normal_force_N"], creep_force_long_N=creep_force_long_N,
        creep_force_lat_N=None if creep_force_long_N is None else 0.0, max_pressure_Pa=ref["max_pressure_Pa"],
        contact_area_m2=ref["contact_area_m2"], status="ok", message="",
        extra={"discretisation_error": {"relative_error": relative}, "tangential": tangential},
    )  # fmt: skip


@pytest.mark.parametrize(("stated", "holds"), [(0.05, True), (0.01, False)])
def test_fea_creep_forces_with_a_stated_error_are_judged_like_every_rung(monkeypatch, stated, holds):
    """The FEA's creep forces from its rolling series (fea.model "Creep forces"): no creep status, the creep error
    filled and in ``error``, the stated creep error in ``stated`` and checked (synthetic result, no solve)."""
    named = load_named_case("creep-long-mid")
    ref = named.reference
    result = _fea_creep_result(ref, ref["creep_force_long_N"] * 1.03, {"status": "ok", "message": ""}, stated)
    monkeypatch.setattr(bench, "solve_contact_case", lambda case, model, options: (
        [("single", case.geometry, case.creepage, result)], True, ""))  # fmt: skip
    run = bench.run_one(named, "fea", "tol5%", {})
    assert run.creep_status is None
    assert run.errors["err_creep_force"] == pytest.approx(0.03)
    assert run.error == pytest.approx(0.03) and run.normal_error == pytest.approx(0.0, abs=1e-12)
    assert run.stated_error == pytest.approx(max(stated, 0.01))
    check = run.stated_check["creep_force"]
    assert check["allowed"] == pytest.approx(stated + named.uncertainty["creep_force_long_N"])
    assert check["holds"] is holds
    assert ("UNDERSTATED (creep force)" in bench._check_word(run)) is not holds
    assert bench.tolerance_table([run])["creep-long-mid"][0.05] is run  # it answers the case's question
    cell = bench._fea_cell([run], "creep-long-mid", bench.fea_tolerance_table([run])["creep-long-mid"])
    assert "creep forces 3 %" in cell and "error-not-stated" not in cell
    assert "creep forces" not in bench._row_status(run)


def test_fea_creep_status_names_the_series_reason(monkeypatch):
    """An "unresolved" series (the slip zone narrower than a cell): creep forces None, the status with its reason."""
    named = load_named_case("creep-long-small")
    ref = named.reference
    tangential = {"status": "unresolved", "message": "creep forces None: series unresolved: ..."}
    result = _fea_creep_result(ref, None, tangential)
    monkeypatch.setattr(bench, "solve_contact_case", lambda case, model, options: (
        [("single", case.geometry, case.creepage, result)], True, ""))  # fmt: skip
    run = bench.run_one(named, "fea", "tol5%", {})
    assert run.creep_status == "error-not-stated (unresolved)" and run.error is None
    assert run.errors["err_creep_force"] is None and "creep_force" not in (run.stated_check or {})
    assert "creep forces error-not-stated (unresolved)" in bench._row_status(run)
