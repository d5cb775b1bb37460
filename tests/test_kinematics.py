"""Kinematics (eq 1, 2, 68-70) checked against the derivative of C_D itself.

Independent reference: omega_D must satisfy dC_D/dt = Omega_D C_D (skew-symmetric Omega_D),
computed here by central differences of the rotation matrix along a smooth angle history;
and eq 68-70 must invert the time derivative of eq 2 (differentiated numerically). Every term
of eq 2 and eq 68-70 is exercised by generic angles and rates, so an error in any one term fails.
"""

import numpy as np
import pytest

from rigid_dynamics.kinematics import angular_velocity, euler_accelerations, skew, wheelset_rotation


def angles(t):
    """A smooth, generic history of (psi, theta, phi) with all rates and accelerations nonzero."""
    psi = 0.3 + 0.7 * np.sin(1.3 * t) + 0.2 * t**2
    theta = -0.2 + 0.4 * np.cos(0.9 * t) + 0.1 * t
    phi = 1.1 + 2.3 * t + 0.5 * np.sin(2.1 * t)
    return psi, theta, phi


def rates(t, h=1e-5):
    a0 = np.array(angles(t - h))
    a1 = np.array(angles(t + h))
    am = np.array(angles(t))
    return am, (a1 - a0) / (2 * h), (a1 - 2 * am + a0) / h**2


@pytest.mark.parametrize("t", [0.0, 0.37, 1.9])
def test_rotation_is_orthonormal_and_matches_eq1_convention(t):
    psi, theta, phi = angles(t)
    c = wheelset_rotation(psi, theta, phi)
    np.testing.assert_allclose(c @ c.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(c) == pytest.approx(1.0)
    # Yaw alone rotates the axle (y_d) towards -x for positive psi: R_z(psi) e_y = (-sin, cos, 0).
    np.testing.assert_allclose(wheelset_rotation(psi, 0, 0)[:, 1], [-np.sin(psi), np.cos(psi), 0], atol=1e-15)


@pytest.mark.parametrize("t", [0.0, 0.37, 1.9])
def test_eq2_is_angular_velocity_of_C_D(t):
    h = 1e-6
    c_dot = (wheelset_rotation(*angles(t + h)) - wheelset_rotation(*angles(t - h))) / (2 * h)
    (psi, theta, _), (dpsi, dtheta, dphi), _ = rates(t)
    omega = angular_velocity(psi, theta, dpsi, dtheta, dphi)
    np.testing.assert_allclose(skew(omega) @ wheelset_rotation(*angles(t)), c_dot, atol=2e-7)


def test_forward_rolling_spins_about_minus_axle():
    # phi' > 0 at zero yaw and roll: omega = -phi' e_y; with z down the wheel centre, above the
    # contact point by -R e_z, moves forward (+x) relative to the contact point.
    omega = angular_velocity(0.0, 0.0, 0.0, 0.0, 10.0)
    np.testing.assert_allclose(omega, [0, -10, 0])
    velocity_centre_rel_contact = np.cross(omega, [0.0, 0.0, -0.46])
    assert velocity_centre_rel_contact[0] > 0


@pytest.mark.parametrize("t", [0.0, 0.37, 1.9])
def test_eq68_70_invert_derivative_of_eq2(t):
    h = 1e-5
    (psi, theta, _), (dpsi, dtheta, dphi), (ddpsi, ddtheta, ddphi) = rates(t)

    def omega_at(s):
        (p, th, _), (dp, dth, dph), _ = rates(s)
        return angular_velocity(p, th, dp, dth, dph)

    alpha = (omega_at(t + h) - omega_at(t - h)) / (2 * h)
    got = euler_accelerations(psi, theta, dpsi, dtheta, dphi, alpha)
    np.testing.assert_allclose(got, [ddpsi, ddtheta, ddphi], rtol=2e-4, atol=2e-4)


def test_vectorised_shapes():
    psi = np.linspace(-0.1, 0.1, 5)
    c = wheelset_rotation(psi, 0.01, np.linspace(0, 1, 5))
    assert c.shape == (5, 3, 3)
    assert angular_velocity(psi, 0.0, 1.0, 2.0, 3.0).shape == (5, 3)
