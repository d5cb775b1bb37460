"""Files of an FE contact solution: one VTU grid (ParaView, pyvista, meshio) and PNG maps.

* ``fea_solution.vtu``: one unstructured grid (linear tetrahedra, coordinates in m) with every field at
  its nodes, units in the names: ``displacement_m`` (3), ``stress_Pa`` (9, row-major sigma_ij of the
  recovered nodal stress), ``principal_stress_Pa`` (3, s1 >= s2 >= s3), ``von_mises_Pa``,
  ``max_shear_Pa`` ((s1 - s3)/2) and, where the mesh has body tags, the cell field ``body``.
  A P2 displacement is interpolated to the vertices. The grid is gathered to rank 0 under MPI and
  written by meshio atomically (temporary name + rename). One grid per file: ``meshio.read``,
  ``pyvista.read`` and ParaView open it as it is (an XDMF with one grid per function, as DOLFINx writes
  it, is not readable by meshio or pyvista).
* ``fea_pressure.png``: contact pressure on the contact plane (contact frame x, y in mm) with the
  outline of the contact area (p > 0).
* ``fea_von_mises_cut.png``: von Mises stress in the plane y = y_c through the patch centre
  (x along rolling, depth below the surface), from the recovered nodal stresses.
PNGs are drawn by rank 0 with matplotlib (Agg backend).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigid_dynamics.files import atomic_write, save_figure

FIELD_UNITS = {
    "displacement_m": "m",
    "stress_Pa": "Pa",
    "principal_stress_Pa": "Pa",
    "von_mises_Pa": "Pa",
    "max_shear_Pa": "Pa",
    "body": "physical group tag of the cell",
}
"""Fields of ``fea_solution.vtu`` and their units (also in the names)."""


def write_outputs(output_dir, sol, stress_fn, fields, domain, spec, young_modulus_Pa, poisson_ratio, comm) -> dict:
    """Write the VTU grid and the PNG maps into ``output_dir``; return {kind: path} (same on every rank)."""
    import dolfinx_solver  # noqa: F401
    from dolfinx import fem

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
    V1 = fem.functionspace(msh, ("Lagrange", 1, (3,)))
    u1 = fem.Function(V1)
    u1.interpolate(sol.displacement)
    u1.x.scatter_forward()
    grid = _gather_vertex_grid(msh, comm, S, u1, stress_fn, getattr(domain, "cell_tags", None))
    vtu = out / "fea_solution.vtu"
    if comm.rank == 0:
        _write_vtu(vtu, *grid)
    files["vtu"] = str(vtu)

    n = S.dofmap.index_map.size_local
    tensors = stress_fn.x.array[: n * 9].reshape(-1, 3, 3)
    von_mises = post.principal_measures(tensors)["von_mises"]
    coords = S.tabulate_dof_coordinates()[:n]
    yc = spec.center_m[1]
    slab = 1e-9 * spec.half_width_m if domain.symmetry == "quarter" else 0.5 * spec.contact_size_m
    sel = np.abs(coords[:, 1] - yc) <= slab
    xyz_parts = comm.gather(coords[sel], root=0)
    vm_parts = comm.gather(von_mises[sel], root=0)
    if comm.rank == 0:
        cut_xyz, cut_vm = np.concatenate(xyz_parts), np.concatenate(vm_parts)
        files.update(_draw(out, fields, cut_xyz, cut_vm, spec, domain.symmetry))
    return comm.bcast(files, root=0)


def _gather_vertex_grid(msh, comm, S, u1, stress_fn, cell_tags):
    """Vertex coordinates, tetrahedra and vertex fields of the whole mesh on rank 0 (None elsewhere).

    P1 dofs and the vertices of a linear geometry are matched cell by cell (same reference ordering);
    every rank sends its owned vertices with their global geometry indices and its owned cells.
    """
    from fea import postprocess as post

    geometry = msh.geometry
    gmap = geometry.index_map()
    n_owned = gmap.size_local
    n_all = n_owned + gmap.num_ghosts
    tdim = msh.topology.dim
    n_cells = msh.topology.index_map(tdim).size_local
    geom_cells = np.asarray(geometry.dofmaps[0])
    if geom_cells.shape[1] != 4:
        raise ValueError(f"mesh geometry with {geom_cells.shape[1]} nodes per cell: expected linear tetrahedra")
    vertex_to_dof = np.empty(n_all, dtype=np.int64)
    vertex_to_dof[geom_cells.ravel()] = np.asarray(S.dofmap.list).ravel()
    dofs = vertex_to_dof[:n_owned]
    bs_u, bs_s = u1.function_space.dofmap.index_map_bs, stress_fn.function_space.dofmap.index_map_bs
    disp = u1.x.array.reshape(-1, bs_u)[dofs]
    stress = stress_fn.x.array.reshape(-1, bs_s)[dofs].reshape(-1, 3, 3)
    measures = post.principal_measures(stress)
    global_index = gmap.local_to_global(np.arange(n_all, dtype=np.int32))
    cells = global_index[geom_cells[:n_cells]]
    body = None
    if cell_tags is not None:
        body = np.full(n_cells, -1, dtype=np.int32)
        keep = cell_tags.indices < n_cells
        body[cell_tags.indices[keep]] = cell_tags.values[keep]
    local = (
        global_index[:n_owned],
        geometry.x[:n_owned, :3],
        cells,
        {
            "displacement_m": disp,
            "stress_Pa": stress.reshape(-1, 9),
            "principal_stress_Pa": measures["principal"],
            "von_mises_Pa": measures["von_mises"],
            "max_shear_Pa": measures["max_shear"],
        },
        body,
    )
    parts = comm.gather(local, root=0)
    if comm.rank != 0:
        return None, None, None, None
    n_global = gmap.size_global
    points = np.empty((n_global, 3))
    point_data = {name: np.empty((n_global, *value.shape[1:])) for name, value in parts[0][3].items()}
    for index, xyz, _, values, _ in parts:
        points[index] = xyz
        for name, value in values.items():
            point_data[name][index] = value
    cells = np.concatenate([part[2] for part in parts])
    cell_data = {}
    if parts[0][4] is not None:
        cell_data["body"] = [np.concatenate([part[4] for part in parts])]
    return points, cells, point_data, cell_data


def _write_vtu(path: Path, points, cells, point_data, cell_data) -> None:
    """Write one tetrahedral grid with meshio (binary, zlib), atomically."""
    import meshio

    mesh = meshio.Mesh(points, [("tetra", cells)], point_data=point_data, cell_data=cell_data)

    def writer(tmp: Path) -> None:
        meshio.write(tmp, mesh, file_format="vtu")

    atomic_write(path, writer)


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
