"""The record of a formed patch (issue 28): a gap-solving model's patches formed as CONTACT's module 1 forms them
(rigid_dynamics/wheelset/formed_patches.py) are recorded in their own plane, while the loop applies the same forces
as before (in the candidate's frame).

Reference: CONTACT (E.A.H. Vollebregt, J.J. Kalker; Apache-2.0, revision 2707), module 1, planar contact approach,
at curve-flange's state with the loop's kinematics (tests/data/contact_curve_flange/left_planar_curve.out; SOURCE.md
there, benchmarks/results/curve_flange_contact.md). CONTACT's flange-root patch lies in the plane at 0.8124 rad
with FN 120.3 kN and a creep force of 0.81 mu FN (F_s 29.25, F_x -1.53 kN on the rail); the compiled candidate's
plane is at 0.554 rad, where the same force reads as a lateral creep force of -2.40 kN.

At the state (the loop's contact, ``WheelsetModel.contact(...).record``), recorded against CONTACT's planar patch:
contact angle 0.8124 against 0.8124 rad, FN 117.81 against 120.3 kN (-2.1 %), F_s 28.66 against 29.25 kN (1.6 % of
mu FN), F_x 2.33 against 1.53 kN (2.2 % of mu FN), creep force 0.812 against 0.812 mu FN, reference point y 0.3 um
apart, approach 109.93 against 112.24 um (-2.1 %), creepages eta -0.007304 against -0.007264, spin -1.5740 against
-1.562 1/m, xi -0.002503 against -0.00248. Tolerances as tests/test_contact_curve_flange.py's loop test (3 % on FN
and the approach, 3 % of mu FN on the creep forces: CONTACT's planar gap is 2.3 um deeper than ours at the same
pose, and its grid 0.2 mm against the loop's 0.35 mm), 0.005 rad on the angle, 0.2 mm on the point, 1 % on eta and
the spin (0.5-0.8 % is the speed they are divided by: our |v_p|, CONTACT's mean rolling speed), 1e-4 on xi.

In a run (2 ms, RK4, the formed patches of curve-flange's flange root) the record holds the formed plane (0.787
rad at t = 0, the run's own equilibrium sits 15 um lower than CONTACT's deck) and a creep force of 0.815 mu N;
the wheel's contact force (main frame) is the record's own-frame force turned by its contact angle, and is the run's
of before the record changed (regression against the values written by the parent commit, 9bc4443: states and
wheel forces bit-identical there, compared here to 1e-10).
"""

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rigid_dynamics.materials import Material

DATA = Path(__file__).parent / "data" / "contact_curve_flange"
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))

from contact_out import read_out  # noqa: E402
from make_contact_curve_flange import STATE  # noqa: E402

MU = Material(shear_modulus_Pa=82.0e9, poisson_ratio=0.28, friction_coefficient=0.3).friction_coefficient


def _frame(angle_rad: float, side: int) -> np.ndarray:
    """Columns e_x, e_y, n (on the wheel) of a formed patch's plane at its contact angle (wheel_patches' frame for
    the rolling direction x)."""
    sgn = -1.0 if side == 1 else 1.0
    n = np.array([0.0, sgn * math.sin(angle_rad), -math.cos(angle_rad)])
    e_x = np.array([1.0, 0.0, 0.0])
    return np.stack([e_x, np.cross(n, e_x), n], -1)


@pytest.fixture(scope="module")
def at_state():
    """The loop's contact (BEM, patches formed) at CONTACT's deck state, and the model."""
    from loop_helpers import curve_flange_bem_at

    model, state = curve_flange_bem_at(STATE)
    return model, state, model.contact(state, record=True, keep_search_memory=True)


def _left(contact) -> int:
    (k,) = np.flatnonzero((contact.side == 0) & (np.nan_to_num(contact.values["normal_force_N"]) > 0))
    return int(k)


def test_formed_flange_root_record_is_contacts_planar_patch(at_state):
    _, _, contact = at_state
    ref = read_out(DATA / "left_planar_curve.out")[0]
    patch = ref["patches"][0]
    k = _left(contact)
    record = {name: float(v[k]) for name, v in contact.record.items()}
    mu_fn = MU * patch["FN"]
    assert record["contact_angle_rad"] == pytest.approx(patch["DELTCP(TR)"], abs=0.005)
    assert record["normal_force_N"] == pytest.approx(patch["FN"], rel=0.03)
    # forces on the wheel: F_x = -FX (CONTACT's on the rail), F_y = +FS (s = -e_y on either side)
    assert abs(record["creep_force_lat_N"] - patch["FS"]) <= 0.03 * mu_fn
    assert abs(record["creep_force_long_N"] + patch["FX"]) <= 0.03 * mu_fn
    creep = math.hypot(record["creep_force_long_N"], record["creep_force_lat_N"]) / (MU * record["normal_force_N"])
    assert creep == pytest.approx(math.hypot(patch["FX"], patch["FS"]) / mu_fn, abs=0.03)  # 0.81 mu N
    assert record["contact_point_y_m"] * 1e3 == pytest.approx(patch["YCP(TR)"], abs=0.2)
    assert record["approach_m"] * 1e3 == pytest.approx(patch["APPROACH"], rel=0.03)
    assert record["creepage_lat"] == pytest.approx(patch["CETA"], rel=0.01)
    assert record["spin_creepage_1_per_m"] == pytest.approx(patch["CPHI"] * 1e3, rel=0.01)
    assert abs(record["creepage_long"] + patch["CKSI"]) <= 1e-4


def test_record_is_the_applied_force_in_the_formed_plane(at_state):
    """The loop still applies the candidate's frame (``values``: the candidate's plane at 0.554 rad, a lateral creep
    force of -2.4 kN); the record's own-frame force turned by its angle is the force the wheel gets (to rounding).
    The wheel's lateral coordinate moves with the reference point (2.3 mm along the axle here)."""
    _, _, contact = at_state
    k = _left(contact)
    values, record = contact.values, contact.record
    assert values["contact_angle_rad"][k] == pytest.approx(0.554, abs=0.005)
    assert values["creep_force_lat_N"][k] == pytest.approx(-2.40e3, abs=0.05e3)
    assert record["contact_angle_rad"][k] - values["contact_angle_rad"][k] == pytest.approx(0.26, abs=0.01)
    own = np.array([record[n][k] for n in ("creep_force_long_N", "creep_force_lat_N", "normal_force_N")])
    force = _frame(record["contact_angle_rad"][k], 0) @ own
    np.testing.assert_allclose(force, contact.force_N[k], rtol=0, atol=1e-9 * np.linalg.norm(force))
    moved = record["contact_point_y_m"][k] - values["contact_point_y_m"][k]
    assert record["wheel_lateral_m"][k] - values["wheel_lateral_m"][k] == pytest.approx(moved, abs=2e-4)
    assert "formed_normal_force_N" not in record
    for name in ("semi_axis_long_m", "contact_area_m2", "max_pressure_Pa", "ellipticity_residual"):
        np.testing.assert_array_equal(record[name], values[name])  # the formed patch's result all along


def test_python_recorder_stores_the_record(at_state):
    """The Python drivers' recorder (scipy methods) stores ``record``, as the compiled loop's tables."""
    from rigid_dynamics.wheelset.recorder import Recorder

    model, state, contact = at_state
    recorder = Recorder(model, model.scene)
    recorder.record(0.0, model.full_state(state))
    k = _left(contact)
    for name in ("contact_angle_rad", "normal_force_N", "creep_force_lat_N", "creepage_lat"):
        assert recorder.patches[name][-1][0, 0, 0] == pytest.approx(contact.record[name][k], rel=1e-6), name


# the parent commit's run (9bc4443, before the record changed): wheel forces (left x, y, z, right x, y, z; main
# frame, N) at t = 0, 1, 2 ms and the state at 2 ms; written from result.to_dataframe() and result.states
REGRESSION_RTOL = 1e-8
BEFORE_WHEEL_FORCES_N = np.array(
    [
        [-1703.2684600992875, 66269.25627585802, -108677.9006965729, 2884.6252762019703, -22026.964491305927,
         -72159.2452441729],
        [-3504.489743052872, 55899.6952702068, -100756.60430141767, 2875.1484542618437, -22338.568966631243,
         -72730.50283895298],
        [-5150.258945081018, 37520.42667169039, -84893.8153777949, 3797.848356304777, -23721.94261311259,
         -77567.57655586327],
    ]
)  # fmt: skip
BEFORE_FINAL_STATE = np.array(
    [0.027777773847654737, -0.006244230701592905, -0.46018343636843845, -0.004541981990900907,
     0.0007004208057133055, 0.059997957219598046, 13.888407093794322, 0.02954455906780925, 0.008770034586533436,
     0.006966076253571798, -0.0034880747134001366, 30.00212818883418]
)  # fmt: skip


def _root_run(contact_model: str, duration_s: float):
    """curve-flange from the flange root (CONTACT's deck state's y and yaw, no settling) on the sampled gap."""
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = load_scene(resolve_scene_path("curve-flange"))
    scene = replace(
        scene, contact_model=contact_model, patch_geometry="sampled", duration_s=duration_s, settling_distance_m=0.0,
        initial=replace(scene.initial, lateral_displacement_m=-0.00628, yaw_rad=-0.00455),
    )  # fmt: skip
    return simulate(scene)


@pytest.fixture(scope="module")
def run():
    return _root_run("bem", 0.002)


def test_run_records_the_formed_plane(run):
    from rigid_dynamics.contact.search import WheelsetPose
    from rigid_dynamics.wheelset.formed_patches import PatchFormer
    from rigid_dynamics.wheelset.simulate import build_provider

    assert run.status == "ok", run.message
    p = run.patches
    angle = p["contact_angle_rad"][:, 0, 0]
    assert np.all(angle > 0.65) and angle[0] == pytest.approx(0.787, abs=0.005)
    # the angle is the formed patch's plane at the recorded state (formed again here from the surfaces)
    former = PatchFormer(build_provider(run.scene).surfaces)  # the search provider's surfaces, as the callback's
    (formed,) = former.patches("left", WheelsetPose(*(float(v) for v in run.states[0, :6])))
    assert angle[0] == pytest.approx(formed.geometry.contact_angle_rad, abs=1e-9)
    creep = np.hypot(p["creep_force_long_N"][0, 0, 0], p["creep_force_lat_N"][0, 0, 0])
    assert creep / (MU * p["normal_force_N"][0, 0, 0]) == pytest.approx(0.81, abs=0.03)


def test_run_wheel_forces_are_the_records_and_the_former_ones(run):
    """The wheel's contact force is each touching patch's recorded force turned by its recorded angle (to
    rounding), and the run's trajectory and wheel forces are the parent commit's (regression)."""
    frame = run.to_dataframe()
    p = run.patches
    for side, name in enumerate(("left", "right")):
        wheel = frame[[f"{name}_wheel_contact_force_{a}_N" for a in "xyz"]].to_numpy()
        for i in range(len(run.t)):
            total = np.zeros(3)
            for slot in range(2):
                if np.nan_to_num(p["normal_force_N"][i, side, slot]) > 0:
                    own = [p[n][i, side, slot] for n in ("creep_force_long_N", "creep_force_lat_N", "normal_force_N")]
                    total += _frame(p["contact_angle_rad"][i, side, slot], side) @ np.array(own)
            np.testing.assert_allclose(wheel[i], total, rtol=0, atol=1e-9 * np.linalg.norm(total))
    forces = frame[[f"{s}_wheel_contact_force_{a}_N" for s in ("left", "right") for a in "xyz"]].to_numpy()
    # REGRESSION_RTOL: recorded on an AMD EPYC; on an Intel Xeon (2026-11-30) round-off moved two forces by 2.9e-10
    # relative (the BEM's NORM/TANG iterations stop at a relative change of 1e-6, so the CPU's rounding reaches the
    # forces); 1e-8 still catches any change of the model's formulas
    np.testing.assert_allclose(forces, BEFORE_WHEEL_FORCES_N, rtol=REGRESSION_RTOL)
    for block in (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12)):
        scale = np.max(np.abs(BEFORE_FINAL_STATE[block]))
        np.testing.assert_allclose(
            run.states[-1, block], BEFORE_FINAL_STATE[block], rtol=0, atol=REGRESSION_RTOL * scale
        )


@pytest.fixture(scope="module")
def auto_run():
    """``auto`` (5 %, its BEM patches reused: auto_reuse.py) on the sampled gap from curve-flange's flange root, 6 ms:
    the flange patch goes to BEM, and most recorded samples of it are served by its anchor's correction (5 of 7;
    the other two were re-solved by the callback there: the sampled gap had moved beyond the trust region)."""
    return _root_run("auto", 0.006)


def test_auto_records_its_served_bem_patches_in_the_formed_plane(auto_run, at_state):
    """A BEM patch ``auto`` serves by its anchor's correction is recorded in the plane of the formed patch the
    anchor was (auto_reuse.reuse_own), not in the compiled candidate's. Referees: the patch formed again from the
    surfaces at each recorded state (formed_patches.PatchFormer, as the static case forms it), and always-BEM at the
    same state (WheelsetModel.contact, the formed patch solved afresh). Measured at the seven samples (0 to 6 ms, the
    plane moving from 0.785 to 0.511 rad): angle within 0.0033 rad and approach within 0.06 um of the re-formed
    patch; creep force within 0.79 % (bench definition |F - F_BEM| / max(|F_BEM|, 0.01 mu N)) and normal force
    within 0.53 % of always-BEM. Before, these samples read the candidate's plane (0.54 rad at t = 0, a lateral
    creep force of -0.3 kN against the formed patch's 30.3 kN). The record's force turned by its angle is the wheel's
    force to 3.3e-6 relative (the candidate's frame moves within the trust region; exact for the solved patches).
    """
    from rigid_dynamics.contact.search import WheelsetPose
    from rigid_dynamics.wheelset.compiled_laws import LAW_BEM_CORRECTED, LAW_CALLBACK
    from rigid_dynamics.wheelset.formed_patches import PatchFormer
    from rigid_dynamics.wheelset.simulate import build_provider

    run = auto_run
    model = at_state[0]
    p = run.patches
    laws = p["contact_law_code"][:, 0, 0]
    assert np.all((laws == LAW_BEM_CORRECTED) | (laws == LAW_CALLBACK)) and np.sum(laws == LAW_BEM_CORRECTED) >= 4, laws
    former = PatchFormer(build_provider(run.scene).surfaces)
    for i in range(len(run.t)):
        (formed,) = former.patches("left", WheelsetPose(*(float(v) for v in run.states[i, :6])))
        assert p["contact_angle_rad"][i, 0, 0] == pytest.approx(formed.geometry.contact_angle_rad, abs=0.005)
        assert p["approach_m"][i, 0, 0] == pytest.approx(formed.geometry.approach_m, abs=0.2e-6)
        bem = model.contact(run.states[i], record=True)
        k = _left(bem)
        force = [p[n][i, 0, 0] for n in ("creep_force_long_N", "creep_force_lat_N")]
        fresh = [bem.record[n][k] for n in ("creep_force_long_N", "creep_force_lat_N")]
        size = max(math.hypot(*fresh), 0.01 * MU * bem.record["normal_force_N"][k])
        assert math.hypot(force[0] - fresh[0], force[1] - fresh[1]) / size < 0.015
        assert p["normal_force_N"][i, 0, 0] == pytest.approx(bem.record["normal_force_N"][k], rel=0.01)
    assert p["contact_angle_rad"][0, 0, 0] == pytest.approx(0.785, abs=0.005)
    creep = np.hypot(p["creep_force_long_N"][0, 0, 0], p["creep_force_lat_N"][0, 0, 0])
    assert creep / (MU * p["normal_force_N"][0, 0, 0]) == pytest.approx(0.81, abs=0.03)
    wheel = run.to_dataframe()[[f"left_wheel_contact_force_{a}_N" for a in "xyz"]].to_numpy()
    for i in range(len(run.t)):
        own = [p[n][i, 0, 0] for n in ("creep_force_long_N", "creep_force_lat_N", "normal_force_N")]
        total = _frame(p["contact_angle_rad"][i, 0, 0], 0) @ np.array(own)
        np.testing.assert_allclose(wheel[i], total, rtol=0, atol=1e-5 * np.linalg.norm(total))


def test_auto_measures_its_reuse_error_in_the_formed_plane(auto_run):
    """The reuse's own error (the corrected value the old anchor would have served against each fresh BEM solve,
    auto_reuse._correction_errors) is judged in the formed patch's plane. Since auto decides on the sampled gap's
    geometry, both wheels' patches of this run go up the ladder (the flange root's ellipticity residual 1.5-2.5, the
    right tread's 0.24-0.45) and are served by the reuse. Since the trust region also sees the sampled gap
    (auto_reuse.gap_descriptor), 19 corrections are measured (46 re-solves), the largest creep-force error 5.3 %
    (normal force 2.2 %), one above the 5 % tolerance, so the run ends ``warning`` and says so. (Before the gap
    entered the region: 14 measured, largest 4.6 %, ``ok``: the gap's moves were served without being measured.
    With the right tread on the ellipse: 11.8 %, 1 of 9 above; in the candidate's plane, 0.26 rad off, the same
    corrections read 110 % and 4 of 10: there the creep force is mostly a component of the normal force, a few per
    cent of the patch's own.)
    """
    stats = auto_run.summary()["callback"]["auto_reuse"]
    assert stats["errors_measured"] >= 15
    assert 0.01 < stats["max_creep_force_error"] < 0.06 and stats["max_normal_force_error"] < 0.03
    assert stats["errors_above_tolerance"] == 1
    assert auto_run.status == "warning" and "1 of 19 measured corrections" in auto_run.message, auto_run.message


def test_reuse_errors_are_judged_in_the_plane_solved_in():
    """auto_reuse._correction_errors against a direct computation: two forces given in a formed plane 0.26 rad from
    the candidate's, written in the candidate's frame; the errors in the formed plane are those of the own-plane
    forces (closed form), whatever the candidate's frame reads."""
    from rigid_dynamics.wheelset.auto_reuse import _correction_errors

    angle = 0.26
    q = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(angle), -math.sin(angle)], [0.0, math.sin(angle), math.cos(angle)]])
    fmap = (*q.ravel(), 0.0, 0.0, 0.0)  # Q[i][j] = C_i . F_j (formed_patches.frame_map); no offset
    own_fresh, own_served = np.array([1.0e3, 30.0e3, 120.0e3]), np.array([1.2e3, 29.0e3, 121.0e3])  # T_x', T_y', N'
    fresh, served = q @ own_fresh, q @ own_served  # (T_x, T_y, N) in the candidate's frame
    mu = 0.3
    e_f, e_n = _correction_errors(served[[2, 0, 1]], fresh[[2, 0, 1]], mu * fresh[2], fmap)
    assert e_f == pytest.approx(np.hypot(*(own_served - own_fresh)[:2]) / np.hypot(*own_fresh[:2]), rel=1e-12)
    assert e_n == pytest.approx(abs(own_served[2] / own_fresh[2] - 1.0), rel=1e-12)
    not_formed = (math.nan,) * 12  # the candidate's own plane: the errors as the candidate's frame reads them
    e_f, _ = _correction_errors(served[[2, 0, 1]], fresh[[2, 0, 1]], mu * fresh[2], not_formed)
    assert e_f == pytest.approx(np.hypot(*(served - fresh)[:2]) / np.hypot(*fresh[:2]), rel=1e-12)
