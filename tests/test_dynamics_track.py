"""The elastic track (scene ``[track_dynamics]``, seed eq 6's rail deflection N_d,t) against closed forms and Jenkins.

Physics tests (independent references):
* the default per-wheel data against the static point stiffness of a Winkler beam and Jenkins et al.'s (1974)
  equivalent track stiffness 150 MN/m;
* the static deflection under a static wheel load against the series springs F (1/k_p + 1/k_b), and the wheelset
  lowered by exactly that much against the rigid track;
* the track's eigenfrequencies (the model's own right-hand side, linearised) against the 2-DOF closed form, and
  the P2 resonance with an unsprung mass against the range published for ballasted track (50-100 Hz);
* the P2 force of a dipped joint against Jenkins' formula (Jenkins et al. 1974, Railway Engineering Journal 3,
  2-16, as given in Iwnicki (ed.), Handbook of Railway Vehicle Dynamics, 2006, P2 = P0 + 2 alpha V
  sqrt(Mu/(Mu+Mt)) [1 - pi Ct / (4 sqrt(Kt (Mu+Mt)))] sqrt(Kt Mu)) over 10-50 m/s, with the energy balance
  including the track.
Regression tests (self-consistency): the Python and the compiled right-hand sides on the elastic track.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from hardening_helpers import assert_error, run, write

from rigid_dynamics.wheelset import DynamicsScene, IntegratorSettings, Irregularities, TrackDynamics, simulate
from rigid_dynamics.wheelset.parameters import SuspensionParameters
from rigid_dynamics.wheelset.state import TRACK
from rigid_dynamics.wheelset.track import UIC60_RAIL_SEAT, lumped_track_equivalent
from wheelrail.scenes import resolve_scene_path

# Jenkins et al. (1974) equivalent track per wheel (UK concrete-sleepered CWR), as quoted with the P2 formula
JENKINS_KT_N_PER_M = 150.0e6
JENKINS_CT_N_S_PER_M = 55.8e3
JENKINS_MT_KG = 245.0


def test_default_track_is_the_uic60_reduction_and_matches_jenkins_stiffness():
    derived = lumped_track_equivalent(**UIC60_RAIL_SEAT)
    default = TrackDynamics()
    for key, value in derived.items():
        assert getattr(default, key) == pytest.approx(value, rel=5e-3), key
    # Winkler beam point stiffness 2 k_f / beta computed here from the rail and the seat springs
    seat = UIC60_RAIL_SEAT
    k_f = (
        1.0
        / (1.0 / seat["pad_stiffness_N_per_m"] + 1.0 / seat["ballast_stiffness_N_per_m"])
        / seat["sleeper_spacing_m"]
    )
    beta = (k_f / (4.0 * seat["rail_bending_stiffness_N_m2"])) ** 0.25
    assert default.static_stiffness_N_per_m == pytest.approx(2.0 * k_f / beta, rel=5e-3)
    assert default.static_stiffness_N_per_m == pytest.approx(JENKINS_KT_N_PER_M, rel=0.01)


def _eigenfrequencies_hz(matrix):
    values = np.linalg.eigvals(matrix)
    return np.sort(np.abs(values.imag[values.imag > 0])) / (2.0 * math.pi)


def _two_dof_closed_form_hz(m1, m2, k1, k2):
    """Undamped masses m1 (top, on k1) and m2 (on k2 to ground): omega^2 roots of the characteristic equation."""
    a = k1 / m1 + (k1 + k2) / m2
    b = k1 * k2 / (m1 * m2)
    root = math.sqrt(a * a - 4.0 * b)
    return np.array([math.sqrt(0.5 * (a - root)), math.sqrt(0.5 * (a + root))]) / (2.0 * math.pi)


def test_track_eigenfrequencies_against_the_closed_form():
    """The model's track right-hand side (wheelset_model.WheelsetModel._track_derivative), linearised by finite
    differences without damping, against the 2-DOF closed form; then with the unsprung mass of half the wheelset
    on the rail (rigid contact): the P2 resonance, which Jenkins' data put at sqrt(Kt/(Mu+Mt))/2pi = 57 Hz and which
    is commonly quoted at 50-100 Hz for ballasted track (Iwnicki, Handbook, P2 force)."""
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    track = replace(TrackDynamics(model="lumped"), pad_damping_N_s_per_m=0.0, ballast_damping_N_s_per_m=0.0)
    scene = DynamicsScene(track_dynamics=track, contact_provider="conical")
    model = WheelsetModel(scene, build_provider(scene), get_contact_model("hertz"))
    matrix = np.zeros((8, 8))
    for j in range(8):
        e = np.zeros(8)
        e[j] = 1e-6
        out = np.zeros(8)
        model._track_derivative(e, np.zeros(2), out)
        matrix[:, j] = out / 1e-6
    found = _eigenfrequencies_hz(matrix)
    expected = _two_dof_closed_form_hz(track.rail_mass_kg, track.sleeper_mass_kg, track.pad_stiffness_N_per_m,
                                       track.ballast_stiffness_N_per_m)  # fmt: skip
    np.testing.assert_allclose(found[::2], expected, rtol=1e-6)  # each frequency twice (left and right)
    print(f"track resonances {expected[0]:.1f} and {expected[1]:.1f} Hz")
    assert 100.0 < expected[0] < 200.0 and 250.0 < expected[1] < 500.0
    unsprung = 0.5 * scene.wheelset.mass_kg
    p2 = _two_dof_closed_form_hz(track.rail_mass_kg + unsprung, track.sleeper_mass_kg, track.pad_stiffness_N_per_m,
                                 track.ballast_stiffness_N_per_m)[0]  # fmt: skip
    print(f"P2 resonance with {unsprung:.0f} kg per wheel: {p2:.1f} Hz")
    assert 50.0 < p2 < 100.0
    jenkins = math.sqrt(JENKINS_KT_N_PER_M / (unsprung + JENKINS_MT_KG)) / (2.0 * math.pi)
    assert p2 == pytest.approx(jenkins, rel=0.1)


def _scene(**changes):
    base = DynamicsScene(
        contact_provider="tables",
        contact_model="linear",
        speed_m_per_s=20.0,
        duration_s=0.004,
        integrator=IntegratorSettings(method="RK4", fixed_step_s=5e-5, output_step_s=1e-3),
        track_dynamics=TrackDynamics(model="lumped"),
    )
    return replace(base, **changes)


def test_static_deflection_is_the_series_springs():
    scene = _scene()
    elastic = simulate(scene)
    rigid = simulate(replace(scene, track_dynamics=TrackDynamics()))
    assert elastic.status == rigid.status == "ok" and elastic.compiled
    track = scene.track_dynamics
    load = scene.static_wheel_load_N
    rail = load * (1.0 / track.pad_stiffness_N_per_m + 1.0 / track.ballast_stiffness_N_per_m)
    np.testing.assert_allclose(elastic.track_states[0, 0:2], rail, rtol=1e-6)
    np.testing.assert_allclose(elastic.track_states[0, 2:4], load / track.ballast_stiffness_N_per_m, rtol=1e-6)
    # the wheelset sits lower by the rail's deflection; the start is at rest (track still at rest at the end)
    assert elastic.states[0, 2] - rigid.states[0, 2] == pytest.approx(rail, rel=1e-5)
    np.testing.assert_allclose(elastic.track_states[-1, 0:4], elastic.track_states[0, 0:4], rtol=1e-6)
    assert rail == pytest.approx(0.591e-3, rel=0.01)  # 88.9 kN on 150 MN/m


def test_python_and_compiled_paths_agree_on_the_elastic_track():
    """Regression (two implementations of the same equations): tables provider, a 1 mm lateral offset and a
    dipped joint under the wheels, 10 ms."""
    scene = _scene(
        duration_s=0.01,
        irregularities=Irregularities(
            joint_dip_angle_rad=0.01, joint_position_m=0.1, joint_ramp_length_m=0.3, joint_entry_rounding_m=0.05
        ),  # fmt: skip
    )
    scene = replace(scene, initial=replace(scene.initial, lateral_displacement_m=1e-3))
    fast = simulate(scene, compiled=True)
    slow = simulate(scene, compiled=False)
    assert fast.status == slow.status == "ok"
    assert fast.compiled and not slow.compiled
    np.testing.assert_allclose(fast.states, slow.states, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fast.track_states, slow.track_states, rtol=1e-8, atol=1e-13)
    np.testing.assert_allclose(fast.contact_force_N, slow.contact_force_N, rtol=1e-7, atol=1e-3)
    assert np.max(np.abs(fast.track_states[:, 4:6])) > 1e-3  # the track moved (m/s)


def jenkins_p2_N(scene, two_alpha, speed):
    """Jenkins et al. (1974) P2 for unsprung mass Mu = half the wheelset, Jenkins' equivalent track."""
    p0 = scene.static_wheel_load_N
    mu, mt, kt, ct = 0.5 * scene.wheelset.mass_kg, JENKINS_MT_KG, JENKINS_KT_N_PER_M, JENKINS_CT_N_S_PER_M
    return p0 + two_alpha * speed * math.sqrt(mu / (mu + mt)) * (
        1.0 - ct * math.pi / (4.0 * math.sqrt(kt * (mu + mt)))
    ) * math.sqrt(kt * mu)


def dipped_joint_scene(speed, two_alpha=0.01, joint_m=6.0):
    """Conical wheels on the Jenkins track: rail mass Mt on Kt, Ct, over a sleeper layer made rigid (10 t on
    1e11 N/m, damped at 0.7 of critical: 0.15 % of the stiffness, resonance at 500 Hz), no vertical suspension
    (the axle load is a constant force: the unsprung mass is the wheelset)."""
    return DynamicsScene(
        contact_provider="tables",
        contact_model="linear",
        speed_m_per_s=speed,
        duration_s=(joint_m + 1.2) / speed,
        suspension=SuspensionParameters(vertical_stiffness_N_per_m=0.0, vertical_damping_N_s_per_m=0.0),
        irregularities=Irregularities(joint_dip_angle_rad=two_alpha, joint_position_m=joint_m),
        integrator=IntegratorSettings(method="RK4", fixed_step_s=2.5e-5, output_step_s=1e-4),
        track_dynamics=TrackDynamics(
            model="lumped",
            rail_mass_kg=JENKINS_MT_KG,
            pad_stiffness_N_per_m=JENKINS_KT_N_PER_M,
            pad_damping_N_s_per_m=JENKINS_CT_N_S_PER_M,
            sleeper_mass_kg=1.0e4,
            ballast_stiffness_N_per_m=1.0e11,
            ballast_damping_N_s_per_m=4.4e7,
        ),
    )


@pytest.mark.parametrize("speed", [10.0, 30.0, 50.0])
def test_dipped_joint_p2_against_jenkins(speed):
    """P2 of Jenkins' formula is the peak force of the track spring (and damper) of a mass Mu + Mt given the
    velocity 2 alpha V Mu/(Mu + Mt) at the joint; the simulation's peak of the force the rail mass puts on its
    support (k_p (z_r - z_s) + c_p (z_r' - z_s')) after the joint is within 10 % of it from 10 to 50 m/s (measured
    ratios of the dynamic increments 0.93 at 10, 1.06 at 30, 1.09 at 50 m/s: below at low speed where the Hertz
    spring in series softens the track by ~11 %, above at speed where the P1 ringing adds). The energy balance,
    track included, closes to < 1e-9 of the track's peak energy scale."""
    scene = dipped_joint_scene(speed)
    result = simulate(scene)
    assert result.status == "ok" and result.compiled
    tr = scene.track_dynamics
    x = result.states[:, 0]
    track = result.track_states
    support = tr.pad_stiffness_N_per_m * (track[:, 0] - track[:, 2]) + tr.pad_damping_N_s_per_m * (
        track[:, 4] - track[:, 6]
    )
    after = x > 6.0 - 0.05
    p0 = scene.static_wheel_load_N
    ratio = (support[after].max() - p0) / (jenkins_p2_N(scene, 0.01, speed) - p0)
    print(f"V = {speed} m/s: P2 simulated / Jenkins (dynamic increments) = {ratio:.3f}")
    assert 0.9 < ratio < 1.1
    # the energy check includes the track: its energy is large against the residual
    track_energy = 0.5 * tr.pad_stiffness_N_per_m * (track[:, 0] - track[:, 2]) ** 2
    assert np.max(np.abs(result.energy_residual_J)) < 1e-3
    assert np.max(track_energy) > 1.0


def test_track_model_is_validated(capsys, tmp_path):
    text = resolve_scene_path("hunting-conical").read_text(encoding="utf-8") + '\n[track_dynamics]\nmodel = "slab"\n'
    code, _, err = run(capsys, "run", write(tmp_path, text, "scene.toml"), "--out", tmp_path / "o", "--quiet")
    assert_error(code, err, "track_dynamics", "'slab'", "rigid, lumped, beam")
    text = resolve_scene_path("hunting-conical").read_text(encoding="utf-8")
    text += '\n[track_dynamics]\nmodel = "lumped"\nrail_mass_kg = -1.0\n'
    code, _, err = run(capsys, "run", write(tmp_path, text, "scene2.toml"), "--out", tmp_path / "o2", "--quiet")
    assert_error(code, err, "rail_mass_kg", "-1.0")
    text = resolve_scene_path("hunting-conical").read_text(encoding="utf-8")
    text += '\n[track_dynamics]\nmodel = "beam"\nrail_theory = "bernoulli"\n'
    code, _, err = run(capsys, "run", write(tmp_path, text, "scene3.toml"), "--out", tmp_path / "o3", "--quiet")
    assert_error(code, err, "rail_theory", "'bernoulli'", "timoshenko, euler-bernoulli")
    text = resolve_scene_path("hunting-conical").read_text(encoding="utf-8")
    text += '\n[track_dynamics]\nmodel = "lumped"\npad_stiffness_N_per_m = 1e20\n'
    code, _, err = run(capsys, "run", write(tmp_path, text, "scene3.toml"), "--out", tmp_path / "o3", "--quiet")
    assert_error(code, err, "track_dynamics.pad_stiffness_N_per_m", "1e+20", "1e+12")


def test_dipped_joint_refused_on_the_search():
    with pytest.raises(ValueError, match="joint_dip_angle_rad"):
        _scene(contact_provider="search", irregularities=Irregularities(joint_dip_angle_rad=0.01))


def test_track_states_sit_in_their_slice():
    from rigid_dynamics.wheelset.state import (
        LATERAL_STATE_NAMES,
        RAIL,
        SLEEPER,
        TRACK_STATE_NAMES,
        n_states,
        state_names,
        track_positions,
        track_velocities,
    )

    assert TRACK == slice(14, None) and n_states(4) == 22 and n_states(0) == 14
    assert track_positions(22) == slice(14, 18) and track_velocities(22) == slice(18, 22)
    assert (RAIL, SLEEPER) == (14, 16)
    # with the lateral track: its positions end the positions, its rates end the rates
    names = state_names(n_states(6))
    assert names[14:20] == TRACK_STATE_NAMES[:4] + LATERAL_STATE_NAMES[:2]
    assert names[20:26] == TRACK_STATE_NAMES[4:] + LATERAL_STATE_NAMES[2:]


def test_compiled_search_equals_the_python_search_on_the_elastic_track():
    """Regression (two implementations): the polygonal-wheel scene on the elastic track for 0.01 s, the compiled loop
    on the compiled search against the Python RK4 loop on SearchProvider; bounds as
    tests/test_dynamics_compiled_search.py (the tabulated surfaces and tracking differ at ~1e-8 m)."""
    from wheelrail.scenes import load_scene

    scene = replace(load_scene(resolve_scene_path("polygonal-wheel")), duration_s=0.01)
    scene = replace(scene, track_dynamics=TrackDynamics(model="lumped"))
    fast = simulate(scene, compiled=True)
    slow = simulate(scene, compiled=False)
    assert fast.status == slow.status == "ok" and fast.compiled and not slow.compiled
    assert fast.provider == slow.provider == "search"
    n0 = scene.static_wheel_load_N
    d_force = np.max(np.abs(fast.contact_force_N - slow.contact_force_N))
    print(f"max |dF|/N0 {d_force / n0:.2e}, track {np.max(np.abs(fast.track_states - slow.track_states)):.2e}")
    assert d_force < 5e-4 * n0
    assert np.max(np.abs(fast.states[:, :3] - slow.states[:, :3])) < 5e-8
    assert np.max(np.abs(fast.track_states[:, :4] - slow.track_states[:, :4])) < 5e-8


def test_wheel_flat_first_impact_elastic_against_rigid():
    """The embedded wheel-flat scene up to just after the first impact (0.03 s): on the lumped track the impact
    peak is far below the rigid track's (measured over the whole scene: 311 kN against 588 kN) and still well above
    the static load; the rail deflects under it (~1 mm scale). The scene's default beam track:
    tests/test_dynamics_beam.py."""
    from wheelrail.scenes import load_scene

    scene = replace(load_scene(resolve_scene_path("wheel-flat")), duration_s=0.03)
    assert scene.track_dynamics.model == "beam"  # the scene's default
    scene = replace(scene, track_dynamics=replace(scene.track_dynamics, model="lumped"))
    elastic = simulate(scene)
    rigid = simulate(replace(scene, track_dynamics=TrackDynamics()))
    assert elastic.status in ("ok", "warning") and rigid.status in ("ok", "warning")
    peak_e = float(np.max(-elastic.contact_force_N[:, :, 2]))
    peak_r = float(np.max(-rigid.contact_force_N[:, :, 2]))
    n0 = scene.static_wheel_load_N
    print(f"first impact: elastic {peak_e / 1e3:.1f} kN, rigid {peak_r / 1e3:.1f} kN, static {n0 / 1e3:.1f} kN")
    assert 2.5 * n0 < peak_e < 0.7 * peak_r
    assert 0.6e-3 < np.max(elastic.track_states[:, 0:2]) < 2e-3


def test_p2_frequency_of_the_default_track_against_the_linear_three_mass_model():
    """The default UIC60 track under a dipped joint at 20 m/s: the frequency of the ballast force's oscillation after
    the joint (mean of 4 half periods between zero crossings of its dynamic part) against the damped eigenfrequency of
    the linear model wheel (half the wheelset) - Hertz spring (linearised at the static approach, 3 N / (2 q)) - rail
    - pad - sleeper - ballast (measured 57.8 Hz against 57.7 Hz; 60.0 Hz with a rigid contact and no damping), inside
    the 50-100 Hz usually quoted for the P2 resonance."""
    scene = replace(dipped_joint_scene(20.0), track_dynamics=TrackDynamics(model="lumped"), duration_s=7.2 / 20.0)
    result = simulate(scene)
    assert result.status == "ok"
    tr = scene.track_dynamics
    track = result.track_states
    ballast = tr.ballast_stiffness_N_per_m * track[:, 2] + tr.ballast_damping_N_s_per_m * track[:, 6]
    after = result.states[:, 0] > 6.0
    dynamic = ballast[after] - scene.static_wheel_load_N
    times = result.t[after]
    crossings = times[np.flatnonzero(np.sign(dynamic[1:]) != np.sign(dynamic[:-1]))]
    simulated = 1.0 / (2.0 * np.mean(np.diff(crossings[:5])))
    load = scene.static_wheel_load_N
    k_hertz = 1.5 * load / float(result.patches["approach_m"][0, 0, 0])
    mu = 0.5 * scene.wheelset.mass_kg
    kp, cp, kb, cb = (tr.pad_stiffness_N_per_m, tr.pad_damping_N_s_per_m, tr.ballast_stiffness_N_per_m,
                      tr.ballast_damping_N_s_per_m)  # fmt: skip
    mass = np.diag([mu, tr.rail_mass_kg, tr.sleeper_mass_kg])
    stiff = np.array([[k_hertz, -k_hertz, 0.0], [-k_hertz, k_hertz + kp, -kp], [0.0, -kp, kp + kb]])
    damp = np.array([[0.0, 0.0, 0.0], [0.0, cp, -cp], [0.0, -cp, cp + cb]])
    system = np.block([[np.zeros((3, 3)), np.eye(3)], [-np.linalg.solve(mass, stiff), -np.linalg.solve(mass, damp)]])
    linear = _eigenfrequencies_hz(system)[0]
    print(f"P2 frequency: simulated {simulated:.2f} Hz, linear three-mass model {linear:.2f} Hz")
    assert simulated == pytest.approx(linear, rel=0.02)
    assert 50.0 < simulated < 100.0


def test_track_states_reach_the_table_and_the_npz(tmp_path):
    from rigid_dynamics.wheelset import save_timeseries
    from rigid_dynamics.wheelset.state import TRACK_STATE_NAMES

    result = simulate(_scene(duration_s=0.002))
    table = result.to_dataframe()
    for name in TRACK_STATE_NAMES:
        assert name in table.columns
    np.testing.assert_array_equal(table["rail_left_m"].to_numpy(), result.track_states[:, 0])
    with np.load(save_timeseries(result, tmp_path / "run.npz")) as data:
        assert data["track_states"].shape == (len(result.t), 8)
        assert list(data["track_state_names"]) == list(TRACK_STATE_NAMES)
    summary = result.summary()
    assert summary["track_model"] == "lumped" and summary["peak_rail_deflection_m"]["left"] > 5e-4


def test_dipped_joint_geometry():
    """N_irr of the dipped joint: about alpha L deep at the joint, slopes +alpha before and -alpha after it (z down),
    level far away; the compiled formula (compiled_tables._dip) gives the same numbers."""
    from rigid_dynamics.wheelset import compiled_tables
    from rigid_dynamics.wheelset.irregular import rail_irregularity
    from rigid_dynamics.wheelset.layout import new_parameters

    irr = Irregularities(joint_dip_angle_rad=0.01, joint_position_m=5.0, joint_ramp_length_m=3.0)
    alpha = 0.005
    value, first, second = rail_irregularity(irr, np.array([5.0, 4.8, 5.2, -20.0, 30.0]))
    # depth alpha (sqrt(L^2 + e^2) - e_j): alpha L = 15 mm deepened by the entry rounding e = 1 m
    assert value[0] == pytest.approx(alpha * (math.sqrt(9.0 + 1.0) - irr.joint_rounding_m), rel=1e-12)
    # slopes next to the joint (0.2 m away): alpha within 1 % (the entry rounding bends the ramps slightly)
    assert first[1] == pytest.approx(alpha, rel=1e-2) and first[2] == pytest.approx(-alpha, rel=1e-2)
    assert abs(value[3]) < 1.5e-4 and abs(value[4]) < 1.5e-4  # alpha e^2 / (2 |u|) far away
    assert abs(first[3]) < 1e-5 and abs(first[4]) < 1e-5
    assert second[0] == pytest.approx(-alpha / irr.joint_rounding_m, rel=1e-3)  # concave bottom, 1/(0.5 m) < 1/r0
    par = new_parameters()
    par["dip_angle_rad"], par["dip_position_m"], par["dip_ramp_length_m"] = 0.01, 5.0, 3.0
    par["dip_entry_rounding_m"], par["dip_rounding_m"] = irr.joint_entry_rounding_m, irr.joint_rounding_m
    for k, x in enumerate((5.0, 4.8, 5.2, -20.0, 30.0)):
        np.testing.assert_allclose(
            compiled_tables._dip(par, x), (value[k], first[k], second[k]), rtol=1e-12, atol=1e-15
        )


@pytest.mark.parametrize("method", ["RK45", "Radau"])
def test_adaptive_methods_carry_the_track(method):
    """Regression: the scipy methods (Python path; Radau with drivers.state_jacobian's track columns) on the
    elastic track with a 1 mm offset give RK4's rail deflections (compiled loop) and close the energy balance."""
    scene = _scene(contact_provider="conical", duration_s=0.02)
    scene = replace(scene, initial=replace(scene.initial, lateral_displacement_m=1e-3))
    reference = simulate(replace(scene, contact_provider="tables"))
    adaptive = simulate(replace(scene, integrator=IntegratorSettings(method=method, output_step_s=1e-3)))
    assert adaptive.status == reference.status == "ok"
    np.testing.assert_allclose(adaptive.track_states[:, 0:2], reference.track_states[:, 0:2], rtol=0, atol=2e-8)
    assert adaptive.summary()["energy_balance_relative"] < 1e-9
