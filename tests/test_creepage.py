"""Creepages from the wheelset kinematics (eq 39-49) against hand-derived values.

Hand derivation (conical wheelset, roll theta = 0, spin angle phi = 0 at the instant).
Right wheel, cone angle gamma (radius grows towards the flange, i.e. towards main -y), contact point at the
lowest point of the wheel x_d = (0, b, r) (eq 7 with alpha = pi/2). Yaw psi, yaw rate psi', spin rate Phi,
centre velocity (V, v_y, v_z).

* C_D = R_z(psi): r = C_D x_d = (-b sin psi, b cos psi, r).
* omega_D (eq 2, theta = 0) = (Phi sin psi, -Phi cos psi, psi'), so
  omega x r = -u (cos psi, sin psi, 0) with u = Phi r + psi' b: the material point moves backwards along the
  wheel's heading e_h = (cos psi, sin psi, 0). Velocity x_w' = (V, v_y, v_z) - u e_h.
* Wheel normal, rail -> wheel: n = C_D (0, -sin gamma, -cos gamma) = (s_psi s_g, -c_psi s_g, -c_g); e_h . n = 0.
* Rolling velocity V e_x projected: v_p = V (e_x - s n) with s = sin psi sin gamma; |v_p| = V sqrt(1 - s^2).
  e_x' = (e_x - s n)/sqrt(1 - s^2), e_y' = n x e_x' = (0, -cos gamma, cos psi sin gamma)/sqrt(1 - s^2).
* Hence, with D = V (1 - s^2):
    xi  = [V - u cos psi - s (V s - v_y cos psi sin gamma - v_z cos gamma)] / D
    eta = [-(v_y - u sin psi) cos gamma + v_z cos psi sin gamma] / D
    phi = (Phi sin gamma - psi' cos gamma) / (V sqrt(1 - s^2))
  Linearised (small psi, Phi = V/r0, v_z = 0): xi = (r0 - r)/r0 - psi' b / V, eta = (psi - v_y/V) cos gamma,
  phi = sin(gamma)/r0 - psi' cos(gamma)/V.
The left wheel is the mirror image: x_d = (0, -b, r), n = C_D (0, +sin gamma, -cos gamma); the same steps give
the spin -sin(gamma)/r0 and xi = (r0 - r)/r0 + psi' b/V.

A second, independent check with roll: the velocity of the material point equals the time derivative of
x_t(t) + C_D(psi(t), theta(t), phi(t)) x_d computed by central differences.
"""

import numpy as np
import pytest

from rigid_dynamics.contact.creepage import contact_frame, patch_kinematics, wheelset_creepage
from rigid_dynamics.contact.types import Creepage
from rigid_dynamics.kinematics import wheelset_rotation


def hand_creepages(psi, dpsi, spin_rate, speed, v_y, v_z, r, gamma, b, side):
    u = spin_rate * r + dpsi * b * (1 if side == "right" else -1)
    sg = np.sin(gamma) * (1 if side == "right" else -1)  # the normal's lateral tilt mirrors
    s = np.sin(psi) * sg
    d = speed * (1 - s**2)
    xi = (speed - u * np.cos(psi) - s * (speed * s - v_y * np.cos(psi) * sg - v_z * np.cos(gamma))) / d
    eta = (-(v_y - u * np.sin(psi)) * np.cos(gamma) + v_z * np.cos(psi) * sg) / d
    spin = (spin_rate * sg - dpsi * np.cos(gamma)) / (speed * np.sqrt(1 - s**2))
    return xi, eta, spin


@pytest.mark.parametrize("side", ["right", "left"])
def test_yawed_shifted_conical_wheelset_matches_hand_derivation(side):
    r0, gamma, b = 0.46, np.arctan(1 / 20), 0.75
    shift = 0.004  # lateral shift to the right: right wheel rolls on a smaller radius
    r = r0 - np.tan(gamma) * shift if side == "right" else r0 + np.tan(gamma) * shift
    psi, dpsi, speed, v_y, v_z = 0.012, 0.03, 20.0, 0.15, -0.02
    spin_rate = speed / r0
    sign = 1 if side == "right" else -1
    x_d = np.array([0.0, sign * b, r])
    n = wheelset_rotation(psi, 0.0, 0.0) @ np.array([0.0, -sign * np.sin(gamma), -np.cos(gamma)])
    got = wheelset_creepage(
        x_d,
        n,
        yaw_rad=psi,
        roll_rad=0.0,
        centre_velocity_m_per_s=[speed, v_y, v_z],
        yaw_rate_rad_per_s=dpsi,
        spin_rate_rad_per_s=spin_rate,
    )
    xi, eta, spin = hand_creepages(psi, dpsi, spin_rate, speed, v_y, v_z, r, gamma, b, side)
    assert got.longitudinal == pytest.approx(xi, rel=1e-12, abs=1e-15)
    assert got.lateral == pytest.approx(eta, rel=1e-12, abs=1e-15)
    assert got.spin_1_per_m == pytest.approx(spin, rel=1e-12)
    s = np.sin(psi) * np.sin(gamma)
    assert got.rolling_speed_m_per_s == pytest.approx(speed * np.sqrt(1 - s**2), rel=1e-14)
    # Linearised forms (error of second order in psi: u cos(psi)/V = 1 - psi^2/2 + ...).
    assert got.longitudinal == pytest.approx((r0 - r) / r0 - sign * dpsi * b / speed, abs=psi**2)
    assert got.lateral == pytest.approx((psi - v_y / speed) * np.cos(gamma), abs=1e-4)
    assert got.spin_1_per_m == pytest.approx(sign * np.sin(gamma) / r0 - dpsi * np.cos(gamma) / speed, rel=1e-3)
    creepage = got.creepage()
    assert isinstance(creepage, Creepage) and creepage.longitudinal == pytest.approx(xi, rel=1e-12)


def test_pure_rolling_has_zero_creepage_and_braking_is_positive():
    # Cylinder r = 0.5 rolling at V = phi' r: no slip; braking (phi' r < V) gives xi > 0 (force on wheel < 0).
    for spin_rate, expected in ((20.0, 0.0), (19.0, 0.05), (21.0, -0.05)):
        got = wheelset_creepage(
            [0, 0.75, 0.5],
            [0, 0, -1],
            yaw_rad=0.0,
            roll_rad=0.0,
            centre_velocity_m_per_s=[10.0, 0, 0],
            spin_rate_rad_per_s=spin_rate,
        )
        assert got.longitudinal == pytest.approx(expected, abs=1e-14)
        assert got.lateral == pytest.approx(0.0, abs=1e-14)
        assert got.spin_1_per_m == pytest.approx(0.0, abs=1e-14)
        np.testing.assert_allclose(got.contact_frame, np.diag([1.0, -1.0, -1.0]), atol=1e-15)


def angles(t):
    return 0.01 + 0.02 * t, -0.003 + 0.004 * t, 0.7 + 40.0 * t  # psi, theta, phi


def centre(t):
    return np.array([15.0 * t, 0.002 + 0.1 * t, -0.46 - 0.01 * t])


def test_material_point_velocity_matches_time_derivative_with_roll():
    """Second method: d/dt (x_t + C_D(t) x_d) by central differences, x_d fixed in the spinning wheelset."""
    x_d = np.array([[0.05, 0.74, 0.45], [-0.02, -0.76, 0.47]])
    n = np.array([[0.01, -0.05, -1.0], [0.0, 0.3, -0.95]])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    h = 1e-6
    rates = (np.array(angles(h)) - np.array(angles(-h))) / (2 * h)

    def position(t):
        return centre(t) + x_d @ wheelset_rotation(*angles(t)).T

    velocity = (position(h) - position(-h)) / (2 * h)
    psi, theta, phi = angles(0.0)
    got = wheelset_creepage(
        x_d,
        n,
        yaw_rad=psi,
        roll_rad=theta,
        spin_angle_rad=phi,
        centre_velocity_m_per_s=(centre(h) - centre(-h)) / (2 * h),
        yaw_rate_rad_per_s=rates[0],
        roll_rate_rad_per_s=rates[1],
        spin_rate_rad_per_s=rates[2],
    )
    frame = got.contact_frame
    expected_local = np.einsum("pji,pj->pi", frame, velocity)
    np.testing.assert_allclose(got.slip_velocity_m_per_s, expected_local, atol=1e-6)
    np.testing.assert_allclose(got.longitudinal, expected_local[:, 0] / got.rolling_speed_m_per_s, atol=1e-7)
    # The frame is right-handed, orthonormal, with e_z = n and e_x along the projected forward direction.
    np.testing.assert_allclose(
        np.einsum("pji,pjk->pik", frame, frame), np.broadcast_to(np.eye(3), (2, 3, 3)), atol=1e-14
    )
    np.testing.assert_allclose(np.linalg.det(frame), 1.0, atol=1e-14)
    np.testing.assert_allclose(frame[:, :, 2], n, atol=1e-15)
    assert np.all(frame[:, 0, 0] > 0.99)


def test_rolling_angle_relative_to_principal_frame():
    n = np.array([0.0, 0.0, -1.0])
    eps = 0.3
    principal = np.array([[np.cos(eps), np.sin(eps), 0], [-np.sin(eps), np.cos(eps), 0], [0, 0, 1.0]]).T
    principal[:, 2] = n
    principal[:, 1] = np.cross(n, principal[:, 0])
    got = patch_kinematics([0, 0, 0.5], np.eye(3), [0, -2.0, 0], [1.0, 0, 0], n, principal_frame=principal)
    # eps_rol (eq 42) is the angle of e_x = main x from the principal frame's first axis, about n.
    e1, e2 = principal[:, 0], principal[:, 1]
    assert got.rolling_angle_rad == pytest.approx(np.arctan2(e2[0], e1[0]), abs=1e-15)
    assert abs(got.rolling_angle_rad) == pytest.approx(eps, abs=1e-14)


def test_zero_rolling_speed_gives_nonfinite_creepage_but_finite_slip():
    got = patch_kinematics([0, 0.75, 0.46], np.eye(3), [0, -1.0, 0], [0, 0, 0], [0, 0, -1])
    assert not np.isfinite(got.longitudinal)
    assert np.all(np.isfinite(got.slip_velocity_m_per_s))
    with pytest.raises(ValueError, match="rolling_speed_m_per_s|longitudinal"):
        got.creepage()


def test_contact_frame_shapes_broadcast():
    frame, speed = contact_frame(np.tile([0, 0.1, -1.0], (4, 1)), [2.0, 0, 0])
    assert frame.shape == (4, 3, 3) and speed.shape == (4,)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"contact_point_wheelset_m": [0, 1]}, "contact_point_wheelset_m has shape"),
        ({"wheelset_rotation": np.eye(2)}, "wheelset_rotation has shape"),
        ({"angular_velocity_rad_per_s": [0, np.nan, 0]}, "angular_velocity_rad_per_s .* finite"),
        ({"centre_velocity_m_per_s": [1.0]}, "centre_velocity_m_per_s has shape"),
        ({"normal_rail_to_wheel": [0, 0, np.inf]}, "normal_rail_to_wheel .* finite"),
    ],
)
def test_bad_input_raises(kwargs, match):
    args = {
        "contact_point_wheelset_m": [0, 0.75, 0.46],
        "wheelset_rotation": np.eye(3),
        "angular_velocity_rad_per_s": [0, -40.0, 0],
        "centre_velocity_m_per_s": [20.0, 0, 0],
        "normal_rail_to_wheel": [0, 0, -1.0],
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        patch_kinematics(**args)
