"""gmsh models -> distributed DOLFINx meshes with named tags (built on rank 0, partitioned over the communicator)."""

from __future__ import annotations

from dataclasses import dataclass

from meshing.quality import MeshQuality, MeshQualityError, QualityLimits, check_quality


@dataclass(frozen=True, eq=False)
class Domain:
    """A DOLFINx mesh with its facet tags and the physical group names.

    Attributes:
        mesh: dolfinx.mesh.Mesh (distributed).
        facet_tags: dolfinx.mesh.MeshTags of the facets.
        groups: physical group name -> tag (facet groups and the body).
        quality: quality report of the gmsh mesh (the same on every rank).
        symmetry: "quarter" or "full"; the quarter model carries 1/4 of the load.
    """

    mesh: object
    facet_tags: object
    groups: dict
    quality: MeshQuality
    symmetry: str

    @property
    def symmetry_factor(self) -> float:
        """Force on the whole patch / force on the modelled part."""
        return 4.0 if self.symmetry == "quarter" else 1.0


def mesh_on_rank0(name: str, build, comm=None, limits: QualityLimits | None = None):
    """Build a gmsh model on rank 0 with ``build(model)``, check its quality, and distribute it.

    Every rank gets the same outcome: the DOLFINx mesh data and the quality report, or the same
    exception (MeshQualityError for a bad mesh, ValueError for a failing builder).

    Returns:
        (mesh data of ``dolfinx.io.gmsh.model_to_mesh``, MeshQuality, {group name: tag}).
    """
    import dolfinx_solver  # noqa: F401  (must precede dolfinx/petsc4py/mpi4py)
    from dolfinx.io import gmsh as gmsh_io
    from mpi4py import MPI

    from meshing.quality import mesh_quality
    from meshing.session import generate, gmsh_model

    comm = MPI.COMM_WORLD if comm is None else comm
    limits = QualityLimits() if limits is None else limits
    error, quality = None, None
    with gmsh_model(name) as model:
        if comm.rank == 0:
            try:
                build(model)
                generate(model)
                quality = check_quality(mesh_quality(model), limits)
            except (MeshQualityError, ValueError) as exc:
                error = (type(exc).__name__, str(exc))
        error = comm.bcast(error, root=0)
        if error is not None:
            kind, message = error
            raise MeshQualityError(message) if kind == "MeshQualityError" else ValueError(message)
        quality = comm.bcast(quality, root=0)
        data = gmsh_io.model_to_mesh(model, comm, 0, gdim=3)
    groups = {group_name: group.tag for group_name, group in data.physical_groups.items()}
    return data, quality, groups


def hertz_block_domain(spec, comm=None, limits: QualityLimits | None = None) -> Domain:
    """Mesh a :class:`meshing.hertz.HertzBlockSpec` on rank 0 and distribute it.

    Raises:
        MeshQualityError: (on every rank) the mesh fails ``limits``.
    """
    from meshing.hertz import build_hertz_block

    data, quality, groups = mesh_on_rank0("hertz-block", lambda model: build_hertz_block(model, spec), comm, limits)
    return Domain(data.mesh, data.facet_tags, groups, quality, spec.symmetry)


def plane_strain_slab_domain(spec, comm=None) -> Domain:
    """Mesh a :class:`meshing.slab.SlabSpec` (one extruded layer) on rank 0 and distribute it.

    The slab's tetrahedra are flat far from the patch (thickness h_c, in-plane size up to L/3): harmless in
    plane strain (u_y = 0 on every node), so the quality limit is relaxed to minSICN 1e-4. symmetry "full"
    (factor 1: forces are per slab thickness h_c).
    """
    from meshing.slab import build_slab

    limits = QualityLimits(min_quality=1e-4)
    data, quality, groups = mesh_on_rank0("plane-strain-slab", lambda model: build_slab(model, spec), comm, limits)
    return Domain(data.mesh, data.facet_tags, groups, quality, "full")


def rolling_block_domain(spec, comm=None, limits: QualityLimits | None = None) -> Domain:
    """Mesh a :class:`meshing.rolling_block.RollingBlockSpec` (full block, structured box under the patch) on rank 0.

    symmetry "full" (factor 1). The face nodes in the box lie on the rows y = j h, at x = i h (the grid) or, with
    ``spec.fit_edge``, moved along their row so that each row's contact nodes end on the expected patch edge
    (:func:`meshing.rolling_block.fit_rows_to_edge`, applied to the distributed mesh's coordinates; ``quality`` is
    gmsh's report before that move, which stretches a row's cells by at most a factor 1 +- 1/(2 m), m >= 1 the
    row's cells to the edge). The steady-rolling solver's transport then runs along the rows.

    Raises:
        MeshQualityError: (on every rank) the mesh fails ``limits``, or the edge fit inverts a tetrahedron.
    """
    import numpy as np

    from meshing.rolling_block import build_rolling_block, fit_rows_to_edge

    data, quality, groups = mesh_on_rank0("rolling-block", lambda model: build_rolling_block(model, spec), comm, limits)
    msh = data.mesh
    if spec.fit_edge:
        x = msh.geometry.x
        cells = np.asarray(msh.geometry.dofmaps[0])
        before = _tet_volumes(x, cells)
        x[:] = fit_rows_to_edge(spec, x)
        ratio = float(np.min(_tet_volumes(x, cells) / before, initial=np.inf))
        ratio = msh.comm.allreduce(ratio, op=_mpi_min())
        if not ratio > 0:
            raise MeshQualityError(f"rolling block: the edge fit inverts a tetrahedron (volume ratio {ratio:.3g})")
    return Domain(msh, data.facet_tags, groups, quality, "full")


def _tet_volumes(x, cells):
    """Signed volumes of the tetrahedra ``cells`` (k, 4) of the coordinates ``x`` (m, 3), m^3."""
    import numpy as np

    p = x[cells]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0


def _mpi_min():
    from mpi4py import MPI

    return MPI.MIN
