"""The named cases of comparisons/cases/ (one source of truth for bench, compare and these tests).

Independent checks of the stored references: the Hertz ellipses against the project's Hertz solver (itself
checked against a quadrature of Hertz's integrals, tests/test_hertz.py) -- the references were written from
scipy's elliptic integrals by a separate route (benchmarks/make_case_references.py); the small-creepage BEM
reference against Kalker's published linear coefficient; the saturated one against full slip (F = mu N); the
A-2.2 references against CONTACT's printed numbers (its runs at the deck's element against the published rows).
"""

import math

import numpy as np
import pytest
from hardening_helpers import quadric_case

from comparisons.named_cases import QUANTITIES, SOURCES, named_case_names
from rigid_dynamics.contact.hertz import hertz_solve_batch
from rigid_dynamics.contact.kalker import kalker_coefficients
from wheelrail.cases import parse_case
from wheelrail.config import ConfigError
from wheelrail.named_cases import load_named_case

NAMES = named_case_names()


def test_all_named_cases_are_there():
    expected = {
        "hertz-ab-0.1", "hertz-ab-1", "hertz-ab-10", "creep-long-small", "creep-long-mid", "creep-long-saturated",
        "creep-lat-spin", "creep-spin-only", "large-spin", "a22-tread", "a22-flange-root", "a22-flange",
        "worn-wheel-worn-rail", "wheel-flat", "corrugation",
    }  # fmt: skip
    assert expected <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_named_case_loads_with_reference_and_source(name):
    named = load_named_case(name)
    assert named.source in SOURCES
    assert (named.folder / "SOURCE.md").read_text().strip()
    assert {"normal_force_N", "max_pressure_Pa", "contact_area_m2"} <= set(named.reference)
    assert all(math.isfinite(v) for v in named.reference.values())
    assert named.case.kind in ("quadric", "wheelset")


@pytest.mark.parametrize("name", ["hertz-ab-0.1", "hertz-ab-1", "hertz-ab-10"])
def test_hertz_references_match_the_hertz_solver(name):
    named = load_named_case(name)
    g, mat = named.case.geometry, named.case.material
    h = hertz_solve_batch(
        np.array([g.curvature_long_1_per_m]),
        np.array([g.curvature_lat_1_per_m]),
        normal_force_N=np.array([named.case.normal_force_N]),
        shear_modulus_Pa=mat.shear_modulus_Pa,
        poisson_ratio=mat.poisson_ratio,
    )
    ref = named.reference
    assert float(h.semi_axis_long_m[0]) == pytest.approx(ref["semi_axis_long_m"], rel=1e-8)
    assert float(h.semi_axis_lat_m[0]) == pytest.approx(ref["semi_axis_lat_m"], rel=1e-8)
    assert float(h.max_pressure_Pa[0]) == pytest.approx(ref["max_pressure_Pa"], rel=1e-8)
    ratio = ref["semi_axis_long_m"] / ref["semi_axis_lat_m"]
    assert ratio == pytest.approx(float(name.split("-")[-1]), rel=1e-12)


def test_small_creepage_reference_agrees_with_kalkers_linear_theory():
    named = load_named_case("creep-long-small")
    c = named.case
    h = hertz_solve_batch(
        np.array([c.geometry.curvature_long_1_per_m]),
        np.array([c.geometry.curvature_lat_1_per_m]),
        normal_force_N=np.array([c.normal_force_N]),
        shear_modulus_Pa=c.material.shear_modulus_Pa,
        poisson_ratio=c.material.poisson_ratio,
    )
    a, b = float(h.semi_axis_long_m[0]), float(h.semi_axis_lat_m[0])
    c11 = float(kalker_coefficients(np.array([a / b]), c.material.poisson_ratio).c11[0])
    linear = -c.material.shear_modulus_Pa * a * b * c11 * c.creepage.longitudinal
    # the exact theory lies ~0.4 % below the linear one here; the BEM limit's own estimate is 0.8 %
    assert named.reference["creep_force_long_N"] == pytest.approx(linear, rel=0.015)


def test_saturated_reference_is_full_slip():
    named = load_named_case("creep-long-saturated")
    mu_n = named.case.material.friction_coefficient * named.reference["normal_force_N"]
    assert named.reference["creep_force_long_N"] == pytest.approx(-mu_n, rel=1e-3)


A22 = ("a22-tread", "a22-flange-root", "a22-flange")


def _contact_rows(path):
    import csv

    with open(path, newline="") as handle:
        return list(csv.DictReader(line for line in handle if not line.startswith("#")))


@pytest.mark.parametrize("name", A22)
def test_a22_contact_runs_at_the_decks_element_reproduce_the_published_solution(name):
    """CONTACT as run here (contact_grid.csv) at the deck's 0.2 mm equals its published row (contact_reference.csv):
    the refined runs are of the same program and deck."""
    folder = load_named_case(name).folder
    published = _contact_rows(folder / "contact_reference.csv")[0]
    row = next(r for r in _contact_rows(folder / "contact_grid.csv") if float(r["dx_mm"]) == 0.2)
    assert float(row["ds_mm"]) == 0.2
    for key in ("fn_N", "fx_N", "fs_N", "pmax_N_per_mm2", "ncon", "contact_area_mm2"):
        assert float(row[key]) == pytest.approx(float(published[key]), rel=1e-9), key


def test_a22_references_are_contacts_finest_element_on_the_wheel():
    """The reference is CONTACT's finest run (forces on the wheel: Fx = -FX, Fy = +FS), with the change over the
    last halving of the element as its own error (CONTACT's printed numbers, benchmarks/results/contact_grid.md)."""
    flange = load_named_case("a22-flange")
    assert flange.source == "contact-converged"
    ref, unc = flange.reference, flange.uncertainty
    assert ref["normal_force_N"] == 12730.0
    assert ref["creep_force_long_N"] == 2073.0
    assert ref["creep_force_lat_N"] == -3194.0
    assert ref["max_pressure_Pa"] == pytest.approx(2597e6)
    assert ref["contact_area_m2"] == pytest.approx(11885 * 0.025**2 * 1e-6, rel=1e-5)  # NCON dx ds
    assert unc["contact_area_m2"] == pytest.approx(7.5075 / 7.428125 - 1.0, rel=1e-4)  # 0.05 mm -> 0.025 mm
    assert unc["max_pressure_Pa"] == 5e-4  # 2596 -> 2597 MPa: below CONTACT's print resolution
    assert unc["normal_force_N"] == 5e-4  # unchanged
    for name in A22:
        named = load_named_case(name)
        assert set(named.uncertainty) == set(QUANTITIES)
        # the published 0.2 mm area lies above the finest by more than the finest's own error (first order)
        published = float(_contact_rows(named.folder / "contact_reference.csv")[0]["contact_area_mm2"]) * 1e-6
        assert published > named.reference["contact_area_m2"] * (1 + named.uncertainty["contact_area_m2"])


def test_contact_converged_case_needs_two_grids(tmp_path):
    import shutil

    folder = tmp_path / "one-grid"
    shutil.copytree(load_named_case("a22-flange").folder, folder)
    rows = (folder / "contact_grid.csv").read_text().splitlines()
    lines = [r for r in rows if not r.startswith("#")]
    (folder / "contact_grid.csv").write_text("\n".join([lines[0], lines[-1]]) + "\n")  # the finest row alone
    with pytest.raises(ConfigError, match="contact_grid.csv: .*expected the finest element and one of twice"):
        load_named_case(folder)


def test_flat_and_corrugation_give_a_sampled_gap_with_local_curvature():
    import tomllib

    case = parse_case(
        tomllib.loads(
            quadric_case(
                geometry_extra="corrugation_wavelength_m = 0.02\ncorrugation_amplitude_m = 1e-5", kinematics=False
            )
        )
    )
    g = case.geometry
    assert g.undeformed is not None and not g.is_elliptic
    # trough of the rail at x = 0: h'' = 1/r_w - A k^2 (r_w = 0.46 m, A = 10 um, k = 2 pi / 20 mm)
    k = 2 * math.pi / 0.02
    assert 2 * g.curvature_long_1_per_m == pytest.approx(1 / 0.46 - 1e-5 * k * k, rel=1e-3)


@pytest.mark.parametrize(
    "extra, match",
    [
        ('wheel_flat_shape = "new"', "without 'wheel_flat_length_m'"),
        ('wheel_flat_length_m = 0.05\nwheel_flat_shape = "square"', "wheel_flat_shape"),
        ("wheel_flat_length_m = -0.05", "wheel_flat_length_m"),
        ("corrugation_phase_rad = 1.0", "corrugation_phase_rad"),
        ("corrugation_wavelength_m = 0.02", "corrugation_amplitude_m"),
    ],
)
def test_bad_irregularity_keys_name_the_key(extra, match):
    import tomllib

    with pytest.raises(ConfigError, match=match):
        parse_case(tomllib.loads(quadric_case(geometry_extra=extra, kinematics=False)))


def test_unknown_named_case_lists_the_choices():
    with pytest.raises(ConfigError, match="expected one of .*hertz-ab-1"):
        load_named_case("no-such-case")


def test_bem_equals_contact_at_the_same_fine_element_on_the_flange():
    """Our BEM on CONTACT's deck (step 17) with CONTACT's 0.05 mm elements against CONTACT's own 0.05 mm run
    (contact_grid.csv): the grid dependence of the published numbers is CONTACT's and ours alike. Recorded: max
    pressure -0.15 %, area +0.03 %, FN -0.03 % (benchmarks/results/contact_grid.md)."""
    from comparisons.manchester import MATERIAL, a22_case
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case

    row = next(
        r for r in _contact_rows(load_named_case("a22-flange").folder / "contact_grid.csv") if r["dx_mm"] == "0.05"
    )
    options = {"model": {"element_size_m": 0.05e-3}, "sides": ("right",)}
    sol = solve_wheelset_case(a22_case(16, "deck"), MATERIAL, "bem", options)
    (patch,) = [p.result for p in sol.patches if p.side == "right"]
    assert patch.normal_force_N == pytest.approx(float(row["fn_N"]), rel=2e-3)
    assert patch.max_pressure_Pa == pytest.approx(float(row["pmax_N_per_mm2"]) * 1e6, rel=5e-3)
    assert patch.contact_area_m2 == pytest.approx(float(row["contact_area_mm2"]) * 1e-6, rel=5e-3)
    # and both lie 3.5 % below the published 0.2 mm area
    assert patch.contact_area_m2 < 0.97 * 7.96e-6
