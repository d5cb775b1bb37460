"""The suspension frame's held yaw (SuspensionParameters.frame_yaw_rad: a bogie frame's angle at its axle, the
angle of attack of flange climbing) in the one set of equations of motion (compiled_motion._assemble).

Reference: the closed form of the primary suspension's moment about z on a lifted wheelset (no contact, no yaw or
spin rate: no damping or gyroscopic term). With the frame's points at (x_f - s b sin psi_f, s b cos psi_f) and the
axle's at (x - s b sin psi, s b cos psi), per side s = +-1:
    M_z = 2 b^2 [k_x cos(psi) (sin psi_f - sin psi) + k_y sin(psi) (cos psi - cos psi_f)] - 2 k_psi (psi - psi_f),
    F_x = F_y = 0,
so the yaw acceleration is M_z / J and vanishes at psi = psi_f.

And with contact: the conical wheelset held at a small angle of attack on tangent track runs displaced sideways by
Kalker's linear-theory balance (closed form in the test's docstring).
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.wheelset.parameters import SuspensionParameters
from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel
from wheelrail.scenes import load_scene

KX, KY, KPSI = 3.0e7, 1.0e6, 2.0e5
FRAME_YAW = -0.0125


@pytest.fixture(scope="module")
def model():
    base = load_scene("hunting-conical")
    scene = replace(
        base,
        suspension=SuspensionParameters(
            longitudinal_stiffness_N_per_m=KX, lateral_stiffness_N_per_m=KY, yaw_stiffness_N_m_per_rad=KPSI,
            longitudinal_damping_N_s_per_m=1e4, lateral_damping_N_s_per_m=1e4, frame_yaw_rad=FRAME_YAW,
        ),
    )  # fmt: skip
    return WheelsetModel(scene, build_provider(scene), get_contact_model(scene.contact_model))


def _lifted(model, yaw):
    """The full state of the wheelset 0.1 m above its rails at the frame's x, rolling speed, no spin."""
    y = np.zeros(model.n_state)
    y[2] = -model.scene.wheelset.nominal_radius_m - 0.1  # z down: lifted
    y[3] = yaw
    y[6] = model.scene.speed_m_per_s  # the frame's speed: no longitudinal damping
    return y


@pytest.mark.parametrize("yaw", [0.0, FRAME_YAW, 0.004, -0.03])
def test_suspension_yaw_moment_against_the_closed_form(model, yaw):
    b = model.scene.wheelset.suspension_half_spacing_m
    jz = model.scene.wheelset.transverse_inertia_kg_m2
    out = model.derivative(0.0, _lifted(model, yaw))
    springs = KX * math.cos(yaw) * (math.sin(FRAME_YAW) - math.sin(yaw))
    springs += KY * math.sin(yaw) * (math.cos(yaw) - math.cos(FRAME_YAW))
    mz = 2 * b * b * springs - 2 * KPSI * (yaw - FRAME_YAW)
    assert out[9] == pytest.approx(mz / jz, rel=1e-9, abs=1e-9 * abs(2 * KX * b * b * FRAME_YAW) / jz)
    mass = model.scene.wheelset.mass_kg
    assert abs(out[7]) < 1e-9 * KX * b * abs(FRAME_YAW) / mass  # F_y = 0
    assert abs(out[6]) < 1e-9 * KX * b * abs(FRAME_YAW) / mass  # F_x = 0
    if yaw == FRAME_YAW:
        assert abs(out[9]) < 1e-9


@pytest.mark.parametrize("frame_yaw", [2.0e-4, -5.0e-4])
def test_a_held_angle_of_attack_on_tangent_track_against_linear_theory(frame_yaw):
    """The conical wheelset (hunting-conical, linear theory) with its frame held at a small yaw and stiff springs
    (k_x 1e8, k_y 5e6 N/m per side) runs steadily displaced sideways. In steady state the lateral creepage of each
    wheel is -psi (no lateral velocity), the two lateral creep forces sum to (f22_L + f22_R) psi (Kalker's linear
    theory, f22 = G a b C22; the spin parts cancel between the wheels) and the lateral springs and the gravitational
    stiffness W lambda_eff / e0 hold them:
        y = (f22_L + f22_R) psi / (2 k_y + W lambda_eff / e0),
    with psi the wheelset's own yaw (the springs yield by about 2 %) and f22 from each patch's recorded semi-axes and
    Kalker's C22 (rigid_dynamics.contact.kalker, his table). Measured within 0.3 %; asserted within 1 %.
    """
    from rigid_dynamics.contact.kalker import kalker_coefficients
    from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2
    from rigid_dynamics.wheelset.simulate import simulate
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    ky = 5.0e6
    path = resolve_scene_path("hunting-conical")
    doc = read_toml(path, "scene file")
    doc["duration_s"] = 1.0
    doc["suspension"].update(
        longitudinal_stiffness_N_per_m=1e8, lateral_stiffness_N_per_m=ky, longitudinal_damping_N_s_per_m=1e5,
        lateral_damping_N_s_per_m=1e5, frame_yaw_rad=frame_yaw,
    )  # fmt: skip
    doc["initial"].update(lateral_displacement_m=0.0, yaw_rad=frame_yaw)
    scene = parse_scene(doc, base_dir=path.parent)
    result = simulate(scene)
    assert result.status == "ok", result.message
    lateral, yaw = result.states[-1, 1], result.states[-1, 3]
    assert abs(result.states[-10, 1] / lateral - 1) < 1e-4  # steady
    assert abs(yaw / frame_yaw - 1) < 0.05
    semi_a = result.patches["semi_axis_long_m"][-1, :, 0]
    semi_b = result.patches["semi_axis_lat_m"][-1, :, 0]
    material, track, ws = scene.material, scene.track, scene.wheelset
    f22 = sum(
        material.shear_modulus_Pa * a * b * float(kalker_coefficients(a / b, material.poisson_ratio).c22)
        for a, b in zip(semi_a, semi_b, strict=True)
    )
    lam_eff = track.conicity / (1 - track.conicity * track.rail_head_radius_m / ws.contact_half_distance_m)
    weight = ws.mass_kg * STANDARD_GRAVITY_M_PER_S2 + scene.loads.axle_load_N
    expected = f22 * yaw / (2 * ky + weight * lam_eff / ws.contact_half_distance_m)
    assert lateral == pytest.approx(expected, rel=0.01)
