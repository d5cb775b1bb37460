"""The state layout of a wheelset run: one place that says where every state sits.

The full state is, in order,

* the 12 mechanical states (:data:`MECHANICAL`): positions x, y, z, yaw, roll, spin (:data:`POSITIONS`), then
  their rates (:data:`VELOCITIES`), main frame, SI units (:data:`STATE_NAMES`);
* two work integrals (:data:`WORK`): the work of the contact forces (:data:`WORK_CONTACT`) and of the exterior
  forces (:data:`WORK_EXTERIOR`), J, diagnostics for the energy balance that do not enter the right-hand side;
* with the elastic track (scene ``track_dynamics.model = "lumped"``) its 8 states (:data:`TRACK`): rail and
  sleeper deflection per side (left, right), z down from the unloaded track, then their rates
  (:data:`TRACK_STATE_NAMES`).

Module-level integers are compile-time constants in numba, so the compiled right-hand side indexes with these
names at no cost (``y[RAIL_VELOCITY + side]``). A new state is added here (its slice and names), in the
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
"""Names of the elastic track's states (z down, from the unloaded track), in order."""

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

# elastic track: first index of each pair (left, right)
RAIL, SLEEPER, RAIL_VELOCITY, SLEEPER_VELOCITY = 14, 16, 18, 20
TRACK = slice(14, 22)
"""Where the elastic track's states sit in the full state (after the 12 mechanical states and 2 work integrals)."""
TRACK_POSITIONS = slice(14, 18)
TRACK_VELOCITIES = slice(18, 22)
N_ELASTIC = 22
"""Length of the full state with the elastic track."""


def n_states(elastic: bool) -> int:
    """Length of the full state: 14 on the rigid track, 22 with the elastic track."""
    return N_ELASTIC if elastic else N_RIGID


def state_names(elastic: bool) -> tuple[str, ...]:
    """Names of every entry of the full state (work integrals ``work_contact_J``, ``work_exterior_J``)."""
    return STATE_NAMES + ("work_contact_J", "work_exterior_J") + (TRACK_STATE_NAMES if elastic else ())
