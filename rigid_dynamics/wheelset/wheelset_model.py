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

Elastic track (scene ``track_dynamics``, seed eq 6's rail deflection N_d,t): its states follow the two work
integrals (:data:`TRACK`), positions then rates, z down from the unloaded track; their physics is in
:mod:`rigid_dynamics.wheelset.track` (the lumped track below; the discretely supported beam there, whose rail
deflection and velocity under the wheel, track.rail_under_wheel, take the place of z_r and z_r'). Lumped: per
wheel m_r z_r'' = F_r - k_p (z_r - z_s) - c_p (z_r' - z_s') and
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

import contextlib
import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2
from rigid_dynamics.wheelset import compiled_rhs
from rigid_dynamics.wheelset import track as track_model
from rigid_dynamics.wheelset.callback import PatchCallback
from rigid_dynamics.wheelset.compiled_laws import LAW_AUTO, LAW_CALLBACK, LAW_FASTSIM, LAW_TABLE, tables_for
from rigid_dynamics.wheelset.compiled_motion import (
    ETA_ROW,
    SPEED_ROW,
    SPIN_ROW,
    XI_ROW,
    patch_creepages,
    track_rates,
)
from rigid_dynamics.wheelset.compiled_records import law_code, model_parameters, pack
from rigid_dynamics.wheelset.layout import (
    CALLBACK_FAILED,
    CREEP_FORCE_LAT,
    CREEP_FORCE_LONG,
    CREEPAGES_UNDEFINED,
    G_APPROACH,
    G_CONTACT_ANGLE,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_LEVER,
    G_NORMAL,
    G_ROLLING_RADIUS,
    G_WHEEL_LATERAL,
    GEOMETRY_GIVEN,
    GEOMETRY_SEARCH,
    MAX_SLOTS,
    N_FIELDS,
    N_GEO,
    NORMAL_FORCE,
    SPIN_MOMENT,
    STATUS,
    record_columns,
    status_name,
)
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import ContactProvider
from rigid_dynamics.wheelset.state import N_RIGID, TRACK, n_states
from rigid_dynamics.wheelset.track_matrices import TrackSystem


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


def _creepages(lever, normal, omega, v_c, rail_velocity=None):
    """Contact frames and creepages of many points (eq 39-49) by the compiled kernel
    (compiled_motion.patch_creepages, the one used by the compiled right-hand side).

    Returns:
        (frames (n, 3, 3), V (n,), xi, eta, spin (n,)).
    """
    lever = np.ascontiguousarray(lever, float)
    normal = np.ascontiguousarray(normal, float)
    n = len(lever)
    rail = np.zeros((n, 3)) if rail_velocity is None else np.asarray(rail_velocity, float)
    rail_vy, rail_vz = np.ascontiguousarray(rail[:, 1]), np.ascontiguousarray(rail[:, 2])
    frames = np.empty((n, 3, 3))
    out = np.empty((4, n))
    patch_creepages(lever, normal, np.asarray(omega, float), np.asarray(v_c, float), rail_vy, rail_vz, frames, out)
    return frames, out[SPEED_ROW], out[XI_ROW], out[ETA_ROW], out[SPIN_ROW]


@dataclass(eq=False)
class ContactState:
    """Solved contact candidates of one state (arrays over candidates; forces on the wheel, main frame)."""

    side: np.ndarray
    slot: np.ndarray
    force_N: np.ndarray  # (n, 3) main frame
    moment_Nm: np.ndarray  # (n, 3) main frame, about the contact point
    lever_m: np.ndarray  # (n, 3)
    point_velocity_m_per_s: np.ndarray  # (n, 3)
    values: dict | None  # PATCH_FIELDS (the candidates'), FORMED_PATCH_FIELDS -> (n,) when recorded

    @property
    def record(self) -> dict | None:
        """The per-patch values as the run records them: ``values`` with a formed patch's own quantities in place of
        its candidate's (formed_patches.recorded); None when not recorded.
        """
        from rigid_dynamics.wheelset.formed_patches import recorded

        return None if self.values is None else recorded(self.values)


def _patch_surfaces(scene: DynamicsScene, provider):
    """The real surfaces a sampled patch comes from: the provider's WheelsetTrack (SearchProvider), else a callable
    building the scene's once (profiles and irregularities as the 3-D search's: the tables provider's section
    surfaces carry no irregularities).
    """
    own = getattr(provider, "surfaces", None)
    if own is not None and hasattr(own, "fast") and hasattr(provider, "searches"):  # SearchProvider
        return own

    def build():
        from rigid_dynamics.wheelset.providers.surfaces import build_surfaces

        return build_surfaces(scene.wheelset, scene.track, scene.irregularities)

    return build


class WheelsetModel:
    """State function of a wheelset (module docstring) for one scene, provider and contact model: a thin wrapper of the
    one compiled right-hand side (compiled_rhs.py) for the scipy methods, the Python RK4, the static equilibrium,
    inspection (:meth:`contact`) and tests; the arguments of the compiled code in ``packed`` (compiled_records.pack,
    a PackedRun), the callback of a contact model that is not compiled in ``callback`` (:class:`PatchCallback`).

    Args:
        scene: the scene (parameters, material, speed).
        provider: contact-geometry provider.
        contact_model: an object with the ContactModel protocol (registry.get_model).
        model_options: options handed to the model's solve().
        python_geometry: the provider's own ``patches`` give the geometry (layout.GEOMETRY_GIVEN) even where the
            compiled code evaluates it (the 3-D search outside the compiled loop: simulate).
    """

    def __init__(
        self, scene: DynamicsScene, provider: ContactProvider, contact_model, model_options=None, python_geometry=False
    ):
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
        self.frame_yaw = susp.frame_yaw_rad
        self.has_suspension = bool(np.any(self.k > 0) or np.any(self.c > 0) or self.k_yaw > 0 or self.c_yaw > 0)
        self.half_spacing = ws.suspension_half_spacing_m
        self.z_frame = -ws.nominal_radius_m
        self.frame_x0 = 0.0
        self.speed = scene.speed_m_per_s
        self.axle_load = scene.loads.axle_load_N
        self.torque = scene.loads.traction_torque_N_m
        self.track = scene.track_dynamics
        self.elastic = self.track.elastic
        self.track_system = TrackSystem(self.track, track_model.travel_m(scene)) if self.elastic else None
        self.n_state = n_states(self.track_system.n_positions if self.elastic else 0)
        self.track_rest = np.zeros(self.n_state - 14)  # the track's states used with a 12-state (static equilibrium)
        self.rhs_evaluations = 0
        self.par = model_parameters(self)  # replaced by the packed record below (same fields, contact fields set)
        code = law_code(contact_model, scene.patch_geometry)
        opts = dict(model_options or {})
        fastsim = (
            opts if code in (LAW_FASTSIM, LAW_TABLE) else dict((opts.get("model_options") or {}).get("fastsim") or {})
        )
        self.tables = tables_for(scene.material.shear_modulus_Pa, scene.material.poisson_ratio)
        tolerance = opts.get("tolerance", 0.05)
        self.packed = pack(self, provider, self.tables, contact_model, fastsim, tolerance, python_geometry)
        self.par = self.packed.par
        self.mode = self.packed.mode
        self.callback = None
        surfaces = _patch_surfaces(scene, provider) if scene.patch_geometry in ("sampled", "formed") else None
        if code == LAW_CALLBACK:
            self.callback = PatchCallback(contact_model, model_options, scene.material, surfaces, self.elastic)
        elif code == LAW_AUTO:
            from rigid_dynamics.contact.registry import get_model

            bem_options = (opts.get("model_options") or {}).get("bem")
            self.callback = PatchCallback(get_model("bem"), bem_options, scene.material, surfaces, self.elastic)
            # auto solves each candidate with its own rung: a region joined into a BEM candidate's patch would lose
            # the force its own (compiled) rung gives it, so auto's BEM forms a patch as always-BEM does (CONTACT's
            # plane) only when it holds the candidate's region alone, else samples the candidate on its own plane
            self.callback.patches = "auto"
            level = float(self.par["auto_level"])
            self.callback.reuse = (self.packed.tables.reuse, None if np.isnan(level) else level,
                                   self.par["auto_reuse"] > 0)  # fmt: skip
        self.auto = code == LAW_AUTO
        ncand = len(self.packed.sides)
        self._rec = np.zeros((ncand + 2, N_FIELDS))
        self._cg = np.full((ncand, N_GEO), np.nan)

    def full_state(self, state: np.ndarray) -> np.ndarray:
        """The full state of a 12-state: work integrals 0 and, with the elastic track, ``track_rest``."""
        parts = [np.asarray(state, float)[:12], [0.0, 0.0]]
        if self.elastic:
            parts.append(self.track_rest)
        return np.concatenate(parts)

    def static_track(self, rail_force_N) -> np.ndarray:
        """Track states at rest under the vertical rail forces (left, right), N, with the wheelset at its start
        (track_matrices.TrackSystem.rest_state).
        """
        return self.track_system.rest_state(rail_force_N)

    def rail_under_wheels(self, full: np.ndarray) -> np.ndarray:
        """The rails' deflection (left, right) and velocity (left, right) under the wheels at a full state, (4,), m
        and m/s, z down (track.rail_under_wheel; zeros on the rigid track).
        """
        out = np.zeros(4)
        if self.elastic:
            self.par["frame_x0_m"] = self.frame_x0
            for side in (0, 1):
                out[side], out[2 + side] = track_model.rail_under_wheel(self.par, full, side)
        return out

    def rail_lateral_under_wheels(self, full: np.ndarray) -> np.ndarray:
        """The rails' lateral displacement (left, right) and velocity (left, right) under the wheels at a full state,
        (4,), m and m/s, y along the track's lateral axis (track.rail_lateral_under_wheel; zeros without the lateral
        track).
        """
        out = np.zeros(4)
        if self.elastic and self.track.lateral:
            for side in (0, 1):
                out[side], out[2 + side] = track_model.rail_lateral_under_wheel(self.par, full, side)
        return out

    def patches_on_track(self, centre, yaw, roll, spin, shift=None, lateral=None):
        """The provider's patches with the rails lowered by ``shift`` (left, right), m, and moved laterally by
        ``lateral`` (left, right), m (None: rigid track, no lateral track).

        A rail lowered by w and moved by u is the wheelset raised by w and moved by -u for that side's contact: the
        provider is asked at the centre so moved per side and the contact points are moved back (levers unchanged).
        """
        offsets = np.zeros((2, 3))
        if shift is not None:
            offsets[:, 2] = -np.asarray(shift, float)
        if lateral is not None:
            offsets[:, 1] = -np.asarray(lateral, float)
        if not np.any(offsets):
            return self.provider.patches(centre, yaw, roll, spin)
        from dataclasses import replace

        from rigid_dynamics.wheelset.providers import PatchSet

        sets = []
        for offset in (offsets[0],) if np.array_equal(offsets[0], offsets[1]) else (offsets[0], offsets[1]):
            sets.append(self.provider.patches(np.array(centre, float) + offset, yaw, roll, spin))
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
        fields["point_m"] = fields["point_m"] - offsets[fields["side"]]
        geometries = None
        if sets[0].geometries is not None:
            geometries = []
            for p, k in zip(sets, pick, strict=True):
                for i in k:
                    g = p.geometries[i]
                    point = np.array(g.point_m, float) - offsets[int(p.side[i])]
                    geometries.append(replace(g, point_m=point))
        return PatchSet(geometries=geometries, **fields)

    # ----------------------------------------------------------------------------------------------
    def _compiled_rhs(self, t: float, full: np.ndarray, out: np.ndarray, record: bool) -> int:
        """The compiled right-hand side (compiled_rhs.rhs_once / rhs_given) at the full state into ``out``; the
        candidates into self._rec (and self._cg with ``record``). Returns its status (layout.STATUS).
        """
        run = self.packed
        if len(full) != self.n_state or len(out) != self.n_state:  # the compiled code does not check bounds
            raise ValueError(f"full state of length {len(full)}: this run's state has {self.n_state} entries")
        run.par["frame_x0_m"] = self.frame_x0
        compiled_rhs.use_callback(self.callback)
        if run.mode == GEOMETRY_GIVEN:
            self._given_geometry(full)
            return int(
                compiled_rhs.rhs_given(float(t), full, run.par, run.tables, run.sides, self._cg, out, self._rec, record)
            )
        if record:
            return int(compiled_rhs.contact_once(float(t), full, run, out, self._rec, self._cg))
        return int(compiled_rhs.rhs_once(float(t), full, run, out, self._rec))

    def _given_geometry(self, full: np.ndarray) -> None:
        """The geometry given by Python (layout.GEOMETRY_GIVEN): the provider's candidates into self._cg (side s,
        slot k at row 2 s + k; rows without a candidate NaN) and their sampled geometries (if any) to the callback.
        """
        track = self.rail_under_wheels(full)[0:2] if self.elastic else None
        patches = self.patches_on_track(
            full[0:3], full[3], full[4], full[5], track, self.rail_lateral_under_wheels(full)[0:2]
        )  # zero offsets (rigid or no lateral track): the provider's own patches
        cg = self._cg
        cg[:, :] = np.nan
        geometries = {}
        for k in range(len(patches)):
            side, slot = int(patches.side[k]), int(patches.slot[k])
            if slot >= MAX_SLOTS:
                raise ContactFailure(f"provider {self.provider.name!r}: more than {MAX_SLOTS} candidates on a side")
            c = 2 * side + slot
            cg[c, G_APPROACH] = patches.approach_m[k]
            cg[c, G_LEVER : G_LEVER + 3] = patches.point_m[k] - full[0:3]
            cg[c, G_NORMAL : G_NORMAL + 3] = patches.normal[k]
            cg[c, G_CURVATURE_LONG] = patches.curvature_long_1_per_m[k]
            cg[c, G_CURVATURE_LAT] = patches.curvature_lat_1_per_m[k]
            cg[c, G_ROLLING_RADIUS], cg[c, G_WHEEL_LATERAL] = patches.rolling_radius_m[k], patches.wheel_lateral_m[k]
            cg[c, G_CONTACT_ANGLE] = patches.contact_angle_rad[k]
            if patches.geometries is not None:
                geometries[c] = patches.geometries[k]
        if self.callback is not None:
            self.callback.geometries = geometries

    @contextlib.contextmanager
    def _search_memory_kept(self, keep: bool):
        """With ``keep``: the compiled search's warm starts (its only state) restored after the block."""
        search = self.packed.search
        memory = [np.copy(search.mem), np.copy(search.n_mem)] if keep and self.mode == GEOMETRY_SEARCH else None
        try:
            yield
        finally:
            if memory is not None:
                search.mem[...], search.n_mem[...] = memory

    def _failure(self, status: int, t: float) -> ContactFailure:
        if status == CALLBACK_FAILED and self.callback is not None:
            return ContactFailure(self.callback.message)
        if status == CREEPAGES_UNDEFINED:
            return ContactFailure(f"rolling speed not > 0 at a contact (t = {t:.6g} s): creepages undefined")
        return ContactFailure(
            f"compiled right-hand side: status {status} ({status_name(status)}, t = {t:.6g} s): {STATUS[status][1]}"
        )

    def contact(
        self, state: np.ndarray, record: bool = False, track: np.ndarray | None = None, keep_search_memory=False
    ) -> ContactState:
        """Contact of every candidate (approach, geometry; forces where approach > 0) at a 12-state, for inspection
        and recording: the compiled right-hand side's candidates with their contact frames.

        With ``record`` the per-patch values (PATCH_FIELDS, and AUTO_PATCH_FIELDS for ``auto``: the candidates', the
        loop's; FORMED_PATCH_FIELDS: a formed patch's own, NaN for other candidates) are filled, else ``values`` is
        None; ContactState.record is what the run records (a formed patch's own quantities in place). ``track``: the
        elastic track's states; None: ``track_rest`` (rigid track: ignored). ``keep_search_memory``: leave the
        compiled search's warm starts as they were (a look that must not change the run).
        """
        full = self.full_state(state)
        if self.elastic and track is not None:
            full[TRACK] = track
        out = np.empty(self.n_state)
        with self._search_memory_kept(keep_search_memory):
            status = self._compiled_rhs(0.0, full, out, True)
        if status != 0:
            raise self._failure(status, 0.0)
        sides, slots = self.packed.sides, self.packed.slots
        present = np.flatnonzero(~np.isnan(self._cg[:, G_APPROACH]))
        rec, cg = self._rec[present], self._cg[present]
        centre, v_c = full[0:3], full[6:9]
        _, _, omega = rotation_and_rates(*full[3:6], *full[9:12])
        lever, normal = cg[:, G_LEVER : G_LEVER + 3], cg[:, G_NORMAL : G_NORMAL + 3]
        velocity = v_c + _cross_rows(omega, lever)
        rail_velocity = np.zeros((len(present), 3))
        if self.elastic:
            rail_velocity[:, 2] = self.rail_under_wheels(full)[2:4][sides[present]]
            rail_velocity[:, 1] = self.rail_lateral_under_wheels(full)[2:4][sides[present]]
        velocity = velocity - rail_velocity
        frames, _, _, _, _ = _creepages(lever, normal, omega, v_c, rail_velocity)
        active = np.nan_to_num(rec[:, NORMAL_FORCE], nan=0.0) > 0
        t_x, t_y, n_f, m_z = (
            np.where(active, np.nan_to_num(rec[:, k]), 0.0)
            for k in (CREEP_FORCE_LONG, CREEP_FORCE_LAT, NORMAL_FORCE, SPIN_MOMENT)
        )
        force = frames[:, :, 0] * t_x[:, None] + frames[:, :, 1] * t_y[:, None] + frames[:, :, 2] * n_f[:, None]
        moment = frames[:, :, 2] * m_z[:, None]
        force[~active] = 0.0
        moment[~active] = 0.0
        values = None
        if record:
            values = {name: rec[:, f].copy() for f, name in record_columns(self.auto)}
            values["contact_point_y_m"] = centre[1] + lever[:, 1]
        return ContactState(sides[present], slots[present], force, moment, lever.copy(), velocity, values)

    def derivative(self, t: float, state: np.ndarray) -> np.ndarray:
        """d/dt of the full state (12 mechanical + 2 work integrals [+ the track's states, TRACK]) by the compiled
        right-hand side (compiled_rhs._rhs's geometry, compiled laws and callback, compiled_motion._assemble): the one
        implementation, also for the scipy methods and the Python RK4.

        Raises:
            ContactFailure: creepages undefined or the contact model failed.
        """
        self.rhs_evaluations += 1
        full = np.array(state, float)
        out = np.empty(self.n_state)
        status = self._compiled_rhs(t, full, out, False)
        if status != 0:
            raise self._failure(status, t)
        return out

    def side_forces(self) -> np.ndarray:
        """Per wheel (left, right) the contact force of the last right-hand side, main frame, (2, 3), N: only set
        by a recording call (:meth:`contact`).
        """
        ncand = len(self.packed.sides)
        return self._rec[ncand : ncand + 2, :3].copy()

    def _track_derivative(self, track, rail_force, out, x_m: float = 0.0) -> float:
        """d/dt of the track's states into ``out`` under the rail forces (left, right) (compiled_motion.track_rates)
        with the wheelset at x (the beam: xi = x - x0 + margin); returns the dampers' power.
        """
        full = np.zeros(self.n_state)
        full[0] = x_m
        full[TRACK] = track
        rates = np.zeros(self.n_state)
        power = track_rates(self.par, full, np.asarray(rail_force, float), rates)
        out[:] = rates[TRACK]
        return float(power)

    def state_jacobian(self, fun, y: np.ndarray, rel_step: float = 1e-8) -> np.ndarray:
        """Jacobian of ``fun`` (this model's full-state rates) at ``y``, by central differences
        (stability.jacobian) in the mechanical states and the work integrals; on the beam the track's columns from
        the structure of the equations: the track's own rates are linear in its states (TrackSystem), and the
        contact sees the track only through the rail's deflection and velocity under each wheel
        (track.rail_under_wheel, linear in the modes: b(xi)). So column j of the track is
        A e_j + sum_k G_k dq_k/dy_j, q = (w left, w right, v left, v right) under the wheels, with G_k the
        difference quotient along a track direction d_k that moves q_k alone (by one), less A d_k; 8 more
        evaluations instead of two per track state; the lateral track's 4 columns by differences. Other tracks: all
        columns by differences.
        """
        from rigid_dynamics.wheelset.stability import jacobian

        y = np.asarray(y, float)
        n = len(y)
        if not self.elastic or self.track_system.layout is None:
            return jacobian(fun, y, rel_step)
        system = self.track_system
        npos = system.n_positions
        lateral = []  # the lateral track's columns: by differences (4 of them)
        if system.lateral:
            lateral = [int(N_RIGID + offset + r) for offset in (0, npos) for r in system.lateral_rows()]
        jac = jacobian(fun, y, rel_step, columns=list(range(N_RIGID)) + lateral)
        vertical = np.setdiff1d(np.arange(2 * npos), np.array(lateral, int) - N_RIGID)
        xi = float(y[0]) - self.frame_x0 + system.start_position_m()
        b = system.load_vector(xi)  # the rail's deflection under the wheel is b . q of its rows
        linear = np.zeros((2 * npos, 2 * npos))
        probes = []
        for side in (0, 1):
            r = system.rows(side)
            linear[np.ix_(r, npos + r)] = np.eye(len(r))
            linear[np.ix_(npos + r, r)] = -system.stiffness / system.mass[:, None]
            linear[np.ix_(npos + r, npos + r)] = -system.damping / system.mass[:, None]
            for offset in (0, npos):  # deflection, then velocity
                d = np.zeros(2 * npos)
                d[offset + r] = b / (b @ b)
                coupling = np.zeros(2 * npos)
                coupling[offset + r] = b
                probes.append((d, coupling))
        jac[N_RIGID:, N_RIGID + vertical] = linear[:, vertical]
        for d, coupling in probes:
            full_d = np.zeros(n)
            full_d[N_RIGID:] = d
            h = rel_step  # q_k moves by rel_step (m or m/s)
            g = (np.asarray(fun(y + h * full_d)) - np.asarray(fun(y - h * full_d))) / (2.0 * h)
            g[N_RIGID:] -= linear @ d
            jac[:, N_RIGID:] += np.outer(g, coupling)
        return jac

    def track_energy_J(self, track) -> tuple:
        """(kinetic, potential) energy of the elastic track's states (n, k) or (k,), J
        (track_matrices.TrackSystem.energy_J; 0, 0 on the rigid track).
        """
        if not self.elastic:
            return 0.0, 0.0
        return self.track_system.energy_J(track)

    # ----------------------------------------------------------------------------------------------
    def kinetic_energy_J(self, state: np.ndarray) -> float:
        """T = m |v|^2/2 + omega . J omega / 2, J."""
        _, rzx, omega = rotation_and_rates(*state[3:6], *state[9:12])
        j_main = rzx @ self.j_body @ rzx.T
        return 0.5 * self.mass * float(state[6:9] @ state[6:9]) + 0.5 * float(omega @ j_main @ omega)

    def potential_energy_J(self, state: np.ndarray) -> float:
        """Gravity potential V_g = -m g z (z down), J."""
        return -self.mass * self.gravity * float(state[2])

    def contact_approaches(self, state: np.ndarray, keep_search_memory=False) -> list:
        """Per wheel (left, right) the approaches of its candidates at a 12-state on ``track_rest``, m: the geometry
        alone (compiled_rhs.geometry_once; the given geometry: the provider), no contact model.
        """
        full = self.full_state(state)
        sides = self.packed.sides
        if self.packed.mode == GEOMETRY_GIVEN:
            self._given_geometry(full)
        else:
            with self._search_memory_kept(keep_search_memory):
                compiled_rhs.geometry_once(full, self.packed, self._cg)
        q = self._cg[:, G_APPROACH]
        return [q[(sides == i) & ~np.isnan(q)] for i in (0, 1)]

    def deepest_approach(self, state: np.ndarray) -> list:
        """Per wheel (left, right) the deepest approach of its candidates at a 12-state on ``track_rest``, m."""
        return [float(np.max(q)) if len(q) else 0.0 for q in self.contact_approaches(state)]

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

        failure = []

        def residual(v):
            trial = work.copy()
            trial[2], trial[4] = v
            full = self.full_state(trial)
            try:
                d = derivative(0.0, full)
            except ContactFailure as exc:
                failure[:] = [str(exc)]
                return np.array([1e3, 1e3])
            return np.array([d[8], d[10] * 0.1])

        # bring both wheels to about the static approach before iterating (no contact = flat residual)
        # (a roll theta lowers the right wheel by about e0 theta and lifts the left one: level them first)
        e0 = self.scene.wheelset.contact_half_distance_m
        for _ in range(6):
            deepest = (deepest_approach or self.deepest_approach)(work)
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
        if not ok and failure:
            message += f"; the contact failed: {failure[0]}"
        approach = self.contact_approaches(work, keep_search_memory=True)
        touching = [bool(np.any(approach[i] > 0)) for i in (0, 1)]
        if ok and not all(touching):
            ok, message = False, "the equilibrium found has a wheel off its rail (no contact at rest)"
        return work, ok, message
