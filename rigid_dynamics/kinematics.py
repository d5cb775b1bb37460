"""Orientation and angular velocity of the wheelset (seed eq 1, 2, 68-70).

Frames. The main (track) frame has x along the track in the direction of travel, y lateral
to the right, z vertically downward (right-handed; the convention of Kalker and of the
SIMPACK/CONTACT profile files, whose z points into the rail). The wheelset frame has y_d
along the axle; a wheel point is x_d = [R cos(alpha), y_d, R sin(alpha)] (eq 7), so the
lowest point of a wheel (towards the rail) is at alpha = +pi/2.

Angles (eq 1): psi yaw about z, theta roll about the once-yawed x axis, phi the rotation
about the axle. The matrix that matches the seed's eq 2 is (REFERENCES.md)

    C_D = R_z(psi) @ R_x(theta) @ R_y(-phi),

mapping wheelset-frame coordinates to main-frame coordinates. With phi_dot > 0 the wheel
spins about -y_d, which with z downward is forward rolling (+x).
"""

from __future__ import annotations

import numpy as np


def rotation_x(angle_rad):
    """R_x(angle): rotation about x, shape (..., 3, 3)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rotation_y(angle_rad):
    """R_y(angle): rotation about y, shape (..., 3, 3)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rotation_z(angle_rad):
    """R_z(angle): rotation about z, shape (..., 3, 3)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def wheelset_rotation(yaw_rad, roll_rad, spin_rad):
    """C_D(psi, theta, phi) = R_z(psi) R_x(theta) R_y(-phi) (eq 1): wheelset frame -> main frame.

    Args:
        yaw_rad: psi, rad. roll_rad: theta, rad. spin_rad: phi, rad (scalars or broadcastable arrays).

    Returns:
        Array (..., 3, 3).
    """
    yaw, roll, spin = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (yaw_rad, roll_rad, spin_rad)))
    return rotation_z(yaw) @ rotation_x(roll) @ rotation_y(-spin)


def angular_velocity(yaw_rad, roll_rad, yaw_rate, roll_rate, spin_rate):
    """Angular velocity omega_D of the wheelset in the main frame (eq 2), rad/s.

    omega_x = theta' cos(psi) + phi' sin(psi) cos(theta)
    omega_y = theta' sin(psi) - phi' cos(psi) cos(theta)
    omega_z = psi' - phi' sin(theta)

    Rates in rad/s. Returns an array (..., 3). (It does not depend on phi.)
    """
    psi, theta = np.asarray(yaw_rad, float), np.asarray(roll_rad, float)
    return np.stack(
        np.broadcast_arrays(
            roll_rate * np.cos(psi) + spin_rate * np.sin(psi) * np.cos(theta),
            roll_rate * np.sin(psi) - spin_rate * np.cos(psi) * np.cos(theta),
            yaw_rate - spin_rate * np.sin(theta),
        ),
        axis=-1,
    )


def skew(vector):
    """Cross-product matrix Omega with Omega @ r = vector x r (the seed's Omega_D of eq 2)."""
    wx, wy, wz = np.moveaxis(np.asarray(vector, float), -1, 0)
    z = np.zeros_like(wx)
    return np.stack([np.stack([z, -wz, wy], -1), np.stack([wz, z, -wx], -1), np.stack([-wy, wx, z], -1)], -2)


def euler_accelerations(yaw_rad, roll_rad, yaw_rate, roll_rate, spin_rate, angular_acceleration):
    """Convert the angular acceleration alpha (main frame) to (psi'', theta'', phi'') (eq 68-70).

    psi''   = (a_x sin(psi) sin(theta) - a_y cos(psi) sin(theta) + a_z cos(theta)
               + psi' theta' sin(theta) + theta' phi') / cos(theta)
    phi''   = (a_x sin(psi) - a_y cos(psi) + psi' theta' + theta' phi' sin(theta)) / cos(theta)
    theta'' = a_x cos(psi) + a_y sin(psi) - psi' phi' cos(theta)

    This inverts d(omega_D)/dt of eq 2 exactly (singular at theta = +-pi/2, never reached by a
    wheelset on rails).

    Args:
        angular_acceleration: alpha = d(omega_D)/dt in the main frame, rad/s^2, shape (..., 3).

    Returns:
        (psi'', theta'', phi'') in rad/s^2.
    """
    psi, theta = np.asarray(yaw_rad, float), np.asarray(roll_rad, float)
    ax, ay, az = np.moveaxis(np.asarray(angular_acceleration, float), -1, 0)
    sp, cp, st, ct = np.sin(psi), np.cos(psi), np.sin(theta), np.cos(theta)
    yaw_acc = (ax * sp * st - ay * cp * st + az * ct + yaw_rate * roll_rate * st + roll_rate * spin_rate) / ct
    spin_acc = (ax * sp - ay * cp + yaw_rate * roll_rate + roll_rate * spin_rate * st) / ct
    roll_acc = ax * cp + ay * sp - yaw_rate * spin_rate * ct
    return yaw_acc, roll_acc, spin_acc
