"""Recording a run: the output samples with their contact patches, energies and force error estimates, checked
for anomalies (blow-up, force anomaly, derailment, wheel lift) and events (lift, contact restored, flange contact).
``Stop`` is the exception by which a driver or the recorder ends a run with a status.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.formed_patches import recorded
from rigid_dynamics.wheelset.layout import AUTO_PATCH_FIELDS, FORMED_PATCH_FIELDS, MAX_SLOTS, PATCH_FIELDS
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import SIDES
from rigid_dynamics.wheelset.state import TRACK
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

NUMERICAL_ERRORS = (ValueError, ArithmeticError, np.linalg.LinAlgError)
"""Exceptions that the static equilibrium or the integration can raise from below for numerical trouble: turned
into a status (``invalid-initial-state``, ``solver-failed``) at the driver, never a traceback."""


MAX_RAIL_DEFLECTION_M = 0.05
"""A rail deflected this far under a wheel (a hundred times a static deflection) ends the run as "blow-up": the track's
states diverged (an RK4 step beyond the stability limit of the beam's rail modes can leave every other state finite)."""


class Stop(Exception):
    def __init__(self, status: str, message: str, t: float | None = None, state=None):
        super().__init__(message)
        self.status, self.message, self.t, self.state = status, message, t, state


class Recorder:
    """Collects output samples and detects events and anomalies on them. Samples are kept as blocks of rows (one
    row from :meth:`append`, many from :meth:`append_many`), joined by :meth:`arrays`.
    """

    def __init__(self, model: WheelsetModel, scene: DynamicsScene):
        self.model = model
        self.scene = scene
        self.t: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        auto = getattr(model.model, "name", "") == "auto"
        self.fields = PATCH_FIELDS + (AUTO_PATCH_FIELDS if auto else ())
        self.patches = {name: [] for name in self.fields}
        self.forces: list[np.ndarray] = []
        self.kinetic: list[np.ndarray] = []
        self.potential: list[np.ndarray] = []
        self.work_contact: list[np.ndarray] = []
        self.work_exterior: list[np.ndarray] = []
        self.errors: list[np.ndarray] = []
        self.track: list[np.ndarray] = []
        self.track_summary: list[np.ndarray] = []
        self.events: list[tuple] = []
        self.in_contact = None
        self.flange = None
        self.limit_force = scene.integrator.max_force_factor * scene.static_wheel_load_N
        self.limit_y = scene.integrator.max_lateral_displacement_m
        self.flange_angle = scene.track.flange_contact_angle_rad

    def record(self, t: float, full_state: np.ndarray, error: float = math.nan) -> None:
        """Check and store the sample at (t, full_state) with the force error estimate of the steps since the last
        sample (N; NaN: none).
        """
        state = full_state[:12]
        if not np.all(np.isfinite(full_state)):
            raise Stop("blow-up", f"non-finite state at t = {t:.6g} s", t, state)
        contact = self.model.contact(state, record=True, track=full_state[TRACK] if self.model.elastic else None)
        table = {name: np.full((2, MAX_SLOTS), np.nan) for name in self.fields + FORMED_PATCH_FIELDS}
        for k in range(len(contact.side)):
            side, slot = int(contact.side[k]), int(contact.slot[k])
            if slot >= MAX_SLOTS:
                continue
            for name in table:
                if name in contact.values:
                    table[name][side, slot] = contact.values[name][k]
        forces = np.zeros((2, 3))
        np.add.at(forces, contact.side, contact.force_N)
        self.append(t, full_state, table, forces, error)

    def append(
        self, t: float, full_state: np.ndarray, table: dict, forces: np.ndarray, error: float = math.nan
    ) -> None:
        """Check and store one sample (patch table: PATCH_FIELDS -> (2, 2); forces per side (2, 3); the force error
        estimate of the step ending there, relative to the static wheel load). The checks and events read the
        candidates' values (the loop's, as the compiled loop's own checks); the table is stored as the record
        (formed_patches.recorded: a formed patch's own quantities from the table's FORMED_PATCH_FIELDS).
        """
        state = full_state[:12]
        normal = np.nansum(table["normal_force_N"], axis=1)
        if not (np.all(np.isfinite(forces)) and np.all(np.isfinite(normal))):
            raise Stop("blow-up", f"non-finite contact force at t = {t:.6g} s", t, state)
        if np.max(normal) > self.limit_force:
            raise Stop(
                "force-anomaly",
                f"normal force {np.max(normal):.4g} N exceeds {self.limit_force:.4g} N "
                f"(max_force_factor x static wheel load) at t = {t:.6g} s",
                t,
                state,
            )
        if abs(state[1]) > self.limit_y:
            raise Stop(
                "derailed", f"|y| = {abs(state[1]):.4g} m exceeds {self.limit_y:.4g} m at t = {t:.6g} s", t, state
            )
        summary = self._summary(np.asarray(full_state, float)[None]) if self.model.elastic else None
        if summary is not None:
            rail = float(np.max(np.abs(summary[0, :2])))
            if rail > MAX_RAIL_DEFLECTION_M:
                raise Stop(
                    "blow-up",
                    f"rail deflection {rail:.4g} m under a wheel exceeds {MAX_RAIL_DEFLECTION_M:g} m (the track's "
                    f"states diverged) at t = {t:.6g} s",
                    t,
                    state,
                )
        touching = normal > 0
        flange = np.array(
            [
                bool(np.any((table["contact_angle_rad"][i] > self.flange_angle) & (table["normal_force_N"][i] > 0)))
                for i in range(2)
            ]
        )
        if self.in_contact is not None:
            for i, side in enumerate(SIDES):
                if self.in_contact[i] and not touching[i]:
                    self.events.append(("wheel-lift", side, t))
                elif touching[i] and not self.in_contact[i]:
                    self.events.append(("contact-restored", side, t))
                if flange[i] and not self.flange[i]:
                    self.events.append(("flange-contact", side, t))
        self.in_contact, self.flange = touching, flange
        self.t.append(np.array([t], float))
        self.states.append(state[None].copy())
        table = recorded(table)
        for name in self.fields:
            self.patches[name].append(np.asarray(table.get(name, np.full((2, MAX_SLOTS), np.nan)), float)[None])
        self.forces.append(np.asarray(forces, float)[None])
        track_kinetic, track_potential = self.model.track_energy_J(full_state[TRACK])
        self.kinetic.append(np.array([self.model.kinetic_energy_J(state) + track_kinetic], float))
        self.potential.append(np.array([self.model.potential_energy_J(state) + track_potential], float))
        if self.model.elastic:
            self.track.append(np.asarray(full_state[TRACK], float)[None].copy())
            self.track_summary.append(summary)
        self.work_contact.append(np.array([full_state[12]], float))
        self.work_exterior.append(np.array([full_state[13]], float))
        self.errors.append(np.array([error], float))
        if self.scene.integrator.stop_at_wheel_lift and not np.all(touching):
            side = SIDES[int(np.argmin(touching))]
            raise Stop("wheel-lift", f"the {side} wheel lost contact at t = {t:.6g} s", t, state)

    def set_last_error(self, error: float) -> None:
        """Set the force error estimate of the last sample (N; NaN: none)."""
        self.errors[-1] = np.array([error], float)

    def append_many(self, times, full_states, tables: dict, forces, errors) -> None:
        """Vectorised :meth:`append` for many samples (tables: name -> (n, 2, 2); forces (n, 2, 3); errors (n,)), its
        checks, events and record as :meth:`append`'s.
        """
        n = len(times)
        if n == 0:
            return
        normal = np.nansum(tables["normal_force_N"], axis=2)
        bad = ~(np.all(np.isfinite(full_states), axis=1) & np.all(np.isfinite(forces), axis=(1, 2)))
        bad |= ~np.all(np.isfinite(normal), axis=1)
        bad |= np.max(normal, axis=1) > self.limit_force
        bad |= np.abs(full_states[:, 1]) > self.limit_y
        summary = self._summary(full_states) if self.model.elastic else None
        if summary is not None:
            bad |= np.max(np.abs(summary[:, :2]), axis=1) > MAX_RAIL_DEFLECTION_M
        touching = normal > 0
        if self.scene.integrator.stop_at_wheel_lift:
            bad |= ~np.all(touching, axis=1)
        stop = int(np.argmax(bad)) if np.any(bad) else n
        if stop < n:
            # store the good samples, then let append() raise with the right status on the bad one
            if stop:
                self.append_many(
                    times[:stop],
                    full_states[:stop],
                    {k: v[:stop] for k, v in tables.items()},
                    forces[:stop],
                    errors[:stop],
                )
            self.append(
                float(times[stop]),
                full_states[stop],
                {k: v[stop] for k, v in tables.items()},
                forces[stop],
                float(errors[stop]),
            )
            return
        flange = np.any((tables["contact_angle_rad"] > self.flange_angle) & (tables["normal_force_N"] > 0), axis=2)
        prev_touch = np.vstack([self.in_contact if self.in_contact is not None else touching[:1], touching[:-1]])
        prev_flange = np.vstack([self.flange if self.flange is not None else flange[:1], flange[:-1]])
        for k, i in zip(*np.nonzero(prev_touch & ~touching), strict=True):
            self.events.append(("wheel-lift", SIDES[i], float(times[k])))
        for k, i in zip(*np.nonzero(~prev_touch & touching), strict=True):
            self.events.append(("contact-restored", SIDES[i], float(times[k])))
        for k, i in zip(*np.nonzero(flange & ~prev_flange), strict=True):
            self.events.append(("flange-contact", SIDES[i], float(times[k])))
        self.events.sort(key=lambda e: e[2])
        self.in_contact, self.flange = touching[-1], flange[-1]
        states = full_states[:, :12]
        self.t.append(np.asarray(times, float).copy())
        self.states.append(states.copy())
        tables = recorded(tables)
        for name in self.fields:
            self.patches[name].append(np.asarray(tables.get(name, np.full((n, 2, MAX_SLOTS), np.nan)), float).copy())
        self.forces.append(np.asarray(forces, float).copy())
        # kinetic energy m|v|^2/2 + omega.J omega/2, J = R diag(Jt, Ja, Jt) R^T (R = R_z R_x), vectorised
        psi, theta = states[:, 3], states[:, 4]
        yr, rr, sr = states[:, 9], states[:, 10], states[:, 11]
        cps, sps, cth, sth = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta)
        omega = np.stack([rr * cps + sr * sps * cth, rr * sps - sr * cps * cth, yr - sr * sth], axis=-1)
        rzx = np.stack(
            [
                np.stack([cps, -sps * cth, sps * sth], -1),
                np.stack([sps, cps * cth, -cps * sth], -1),
                np.stack([np.zeros_like(cps), sth, cth], -1),
            ],
            -2,
        )
        body = np.einsum("nji,nj->ni", rzx, omega)
        j_diag = np.diag(self.model.j_body)
        kinetic = 0.5 * self.model.mass * np.sum(states[:, 6:9] ** 2, axis=1) + 0.5 * np.sum(j_diag * body**2, axis=1)
        track_kinetic, track_potential = self.model.track_energy_J(full_states[:, TRACK])
        self.kinetic.append(kinetic + track_kinetic)
        self.potential.append(-self.model.mass * self.model.gravity * states[:, 2] + track_potential)
        if self.model.elastic:
            self.track.append(np.asarray(full_states[:, TRACK], float).copy())
            self.track_summary.append(summary)
        self.work_contact.append(full_states[:, 12].copy())
        self.work_exterior.append(full_states[:, 13].copy())
        self.errors.append(np.asarray(errors, float).copy())

    def arrays(self):
        def joined(blocks, empty_shape):
            return np.concatenate(blocks) if blocks else np.zeros(empty_shape)

        patches = {name: joined(v, (0, 2, MAX_SLOTS)) for name, v in self.patches.items()}
        return (
            joined(self.t, (0,)),
            joined(self.states, (0, 12)),
            patches,
            joined(self.forces, (0, 2, 3)),
            joined(self.kinetic, (0,)),
            joined(self.potential, (0,)),
            joined(self.work_contact, (0,)),
            joined(self.work_exterior, (0,)),
            joined(self.errors, (0,)),
            joined(self.track, (0, self.model.n_state - 14)) if self.model.elastic else None,
        )

    def _summary(self, full_states: np.ndarray) -> np.ndarray:
        """What the run records of the track at full states (n, n_state): track_matrices.TrackSystem.summary."""
        system = self.model.track_system
        xi = full_states[:, 0] - self.model.frame_x0 + system.start_position_m()
        return system.summary(full_states[:, TRACK], xi)

    def summary_arrays(self):
        """(names, (n, k) array) of the recorded track summary (None, None on the rigid track)."""
        if not self.model.elastic:
            return None, None
        system = self.model.track_system
        blocks = self.track_summary
        return system.summary_names, np.concatenate(blocks) if blocks else np.zeros((0, len(system.summary_names)))


WHEEL_SLIDE_CREEPAGE = 0.05
"""|xi| at which a wheel past its adhesion limit is said to slide (a definition: 5 % slip, beyond the creep-force
maximum of the laws here, whose maxima lie below 1 % creepage at rolling speeds of 10-30 m/s)."""
ADHESION_DROP = 0.01
"""The fall of the adhesion ratio |T_x| / N below its maximum (relative) that marks the maximum as passed."""


def adhesion_events(t: np.ndarray, patches: dict) -> list[tuple]:
    """The adhesion limit and wheel slide of a driven or braked wheelset, per side, from the recorded samples.

    Per side (both slots summed): the adhesion ratio f = |T_x| / N (longitudinal creep force over normal force) and
    the longitudinal creepage xi of the patch with the larger normal force.

    * ``"adhesion-limit"`` at the sample where f is largest, when later the creepage grows beyond its value there
      while f falls by more than :data:`ADHESION_DROP` of it (the creep curve's maximum passed: the falling branch);
    * ``"wheel-slide"`` at the first sample after that with |xi| >= :data:`WHEEL_SLIDE_CREEPAGE`.

    Returns tuples (kind, side, time_s) as the recorder's events.
    """
    events: list[tuple] = []
    if len(t) < 3:
        return events
    normal = np.nan_to_num(patches["normal_force_N"])
    tx = np.nan_to_num(patches["creep_force_long_N"])
    xi_all = np.nan_to_num(patches["creepage_long"])
    for i, side in enumerate(SIDES):
        n_side = normal[:, i, :].sum(axis=1)
        ratio = np.where(n_side > 0.0, np.abs(tx[:, i, :].sum(axis=1)) / np.where(n_side > 0.0, n_side, 1.0), 0.0)
        main = np.argmax(normal[:, i, :], axis=1)
        xi = np.abs(xi_all[np.arange(len(t)), i, main])
        peak = int(np.argmax(ratio))
        later = np.arange(len(t)) > peak
        past = later & (xi > xi[peak]) & (ratio < (1.0 - ADHESION_DROP) * ratio[peak])
        if not np.any(past):
            continue
        events.append(("adhesion-limit", side, float(t[peak])))
        sliding = later & (xi >= WHEEL_SLIDE_CREEPAGE)
        if np.any(sliding):
            events.append(("wheel-slide", side, float(t[int(np.argmax(sliding))])))
    return events
