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
    Irregularities,
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


IRREGULARITIES = {
    "none": Irregularities(),
    "polygon": Irregularities(polygon_order=3, polygon_amplitude_m=3e-4),
    "flat": Irregularities(flat_length_m=0.05),
    "corrugation-right": Irregularities(corrugation_wavelength_m=0.05, corrugation_amplitude_m=3e-5, side="right"),
}


@pytest.mark.parametrize(
    ("model", "irregularity"),
    [
        ("hertz", "none"),
        ("linear", "none"),
        ("vermeulen-johnson", "none"),
        ("fastsim", "none"),
        ("fastsim-10x6", "none"),
        ("fastsim", "polygon"),
        ("vermeulen-johnson", "flat"),
        ("linear", "corrugation-right"),
    ],
)
def test_compiled_equals_python(model, irregularity):
    """FASTSIM (the contact package's strip kernel) and the running-direction irregularities (polygon, rounded flat,
    corrugation on one side) evaluated in the compiled loop must equal the Python path (providers and batch kernels)."""
    scene = replace(SCENE, contact_model=model, irregularities=IRREGULARITIES[irregularity])
    if model == "fastsim-10x6":  # the scene's FASTSIM grid reaches both paths
        scene = replace(scene, contact_model="fastsim", fastsim_elements_per_strip=10, fastsim_strips=6)
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
    for name in ("approach_m", "rolling_radius_m", "semi_axis_long_m", "creepage_lat", "spin_creepage_1_per_m"):
        np.testing.assert_allclose(fast.patches[name], slow.patches[name], rtol=1e-9, atol=1e-15, err_msg=name)
    np.testing.assert_allclose(fast.patches["creep_force_lat_N"], slow.patches["creep_force_lat_N"], rtol=0, atol=1e-3)
    if model == "fastsim-10x6":
        fine = simulate(replace(scene, fastsim_elements_per_strip=20, fastsim_strips=20), provider=provider)
        assert np.nanmax(np.abs(fine.patches["creep_force_lat_N"] - fast.patches["creep_force_lat_N"])) > 1.0


def test_compiled_stops_and_refuses():
    scene = replace(SCENE, contact_model="linear", integrator=replace(SCENE.integrator, fixed_step_s=0.02))
    result = simulate(scene, compiled=True)
    # a 20 ms step is far beyond RK4's stability limit: the failure is named as the integrator's (stability.py)
    assert result.status == "step-unstable" and not result.success
    assert "stability limit" in result.message
    assert result.failure_state is not None and np.all(np.isfinite(result.states))
    with pytest.raises(ValueError, match="compiled = True: the compiled path needs method RK4"):
        simulate(replace(scene, integrator=IntegratorSettings(method="RK45")), compiled=True)
