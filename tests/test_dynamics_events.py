"""Flange-contact onset on real profiles (S1002 on UIC60 1:40, contact-geometry tables).

Independent reference: the profile geometry itself. The profile section (tested against the 3-D search in
test_dynamics_search.py) puts the right wheel's contact on the flange (contact angle > 0.5 rad) for shifts
beyond about 5.5 mm; a wheelset thrown to the right (5 mm, 0.3 m/s) must report a "flange-contact" event on
the right side at the time its contact angle first exceeds the threshold, and none on the left.
"""

import numpy as np

from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.simulate import simulate


def test_flange_contact_event():
    scene = DynamicsScene(
        track=TrackGeometry(wheel_profile="S1002", rail_profile="UIC60", rail_inclination_rad=0.025),
        suspension=SuspensionParameters(vertical_damping_N_s_per_m=1e5),
        contact_model="vermeulen-johnson",
        contact_provider="tables",
        speed_m_per_s=20.0,
        duration_s=0.05,
        # thrown: no free-rolling yaw rate (that would steer the wheelset back before the flange)
        initial=InitialConditions(lateral_displacement_m=0.005, lateral_velocity_m_per_s=0.3, free_rolling=False),
        integrator=IntegratorSettings(method="RK4", fixed_step_s=2.5e-4, output_step_s=5e-4),
    )
    result = simulate(scene)
    assert result.success, result.message
    flange = [e for e in result.events if e[0] == "flange-contact"]
    assert flange and all(side == "right" for _, side, _ in flange)
    angle = np.nanmax(
        np.where(result.patches["normal_force_N"][:, 1] > 0, result.patches["contact_angle_rad"][:, 1], 0), axis=1
    )
    first = result.t[np.argmax(angle > scene.track.flange_contact_angle_rad)]
    assert flange[0][2] == first
    assert np.max(result.states[:, 1]) > 0.0055
