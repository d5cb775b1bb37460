"""The time series of a wheelset run as a tidy table: one row per output time, one column per named quantity.

Columns (units in the names, SI):

* ``time_s``;
* the 12 states (:data:`~rigid_dynamics.wheelset.state.STATE_NAMES`: ``x_m`` ... ``spin_rate_rad_per_s``;
  position of the centre of mass and Euler angles in the track frame);
* per wheel ``left`` / ``right`` and contact slot ``tread`` (first patch) / ``second`` (flange or second point):
  ``<side>_<slot>_<quantity>`` for every recorded patch quantity
  (:data:`~rigid_dynamics.wheelset.layout.PATCH_FIELDS`, forces on the wheel in the patch's contact frame),
  e.g. ``left_tread_normal_force_N``; NaN where the slot is not in contact;
* ``<side>_wheel_contact_force_<x|y|z>_N``: sum of the contact forces on that wheel, track frame
  (x along the track, y to the right, z down);
* ``kinetic_energy_J``, ``potential_energy_J``, ``work_contact_J``, ``work_exterior_J``.

numpy only at import; pandas (and pyarrow for Parquet) are imported by the functions that need them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

SLOT_NAMES = ("tread", "second")
"""Names of the two contact slots per wheel in the columns (slot 0: tread; slot 1: flange or second point)."""
AXES = ("x", "y", "z")


def timeseries_columns(
    t: np.ndarray,
    states: np.ndarray,
    patches: dict,
    contact_force_N: np.ndarray,
    energies: dict | None = None,
) -> dict[str, np.ndarray]:
    """Ordered columns of the tidy table from a run's recorded arrays.

    Args:
        t: output times (n,), s.
        states: (n, 12) states in STATE_NAMES order.
        patches: PATCH_FIELDS name -> (n, 2 sides, 2 slots).
        contact_force_N: (n, 2 sides, 3) total contact force on each wheel, track frame, N.
        energies: further (n,) columns by name (e.g. ``kinetic_energy_J``), appended as they are.

    Returns:
        name -> (n,) float array, in column order.
    """
    from rigid_dynamics.wheelset.providers import SIDES
    from rigid_dynamics.wheelset.state import STATE_NAMES

    t = np.asarray(t, float)
    n = len(t)
    states = np.asarray(states, float)
    if states.size != n * len(STATE_NAMES):  # (a run stopped before its first sample has n = 0: no -1 to infer)
        raise ValueError(f"states of shape {states.shape}: expected (n, {len(STATE_NAMES)})")
    states = states.reshape(n, len(STATE_NAMES))
    if states.shape[1] != len(STATE_NAMES):
        raise ValueError(f"states of shape {states.shape}: expected (n, {len(STATE_NAMES)})")
    columns = {"time_s": t}
    for k, name in enumerate(STATE_NAMES):
        columns[name] = states[:, k]
    for i, side in enumerate(SIDES):
        for j, slot in enumerate(SLOT_NAMES):
            for name, values in patches.items():
                shaped = np.asarray(values, float).reshape(n, len(SIDES), len(SLOT_NAMES))
                columns[f"{side}_{slot}_{name}"] = shaped[:, i, j]
    forces = np.asarray(contact_force_N, float).reshape(n, len(SIDES), 3)
    for i, side in enumerate(SIDES):
        for k, axis in enumerate(AXES):
            columns[f"{side}_wheel_contact_force_{axis}_N"] = forces[:, i, k]
    for name, values in (energies or {}).items():
        columns[name] = np.asarray(values, float).reshape(n)
    return columns


def result_columns(result) -> dict[str, np.ndarray]:
    """:func:`timeseries_columns` of a :class:`~rigid_dynamics.wheelset.simulate.SimulationResult`."""
    energies = {
        name: getattr(result, name)
        for name in ("kinetic_energy_J", "potential_energy_J", "work_contact_J", "work_exterior_J")
    }
    columns = timeseries_columns(result.t, result.states, result.patches, result.contact_force_N, energies)
    track = getattr(result, "track_states", None)
    if track is not None:  # what the run recorded of the elastic track (its track_state_names), after the others
        for k, name in enumerate(result.track_state_names):
            columns[name] = np.asarray(track, float)[:, k]
    for name, values in (getattr(result, "traction", None) or {}).items():  # the traction controller's samples
        columns[name] = np.asarray(values, float)
    return columns


def to_dataframe(result):
    """The tidy table of a run as a ``pandas.DataFrame`` (one row per output time)."""
    import pandas as pd

    return pd.DataFrame(result_columns(result))


def write_table(result, path: str | Path) -> Path:
    """Write the tidy table to ``path`` atomically: CSV for ``.csv``, Parquet (pyarrow) for ``.parquet``.

    The CSV has one header line of column names (units in the names) and floats written by ``repr`` (they read
    back exactly); NaN is written as an empty field, which ``pandas.read_csv`` reads as NaN.
    """
    from rigid_dynamics.files import atomic_write

    path = Path(path)
    if path.suffix not in (".csv", ".parquet"):
        raise ValueError(f"path = {str(path)!r}: expected a .csv or .parquet file")
    frame = to_dataframe(result)
    if path.suffix == ".csv":
        return atomic_write(path, lambda tmp: frame.to_csv(tmp, index=False))
    return atomic_write(path, lambda tmp: frame.to_parquet(tmp, index=False, engine="pyarrow"))
