"""Field files of a contact run: NPZ and VTU surfaces per patch, outlines, and the Hertz map of analytic models.

For each patch ``<side>-<k>`` of a solved case the output folder gets

* ``fields-<side>-<k>.npz``: ``x_m`` (nx,), ``y_m`` (ny,) (contact frame, m), ``pressure_Pa``,
  ``traction_long_Pa``, ``traction_lat_Pa`` (on the wheel, Pa), ``slip_m_per_s``, ``in_contact``,
  ``in_slip``, ``in_adhesion`` (bool masks), each (ny, nx) with ``[j, i]`` at ``(x_m[i], y_m[j])``;
  ``outline_m`` (k, 2): the contact outline (the 0.5 level of ``in_contact``), closed curves separated by
  rows of NaN; ``point_m`` (3,) and ``frame`` (3, 3) of the patch (track frame, columns = contact axes);
  ``method`` and ``source`` as strings; ``units`` and ``dims`` as JSON strings (``json.loads(f["units"][()])``):
  each array's SI unit ("Pa", "m/s", "1" for masks) and its axis names (``["y", "x"]`` for the fields: row j is
  ``y_m[j]``, column i is ``x_m[i]``). Fields a model does not give are absent.
* ``fields-<side>-<k>.vtu``: the same grid as one quad surface (VTK unstructured grid) placed in the track
  frame (point = ``point_m + frame @ (x, y, 0)``, m), every field as point data with its unit in the name
  (masks as 0/1 integers), the contact-frame coordinates as ``contact_frame_xy_m``.
* ``outline-<side>-<k>.vtu``: the outline as line cells in the track frame.

Models that give fields (``fastsim``, ``bem``, ``fea``) are written as they are (``source`` = "model").
The analytic models (``hertz``, ``linear``, ``vermeulen-johnson``) give no field; for them the file holds
Hertz's pressure p = p0 sqrt(1 - x^2/a^2 - y^2/b^2) of the semi-axes and peak pressure the model computed
(Johnson 1985, eq 4.39; ``source`` = "hertz-closed-form"), since that is the pressure those models assume.
No tractions are written for them: the linear and Vermeulen-Johnson theories give forces, not traction fields.

Every file is written atomically (:func:`wheelrail.output.atomic_write`); meshio and pyvista read the VTU files.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from rigid_dynamics.contact.types import ContactFields, ContactResult

FIELD_NAMES = ("pressure_Pa", "traction_long_Pa", "traction_lat_Pa", "slip_m_per_s")
MASK_NAMES = ("in_contact", "in_slip", "in_adhesion")
HERTZ_GRID_POINTS = 81
"""Points per side of the grid on which the Hertz pressure of an analytic model is sampled."""


def hertz_fields(result: ContactResult, grid_points: int = HERTZ_GRID_POINTS) -> ContactFields | None:
    """Hertz's pressure of an elliptic patch on a regular grid spanning 1.2 semi-axes each way.

    p(x, y) = p0 sqrt(1 - x^2/a^2 - y^2/b^2) inside the ellipse, 0 outside (ellipse aligned with the
    rolling direction, as the analytic models assume). p0 = ``result.max_pressure_Pa``,
    a = ``semi_axis_long_m``, b = ``semi_axis_lat_m``. None when the patch has no finite semi-axes.
    """
    a, b, p0 = result.semi_axis_long_m, result.semi_axis_lat_m, result.max_pressure_Pa
    if a is None or b is None or p0 is None or not (math.isfinite(a) and math.isfinite(b)) or a <= 0 or b <= 0:
        return None
    x_m = np.linspace(-1.2 * a, 1.2 * a, grid_points)
    y_m = np.linspace(-1.2 * b, 1.2 * b, grid_points)
    gx, gy = np.meshgrid(x_m, y_m)
    inside = 1.0 - (gx / a) ** 2 - (gy / b) ** 2
    in_contact = inside > 0
    pressure = np.where(in_contact, p0 * np.sqrt(np.clip(inside, 0.0, None)), 0.0)
    return ContactFields(x_m=x_m, y_m=y_m, pressure_Pa=pressure, in_contact=in_contact)


def patch_fields(result: ContactResult) -> tuple[ContactFields | None, str]:
    """The fields to write for a patch and where they come from ("model" or "hertz-closed-form")."""
    if result.fields is not None:
        return result.fields, "model"
    fields = hertz_fields(result)
    return fields, ("hertz-closed-form" if fields is not None else "")


def field_arrays(fields: ContactFields) -> dict[str, np.ndarray]:
    """Named (ny, nx) arrays of a ContactFields (absent fields left out; masks as bool)."""
    arrays = {}
    for name in FIELD_NAMES:
        value = getattr(fields, name)
        if value is not None:
            arrays[name] = np.asarray(value, float)
    in_contact = (
        np.asarray(fields.in_contact, bool) if fields.in_contact is not None else np.asarray(fields.pressure_Pa) > 0
    )
    arrays["in_contact"] = in_contact
    if fields.in_slip is not None:
        in_slip = np.asarray(fields.in_slip, bool)
        arrays["in_slip"] = in_slip
        arrays["in_adhesion"] = in_contact & ~in_slip
    return arrays


def outline_curves(fields: ContactFields) -> list[np.ndarray]:
    """Closed curves (k, 2) of the contact outline, the 0.5 level of the in-contact mask (contact frame, m)."""
    import contourpy

    mask = field_arrays(fields)["in_contact"]
    if mask.shape[0] < 2 or mask.shape[1] < 2 or not mask.any():
        return []
    # pad with a ring of "no contact" so a patch touching the grid edge still gives closed curves
    x, y = np.asarray(fields.x_m, float), np.asarray(fields.y_m, float)
    dx = x[1] - x[0] if len(x) > 1 else 1.0
    dy = y[1] - y[0] if len(y) > 1 else 1.0
    xp = np.concatenate([[x[0] - dx], x, [x[-1] + dx]])
    yp = np.concatenate([[y[0] - dy], y, [y[-1] + dy]])
    zp = np.zeros((len(yp), len(xp)))
    zp[1:-1, 1:-1] = mask
    lines = contourpy.contour_generator(xp, yp, zp).lines(0.5)
    return [np.asarray(line, float) for line in lines if len(line) >= 2]


def _track_points(xy: np.ndarray, geometry) -> np.ndarray:
    """Contact-frame points (k, 2) in the track frame: point_m + frame @ (x, y, 0)."""
    point = np.asarray(getattr(geometry, "point_m", np.zeros(3)), float)
    frame = np.asarray(getattr(geometry, "frame", np.eye(3)), float)
    if not (np.isfinite(point).all() and np.isfinite(frame).all()):
        point, frame = np.zeros(3), np.eye(3)
    local = np.column_stack([xy, np.zeros(len(xy))])
    return point + local @ frame.T


def write_patch_files(out_dir: str | Path, name: str, geometry, result: ContactResult) -> dict[str, str]:
    """Write the NPZ, VTU and outline files of one patch; return {kind: file name} ({} if it has no fields)."""
    import meshio

    from wheelrail.output import atomic_write, write_npz

    fields, source = patch_fields(result)
    if fields is None:
        return {}
    out = Path(out_dir)
    arrays = field_arrays(fields)
    curves = outline_curves(fields)
    outline = np.concatenate([np.vstack([c, [[np.nan, np.nan]]]) for c in curves])[:-1] if curves else np.zeros((0, 2))
    from comparisons.style import unit_of

    units = {key: "1" if key in MASK_NAMES else unit_of(key) for key in arrays}
    units.update({"x_m": "m", "y_m": "m", "outline_m": "m", "point_m": "m", "frame": "1"})
    dims = {key: ["y", "x"] for key in arrays}
    dims.update(
        {"x_m": ["x"], "y_m": ["y"], "outline_m": ["point", "xy"], "point_m": ["xyz"], "frame": ["xyz", "axis"]}
    )
    point = np.asarray(getattr(geometry, "point_m", np.zeros(3)), float)
    frame = np.asarray(getattr(geometry, "frame", np.eye(3)), float)
    files = {}
    npz = write_npz(
        out / f"fields-{name}.npz",
        x_m=np.asarray(fields.x_m, float),
        y_m=np.asarray(fields.y_m, float),
        outline_m=outline,
        point_m=point,
        frame=frame,
        method=np.array(result.method),
        source=np.array(source),
        units=np.array(json.dumps(units)),
        dims=np.array(json.dumps(dims)),
        **arrays,
    )
    files["npz"] = npz.name

    x, y = np.asarray(fields.x_m, float), np.asarray(fields.y_m, float)
    gx, gy = np.meshgrid(x, y)  # (ny, nx), row j = y_j
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    nx, ny = len(x), len(y)
    point_data = {"contact_frame_xy_m": xy}
    for key, value in arrays.items():
        point_data[key] = value.ravel().astype(np.uint8 if value.dtype == bool else float)
    if nx >= 2 and ny >= 2:
        j, i = np.meshgrid(np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
        k = (j * nx + i).ravel()
        cells = [("quad", np.column_stack([k, k + 1, k + 1 + nx, k + nx]))]
    else:
        cells = [("vertex", np.arange(nx * ny)[:, None])]
    surface = meshio.Mesh(_track_points(xy, geometry), cells, point_data=point_data)
    vtu = atomic_write(out / f"fields-{name}.vtu", lambda tmp: meshio.write(tmp, surface, file_format="vtu"))
    files["vtu"] = vtu.name

    if curves:
        points, segments, start = [], [], 0
        for curve in curves:
            points.append(curve)
            idx = np.arange(start, start + len(curve))
            segments.append(np.column_stack([idx[:-1], idx[1:]]))
            start += len(curve)
        line_mesh = meshio.Mesh(_track_points(np.concatenate(points), geometry), [("line", np.concatenate(segments))])
        path = atomic_write(out / f"outline-{name}.vtu", lambda tmp: meshio.write(tmp, line_mesh, file_format="vtu"))
        files["outline_vtu"] = path.name
    files["source"] = source
    return files


def write_solution_files(solution, out_dir: str | Path) -> list[dict]:
    """Write the field files of every patch of a ``CaseSolution``; one entry per patch (may be empty)."""
    written = []
    for index, (side, geometry, _creepage, result) in enumerate(solution.patches):
        written.append(write_patch_files(out_dir, f"{side}-{index}", geometry, result))
    return written


def plot_patch(result: ContactResult, path: str | Path | None = None):
    """PNG of a patch: the model's fields, or for an analytic model Hertz's ellipse and pressure; None if neither.

    ``path`` None returns the matplotlib Figure (shown inline in a notebook) instead of writing a file.
    """
    if result.fields is not None:
        from comparisons.contact_plots import plot_contact_fields

        return plot_contact_fields(result, path)
    fields = hertz_fields(result)
    if fields is None:
        return None
    from matplotlib.figure import Figure  # no pyplot: the caller's backend is left alone

    a, b = result.semi_axis_long_m, result.semi_axis_lat_m
    fig = Figure(figsize=(6, 4.5))
    ax = fig.subplots()
    p = np.ma.masked_where(fields.pressure_Pa <= 0, fields.pressure_Pa)
    mesh = ax.pcolormesh(1e3 * fields.x_m, 1e3 * fields.y_m, p / 1e6, shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="Hertz pressure [MPa]", shrink=0.85)
    angle = np.linspace(0.0, 2.0 * np.pi, 200)
    ax.plot(1e3 * a * np.cos(angle), 1e3 * b * np.sin(angle), "k-", lw=1.2, label="Hertz ellipse")
    ax.set_aspect("equal")
    ax.set_xlabel("x (rolling) [mm]")
    ax.set_ylabel("y (lateral) [mm]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(
        f"{result.method}: a = {1e3 * a:.3g} mm, b = {1e3 * b:.3g} mm, p0 = {result.max_pressure_Pa / 1e6:.4g} MPa",
        fontsize=9,
    )
    if path is None:
        return fig
    from wheelrail.output import atomic_write

    path = Path(path)
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=120, bbox_inches="tight", format="png"))
    return path
