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

numpy only at import; the files are written by the standard library's ``csv`` and by pyarrow (Parquet), without
pandas (its import is 0.25-0.33 s of a short ``wheelrail run``); :func:`to_dataframe` imports pandas.
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
    back exactly, 0 as ``0.0``); NaN is written as an empty field, which ``pandas.read_csv`` reads as NaN. The
    Parquet file holds one float64 column per name, NaN as null (as pandas' ``to_parquet`` writes it).
    """
    from rigid_dynamics.files import atomic_write

    path = Path(path)
    if path.suffix not in (".csv", ".parquet"):
        raise ValueError(f"path = {str(path)!r}: expected a .csv or .parquet file")
    columns = {name: np.asarray(values, float) for name, values in result_columns(result).items()}
    if path.suffix == ".csv":
        return atomic_write(path, lambda tmp: _write_csv(columns, tmp))
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_arrays([_arrow_column(pa, v) for v in columns.values()], names=list(columns))
    return atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def _arrow_column(pa, values: np.ndarray):
    """A float64 Arrow array of ``values`` with NaN as null, made from its buffers (the validity bitmap, least
    significant bit first, and the values): ``pyarrow.array`` on a numpy array imports pandas to ask whether it is
    a Series (0.25-0.33 s, for a file that does not need it).
    """
    values = np.ascontiguousarray(values, dtype=np.float64)
    missing = np.isnan(values)
    validity = pa.py_buffer(np.packbits(~missing, bitorder="little"))
    return pa.Array.from_buffers(
        pa.float64(), len(values), [validity, pa.py_buffer(values)], null_count=int(missing.sum())
    )


def _write_csv(columns: dict, path: Path) -> None:
    """The columns (equal-length float arrays) as CSV: a header of their names, then one row per index, each value
    by ``repr`` (the csv module's float text) and NaN as an empty field.
    """
    import csv

    rows = np.column_stack(list(columns.values())).tolist() if columns else []
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(columns)
        writer.writerows([("" if v != v else v) for v in row] for row in rows)
