"""3-D views of FE fields with pyvista (off screen): the body around the stress maximum, coloured by a stress field.

pyvista (VTK) is imported inside the function. It renders without a display through VTK's off-screen
window; a machine whose VTK cannot render off screen raises, and the caller reports the view as not drawn.
"""

from __future__ import annotations

from pathlib import Path


def render_stress_view(vtu_path: str | Path, png_path: str | Path, field: str = "von_mises_Pa") -> Path:
    """PNG of the FE grid of ``vtu_path`` around the maximum of ``field`` (a box of 3 x its depth each way), in 3-D.

    On the quarter model the two cut faces (symmetry planes) show the field inside the body.

    Args:
        vtu_path: ``fea_solution.vtu`` (fea.output).
        png_path: the PNG to write (atomically: temporary name, then rename).
        field: a point field of the grid, e.g. "von_mises_Pa", "max_shear_Pa".

    Raises:
        ValueError: the grid has no such field.
    """
    import pyvista as pv

    from rigid_dynamics.files import atomic_write

    grid = pv.read(str(vtu_path))
    if field not in grid.point_data:
        raise ValueError(f"field = {field!r}: expected one of {sorted(grid.point_data.keys())}")
    # the region around the stress maximum: a box of a few times its depth, cut to the grid
    values = grid.point_data[field]
    peak = grid.points[int(values.argmax())]
    b = grid.bounds
    depth = max(abs(b[5] - peak[2]), abs(b[4] - peak[2]) * 1e-3)
    half = 3.0 * depth
    box = (
        max(b[0], peak[0] - half),
        min(b[1], peak[0] + half),
        max(b[2], peak[1] - half),
        min(b[3], peak[1] + half),
        max(b[4], b[5] - half),
        b[5],
    )
    region = grid.clip_box(box, invert=False)
    plotter = pv.Plotter(off_screen=True, window_size=(1000, 650))
    try:
        plotter.add_mesh(region, scalars=field, cmap="inferno", show_edges=False, scalar_bar_args={"title": field})
        plotter.add_mesh(region.outline(), color="black")
        plotter.view_vector((-1.0, -1.0, 0.8), viewup=(0.0, 0.0, 1.0))  # onto the symmetry faces x = y = 0
        png_path = atomic_write(png_path, lambda tmp: plotter.screenshot(str(tmp)))
    finally:
        plotter.close()
    return png_path
