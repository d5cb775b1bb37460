"""Two elastic bodies in frictionless contact: node-to-surface pairing, penalty, semismooth Newton.

Bodies: ``lower`` (rail side, material below its contact face) and ``upper`` (wheel side), meshed
as disconnected parts of one DOLFINx mesh, each linear elastic (E, nu). The contact plane is
z = 0 with normal +z (contact frame); the lower base is clamped, the upper base is moved rigidly
by u = -q e_z (q the approach; load control finds q for the normal force P).

Contact (slave = upper face nodes s, master = lower face triangles): for the current (deformed)
positions the slave node is projected along z onto the deformed master surface; with barycentric
coordinates beta_k of the master triangle the normal gap is::

    c_s(u) = (X_s + u_s)_z - sum_k beta_k (X_k + u_k)_z   >= 0

Penalty with nodal (lumped) weights: contact force on the slave node lambda_s = eps w_s max(0, -c_s),
eps = kappa E / h_c (pressure per unit penetration; kappa = 100 makes the penetration ~1e-3 of the
element size at p ~ E/100), w_s the slave face weight. Semismooth Newton: for a fixed active set and
pairing the problem is linear, K u + sum_active eps w_s b_s (b_s . u + g0_s) = 0, b_s = e_s - sum_k
beta_k e_k (z components); the active set {c_s < 0} and the pairing are updated from the new
solution until both repeat. Load control: u = u_0 + q u_1 (one factorisation, two solves per
iteration). Total force = sum of lambda_s (times the symmetry factor), i.e. from the contact term.

Linear (small-strain) kinematics and a fixed normal (slopes within the patch small): the
linearisation of the projection point (beta varies with u) is neglected, the pairing is refreshed
each iteration instead.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fea.solver import ContactSolution, SolverSettings


@dataclass(frozen=True, eq=False)
class PairDomain:
    """Mesh of two bodies with facet tags and named groups (see :func:`hertz_pair_domain`)."""

    mesh: object
    cell_tags: object
    facet_tags: object
    groups: dict
    quality: object
    symmetry: str

    @property
    def symmetry_factor(self) -> float:
        return 4.0 if self.symmetry == "quarter" else 1.0


def hertz_pair_domain(spec, lower_curvatures, upper_curvatures, comm=None, limits=None) -> PairDomain:
    """Two quadric bodies: block pair of :func:`meshing.hertz.build_hertz_pair` morphed to curved faces.

    The lower contact face becomes z = -(A1 x^2 + B1 y^2), the upper z = A2 x^2 + B2 y^2 (x, y from the
    patch centre); the morph decays linearly to the bases, which stay flat. Undeformed distance
    h = (A1 + A2) x^2 + (B1 + B2) y^2.

    Args:
        spec: :class:`meshing.hertz.HertzBlockSpec`.
        lower_curvatures, upper_curvatures: (A_i, B_i) in 1/m (>= 0).
    """
    from fea.domain import mesh_on_rank0
    from meshing.hertz import build_hertz_pair

    data, quality, groups = mesh_on_rank0("hertz-pair", lambda model: build_hertz_pair(model, spec), comm, limits)
    msh = data.mesh
    x = msh.geometry.x
    depth = spec.half_width_m
    xc, yc = spec.center_m
    for name, (a_i, b_i), sign in (("upper", upper_curvatures, 1.0), ("lower", lower_curvatures, -1.0)):
        cells = data.cell_tags.find(groups[name])
        nodes = np.unique(msh.geometry.dofmaps[0][cells].ravel())
        px, py, pz = x[nodes, 0] - xc, x[nodes, 1] - yc, x[nodes, 2]
        ramp = np.clip(1.0 - np.abs(pz) / depth, 0.0, 1.0)
        x[nodes, 2] = pz + sign * (a_i * px**2 + b_i * py**2) * ramp
    return PairDomain(msh, data.cell_tags, data.facet_tags, groups, quality, spec.symmetry)


def _face_dofs(V, tags, tag, comp, n_owned):
    from dolfinx import fem

    dofs = fem.locate_dofs_topological(V.sub(comp), 2, tags.find(tag))
    return np.sort(dofs[dofs < n_owned]).astype(np.int32)


def solve_two_body(
    domain: PairDomain,
    young_modulus_Pa: float,
    poisson_ratio: float,
    *,
    normal_force_N: float | None = None,
    approach_m: float | None = None,
    initial_approach_m: float = 0.0,
    contact_size_m: float,
    penalty_factor: float = 100.0,
    settings: SolverSettings | None = None,
) -> ContactSolution:
    """Solve the two-body contact (module docstring). Non-convergence -> success False, never raises.

    Args:
        domain: :class:`PairDomain`.
        young_modulus_Pa, poisson_ratio: E, nu of both bodies.
        normal_force_N: P (load control) or None; approach_m: q (displacement control) or None.
        initial_approach_m: first guess of q for the first pairing (load control), m.
        contact_size_m: h_c, element size at the patch (sets eps), m.
        penalty_factor: kappa.
        settings: :class:`fea.solver.SolverSettings` (linear solver, iteration limit).
    """
    import dolfinx_solver  # noqa: F401
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc
    from petsc4py import PETSc
    from scipy.spatial import Delaunay

    settings = SolverSettings() if settings is None else settings
    if (normal_force_N is None) == (approach_m is None):
        raise ValueError("give exactly one of normal_force_N (load control) and approach_m (displacement control)")
    t0 = time.perf_counter()
    msh = domain.mesh
    comm = msh.comm
    msh.topology.create_connectivity(2, 3)
    V = fem.functionspace(msh, ("Lagrange", 1, (3,)))
    bs = 3
    imap = V.dofmap.index_map
    n_owned = imap.size_local * bs
    offset = imap.local_range[0] * bs
    tags, groups = domain.facet_tags, domain.groups

    zero3 = np.zeros(3, dtype=PETSc.ScalarType)
    bcs = [fem.dirichletbc(zero3, fem.locate_dofs_topological(V, 2, tags.find(groups["lower_base"])), V)]
    for name, comp in (("symmetry_x", 0), ("symmetry_y", 1)):
        if name in groups:
            dofs = fem.locate_dofs_topological(V.sub(comp), 2, tags.find(groups[name]))
            bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(comp)))
    mu = young_modulus_Pa / (2.0 * (1.0 + poisson_ratio))
    lam = young_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps_(w):
        return ufl.sym(ufl.grad(w))

    a_form = fem.form(ufl.inner(lam * ufl.tr(eps_(u)) * ufl.Identity(3) + 2 * mu * eps_(u), eps_(v)) * ufl.dx)
    K = fem_petsc.assemble_matrix(a_form, bcs=bcs)
    K.assemble()
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    w_vec = fem_petsc.assemble_vector(fem.form(v[2] * ds(groups["upper_contact"])))
    w_vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    coords = V.tabulate_dof_coordinates()
    slave = _face_dofs(V, tags, groups["upper_contact"], 2, n_owned)
    master = _face_dofs(V, tags, groups["lower_contact"], 2, n_owned)
    slave_x = coords[slave // bs]
    slave_w = w_vec.array[slave].copy()
    # The upper base moves rigidly: all three components prescribed.
    base_up = fem.locate_dofs_topological(V, 2, tags.find(groups["upper_base"]))
    base_blocks = base_up[base_up < imap.size_local]
    base_rows = np.concatenate([base_blocks * bs + c for c in range(3)]).astype(np.int32)
    base_z = (base_blocks * bs + 2).astype(np.int32)
    # Symmetry-plane rows of the upper body stay free (they are not in bcs for the base), fine.

    # Master surface (gathered on every rank): reference coordinates and global z-dof numbers.
    m_x = np.concatenate(comm.allgather(coords[master // bs]))
    m_gdof = np.concatenate(comm.allgather((master + offset).astype(np.int64)))
    tri = Delaunay(m_x[:, :2] / contact_size_m)  # planar triangulation of the master nodes (in-plane)

    eps_pen = penalty_factor * young_modulus_Pa / contact_size_m
    sym = domain.symmetry_factor
    uh = fem.Function(V, name="displacement")
    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    prescribed, rhs = K.createVecLeft(), K.createVecLeft()

    def pairing(u_master_z, u_slave):
        """Master triangle and barycentric weights for each slave node (deformed in-plane positions)."""
        pos = (slave_x[:, :2] + u_slave[:, :2]) / contact_size_m
        simplex = tri.find_simplex(pos)
        inside = simplex >= 0
        idx = np.zeros((len(pos), 3), dtype=np.int64)
        beta = np.zeros((len(pos), 3))
        if inside.any():
            trans = tri.transform[simplex[inside]]
            b2 = np.einsum("nij,nj->ni", trans[:, :2], pos[inside] - trans[:, 2])
            beta[inside] = np.column_stack([b2, 1.0 - b2.sum(axis=1)])
            idx[inside] = tri.simplices[simplex[inside]]
        master_z = m_x[:, 2] + u_master_z
        g0 = np.full(len(pos), np.inf)
        g0[inside] = slave_x[inside, 2] - np.einsum("nk,nk->n", beta[inside], m_x[idx[inside], 2])
        cur = np.full(len(pos), np.inf)
        cur[inside] = (
            slave_x[inside, 2] + u_slave[inside, 2] - np.einsum("nk,nk->n", beta[inside], master_z[idx[inside]])
        )
        return idx, beta, g0, cur

    def gather_master_uz(vec_array_local):
        return np.concatenate(comm.allgather(vec_array_local[master]))

    def slave_u(arr):
        blocks = slave // bs
        return np.column_stack([arr[blocks * bs + c] for c in range(3)])

    # Initial state: undeformed bodies, upper body shifted rigidly by -q0.
    q = float(approach_m) if approach_m is not None else float(initial_approach_m)
    u_slave0 = np.zeros((len(slave), 3))
    u_slave0[:, 2] = -q
    idx, beta, g0, cur = pairing(np.zeros(len(m_x)), u_slave0)
    # first guess: the rigid overlap at half the approach (exactly Hertz's ellipse for quadric bodies)
    active = cur < -0.5 * q
    band = 1e-5 * max(abs(q), contact_size_m * 1e-3)
    status, message, success = "not-converged", "", False
    it = 0
    force_nodes = np.zeros(len(slave))
    for it in range(1, settings.max_iterations + 1):
        P = PETSc.Mat().createAIJ(K.getSizes(), nnz=(24, 24), comm=comm)
        P.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        P.setUp()
        rows_s = slave + offset
        act_idx = np.flatnonzero(active)
        for s in act_idx:
            dofs = np.concatenate([[rows_s[s]], m_gdof[idx[s]]]).astype(PETSc.IntType)
            b = np.concatenate([[1.0], -beta[s]])
            P.setValues(dofs, dofs, (eps_pen * slave_w[s]) * np.outer(b, b), addv=PETSc.InsertMode.ADD_VALUES)
        P.assemble()
        # rhs from the reference gap: - sum eps w g0 b
        G = K.createVecLeft()
        for s in act_idx:
            dofs = np.concatenate([[rows_s[s]], m_gdof[idx[s]]]).astype(PETSc.IntType)
            b = np.concatenate([[1.0], -beta[s]])
            G.setValues(dofs, -(eps_pen * slave_w[s] * g0[s]) * b, addv=PETSc.InsertMode.ADD_VALUES)
        G.assemblyBegin()
        G.assemblyEnd()
        A = K.duplicate(copy=True)
        A.axpy(1.0, P, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        # lifting of the unit rigid motion of the upper base (u_z = -1), before the rows are eliminated
        prescribed.set(0.0)
        prescribed.array[base_z] = -1.0
        lift = K.createVecLeft()
        A.mult(prescribed, lift)
        lift.scale(-1.0)

        def solve_rhs(q_value, with_gap, lift=lift, gap_rhs=G):
            rhs.set(0.0)
            rhs.axpy(q_value, lift)
            if with_gap:
                rhs.axpy(1.0, gap_rhs)
            rhs.array[base_rows] = q_value * prescribed.array[base_rows]
            out = K.createVecRight()
            ksp.solve(rhs, out)
            return out, ksp.getConvergedReason()

        A.zeroRowsColumns((base_rows + offset).astype(PETSc.IntType), diag=1.0)
        ksp.setOperators(A)
        if normal_force_N is None:
            x_sol, reason = solve_rhs(q, True)
            if reason < 0:
                message = f"linear solver failed (PETSc reason {reason})"
                break
        else:
            x_0, r0 = solve_rhs(0.0, True)
            x_1, r1 = solve_rhs(1.0, False)
            if min(r0, r1) < 0:
                message = f"linear solver failed (PETSc reason {min(r0, r1)})"
                break

            # contact force = sum eps w max(0, -c); for the fixed active set linear in q
            def b_dot(vec, beta=beta, idx=idx):
                arr = vec.array
                return slave_u(arr)[:, 2] - np.einsum("nk,nk->n", beta, gather_master_uz(arr)[idx])

            c0, c1 = g0 + b_dot(x_0), b_dot(x_1)
            f0 = comm.allreduce(float(np.sum((eps_pen * slave_w * -c0)[active])))
            f1 = comm.allreduce(float(np.sum((eps_pen * slave_w * -c1)[active])))
            if not f1 > 0:
                message = "contact stiffness not positive (no active pair)"
                break
            q = (normal_force_N / sym - f0) / f1
            x_sol = x_0.copy()
            x_sol.axpy(q, x_1)
        x_sol.copy(uh.x.petsc_vec)
        uh.x.scatter_forward()
        arr = uh.x.array
        u_m = gather_master_uz(arr)
        u_s = slave_u(arr)
        c_lin = g0 + u_s[:, 2] - np.einsum("nk,nk->n", beta, u_m[idx])
        force_nodes = np.where(active, eps_pen * slave_w * np.maximum(-c_lin, 0.0), 0.0)
        # Update the pairing from the deformed configuration and the active set.
        idx_new, beta_new, g0_new, cur = pairing(u_m, u_s)
        # hysteresis band: nodes within +-band of touching keep their status (stops +-1 node cycling)
        new_active = np.where(np.abs(cur) <= band, active, cur < 0)
        changed = comm.allreduce(int(np.count_nonzero(new_active != active)))
        moved = comm.allreduce(int(np.count_nonzero(np.any(idx_new != idx, axis=1) & (active | new_active))))
        idx, beta, g0, active = idx_new, beta_new, g0_new, new_active
        A.destroy()
        P.destroy()
        G.destroy()
        lift.destroy()
        if changed == 0 and moved == 0:
            success, status = True, "ok"
            message = f"active set and pairing converged in {it} iterations (hysteresis band {band:.2g} m)"
            break
        if it >= 5:
            band *= 3.0  # widen the band while the set still cycles (each step bounded by ~band of gap)
    else:
        message = f"active set did not settle in {settings.max_iterations} iterations"
    ksp.destroy()
    K.destroy()

    total = sym * comm.allreduce(float(force_nodes.sum()))

    def gather(a):
        return np.concatenate(comm.allgather(np.asarray(a)))

    finite = np.where(np.isfinite(cur), cur, 0.0)
    pressure = force_nodes / slave_w
    return ContactSolution(
        success=success,
        status=status,
        message=message,
        iterations=it,
        normal_force_N=total,
        approach_m=q,
        node_xy_m=gather(slave_x[:, :2]).reshape(-1, 2),
        node_force_N=gather(force_nodes),
        node_weight_m2=gather(slave_w),
        node_pressure_Pa=gather(pressure),
        node_gap_m=gather(finite),
        active=gather(force_nodes > 0),
        dofs=imap.size_global * bs,
        displacement=uh,
        complementarity_residual=float("nan") if not math.isfinite(total) else 0.0,
        wall_time_s=time.perf_counter() - t0,
        timings={"linear_solver": "mumps", "penalty_Pa_per_m": eps_pen},
    )


def profile_pair_domain(rail_curve, wheel_curve, rail_spec, wheel_spec, comm=None, limits=None) -> PairDomain:
    """Rail section (``lower``) and wheel section (``upper``) from real profiles, touching at the origin.

    Both sections (:func:`meshing.profile_sections.build_profile_section`) are turned so that their
    contact points are at the origin with the common normal along +Z (the contact frame, yaw
    neglected); the undeformed distance is then the distance of the two real surfaces.
    """
    from fea.domain import mesh_on_rank0
    from meshing.profile_sections import build_profile_section

    def build(model):
        build_profile_section(model, rail_curve, rail_spec, prefix="lower")
        build_profile_section(model, wheel_curve, wheel_spec, prefix="upper", size_field=False)

    data, quality, groups = mesh_on_rank0("profile-pair", build, comm, limits)
    return PairDomain(data.mesh, data.cell_tags, data.facet_tags, groups, quality, "full")
