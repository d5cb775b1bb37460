"""Coulomb friction in the FEA: the shift (Cattaneo-Mindlin) problem with partial slip (FEniCSx/PETSc).

Model. Two quasi-identical elastic bodies (equal E and nu): the normal and tangential problems uncouple
exactly in half-space theory (Kalker's difference parameter beta = 0; Johnson 1985, sec. 5.1 and 7.2): the
tangential tractions do not change the pressure. As for the normal problem (:mod:`fea.solver`), the pair is
one elastic block of E_body = E* (1 - nu^2) (= E/2 for equal bodies, so G_body = G/2 and the block's
compliance (2 - nu)/G_body is the pair's (2 - nu)/G_1 + (2 - nu)/G_2) against a rigid indenter. The indenter
is shifted tangentially by the rigid displacement delta; the contact nodes carry the nodal normal forces N_i
of a converged frictionless solve (:func:`fea.solver.solve_rigid_indenter`, the same mesh), held fixed. The
tangential problem is solved with the normal displacement of the contact face free (its normal traction
change is zero: with beta = 0 the normal displacements the tangential tractions cause are equal on both
bodies and do not change the gap; in the one-block model they are simply not fed back).

Coulomb's law per contact node i (nodal form, P1): tangential nodal force F_i on the block (2 components),
relative slip g_i = delta - u_t,i (indenter against the surface, monotone loading so the slip is the total
displacement difference), and

    stick:  g_i = 0,               |F_i| <= mu N_i,
    slip:   F_i = mu N_i g_i/|g_i|.

Solution: primal-dual active set, i.e. the semismooth Newton method for the nonlinear complementarity form
F_i = P_{mu N_i}(F_i + c w_i g_i) with P the projection on the disk of radius mu N_i (Hueber, Stadler &
Wohlmuth, SIAM J. Sci. Comput. 30 (2008) 572-596): stick nodes have their tangential displacement prescribed
(rows and columns eliminated), slip nodes carry the nodal force mu N_i e_i; the next stick set is
{|F_i + c w_i g_i| <= mu N_i} and the next slip directions are e_i = (F_i + c w_i g_i)/|...|. It stops when the
set repeats and no slip direction turns by more than ``direction_tolerance`` (1e-4 rad). Load control on the
total tangential force Q: the solution is affine in delta for a fixed set and fixed directions (two solves, one
factorisation).

Quarter model: a shift along x is symmetric about y = 0 (u_y = 0 there, as for the normal problem) and
antisymmetric about x = 0 (u_y = u_z = 0 on that plane); other directions need the full block.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np


@dataclass(eq=False)
class ShiftSolution:
    """Raw FE solution of the shift problem (the same on every rank).

    Attributes:
        success, status, message: convergence report ("ok", "not-converged", "gross-slip": Q >= mu P).
        iterations: active-set iterations.
        tangential_force_N: (Q_x, Q_y), total tangential force on the block (whole patch), N.
        shift_m: (delta_x, delta_y), the indenter's rigid tangential displacement relative to the clamped base, m.
        node_xy_m: (n, 2) contact-face node coordinates (modelled part), m.
        node_normal_force_N: (n,) N_i of the normal solve, N.
        node_tangential_force_N: (n, 2) F_i, N.
        node_weight_m2: (n,) lumped weights w_i, m^2.
        node_slip_m: (n, 2) g_i (zero at stick nodes), m.
        stick: (n,) bool, nodes in contact that stick.
        in_contact: (n,) bool, nodes with N_i > 0.
        dofs: global number of displacement unknowns.
        wall_time_s: time of the solve, s.
        timings: breakdown, s.
    """

    success: bool
    status: str
    message: str
    iterations: int
    tangential_force_N: tuple
    shift_m: tuple
    node_xy_m: np.ndarray
    node_normal_force_N: np.ndarray
    node_tangential_force_N: np.ndarray
    node_weight_m2: np.ndarray
    node_slip_m: np.ndarray
    stick: np.ndarray
    in_contact: np.ndarray
    dofs: int
    wall_time_s: float = 0.0
    timings: dict = field(default_factory=dict)

    def stick_area_m2(self, symmetry_factor: float) -> float:
        """Area of the stick zone (sum of the lumped weights of the stick nodes) on the whole patch, m^2."""
        return float(symmetry_factor * self.node_weight_m2[self.stick].sum())


def solve_shift(
    domain,
    normal,
    young_modulus_Pa: float,
    poisson_ratio: float,
    friction_coefficient: float,
    *,
    tangential_force_N: float,
    direction: tuple[float, float] = (1.0, 0.0),
    length_scale_m: float = 1e-3,
    max_iterations: int = 100,
    direction_tolerance: float = 1e-4,
) -> ShiftSolution:
    """Solve the Cattaneo-Mindlin shift of the rigid indenter over ``domain`` under the total force Q.

    Args:
        domain: :class:`fea.domain.Domain` of the normal solve ``normal`` (the same mesh and P1 space).
        normal: converged :class:`fea.solver.ContactSolution` (degree 1) on ``domain``.
        young_modulus_Pa, poisson_ratio: the block's constants (as given to the normal solve).
        friction_coefficient: mu (> 0).
        tangential_force_N: Q, the total tangential force on the block along ``direction`` (>= 0), N.
        direction: unit direction of the shift in the contact plane; the quarter model takes (1, 0) only.
        length_scale_m: patch size, scales the active-set constant c = E/length.
        max_iterations: largest number of active-set iterations.
        direction_tolerance: the iteration stops when the stick set repeats and no slip direction turns by more
            than this (radians; the nodal friction force is then within this fraction of mu N_i of Coulomb's law;
            the directions converge linearly, not quadratically, near the stick-slip boundary).

    Returns:
        :class:`ShiftSolution`; Q >= mu P gives status "gross-slip" (no static solution), non-convergence
        "not-converged", never an exception for a numerical failure.
    """
    import dolfinx_solver  # noqa: F401
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc
    from petsc4py import PETSc

    if not (math.isfinite(friction_coefficient) and friction_coefficient > 0):
        raise ValueError(f"friction_coefficient = {friction_coefficient!r}: expected a finite number > 0")
    if not (math.isfinite(tangential_force_N) and tangential_force_N >= 0):
        raise ValueError(f"tangential_force_N = {tangential_force_N!r}: expected a finite number >= 0")
    d = np.asarray(direction, dtype=float)
    if d.shape != (2,) or not np.all(np.isfinite(d)) or abs(np.hypot(*d) - 1.0) > 1e-9:
        raise ValueError(f"direction = {direction!r}: expected a unit vector (dx, dy)")
    if domain.symmetry == "quarter" and not (d[0] == 1.0 and d[1] == 0.0):
        raise ValueError(f"direction = {direction!r}: the quarter model takes a shift along x, (1, 0), only")
    if not normal.success:
        raise ValueError(f"normal solution status {normal.status!r}: expected a converged normal solve")

    t_start = time.perf_counter()
    timings = {}
    msh = domain.mesh
    comm = msh.comm
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    V = fem.functionspace(msh, ("Lagrange", 1, (3,)))
    bs = 3
    imap = V.dofmap.index_map
    n_owned = imap.size_local * bs
    global_offset = imap.local_range[0] * bs
    dofs_global = imap.size_global * bs
    tags, groups = domain.facet_tags, domain.groups

    bcs = []
    base = fem.locate_dofs_topological(V, tdim - 1, tags.find(groups["base"]))
    bcs.append(fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), base, V))
    # shift along x: u_y = 0 on y = 0 (symmetric), u_y = u_z = 0 on x = 0 (antisymmetric)
    for name, comps in (("symmetry_x", (1, 2)), ("symmetry_y", (1,))):
        if name in groups:
            for comp in comps:
                dofs = fem.locate_dofs_topological(V.sub(comp), tdim - 1, tags.find(groups[name]))
                bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(comp)))
    bc_dofs = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs])).astype(np.int32)
    bc_dofs = bc_dofs[bc_dofs < n_owned]

    mu_l = young_modulus_Pa / (2.0 * (1.0 + poisson_ratio))
    lam = young_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    a_form = fem.form(ufl.inner(lam * ufl.tr(eps(u)) * ufl.Identity(3) + 2.0 * mu_l * eps(u), eps(v)) * ufl.dx)
    K = fem_petsc.assemble_matrix(a_form, bcs=bcs)
    K.assemble()
    timings["assembly_s"] = time.perf_counter() - t_start

    cdofs = fem.locate_dofs_topological(V.sub(2), tdim - 1, tags.find(groups["contact"]))
    cdofs = np.sort(cdofs[cdofs < n_owned]).astype(np.int32)
    xy = V.tabulate_dof_coordinates()[cdofs // bs][:, :2].copy()
    n_local = len(cdofs)
    start = comm.exscan(n_local) or 0
    normal_xy = np.asarray(normal.node_xy_m)[start : start + n_local]
    if normal_xy.shape != xy.shape or not np.allclose(normal_xy, xy, rtol=0, atol=1e-12 * length_scale_m + 1e-15):
        raise ValueError("the normal solution's contact nodes differ from this domain's (same mesh and degree 1)")
    n_force = np.asarray(normal.node_force_N)[start : start + n_local].astype(float)
    weights = np.asarray(normal.node_weight_m2)[start : start + n_local].astype(float)
    in_contact = n_force > 0.0
    limit = friction_coefficient * n_force
    xdofs, ydofs = cdofs - 2, cdofs - 1
    sym = domain.symmetry_factor
    total_normal = sym * comm.allreduce(float(n_force.sum()))
    if tangential_force_N >= friction_coefficient * total_normal:
        g_xy, g_n, g_w = (_gather(comm, a) for a in (xy, n_force, weights))
        n_all = len(g_n)
        return ShiftSolution(
            success=False,
            status="gross-slip",
            message=f"Q = {tangential_force_N:.6g} N >= mu P = {friction_coefficient * total_normal:.6g} N: "
            "the whole patch slides (no static solution)",
            iterations=0,
            tangential_force_N=(math.nan, math.nan),
            shift_m=(math.nan, math.nan),
            node_xy_m=g_xy.reshape(-1, 2),
            node_normal_force_N=g_n,
            node_tangential_force_N=np.zeros((n_all, 2)),
            node_weight_m2=g_w,
            node_slip_m=np.zeros((n_all, 2)),
            stick=np.zeros(n_all, bool),
            in_contact=g_n > 0,
            dofs=dofs_global,
            wall_time_s=time.perf_counter() - t_start,
        )

    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    K_A = K.duplicate(copy=True)
    f_vec, prescribed, b, reaction = K.createVecLeft(), K.createVecLeft(), K.createVecLeft(), K.createVecLeft()
    c_const = 4.0 * young_modulus_Pa / length_scale_m
    stick = in_contact.copy()
    e_dir = np.tile(d, (n_local, 1))
    tangent = np.zeros(n_local)  # k_i of the slip nodes' tangent
    gap = np.zeros((n_local, 2))
    is_bc = np.zeros(n_owned, bool)
    is_bc[bc_dofs] = True
    status, message, success = "not-converged", "", False
    it = 0
    delta = 0.0
    u_t = np.zeros((n_local, 2))
    force = np.zeros((n_local, 2))
    for it in range(1, max_iterations + 1):
        slip = in_contact & ~stick
        # semismooth Newton tangent of the slip nodes: F_i = mu N_i e_i + k_i P_i (g_i - g_i^k), P_i = I - e_i e_i^T
        proj = np.eye(2)[None, :, :] - e_dir[:, :, None] * e_dir[:, None, :]
        K.copy(K_A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        for i in np.flatnonzero(slip):
            local = np.array([xdofs[i], ydofs[i]])
            block = tangent[i] * proj[i] * np.outer(~is_bc[local], ~is_bc[local])
            rows_g = (local + global_offset).astype(PETSc.IntType)
            K_A.setValues(rows_g, rows_g, block.ravel(), addv=PETSc.InsertMode.ADD_VALUES)
        K_A.assemble()
        rows = np.concatenate([xdofs[stick], ydofs[stick]])
        K_A.zeroRowsColumns((rows + global_offset).astype(PETSc.IntType), diag=1.0)
        ksp.setOperators(K_A)
        kp_gap = tangent[:, None] * np.einsum("nij,nj->ni", proj, gap)
        kp_dir = tangent[:, None] * np.einsum("nij,j->ni", proj, d)

        def solve(values_x, values_y, nodal_load, stick=stick, slip=slip):
            prescribed.set(0.0)
            prescribed.array[xdofs[stick]] = values_x
            prescribed.array[ydofs[stick]] = values_y
            K.mult(prescribed, b)
            b.scale(-1.0)
            f_vec.set(0.0)
            f_vec.array[xdofs[slip]] = nodal_load[slip, 0]
            f_vec.array[ydofs[slip]] = nodal_load[slip, 1]
            f_vec.array[bc_dofs] = 0.0
            b.axpy(1.0, f_vec)
            b.array[xdofs[stick]] = values_x
            b.array[ydofs[stick]] = values_y
            out = K.createVecRight()
            ksp.solve(b, out)
            return out, ksp.getConvergedReason()

        n_stick = int(stick.sum())
        x_a, r1 = solve(np.zeros(n_stick), np.zeros(n_stick), limit[:, None] * e_dir - kp_gap)
        x_1, r2 = solve(np.full(n_stick, d[0]), np.full(n_stick, d[1]), kp_dir)
        if min(r1, r2) < 0:
            message = f"linear solver failed (PETSc reason {min(r1, r2)})"
            break

        def nodal_forces(vec):
            K.mult(vec, reaction)  # = the contact force at stick and slip nodes (no other load there)
            r = reaction.array
            return np.column_stack([r[xdofs], r[ydofs]]) * in_contact[:, None]

        f_a, f_1 = nodal_forces(x_a), nodal_forces(x_1)
        s_a = comm.allreduce(float((f_a @ d).sum()))
        s_1 = comm.allreduce(float((f_1 @ d).sum()))
        if not s_1 > 0:
            message = "no stick node carries the shift (tangential stiffness not positive)"
            break
        delta = (tangential_force_N / sym - s_a) / s_1
        x_a.axpy(delta, x_1)
        arr = x_a.array
        u_t = np.column_stack([arr[xdofs], arr[ydofs]])
        force = f_a + delta * f_1
        gap = np.where(stick[:, None], 0.0, delta * d[None, :] - u_t) * in_contact[:, None]
        trial = force + c_const * weights[:, None] * gap
        norm = np.hypot(trial[:, 0], trial[:, 1])
        new_stick = in_contact & (norm <= limit)
        new_dir = e_dir.copy()
        moving = in_contact & ~new_stick & (norm > 0)
        new_dir[moving] = trial[moving] / norm[moving, None]
        alpha = np.where(moving, limit / np.where(moving, norm, 1.0), 0.0)
        tangent = np.minimum(alpha / np.maximum(1.0 - alpha, 1e-3), 1e3) * c_const * weights
        changed = comm.allreduce(int(np.count_nonzero(new_stick != stick)))
        turned = comm.allreduce(float(np.max(np.abs(new_dir - e_dir)[moving], initial=0.0)), op=_mpi_max())
        stick, e_dir = new_stick, new_dir
        x_a.destroy()
        x_1.destroy()
        if changed == 0 and turned < direction_tolerance:
            success, status, message = True, "ok", f"stick set and slip directions converged in {it} iterations"
            break
    else:
        message = f"stick set did not settle in {max_iterations} iterations"
    ksp.destroy()
    K_A.destroy()
    K.destroy()
    total = (sym * comm.allreduce(float(force[:, 0].sum())), sym * comm.allreduce(float(force[:, 1].sum())))
    if domain.symmetry == "quarter":
        total = (total[0], 0.0)  # the y forces cancel between the mirrored quarters
    slip_vec = gap
    g_xy, g_n, g_w, g_f, g_s, g_st, g_c = (
        _gather(comm, a) for a in (xy, n_force, weights, force, slip_vec, stick, in_contact)
    )
    return ShiftSolution(
        success=success,
        status=status,
        message=message,
        iterations=it,
        tangential_force_N=total,
        shift_m=(float(delta * d[0]), float(delta * d[1])),
        node_xy_m=g_xy.reshape(-1, 2),
        node_normal_force_N=g_n,
        node_tangential_force_N=g_f.reshape(-1, 2),
        node_weight_m2=g_w,
        node_slip_m=g_s.reshape(-1, 2),
        stick=g_st.astype(bool),
        in_contact=g_c.astype(bool),
        dofs=dofs_global,
        wall_time_s=time.perf_counter() - t_start,
        timings={**timings, "iterations_s": time.perf_counter() - t_start - timings["assembly_s"]},
    )


def _gather(comm, arr):
    return np.concatenate(comm.allgather(np.asarray(arr)))


def _mpi_max():
    from mpi4py import MPI

    return MPI.MAX


def cattaneo_mindlin(
    tangential_force_N: float,
    normal_force_N: float,
    friction_coefficient: float,
    contact_radius_m: float,
    shear_modulus_Pa: float,
    poisson_ratio: float,
) -> dict[str, float]:
    """Closed form of the shift of a rigid sphere on an elastic half-space (Johnson 1985, eqs 7.33, 7.42).

    Monotone loading 0 <= Q < mu P of a circular Hertz contact of radius a; the body's tangential compliance is
    (2 - nu)/G (a rigid indenter; for two bodies use the sum of (2 - nu_k)/G_k, i.e. the equivalent block).

    Returns:
        {"stick_radius_ratio": c/a = (1 - Q/(mu P))^(1/3),
         "shift_m": delta = 3 mu P (2 - nu)/(16 G a) [1 - (1 - Q/(mu P))^(2/3)],
         "full_stick_compliance_m_per_N": (2 - nu)/(8 G a), the slope at Q = 0}.
    """
    ratio = tangential_force_N / (friction_coefficient * normal_force_N)
    if not (0.0 <= ratio < 1.0):
        raise ValueError(f"Q/(mu P) = {ratio!r}: expected a number in [0, 1)")
    compliance = (2.0 - poisson_ratio) / shear_modulus_Pa
    return {
        "stick_radius_ratio": (1.0 - ratio) ** (1.0 / 3.0),
        "shift_m": 3.0
        * friction_coefficient
        * normal_force_N
        * compliance
        / (16.0 * contact_radius_m)
        * (1.0 - (1.0 - ratio) ** (2.0 / 3.0)),
        "full_stick_compliance_m_per_N": compliance / (8.0 * contact_radius_m),
    }
