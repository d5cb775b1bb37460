"""Integrators, invariants and safety stops of the wheelset simulation.

Independent references: the classical Runge-Kutta method is of order 4 (observed order fitted over four step
sizes against a DOP853 run at rtol 1e-12); conservation of mechanical energy T + V_g + U_Hertz + U_springs -
F_axle z for an undamped, frictionless case (U_Hertz = (2/5) N q for every patch, Johnson 1985 eq 4.23 integrated);
a pure sine for the wavelength estimate. The safety tests check the documented statuses.
"""

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact.types import ContactResult
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.providers import PatchSet
from rigid_dynamics.wheelset.simulate import dominant_wavelength_m, save_timeseries, simulate

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


@pytest.mark.parametrize(("method", "rtol"), [("RK45", 1e-7), ("DOP853", 1e-9), ("Radau", 1e-7), ("LSODA", 1e-8)])
def test_adaptive_methods_agree_to_tolerance(reference, method, rtol):
    state = final_state(method=method, relative_tolerance=rtol, absolute_tolerance=rtol * 1e-3)
    scale = np.array([BASE.initial.lateral_displacement_m, BASE.wheelset.nominal_radius_m])
    error = np.abs(state[[1, 2]] - reference[[1, 2]]) / scale
    print(f"{method} rtol {rtol:g}: relative error {error}")
    assert np.all(error < 300 * rtol)


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
    assert r.status in ("blow-up", "force-anomaly", "contact-failed", "derailed"), r.status
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
