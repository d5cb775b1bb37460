"""The elastic track of a run as matrices (per rail M q'' + C q' + K q = b(x) F): the same equations as the compiled
:func:`rigid_dynamics.wheelset.track.track_rates`, in the form the rest state, the energy, the receptance, the
eigenfrequencies and the recorded summary need. The track's models, data and compiled rates: track.py.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.state import LATERAL_STATE_NAMES, N_RIGID, n_states, state_names
from rigid_dynamics.wheelset.track import TrackDynamics, beam_layout, flexural_frequency_rad_per_s

BEAM_SUMMARY_NAMES = (
    "rail_left_m",
    "rail_right_m",
    "rail_left_velocity_m_per_s",
    "rail_right_velocity_m_per_s",
)
"""What a run records of the beam: the rail's deflection (z down) and velocity under each wheel."""


class TrackSystem:
    """The elastic track of a run as matrices: per rail M q'' + C q' + K q = b(xi) F, F the vertical contact force
    on that rail (z down) and xi where the wheelset is; both rails alike and uncoupled.

    The same equations as :func:`track_rates` (a regression test compares them), in the form the rest state, the
    energy, the receptance and the eigenfrequencies need. ``rows(side)``: the rail's positions within the track's
    positions (lumped: [rail, sleeper] of that side; beam: the rail's block of BeamLayout).
    """

    def __init__(self, track: TrackDynamics, travel: float):
        if not track.elastic:
            raise ValueError("TrackSystem: the rigid track has no states")
        self.track = track
        self.model = track.model
        self.layout = None
        self.lateral = track.lateral
        if track.model == "lumped":
            kp, kb, cp, cb = (track.pad_stiffness_N_per_m, track.ballast_stiffness_N_per_m,
                              track.pad_damping_N_s_per_m, track.ballast_damping_N_s_per_m)  # fmt: skip
            self.mass = np.array([track.rail_mass_kg, track.sleeper_mass_kg])
            self.stiffness = np.array([[kp, -kp], [-kp, kp + kb]])
            self.damping = np.array([[cp, -cp], [-cp, cp + cb]])
            self.n_vertical = 4
            self.n_positions = 4 + (2 if self.lateral else 0)
            self.summary_names = state_names(n_states(self.n_positions))[N_RIGID:]  # every state, named by state.py
            return
        layout = self.layout = beam_layout(track, travel)
        nm, ns, length = layout.n_modes, layout.n_sleepers, layout.length_m
        self.n_vertical = layout.n_positions
        self.n_positions = layout.n_positions + (2 if self.lateral else 0)
        self.summary_names = BEAM_SUMMARY_NAMES + (LATERAL_STATE_NAMES if self.lateral else ())
        k = np.arange(1, nm + 1) * math.pi / length
        self.wavenumber_1_per_m = k
        self.seat_m = (np.arange(ns) + 1.0) * track.sleeper_spacing_m
        phi = np.sin(np.outer(self.seat_m, k))  # (seats, modes)
        n_w = nm * (2 if layout.timoshenko else 1)
        n = layout.per_rail
        ei, ga, half = track.rail_bending_stiffness_N_m2, track.rail_shear_stiffness_N, 0.5 * length
        mass = np.empty(n)
        mass[:nm] = half * track.rail_mass_per_length_kg_per_m
        stiff = np.zeros((n, n))
        w_rows = np.arange(nm)
        if layout.timoshenko:
            p_rows = nm + w_rows
            mass[nm:n_w] = half * track.rail_rotary_inertia_kg_m
            stiff[w_rows, w_rows] = half * ga * k * k
            stiff[w_rows, p_rows] = stiff[p_rows, w_rows] = -half * ga * k
            stiff[p_rows, p_rows] = half * (ei * k * k + ga)
        else:
            stiff[w_rows, w_rows] = half * ei * k**4
        mass[n_w:] = track.seat_sleeper_mass_kg
        damp = np.zeros((n, n))
        damp[w_rows, w_rows] = track.rail_loss_factor * flexural_frequency_rad_per_s(track, k) * mass[:nm]
        z_rows = n_w + np.arange(ns)
        for matrix, pad, ballast in (
            (stiff, track.seat_pad_stiffness_N_per_m, track.seat_ballast_stiffness_N_per_m),
            (damp, track.seat_pad_damping_N_s_per_m, track.seat_ballast_damping_N_s_per_m),
        ):
            matrix[:nm, :nm] += pad * phi.T @ phi
            matrix[np.ix_(w_rows, z_rows)] -= pad * phi.T
            matrix[np.ix_(z_rows, w_rows)] -= pad * phi
            matrix[z_rows, z_rows] += pad + ballast
        self.mass, self.stiffness, self.damping = mass, stiff, damp

    def rows(self, side: int) -> np.ndarray:
        """The rail's positions within the track's positions (its rates: + n_positions)."""
        if self.layout is None:
            return np.array([side, 2 + side])
        return side * self.layout.per_rail + np.arange(self.layout.per_rail)

    def load_vector(self, xi_m: float) -> np.ndarray:
        """b(xi): the generalised forces of a unit force on the rail at xi (lumped: on the rail mass)."""
        if self.layout is None:
            return np.array([1.0, 0.0])
        b = np.zeros(self.layout.per_rail)
        b[: self.layout.n_modes] = np.sin(self.wavenumber_1_per_m * xi_m)
        return b

    def start_position_m(self) -> float:
        """Where the wheelset is along the beam at t = 0 (xi = margin; 0 for the lumped track)."""
        return 0.0 if self.layout is None else self.layout.margin_m

    def lateral_rows(self) -> np.ndarray:
        """The lateral rails' positions (left, right) within the track's positions (their rates: + n_positions)."""
        return self.n_vertical + np.arange(2)

    def rest_state(self, rail_force_N, xi_m: float | None = None) -> np.ndarray:
        """The track's states (positions, then zero rates) at rest under the vertical rail forces (left, right), N,
        applied at xi (default: the start): K q = b F per rail; with the lateral track and 4 forces (vertical left,
        right, lateral left, right) the lateral rails at F_y / k_y.
        """
        xi = self.start_position_m() if xi_m is None else xi_m
        out = np.zeros(2 * self.n_positions)
        b = self.load_vector(xi)
        for side in (0, 1):
            out[self.rows(side)] = np.linalg.solve(self.stiffness, b * float(rail_force_N[side]))
        if self.lateral and len(rail_force_N) > 2:
            out[self.lateral_rows()] = np.asarray(rail_force_N[2:4], float) / self.track.lateral_rail_stiffness_N_per_m
        return out

    def rail_forces_at_rest(self, rest, rates, xi_m: float | None = None) -> np.ndarray:
        """The vertical contact force on each rail (left, right), N, of a track at rest in ``rest`` whose rates the
        right-hand side gives as ``rates`` (track part of the full state): b F = M q'' + K q (least squares in F);
        with the lateral track then the lateral ones (left, right), m_y u'' + k_y u.
        """
        xi = self.start_position_m() if xi_m is None else xi_m
        b = self.load_vector(xi)
        rest, rates = np.asarray(rest, float), np.asarray(rates, float)
        force = np.zeros(4 if self.lateral else 2)
        for side in (0, 1):
            r = self.rows(side)
            lhs = self.mass * rates[self.n_positions + r] + self.stiffness @ rest[r]
            force[side] = float(b @ lhs / (b @ b))
        if self.lateral:
            r = self.lateral_rows()
            tr = self.track
            force[2:4] = (
                tr.lateral_rail_mass_kg * rates[self.n_positions + r] + tr.lateral_rail_stiffness_N_per_m * rest[r]
            )
        return force

    def rates(self, track_state, rail_force_N, xi_m: float) -> np.ndarray:
        """The track's rates M^-1 (b F - C v - K q) (the matrices' version of :func:`track_rates`); ``rail_force_N``
        (left, right) vertical, then (left, right) lateral with the lateral track (absent: 0).
        """
        y = np.asarray(track_state, float)
        out = np.zeros_like(y)
        b = self.load_vector(xi_m)
        for side in (0, 1):
            r = self.rows(side)
            q, v = y[r], y[self.n_positions + r]
            out[r] = v
            out[self.n_positions + r] = (
                b * float(rail_force_N[side]) - self.damping @ v - self.stiffness @ q
            ) / self.mass
        if self.lateral:
            r, tr = self.lateral_rows(), self.track
            u, v = y[r], y[self.n_positions + r]
            force = np.asarray(rail_force_N, float)[2:4] if len(rail_force_N) > 2 else np.zeros(2)
            out[r] = v
            out[self.n_positions + r] = (
                force - tr.lateral_rail_damping_N_s_per_m * v - tr.lateral_rail_stiffness_N_per_m * u
            ) / tr.lateral_rail_mass_kg
        return out

    def energy_J(self, states) -> tuple:
        """(kinetic, potential) energy of the track's states (n, 2 n_positions) or (2 n_positions,), J:
        v^T M v / 2 and q^T K q / 2 summed over both rails.
        """
        t = np.asarray(states, float)
        kinetic = np.zeros(t.shape[:-1])
        potential = np.zeros(t.shape[:-1])
        for side in (0, 1):
            r = self.rows(side)
            q, v = t[..., r], t[..., self.n_positions + r]
            kinetic = kinetic + 0.5 * np.sum(self.mass * v * v, axis=-1)
            potential = potential + 0.5 * np.sum(q * (q @ self.stiffness), axis=-1)
        if self.lateral:
            r, tr = self.lateral_rows(), self.track
            u, v = t[..., r], t[..., self.n_positions + r]
            kinetic = kinetic + 0.5 * tr.lateral_rail_mass_kg * np.sum(v * v, axis=-1)
            potential = potential + 0.5 * tr.lateral_rail_stiffness_N_per_m * np.sum(u * u, axis=-1)
        return kinetic, potential

    def under_wheel(self, states, xi_m) -> np.ndarray:
        """Rail deflection (left, right) and velocity (left, right) under the wheels, (n, 4), from the track's
        states (n, 2 n_positions) with the wheelset at xi (n,).
        """
        t = np.atleast_2d(np.asarray(states, float))
        xi = np.broadcast_to(np.asarray(xi_m, float), (len(t),))
        out = np.zeros((len(t), 4))
        for side in (0, 1):
            r = self.rows(side)
            if self.layout is None:
                out[:, side], out[:, 2 + side] = t[:, r[0]], t[:, self.n_positions + r[0]]
                continue
            shape = np.sin(np.outer(xi, self.wavenumber_1_per_m))
            nm = self.layout.n_modes
            out[:, side] = np.sum(shape * t[:, r[:nm]], axis=1)
            out[:, 2 + side] = np.sum(shape * t[:, self.n_positions + r[:nm]], axis=1)
        return out

    def summary(self, states, xi_m) -> np.ndarray:
        """What a run records of the track (``summary_names``): the lumped track's states, or the beam's rail
        deflection and velocity under each wheel (BEAM_SUMMARY_NAMES); with the lateral track its states too.
        """
        t = np.atleast_2d(np.asarray(states, float))
        if self.layout is None:
            return t.copy()
        out = self.under_wheel(t, xi_m)
        if self.lateral:
            r = self.lateral_rows()
            out = np.concatenate([out, t[:, r], t[:, self.n_positions + r]], axis=1)
        return out

    def deflection_m(self, track_state, x_m) -> np.ndarray:
        """The beam's deflection of each rail (2, len(x)) at positions x along it, m (lumped: the rail mass)."""
        y = np.asarray(track_state, float)
        x = np.atleast_1d(np.asarray(x_m, float))
        if self.layout is None:
            return np.repeat(y[[0, 1]][:, None], len(x), axis=1)
        shape = np.sin(np.outer(x, self.wavenumber_1_per_m))
        nm = self.layout.n_modes
        return np.stack([shape @ y[self.rows(side)[:nm]] for side in (0, 1)])

    def receptance_m_per_N(self, frequency_Hz, x_force_m: float, x_response_m: float | None = None) -> np.ndarray:
        """One rail's receptance (complex, m/N) at the frequencies: (K + i w C - w^2 M) u = b(x_force), the
        response at x_response (default: at the force).
        """
        xr = x_force_m if x_response_m is None else x_response_m
        b, r = self.load_vector(x_force_m), self.load_vector(xr)
        out = np.empty(len(np.atleast_1d(frequency_Hz)), complex)
        for i, f in enumerate(np.atleast_1d(frequency_Hz)):
            w = 2.0 * math.pi * f
            u = np.linalg.solve(self.stiffness + 1j * w * self.damping - w * w * np.diag(self.mass), b)
            out[i] = r @ u
        return out

    def eigenfrequencies_Hz(self) -> np.ndarray:
        """One rail's undamped natural frequencies, Hz, ascending."""
        values = np.linalg.eigvalsh(self.stiffness / np.sqrt(np.outer(self.mass, self.mass)))
        return np.sqrt(np.clip(values, 0.0, None)) / (2.0 * math.pi)
