"""Measured irregularity grids from CSV files: wheel out-of-roundness R_irr(alpha, y_p) and rail N_irr(x, y_r).

One format for both (comma-separated, ``#`` comments allowed):

    angle_rad, -0.03, -0.01, 0.01, 0.03        <- header: the running coordinate's name, then the lateral
    0.0,       1e-5,  2e-5,  2e-5,  1e-5          grid (wheel-profile y_p or rail y_r, m, >= 4 values)
    0.1,       ...                              <- one row per running coordinate: alpha (rad) or x (m),
                                                   then the irregularity at each lateral point, m

The header's first cell names the running coordinate: ``angle_rad`` for a wheel (the grid spans less than
one revolution; the period is 2 pi) and ``x_m`` for a rail (measured corrugation; z down, positive lowers
the rail). Outside the lateral grid (and for a rail outside the x grid) the irregularity is 0, so taper
measured data to 0 at its edges. A value uniform across the tread is given by repeating it in every column.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigid_dynamics.geometry.irregularities import MeasuredRailIrregularity, MeasuredWheelIrregularity


def read_grid_csv(path: str | Path, running_name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(running coordinate (n,), lateral grid (m,), values (n, m)) of a grid file (module docstring).

    Raises:
        ValueError: unreadable file, a header that does not start with ``running_name``, rows of the wrong
            length or values that are not finite numbers (the message names the file and the line).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"cannot read {str(path)!r}: {exc.strerror or exc}") from None
    rows = []
    for number, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if line:
            rows.append((number, [cell.strip() for cell in line.split(",")]))
    if len(rows) < 2:
        raise ValueError(f"{str(path)!r}: expected a header line and at least one data row")
    number, header = rows[0]
    if header[0] != running_name:
        raise ValueError(f"{str(path)!r} line {number}: first cell {header[0]!r}, expected {running_name!r}")
    try:
        lateral = np.array([float(cell) for cell in header[1:]])
    except ValueError:
        raise ValueError(f"{str(path)!r} line {number}: expected lateral grid values in m") from None
    running, values = [], []
    for number, cells in rows[1:]:
        if len(cells) != len(header):
            raise ValueError(f"{str(path)!r} line {number}: {len(cells)} values, expected {len(header)}")
        try:
            numbers = [float(cell) for cell in cells]
        except ValueError:
            raise ValueError(f"{str(path)!r} line {number}: expected numbers") from None
        if not all(np.isfinite(numbers)):
            raise ValueError(f"{str(path)!r} line {number}: expected finite numbers")
        running.append(numbers[0])
        values.append(numbers[1:])
    return np.array(running), lateral, np.array(values)


def read_wheel_grid_csv(path: str | Path) -> MeasuredWheelIrregularity:
    """Measured wheel out-of-roundness R_irr(alpha, y_p) from a CSV grid (header ``angle_rad, y...``)."""
    angle, lateral, values = read_grid_csv(path, "angle_rad")
    try:
        return MeasuredWheelIrregularity(angle, lateral, values)
    except ValueError as exc:
        raise ValueError(f"{str(path)!r}: {exc}") from None


def read_rail_grid_csv(path: str | Path) -> MeasuredRailIrregularity:
    """Measured rail irregularity (corrugation) N_irr(x, y_r) from a CSV grid (header ``x_m, y...``)."""
    x, lateral, values = read_grid_csv(path, "x_m")
    try:
        return MeasuredRailIrregularity(x, lateral, values)
    except ValueError as exc:
        raise ValueError(f"{str(path)!r}: {exc}") from None


def write_grid_csv(path: str | Path, running_name: str, running, lateral_m, values_m) -> Path:
    """Write a grid in the format of :func:`read_grid_csv` (full float precision)."""
    path = Path(path)
    lines = [",".join([running_name, *(repr(float(y)) for y in lateral_m)])]
    for r, row in zip(np.asarray(running, float), np.asarray(values_m, float), strict=True):
        lines.append(",".join([repr(float(r)), *(repr(float(v)) for v in row)]))
    from rigid_dynamics.files import write_text

    return write_text(path, "\n".join(lines) + "\n")
