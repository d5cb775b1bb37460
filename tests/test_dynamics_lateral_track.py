"""The lateral track (``[track_dynamics] lateral_model = "lumped"``): verification.

* Its defaults against the Winkler beam they are reduced from (closed form, Timoshenko's 2 k_f / beta) and against
  a second method: the discretely supported beam of :class:`track_matrices.TrackSystem` written with the rail's
  lateral bending stiffness and the fastenings' lateral springs on rigid sleepers, whose static point stiffness (between
  two rail seats and over one) brackets the lumped model's.
* Steady curving on the elastic track (lumped vertical and lateral) against the independent quasi-static curving
  solution of tests/test_dynamics_curve.py with each rail at rest on its springs under its wheel's force (w = F_z /
  k_v, u = F_y / k_y, unknowns of the textbook model): wheelset position and yaw, loads, creep forces and the
  rails' lateral and vertical displacements.
* The energy balance and the mirror image on a flange-contact curve with the 3-D search; the compiled track rates
  against the matrices (regression); bad input. The structured Jacobian with the lateral track: tests/
  test_dynamics_beam.py.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from test_dynamics_curve import curve_scene, quasi_static, settled

from rigid_dynamics.wheelset.simulate import simulate
from rigid_dynamics.wheelset.track import (
    UIC60_LATERAL_SEAT,
    TrackDynamics,
    lumped_lateral_equivalent,
)
from rigid_dynamics.wheelset.track_matrices import TrackSystem

LATERAL = TrackDynamics(model="lumped", lateral_model="lumped")


def test_lateral_defaults_are_the_reduced_rail_seat_data():
    eq = lumped_lateral_equivalent(**UIC60_LATERAL_SEAT)
    track = TrackDynamics()
    assert track.lateral_rail_mass_kg == pytest.approx(eq["lateral_rail_mass_kg"], rel=0.005)
    assert track.lateral_rail_stiffness_N_per_m == pytest.approx(eq["lateral_rail_stiffness_N_per_m"], rel=0.005)
    assert track.lateral_rail_damping_N_s_per_m == pytest.approx(eq["lateral_rail_damping_N_s_per_m"], rel=0.005)
    # Timoshenko's Winkler beam: w0 = P beta / (2 k_f)
    d = UIC60_LATERAL_SEAT
    k_f = d["fastening_lateral_stiffness_N_per_m"] / d["sleeper_spacing_m"]
    beta = (k_f / (4.0 * d["rail_lateral_bending_stiffness_N_m2"])) ** 0.25
    assert eq["lateral_rail_stiffness_N_per_m"] == pytest.approx(2.0 * k_f / beta, rel=1e-12)


def test_lateral_stiffness_against_the_discretely_supported_lateral_beam():
    """Second method: the beam on discrete rail seats (TrackSystem, Euler-Bernoulli, modes to 20 kHz) with the
    lateral data (E I_z, fastening k_y per seat, sleepers held: a very stiff 'ballast' and a heavy sleeper); its
    static point stiffness between two seats and over one brackets the continuous Winkler value the lumped model
    uses (measured: 32.0 mid-span, 32.6 MN/m over a seat, against 32.4 MN/m)."""
    d = UIC60_LATERAL_SEAT
    beam = TrackDynamics(
        model="beam", rail_theory="euler-bernoulli",
        rail_mass_per_length_kg_per_m=d["rail_mass_per_length_kg_per_m"],
        rail_bending_stiffness_N_m2=d["rail_lateral_bending_stiffness_N_m2"],
        sleeper_spacing_m=d["sleeper_spacing_m"], seat_pad_stiffness_N_per_m=d["fastening_lateral_stiffness_N_per_m"],
        seat_ballast_stiffness_N_per_m=1.0e14, seat_sleeper_mass_kg=1.0e4, cutoff_frequency_Hz=20000.0,
        end_margin_m=12.0,
    )  # fmt: skip
    system = TrackSystem(beam, 0.0)
    lumped = TrackDynamics().lateral_rail_stiffness_N_per_m
    a = d["sleeper_spacing_m"]
    seat = system.seat_m[len(system.seat_m) // 2]
    stiffness = []
    for x in (seat, seat + 0.5 * a):  # over a seat, mid-span
        rest = system.rest_state([1.0, 1.0], xi_m=x)
        stiffness.append(1.0 / float(system.deflection_m(rest, [x])[0, 0]))
    assert min(stiffness) < lumped < max(stiffness)
    assert max(stiffness) / min(stiffness) < 1.1
    assert np.mean(stiffness) == pytest.approx(lumped, rel=0.03)


@pytest.fixture(scope="module")
def curve_on_elastic_track():
    scene = curve_scene()
    scene = replace(
        scene, track_dynamics=LATERAL, integrator=replace(scene.integrator, fixed_step_s=2.5e-4)
    )  # the light lateral rail under the creep forces' damping: RK4's limit is 0.31 ms here (the start check)
    result = simulate(scene)
    assert result.status == "ok", result.message
    return scene, result


def test_steady_curving_on_the_elastic_track_against_the_quasi_static_solution(curve_on_elastic_track):
    scene, result = curve_on_elastic_track
    sim, drift = settled(result)
    ref = quasi_static(scene, elastic=True)
    rigid = quasi_static(curve_scene())
    assert drift < 1e-7
    names = list(result.track_state_names)
    last = result.track_states[-1]
    lateral = np.array([last[names.index("rail_left_lateral_m")], last[names.index("rail_right_lateral_m")]])
    vertical = np.array([last[names.index("rail_left_m")], last[names.index("rail_right_m")]])
    # measured: rails moved 0.548 / 0.710 mm, lowered 0.516 / 0.670 mm; y -5.296 mm against rigid -5.465 mm
    np.testing.assert_allclose(lateral, ref["rail_lateral"], rtol=0.005)
    np.testing.assert_allclose(vertical, ref["rail_vertical"], rtol=0.005)
    assert sim["y"] == pytest.approx(ref["y"], rel=0.005)
    assert sim["psi"] == pytest.approx(ref["psi"], rel=0.005)
    assert sim["N"] == pytest.approx(ref["N"], rel=1e-3)
    for key in ("Tx", "Ty", "xi", "eta"):
        assert np.max(np.abs(sim[key] - ref[key])) < 0.005 * np.max(np.abs(ref[key])), key
    # the elastic track's effect is well above the agreement: the wheelset sits 0.17 mm (3 %) further in
    assert abs(ref["y"] - rigid["y"]) > 10 * abs(sim["y"] - ref["y"])
    assert np.all(np.abs(ref["rail_lateral"]) > 3e-4)


def test_lateral_track_rates_equal_the_matrices():
    """Regression (self-consistency): the compiled track rates (lumped and beam, with the lateral track) equal
    TrackSystem.rates."""
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model
    from rigid_dynamics.wheelset.state import N_RIGID
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    for model in ("lumped", "beam"):
        scene = replace(curve_scene(), track_dynamics=replace(LATERAL, model=model), duration_s=0.05)
        wm = WheelsetModel(scene, build_provider(scene), get_contact_model("linear"))
        rng = np.random.default_rng(3)
        n = wm.n_state - N_RIGID
        track = rng.normal(size=n) * 1e-4
        force = np.array([8.0e4, 9.0e4, 3.0e3, -2.0e3])
        out = np.zeros(n)
        wm._track_derivative(track, force, out, x_m=0.0)
        xi = wm.track_system.start_position_m()
        np.testing.assert_allclose(out, wm.track_system.rates(track, force, xi), rtol=1e-12, atol=1e-9)


def test_bad_lateral_input():
    with pytest.raises(ValueError, match="lateral_model = 'beam'"):
        TrackDynamics(model="lumped", lateral_model="beam")
    with pytest.raises(ValueError, match="lateral_model = 'lumped': expected 'rigid' with model = 'rigid'"):
        TrackDynamics(model="rigid", lateral_model="lumped")
    with pytest.raises(ValueError, match="lateral_rail_stiffness_N_per_m"):
        TrackDynamics(model="lumped", lateral_model="lumped", lateral_rail_stiffness_N_per_m=-1.0)


def test_lateral_track_frequency_closed_form():
    """The free lateral rail (no wheel): m_y u'' + c_y u' + k_y u = 0, eigenvalues of the track's own rates
    against the closed form -zeta w0 +- w0 sqrt(zeta^2 - 1)."""
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model
    from rigid_dynamics.wheelset.state import N_RIGID
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    scene = replace(curve_scene(), track_dynamics=LATERAL, duration_s=0.05)
    wm = WheelsetModel(scene, build_provider(scene), get_contact_model("linear"))
    n = wm.n_state - N_RIGID
    jac = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1.0
        out = np.zeros(n)
        wm._track_derivative(e, np.zeros(4), out)
        jac[:, j] = out
    r = wm.track_system.lateral_rows()
    rows = np.r_[r, wm.track_system.n_positions + r]
    sub = jac[np.ix_(rows, rows)]
    t = LATERAL
    w0 = math.sqrt(t.lateral_rail_stiffness_N_per_m / t.lateral_rail_mass_kg)
    k_y, m_y = t.lateral_rail_stiffness_N_per_m, t.lateral_rail_mass_kg
    zeta = t.lateral_rail_damping_N_s_per_m / (2.0 * math.sqrt(k_y * m_y))
    expected = sorted([-zeta * w0 + w0 * math.sqrt(zeta**2 - 1.0), -zeta * w0 - w0 * math.sqrt(zeta**2 - 1.0)] * 2)
    np.testing.assert_allclose(sorted(np.linalg.eigvals(sub).real), expected, rtol=1e-10)
    assert w0 / (2 * math.pi) == pytest.approx(102.6, abs=0.1)


def test_flange_curve_on_the_lateral_track():
    """curve-flange (S1002/UIC60, R = 100 m, the 3-D search) on the lumped vertical and lateral track: the outer
    rail is pushed out by its flange force, at rest u = -F_y / k_y (the force of the wheel on the rail); energy
    balance, fourth-order convergence of its residual with the step (the start-up into the flange; measured 2.2e-3
    at the scene's 0.5 ms, 1.25e-4 at 0.25 ms, 1.6e-9 at 0.1 ms); the left-hand curve mirrors it."""
    from wheelrail.scenes import load_scene

    scene = load_scene("curve-flange")
    scene = replace(scene, track_dynamics=LATERAL)
    runs = {}
    for step in (5e-4, 2.5e-4, 1e-4):
        runs[step] = simulate(replace(scene, integrator=replace(scene.integrator, fixed_step_s=step)))
        assert runs[step].status == "ok", runs[step].message
    energy = {step: r.summary()["energy_balance_relative"] for step, r in runs.items()}
    assert energy[1e-4] < 1e-7
    assert 8.0 < energy[5e-4] / energy[2.5e-4] < 32.0  # RK4: 2^4
    fine = runs[1e-4]
    names = list(fine.track_state_names)
    last = fine.track_states[-1]
    k_y = LATERAL.lateral_rail_stiffness_N_per_m
    for side, name in enumerate(("rail_left_lateral_m", "rail_right_lateral_m")):
        assert last[names.index(name)] == pytest.approx(-fine.contact_force_N[-1, side, 1] / k_y, rel=1e-6)
    assert last[names.index("rail_left_lateral_m")] < -5e-4  # the outer (left) rail, 0.82 mm out
    peaks = fine.summary()["peak_rail_lateral_displacement_m"]
    column = fine.track_states[:, names.index("rail_left_lateral_m")]
    assert peaks["left"] == column[np.argmax(np.abs(column))] and peaks["left"] < -5e-4
    assert runs[5e-4].summary()["peak_rail_lateral_displacement_m"] is not None
    assert fine.states[-1, 1] < -7.0e-3  # the wheelset follows its rail out: -7.11 mm against -6.28 mm rigid
    left = simulate(
        replace(scene, track=replace(scene.track, curve_direction="left"),
                integrator=replace(scene.integrator, fixed_step_s=1e-4))
    )  # fmt: skip
    assert left.status == "ok"
    assert left.states[-1, 1] == pytest.approx(-fine.states[-1, 1], rel=1e-8)
    assert left.states[-1, 3] == pytest.approx(-fine.states[-1, 3], rel=1e-6)
    lat = [names.index("rail_left_lateral_m"), names.index("rail_right_lateral_m")]
    assert left.track_states[-1, lat] == pytest.approx(-last[lat][::-1], rel=1e-7)


def test_lateral_input_is_checked(capsys, tmp_path):
    """Bad lateral keys get one line naming the key, the value and what was expected (CLI, exit 2)."""
    from hardening_helpers import assert_error, run, write

    from wheelrail.scenes import resolve_scene_path

    base = resolve_scene_path("wheel-flat").read_text(encoding="utf-8")
    for key, value, fragment in (
        ("lateral_model", '"beam"', "expected one of rigid, lumped"),
        ("lateral_rail_stiffness_N_per_m", "1.0", "100000 to 1e+11"),
        ("lateral_rail_mass_kg", "0.0", "1 to 10000"),
        ("lateral_rail_damping_N_s_per_m", "-1.0", "0 to 1e+08"),
    ):
        text = base.replace('model = "beam"', f'model = "beam"\n{key} = {value}')
        code, _, err = run(capsys, "run", write(tmp_path, text, f"{key}.toml"), "--out", tmp_path / key, "--quiet")
        assert_error(code, err, key, fragment)
    text = base.replace('model = "beam"', 'model = "rigid"\nlateral_model = "lumped"')
    code, _, err = run(capsys, "run", write(tmp_path, text, "rigid.toml"), "--out", tmp_path / "rigid", "--quiet")
    assert_error(code, err, "lateral_model", "expected 'rigid' with model = 'rigid'")
