# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: light
# ---

# # An FEA stress map
#
# The `fea` model (FEniCSx) solves the normal contact of one Hertzian patch as an elastic block pressed by
# the rigid gap, and recovers the subsurface stresses. Its field file `fea_solution.vtu` holds displacement,
# stress tensor, principal stresses, von Mises and maximum shear at the nodes (units in the names); meshio,
# pyvista and ParaView open it. For a circular patch Johnson (1985, Fig. 3.7) gives the largest
# shear stress (s1 - s3)/2 = 0.31 p0 at a depth 0.48 a below the centre.

# +
import math
import os
from pathlib import Path

import wheelrail as wr

QUICK = os.environ.get("WHEELRAIL_EXAMPLES_QUICK") == "1"
OUT = Path(os.environ.get("WHEELRAIL_EXAMPLES_OUT", "examples-out")) / "fea"
OUT.mkdir(parents=True, exist_ok=True)

material = wr.Material.from_young(210e9, 0.3, 0.3)
geometry = wr.ContactGeometry.quadric(0.3, 0.3)
# quick mode (the test suite): the coarse mesh refined to 5 % (two levels) instead of the default 2 %
options = {"quick": True, "mesh_tolerance": 0.05, "output_dir": str(OUT)} if QUICK else {"output_dir": str(OUT)}
result = wr.get_model("fea").solve(geometry, wr.Creepage(), material, normal_force_N=1e5, options=options)
print(result)
assert result.success, result.message
# -

# The subsurface maximum along the axis against Johnson's numbers (coarse mesh in quick mode: a few per cent).

# +
hertz = wr.get_model("hertz").solve(geometry, wr.Creepage(), material, normal_force_N=1e5)
p0, a = hertz.max_pressure_Pa, hertz.semi_axis_long_m
shear, depth = result.extra["axis_max_shear_Pa"], result.extra["axis_max_shear_depth_m"]
print(f"max shear {shear / p0:.3f} p0 at depth {depth / a:.3f} a (Johnson: 0.31 p0 at 0.48 a)")
assert math.isclose(shear / p0, 0.31, rel_tol=0.1) and math.isclose(depth / a, 0.48, rel_tol=0.25)
# -

# A 3-D view with pyvista (off screen): the block cut through the patch centre, coloured by von Mises.

# +
import meshio  # noqa: E402
import pyvista as pv  # noqa: E402

mesh = meshio.read(OUT / "fea_solution.vtu")
print({name: values.shape for name, values in mesh.point_data.items()})
grid = pv.read(OUT / "fea_solution.vtu")
cut = grid.slice(normal="y", origin=(0.0, 1e-9, 0.0))
plotter = pv.Plotter(off_screen=True, window_size=(900, 600))
plotter.add_mesh(grid.outline(), color="black")
plotter.add_mesh(cut, scalars="von_mises_Pa", cmap="inferno", scalar_bar_args={"title": "von Mises [Pa]"})
plotter.view_xz()
plotter.screenshot(OUT / "fea_von_mises_3d.png")
plotter.close()
# -
