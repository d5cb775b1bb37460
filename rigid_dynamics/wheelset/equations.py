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

Elastic track (scene ``track_dynamics.model = "lumped"``, seed eq 6's rail deflection N_d,t): 8 more states
after the two work integrals, :data:`TRACK` = [z_r, z_s per side (left, right), then their rates], z down, from
the unloaded track. Per wheel m_r z_r'' = F_r - k_p (z_r - z_s) - c_p (z_r' - z_s') and
m_s z_s'' = k_p (z_r - z_s) + c_p (z_r' - z_s') - k_b z_s - c_b z_s', with F_r = -sum F_con,z over that wheel's
patches (the vertical component of the contact forces, on the rail). The rail mass's displacement z_r lowers that
rail's surface: the contact geometry is evaluated with the wheelset centre raised by z_r for that side (a rigid
vertical shift of the rail, exact for every provider), and the creepages use the wheel's velocity relative to the
rail (v_w - z_r' e_z). The contact power then is F_con . (v_w - v_r): the work on wheel and rail together.

Energy: T = m |x_t'|^2 / 2 + omega . J omega / 2, V_g = -m g z; then
d(T + V_g)/dt = P_contact + P_exterior with P = sum F . v_point + M . omega (v_point the velocity of
the material point the force acts on). The appended states integrate P_contact and P_exterior.
With the elastic track T adds m_r z_r'^2/2 + m_s z_s'^2/2, the potential adds k_p (z_r - z_s)^2/2 + k_b z_s^2/2
(the track masses' own weight is balanced in the unloaded track), and P_exterior adds the track dampers' power
-c_p (z_r' - z_s')^2 - c_b z_s'^2.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2
from rigid_dynamics.wheelset import track as track_model
from rigid_dynamics.wheelset.compiled import (
    derivative_from_contact,
    frame_velocities,
    model_parameters,
    patch_creepages,
    track_rates,
)
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import SIDES, ContactProvider
from rigid_dynamics.wheelset.state import (
    MECHANICAL,
    TRACK,
    n_states,
)

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

AUTO_PATCH_FIELDS = (
    "auto_rung",
    "auto_level",
    "auto_deciding_feature",
    "auto_deciding_threshold",
    "auto_saturation",
    "auto_spin_share",
    "auto_ellipticity_residual",
    "auto_curvature_change",
    "auto_second_patch_nearness",
)
"""Per-patch record of the ``auto`` model's choice (runs with contact_model "auto" only): ``auto_rung`` the index of
the chosen rung in rigid_dynamics.contact.auto.AUTO_RUNGS, ``auto_level`` the tolerance level used (NaN: below every
level), ``auto_deciding_feature`` the index in auto.FEATURES of the feature whose threshold decided (-1: none) and
that threshold, then the patch's features (rigid_dynamics.contact.auto.patch_features)."""


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


def _cross_rows(vector, rows):
    """Cross products vector x rows[i] for a 3-vector and an (n, 3) array."""
    wx, wy, wz = vector
    x, y, z = rows[:, 0], rows[:, 1], rows[:, 2]
    return np.stack([wy * z - wz * y, wz * x - wx * z, wx * y - wy * x], axis=-1)


def _cross_pairs(first, second):
    """first[i] x second[i] for two (n, 3) arrays."""
    a1, a2, a3 = first[:, 0], first[:, 1], first[:, 2]
    b1, b2, b3 = second[:, 0], second[:, 1], second[:, 2]
    return np.stack([a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1], axis=-1)


def _cross3(a, b):
    """Cross product a x b of two 3-vectors (plain arithmetic)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _creepages(lever, normal, omega, v_c, rail_velocity=None):
    """Contact frames and creepages of many points (eq 39-49) by the compiled kernel (compiled.patch_creepages, the
    one used by the compiled right-hand side).

    Returns:
        (frames (n, 3, 3), V (n,), xi, eta, spin (n,)).
    """
    lever = np.ascontiguousarray(lever, float)
    normal = np.ascontiguousarray(normal, float)
    n = len(lever)
    rail_vz = np.zeros(n) if rail_velocity is None else np.ascontiguousarray(np.asarray(rail_velocity, float)[:, 2])
    frames = np.empty((n, 3, 3))
    out = np.empty((4, n))
    patch_creepages(lever, normal, np.asarray(omega, float), np.asarray(v_c, float), rail_vz, frames, out)
    return frames, out[0], out[1], out[2], out[3]


BATCH_MODELS = ("hertz", "linear", "vermeulen-johnson", "fastsim")
"""Registered models evaluated for all patches at once through their vectorised kernels."""


def _uniform_interp(x, grid, rows):
    """Linear interpolation of several tables sampled on the same uniform grid (x inside the grid)."""
    step = grid[1] - grid[0]
    f = (x - grid[0]) / step
    i = np.minimum(f.astype(np.intp), len(grid) - 2)
    w = f - i
    return [row[i] * (1.0 - w) + row[i + 1] * w for row in rows]


class TabulatedHertzKalker:
    """Hertz (approach control) and Kalker's C_ij for many patches by look-up tables, for speed.

    Two smooth functions of one variable are tabulated once, on fine grids, from the project's own
    solvers and interpolated linearly:

    * the inverted axial function p = (b_minor/a_major)^2 of r = max(A, B)/min(A, B) and Kalker's
      elliptic functions K(p), D(p) (contact.hertz.ellipse_shape_from_curvature_ratio, elliptic_kdbc),
      on ``HERTZ_POINTS`` points of ln r in [0, ln 1e4];
    * C11, C22, C23, C33 (contact.kalker.kalker_coefficients at the material's nu) on ``KALKER_POINTS``
      points of ln(a/b) in [-ln 50, ln 50].

    Then (hertz.py, approach control): a_major = sqrt(q D / (K min(A, B))), N = 2 pi a_major E* q / (3 K),
    b_minor = a_major sqrt(p), E* = G/(1 - nu). Relative interpolation error < 1e-7 (the test compares
    with hertz_solve_batch and kalker_coefficients). Ratios outside the grids fall back to the solvers.
    """

    HERTZ_POINTS = 20001
    KALKER_POINTS = 8001

    def __init__(self, material):
        from rigid_dynamics.contact.hertz import ellipse_shape_from_curvature_ratio, elliptic_kdbc
        from rigid_dynamics.contact.kalker import kalker_coefficients

        self.shear = material.shear_modulus_Pa
        self.nu = material.poisson_ratio
        self.e_star = self.shear / (1.0 - self.nu)
        self.log_r = np.linspace(0.0, math.log(1e4), self.HERTZ_POINTS)
        p, _, _ = ellipse_shape_from_curvature_ratio(np.exp(self.log_r))
        k, d, _, _ = elliptic_kdbc(p)
        self.p, self.k, self.d = p, k, d
        self.log_ab = np.linspace(-math.log(50.0), math.log(50.0), self.KALKER_POINTS)
        coef = kalker_coefficients(np.exp(self.log_ab), self.nu)
        self.c = np.stack([coef.c11, coef.c22, coef.c23, coef.c33])

    def hertz(self, curv_a, curv_b, approach):
        """(a, b, N) for approach control (arrays); exact solver outside the table."""
        from rigid_dynamics.contact.hertz import hertz_solve_batch

        a_min = np.minimum(curv_a, curv_b)
        log_r = np.log(np.maximum(curv_a, curv_b) / a_min)
        if np.any(log_r > self.log_r[-1]) or not np.all(a_min > 0):
            sol = hertz_solve_batch(
                curv_a, curv_b, approach_m=approach, shear_modulus_Pa=self.shear, poisson_ratio=self.nu
            )
            return sol.semi_axis_long_m, sol.semi_axis_lat_m, sol.normal_force_N
        p, k, d = _uniform_interp(log_r, self.log_r, (self.p, self.k, self.d))
        major = np.sqrt(approach * d / (k * a_min))
        force = 2.0 * math.pi * major * self.e_star * approach / (3.0 * k)
        minor = major * np.sqrt(p)
        along_x = curv_a <= curv_b
        return np.where(along_x, major, minor), np.where(along_x, minor, major), force

    def coefficients(self, semi_a, semi_b):
        """CreepCoefficients for a/b (table, exact outside)."""
        from rigid_dynamics.contact.kalker import CreepCoefficients, kalker_coefficients

        log_ab = np.log(semi_a / semi_b)
        if np.any(np.abs(log_ab) > self.log_ab[-1]):
            return kalker_coefficients(semi_a / semi_b, self.nu)
        return CreepCoefficients(*_uniform_interp(log_ab, self.log_ab, self.c))


@functools.lru_cache(maxsize=8)
def _tables_for(shear_modulus_Pa: float, poisson_ratio: float) -> TabulatedHertzKalker:
    """TabulatedHertzKalker per material (built once per process: ~0.5 s)."""
    from rigid_dynamics.materials import Material

    return TabulatedHertzKalker(Material(shear_modulus_Pa, poisson_ratio, 0.0))


def batch_contact_function(name: str, material, options=None):
    """A function (A, B, q, xi, eta, phi) -> (N, T_x, T_y, M_z, a, b) for all patches at once, or None.

    Uses the vectorised kernels behind the registry's models (contact.linear.linear_creep_forces,
    contact.vermeulen_johnson.vermeulen_johnson_saturation, contact.fastsim.fastsim_batch) with the same
    defaults as the model classes (contact.models), Hertz and C_ij from :class:`TabulatedHertzKalker`, so
    the result equals one ``solve`` per patch to interpolation accuracy (tests/test_dynamics_contact.py).
    Approach control. Returns None for models without a batch path (then every patch is solved by
    ``model.solve``).
    """
    if name not in BATCH_MODELS:
        return None
    from rigid_dynamics.contact.linear import linear_creep_forces

    shear, nu, mu = material.shear_modulus_Pa, material.poisson_ratio, material.friction_coefficient
    opts = {"nx": 20, "ny": 20, "traction_bound": "elliptic", "flexibility": "three"}
    opts.update({k: v for k, v in (options or {}).items() if k in opts})
    tables = _tables_for(material.shear_modulus_Pa, material.poisson_ratio)

    def solve(curv_a, curv_b, approach, xi, eta, spin):
        semi_a, semi_b, normal = tables.hertz(curv_a, curv_b, approach)
        zero = np.zeros_like(normal)
        if name == "hertz":
            return normal, zero, zero, zero, semi_a, semi_b
        coef = tables.coefficients(semi_a, semi_b)
        if name == "fastsim":
            from rigid_dynamics.contact.fastsim import fastsim_batch

            res = fastsim_batch(
                semi_a, semi_b, normal, xi, eta, spin, shear_modulus_Pa=shear, poisson_ratio=nu,
                friction_coefficient=mu, coefficients=coef, **opts,
            )  # fmt: skip
            return normal, res.creep_force_long_N, res.creep_force_lat_N, res.spin_moment_Nm, semi_a, semi_b
        t_x, t_y, m_z = linear_creep_forces(
            semi_a, semi_b, xi, eta, spin, shear_modulus_Pa=shear, poisson_ratio=nu, coefficients=coef
        )
        if name == "vermeulen-johnson":
            from rigid_dynamics.contact.vermeulen_johnson import vermeulen_johnson_saturation

            t_x, t_y = vermeulen_johnson_saturation(t_x, t_y, normal, mu)
            m_z = zero
        return normal, np.asarray(t_x, float), np.asarray(t_y, float), np.asarray(m_z, float), semi_a, semi_b

    solve.tables = tables
    solve.options = dict(opts)
    return solve


def _auto_record(extra: dict) -> np.ndarray:
    """AUTO_PATCH_FIELDS values of one ``auto`` result's ``extra``."""
    from rigid_dynamics.contact.auto import AUTO_RUNGS, FEATURES

    model = extra.get("selected_model", "")
    feats = extra.get("auto_features") or {}
    deciding = extra.get("auto_deciding_feature")
    return np.array(
        [
            AUTO_RUNGS.index(model) if model in AUTO_RUNGS else np.nan,
            np.nan if extra.get("auto_level") is None else extra["auto_level"],
            FEATURES.index(deciding) if deciding in FEATURES else -1,
            np.nan if extra.get("auto_deciding_threshold") is None else extra["auto_deciding_threshold"],
            *(feats.get(f, np.nan) for f in FEATURES),
        ],
        float,
    )


def _patch_values(patches) -> dict:
    """PATCH_FIELDS arrays of a PatchSet: geometry filled in, forces 0 / creepages NaN until solved."""
    n = len(patches)
    values = {name: np.full(n, np.nan) for name in PATCH_FIELDS}
    values["normal_force_N"] = np.zeros(n)
    values["approach_m"] = np.asarray(patches.approach_m, float).copy()
    values["contact_point_y_m"] = patches.point_m[:, 1].copy()
    values["wheel_lateral_m"] = np.asarray(patches.wheel_lateral_m, float).copy()
    values["rolling_radius_m"] = np.asarray(patches.rolling_radius_m, float).copy()
    values["contact_angle_rad"] = np.asarray(patches.contact_angle_rad, float).copy()
    return values


@dataclass(eq=False)
class ContactState:
    """Solved contact candidates of one state (arrays over candidates; forces on the wheel, main frame)."""

    side: np.ndarray
    slot: np.ndarray
    force_N: np.ndarray  # (n, 3) main frame
    moment_Nm: np.ndarray  # (n, 3) main frame, about the contact point
    lever_m: np.ndarray  # (n, 3)
    point_velocity_m_per_s: np.ndarray  # (n, 3)
    values: dict | None  # PATCH_FIELDS -> (n,) when recorded


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
        name = getattr(contact_model, "name", "")
        model_cls = type(contact_model).__module__
        self.batch = (
            batch_contact_function(name, scene.material, model_options)
            if model_cls == "rigid_dynamics.contact.models"
            else None
        )
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
        self.track = scene.track_dynamics
        self.elastic = self.track.elastic
        self.n_state = n_states(self.elastic)
        self.track_rest = np.zeros(8)  # the track's states used with a 12-state (static equilibrium)
        self.rhs_evaluations = 0
        self.last_auto = None  # AUTO_PATCH_FIELDS of the last contact() that ran "auto", (n_active, fields)
        self.par = model_parameters(self)  # the compiled equations' parameter record (compiled.PARAMETERS)

    def full_state(self, state: np.ndarray) -> np.ndarray:
        """The full state of a 12-state: work integrals 0 and, with the elastic track, ``track_rest``."""
        parts = [np.asarray(state, float)[:12], [0.0, 0.0]]
        if self.elastic:
            parts.append(self.track_rest)
        return np.concatenate(parts)

    def static_track(self, rail_force_N) -> np.ndarray:
        """Track states at rest under the vertical rail forces (left, right), N (track.rest_state)."""
        return track_model.rest_state(self.track, rail_force_N)

    def patches_on_track(self, centre, yaw, roll, spin, shift=None):
        """The provider's patches with the rails lowered by ``shift`` (left, right), m (None: rigid track).

        A rail lowered by w is the wheelset raised by w for that side's contact: the provider is asked at the centre
        raised by w per side and the contact points are moved back down by w (levers unchanged).
        """
        if shift is None or (shift[0] == 0.0 and shift[1] == 0.0):
            return self.provider.patches(centre, yaw, roll, spin)
        from dataclasses import replace

        from rigid_dynamics.wheelset.providers import PatchSet

        sets = []
        for w in (shift[0],) if shift[0] == shift[1] else (shift[0], shift[1]):
            raised = np.array(centre, float)
            raised[2] -= w
            sets.append(self.provider.patches(raised, yaw, roll, spin))
        pick = [np.arange(len(sets[0]))] if len(sets) == 1 else [np.flatnonzero(sets[i].side == i) for i in (0, 1)]
        fields = {}
        for name in (
            "side", "slot", "point_m", "normal", "curvature_long_1_per_m", "curvature_lat_1_per_m", "approach_m",
            "rolling_radius_m", "contact_angle_rad", "wheel_lateral_m", "merge_approach_m",
        ):  # fmt: skip
            parts = [getattr(p, name) for p in sets]
            if parts[0] is None:
                fields[name] = None
                continue
            fields[name] = np.concatenate([np.array(v)[k] for v, k in zip(parts, pick, strict=True)])
        moved = np.asarray(shift, float)[fields["side"]]
        fields["point_m"][:, 2] += moved
        geometries = None
        if sets[0].geometries is not None:
            geometries = []
            for p, k in zip(sets, pick, strict=True):
                for i in k:
                    g = p.geometries[i]
                    point = np.array(g.point_m, float)
                    point[2] += shift[int(p.side[i])]
                    geometries.append(replace(g, point_m=point))
        return PatchSet(geometries=geometries, **fields)

    # ----------------------------------------------------------------------------------------------
    def contact(self, state: np.ndarray, record: bool = False, track: np.ndarray | None = None) -> ContactState:
        """Contact forces of every candidate in contact (approach > 0) for a 12-state.

        With ``record`` the per-patch values (PATCH_FIELDS) are filled, else ``values`` is None. ``track``: the
        elastic track's 8 states (TRACK_STATE_NAMES); None: ``track_rest`` (rigid track: ignored).
        """
        x, y, z, yaw, roll, spin = state[:6]
        centre = state[0:3]
        v_c = state[6:9]
        c_d, _, omega = rotation_and_rates(yaw, roll, spin, state[9], state[10], state[11])
        rail_velocity = None
        if self.elastic:
            track = self.track_rest if track is None else track
            patches = self.patches_on_track(centre, yaw, roll, spin, track[0:2])
        else:
            patches = self.provider.patches(centre, yaw, roll, spin)
        n = len(patches)
        values = None
        force = np.zeros((n, 3))
        moment = np.zeros((n, 3))
        lever = patches.point_m - centre
        velocity = v_c + _cross_rows(omega, lever)
        if self.elastic:
            rail_velocity = np.zeros((n, 3))
            rail_velocity[:, 2] = track[4:6][patches.side]
            velocity = velocity - rail_velocity  # relative to the rail (power on wheel and rail together)
        active = np.flatnonzero(patches.approach_m > 0)
        self.last_auto = None
        if len(active):
            omega_abs, v_abs = frame_velocities(self.par, state, omega)  # in a curve: absolute, for the creepages
            frames, speed, xi, eta, spin = _creepages(
                lever[active],
                patches.normal[active],
                omega_abs,
                v_abs,
                None if rail_velocity is None else rail_velocity[active],
            )
            if not np.all(speed > 0) or not np.all(np.isfinite(speed)):
                raise ContactFailure(f"rolling speed {speed.min()!r} m/s at a contact: creepages undefined")
            elliptic = patches.geometries is None or all(patches.geometries[k].is_elliptic for k in active)
            if self.batch is not None and elliptic:
                normal, t_x, t_y, m_z, semi_a, semi_b = self.batch(
                    patches.curvature_long_1_per_m[active],
                    patches.curvature_lat_1_per_m[active],
                    patches.approach_m[active],
                    xi,
                    eta,
                    spin,
                )
            else:
                normal, t_x, t_y, m_z, semi_a, semi_b = self._solve_each(patches, active, frames, speed, xi, eta, spin)
            force[active] = (
                frames[:, :, 0] * t_x[:, None] + frames[:, :, 1] * t_y[:, None] + frames[:, :, 2] * normal[:, None]
            )
            moment[active] = frames[:, :, 2] * m_z[:, None]
            if record:
                values = _patch_values(patches)
                for key, val in (
                    ("normal_force_N", normal), ("creep_force_long_N", t_x), ("creep_force_lat_N", t_y),
                    ("spin_moment_Nm", m_z), ("creepage_long", xi), ("creepage_lat", eta),
                    ("spin_creepage_1_per_m", spin), ("semi_axis_long_m", semi_a), ("semi_axis_lat_m", semi_b),
                ):  # fmt: skip
                    values[key][active] = val
                if self.last_auto is not None:
                    for j, key in enumerate(AUTO_PATCH_FIELDS):
                        values[key] = np.full(n, np.nan)
                        values[key][active] = self.last_auto[:, j]
        elif record:
            values = _patch_values(patches)
        return ContactState(patches.side, patches.slot, force, moment, lever, velocity, values)

    def _solve_each(self, patches, active, frames, speed, xi, eta, spin):
        """One ``model.solve`` per active patch (any registered model, sampled geometries)."""
        n = len(active)
        out = [np.zeros(n) for _ in range(6)]
        material = self.scene.material
        for i, k in enumerate(active):
            if patches.geometries is not None:
                geometry = patches.geometries[k]
            else:
                geometry = ContactGeometry(
                    curvature_long_1_per_m=float(patches.curvature_long_1_per_m[k]),
                    curvature_lat_1_per_m=float(patches.curvature_lat_1_per_m[k]),
                    approach_m=float(patches.approach_m[k]),
                    side=SIDES[patches.side[k]],
                    point_m=patches.point_m[k],
                    frame=frames[i],
                    contact_angle_rad=float(patches.contact_angle_rad[k]),
                    rolling_radius_m=float(patches.rolling_radius_m[k]),
                )
            creepage = Creepage(float(xi[i]), float(eta[i]), float(spin[i]), float(speed[i]))
            result = self.model.solve(geometry, creepage, material, options=self.model_options)
            if not result.success and result.status != "no-contact":
                raise ContactFailure(f"contact model {result.method!r} failed: {result.status}: {result.message}")
            out[0][i] = result.normal_force_N or 0.0
            out[1][i] = result.creep_force_long_N or 0.0
            out[2][i] = result.creep_force_lat_N or 0.0
            out[3][i] = result.spin_moment_Nm or 0.0
            out[4][i] = result.semi_axis_long_m or np.nan
            out[5][i] = result.semi_axis_lat_m or np.nan
            if "auto_rung" in result.extra:
                if self.last_auto is None:
                    self.last_auto = np.full((n, len(AUTO_PATCH_FIELDS)), np.nan)
                self.last_auto[i] = _auto_record(result.extra)
        return out

    def derivative(self, t: float, state: np.ndarray, contact: ContactState | None = None) -> np.ndarray:
        """d/dt of the full state (12 mechanical + 2 work integrals [+ 8 track states, TRACK]).

        The contact forces come from :meth:`contact` (any provider and contact model); the equations of motion,
        the suspension and the track are the compiled ones (compiled.derivative_from_contact, the same code as the
        compiled loop's right-hand side).
        """
        self.rhs_evaluations += 1
        state = np.asarray(state, float)
        track = state[TRACK] if self.elastic else None
        if contact is None:
            contact = self.contact(state[MECHANICAL], track=track)
        _, _, omega = rotation_and_rates(*state[3:6], *state[9:12])
        f_con = contact.force_N.sum(axis=0)
        m_con = _cross_pairs(contact.lever_m, contact.force_N).sum(axis=0) + contact.moment_Nm.sum(axis=0)
        p_con = float(np.sum(contact.force_N * contact.point_velocity_m_per_s) + contact.moment_Nm.sum(axis=0) @ omega)
        rail_force = np.zeros(2)
        if self.elastic:
            np.add.at(rail_force, contact.side, -contact.force_N[:, 2])
        out = np.empty(self.n_state)
        self.par["frame_x0_m"] = self.frame_x0
        derivative_from_contact(float(t), state, self.par, f_con, m_con, p_con, rail_force, out)
        return out

    def _track_derivative(self, track, rail_force, out) -> float:
        """d/dt of the 8 track states into ``out`` under the rail forces (left, right) (compiled.track_rates);
        returns the dampers' power.
        """
        full = np.zeros(self.n_state)
        full[TRACK] = track
        rates = np.zeros(self.n_state)
        power = track_rates(self.par, full, np.asarray(rail_force, float), rates)
        out[:] = rates[TRACK]
        return float(power)

    def track_energy_J(self, track) -> tuple:
        """(kinetic, potential) energy of the elastic track's states (n, 8) or (8,), J (track.energy_J)."""
        return track_model.energy_J(self.track, track)

    # ----------------------------------------------------------------------------------------------
    def kinetic_energy_J(self, state: np.ndarray) -> float:
        """T = m |v|^2/2 + omega . J omega / 2, J."""
        _, rzx, omega = rotation_and_rates(*state[3:6], *state[9:12])
        j_main = rzx @ self.j_body @ rzx.T
        return 0.5 * self.mass * float(state[6:9] @ state[6:9]) + 0.5 * float(omega @ j_main @ omega)

    def potential_energy_J(self, state: np.ndarray) -> float:
        """Gravity potential V_g = -m g z (z down), J."""
        return -self.mass * self.gravity * float(state[2])

    def _rest_shift(self):
        """The rails' deflection in ``track_rest`` (None for the rigid track)."""
        return self.track_rest[0:2] if self.elastic else None

    def static_state(self, state: np.ndarray, derivative=None, deepest_approach=None) -> tuple[np.ndarray, bool, str]:
        """Adjust z and theta of ``state`` so that vertical force and roll moment balance (t = 0).

        Args:
            state: the 12-state to adjust.
            derivative: optional (t, 14-state) -> d/dt replacing :meth:`derivative` (the compiled loop's RHS).
            deepest_approach: optional 12-state -> (left, right) deepest approach of each wheel, m, replacing the
                provider's patches.

        Returns:
            (state, success, message).
        """
        from scipy.optimize import root

        work = np.array(state, float)
        derivative = self.derivative if derivative is None else derivative

        def residual(v):
            trial = work.copy()
            trial[2], trial[4] = v
            full = self.full_state(trial)
            try:
                d = derivative(0.0, full)
            except ContactFailure:
                return np.array([1e3, 1e3])
            return np.array([d[8], d[10] * 0.1])

        # bring both wheels to about the static approach before iterating (no contact = flat residual)
        # (a roll theta lowers the right wheel by about e0 theta and lifts the left one: level them first)
        e0 = self.scene.wheelset.contact_half_distance_m
        for _ in range(6):
            if deepest_approach is not None:
                deepest = deepest_approach(work)
            else:
                patches = self.patches_on_track(work[0:3], work[3], work[4], work[5], self._rest_shift())
                deepest = [
                    np.max(patches.approach_m[patches.side == i]) if np.any(patches.side == i) else 0.0 for i in (0, 1)
                ]
            work[4] += (deepest[0] - deepest[1]) / (2.0 * e0)
            shift = 1e-4 - 0.5 * (deepest[0] + deepest[1])
            work[2] += shift
            if abs(shift) < 1e-7 and abs(deepest[0] - deepest[1]) < 1e-7:
                break
        guess = np.array([work[2], work[4]])
        # damped Newton with a finite-difference Jacobian and limited steps (the tables are only piecewise
        # smooth in roll), then scipy's hybrid method as a fallback
        x = guess.copy()
        r = residual(x)
        limit = np.array([1e-4, 5e-4])
        for _ in range(60):
            if np.max(np.abs(r)) < 1e-6:
                break
            jac = np.empty((2, 2))
            for k, h in enumerate((1e-8, 1e-7)):
                xp = x.copy()
                xp[k] += h
                jac[:, k] = (residual(xp) - r) / h
            try:
                step = np.linalg.solve(jac, -r)
            except np.linalg.LinAlgError:
                break
            step = np.clip(step, -limit, limit)
            for _damp in range(8):
                trial = residual(x + step)
                if np.max(np.abs(trial)) < np.max(np.abs(r)):
                    break
                step *= 0.5
            x, r = x + step, trial
        best, message = (x, float(np.max(np.abs(r)))), "damped Newton"
        if best[1] >= 1e-3:
            sol = root(residual, guess, method="hybr", options={"xtol": 1e-13})
            size = float(np.max(np.abs(residual(sol.x))))
            if size < best[1]:
                best, message = (sol.x, size), f"hybr: {sol.message}"
        work[2], work[4] = best[0]
        # accept a residual acceleration below 1e-3 m/s^2 (vertical) / 1e-2 rad/s^2 (roll)
        ok = best[1] < 1e-3
        patches = self.patches_on_track(work[0:3], work[3], work[4], work[5], self._rest_shift())
        touching = [bool(np.any((patches.side == i) & (patches.approach_m > 0))) for i in (0, 1)]
        if ok and not all(touching):
            ok, message = False, "the equilibrium found has a wheel off its rail (no contact at rest)"
        return work, ok, message
