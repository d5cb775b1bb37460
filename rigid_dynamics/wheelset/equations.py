"""Equations of motion of the rigid wheelset (seed eq 59-71) and its state function.

State (12, SI): q = [x, y, z, psi, theta, phi, x', y', z', psi', theta', phi'] with the centre of mass
x_t = (x, y, z) in the main frame (x along the track, y right, z down) and the angles of
C_D = R_z(psi) R_x(theta) R_y(-phi) (kinematics.py). Internally two work integrals are appended
(W_contact, W_exterior, J) so that the energy balance can be checked; they are not part of the
mechanical state.

Right-hand side, for every contact candidate with approach q > 0 (the provider gives point,
normal and curvatures; creepages by eq 39-49, rigid_dynamics.contact.creepage):

* the contact model returns N, T_x, T_y, M_z on the wheel in the contact frame (x rolling, y = n x e_x,
  z = n from rail into wheel). Main frame (eq 59-62): F_con = [e_x e_y n] [T_x, T_y, N]^T,
  M_con = M_z n. (The contact frame is already aligned with the rolling direction, so T_rol = I.)
* lever arm (eq 65): r_con = x_w - x_t.
* exterior forces (eq 63-64): primary suspension (parameters.SuspensionParameters), the axle load
  (+z at the centre), a traction/braking torque -T C_D e_y about the axle.
* Newton (eq 66): m x_t'' = sum F_con + F_e + m g e_z (z down, so gravity is +g e_z).
* Euler (eq 67 with the gyroscopic term): the angular momentum in the main frame is L = J omega with
  J = C_D J_body C_D^T, J_body = diag(J_t, J_a, J_t) (axle along y_d; axisymmetric, so J does not
  depend on phi). dL/dt = M gives alpha = J^-1 (M - omega x J omega); the seed's eq 67 omits the
  omega x J omega term, which for a spinning wheelset is the gyroscopic couple J_a phi' psi' that
  couples yaw and roll.
* alpha -> (psi'', theta'', phi'') by eq 68-70 (kinematics.euler_accelerations).

Energy: T = m |x_t'|^2 / 2 + omega . J omega / 2, V_g = -m g z; then
d(T + V_g)/dt = P_contact + P_exterior with P = sum F . v_point + M . omega (v_point the velocity of
the material point the force acts on). The appended states integrate P_contact and P_exterior.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.creepage import patch_kinematics
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import SIDES, ContactProvider

STATE_NAMES = (
    "x_m",
    "y_m",
    "z_m",
    "yaw_rad",
    "roll_rad",
    "spin_rad",
    "x_velocity_m_per_s",
    "y_velocity_m_per_s",
    "z_velocity_m_per_s",
    "yaw_rate_rad_per_s",
    "roll_rate_rad_per_s",
    "spin_rate_rad_per_s",
)
"""Names of the 12 states, in order."""

PATCH_FIELDS = (
    "normal_force_N",
    "creep_force_long_N",
    "creep_force_lat_N",
    "spin_moment_Nm",
    "creepage_long",
    "creepage_lat",
    "spin_creepage_1_per_m",
    "approach_m",
    "contact_point_y_m",
    "wheel_lateral_m",
    "rolling_radius_m",
    "contact_angle_rad",
    "semi_axis_long_m",
    "semi_axis_lat_m",
)
"""Per-patch quantities recorded in the results, each of shape (n_out, 2 sides, 2 slots)."""

MAX_SLOTS = 2


class ContactFailure(RuntimeError):
    """A contact model did not converge or the kinematics became undefined (reported, not raised out)."""


def rotation_and_rates(yaw, roll, spin, yaw_rate, roll_rate, spin_rate):
    """C_D (eq 1, R_z R_x R_y(-phi)) and omega_D (eq 2), scalar arithmetic for speed.

    Returns:
        (C_D (3, 3), R = R_z R_x (3, 3), omega (3,)).
    """
    cps, sps = math.cos(yaw), math.sin(yaw)
    cth, sth = math.cos(roll), math.sin(roll)
    cph, sph = math.cos(spin), math.sin(spin)
    rzx = np.array([[cps, -sps * cth, sps * sth], [sps, cps * cth, -cps * sth], [0.0, sth, cth]])
    ry = np.array([[cph, 0.0, -sph], [0.0, 1.0, 0.0], [sph, 0.0, cph]])  # R_y(-phi)
    omega = np.array(
        [
            roll_rate * cps + spin_rate * sps * cth,
            roll_rate * sps - spin_rate * cps * cth,
            yaw_rate - spin_rate * sth,
        ]
    )
    return rzx @ ry, rzx, omega


@dataclass(eq=False)
class ContactState:
    """Solved contact candidates of one state (arrays over candidates; forces on the wheel, main frame)."""

    side: np.ndarray
    slot: np.ndarray
    force_N: np.ndarray  # (n, 3) main frame
    moment_Nm: np.ndarray  # (n, 3) main frame, about the contact point
    lever_m: np.ndarray  # (n, 3)
    point_velocity_m_per_s: np.ndarray  # (n, 3)
    values: dict  # PATCH_FIELDS -> (n,)


class WheelsetModel:
    """State function of a wheelset (module docstring) for one scene, provider and contact model.

    Args:
        scene: the scene (parameters, material, speed).
        provider: contact-geometry provider.
        contact_model: an object with the ContactModel protocol (registry.get_model).
        model_options: options handed to the model's solve().
    """

    def __init__(self, scene: DynamicsScene, provider: ContactProvider, contact_model, model_options=None):
        self.scene = scene
        self.provider = provider
        self.model = contact_model
        self.model_options = model_options
        ws = scene.wheelset
        self.mass = ws.mass_kg
        self.j_body = np.diag([ws.transverse_inertia_kg_m2, ws.axle_inertia_kg_m2, ws.transverse_inertia_kg_m2])
        self.gravity = STANDARD_GRAVITY_M_PER_S2
        susp = scene.suspension
        self.k = np.array(
            [susp.longitudinal_stiffness_N_per_m, susp.lateral_stiffness_N_per_m, susp.vertical_stiffness_N_per_m]
        )
        self.c = np.array(
            [susp.longitudinal_damping_N_s_per_m, susp.lateral_damping_N_s_per_m, susp.vertical_damping_N_s_per_m]
        )
        self.k_yaw = susp.yaw_stiffness_N_m_per_rad
        self.c_yaw = susp.yaw_damping_N_m_s_per_rad
        self.has_suspension = bool(np.any(self.k > 0) or np.any(self.c > 0) or self.k_yaw > 0 or self.c_yaw > 0)
        self.half_spacing = ws.suspension_half_spacing_m
        self.z_frame = -ws.nominal_radius_m
        self.frame_x0 = 0.0
        self.speed = scene.speed_m_per_s
        self.axle_load = scene.loads.axle_load_N
        self.torque = scene.loads.traction_torque_N_m
        self.rhs_evaluations = 0

    # ----------------------------------------------------------------------------------------------
    def contact(self, state: np.ndarray) -> ContactState:
        """Contact forces of every candidate in contact (approach > 0) for a 12-state."""
        x, y, z, yaw, roll, spin = state[:6]
        centre = state[0:3]
        v_c = state[6:9]
        c_d, _, omega = rotation_and_rates(yaw, roll, spin, state[9], state[10], state[11])
        patches = self.provider.patches(centre, yaw, roll, spin)
        n = len(patches)
        values = {name: np.full(n, np.nan) for name in PATCH_FIELDS}
        values["approach_m"] = np.asarray(patches.approach_m, float).copy()
        values["contact_point_y_m"] = patches.point_m[:, 1].copy()
        values["wheel_lateral_m"] = np.asarray(patches.wheel_lateral_m, float).copy()
        values["rolling_radius_m"] = np.asarray(patches.rolling_radius_m, float).copy()
        values["contact_angle_rad"] = np.asarray(patches.contact_angle_rad, float).copy()
        values["normal_force_N"] = np.zeros(n)
        force = np.zeros((n, 3))
        moment = np.zeros((n, 3))
        lever = patches.point_m - centre
        velocity = v_c + np.cross(omega, lever)
        active = np.flatnonzero(patches.approach_m > 0)
        if len(active):
            try:
                kin = patch_kinematics(lever[active], np.eye(3), omega, v_c, patches.normal[active])
            except ValueError as exc:
                raise ContactFailure(f"creepages undefined: {exc}") from None
            material = self.scene.material
            for i, k in enumerate(active):
                speed = float(kin.rolling_speed_m_per_s[i])
                if not speed > 0 or not math.isfinite(speed):
                    raise ContactFailure(f"rolling speed {speed!r} m/s at a contact: creepages undefined")
                frame = kin.contact_frame[i]
                if patches.geometries is not None:
                    geometry = patches.geometries[k]
                else:
                    geometry = ContactGeometry(
                        curvature_long_1_per_m=float(patches.curvature_long_1_per_m[k]),
                        curvature_lat_1_per_m=float(patches.curvature_lat_1_per_m[k]),
                        approach_m=float(patches.approach_m[k]),
                        side=SIDES[patches.side[k]],
                        point_m=patches.point_m[k],
                        frame=frame,
                        contact_angle_rad=float(patches.contact_angle_rad[k]),
                        rolling_radius_m=float(patches.rolling_radius_m[k]),
                    )
                creepage = Creepage(
                    float(kin.longitudinal[i]), float(kin.lateral[i]), float(kin.spin_1_per_m[i]), speed
                )
                result = self.model.solve(geometry, creepage, material, options=self.model_options)
                if not result.success and result.status != "no-contact":
                    raise ContactFailure(f"contact model {result.method!r} failed: {result.status}: {result.message}")
                normal = result.normal_force_N or 0.0
                t_x = result.creep_force_long_N or 0.0
                t_y = result.creep_force_lat_N or 0.0
                m_z = result.spin_moment_Nm or 0.0
                force[k] = frame @ np.array([t_x, t_y, normal])
                moment[k] = m_z * frame[:, 2]
                values["normal_force_N"][k] = normal
                values["creep_force_long_N"][k] = t_x
                values["creep_force_lat_N"][k] = t_y
                values["spin_moment_Nm"][k] = m_z
                values["creepage_long"][k] = kin.longitudinal[i]
                values["creepage_lat"][k] = kin.lateral[i]
                values["spin_creepage_1_per_m"][k] = kin.spin_1_per_m[i]
                values["semi_axis_long_m"][k] = result.semi_axis_long_m if result.semi_axis_long_m else np.nan
                values["semi_axis_lat_m"][k] = result.semi_axis_lat_m if result.semi_axis_lat_m else np.nan
        return ContactState(patches.side, patches.slot, force, moment, lever, velocity, values)

    def exterior(self, t: float, state: np.ndarray, c_d: np.ndarray, omega: np.ndarray):
        """Exterior force and moment (eq 63-64) about the centre, and their power (main frame)."""
        force = np.array([0.0, 0.0, self.axle_load])
        moment = np.zeros(3)
        power = self.axle_load * state[8]
        if self.has_suspension:
            x_frame = self.frame_x0 + self.speed * t
            for s in (-1.0, 1.0):
                arm = c_d[:, 1] * (s * self.half_spacing)
                point = state[0:3] + arm
                vel = state[6:9] + np.cross(omega, arm)
                rel = point - np.array([x_frame, s * self.half_spacing, self.z_frame])
                rel_v = vel - np.array([self.speed, 0.0, 0.0])
                f = -self.k * rel - self.c * rel_v
                force += f
                moment += np.cross(arm, f)
                power += f @ vel
            m_yaw = -2.0 * (self.k_yaw * state[3] + self.c_yaw * state[9])
            moment[2] += m_yaw
            power += m_yaw * omega[2]
        if self.torque:
            m_t = -self.torque * c_d[:, 1]
            moment += m_t
            power += m_t @ omega
        return force, moment, power

    def derivative(self, t: float, state: np.ndarray, contact: ContactState | None = None) -> np.ndarray:
        """d/dt of the 14-state (12 mechanical + 2 work integrals)."""
        self.rhs_evaluations += 1
        yaw, roll, spin = state[3], state[4], state[5]
        yaw_rate, roll_rate, spin_rate = state[9], state[10], state[11]
        c_d, rzx, omega = rotation_and_rates(yaw, roll, spin, yaw_rate, roll_rate, spin_rate)
        if contact is None:
            contact = self.contact(state[:12])
        f_con = contact.force_N.sum(axis=0)
        m_con = np.cross(contact.lever_m, contact.force_N).sum(axis=0) + contact.moment_Nm.sum(axis=0)
        p_con = float(np.sum(contact.force_N * contact.point_velocity_m_per_s) + contact.moment_Nm.sum(axis=0) @ omega)
        f_ext, m_ext, p_ext = self.exterior(t, state, c_d, omega)
        acc = (f_con + f_ext) / self.mass
        acc[2] += self.gravity
        j_main = rzx @ self.j_body @ rzx.T
        torque = m_con + m_ext - np.cross(omega, j_main @ omega)
        alpha = np.linalg.solve(j_main, torque)
        ax, ay, az = alpha
        sp, cp, st, ct = math.sin(yaw), math.cos(yaw), math.sin(roll), math.cos(roll)
        yaw_acc = (ax * sp * st - ay * cp * st + az * ct + yaw_rate * roll_rate * st + roll_rate * spin_rate) / ct
        spin_acc = (ax * sp - ay * cp + yaw_rate * roll_rate + roll_rate * spin_rate * st) / ct
        roll_acc = ax * cp + ay * sp - yaw_rate * spin_rate * ct
        out = np.empty(14)
        out[0:3] = state[6:9]
        out[3:6] = state[9:12]
        out[6:9] = acc
        out[9], out[10], out[11] = yaw_acc, roll_acc, spin_acc
        out[12], out[13] = p_con, p_ext
        return out

    # ----------------------------------------------------------------------------------------------
    def kinetic_energy_J(self, state: np.ndarray) -> float:
        """T = m |v|^2/2 + omega . J omega / 2, J."""
        _, rzx, omega = rotation_and_rates(*state[3:6], *state[9:12])
        j_main = rzx @ self.j_body @ rzx.T
        return 0.5 * self.mass * float(state[6:9] @ state[6:9]) + 0.5 * float(omega @ j_main @ omega)

    def potential_energy_J(self, state: np.ndarray) -> float:
        """Gravity potential V_g = -m g z (z down), J."""
        return -self.mass * self.gravity * float(state[2])

    def static_state(self, state: np.ndarray) -> tuple[np.ndarray, bool, str]:
        """Adjust z and theta of ``state`` so that vertical force and roll moment balance (t = 0).

        Returns:
            (state, success, message).
        """
        from scipy.optimize import root

        work = np.array(state, float)

        def residual(v):
            trial = work.copy()
            trial[2], trial[4] = v
            full = np.concatenate([trial, [0.0, 0.0]])
            try:
                d = self.derivative(0.0, full)
            except ContactFailure:
                return np.array([1e3, 1e3])
            return np.array([d[8], d[10] * 0.1])

        guess = np.array([work[2], work[4]])
        sol = root(residual, guess, method="hybr", options={"xtol": 1e-13})
        work[2], work[4] = sol.x
        ok = bool(sol.success) and bool(np.all(np.abs(residual(sol.x)) < 1e-3))
        return work, ok, str(sol.message)
