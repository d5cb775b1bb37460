"""The compiled RK4 path (rigid_dynamics.wheelset.compiled) against the Python path of the same equations.

Second implementation: the same scene integrated by the Python right-hand side (equations.py) and by the
compiled loop must give the same states and contact forces to round-off; the compiled path must report the
same safety statuses.
"""

from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.simulate import build_provider, simulate

SCENE = DynamicsScene(
    track=TrackGeometry(rail_head_radius_m=0.05),
    contact_provider="tables",
    speed_m_per_s=30.0,
    duration_s=0.1,
    suspension=SuspensionParameters(
        longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5, vertical_damping_N_s_per_m=1e5
    ),
    initial=InitialConditions(lateral_displacement_m=0.002, yaw_rate_rad_per_s=0.01, vertical_velocity_m_per_s=0.01),
    integrator=IntegratorSettings(method="RK4", fixed_step_s=5e-4, output_step_s=1e-3),
)


@pytest.mark.parametrize("model", ["hertz", "linear", "vermeulen-johnson"])
def test_compiled_equals_python(model):
    scene = replace(SCENE, contact_model=model)
    provider = build_provider(scene)
    fast = simulate(scene, provider=provider, compiled=True)
    slow = simulate(scene, provider=provider, compiled=False)
    assert fast.success and slow.success
    np.testing.assert_array_equal(fast.t, slow.t)
    scale = np.array([1, 1e-3, 1e-3, 1e-3, 1e-3, 1, 30, 1, 1, 1, 1, 60])
    np.testing.assert_allclose(fast.states / scale, slow.states / scale, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fast.contact_force_N, slow.contact_force_N, rtol=0, atol=1e-3)
    np.testing.assert_allclose(fast.work_contact_J, slow.work_contact_J, rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(fast.kinetic_energy_J, slow.kinetic_energy_J, rtol=1e-12)
    assert fast.events == slow.events
    assert fast.rhs_evaluations > 0


def test_compiled_stops_and_refuses():
    scene = replace(SCENE, contact_model="linear", integrator=replace(SCENE.integrator, fixed_step_s=0.02))
    result = simulate(scene, compiled=True)
    assert result.status in ("force-anomaly", "blow-up", "derailed", "contact-failed") and not result.success
    assert result.failure_state is not None and np.all(np.isfinite(result.states))
    with pytest.raises(ValueError, match="compiled = True: the compiled path needs method RK4"):
        simulate(replace(scene, integrator=IntegratorSettings(method="RK45")), compiled=True)
