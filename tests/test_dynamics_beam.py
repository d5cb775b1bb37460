"""The discretely supported beam track (scene ``[track_dynamics] model = "beam"``) against closed forms and the
literature.

Physics tests (independent references):
* the static deflection line of an Euler-Bernoulli rail on closely spaced seats against the Winkler beam's closed
  form w(x) = P beta / (2 k) exp(-beta |x|) (cos beta x + sin beta |x|) (Timoshenko's beam on an elastic
  foundation); on the UIC60 seats at 0.6 m under a seat and at mid-span;
* the pinned-pinned resonance: the mode with its nodes at the seats at pi / (2 a^2) sqrt(E I / rho A)
  (Euler-Bernoulli) and at the simply supported Timoshenko span's frequency (both closed forms written here), near
  the 1 kHz reported for a 60 kg rail on 0.6 m sleeper spacing; the receptance at mid-span peaks there and the
  receptance above a seat has its minimum near it (Knothe & Grassie 1993, Vehicle System Dynamics 22, 209-262);
* the track's static point stiffness and the P2 resonance of an unsprung mass on it against Jenkins et al.'s
  (1974) equivalent track (150 MN/m, 245 kg: sqrt(Kt / (Mu + Mt)) / 2 pi = 57 Hz);
* a wheelset run on the beam: at rest the rail under the wheel deflects as the static solution, the wheelset
  sits lower by it, and the energy balance holds with the beam's energy in it.
Regression tests (self-consistency): the compiled right-hand side of the beam against the matrices' rates.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.wheelset import DynamicsScene, IntegratorSettings, TrackDynamics, simulate
from rigid_dynamics.wheelset.track import beam_layout
from rigid_dynamics.wheelset.track_matrices import TrackSystem

JENKINS_KT_N_PER_M = 150.0e6
JENKINS_MT_KG = 245.0


def _beam(**changes) -> TrackDynamics:
    return replace(TrackDynamics(model="beam"), **changes)


def _winkler(track: TrackDynamics, force_N: float, x_m):
    k_f = track.seat_stiffness_N_per_m / track.sleeper_spacing_m
    beta = (k_f / (4.0 * track.rail_bending_stiffness_N_m2)) ** 0.25
    bx = beta * np.abs(np.asarray(x_m, float))
    return force_N * beta / (2.0 * k_f) * np.exp(-bx) * (np.cos(bx) + np.sin(bx))


def test_static_deflection_line_against_the_winkler_beam():
    """Seats every 0.1 m carrying the UIC60 track's foundation modulus (k_seat scaled by 0.1 / 0.6): the continuous
    foundation's closed form within 0.5 % of the peak along +-3 m; on the real 0.6 m seats, the deflection under a
    seat and at mid-span within 1 % of it (the discrete supports' own effect on EB is that small)."""
    real = _beam(rail_theory="euler-bernoulli", cutoff_frequency_Hz=20000.0)
    scale = 0.1 / 0.6
    dense = replace(
        real,
        sleeper_spacing_m=0.1,
        seat_pad_stiffness_N_per_m=real.seat_pad_stiffness_N_per_m * scale,
        seat_ballast_stiffness_N_per_m=real.seat_ballast_stiffness_N_per_m * scale,
        seat_sleeper_mass_kg=real.seat_sleeper_mass_kg * scale,
    )
    force = 100.0e3
    system = TrackSystem(dense, 4.0)
    x0 = system.start_position_m() + 2.05  # between two seats
    rest = system.rest_state([force, force], x0)
    x = x0 + np.linspace(-3.0, 3.0, 121)
    found = system.deflection_m(rest, x)[0]
    expected = _winkler(dense, force, x - x0)
    print(f"dense seats: w0 {found[60] * 1e3:.4f} mm, closed form {expected[60] * 1e3:.4f} mm")
    assert np.max(np.abs(found - expected)) < 5e-3 * expected[60]
    system = TrackSystem(real, 4.0)
    w0 = _winkler(real, force, 0.0)
    for offset in (0.0, 0.3):  # at a seat (the start is at a seat), at mid-span
        xi = system.start_position_m() + 1.2 + offset
        w = system.deflection_m(system.rest_state([force, force], xi), [xi])[0, 0]
        print(f"0.6 m seats, {offset} m from a seat: {w * 1e3:.4f} mm, Winkler {w0 * 1e3:.4f} mm")
        assert w == pytest.approx(w0, rel=0.01)


def test_timoshenko_shear_adds_a_little_static_compliance():
    """Timoshenko against Euler-Bernoulli on the same seats: softer by the shear deflection, a few per cent (more at
    mid-span, where the rail bends between seats)."""
    force = 100.0e3
    out = {}
    for theory in ("euler-bernoulli", "timoshenko"):
        system = TrackSystem(_beam(rail_theory=theory), 4.0)
        xi = system.start_position_m() + 1.2
        out[theory] = [
            system.deflection_m(system.rest_state([force, force], xi + d), [xi + d])[0, 0] for d in (0.0, 0.3)
        ]
    ratio = np.array(out["timoshenko"]) / np.array(out["euler-bernoulli"])
    print(f"Timoshenko / Euler-Bernoulli static deflection at a seat, mid-span: {ratio}")
    assert np.all(ratio > 1.0) and np.all(ratio < 1.15) and ratio[1] > ratio[0]


def _timoshenko_span_frequency_hz(track: TrackDynamics, span_m: float) -> float:
    """Lowest frequency of a simply supported Timoshenko span (w = W sin(pi x / a)): the lower root of
    (kGA k^2 - rho A w^2)(E I k^2 + kGA - rho I w^2) = (kGA k)^2, k = pi / a."""
    k = math.pi / span_m
    ei, ga = track.rail_bending_stiffness_N_m2, track.rail_shear_stiffness_N
    ra, ri = track.rail_mass_per_length_kg_per_m, track.rail_rotary_inertia_kg_m
    coeffs = [ra * ri, -(ga * k * k * ri + ra * (ei * k * k + ga)), ga * k * k * (ei * k * k + ga) - (ga * k) ** 2]
    return math.sqrt(min(np.roots(coeffs).real)) / (2.0 * math.pi)


@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_pinned_pinned_frequency(theory):
    track = _beam(rail_theory=theory, rail_loss_factor=0.0)
    a = track.sleeper_spacing_m
    if theory == "euler-bernoulli":
        expected = (
            math.pi / (2.0 * a * a) * math.sqrt(track.rail_bending_stiffness_N_m2 / track.rail_mass_per_length_kg_per_m)
        )
    else:
        expected = _timoshenko_span_frequency_hz(track, a)
    system = TrackSystem(track, 3.0)
    frequencies = system.eigenfrequencies_Hz()
    nearest = frequencies[np.argmin(np.abs(frequencies - expected))]
    print(f"{theory}: pinned-pinned {expected:.1f} Hz (closed form), model {nearest:.1f} Hz")
    assert nearest == pytest.approx(expected, rel=1e-6)
    if theory == "timoshenko":
        assert 950.0 < expected < 1150.0  # near 1 kHz for a 60 kg rail on 0.6 m spacing
    # with damping: the mid-span receptance peaks at the pinned-pinned frequency, the one above a seat dips near it
    damped = TrackSystem(_beam(rail_theory=theory), 3.0)
    f = np.arange(600.0, 2000.0, 1.0)
    x_seat = damped.start_position_m()
    mid = np.abs(damped.receptance_m_per_N(f, x_seat + 0.5 * a))
    seat = np.abs(damped.receptance_m_per_N(f, x_seat))
    band = f > 0.8 * expected
    peak, dip = f[band][np.argmax(mid[band])], f[band][np.argmin(seat[band])]
    print(f"  mid-span receptance peak {peak:.0f} Hz, above-seat minimum {dip:.0f} Hz")
    assert peak == pytest.approx(expected, rel=0.01)
    assert dip == pytest.approx(expected, rel=0.06)
    assert mid[f == peak][0] > 4.0 * seat[f == peak][0]


def test_point_stiffness_and_p2_resonance_against_jenkins():
    """The beam's static point stiffness (receptance at 1 Hz) against Jenkins' 150 MN/m within 10 %; the P2
    resonance of half the Manchester wheelset (906.5 kg, rigid contact: the peak of |1 / (1 - w^2 Mu alpha)|)
    against Jenkins' sqrt(Kt / (Mu + Mt)) / 2 pi within 10 %."""
    unsprung = 0.5 * DynamicsScene().wheelset.mass_kg
    jenkins = math.sqrt(JENKINS_KT_N_PER_M / (unsprung + JENKINS_MT_KG)) / (2.0 * math.pi)
    for theory in ("euler-bernoulli", "timoshenko"):
        system = TrackSystem(_beam(rail_theory=theory), 3.0)
        x = system.start_position_m() + 0.3
        stiffness = 1.0 / abs(system.receptance_m_per_N([1.0], x)[0])
        f = np.arange(20.0, 200.0, 0.5)
        alpha = system.receptance_m_per_N(f, x)
        p2 = f[np.argmax(np.abs(1.0 / (1.0 - (2.0 * math.pi * f) ** 2 * unsprung * alpha)))]
        print(f"{theory}: static {stiffness / 1e6:.1f} MN/m, P2 resonance {p2:.1f} Hz (Jenkins {jenkins:.1f} Hz)")
        assert stiffness == pytest.approx(JENKINS_KT_N_PER_M, rel=0.10)
        assert p2 == pytest.approx(jenkins, rel=0.10)


def test_beam_size_follows_the_run_and_the_cutoff():
    track = _beam()
    short, long_ = beam_layout(track, 5.0), beam_layout(track, 20.0)
    assert long_.length_m - short.length_m == pytest.approx(16.8, abs=0.61)  # 1.1 x the extra travel
    assert short.length_m >= 1.1 * 5.0 + 2 * track.end_margin_m
    # modes up to the cut-off: the last kept below it, the next above it (flexural branch)
    from rigid_dynamics.wheelset.track import flexural_frequency_rad_per_s

    k = np.arange(1, short.n_modes + 2) * math.pi / short.length_m
    f = flexural_frequency_rad_per_s(track, k) / (2.0 * math.pi)
    assert f[-2] <= track.cutoff_frequency_Hz < f[-1]


def test_compiled_beam_rates_equal_the_matrices():
    """Regression (two implementations of the same equations): compiled track_rates (recurrence for the mode
    shapes, loops over seats) against TrackSystem.rates (M^-1 (b F - C v - K q)) at a random state."""
    from rigid_dynamics.wheelset.compiled_motion import track_rates
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    for theory in ("euler-bernoulli", "timoshenko"):
        scene = DynamicsScene(track_dynamics=_beam(rail_theory=theory), contact_provider="conical", duration_s=0.2)
        model = WheelsetModel(scene, build_provider(scene), get_contact_model("hertz"))
        system = model.track_system
        rng = np.random.default_rng(3)
        y = np.zeros(model.n_state)
        y[0] = 0.37
        y[14:] = rng.normal(size=model.n_state - 14) * 1e-4
        out = np.zeros(model.n_state)
        model.par["frame_x0_m"] = 0.0
        track_rates(model.par, y, np.array([1.0e5, 0.5e5]), out)
        expected = system.rates(y[14:], [1.0e5, 0.5e5], 0.37 + system.start_position_m())
        scale = np.max(np.abs(expected))
        assert np.max(np.abs(out[14:] - expected)) < 1e-9 * scale, theory
        under = model.rail_under_wheels(y)
        np.testing.assert_allclose(under, system.under_wheel(y[14:][None], [0.37 + system.start_position_m()])[0])


def _scene(**changes):
    base = DynamicsScene(
        contact_provider="tables",
        contact_model="linear",
        speed_m_per_s=20.0,
        duration_s=0.01,
        integrator=IntegratorSettings(method="RK4", fixed_step_s=2.5e-5, output_step_s=1e-3),
        track_dynamics=TrackDynamics(model="beam"),
    )
    return replace(base, **changes)


def test_wheelset_on_the_beam_starts_at_rest_on_its_static_deflection():
    scene = _scene()
    beam = simulate(scene)
    rigid = simulate(replace(scene, track_dynamics=TrackDynamics()))
    assert beam.status == rigid.status == "ok" and beam.compiled
    assert beam.track_state_names[:2] == ("rail_left_m", "rail_right_m")
    system = TrackSystem(scene.track_dynamics, scene.speed_m_per_s * scene.duration_s)
    load = scene.static_wheel_load_N
    rest = system.rest_state([load, load])
    w = system.deflection_m(rest, [system.start_position_m()])[:, 0]
    # the rail force at rest is the wheel load up to the creep forces' small vertical share: 0.2 %
    np.testing.assert_allclose(beam.track_states[0, 0:2], w, rtol=2e-3)
    assert beam.states[0, 2] - rigid.states[0, 2] == pytest.approx(beam.track_states[0, 0], rel=1e-3)
    # 0.2 m along the track over 3 seats the deflection under the wheel stays within the sleeper-passing ripple
    assert np.max(np.abs(beam.track_states[:, 0] - w[0])) < 0.1 * w[0]
    kinetic, potential = system.energy_J(beam.track_full_states)
    assert potential[0] > 1.0  # the beam's strain energy enters the energy balance
    scale = max(float(np.max(np.abs(beam.kinetic_energy_J))), 1.0)
    print(f"energy residual {np.max(np.abs(beam.energy_residual_J)):.3g} J of {scale:.3g} J")
    assert np.max(np.abs(beam.energy_residual_J)) < 1e-6 * scale


@pytest.mark.parametrize("lateral", ["rigid", "lumped"])
def test_structured_jacobian_equals_the_difference_quotients(lateral):
    """Regression (two ways to the same matrix): WheelsetModel.state_jacobian (differences in the mechanical states,
    the beam's columns from its linear equations and the rail under the wheels; the lateral track's 4 columns by
    differences) against central differences in every state, at the rest state of a short run on the beam; and the
    RK4 step limit from both."""
    from rigid_dynamics.wheelset.equilibrium import elastic_start, initial_state
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, model_options
    from rigid_dynamics.wheelset.stability import jacobian, rk4_stable_step
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    scene = _scene(
        duration_s=0.001, track_dynamics=_beam(cutoff_frequency_Hz=2000.0, end_margin_m=1.2, lateral_model=lateral)
    )
    law = get_contact_model(scene.contact_model)
    model = WheelsetModel(scene, build_provider(scene), law, model_options(law.name, scene))
    state, ok, _ = elastic_start(model, initial_state(scene))
    assert ok
    y = model.full_state(state)

    def fun(v):
        return model.derivative(0.0, v)

    fast = model.state_jacobian(fun, y)
    slow = jacobian(fun, y)
    rows = slice(0, None)
    scale = np.max(np.abs(slow[rows]), axis=1, keepdims=True) + 1e-30
    rel = np.abs(fast - slow) / scale
    rel[12:14] = 0.0  # the work integrals' rows (diagnostics: the dampers' power is quadratic in the rates)
    print(f"{len(y)} states, largest difference {np.max(rel):.2e} of each row's largest entry")
    assert np.max(rel) < 1e-4
    a = rk4_stable_step(fun, y, jac=model.state_jacobian)
    b = rk4_stable_step(fun, y)
    assert a.max_step_s == pytest.approx(b.max_step_s, rel=1e-4)


def test_largest_eigenvalues_give_the_step_limit_of_the_full_spectrum():
    """Regression (two ways to the same limit): above 200 states the step limit comes from ARPACK's largest
    eigenvalues (stability._largest_eigenvalues); on the wheel-flat scene's beam (Timoshenko, 5 kHz) it equals the
    limit from every eigenvalue (numpy) to 1e-6."""
    from rigid_dynamics.wheelset import stability
    from rigid_dynamics.wheelset.equilibrium import elastic_start, initial_state
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    scene = _scene(duration_s=0.05)
    law = get_contact_model(scene.contact_model)
    model = WheelsetModel(scene, build_provider(scene), law, model_options(law.name, scene))
    state, ok, _ = elastic_start(model, initial_state(scene))
    y = model.full_state(state)
    assert ok and len(y) > 200

    def fun(v):
        return model.derivative(0.0, v)

    matrix = model.state_jacobian(fun, y)
    fast = stability.rk4_stable_step(fun, y, jac=lambda f, v: matrix)
    original = stability._largest_eigenvalues
    try:
        stability._largest_eigenvalues = np.linalg.eigvals
        full = stability.rk4_stable_step(fun, y, jac=lambda f, v: matrix)
    finally:
        stability._largest_eigenvalues = original
    print(f"{len(y)} states: limit {fast.max_step_s * 1e6:.2f} us ({fast.describe()}); all eigenvalues "
          f"{full.max_step_s * 1e6:.2f} us")  # fmt: skip
    assert fast.max_step_s == pytest.approx(full.max_step_s, rel=1e-6)


def test_fe_rail_static_deflection_equals_the_modal_beam():
    """The finite-element rail of comparisons/wheelflat_fe_beam.py (Hermite elements, 6 per span) against the modal
    beam with modes to 40 kHz (Euler-Bernoulli): the static deflection under 100 kN at a seat and at mid-span within
    0.1 % (two discretisations of the same beam)."""
    from scipy.sparse.linalg import spsolve

    from comparisons.wheelflat_fe_beam import FeBeam, fe_track_from_scene

    track = _beam(rail_theory="euler-bernoulli", cutoff_frequency_Hz=40000.0)
    system = TrackSystem(track, 4.0)
    fe = FeBeam(fe_track_from_scene(track, system.layout.n_sleepers, 6))
    for offset in (0.0, 0.3):
        xi = system.start_position_m() + 1.2 + offset
        modal = system.deflection_m(system.rest_state([1e5, 1e5], xi), [xi])[0, 0]
        shape = fe.shape_vector(xi)
        finite = float(shape @ spsolve(fe.K, shape * 1e5))
        print(f"{offset} m from a seat: modal {modal * 1e3:.5f} mm, FE {finite * 1e3:.5f} mm")
        assert modal == pytest.approx(finite, rel=1e-3)


def test_wheel_flat_on_the_beam_against_the_fe_rail():
    """The wheel-flat scene (100 mm flat, 60 km/h) on the Euler-Bernoulli modal beam without rail damping against the
    vertical half-wheelset on the finite-element rail (comparisons/wheelflat_fe_beam.py: FE rail, Newmark, a point
    Hertz spring fed with the wheel-centre trajectory): the peak within 5 % (measured 0.985; the two contact models
    differ as on the lumped and rigid tracks, ratios 0.88-1.07 in wheelflat_study.md)."""
    from comparisons.wheelflat_fe_beam import fe_track_from_scene, simulate_passage_fe
    from comparisons.wheelflat_vertical import from_scene
    from wheelrail.scenes import load_scene

    speed, distance = 60.0 / 3.6, 0.5
    scene = load_scene("wheel-flat")
    assert scene.track_dynamics.model == "beam"  # the scene's default
    scene = replace(
        scene,
        speed_m_per_s=speed,
        duration_s=distance / speed,
        irregularities=replace(scene.irregularities, flat_length_m=0.10),
        track_dynamics=replace(
            scene.track_dynamics, rail_theory="euler-bernoulli", rail_loss_factor=0.0, cutoff_frequency_Hz=5000.0
        ),  # the cut-off and step at which 0.985 was measured (the scene now ships 15 kHz at 6.25 us)
        integrator=replace(scene.integrator, fixed_step_s=2.5e-5, output_step_s=2.5e-5, lift_half_step_check=False),
    )
    result = simulate(scene)
    assert result.status in ("ok", "warning"), result.message
    peak = float(np.max(-result.contact_force_N[:, :, 2]))
    hertz = result.patches["normal_force_N"][0, 0, 0] / result.patches["approach_m"][0, 0, 0] ** 1.5
    centre = scene.wheelset.nominal_radius_m * (0.5 * math.pi - scene.irregularities.flat_angle_rad)
    wheel = from_scene(replace(scene, track_dynamics=replace(scene.track_dynamics, model="lumped")), hertz, centre)
    layout = beam_layout(scene.track_dynamics, distance)
    track = fe_track_from_scene(scene.track_dynamics, layout.n_sleepers)
    _, _, force = simulate_passage_fe(wheel, track, speed, layout.margin_m, distance)
    print(f"peak: wheelset on the modal beam {peak / 1e3:.1f} kN, vertical on the FE rail {force.max() / 1e3:.1f} kN")
    assert peak / force.max() == pytest.approx(1.0, abs=0.05)


def test_beam_input_is_checked(capsys, tmp_path):
    """Bad beam keys get one line naming the key, the value and the range; a run too long for a beam is refused
    with its size."""
    from hardening_helpers import assert_error, run, write

    from wheelrail.scenes import resolve_scene_path

    base = resolve_scene_path("wheel-flat").read_text(encoding="utf-8")
    for key, value, fragment in (
        ("sleeper_spacing_m", "0.001", "0.3 to 1.5"),
        ("cutoff_frequency_Hz", "1e9", "500 to 50000"),
        ("rail_loss_factor", "-0.1", "0 to 1"),
    ):
        text = base.replace("cutoff_frequency_Hz = 15000.0", "")  # the scene's own, replaced below
        text = text.replace('model = "beam"', f'model = "beam"\n{key} = {value}')
        code, _, err = run(capsys, "run", write(tmp_path, text, f"{key}.toml"), "--out", tmp_path / key, "--quiet")
        assert_error(code, err, key, fragment)
    text = base.replace("duration_s = 0.4", "duration_s = 60.0")
    code, _, err = run(capsys, "run", write(tmp_path, text, "long.toml"), "--out", tmp_path / "long", "--quiet")
    assert_error(code, err, "track_dynamics.model = 'beam'", "1000 m", "at most 8000")
