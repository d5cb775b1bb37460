"""Linear elastic body in frictionless unilateral contact with a rigid indenter (FEniCSx/PETSc).

Problem (small strains, no body force): find u in the elastic block Omega (material at z < 0,
contact face Gamma_c = {z = 0}, clamped base, symmetry planes of the quarter model) with::

    div sigma(u) = 0,   sigma = lambda tr(eps) I + 2 mu eps,
    d = h(x, y) - q - u_z >= 0,   p >= 0,   p d = 0   on Gamma_c,

h the undeformed distance of the rigid indenter's surface above Gamma_c (h = A x^2 + B y^2 for a
quadric), q the rigid approach, p the contact pressure (traction -p e_z on the body). For two
elastic quadric bodies of equal constants, one elastic block with Young's modulus
E_body = E* (1 - nu^2) against the rigid gap reproduces Hertz (Johnson 1985, sec. 4.2), E* the
combined modulus of :class:`rigid_dynamics.materials.Material`.

Discretisation: Lagrange P1 (or P2) displacements; the contact condition is imposed at the contact-face
nodes (the gap h is interpolated into the displacement space, i.e. sampled at the nodes), the
pressure is the nodal contact reaction divided by the lumped face weight w_i = int_Gamma phi_i ds.

Solution: primal-dual active set method, which is a semismooth Newton method for the
complementarity function C(N, d) = N - max(0, N - c d) (Hintermueller, Ito & Kunisch, SIAM J.
Optim. 13 (2002) 865-888). For an active set A the nodes of A are held at u_z = h - q (rows and
columns eliminated in the assembled stiffness K, MatZeroRowsColumns), the others are free; the
nodal contact force is N_i = -(K u)_i. The next active set is {N_i / w_i - c d_i > 0}. It stops
when the set repeats. Load control: u = u_h + q u_1 is linear in q for a fixed set (two solves
with one factorisation), q follows from sum N_i = P / symmetry factor. Displacement control: q given.

Linear solver: MUMPS LU (default for small problems) or CG + GAMG with the six rigid-body modes as
near-nullspace (large problems; hypre is not available in the wheel).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

LINEAR_SOLVERS = ("auto", "mumps", "cg-gamg")

_MUMPS_OPTIONS = {"mat_mumps_icntl_7": "5"}


@dataclass(frozen=True)
class SolverSettings:
    """Settings of the contact solver.

    Attributes:
        degree: polynomial degree of the displacement, 1 or 2 (P2: the constraint holds at all face
            nodes, vertices and edge midpoints; the lumped weight of a P2 vertex is 0, so the active-set
            test uses N_i - c w_ref d_i with the mean face weight w_ref).
        linear_solver: "auto" (MUMPS up to ``direct_max_dofs``, else CG + GAMG), "mumps" or "cg-gamg".
        direct_max_dofs: largest problem solved by MUMPS in "auto" mode.
        max_iterations: maximum number of active-set (semismooth Newton) iterations.
        krylov_rtol: relative tolerance of CG.
    """

    degree: int = 1
    linear_solver: str = "auto"
    direct_max_dofs: int = 15_000
    max_iterations: int = 40
    krylov_rtol: float = 1e-10

    def __post_init__(self) -> None:
        if self.degree not in (1, 2):
            raise ValueError(f"degree = {self.degree!r}: expected 1 or 2")
        if self.linear_solver not in LINEAR_SOLVERS:
            raise ValueError(f"linear_solver = {self.linear_solver!r}: expected one of {LINEAR_SOLVERS}")
        if int(self.max_iterations) != self.max_iterations or self.max_iterations < 1:
            raise ValueError(f"max_iterations = {self.max_iterations!r}: expected an integer >= 1")
        if not (0 < self.krylov_rtol < 1):
            raise ValueError(f"krylov_rtol = {self.krylov_rtol!r}: expected a number in (0, 1)")


@dataclass(eq=False)
class ContactSolution:
    """Raw FE solution (the same on every rank except ``displacement``, which is distributed).

    Attributes:
        success, status, message: convergence report.
        iterations: active-set iterations.
        normal_force_N: total force on the whole patch (sum of the nodal contact forces times the
            symmetry factor), N.
        approach_m: q, m.
        node_xy_m: (n, 2) contact-face node coordinates (modelled part), m.
        node_force_N: (n,) nodal contact forces N_i >= 0, N.
        node_weight_m2: (n,) lumped weights w_i, m^2.
        node_pressure_Pa: (n,) N_i / w_i, Pa.
        node_gap_m: (n,) deformed gap d_i, m.
        active: (n,) bool, nodes in contact.
        dofs: global number of displacement unknowns.
        displacement: dolfinx Function (distributed).
        complementarity_residual: max over nodes of |min(N_i/w_i, c d_i)| / (c * length scale).
        wall_time_s: time of the solve (assembly + iterations), s.
        timings: breakdown, s.
    """

    success: bool
    status: str
    message: str
    iterations: int
    normal_force_N: float
    approach_m: float
    node_xy_m: np.ndarray
    node_force_N: np.ndarray
    node_weight_m2: np.ndarray
    node_pressure_Pa: np.ndarray
    node_gap_m: np.ndarray
    active: np.ndarray
    dofs: int
    displacement: object
    complementarity_residual: float = 0.0
    wall_time_s: float = 0.0
    timings: dict = field(default_factory=dict)


def _rigid_body_modes(V, template):
    """Six orthonormalised rigid-body modes (3 translations, 3 rotations) as PETSc vectors."""
    bs = V.dofmap.index_map_bs
    n = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n]
    modes = [template.duplicate() for _ in range(6)]
    arrays = [np.zeros((n, bs)) for _ in range(6)]
    for k in range(3):
        arrays[k][:, k] = 1.0
    arrays[3][:, 0], arrays[3][:, 1] = -x[:, 1], x[:, 0]
    arrays[4][:, 1], arrays[4][:, 2] = -x[:, 2], x[:, 1]
    arrays[5][:, 0], arrays[5][:, 2] = x[:, 2], -x[:, 0]
    for vec, arr in zip(modes, arrays, strict=True):
        vec.array[:] = arr.ravel()
    for i, vec in enumerate(modes):
        for prev in modes[:i]:
            vec.axpy(-vec.dot(prev), prev)
        vec.normalize()
    return modes


def solve_rigid_indenter(
    domain,
    gap_function,
    young_modulus_Pa: float,
    poisson_ratio: float,
    *,
    normal_force_N: float | None = None,
    approach_m: float | None = None,
    initial_approach_m: float | None = None,
    initial_active=None,
    length_scale_m: float = 1e-3,
    settings: SolverSettings | None = None,
    surface_traction=None,
) -> ContactSolution:
    """Solve the contact of the elastic block ``domain`` with the rigid indenter of gap ``h``.

    Args:
        domain: :class:`fea.domain.Domain` (named groups ``contact``, ``base``, optional
            ``symmetry_x``, ``symmetry_y``).
        gap_function: h(x_m, y_m) -> undeformed distance at zero approach, m (arrays in, array out;
            +inf where the indenter is absent).
        young_modulus_Pa: E of the block, Pa (use E* (1 - nu^2) for the combined-modulus model).
        poisson_ratio: nu.
        normal_force_N: P on the whole patch (load control), N; or None.
        approach_m: q (displacement control), m; or None. Exactly one of the two is given.
        initial_approach_m: first guess of q for load control (e.g. Hertz's), m.
        initial_active: optional predicate (x_m, y_m) -> bool array, first guess of the contact
            region (e.g. Hertz's ellipse); default: the rigid overlap h < q.
        length_scale_m: expected patch size (scales the active-set constant c = E/length), m.
        settings: :class:`SolverSettings`.
        surface_traction: optional (x_m, y_m) -> (t_x, t_y), the tangential traction ON THE BLOCK's contact face,
            Pa (e.g. minus a BEM solution's tractions on the wheel): a Neumann load sum_i int t_i v_i ds added to
            the affine part of every solve (frictional tractions prescribed, not solved for; the normal contact
            stays frictionless and is solved as before). None: no tangential load.

    Returns:
        :class:`ContactSolution`; non-convergence gives success False, never an exception.
    """
    import dolfinx_solver  # noqa: F401
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc
    from petsc4py import PETSc

    settings = SolverSettings() if settings is None else settings
    if (normal_force_N is None) == (approach_m is None):
        raise ValueError("give exactly one of normal_force_N (load control) and approach_m (displacement control)")
    if normal_force_N is not None and not (math.isfinite(normal_force_N) and normal_force_N > 0):
        raise ValueError(f"normal_force_N = {normal_force_N!r}: expected a finite number > 0")
    if approach_m is not None and not math.isfinite(approach_m):
        raise ValueError(f"approach_m = {approach_m!r}: expected a finite number")

    t_start = time.perf_counter()
    timings = {}
    msh = domain.mesh
    comm = msh.comm
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    V = fem.functionspace(msh, ("Lagrange", settings.degree, (3,)))
    bs = 3
    imap = V.dofmap.index_map
    n_owned = imap.size_local * bs
    global_offset = imap.local_range[0] * bs
    dofs_global = imap.size_global * bs

    tags = domain.facet_tags
    groups = domain.groups
    bcs = []
    zero3 = np.zeros(3, dtype=PETSc.ScalarType)
    base = fem.locate_dofs_topological(V, tdim - 1, tags.find(groups["base"]))
    bcs.append(fem.dirichletbc(zero3, base, V))
    for name, comp in (("symmetry_x", 0), ("symmetry_y", 1)):
        if name in groups:
            dofs = fem.locate_dofs_topological(V.sub(comp), tdim - 1, tags.find(groups[name]))
            bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(comp)))

    mu = young_modulus_Pa / (2.0 * (1.0 + poisson_ratio))
    lam = young_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    def sigma(w):
        return lam * ufl.tr(eps(w)) * ufl.Identity(3) + 2.0 * mu * eps(w)

    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    a_form = fem.form(ufl.inner(sigma(u), eps(v)) * ufl.dx)
    w_form = fem.form(v[2] * ds(groups["contact"]))
    K = fem_petsc.assemble_matrix(a_form, bcs=bcs)
    K.assemble()
    w_vec = fem_petsc.assemble_vector(w_form)
    w_vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    load_vec = None
    if surface_traction is not None:
        t_fn = fem.Function(V, name="surface_traction")

        def traction_values(x):
            tx, ty = surface_traction(x[0], x[1])
            return np.vstack([np.asarray(tx, float), np.asarray(ty, float), np.zeros(x.shape[1])])

        t_fn.interpolate(traction_values)
        load_vec = fem_petsc.assemble_vector(fem.form(ufl.inner(t_fn, v) * ds(groups["contact"])))
        load_vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        fem_petsc.set_bc(load_vec, bcs)
    timings["assembly_s"] = time.perf_counter() - t_start

    cdofs = fem.locate_dofs_topological(V.sub(2), tdim - 1, tags.find(groups["contact"]))
    cdofs = np.sort(cdofs[cdofs < n_owned]).astype(np.int32)
    coords = V.tabulate_dof_coordinates()[cdofs // bs]
    xy = coords[:, :2].copy()
    weights = w_vec.array[cdofs].copy()
    h = np.asarray(gap_function(xy[:, 0], xy[:, 1]), dtype=float)
    h = np.where(np.isfinite(h), h, np.inf)
    rows_global = (cdofs + global_offset).astype(PETSc.IntType)
    sym = domain.symmetry_factor

    use_direct = settings.linear_solver == "mumps" or (
        settings.linear_solver == "auto" and dofs_global <= settings.direct_max_dofs
    )
    K_A = K.duplicate(copy=True)
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(K_A)
    if use_direct:
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setOptionsPrefix(f"wheelrail_fea_{id(ksp)}_")
        opts = PETSc.Options(ksp.getOptionsPrefix())
        for key, value in _MUMPS_OPTIONS.items():
            opts[key] = value
        ksp.setFromOptions()
        for key in _MUMPS_OPTIONS:
            opts.delValue(key)
    else:
        ksp.setType("cg")
        ksp.getPC().setType("gamg")
        ksp.setTolerances(rtol=settings.krylov_rtol, max_it=2000)
        ns = PETSc.NullSpace().create(vectors=_rigid_body_modes(V, K.createVecRight()))
        K_A.setNearNullSpace(ns)

    uh = fem.Function(V, name="displacement")
    x_h, x_1 = K.createVecRight(), K.createVecRight()
    b, prescribed, reaction = K.createVecLeft(), K.createVecLeft(), K.createVecLeft()
    c_const = young_modulus_Pa / length_scale_m
    positive = weights[weights > 0]
    w_ref = comm.allreduce(float(positive.sum())) / max(comm.allreduce(int(positive.size)), 1)
    w_test = weights if settings.degree == 1 else np.full_like(weights, w_ref)
    sum_all = comm.allreduce

    def solve_with(active, values, loaded=True):
        """Solve for u with u_z = values at the active contact nodes (other contact nodes free); ``loaded`` adds
        the tangential surface load (the affine part; not for the unit-approach solve of load control).
        """
        prescribed.set(0.0)
        prescribed.array[cdofs[active]] = values
        K.mult(prescribed, b)
        b.scale(-1.0)
        if loaded and load_vec is not None:
            b.axpy(1.0, load_vec)
        b.array[cdofs[active]] = values
        out = K.createVecRight()
        ksp.solve(b, out)
        reason = ksp.getConvergedReason()
        return out, reason

    def forces(vec):
        K.mult(vec, reaction)
        return -reaction.array[cdofs].copy()

    if approach_m is not None:
        q = float(approach_m)
    else:
        q = float(initial_approach_m) if initial_approach_m is not None else float(np.min(h))
    active = h - q < 0.0
    if initial_active is not None:
        active = np.asarray(initial_active(xy[:, 0], xy[:, 1]), dtype=bool) & np.isfinite(h)
    if sum_all(int(active.sum())) == 0:
        h_min = comm.allreduce(float(np.min(h)) if h.size else math.inf, op=_mpi_min())
        if normal_force_N is None:
            return _no_contact(comm, q, xy, weights, h, dofs_global, uh, t_start, timings)
        active = h <= h_min * (1 + 1e-12) + 1e-15

    status, message, success = "not-converged", "", False
    it = 0
    t_iter = time.perf_counter()
    n_factor = 0
    for it in range(1, settings.max_iterations + 1):
        n_active = sum_all(int(active.sum()))
        if n_active == 0:
            if normal_force_N is None:
                return _no_contact(comm, q, xy, weights, h, dofs_global, uh, t_start, timings)
            status, message = "not-converged", "active set became empty under load control"
            break
        K.copy(K_A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        K_A.zeroRowsColumns(rows_global[active], diag=1.0)
        ksp.setOperators(K_A)
        n_factor += 1
        if normal_force_N is None:
            x_h, reason = solve_with(active, h[active] - q)
            if reason < 0:
                status, message = "not-converged", f"linear solver failed (PETSc reason {reason})"
                break
            node_force = forces(x_h)
            x_h.copy(uh.x.petsc_vec)
        else:
            x_h, r1 = solve_with(active, h[active])
            x_1, r2 = solve_with(active, -np.ones(int(active.sum())), loaded=False)
            if min(r1, r2) < 0:
                status, message = "not-converged", f"linear solver failed (PETSc reason {min(r1, r2)})"
                break
            f_h, f_1 = forces(x_h), forces(x_1)
            s_h, s_1 = sum_all(float(f_h.sum())), sum_all(float(f_1.sum()))
            if not s_1 > 0:
                status, message = "not-converged", "contact stiffness not positive (singular active set)"
                break
            q = (normal_force_N / sym - s_h) / s_1
            node_force = f_h + q * f_1
            x_h.axpy(q, x_1)
            x_h.copy(uh.x.petsc_vec)
        uh.x.scatter_forward()
        u_z = uh.x.array[cdofs]
        gap = h - q - u_z
        finite = np.isfinite(gap)
        new_active = np.zeros_like(active)
        new_active[finite] = node_force[finite] / w_test[finite] - c_const * gap[finite] > 0.0
        changed = sum_all(int(np.count_nonzero(new_active != active)))
        active = new_active
        if changed == 0:
            success, status, message = True, "ok", f"active set converged in {it} iterations"
            break
    else:
        message = f"active set did not settle in {settings.max_iterations} iterations"
    timings["iterations_s"] = time.perf_counter() - t_iter

    node_force = np.where(active, node_force, 0.0)
    pressure = node_force / w_test
    finite_gap = np.where(np.isfinite(gap), gap, 0.0)
    scale = c_const * length_scale_m
    compl = np.abs(np.minimum(pressure, c_const * finite_gap)) / scale if pressure.size else np.zeros(0)
    compl_max = comm.allreduce(float(compl.max()) if compl.size else 0.0, op=_mpi_max())
    total = sym * sum_all(float(node_force.sum()))

    def gather(arr):
        parts = comm.allgather(np.asarray(arr))
        return np.concatenate(parts) if parts else np.asarray(arr)

    ksp.destroy()
    K_A.destroy()
    K.destroy()
    if load_vec is not None:
        load_vec.destroy()
    return ContactSolution(
        success=success,
        status=status,
        message=message,
        iterations=it,
        normal_force_N=total,
        approach_m=q,
        node_xy_m=gather(xy).reshape(-1, 2),
        node_force_N=gather(node_force),
        node_weight_m2=gather(weights),
        node_pressure_Pa=gather(pressure),
        node_gap_m=gather(finite_gap),
        active=gather(active).astype(bool),
        dofs=dofs_global,
        displacement=uh,
        complementarity_residual=compl_max,
        wall_time_s=time.perf_counter() - t_start,
        timings={**timings, "factorisations": n_factor, "linear_solver": "mumps" if use_direct else "cg-gamg"},
    )


def _mpi_min():
    from mpi4py import MPI

    return MPI.MIN


def _mpi_max():
    from mpi4py import MPI

    return MPI.MAX


def _no_contact(comm, q, xy, weights, h, dofs, uh, t_start, timings):
    def gather(arr):
        return np.concatenate(comm.allgather(np.asarray(arr)))

    n = len(h)
    return ContactSolution(
        success=True,
        status="no-contact",
        message=f"no contact-face node penetrates the indenter at approach {q:.6g} m",
        iterations=0,
        normal_force_N=0.0,
        approach_m=q,
        node_xy_m=gather(xy).reshape(-1, 2),
        node_force_N=gather(np.zeros(n)),
        node_weight_m2=gather(weights),
        node_pressure_Pa=gather(np.zeros(n)),
        node_gap_m=gather(np.where(np.isfinite(h), h - q, 0.0)),
        active=gather(np.zeros(n, bool)),
        dofs=dofs,
        displacement=uh,
        wall_time_s=time.perf_counter() - t_start,
        timings=timings,
    )
