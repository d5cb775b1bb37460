"""Steady rolling on ideal geometry (contact-geometry tables), 60 s simulated.

Independent references: statics (the vertical contact forces must carry the wheelset weight plus the axle load,
W = m g + F_axle, when nothing else carries vertical load: the vertical suspension has dampers only) and
symmetry (a stable wheelset started off-centre returns to the centre line and stays there: no drift).
"""

import numpy as np
import pytest

from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.simulate import simulate


def test_steady_rolling_60_s_on_tables():
    scene = DynamicsScene(
        track=TrackGeometry(conicity=0.05, rail_head_radius_m=0.05),
        suspension=SuspensionParameters(
            longitudinal_stiffness_N_per_m=5e5,
            lateral_stiffness_N_per_m=5e5,
            lateral_damping_N_s_per_m=1e4,
            vertical_damping_N_s_per_m=1e5,
        ),
        speed_m_per_s=30.0,
        duration_s=60.0,
        contact_model="linear",
        contact_provider="tables",
        initial=InitialConditions(lateral_displacement_m=5e-4),
        integrator=IntegratorSettings(method="Radau", max_step_s=1.0, output_step_s=0.05),
    )
    r = simulate(scene)
    assert r.success, r.message
    assert r.provider == "tables"
    weight = scene.wheelset.mass_kg * STANDARD_GRAVITY_M_PER_S2 + scene.loads.axle_load_N
    vertical = -r.contact_force_N[:, :, 2].sum(axis=1)
    late = r.t > 10.0
    print(f"vertical/W over the last 50 s: {vertical[late].min() / weight:.9f} .. {vertical[late].max() / weight:.9f}")
    assert vertical[late] == pytest.approx(weight, rel=1e-6)
    assert np.max(np.abs(r.states[late, 1])) < 1e-7  # back on the centre line, no drift
    assert np.max(np.abs(r.states[r.t > 50.0, 1])) < 1e-9
    assert r.states[-1, 0] == pytest.approx(60.0 * 30.0, rel=1e-6)  # the frame pulls it along at 30 m/s
