"""Creep-force tables (rigid_dynamics/contact/creep_table.py): the table against its source rung, against Kalker's
linear theory and Coulomb's bound, its cache, the compiled law, auto's rung and bad input.

The first test is a regression test of the interpolation against the rung it tabulates (two code paths of this
project: the table and FASTSIM at the same grid); the physics of FASTSIM itself is verified in tests/test_fastsim.py.
The limits and the closed forms checked independently: Kalker's linear theory F_x = -G a b C11 xi at small creepage,
Coulomb's |F| = mu N at full slip.
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

from rigid_dynamics.contact import creep_table as ct

SMALL_GRID = ct.TableGrid(9, 17, 9, 5, math.log(20.0))
"""A coarse grid for the cache and plumbing tests (built in well under a second)."""


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty table cache folder for the test (and the process memo emptied before and after)."""
    monkeypatch.setenv("WHEELRAIL_CACHE_DIR", str(tmp_path))
    ct._creep_table.cache_clear()
    yield tmp_path / "creep_tables"
    ct._creep_table.cache_clear()


@pytest.fixture(scope="module")
def full_table(tmp_path_factory):
    """The default table (GRID, FASTSIM 20 x 20) for nu = 0.28, built once for the module in a private cache."""
    folder = tmp_path_factory.mktemp("creep_cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("WHEELRAIL_CACHE_DIR", str(folder))
        ct._creep_table.cache_clear()
        built = ct.creep_table(0.28)
    ct._creep_table.cache_clear()
    return built


def test_table_against_fastsim_on_500_random_points(full_table):
    """Regression of the interpolation against its source (same grid, same kernels): 500 seeded points over |c*| in
    [0.01, 10], every direction, a/b in [0.1, 10], sqrt(ab) 2-15 mm, N 10-150 kN, mu 0.1-0.6. Measured (also in
    benchmarks/results/creep_table.md): max 1.8 %, rms 0.25 % of mu N for the creep force; max 1.9 %, rms 0.2 % of
    mu N sqrt(ab) for the spin moment.
    """
    sample = ct.sample_patches(500, 1, 0.28)
    errors = ct.compare_with_source(full_table.table, ct.SourceOptions(), sample, repeats=1)
    stated = (errors.max_force_error, errors.rms_force_error, errors.max_moment_error, errors.rms_moment_error)
    print("table vs FASTSIM: max, rms force / (mu N); max, rms moment / (mu N sqrt(ab)):", stated)
    assert errors.points == 500
    assert errors.max_force_error < 0.025 and errors.rms_force_error < 0.004, stated
    assert errors.max_moment_error < 0.03 and errors.rms_moment_error < 0.004, stated


def test_the_normalisation_removes_G_mu_N_and_size(full_table):
    """One normalised point at very different G, mu, N and patch size: the same normalised forces from the table and
    (within FASTSIM's own size dependence with spin, module docstring) from FASTSIM.
    """
    ranges = ct.SampleRanges(min_star=0.5, max_star=0.5, max_ratio=1.0000001)
    got = []
    for size, fn, mu, shear in ((3e-3, 2e4, 0.15, 7e10), (12e-3, 1.4e5, 0.5, 8.5e10)):
        ranges_i = ranges._replace(size_m=(size, size), normal_force_N=(fn, fn), friction=(mu, mu))
        ranges_i = ranges_i._replace(shear_modulus_Pa=shear)
        sample = ct.sample_patches(20, 7, 0.28, ranges_i)
        errors = ct.compare_with_source(full_table.table, ct.SourceOptions(), sample, repeats=1)
        assert errors.max_force_error < 0.02
        got.append(errors.force_error)
    assert np.max(np.abs(got[0] - got[1])) < 0.01


def test_small_creepage_gives_kalkers_linear_theory_and_full_slip_gives_mu_N(full_table):
    """Independent references: Kalker's linear theory F_x = -G a b C11 xi, F_y = -G a b C22 eta at small creepage
    (FASTSIM's three flexibilities reproduce them exactly as creepage -> 0), and Coulomb's |F| = mu N at full slip
    (FASTSIM 20 x 20 within 0.5 %, contact/models.py FRICTION_BOUND_TOLERANCE).
    """
    from rigid_dynamics.contact.kalker import kalker_coefficients

    shear, mu, fn = 8.2e10, 0.3, 1e5
    for ratio in (0.3, 1.0, 3.0):
        a, b = 6e-3 * math.sqrt(ratio), 6e-3 / math.sqrt(ratio)
        c = kalker_coefficients(np.array([ratio]), 0.28)
        patch = (a, b, float(c.c11[0]), float(c.c22[0]), float(c.c23[0]))
        xi = 0.002 * 3 * mu * fn / (shear * a * b * patch[2])  # xi* = 0.002
        fx, fy, _, inside = ct.table_creep_law(full_table.table, shear, patch, (xi, 0.0, 0.0), mu * fn)
        assert inside and fx == pytest.approx(-shear * a * b * patch[2] * xi, rel=0.02) and abs(fy) < 1e-3 * abs(fx)
        eta = 0.002 * 3 * mu * fn / (shear * a * b * patch[3])
        fx, fy, _, _ = ct.table_creep_law(full_table.table, shear, patch, (0.0, eta, 0.0), mu * fn)
        assert fy == pytest.approx(-shear * a * b * patch[3] * eta, rel=0.02)
        for direction in ((1.0, 0.0), (0.6, -0.8), (0.0, 1.0)):
            creep = (0.5 * direction[0], 0.5 * direction[1], 0.0)
            fx, fy, _, _ = ct.table_creep_law(full_table.table, shear, patch, creep, mu * fn)
            assert math.hypot(fx, fy) == pytest.approx(mu * fn, rel=0.006)
            # opposite to the creepage (FASTSIM's own force turns up to 7 degrees from it at creepage 0.5, a/b 0.3)
            assert (fx * direction[0] + fy * direction[1]) / math.hypot(fx, fy) < -0.99


def test_beyond_the_tables_ellipticity_the_source_serves():
    table = ct.build(0.28, grid=SMALL_GRID)
    fx, fy, mz, inside = ct.tabulated_forces(table, math.log(25.0), (0.1, 0.0, 0.0))
    assert not inside and (fx, fy, mz) == (0.0, 0.0, 0.0)
    assert ct.tabulated_forces(table, math.log(19.0), (0.1, 0.0, 0.0))[3]


def test_cache_builds_once_loads_and_rebuilds_a_bad_file(cache):
    first = ct.creep_table(0.28, grid=SMALL_GRID)
    assert first.status == "built" and first.path is not None and first.path.parent == cache
    assert [p.name for p in cache.iterdir()] == [first.path.name]  # no temporary file left (atomic write)
    assert ct.creep_table(0.28, grid=SMALL_GRID) is first  # the process's memo
    ct._creep_table.cache_clear()
    again = ct.creep_table(0.28, grid=SMALL_GRID)
    assert again.status == "hit" and np.array_equal(again.table.values, first.table.values)
    # another Poisson ratio or other source options: another key, another file
    other = ct.creep_table(0.3, ct.SourceOptions(nx=10, ny=10), grid=SMALL_GRID)
    assert other.path != first.path and len(list(cache.iterdir())) == 2
    first.path.write_bytes(b"not an npz file")
    ct._creep_table.cache_clear()
    rebuilt = ct.creep_table(0.28, grid=SMALL_GRID)
    assert rebuilt.status == "rebuilt" and "unreadable" in rebuilt.note
    assert np.array_equal(rebuilt.table.values, first.table.values)


def test_falling_friction_and_unknown_sources_are_refused():
    from rigid_dynamics.contact.friction import FrictionLaw, polach, uniform

    ct.check_friction(None)
    ct.check_friction(uniform(0.4))
    with pytest.raises(ct.TableUnavailable, match=r"friction law = 'exponential' \(falling with the slip velocity\)"):
        ct.check_friction(FrictionLaw((polach(0.5, 0.4, 0.6),)))
    with pytest.raises(ct.TableUnavailable, match=r"source = 'bem': expected one of fastsim"):
        ct.creep_table(0.28, ct.SourceOptions(source="bem"))


def test_the_compiled_law_is_the_static_models(full_table, monkeypatch):
    """The loop's law (compiled_laws.patch_forces with model_code LAW_TABLE) against the registry's ``table`` model on
    the same Hertz patch (regression: one interpolation, two callers); its departure from FASTSIM stated in extra.
    """
    import wheelrail as wr
    from rigid_dynamics.wheelset.compiled_laws import LAW_TABLE, hertz_kalker_tables, patch_forces, tables_for
    from rigid_dynamics.wheelset.layout import new_parameters

    monkeypatch.setattr(ct, "_creep_table", lambda nu, options, grid: full_table)
    creep_values = (1e-3, -5e-4, 0.4)
    geometry, creep = wr.ContactGeometry.quadric(0.46, 0.3), wr.Creepage(*creep_values)
    static = wr.get_model("table").solve(geometry, creep, wr.STEEL, normal_force_N=1e5)
    assert static.status == "ok" and static.extra["table_source"] == "fastsim 20x20"
    assert static.extra["table_departure"] < 0.01
    tables = tables_for(wr.STEEL.shear_modulus_Pa, wr.STEEL.poisson_ratio)
    par = new_parameters()
    par["shear_modulus_Pa"], par["contact_modulus_Pa"] = wr.STEEL.shear_modulus_Pa, tables.e_star
    par["friction_coefficient"], par["model_code"] = 0.3, LAW_TABLE
    par["fastsim_nx"] = par["fastsim_ny"] = 20
    hk = hertz_kalker_tables(tables, None, full_table.table)
    ca, cb = 0.5 / 0.46, 0.5 / 0.3
    q = static.approach_m
    normal, tx, ty, mz, a, b, to_callback = patch_forces(par, hk, q, ca, cb, *creep_values)
    assert not to_callback and normal == pytest.approx(1e5, rel=1e-5)
    assert (tx, ty) == pytest.approx((static.creep_force_long_N, static.creep_force_lat_N), rel=1e-4)
    assert mz == pytest.approx(static.spin_moment_Nm, rel=1e-4)


def test_auto_serves_its_fastsim_rung_from_the_table(full_table):
    """auto in the loop with par.auto_fastsim_table: where its choice is FASTSIM (boxes set so that only FASTSIM's
    holds the patch) the forces are the table's; without the flag FASTSIM's.
    """
    import wheelrail as wr
    from rigid_dynamics.wheelset.compiled_laws import (
        LAW_AUTO,
        LAW_FASTSIM,
        LAW_TABLE,
        hertz_kalker_tables,
        patch_forces,
        tables_for,
    )
    from rigid_dynamics.wheelset.layout import AUTO_FEATURE_NAMES, new_parameters

    tables = tables_for(wr.STEEL.shear_modulus_Pa, wr.STEEL.poisson_ratio)
    hk = hertz_kalker_tables(tables, None, full_table.table)
    par = new_parameters()
    par["shear_modulus_Pa"], par["contact_modulus_Pa"] = wr.STEEL.shear_modulus_Pa, tables.e_star
    par["friction_coefficient"], par["fastsim_nx"], par["fastsim_ny"] = 0.3, 20, 20
    par["auto_level"], par["auto_friction_bound_tolerance"] = 0.05, 0.01
    for f in AUTO_FEATURE_NAMES:
        par[f"auto_linear_{f}"] = par[f"auto_vermeulen_johnson_{f}"] = np.nan  # no box: FASTSIM's decides
        par[f"auto_fastsim_{f}"] = 10.0
    geometry = (2e-5, 0.5 / 0.46, 0.5 / 0.3)
    creep = (1e-3, -5e-4, 0.4)
    results = {}
    for flag, code in ((1.0, LAW_TABLE), (0.0, LAW_FASTSIM)):
        par["model_code"], par["auto_fastsim_table"] = LAW_AUTO, flag
        auto = patch_forces(par, hk, *geometry, *creep)
        par["model_code"] = code
        direct = patch_forces(par, hk, *geometry, *creep)
        assert auto[:4] == pytest.approx(direct[:4], rel=1e-12) and not auto[6]
        results[code] = auto
    assert results[LAW_TABLE][1] != results[LAW_FASTSIM][1]  # two different laws served


def test_a_dynamics_run_with_the_table_follows_fastsim():
    """polygonal-wheel (compiled 3-D search), 1 s, with contact_model "table" against "fastsim": after the settling
    distance the per-wheel contact forces part by less than 3 % of the static wheel load (measured 1.6 %, rms 0.3 %;
    in the start-up the two runs' two-point contact flips part them by up to 98 % over t = 0.1-0.27 s, as the step does,
    benchmarks/results/step_sensitivity.md), over the last 0.3 s by less than 0.2 %; on the table run's own settled
    patches the table departs from FASTSIM by less than 0.5 % of the wheel load (the run's statement,
    discretisation.contact_grid_error).
    """
    from rigid_dynamics.wheelset.compiled_laws import LAW_TABLE
    from rigid_dynamics.wheelset.discretisation import contact_grid_error
    from rigid_dynamics.wheelset.simulate import simulate
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = dataclasses.replace(load_scene(resolve_scene_path("polygonal-wheel")), duration_s=1.0)
    fs = simulate(dataclasses.replace(scene, contact_model="fastsim"), compiled=True, companions=False)
    tb = simulate(dataclasses.replace(scene, contact_model="table"), compiled=True, companions=False)
    assert fs.status == tb.status == "ok" and tb.contact_model == "table"
    departure = np.max(np.abs(tb.contact_force_N - fs.contact_force_N), axis=(1, 2)) / scene.static_wheel_load_N
    print("settled max, last 0.3 s max:", departure[tb.settled].max(), departure[tb.t > 0.7].max())
    assert departure[tb.settled].max() < 0.03 and departure[tb.t > 0.7].max() < 0.002
    codes = tb.patches["contact_law_code"]
    assert np.all(codes[np.isfinite(codes)] == LAW_TABLE)
    stated = contact_grid_error(tb)
    assert stated["table_departure"] is not None and stated["table_departure"] < 0.005, stated


@pytest.mark.parametrize(
    ("sets", "pattern"),
    [
        (["contact_model=table"], r"key 'contact_model' = 'table': expected Coulomb friction \(\[friction\] law"),
        (["contact_model=auto", "creep_table=true"], r"key 'creep_table' = True: expected Coulomb friction"),
    ],
)
def test_falling_friction_scene_with_the_table_exits_2(capsys, sets, pattern):
    from wheelrail.cli import main

    args = ["run", "braking-slide"]
    for s in sets:
        args += ["--set", s]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert re.search(pattern, err), err


@pytest.mark.parametrize(
    ("sets", "pattern"),
    [
        (["creep_table=true"], r"key 'creep_table' = True: expected false with contact_model 'fastsim'"),
        (["contact_model=auto", "creep_table=2"], r"key 'creep_table' = 2: expected true or false"),
    ],
)
def test_bad_creep_table_key_exits_2(capsys, sets, pattern):
    from wheelrail.cli import main

    args = ["run", "curve"]
    for s in sets:
        args += ["--set", s]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error: ") and err.count("\n") == 1 and re.search(pattern, err), err


def test_a_case_with_falling_friction_and_the_table_exits_2(tmp_path, capsys):
    from wheelrail.cli import main

    path = tmp_path / "case.toml"
    path.write_text(
        "[material]\nshear_modulus_Pa = 82e9\npoisson_ratio = 0.28\n"
        '[geometry]\nkind = "quadric"\nradius_long_m = 0.46\nradius_lat_m = 0.3\n[loading]\nnormal_force_N = 1e5\n'
        "[kinematics]\ncreepage_long = 0.001\ncreepage_lat = 0.0\nspin_creepage_1_per_m = 0.0\n"
        'rolling_speed_m_per_s = 20.0\n[friction]\nlaw = "exponential"\nkinetic = 0.14\nterm_1 = 0.19\n'
        "half_velocity_1_m_per_s = 1.25\n"
    )
    assert main(["contact", str(path), "--method", "table"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error: ") and err.count("\n") == 1
    assert "friction law = 'exponential' (falling with the slip velocity)" in err and "Coulomb" in err


@pytest.mark.parametrize(
    ("option", "pattern"),
    [
        ("solver.source=bem", r"key 'solver.source' = 'bem': expected one of 'fastsim' \(option of the contact model"),
        ("solver.nx=0", r"key 'solver.nx' = 0: expected an integer from 1 to 1000"),
    ],
)
def test_bad_table_option_exits_2(capsys, option, pattern):
    from wheelrail.cli import main

    assert main(["contact", "hertz-quadric", "--method", "table", "--set", option]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error: ") and err.count("\n") == 1 and re.search(pattern, err), err
