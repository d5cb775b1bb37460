"""Integrators, invariants and safety stops of the wheelset simulation.

Independent references: the classical Runge-Kutta method is of order 4 (observed order fitted over four step
sizes against a DOP853 run at rtol 1e-12); conservation of mechanical energy T + V_g + U_Hertz + U_springs -
F_axle z for an undamped, frictionless case (U_Hertz = (2/5) N q for every patch, Johnson 1985 eq 4.23 integrated);
a pure sine for the wavelength estimate; for the Jacobian of the implicit methods, a closed-form entry, central
differences and the eigenvalues of the linear wheelset model. The safety tests check the documented statuses.
"""

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact.types import ContactResult
from rigid_dynamics.wheelset.drivers import state_jacobian
from rigid_dynamics.wheelset.linear import creep_coefficients, linear_model_for_scene
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    Irregularities,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.providers import PatchSet
from rigid_dynamics.wheelset.recorder import Stop
from rigid_dynamics.wheelset.simulate import (
    build_provider,
    dominant_wavelength_m,
    get_contact_model,
    initial_state,
    save_timeseries,
    simulate,
)
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

BASE = DynamicsScene(
    track=TrackGeometry(rail_head_radius_m=0.05),
    contact_model="linear",
    speed_m_per_s=20.0,
    duration_s=0.02,
    suspension=SuspensionParameters(lateral_stiffness_N_per_m=1e6, vertical_stiffness_N_per_m=1e6),
    initial=InitialConditions(
        lateral_displacement_m=0.002,
        lateral_velocity_m_per_s=0.05,
        vertical_velocity_m_per_s=0.01,
        yaw_rate_rad_per_s=0.01,
    ),
)


def final_state(scene=BASE, **settings):
    result = simulate(replace(scene, integrator=IntegratorSettings(output_step_s=scene.duration_s, **settings)))
    assert result.success, result.message
    return result.states[-1]


@pytest.fixture(scope="module")
def reference():
    return final_state(method="DOP853", relative_tolerance=1e-12, absolute_tolerance=1e-15, max_step_s=1e-3)


def test_rk4_observed_order(reference):
    steps = np.array([8e-4, 4e-4, 2e-4, 1e-4])
    errors = np.array([np.abs(final_state(method="RK4", fixed_step_s=h) - reference)[[1, 2]] for h in steps])
    for k, name in enumerate(("y", "z")):
        order = np.polyfit(np.log(steps), np.log(errors[:, k]), 1)[0]
        print(f"RK4 observed order in {name}: {order:.3f} (errors {errors[:, k]})")
        assert 3.6 < order < 4.4


@pytest.mark.parametrize(
    ("method", "rtol"), [("RK45", 1e-7), ("DOP853", 1e-9), ("Radau", 1e-7), ("BDF", 1e-7), ("LSODA", 1e-8)]
)
def test_adaptive_methods_agree_to_tolerance(reference, method, rtol):
    """Final y and z against DOP853 at rtol 1e-12, relative to y(0) and r0: below 300 rtol for every method.

    Each step keeps its local error estimate below about rtol (scaled), and the runs take 30-250 steps
    (BDF 170 at rtol 1e-7, it is limited by the lightly damped vertical contact mode, about 1100 rad/s), so
    steps x rtol bounds the accumulated error. Measured: RK45 1.2e-8, DOP853 2.9e-11, Radau 2.2e-11,
    BDF 1.6e-8, LSODA 2.3e-9.
    """
    state = final_state(method=method, relative_tolerance=rtol, absolute_tolerance=rtol * 1e-3)
    scale = np.array([BASE.initial.lateral_displacement_m, BASE.wheelset.nominal_radius_m])
    error = np.abs(state[[1, 2]] - reference[[1, 2]]) / scale
    print(f"{method} rtol {rtol:g}: relative error {error}")
    assert np.all(error < 300 * rtol)


def _jacobian_setup(scene):
    model = WheelsetModel(scene, build_provider(scene), get_contact_model(scene.contact_model))
    state, ok, why = model.static_state(initial_state(scene))
    assert ok, why
    model.frame_x0 = float(state[0])
    fun = lambda t, y: model.derivative(t, y)  # noqa: E731
    return fun, np.concatenate([state, [0.0, 0.0]])


def test_state_jacobian_of_the_implicit_methods():
    """The Jacobian handed to Radau and BDF (drivers.state_jacobian) against independent references.

    Suspended conical wheelset with a 3rd-order wheel polygon, so that every mechanical state enters the
    right-hand side (x through the longitudinal springs, the spin angle through the polygon):

    * structure: rows 0-5 are [0 I 0] exactly and the work integrals (columns 12-13) do not enter;
    * closed form: d x''/d x = -2 k_x / m (two longitudinal springs);
    * second method: central differences with the steps 1e-6 and 1e-7 x max(|y_j|, 1) agree with each other to
      1e-5 of each column's largest entry in rows 6-11 (measured 3e-6), and with the forward differences to 3e-4
      (measured 3e-5; the forward difference has an O(h) error where a row is even in the state, as z'' in y at
      the centred state);
    * far along the track (500 s of running: x = 1e4 m, spin angle + 2 pi 3183, frame moved along, work
      integrals -1e5 J and 3e4 J) the Jacobian is finite and equals the one at the start: columns 0-4 and 6-13
      to 1e-5 (measured 6e-6), the spin-angle column to 2e-3 (measured 4e-4: its step grows to 3e-4 rad
      with |phi|). scipy's own finite differences grew the steps of the columns that are zero tenfold per
      Jacobian until they overflowed to inf (BDF on hunting-conical stopped at t = 1.58 s);
    * physics: without the polygon, the hunting eigenvalue pair of the 14x14 Jacobian is within 3 % of
      that of the separately written linear 4-state model (rigid_dynamics.wheelset.linear; measured 1.5 %,
      that model omits spin creep and the gyroscopic couple).
    """
    k_x = 5e5
    scene = replace(
        BASE,
        suspension=SuspensionParameters(longitudinal_stiffness_N_per_m=k_x, lateral_stiffness_N_per_m=5e5),
        irregularities=Irregularities(polygon_order=3, polygon_amplitude_m=3e-4),
        initial=InitialConditions(),
    )
    fun, y0 = _jacobian_setup(scene)
    jac = state_jacobian(fun)(0.0, y0)
    assert jac.shape == (14, 14)
    np.testing.assert_array_equal(jac[0:6], np.hstack([np.zeros((6, 6)), np.eye(6), np.zeros((6, 2))]))
    np.testing.assert_array_equal(jac[:, 12:], 0.0)
    assert jac[6, 0] == pytest.approx(-2 * k_x / scene.wheelset.mass_kg, rel=1e-9)
    assert np.all(np.any(jac[6:, :12] != 0, axis=0))  # every mechanical state enters here

    def central(t, y, rel):
        out = np.zeros((14, 14))
        for j in range(14):
            h = rel * max(abs(y[j]), 1.0)
            up, down = y.copy(), y.copy()
            up[j] += h
            down[j] -= h
            out[:, j] = (fun(t, up) - fun(t, down)) / (2 * h)
        return out

    def column_error(a, b, rows=slice(6, 12)):
        return np.max(np.abs(a[rows] - b[rows]), axis=0) / np.maximum(np.max(np.abs(b[rows]), axis=0), 1e-300)

    coarse, fine = central(0.0, y0, 1e-6), central(0.0, y0, 1e-7)
    print(f"central differences, steps 1e-6 and 1e-7: {np.max(column_error(coarse, fine)):.2e}")
    assert np.max(column_error(coarse, fine)) < 1e-5
    print(f"forward vs central differences: {np.max(column_error(jac, fine)):.2e} of the column maxima")
    assert np.max(column_error(jac, fine)) < 3e-4

    far = y0.copy()
    duration = 500.0
    far[0] += scene.speed_m_per_s * duration
    far[5] += 2 * math.pi * 3183
    far[12:] = [-1e5, 3e4]
    jac_far = state_jacobian(fun)(duration, far)
    assert np.all(np.isfinite(jac_far))
    error = column_error(jac_far, jac, rows=slice(None))
    print(f"far along the track vs start: {error}")
    assert np.max(np.delete(error, 5)) < 1e-5 and error[5] < 2e-3

    plain = replace(scene, irregularities=Irregularities())
    fun, y0 = _jacobian_setup(plain)
    eigenvalues = np.linalg.eigvals(state_jacobian(fun)(0.0, y0))
    f11, f22 = creep_coefficients(plain)
    linear = linear_model_for_scene(plain, f11, f22).eigenvalues(plain.speed_m_per_s)
    hunting = linear[np.argmin(np.abs(linear.real))]  # the oscillatory pair; the others are real, ~ -500 1/s
    nearest = eigenvalues[np.argmin(np.abs(eigenvalues - hunting))]
    print(f"hunting eigenvalue: 14-state Jacobian {nearest:.4f}, linear model {hunting:.4f}")
    assert abs(nearest - hunting) < 0.03 * abs(hunting)


def test_state_jacobian_around_rejected_states():
    """A linear 14-state function (exact forward differences) that answers NaN beyond a wall, as ``trouble`` does:
    the column next to the wall is differenced backwards, a rejected state itself gets the last Jacobian, and a
    state that cannot be differenced either way ends with "solver-failed"."""
    rng = np.random.default_rng(1)
    b = rng.uniform(-1.0, 1.0, (8, 12))
    wall = [np.inf]

    def fun(t, y):
        if y[2] > wall[0]:
            return np.full(14, np.nan)
        return np.concatenate([y[6:12], b @ y[:12]])

    exact = np.zeros((14, 14))
    exact[0:6, 6:12] = np.eye(6)
    exact[6:, :12] = b
    jac = state_jacobian(fun)
    y = rng.uniform(-1.0, 1.0, 14)
    np.testing.assert_allclose(jac(0.0, y), exact, atol=1e-7)
    wall[0] = y[2]  # z + h is rejected: backward difference
    np.testing.assert_allclose(jac(0.0, y), exact, atol=1e-7)
    beyond = y.copy()
    beyond[2] += 1.0
    np.testing.assert_allclose(jac(0.0, beyond), exact, atol=1e-7)  # the last one
    with pytest.raises(Stop) as stop:
        state_jacobian(fun)(0.0, beyond)  # no last one
    assert stop.value.status == "solver-failed"

    def spiky(t, y):  # rejects both neighbours of y[4] = 0.5
        return np.full(14, np.nan) if y[4] != 0.5 else fun(t, y)

    y[4] = 0.5
    with pytest.raises(Stop) as stop:
        state_jacobian(spiky)(0.0, y)
    assert stop.value.status == "solver-failed" and "roll_rad" in stop.value.message


def test_energy_conserved_without_damping_or_friction():
    """Cylindrical wheels (lambda = 0: Hertz stiffness independent of the position), 'hertz' (no creep forces),
    springs only: E = T + V_g + U_H + U_s - F_axle z is constant, and the contact work equals -Delta U_H."""
    k_x, k_y, k_z, b = 1e6, 1e6, 2e6, 1.0
    scene = replace(
        BASE,
        track=TrackGeometry(conicity=0.0, rail_head_radius_m=0.3),
        contact_model="hertz",
        duration_s=0.2,
        suspension=SuspensionParameters(
            longitudinal_stiffness_N_per_m=k_x, lateral_stiffness_N_per_m=k_y, vertical_stiffness_N_per_m=k_z
        ),
        initial=InitialConditions(lateral_displacement_m=0.003, vertical_velocity_m_per_s=0.02),
        integrator=IntegratorSettings(
            method="DOP853", relative_tolerance=1e-10, absolute_tolerance=1e-13, output_step_s=1e-3
        ),
    )
    r = simulate(scene)
    assert r.success, r.message
    st = r.states
    normal = np.nan_to_num(r.patches["normal_force_N"])
    approach = np.where(normal > 0, np.nan_to_num(r.patches["approach_m"]), 0.0)
    u_hertz = 0.4 * np.sum(normal * approach, axis=(1, 2))
    psi, theta = st[:, 3], st[:, 4]
    axle = np.stack([-np.sin(psi) * np.cos(theta), np.cos(psi) * np.cos(theta), np.sin(theta)], -1)
    x_frame = st[0, 0] + scene.speed_m_per_s * r.t
    u_springs = 0.0
    for s in (-1, 1):
        rel = st[:, 0:3] + s * b * axle
        rel = rel - np.stack([x_frame, np.full_like(x_frame, s * b), np.full_like(x_frame, -0.46)], -1)
        u_springs = u_springs + 0.5 * (k_x * rel[:, 0] ** 2 + k_y * rel[:, 1] ** 2 + k_z * rel[:, 2] ** 2)
    energy = r.kinetic_energy_J + r.potential_energy_J + u_hertz + u_springs - scene.loads.axle_load_N * st[:, 2]
    swing = np.ptp(r.kinetic_energy_J)
    print(f"energy drift {np.ptp(energy):.3e} J against kinetic-energy swing {swing:.3e} J")
    assert swing > 1.0
    assert np.ptp(energy) < 1e-6 * swing
    assert np.max(np.abs(r.work_contact_J + u_hertz - u_hertz[0])) < 1e-6 * swing
    assert np.max(np.abs(r.energy_residual_J)) < 1e-6 * swing


def test_wavelength_of_a_sine():
    x = np.linspace(0.0, 50.0, 2001)
    y = 0.003 * np.sin(2 * math.pi * x / 16.5 + 0.3) + 0.0005
    assert dominant_wavelength_m(x, y) == pytest.approx(16.5, rel=1e-4)
    assert math.isnan(dominant_wavelength_m(x, np.zeros_like(x)))


# ------------------------------------------------------------------------------------------------ safety
def _no_nan_written(result):
    assert np.all(np.isfinite(result.states)) and np.all(np.isfinite(result.t))
    assert np.all(np.isfinite(result.wheel_normal_force_N))
    json.dumps(result.summary())


def test_budget_exceeded_stops_with_state():
    r = simulate(replace(BASE, integrator=IntegratorSettings(max_rhs_evaluations=30)))
    assert r.status == "budget-exceeded" and not r.success
    assert r.failure_state is not None and r.failure_state.shape == (12,)
    _no_nan_written(r)


def test_oversized_fixed_step_ends_with_a_status():
    r = simulate(replace(BASE, duration_s=0.5, integrator=IntegratorSettings(method="RK4", fixed_step_s=0.02)))
    assert r.status == "step-unstable" and "stability limit" in r.message, r.status  # stability.py
    assert r.failure_time_s is not None and math.isfinite(r.failure_time_s)
    _no_nan_written(r)


def test_force_anomaly_and_derailment_statuses():
    r = simulate(replace(BASE, integrator=IntegratorSettings(max_force_factor=1.0001)))
    assert r.status == "force-anomaly", r.message
    scene = replace(
        BASE,
        duration_s=1.0,
        suspension=SuspensionParameters(),
        initial=InitialConditions(lateral_displacement_m=0.003),
        integrator=IntegratorSettings(max_lateral_displacement_m=0.0031, output_step_s=2e-3),
    )
    r = simulate(scene)  # the unsuspended conical wheelset hunts with growing amplitude
    assert r.status == "derailed", r.message
    assert abs(r.failure_state[1]) > 0.0031
    _no_nan_written(r)


class _NoContact:
    name = "none"

    def patches(self, centre_m, yaw_rad, roll_rad, spin_rad=0.0):
        one = np.ones(2)
        return PatchSet(
            np.array([0, 1]), np.array([0, 0]), np.zeros((2, 3)), np.tile([0.0, 0.0, -1.0], (2, 1)),
            one, one, -one, 0.46 * one, 0 * one, 0 * one,
        )  # fmt: skip


class _FailingModel:
    name = "failing"
    description = "always fails"

    def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None):
        return ContactResult("failing", False, "not-converged", "test model", 0.0)


def test_invalid_initial_state_and_contact_failure():
    r = simulate(BASE, provider=_NoContact())
    assert r.status == "invalid-initial-state", r.message
    r = simulate(BASE, contact_model=_FailingModel())
    assert r.status in ("invalid-initial-state", "contact-failed")
    assert not r.success


def test_progress_and_save_timeseries(tmp_path):
    fractions = []
    r = simulate(replace(BASE, integrator=IntegratorSettings(output_step_s=1e-3)), progress=fractions.append)
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    path = save_timeseries(r, tmp_path / "series")
    assert path.name == "series.npz" and sorted(p.name for p in tmp_path.iterdir()) == ["series.npz"]
    with np.load(path) as data:
        np.testing.assert_array_equal(data["states"], r.states)
        assert data["patch_normal_force_N"].shape == (len(r.t), 2, 2)
        assert str(data["status"]) == "ok"
    summary = r.summary()
    for key in (
        "status", "message", "simulated_time_s", "wall_time_s", "real_time_factor", "peak_normal_force_N",
        "max_abs_lateral_displacement_m", "dominant_lateral_wavelength_m",
    ):  # fmt: skip
        assert key in summary
    assert set(summary["peak_normal_force_N"]) == {"left", "right"}
