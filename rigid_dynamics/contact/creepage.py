"""Rigid creepages of a wheel contact point from the wheelset's motion (seed eq 39-49).

The rail does not move, so the rigid slip of a patch is the velocity of the wheel's material
point at the contact point, seen in the contact frame, divided by the rolling speed:

* rolling velocity (eq 39): v_rol = [x_t', 0, 0] (the forward velocity of the wheelset centre),
  or any vector the caller passes;
* its projection on the contact plane (eq 40) v_p = v_rol - (v_rol . n) n, rolling speed (eq 41)
  V = |v_p|;
* the contact frame is the common principal frame rotated about n by eps_rol = atan2(v_p.t2, v_p.t1)
  (eq 42-43) so that its x axis is along v_p. That frame depends on n and v_rol only:
  e_x = v_p / V, e_z = n, e_y = e_z x e_x (right-handed);
* velocity of the wheel's material point (eq 44): x_w' = Omega_D C_D x_d + x_t' = omega_D x r + x_t';
* creepages (eq 45-49): longitudinal xi = x_w'.e_x / V, lateral eta = x_w'.e_y / V,
  spin phi = omega_D . n / V (1/m).

Frames and signs. Main frame: x along the track, y to the right, z down (kinematics.py). The contact
frame's z axis is the common normal pointing from the rail INTO the wheel (up, at a tread contact), so
at a tread contact its y axis points to the LEFT of the direction of travel (main -y). Example, hand-derived
in tests/test_creepage.py: a wheel of radius r rolling forward at speed V with spin rate phi' and no yaw
has xi = (V - phi' r)/V, so a braking wheel (phi' r < V) has xi > 0 and a driving wheel xi < 0; the creep
force on the wheel opposes xi (eq 50). The right wheel of a conical wheelset (cone angle gamma,
radius growing towards the flange) has n = (0, -sin gamma, -cos gamma) and spin +sin(gamma)/r; the left
wheel -sin(gamma)/r. A yaw psi > 0 (R_z(psi): the wheels head towards main +y) makes the contact point's
material slide towards main -y, which is the contact frame's +y: eta = +psi cos(gamma) at small angles (exact
expressions in the test).

Symbols: x_d contact point in the wheelset frame (eq 7), m; C_D wheelset rotation (eq 1); omega_D angular
velocity (eq 2) in the main frame, rad/s; x_t' centre velocity, m/s; n unit normal rail -> wheel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.types import Creepage


@dataclass(frozen=True, eq=False)
class PatchKinematics:
    """Creepages of one or many contact points (arrays of the batch shape ``S``).

    Attributes:
        longitudinal: xi, dimensionless, shape S.
        lateral: eta, dimensionless, shape S.
        spin_1_per_m: phi, 1/m, shape S.
        rolling_speed_m_per_s: V = |v_p| (eq 41), m/s, shape S.
        contact_frame: columns e_x (rolling), e_y, e_z (= n, rail -> wheel) in the main frame, shape S + (3, 3).
        slip_velocity_m_per_s: velocity of the wheel's material point in the contact frame (x, y, z), m/s,
            shape S + (3,). The z component is the rate of approach (0 for a wheel that stays on the rail).
        rolling_angle_rad: eps_rol (eq 42), angle from the first axis of the given principal frame to the
            rolling direction about n, shape S; 0 when no principal frame was given.
    """

    longitudinal: np.ndarray
    lateral: np.ndarray
    spin_1_per_m: np.ndarray
    rolling_speed_m_per_s: np.ndarray
    contact_frame: np.ndarray
    slip_velocity_m_per_s: np.ndarray
    rolling_angle_rad: np.ndarray

    def creepage(self, index: int | tuple = ()) -> Creepage:
        """The :class:`Creepage` of one contact point (``index`` into the batch; ``()`` for a scalar batch).

        Raises:
            ValueError: the rolling speed is zero (creepages are undefined) or not finite.
        """
        return Creepage(
            longitudinal=float(self.longitudinal[index]),
            lateral=float(self.lateral[index]),
            spin_1_per_m=float(self.spin_1_per_m[index]),
            rolling_speed_m_per_s=float(self.rolling_speed_m_per_s[index]),
        )


def _as_vectors(name: str, value, last: tuple[int, ...]) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.shape[array.ndim - len(last) :] != last:
        raise ValueError(f"{name} has shape {array.shape}: expected (..., {', '.join(map(str, last))})")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} = {value!r}: expected finite numbers")
    return array


def contact_frame(normal_rail_to_wheel, rolling_velocity_m_per_s) -> tuple[np.ndarray, np.ndarray]:
    """Contact frame with x along the rolling velocity projected on the contact plane (eq 40-43).

    Args:
        normal_rail_to_wheel: n, shape (..., 3) (normalised here).
        rolling_velocity_m_per_s: v_rol, shape (..., 3) broadcastable to n.

    Returns:
        (frame, V): frame (..., 3, 3) with columns e_x, e_y = n x e_x, e_z = n; V = |v_p| (..., ), m/s.
        Where V = 0 (standstill) e_x is the main x axis projected on the contact plane instead.
    """
    n = np.asarray(normal_rail_to_wheel, float)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    v = np.asarray(rolling_velocity_m_per_s, float)
    v, n = np.broadcast_arrays(v, n)
    v_p = v - np.sum(v * n, axis=-1, keepdims=True) * n
    speed = np.linalg.norm(v_p, axis=-1)
    still = speed <= 1e-300
    if np.any(still):
        fallback = np.array([1.0, 0.0, 0.0]) - n[..., 0:1] * n
        v_p = np.where(still[..., None], fallback, v_p)
    e_x = v_p / np.linalg.norm(v_p, axis=-1, keepdims=True)
    e_y = np.cross(n, e_x)
    e_x, e_y, n = np.broadcast_arrays(e_x, e_y, n)
    return np.stack([e_x, e_y, n], axis=-1), speed


def patch_kinematics(
    contact_point_wheelset_m,
    wheelset_rotation,
    angular_velocity_rad_per_s,
    centre_velocity_m_per_s,
    normal_rail_to_wheel,
    *,
    rolling_velocity_m_per_s=None,
    principal_frame=None,
) -> PatchKinematics:
    """Creepages of wheel contact points from the wheelset state (eq 39-49), vectorised over points.

    Args:
        contact_point_wheelset_m: x_d, contact point in the wheelset frame (eq 7), shape (..., 3), m.
        wheelset_rotation: C_D (eq 1), wheelset -> main frame, shape (3, 3) or (..., 3, 3).
        angular_velocity_rad_per_s: omega_D (eq 2), main frame, shape (3,), rad/s.
        centre_velocity_m_per_s: x_t' (eq 4), main frame, shape (3,), m/s.
        normal_rail_to_wheel: n, unit normal of the contact plane from the rail into the wheel, main frame,
            shape (..., 3).
        rolling_velocity_m_per_s: v_rol (main frame, (3,)); default [x_t', 0, 0] (eq 39).
        principal_frame: optional common principal frame C_PS (..., 3, 3) (eq 31; third column +-n), only
            used to report eps_rol (eq 42).

    Returns:
        :class:`PatchKinematics`. Where the rolling speed is 0 the creepages are not finite (the caller
        decides how to regularise; ``slip_velocity_m_per_s`` stays finite).

    Raises:
        ValueError: an argument has the wrong shape or is not finite.
    """
    x_d = _as_vectors("contact_point_wheelset_m", contact_point_wheelset_m, (3,))
    c_d = _as_vectors("wheelset_rotation", wheelset_rotation, (3, 3))
    omega = _as_vectors("angular_velocity_rad_per_s", angular_velocity_rad_per_s, (3,))
    v_c = _as_vectors("centre_velocity_m_per_s", centre_velocity_m_per_s, (3,))
    n = _as_vectors("normal_rail_to_wheel", normal_rail_to_wheel, (3,))
    if rolling_velocity_m_per_s is None:
        v_rol = np.zeros_like(v_c)
        v_rol[..., 0] = v_c[..., 0]
    else:
        v_rol = _as_vectors("rolling_velocity_m_per_s", rolling_velocity_m_per_s, (3,))

    lever = np.einsum("...ij,...j->...i", c_d, x_d)  # r_con = C_D x_d (eq 65)
    velocity = np.cross(omega, lever) + v_c  # eq 44
    frame, speed = contact_frame(n, v_rol)
    local = np.einsum("...ji,...j->...i", frame, velocity)  # frame^T x_w' (eq 45)
    spin_rate = np.einsum("...i,...i->...", np.broadcast_to(omega, n.shape), frame[..., :, 2])  # eq 46
    with np.errstate(invalid="ignore", divide="ignore"):
        xi = local[..., 0] / speed
        eta = local[..., 1] / speed
        spin = spin_rate / speed
    if principal_frame is None:
        angle = np.zeros_like(speed)
    else:
        c_ps = _as_vectors("principal_frame", principal_frame, (3, 3))
        e_x = frame[..., :, 0]
        angle = np.arctan2(
            np.einsum("...i,...i->...", e_x, c_ps[..., :, 1]), np.einsum("...i,...i->...", e_x, c_ps[..., :, 0])
        )
    return PatchKinematics(
        longitudinal=xi,
        lateral=eta,
        spin_1_per_m=spin,
        rolling_speed_m_per_s=speed,
        contact_frame=frame,
        slip_velocity_m_per_s=local,
        rolling_angle_rad=angle,
    )


def wheelset_creepage(
    contact_point_wheelset_m,
    normal_rail_to_wheel,
    *,
    yaw_rad: float,
    roll_rad: float,
    spin_angle_rad: float = 0.0,
    centre_velocity_m_per_s,
    yaw_rate_rad_per_s: float = 0.0,
    roll_rate_rad_per_s: float = 0.0,
    spin_rate_rad_per_s: float,
) -> PatchKinematics:
    """Same as :func:`patch_kinematics`, from the wheelset's angles and rates (C_D by eq 1, omega_D by eq 2).

    Forward rolling has spin_rate_rad_per_s > 0 (free rolling: V / r0).
    """
    from rigid_dynamics.kinematics import angular_velocity, wheelset_rotation

    c_d = wheelset_rotation(yaw_rad, roll_rad, spin_angle_rad)
    omega = angular_velocity(yaw_rad, roll_rad, yaw_rate_rad_per_s, roll_rate_rad_per_s, spin_rate_rad_per_s)
    return patch_kinematics(contact_point_wheelset_m, c_d, omega, centre_velocity_m_per_s, normal_rail_to_wheel)
