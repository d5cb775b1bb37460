"""Creep-force sensitivities (rigid_dynamics.contact.sensitivities).

References:
* the analytic rungs (linear, vermeulen-johnson) against central differences of their own ``solve``, taken here
  with the test's own steps (an independent derivative of the same forces);
* Kalker (1990), Three-Dimensional Elastic Bodies in Rolling Contact, Table E.3, typed in below (a/b = 1,
  nu = 0.25: C11 = 4.12, C22 = 3.67, C23 = 1.47, C33 = 1.19): the slope at zero creepage of the linear rung is the
  table, of FASTSIM and the BEM it approaches the table as the grid refines (the grid error stated per test);
* the difference rungs (fastsim, fastrip, kpec, bem) against differences of their own ``solve`` at a third of the
  step: a consistency check of the step choice and of the stated error estimate (a regression test of one code
  path against a second use of it, not an independent reference).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.sensitivities import COLUMNS, ROWS, OperatingPoint, creep_sensitivities
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import Material

MAT = Material(82e9, 0.25, 0.3)
ROUND = ContactGeometry.quadric(0.46, 0.46)  # a/b = 1
OVAL = ContactGeometry.quadric(0.46, 0.30)
LOAD_N = 1e5
KALKER_ROUND_NU025 = {"c11": 4.12, "c22": 3.67, "c23": 1.47, "c33": 1.19}  # Table E.3, a/b = 1, nu = 0.25


def _solve_forces(name, point, column, value, options=None):
    c = point.creepage
    creep = [c.longitudinal, c.lateral, c.spin_1_per_m]
    normal = point.normal_force_N
    if column < 3:
        creep[column] = value
    else:
        normal = value
    r = get_model(name).solve(point.geometry, Creepage(*creep, c.rolling_speed_m_per_s), point.material,
                              normal_force_N=normal, options=options)  # fmt: skip
    assert r.success, r.message
    return np.array(
        [r.creep_force_long_N, r.creep_force_lat_N, np.nan if r.spin_moment_Nm is None else r.spin_moment_Nm]
    )


def _own_differences(name, point, steps, options=None):
    base = [point.creepage.longitudinal, point.creepage.lateral, point.creepage.spin_1_per_m, point.normal_force_N]
    jac = np.empty((3, 4))
    for j in range(4):
        plus = _solve_forces(name, point, j, base[j] + steps[j], options)
        minus = _solve_forces(name, point, j, base[j] - steps[j], options)
        jac[:, j] = (plus - minus) / (2 * steps[j])
    return jac


POINTS = {
    "zero": Creepage(0.0, 0.0, 0.0, 20.0),
    "small": Creepage(2e-4, -1e-4, 0.05, 20.0),
    "mid": Creepage(1e-3, -5e-4, 0.2, 20.0),
    "saturated": Creepage(6e-3, 2e-3, -0.3, 20.0),
}


@pytest.mark.parametrize("name", ["linear", "vermeulen-johnson"])
@pytest.mark.parametrize("where", list(POINTS))
def test_analytic_rungs_against_their_own_differences(name, where):
    """The closed forms against central differences of the rung's solve with steps 1e-7 (creepages), 1e-3 N (a
    smooth law: truncation ~1e-10 relative, rounding ~1e-8); agreement to 1e-5 of the largest entry of the row.
    """
    point = OperatingPoint(OVAL, POINTS[where], MAT, LOAD_N)
    s = creep_sensitivities(name, point)
    assert s.success and s.kind == "analytic"
    fd = _own_differences(name, point, [1e-8, 1e-8, 1e-6, 1.0])
    rows = 2 if name == "vermeulen-johnson" else 3
    for i in range(rows):
        scale = np.max(np.abs(s.jacobian[i, :3]))
        np.testing.assert_allclose(s.jacobian[i, :3], fd[i, :3], atol=1e-5 * scale, err_msg=f"{ROWS[i]} at {where}")
        np.testing.assert_allclose(s.jacobian[i, 3], fd[i, 3], rtol=1e-5, atol=1e-12, err_msg=f"{ROWS[i]} d/dN")
    if name == "vermeulen-johnson":
        assert np.all(np.isnan(s.jacobian[2]))  # no spin moment in the law


def test_vermeulen_johnson_beyond_saturation_is_the_friction_limit():
    """Beyond w' = 1 the force is mu N along the linear force: d|F|/dN = mu, d|F| along T = 0."""
    point = OperatingPoint(OVAL, Creepage(0.05, 0.0, 0.0, 20.0), MAT, LOAD_N)
    s = creep_sensitivities("vermeulen-johnson", point)
    assert s.jacobian[0, 0] == 0.0
    assert s.jacobian[0, 3] == pytest.approx(-MAT.friction_coefficient, rel=1e-12)


def test_linear_rung_at_zero_creepage_is_kalkers_table():
    point = OperatingPoint(ROUND, POINTS["zero"], MAT, LOAD_N)
    s = creep_sensitivities("linear", point)
    c = s.coefficients()
    for name in ("c11", "c22", "c23"):
        assert getattr(c, name) == pytest.approx(KALKER_ROUND_NU025[name], rel=1e-12)
    ab = s.semi_axis_long_m * s.semi_axis_lat_m
    assert -s.d("spin_moment_Nm", "spin_1_per_m") / (MAT.shear_modulus_Pa * ab * ab) == pytest.approx(1.19, rel=1e-12)
    assert s.d("spin_moment_Nm", "lateral") == pytest.approx(-s.d("creep_force_lat_N", "spin_1_per_m"), rel=1e-12)


def _observed_order(sizes, errors):
    """p of error ~ size^p, fitted over the refinements."""
    return float(np.polyfit(np.log(sizes), np.log(errors), 1)[0])


def test_fastsim_slope_at_zero_creepage_converges_to_kalker():
    """FASTSIM (three flexibilities) at zero creepage is Kalker's linear theory up to its midpoint quadrature:
    measured errors of c11 against Table E.3 at 10, 20, 40 elements: 0.50 %, 0.125 %, 0.031 % (order 2.0);
    c22 the same, c23 0.65 %, 0.15 %, 0.036 %.
    """
    point = OperatingPoint(ROUND, POINTS["zero"], MAT, LOAD_N)
    errors = {name: [] for name in ("c11", "c22", "c23")}
    grids = (10, 20, 40)
    for n in grids:
        s = creep_sensitivities("fastsim", point._replace(options={"nx": n, "ny": n}))
        assert s.success and s.kind == "central-difference"
        c = s.coefficients()
        for name in errors:
            errors[name].append(abs(getattr(c, name) / KALKER_ROUND_NU025[name] - 1))
    for name, e in errors.items():
        order = _observed_order([1 / n for n in grids], e)
        assert 1.8 < order < 2.3, f"{name}: errors {e}, order {order:.2f}"
        assert e[-1] < 5e-4, f"{name}: errors {e}"


def test_bem_slope_at_zero_creepage_converges_to_kalker():
    """The BEM's slope at zero creepage (the exact theory on a grid) against Table E.3 on 16, 32, 64 elements:
    measured errors of c11 4.5 %, 2.1 %, 1.2 %, of c22 5.2 %, 2.5 %, 1.4 %, of c23 0.6 %, 0.5 %, 0.04 %: the grid
    error of the slope is about 1 % at 64 x 64 and falls at order 1-1.5 (the contact edge cuts the elements).
    Extrapolated with the order observed on the three grids, c11 and c22 come within 1 % of the table (the table
    itself has three digits: 0.1-0.3 %).
    """
    point = OperatingPoint(ROUND, POINTS["zero"], MAT, LOAD_N)
    values = {name: [] for name in ("c11", "c22", "c23")}
    for n in (16, 32, 64):
        s = creep_sensitivities("bem", point._replace(options={"nx": n, "ny": n}))
        assert s.success, s.message
        for name in values:
            values[name].append(getattr(s.coefficients(), name))
    for name in ("c11", "c22"):
        v = values[name]
        err = [abs(x / KALKER_ROUND_NU025[name] - 1) for x in v]
        assert err[0] > err[1] > err[2] and err[2] < 0.02, f"{name}: {v}"
        ratio = (v[0] - v[1]) / (v[1] - v[2])
        order = math.log2(ratio)
        assert 0.8 < order < 2.0, f"{name}: {v}, order {order:.2f}"
        extrapolated = v[2] - (v[1] - v[2]) / (ratio - 1)
        assert extrapolated == pytest.approx(KALKER_ROUND_NU025[name], rel=0.01), f"{name}: {v}"
    assert values["c23"][2] == pytest.approx(KALKER_ROUND_NU025["c23"], rel=0.01)


DIFFERENCE_RUNGS = {
    "fastsim": None,
    "fastrip": None,
    "kpec": None,
    "bem": {"nx": 32, "ny": 32},
}


@pytest.mark.parametrize("name", list(DIFFERENCE_RUNGS))
@pytest.mark.parametrize("where", ["zero", "mid"])
def test_difference_rungs_consistent_with_a_third_of_the_step(name, where):
    """Regression/consistency: the sensitivities (steps 1e-4 x the creepage scale, the BEM 1e-3) against the rung's
    own central differences at a third of those steps; they agree within 3 x the stated error estimate plus 1e-3 of
    the row's largest entry (the rounding of the perturbed solves).
    """
    options = DIFFERENCE_RUNGS[name]
    point = OperatingPoint(OVAL, POINTS[where], MAT, LOAD_N, options)
    s = creep_sensitivities(name, point)
    assert s.success and s.kind == "central-difference", s.message
    assert s.solves == 17
    fd_options = {**options, "estimate_grid_error": False} if name == "bem" else options  # one grid, as the module
    fd = _own_differences(name, point, s.steps / 3.0, fd_options)
    for i in range(3):
        scale = np.max(np.abs(s.jacobian[i, :3]))
        tol = 3 * s.error_estimate[i, :3] + 1e-3 * scale
        assert np.all(np.abs(s.jacobian[i, :3] - fd[i, :3]) <= tol), (ROWS[i], s.jacobian[i], fd[i], tol)
        tol_n = 3 * s.error_estimate[i, 3] + 1e-3 * abs(s.jacobian[i, 3]) + 1e-9
        assert abs(s.jacobian[i, 3] - fd[i, 3]) <= tol_n, (ROWS[i], "d/dN", s.jacobian[i, 3], fd[i, 3])


def test_auto_uses_the_rung_it_chose():
    point = OperatingPoint(OVAL, POINTS["small"], MAT, LOAD_N)
    s = creep_sensitivities("auto", point)
    assert s.success and s.message.startswith("auto chose ")
    chosen = s.message.split()[2].rstrip(":")
    assert s.method == chosen


def test_no_contact_is_a_status_not_a_number():
    point = OperatingPoint(OVAL, POINTS["mid"], MAT, None)  # approach control, approach 0: no contact
    for name in ("linear", "fastsim"):
        s = creep_sensitivities(name, point)
        assert not s.success and s.status == "no-contact"
        assert np.all(np.isnan(s.jacobian))


def test_to_dict_names_rows_and_columns():
    s = creep_sensitivities("linear", OperatingPoint(OVAL, POINTS["mid"], MAT, LOAD_N))
    d = s.to_dict()
    assert list(d["jacobian"]) == list(ROWS) and list(d["jacobian"][ROWS[0]]) == list(COLUMNS)
    assert d["coefficients"]["f11_N"] == pytest.approx(-s.jacobian[0, 0])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"relative_step": 0.0}, "relative_step = 0.0: expected a number in"),
        ({"relative_step": 0.5}, "relative_step = 0.5"),
        ({"method": "forward"}, "method = 'forward': expected None"),
    ],
)
def test_bad_arguments_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        creep_sensitivities("linear", OperatingPoint(OVAL, POINTS["mid"], MAT, LOAD_N), **kwargs)


def test_analytic_asked_of_a_difference_rung_raises():
    with pytest.raises(ValueError, match="method = 'analytic': the rung 'fastsim' has no closed form"):
        creep_sensitivities("fastsim", OperatingPoint(OVAL, POINTS["mid"], MAT, LOAD_N), method="analytic")
    with pytest.raises(ValueError, match="contact model = 'nope'"):
        creep_sensitivities("nope", OperatingPoint(OVAL, POINTS["mid"], MAT, LOAD_N))
    with pytest.raises(ValueError, match="row = 'fx'"):
        creep_sensitivities("linear", OperatingPoint(OVAL, POINTS["mid"], MAT, LOAD_N)).d("fx", "lateral")


def test_cli_contact_sensitivities_json_is_the_api(capsys):
    import json

    from wheelrail.cases import load_case
    from wheelrail.cli import main

    assert main(["contact", "hertz-quadric", "--method", "vermeulen-johnson", "--sensitivities", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    patch = record["patches"][0]
    case = load_case("hertz-quadric")
    point = OperatingPoint(case.geometry, case.creepage, case.material, patch["normal_force_N"], case.solver_options)
    api = creep_sensitivities("vermeulen-johnson", point)
    assert patch["sensitivities"]["kind"] == "analytic" and record["status"] == "ok"
    for i, row in enumerate(ROWS):
        for k, column in enumerate(COLUMNS):
            value = patch["sensitivities"]["jacobian"][row][column]
            assert (value is None and math.isnan(api.jacobian[i, k])) or value == pytest.approx(api.jacobian[i, k])


def test_cli_contact_sensitivities_table(capsys):
    from wheelrail.cli import main

    assert main(["contact", "hertz-quadric", "--method", "fastsim", "--sensitivities"]) == 0
    out = capsys.readouterr().out
    assert "sensitivities   d/dxi [N]" in out and "single: fastsim central-difference (ok)" in out


def test_cli_contact_sensitivities_refuse_fea(capsys):
    from wheelrail.cli import main

    assert main(["contact", "hertz-quadric", "--method", "fea", "--sensitivities"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error: --sensitivities with --method 'fea'") and err.count("\n") == 1
