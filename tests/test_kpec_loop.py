"""The compiled KPEC law in the dynamics loop (compiled_laws._kpec_law on the gap compiled_patch.py samples).

* Regression (two code paths of ours): at a held pose of ``curve-flange`` (3-D search, flange contact on the left
  wheel) the loop's forces, area and max pressure per patch equal the static ``kpec`` model (semi_hertzian.KpecModel)
  solved on the same sampled gap, grid and creepages (Kalker's C_ij: the loop's tables, relative error < 1e-7).
* Against CONTACT's own KPEC (tests/data/contact_kpec, its ``mbench_a22_kpec`` example, as tests/test_kpec_contact.py):
  the loop's compiled law on the gap of the wheelset case's patch at CONTACT's poses (the same 0.2 mm grid), to the
  static test's tolerances. This checks the law the loop runs; the loop's own grid (kpec_points over the fitted box)
  is coarser than CONTACT's, its effect is measured in benchmarks/results/kpec_loop.md.
* A short ``wheelrail run curve-flange --set contact_model="kpec"`` records sampled patches with a finite
  ellipticity residual; the flange patch's area and max pressure differ from patch_geometry="ellipse".
"""

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rigid_dynamics.contact.semi_hertzian import KpecModel
from rigid_dynamics.contact.types import ContactGeometry, Creepage, UndeformedDistance
from rigid_dynamics.wheelset import compiled_rhs
from rigid_dynamics.wheelset import layout as lay
from rigid_dynamics.wheelset.compiled_laws import LAW_KPEC, _kpec_law, hertz_kalker_tables, tables_for
from rigid_dynamics.wheelset.compiled_patch import patch_scratch
from rigid_dynamics.wheelset.layout import new_parameters
from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel
from wheelrail.scenes import load_scene

ROOT = Path(__file__).resolve().parents[1]
# the flange-contact pose of tests/test_search_flange.py (curve-flange: left wheel on its flange root)
POSE = (1.277976414642136, -0.006342631482373633, -0.4602028328462104, -0.009009176923680725, 7.54273503739788e-4,
        2.7759919663658916)  # fmt: skip


def _static_kpec(xs, ys, gap, creepage, material):
    """The static KpecModel on the loop's grid: element centres xs, ys, the gap at them."""
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    area = (xs[0] - 0.5 * dx, xs[-1] + 0.5 * dx, ys[0] - 0.5 * dy, ys[-1] + 0.5 * dy)
    und = UndeformedDistance(x_m=xs.copy(), y_m=ys.copy(), distance_m=gap.copy(), potential_area_m=area)
    q = -float(gap.min())
    geometry = ContactGeometry(curvature_long_1_per_m=1.0, curvature_lat_1_per_m=1.0, approach_m=q, undeformed=und)
    return KpecModel().solve(geometry, creepage, material, options={"nx": xs.size, "ny": ys.size})


def _loop_law_on(sampled, material, approach_m, creep):
    """The loop's compiled KPEC law (compiled_laws._kpec_law) on a given sampled gap: sampled = (xs, ys, gap) (element
    centres, m; gap (ny, nx), m), the approach and creep = (xi, eta, phi); its (N, a, b, T_x, T_y, M_z, area, p_max).
    """
    xs, ys, gap = sampled
    par = new_parameters()
    g, nu = material.shear_modulus_Pa, material.poisson_ratio
    par["shear_modulus_Pa"], par["contact_modulus_Pa"] = g, g / (1 - nu)
    par["friction_coefficient"] = material.friction_coefficient
    par["kpec_nx"], par["kpec_ny"] = xs.size, ys.size
    field = patch_scratch(par, 1)
    field.xs[0], field.ys[0], field.gap[0], field.sampled[0] = xs, ys, gap, 1.0
    tables = hertz_kalker_tables(tables_for(g, nu))
    return _kpec_law(par, tables, field, 0, (approach_m, 1.0, 1.0, 0.0), creep, material.friction_coefficient)


@pytest.fixture(scope="module")
def held():
    scene = replace(load_scene("curve-flange"), contact_model="kpec", contact_provider="search")
    model = WheelsetModel(scene, build_provider(scene), get_contact_model("kpec"))
    return scene, model.packed, None


def test_regression_loop_kpec_equals_static_kpec_on_the_sampled_gap(held):
    """At the held flange-contact pose: the patches of one compiled right-hand side (compiled_rhs.contact_once, the
    loop's own evaluation, kernels compiled at setup) against the static KpecModel on the gap the loop's sampler
    (compiled_patch.sample_candidates, which _rhs calls for KPEC) gives for that evaluation's candidate geometry,
    state and rotation: forces, area and max pressure to 1e-9 (forces 1e-6 mu N) on >= 2 sampled patches, one on the
    flange (contact angle > 0.5 rad). Were the loop's law served another gap than the sampler's, they would differ.
    Until 2026-11-30 the gap came from compiled_rhs.patches_once (the workspace's copy), a test-only entry point that
    compiled the whole right-hand side again in every clean clone (24-55 s; this test was its only caller, and it was
    removed): the same claim, now checked in about 3 s.
    """
    from rigid_dynamics.wheelset.compiled_patch import sample_candidates

    scene, run, _ = held
    from rigid_dynamics.wheelset.equilibrium import initial_state
    from rigid_dynamics.wheelset.state import n_states

    y = np.zeros(n_states(int(run.par["track_positions"])))  # the full state of the compiled right-hand side
    y[:12] = initial_state(scene)  # the run's start (rolling velocities)
    y[:6] = POSE
    ncand = run.sides.shape[0]
    rec = np.zeros((ncand + 2, lay.N_FIELDS))
    cg = np.zeros((ncand, lay.N_GEO))
    field = patch_scratch(run.par, ncand)
    out = np.zeros_like(y)
    assert compiled_rhs.contact_once(0.0, y, run, out, rec, cg) == lay.OK
    sample_candidates(y, run, cg, field, np.zeros(3))  # the sampled gaps of this evaluation (3-vector: scratch)
    material = scene.material
    checked = 0
    for c in range(ncand):
        if not rec[c, lay.NORMAL_FORCE] > 0:
            continue
        assert rec[c, lay.PATCH_GEOMETRY] == lay.PATCH_SAMPLED and rec[c, lay.CONTACT_LAW] == LAW_KPEC
        assert math.isfinite(rec[c, lay.ELLIPTICITY_RESIDUAL])
        creep = Creepage(rec[c, lay.CREEPAGE_LONG], rec[c, lay.CREEPAGE_LAT], rec[c, lay.SPIN_CREEPAGE], 10.0)
        res = _static_kpec(field.xs[c], field.ys[c], field.gap[c], creep, material)
        assert res.success
        assert rec[c, lay.NORMAL_FORCE] == pytest.approx(res.normal_force_N, rel=1e-9)
        assert rec[c, lay.CONTACT_AREA] == pytest.approx(res.contact_area_m2, rel=1e-9)
        assert rec[c, lay.MAX_PRESSURE] == pytest.approx(res.max_pressure_Pa, rel=1e-9)
        mu_n = material.friction_coefficient * res.normal_force_N
        assert abs(rec[c, lay.CREEP_FORCE_LONG] - res.creep_force_long_N) < 1e-6 * mu_n
        assert abs(rec[c, lay.CREEP_FORCE_LAT] - res.creep_force_lat_N) < 1e-6 * mu_n
        assert abs(rec[c, lay.SPIN_MOMENT] - res.spin_moment_Nm) < 1e-6 * mu_n * 0.01
        checked += 1
    assert checked >= 2
    assert max(rec[c, lay.CONTACT_ANGLE] for c in range(ncand) if rec[c, lay.NORMAL_FORCE] > 0) > 0.5


@pytest.fixture(scope="module")
def contact_cases():
    """The wheelset case's patches at CONTACT's mbench_a22_kpec poses (tests/test_kpec_contact.py's runs)."""
    from test_kpec_contact import OPTIONS, STEP_OF_CASE

    from comparisons.manchester import MATERIAL, a22_case
    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case

    track = build_track(a22_case(0, "deck"))  # the deck's SMOOTH = 0, as tests/test_kpec_contact.py
    out = {}
    for case, step in STEP_OF_CASE.items():
        sol = solve_wheelset_case(a22_case(step, "deck"), MATERIAL, "kpec", OPTIONS, track=track)
        out[case] = [p for p in sol.patches if p.side == "right"]
    return MATERIAL, out


@pytest.mark.parametrize("case", [1, 2, 3])
def test_loop_kpec_law_equals_contacts_kpec(contact_cases, case):
    """The loop's compiled KPEC law on the gap of the wheelset case's patch (CONTACT's 0.2 mm grid, the same
    creepages) against CONTACT's printed KPEC output, at tests/test_kpec_contact.py's tolerances per case (F_N,
    p_max, area relative; F_x, F_s in mu F_N).
    """
    from test_kpec_contact import TOLERANCES, _reference

    material, cases = contact_cases
    ref = {k: float(v) for k, v in _reference()[case].items() if k != "method" and v != ""}
    (patch,) = cases[case]
    res, geo = patch.result, patch.geometry
    xs, ys = np.asarray(res.fields.x_m, float), np.asarray(res.fields.y_m, float)
    gap = np.asarray(geo.gap_m(*np.meshgrid(xs, ys)), float)
    gap = np.where(np.isfinite(gap), gap, 1.0)
    cr = patch.creepage
    fn, _, _, fx, fy, _, area, pmax = _loop_law_on(
        (xs, ys, gap), material, geo.approach_m, (cr.longitudinal, cr.lateral, cr.spin_1_per_m)
    )
    mu_fn = material.friction_coefficient * ref["fn_N"]
    diffs = {
        "fn": fn / ref["fn_N"] - 1,
        "pmax": pmax / (ref["pmax_N_per_mm2"] * 1e6) - 1,
        "area": area / (ref["contact_area_mm2"] * 1e-6) - 1,
        "fx": (fx + ref["fx_N"]) / mu_fn,
        "fs": (fy - ref["fs_N"]) / mu_fn,
    }
    bad = {k: v for k, v in diffs.items() if abs(v) > TOLERANCES[case][k]}
    assert not bad, (case, diffs)
    # and the static rung on the same patch to round-off (the law is the same)
    assert fn == pytest.approx(res.normal_force_N, rel=1e-9)
    assert abs(fx - res.creep_force_long_N) < 1e-6 * mu_fn and abs(fy - res.creep_force_lat_N) < 1e-6 * mu_fn


def _cli_run(tmp_path, name, *sets):
    from wheelrail.cli import main

    out = tmp_path / name
    args = ["run", "curve-flange", "--set", 'contact_model="kpec"', "--set", "duration_s=0.2", "--quiet", "--no-plots"]
    for item in sets:
        args += ["--set", item]
    assert main([*args, "--out", str(out)]) == 0
    with np.load(out / "timeseries.npz") as data:
        return {k: data[k] for k in data.files}


def test_cli_curve_flange_kpec_records_sampled_flange_patches(tmp_path):
    """``wheelrail run curve-flange --set contact_model="kpec"`` (0.2 s: the left wheel reaches its flange root by
    0.14 s): every patch in contact is sampled (patch_geometry_code 1) and served by KPEC, with a finite ellipticity
    residual on the flange patch (contact angle > 0.4 rad); with patch_geometry="ellipse" the same law sees the
    quadric, and the flange patch's area and max pressure differ (the message prints by how much).
    """
    sampled = _cli_run(tmp_path, "sampled")
    ellipse = _cli_run(tmp_path, "ellipse", 'patch_geometry="ellipse"')
    assert str(sampled["status"]) == "ok" and str(ellipse["status"]) == "ok"
    stats = {}
    for label, data, code in (("sampled", sampled, lay.PATCH_SAMPLED), ("ellipse", ellipse, lay.PATCH_ELLIPSE)):
        force = data["patch_normal_force_N"]
        on = force > 0
        assert np.all(data["patch_patch_geometry_code"][on] == code)
        assert np.all(data["patch_contact_law_code"][on] == LAW_KPEC)
        flange = on & (data["patch_contact_angle_rad"] > 0.4) & (data["t"][:, None, None] >= 0.15)
        assert flange.sum() >= 5, label
        if label == "sampled":
            assert np.all(np.isfinite(data["patch_ellipticity_residual"][flange]))
        else:
            assert np.all(np.isnan(data["patch_ellipticity_residual"][on]))
        stats[label] = (
            float(np.mean(data["patch_contact_area_m2"][flange])),
            float(np.mean(data["patch_max_pressure_Pa"][flange])),
            float(np.median(data["patch_ellipticity_residual"][flange])),
        )
    (a_s, p_s, r_s), (a_e, p_e, _) = stats["sampled"], stats["ellipse"]
    message = (
        f"flange patch (t >= 0.15 s, mean): sampled area {a_s * 1e6:.1f} mm^2, p_max {p_s / 1e6:.0f} MPa "
        f"(residual median {r_s:.2f}); ellipse area {a_e * 1e6:.1f} mm^2, p_max {p_e / 1e6:.0f} MPa; "
        f"area {a_s / a_e - 1:+.1%}, p_max {p_s / p_e - 1:+.1%}"
    )
    print(message)
    assert abs(a_s / a_e - 1) > 0.01 or abs(p_s / p_e - 1) > 0.01, message


def _no_pressure_gap():
    """A gap the loop sampled on curve-flange with the frame held at -12.5 mrad (suspension.frame_yaw_rad, kx 3e7 N/m,
    kpec, 0.1 ms), t = 0.141 s, left wheel: a deep narrow overlap (-24.8 um) on the row next to grid rows whose normal
    misses a profile (FAR_GAP, 1e6 m) and a shallow wide one below it. KPEC's equivalent ellipse then puts the deepest
    row outside itself (eps = 0): the deepest element alone is flagged, on a strip of zero length.
    """
    data = np.load(ROOT / "tests" / "data" / "kpec_no_pressure_gap.npz")
    return data["x_m"], data["y_m"], data["gap_m"]


def test_kpec_puts_no_contact_flag_without_pressure_and_fails_on_an_overlapping_gap():
    """Before 2026-11-30 the element on the zero-length strip was flagged in contact with zero pressure: the law
    went on with F_N = 0 into the flexibilities and the compiled loop died of a ZeroDivisionError (the run ended
    'solver-failed: ZeroDivisionError'). Now an element is in the contact area only where it carries pressure, the
    static rung ends 'no-pressure' (success False, no number) and the loop's law returns NaN, which
    compiled_rhs turns into layout.GAP_LAW_FAILED ('contact-failed', named)."""
    from rigid_dynamics.contact.kpec import kpec_pressure

    xs, ys, gap = _no_pressure_gap()
    assert gap.min() < -2e-5
    p, c = np.zeros(gap.shape), np.zeros(gap.shape, np.bool_)
    force = kpec_pressure(gap, xs, ys, 82e9, 0.28, p, c)[0]
    assert force == 0.0 and not c.any() and not p.any()
    # the static rung fits its own grid to the overlap (where this gap gives pressure); its branch for the same
    # outcome, a kernel that flags nothing on an overlapping gap, ends 'no-pressure' with no number
    material = load_scene("curve-flange").material

    class Degenerate(KpecModel):
        def _normal(self, h, x, y, g_mod, nu, p, contact):
            out = super()._normal(h, x, y, g_mod, nu, p, contact)
            p[...], contact[...] = 0.0, False
            return out

    geometry = ContactGeometry.quadric(0.46, 0.3, approach_m=5e-5)
    res = Degenerate().solve(geometry, Creepage(1e-3, -2e-3, 0.5, 10.0), material)
    assert not res.success and res.status == "no-pressure" and "put pressure on no element" in res.message
    assert math.isnan(res.normal_force_N)
    # the loop's law
    out = _loop_law_on((xs, ys, gap), material, -float(gap.min()), (1e-3, -2e-3, 0.5))
    assert math.isnan(out[0])
    assert lay.STATUS[lay.GAP_LAW_FAILED][0] == "contact-failed"


def test_kpec_contact_flags_are_the_elements_with_pressure(held):
    """On the loop's sampled gaps at the held flange pose the contact area (flags) is where the pressure is > 0."""
    from rigid_dynamics.contact.kpec import kpec_pressure
    from rigid_dynamics.wheelset.compiled_patch import sample_candidates
    from rigid_dynamics.wheelset.equilibrium import initial_state
    from rigid_dynamics.wheelset.state import n_states

    scene, run, _ = held
    y = np.zeros(n_states(int(run.par["track_positions"])))
    y[:12] = initial_state(scene)
    y[:6] = POSE
    ncand = run.sides.shape[0]
    rec, cg = np.zeros((ncand + 2, lay.N_FIELDS)), np.zeros((ncand, lay.N_GEO))
    field = patch_scratch(run.par, ncand)
    assert compiled_rhs.contact_once(0.0, y, run, np.zeros_like(y), rec, cg) == lay.OK
    sample_candidates(y, run, cg, field, np.zeros(3))
    checked = 0
    for c in range(ncand):
        if field.sampled[c] > 0:
            gap = field.gap[c]
            p, flags = np.zeros(gap.shape), np.zeros(gap.shape, np.bool_)
            kpec_pressure(
                gap, field.xs[c], field.ys[c], scene.material.shear_modulus_Pa, scene.material.poisson_ratio, p, flags
            )
            assert flags.any() and np.array_equal(flags, p > 0)
            checked += 1
    assert checked >= 2


def test_a_kpec_run_that_meets_such_a_gap_ends_contact_failed_in_print_json_and_exit_code(tmp_path, capsys):
    """The run the gap above came from (curve-flange, the frame held at -12.5 mrad, kx 3e7 N/m, 0.1 ms): it stops with
    the named status (at about 0.10 s here, within 0.3 s); printed status, summary.json's status and the exit code
    agree.
    """
    import json

    from wheelrail.cli import main

    out = tmp_path / "run"
    code = main(
        [
            "run", "curve-flange", "--set", 'contact_model="kpec"', "--set", "suspension.frame_yaw_rad=-0.0125",
            "--set", "suspension.longitudinal_stiffness_N_per_m=3e7", "--set", "integrator.fixed_step_s=1e-4",
            "--set", "duration_s=0.3", "--out", str(out),
        ]
    )  # fmt: skip
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "contact-failed" and "KPEC put pressure on no element" in summary["message"]
    assert printed.startswith("curve-flange: contact-failed - ") and code == 1
    assert 0.05 < summary["simulated_time_s"] < 0.3
