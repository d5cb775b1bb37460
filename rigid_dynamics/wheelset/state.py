"""The state layout of a wheelset run: one place that says where every state sits.

The full state is, in order,

* the 12 mechanical states (:data:`MECHANICAL`): positions x, y, z, yaw, roll, spin (:data:`POSITIONS`), then
  their rates (:data:`VELOCITIES`), main frame, SI units (:data:`STATE_NAMES`);
* two work integrals (:data:`WORK`): the work of the contact forces (:data:`WORK_CONTACT`) and of the exterior
  forces (:data:`WORK_EXTERIOR`), J, diagnostics for the energy balance that do not enter the right-hand side;
* with an elastic track its states (:data:`TRACK`: everything after the work integrals), positions then their
  rates, z down from the unloaded track: for ``track_dynamics.model = "lumped"`` 8 states, rail and sleeper
  deflection per side (left, right) and their rates (:data:`TRACK_STATE_NAMES`); for "beam" the modes and rail
  seats of both rails (track.BeamLayout), as many as the run's beam needs; with ``lateral_model = "lumped"``
  the rails' lateral displacements (left, right) end the positions and their rates end the rates
  (:data:`LATERAL_STATE_NAMES`).

Module-level integers are compile-time constants in numba, so the compiled right-hand side indexes with these
names at no cost (``y[RAIL + side]``). A new state is added here (its slice and names), in the
right-hand side and in the module of its physics.
"""

from __future__ import annotations

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
"""Names of the 12 mechanical states, in order."""

TRACK_STATE_NAMES = (
    "rail_left_m",
    "rail_right_m",
    "sleeper_left_m",
    "sleeper_right_m",
    "rail_left_velocity_m_per_s",
    "rail_right_velocity_m_per_s",
    "sleeper_left_velocity_m_per_s",
    "sleeper_right_velocity_m_per_s",
)
"""Names of the lumped track's states (z down, from the unloaded track), in order."""

LATERAL_STATE_NAMES = (
    "rail_left_lateral_m",
    "rail_right_lateral_m",
    "rail_left_lateral_velocity_m_per_s",
    "rail_right_lateral_velocity_m_per_s",
)
"""Names of the lateral track's states (y along the track's lateral axis): the last two of the track's positions
and the last two of its rates (track.rail_lateral_under_wheel)."""

# mechanical states: positions, then rates
X, Y, Z, YAW, ROLL, SPIN = range(6)
X_VELOCITY, Y_VELOCITY, Z_VELOCITY, YAW_RATE, ROLL_RATE, SPIN_RATE = range(6, 12)
N_MECHANICAL = 12
MECHANICAL = slice(0, N_MECHANICAL)
POSITIONS = slice(0, 6)
VELOCITIES = slice(6, 12)

# work integrals
WORK_CONTACT, WORK_EXTERIOR = 12, 13
WORK = slice(12, 14)
N_RIGID = 14
"""Length of the full state on the rigid track."""

TRACK = slice(N_RIGID, None)
"""Where an elastic track's states sit in the full state (after the 12 mechanical states and 2 work integrals)."""
# the lumped track: first index of each pair (left, right); the rates follow all the track's positions (with
# the lateral track at 20, 22, else at 18, 20: track.track_rates indexes them from the track's size)
RAIL, SLEEPER = 14, 16
N_LUMPED = 22
"""Length of the full state with the lumped track (without the lateral track)."""


def n_states(track_positions: int) -> int:
    """Length of the full state with ``track_positions`` track positions (as many rates follow): 14 on the rigid
    track, 22 with the lumped track.
    """
    return N_RIGID + 2 * int(track_positions)


def track_positions(n_state: int) -> slice:
    """The track's positions in a full state of length ``n_state`` (empty on the rigid track)."""
    n = (n_state - N_RIGID) // 2
    return slice(N_RIGID, N_RIGID + n)


def track_velocities(n_state: int) -> slice:
    """The track's rates in a full state of length ``n_state`` (empty on the rigid track)."""
    n = (n_state - N_RIGID) // 2
    return slice(N_RIGID + n, N_RIGID + 2 * n)


def state_names(n_state: int) -> tuple[str, ...]:
    """Names of every entry of a full state of length ``n_state`` (work integrals ``work_contact_J``,
    ``work_exterior_J``; the lumped track's TRACK_STATE_NAMES; a beam's states ``track_<i>``).
    """
    names = STATE_NAMES + ("work_contact_J", "work_exterior_J")
    if n_state == N_LUMPED:
        return names + TRACK_STATE_NAMES
    if n_state == N_LUMPED + 4:
        return names + TRACK_STATE_NAMES[:4] + LATERAL_STATE_NAMES[:2] + TRACK_STATE_NAMES[4:] + LATERAL_STATE_NAMES[2:]
    return names + tuple(f"track_{i}" for i in range(n_state - N_RIGID))
