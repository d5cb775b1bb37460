"""Kinematic oscillation (Klingel) and the linear critical speed of a suspended conical wheelset.

Independent references:
* Klingel's formula for the kinematic wavelength of a conical wheelset, 2 pi sqrt(r0 e0 / lambda)
  (A.H. Wickens, Fundamentals of Rail Vehicle Dynamics, 2003; S. Iwnicki (ed.), Handbook of Railway
  Vehicle Dynamics, 2006), compared with the nonlinear 12-state simulation.
* The eigenvalues of the separately written linear 4-state lateral/yaw model (rigid_dynamics.wheelset.linear)
  give the critical speed; the nonlinear simulation must switch from decaying to growing oscillation there.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.wheelset.linear import creep_coefficients, critical_speed, linear_model_for_scene
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.simulate import simulate

R0, E0, LAM = 0.46, 0.75, 0.05


def test_klingel_wavelength():
    """No suspension, Kalker linear creep, 20 m/s, 3 mm start: wavelength within 1 % of 2 pi sqrt(r0 e0/lambda).

    The rail head radius is 50 mm, so the roll correction of the conicity (providers/conical.py) is 0.3 %.
    """
    scene = DynamicsScene(
        track=TrackGeometry(conicity=LAM, rail_head_radius_m=0.05),
        speed_m_per_s=20.0,
        duration_s=1.8,
        contact_model="linear",
        initial=InitialConditions(lateral_displacement_m=0.003),
    )
    result = simulate(scene)
    assert result.success, result.message
    klingel = 2 * math.pi * math.sqrt(R0 * E0 / LAM)
    measured = result.summary()["dominant_lateral_wavelength_m"]
    print(f"Klingel {klingel:.4f} m, simulated {measured:.4f} m, error {measured / klingel - 1:+.3%}")
    assert measured == pytest.approx(klingel, rel=0.01)
    # the unsuspended wheelset rolls without drifting off: |y| stays of the order of the start offset
    assert np.max(np.abs(result.states[:, 1])) < 0.006


def _growth_rate(result, skip_s=0.2):
    """Slope of ln|y| through the extremes of y(t) after ``skip_s`` (1/s)."""
    keep = result.t > skip_s
    t, y = result.t[keep], np.abs(result.states[keep, 1])
    peaks = [i for i in range(1, len(y) - 1) if y[i] >= y[i - 1] and y[i] >= y[i + 1]]
    assert len(peaks) >= 4, "too few oscillation extremes to fit a growth rate"
    return float(np.polyfit(t[peaks], np.log(y[peaks]), 1)[0])


def test_critical_speed_linear_vs_nonlinear():
    """Suspended wheelset (k_x = k_y = 0.5 MN/m per side): the nonlinear runs at 0.97 and 1.03 x the linear
    critical speed decay and grow, and the zero crossing of their growth rates is within 3 % of it."""
    scene = DynamicsScene(
        suspension=SuspensionParameters(longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5),
        track=TrackGeometry(conicity=LAM, rail_head_radius_m=0.05),
        contact_model="linear",
        duration_s=1.5,
        initial=InitialConditions(lateral_displacement_m=0.001),
        integrator=IntegratorSettings(output_step_s=2e-3),
    )
    f11, f22 = creep_coefficients(scene)
    linear = critical_speed(linear_model_for_scene(scene, f11, f22))
    classic = critical_speed(linear_model_for_scene(scene, f11, f22, classic=True))
    assert linear.success and classic.success
    speeds = [0.97 * linear.speed_m_per_s, 1.03 * linear.speed_m_per_s]
    rates = []
    for speed in speeds:
        result = simulate(replace(scene, speed_m_per_s=speed))
        assert result.success, result.message
        rates.append(_growth_rate(result))
    crossing = speeds[0] - rates[0] * (speeds[1] - speeds[0]) / (rates[1] - rates[0])
    print(
        f"critical speed: linear {linear.speed_m_per_s:.2f} m/s (classic model {classic.speed_m_per_s:.2f}), "
        f"nonlinear growth {rates} 1/s at {speeds} m/s -> {crossing:.2f} m/s"
    )
    assert rates[0] < 0 < rates[1]
    assert crossing == pytest.approx(linear.speed_m_per_s, rel=0.03)
