"""Files of an FE contact solution: XDMF (ParaView) and PNG maps.

* ``fea_solution.xdmf`` (+ .h5): mesh, displacement u (m), recovered stress tensor (Pa), von Mises (Pa);
  written collectively by all ranks.
* ``fea_pressure.png``: contact pressure on the contact plane (contact frame x, y in mm) with the
  outline of the contact area (p > 0).
* ``fea_von_mises_cut.png``: von Mises stress in the plane y = y_c through the patch centre
  (x along rolling, depth below the surface), from the recovered nodal stresses.
PNGs are drawn by rank 0 with matplotlib (Agg backend).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigid_dynamics.files import save_figure


def write_outputs(output_dir, sol, stress_fn, fields, domain, spec, young_modulus_Pa, poisson_ratio, comm) -> dict:
    """Write the XDMF file and the PNG maps into ``output_dir``; return {kind: path}."""
    import dolfinx_solver  # noqa: F401
    from dolfinx import fem, io

    from fea import postprocess as post

    out = Path(output_dir)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    files = {}
    if stress_fn is None:
        stress_fn, _, _ = post.recover_nodal_stress(sol.displacement, young_modulus_Pa, poisson_ratio)
    msh = sol.displacement.function_space.mesh
    S = fem.functionspace(msh, ("Lagrange", 1))
    vm = fem.Function(S, name="von_mises")
    n = S.dofmap.index_map.size_local
    tensors = stress_fn.x.array[: n * 9].reshape(-1, 3, 3)
    vm.x.array[:n] = post.principal_measures(tensors)["von_mises"]
    vm.x.scatter_forward()
    xdmf = out / "fea_solution.xdmf"
    with io.XDMFFile(comm, str(xdmf), "w") as f:
        f.write_mesh(msh)
        f.write_function(sol.displacement)
        f.write_function(stress_fn)
        f.write_function(vm)
    files["xdmf"] = str(xdmf)

    coords = S.tabulate_dof_coordinates()[:n]
    yc = spec.center_m[1]
    slab = 1e-9 * spec.half_width_m if domain.symmetry == "quarter" else 0.5 * spec.contact_size_m
    sel = np.abs(coords[:, 1] - yc) <= slab
    xyz_parts = comm.gather(coords[sel], root=0)
    vm_parts = comm.gather(vm.x.array[:n][sel], root=0)
    if comm.rank == 0:
        cut_xyz, cut_vm = np.concatenate(xyz_parts), np.concatenate(vm_parts)
        files.update(_draw(out, fields, cut_xyz, cut_vm, spec, domain.symmetry))
    return comm.bcast(files, root=0)


def _draw(out: Path, fields, cut_xyz, cut_vm, spec, symmetry) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri

    files = {}
    if fields is not None:
        fig, ax = plt.subplots(figsize=(6, 5))
        mesh = ax.pcolormesh(
            fields.x_m * 1e3, fields.y_m * 1e3, fields.pressure_Pa / 1e6, shading="auto", cmap="viridis"
        )
        ax.contour(fields.x_m * 1e3, fields.y_m * 1e3, fields.pressure_Pa > 0, levels=[0.5], colors="w", linewidths=1)
        fig.colorbar(mesh, ax=ax, label="contact pressure p / MPa")
        ax.set_xlabel("x (rolling) / mm")
        ax.set_ylabel("y (lateral) / mm")
        ax.set_aspect("equal")
        ax.set_title("FEA contact pressure (white: contact outline)")
        path = out / "fea_pressure.png"
        try:
            save_figure(fig, path, dpi=120, bbox_inches="tight")  # atomic (rigid_dynamics.files)
        finally:
            plt.close(fig)
        files["pressure_png"] = str(path)

    x, z, v = cut_xyz[:, 0], -cut_xyz[:, 2], cut_vm
    if symmetry == "quarter":
        x, z, v = np.concatenate([x, -x]), np.concatenate([z, z]), np.concatenate([v, v])
    window = 3.0 * max(spec.semi_axis_long_m, spec.semi_axis_lat_m)
    keep = (np.abs(x - spec.center_m[0]) < window) & (z < window)
    if keep.sum() >= 3:
        _, unique = np.unique(np.round(np.c_[x[keep], z[keep]] / (1e-9 * window)), axis=0, return_index=True)
        xs, zs, vs = x[keep][unique], z[keep][unique], v[keep][unique]
        fig, ax = plt.subplots(figsize=(7, 4))
        tri = mtri.Triangulation(xs * 1e3, zs * 1e3)
        filled = ax.tricontourf(tri, vs / 1e6, levels=20, cmap="inferno")
        fig.colorbar(filled, ax=ax, label="von Mises / MPa")
        ax.invert_yaxis()
        ax.set_xlabel("x (rolling) / mm")
        ax.set_ylabel("depth / mm")
        ax.set_aspect("equal")
        ax.set_title("FEA subsurface von Mises stress, cut y = y_c")
        path = out / "fea_von_mises_cut.png"
        try:
            save_figure(fig, path, dpi=120, bbox_inches="tight")  # atomic (rigid_dynamics.files)
        finally:
            plt.close(fig)
        files["von_mises_cut_png"] = str(path)
    return files
