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


class _TangentialSystem:
    """The block's stiffness, its constraints and the contact nodes of one normal solution (P1, any rank count).

    ``iterate`` solves one frictional step: stick nodes get their tangential displacement prescribed
    (``target + delta * unit``), slip nodes the force mu N_i e_i along target - u (the semismooth Newton
    iteration of the module docstring); ``delta`` follows from the load when one is given (load control).
    """

    def __init__(self, domain, normal, young_modulus_Pa, poisson_ratio, friction_coefficient, length_scale_m, comps):
        import dolfinx_solver  # noqa: F401
        import ufl
        from dolfinx import fem
        from dolfinx.fem import petsc as fem_petsc
        from petsc4py import PETSc

        self.PETSc = PETSc
        t0 = time.perf_counter()
        msh = domain.mesh
        comm = self.comm = msh.comm
        tdim = msh.topology.dim
        msh.topology.create_connectivity(tdim - 1, tdim)
        V = fem.functionspace(msh, ("Lagrange", 1, (3,)))
        bs = 3
        imap = V.dofmap.index_map
        n_owned = imap.size_local * bs
        self.global_offset = imap.local_range[0] * bs
        self.dofs_global = imap.size_global * bs
        tags, groups = domain.facet_tags, domain.groups
        base = fem.locate_dofs_topological(V, tdim - 1, tags.find(groups["base"]))
        bcs = [fem.dirichletbc(np.zeros(3, PETSc.ScalarType), base, V)]
        for name, constrained in comps.items():
            if name in groups:
                for comp in constrained:
                    dofs = fem.locate_dofs_topological(V.sub(comp), tdim - 1, tags.find(groups[name]))
                    bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(comp)))
        bc_dofs = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs])).astype(np.int32)
        self.bc_dofs = bc_dofs[bc_dofs < n_owned]
        self.is_bc = np.zeros(n_owned, bool)
        self.is_bc[self.bc_dofs] = True
        mu_l = young_modulus_Pa / (2.0 * (1.0 + poisson_ratio))
        lam = young_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

        def eps(w):
            return ufl.sym(ufl.grad(w))

        a_form = fem.form(ufl.inner(lam * ufl.tr(eps(u)) * ufl.Identity(3) + 2.0 * mu_l * eps(u), eps(v)) * ufl.dx)
        self.K = fem_petsc.assemble_matrix(a_form, bcs=bcs)
        self.K.assemble()
        cdofs = fem.locate_dofs_topological(V.sub(2), tdim - 1, tags.find(groups["contact"]))
        cdofs = np.sort(cdofs[cdofs < n_owned]).astype(np.int32)
        self.xy = V.tabulate_dof_coordinates()[cdofs // bs][:, :2].copy()
        n_local = len(cdofs)
        start = comm.exscan(n_local) or 0
        normal_xy = np.asarray(normal.node_xy_m)[start : start + n_local]
        if normal_xy.shape != self.xy.shape or not np.allclose(normal_xy, self.xy, rtol=0, atol=1e-9 * length_scale_m):
            raise ValueError("the normal solution's contact nodes differ from this domain's (same mesh and degree 1)")
        self.n_force = np.asarray(normal.node_force_N)[start : start + n_local].astype(float)
        self.weights = np.asarray(normal.node_weight_m2)[start : start + n_local].astype(float)
        self.in_contact = self.n_force > 0.0
        self.limit = friction_coefficient * self.n_force
        self.xdofs, self.ydofs = cdofs - 2, cdofs - 1
        self.sym = domain.symmetry_factor
        self.total_normal_N = self.sym * comm.allreduce(float(self.n_force.sum()))
        self.c_const = 4.0 * young_modulus_Pa / length_scale_m
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setType("preonly")
        self.ksp.getPC().setType("lu")
        self.ksp.getPC().setFactorSolverType("mumps")
        self.K_A = self.K.duplicate(copy=True)
        K = self.K
        self.f_vec, self.prescribed, self.b, self.reaction = (K.createVecLeft() for _ in range(4))
        self.assembly_s = time.perf_counter() - t0

    def destroy(self):
        for obj in (self.ksp, self.K_A, self.K, self.f_vec, self.prescribed, self.b, self.reaction):
            obj.destroy()

    def gather(self, arr):
        return _gather(self.comm, arr)

    def _solve(self, values, nodal_load, stick, slip):
        xd, yd, b = self.xdofs, self.ydofs, self.b
        self.prescribed.set(0.0)
        self.prescribed.array[xd[stick]] = values[stick, 0]
        self.prescribed.array[yd[stick]] = values[stick, 1]
        self.K.mult(self.prescribed, b)
        b.scale(-1.0)
        self.f_vec.set(0.0)
        self.f_vec.array[xd[slip]] = nodal_load[slip, 0]
        self.f_vec.array[yd[slip]] = nodal_load[slip, 1]
        self.f_vec.array[self.bc_dofs] = 0.0
        b.axpy(1.0, self.f_vec)
        b.array[xd[stick]] = values[stick, 0]
        b.array[yd[stick]] = values[stick, 1]
        out = self.K.createVecRight()
        self.ksp.solve(b, out)
        return out, self.ksp.getConvergedReason()

    def _forces(self, vec):
        self.K.mult(vec, self.reaction)  # = the contact force at stick and slip nodes (no other load there)
        r = self.reaction.array
        return np.column_stack([r[self.xdofs], r[self.ydofs]]) * self.in_contact[:, None]

    def iterate(self, target, unit=None, load=None, stick=None, e_dir=None, max_iterations=100, tolerance=1e-4):
        """One frictional step. target, unit: (n, 2) stick displacements (affine part, per unit delta), m;
        load: (direction d, force along d on the modelled part) for load control, else delta = 0.

        Returns dict: success, message, iterations, delta, force (n, 2) on the block, slip (n, 2), stick, e_dir,
        u_t (n, 2) tangential surface displacement of the block.
        """
        PETSc, comm = self.PETSc, self.comm
        n = len(self.xy)
        in_contact, limit, weights = self.in_contact, self.limit, self.weights
        stick = in_contact.copy() if stick is None else stick & in_contact
        if e_dir is None:
            e_dir = np.tile(np.array([1.0, 0.0]), (n, 1))
        unit = np.zeros((n, 2)) if unit is None else unit
        tangent = np.zeros(n)
        gap = np.zeros((n, 2))
        delta, u_t, force = 0.0, np.zeros((n, 2)), np.zeros((n, 2))
        success, message, it = False, f"stick set did not settle in {max_iterations} iterations", 0
        for it in range(1, max_iterations + 1):
            slip = in_contact & ~stick
            # semismooth Newton tangent of the slip nodes: F_i = mu N_i e_i + k_i P_i (g_i - g_i^k), P = I - e e^T
            proj = np.eye(2)[None, :, :] - e_dir[:, :, None] * e_dir[:, None, :]
            self.K.copy(self.K_A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            for i in np.flatnonzero(slip):
                local = np.array([self.xdofs[i], self.ydofs[i]])
                free = ~self.is_bc[local]
                rows_g = (local + self.global_offset).astype(PETSc.IntType)
                block = tangent[i] * proj[i] * np.outer(free, free)
                self.K_A.setValues(rows_g, rows_g, block.ravel(), addv=PETSc.InsertMode.ADD_VALUES)
            self.K_A.assemble()
            rows = np.concatenate([self.xdofs[stick], self.ydofs[stick]]) + self.global_offset
            self.K_A.zeroRowsColumns(rows.astype(PETSc.IntType), diag=1.0)
            self.ksp.setOperators(self.K_A)
            kp_gap = tangent[:, None] * np.einsum("nij,nj->ni", proj, gap)
            kp_target = tangent[:, None] * np.einsum("nij,nj->ni", proj, target)
            x_a, r1 = self._solve(target, limit[:, None] * e_dir - kp_gap + kp_target, stick, slip)
            f_a = self._forces(x_a)
            if load is not None:
                d, q = load
                x_1, r2 = self._solve(unit, tangent[:, None] * np.einsum("nij,nj->ni", proj, unit), stick, slip)
                if min(r1, r2) < 0:
                    message = f"linear solver failed (PETSc reason {min(r1, r2)})"
                    break
                f_1 = self._forces(x_1)
                s_a = comm.allreduce(float((f_a @ d).sum()))
                s_1 = comm.allreduce(float((f_1 @ d).sum()))
                if not s_1 > 0:
                    message = "no stick node carries the shift (tangential stiffness not positive)"
                    break
                delta = (q - s_a) / s_1
                x_a.axpy(delta, x_1)
                f_a = f_a + delta * f_1
                x_1.destroy()
            elif r1 < 0:
                message = f"linear solver failed (PETSc reason {r1})"
                break
            arr = x_a.array
            u_t = np.column_stack([arr[self.xdofs], arr[self.ydofs]])
            x_a.destroy()
            force = f_a
            gap = np.where(stick[:, None], 0.0, target + delta * unit - u_t) * in_contact[:, None]
            trial = force + self.c_const * weights[:, None] * gap
            norm = np.hypot(trial[:, 0], trial[:, 1])
            new_stick = in_contact & (norm <= limit)
            new_dir = e_dir.copy()
            moving = in_contact & ~new_stick & (norm > 0)
            new_dir[moving] = trial[moving] / norm[moving, None]
            alpha = np.where(moving, limit / np.where(moving, norm, 1.0), 0.0)
            tangent = np.minimum(alpha / np.maximum(1.0 - alpha, 1e-3), 1e3) * self.c_const * weights
            changed = comm.allreduce(int(np.count_nonzero(new_stick != stick)))
            turned = comm.allreduce(float(np.max(np.abs(new_dir - e_dir)[moving], initial=0.0)), op=_mpi_max())
            stick, e_dir = new_stick, new_dir
            if changed == 0 and turned < tolerance:
                success, message = True, f"stick set and slip directions converged in {it} iterations"
                break
        return {
            "success": success,
            "message": message,
            "iterations": it,
            "delta": delta,
            "force": force,
            "slip": gap,
            "stick": stick,
            "e_dir": e_dir,
            "u_t": u_t,
        }


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
        length_scale_m: patch size, scales the active-set constant c = 4 E/length.
        max_iterations: largest number of active-set iterations.
        direction_tolerance: the iteration stops when the stick set repeats and no slip direction turns by more
            than this (radians; the nodal friction force is then within this fraction of mu N_i of Coulomb's law;
            the directions converge linearly, not quadratically, near the stick-slip boundary).

    Returns:
        :class:`ShiftSolution`; Q >= mu P gives status "gross-slip" (no static solution), non-convergence
        "not-converged", never an exception for a numerical failure.
    """
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
    # shift along x: u_y = 0 on y = 0 (symmetric), u_y = u_z = 0 on x = 0 (antisymmetric)
    system = _TangentialSystem(
        domain, normal, young_modulus_Pa, poisson_ratio, friction_coefficient, length_scale_m,
        {"symmetry_x": (1, 2), "symmetry_y": (1,)},
    )  # fmt: skip
    n = len(system.xy)
    common = {
        "node_xy_m": system.gather(system.xy).reshape(-1, 2),
        "node_normal_force_N": system.gather(system.n_force),
        "node_weight_m2": system.gather(system.weights),
        "in_contact": system.gather(system.in_contact).astype(bool),
        "dofs": system.dofs_global,
    }
    if tangential_force_N >= friction_coefficient * system.total_normal_N:
        system.destroy()
        n_all = len(common["node_weight_m2"])
        return ShiftSolution(
            success=False,
            status="gross-slip",
            message=f"Q = {tangential_force_N:.6g} N >= mu P = {friction_coefficient * system.total_normal_N:.6g} "
            "N: the whole patch slides (no static solution)",
            iterations=0,
            tangential_force_N=(math.nan, math.nan),
            shift_m=(math.nan, math.nan),
            node_tangential_force_N=np.zeros((n_all, 2)),
            node_slip_m=np.zeros((n_all, 2)),
            stick=np.zeros(n_all, bool),
            wall_time_s=time.perf_counter() - t_start,
            **common,
        )
    out = system.iterate(
        np.zeros((n, 2)),
        unit=np.tile(d, (n, 1)),
        load=(d, tangential_force_N / system.sym),
        e_dir=np.tile(d, (n, 1)),
        max_iterations=max_iterations,
        tolerance=direction_tolerance,
    )
    comm, sym, force = system.comm, system.sym, out["force"]
    total = (sym * comm.allreduce(float(force[:, 0].sum())), sym * comm.allreduce(float(force[:, 1].sum())))
    if domain.symmetry == "quarter":
        total = (total[0], 0.0)  # the y forces cancel between the mirrored quarters
    assembly_s = system.assembly_s
    system.destroy()
    delta = out["delta"]
    return ShiftSolution(
        success=out["success"],
        status="ok" if out["success"] else "not-converged",
        message=out["message"],
        iterations=out["iterations"],
        tangential_force_N=total,
        shift_m=(float(delta * d[0]), float(delta * d[1])),
        node_tangential_force_N=_gather(comm, force).reshape(-1, 2),
        node_slip_m=_gather(comm, out["slip"]).reshape(-1, 2),
        stick=_gather(comm, out["stick"]).astype(bool),
        wall_time_s=time.perf_counter() - t_start,
        timings={"assembly_s": assembly_s, "iterations_s": time.perf_counter() - t_start - assembly_s},
        **common,
    )


@dataclass(eq=False)
class RollingSolution:
    """Steady rolling with creepage (the same on every rank).

    Attributes:
        success, status, message: "ok" or "not-converged" (the active set did not settle).
        iterations: active-set iterations.
        creep_force_N: (F_x, F_y) on the WHEEL (the indenter), contact frame, N (per slab thickness in plane strain).
        spin_moment_Nm: moment about the normal on the wheel, N m.
        node_xy_m, node_normal_force_N, node_weight_m2: the contact-face nodes of the normal solution (the
            contact's nodes only, in_contact all True).
        node_traction_Pa: (n, 2) tangential traction on the wheel, -F_i / w_i, Pa.
        node_slip_m: (n, 2) slip of the wheel over the rail per ``step_m`` rolled, m (zero where it sticks).
        stick, in_contact: (n,) bool.
        dofs: global number of displacement unknowns.
        wall_time_s: s.
    """

    success: bool
    status: str
    message: str
    iterations: int
    creep_force_N: tuple
    spin_moment_Nm: float
    node_xy_m: np.ndarray
    node_normal_force_N: np.ndarray
    node_weight_m2: np.ndarray
    node_traction_Pa: np.ndarray
    node_slip_m: np.ndarray
    stick: np.ndarray
    in_contact: np.ndarray
    dofs: int
    wall_time_s: float = 0.0


def solve_rolling(
    domain,
    normal,
    young_modulus_Pa: float,
    poisson_ratio: float,
    friction_coefficient: float,
    creepage: tuple[float, float, float],
    *,
    step_m: float,
    length_scale_m: float = 1e-3,
    max_iterations: int = 300,
    direction_tolerance: float = 1e-6,
    row_transport: bool | None = None,
) -> RollingSolution:
    """Steady rolling of the rigid indenter (the wheel) over ``domain`` with creepages, solved as a steady state.

    Steady-state (Eulerian) form of Kalker's rolling (Kalker 1990, ch. 5; CONTACT's steady rolling): the patch
    stands, the material passes through it in -x; over a rolled distance ``step_m`` = dq the slip of the wheel over
    the rail is s = w dq - (u_b(x) - u_b(x + dq)), w = (xi - phi y, eta + phi x) the rigid creepage and u_b the
    block's surface displacement (= minus the pair's combined one), u_b(x + dq) interpolated linearly between the
    face nodes (for dq below the element size this is the upwind difference quotient dq du_b/dx of the element
    ahead). Stick: s = 0, |F_i| <= mu N_i; slip: F_i = mu N_i s/|s| (F_i the nodal force on the block).

    The block's face enters through its tangential compliance: u_b = C F, C computed column by column from the
    factorised stiffness (one solve per tangential unknown of a contact node, the normal displacements free, as in
    :func:`solve_shift`), on the contact nodes and the face nodes the transport reaches. The frictional problem is
    then a small dense one, A F = w dq on the stick nodes with A = C_contact - Pi C_near (Pi the interpolation at
    x + dq), F = mu N e on the slip nodes, solved by an active-set iteration with the slip directions updated by
    e = (F + c s)/|F + c s| (c = 1/diag A).

    Why not the transient (a sequence of shifts from rest until the force settles): the earlier version did that,
    and its approach to the steady state is slow and not geometric (the rigid part of the entering material's
    displacement follows the total force through the block's global compliance; on the plane-strain slab at 8
    elements per semi-axis the force still moved by 1e-3 mu P per step after 150 steps, i.e. 19 a rolled), so
    Aitken's stop was premature and a fine step unaffordable. The steady state has no such error.

    Args:
        domain: full block or plane-strain slab (:func:`fea.domain.plane_strain_slab_domain`: ``symmetry_y`` held).
        normal: converged frictionless normal solution on ``domain`` (P1), held fixed (equal materials).
        creepage: (xi, eta, phi): longitudinal, lateral creepage and spin (1/m) of the wheel over the rail.
        step_m: dq, m (below the element size at the patch, e.g. h/2; the result does not depend on it much).
        max_iterations: largest number of active-set iterations.
        direction_tolerance: stop when the stick set repeats and no slip direction turns by more than this.
        row_transport: interpolate u_b(x + dq) along the node's own row (the face nodes of the same y) instead of on
            a Delaunay triangulation of the face nodes; every contact node's row must hold nodes on both sides of
            x + dq (else ValueError). None: rows on the plane-strain slab, Delaunay otherwise. The rolling block
            (:func:`fea.domain.rolling_block_domain`) needs rows: its edge-fitted rows are shifted against each other,
            so a Delaunay triangle may mix neighbouring rows and break the mesh's symmetry about y = 0.

    Returns:
        :class:`RollingSolution`; numerical failure is a status. Serial only (one MPI rank).
    """
    from scipy.spatial import Delaunay

    if domain.symmetry != "full":
        raise ValueError(f"domain symmetry {domain.symmetry!r}: rolling with creepage needs the full block")
    if not (math.isfinite(friction_coefficient) and friction_coefficient > 0):
        raise ValueError(f"friction_coefficient = {friction_coefficient!r}: expected a finite number > 0")
    xi, eta, phi = (float(c) for c in creepage)
    if not all(math.isfinite(c) for c in (xi, eta, phi)):
        raise ValueError(f"creepage = {creepage!r}: expected three finite numbers")
    if not (math.isfinite(step_m) and step_m > 0):
        raise ValueError(f"step_m = {step_m!r}: expected a finite number > 0")
    if not normal.success:
        raise ValueError(f"normal solution status {normal.status!r}: expected a converged normal solve")
    t_start = time.perf_counter()
    plane_strain = "symmetry_y" in domain.groups  # the plane-strain slab (meshing.slab): u_y = 0 on every node
    rows = plane_strain if row_transport is None else bool(row_transport)
    system = _TangentialSystem(
        domain, normal, young_modulus_Pa, poisson_ratio, friction_coefficient, length_scale_m,
        {"symmetry_y": (1,)} if plane_strain else {},
    )  # fmt: skip
    if system.comm.size != 1:
        system.destroy()
        raise ValueError(f"solve_rolling runs on one MPI rank, got {system.comm.size}")
    xy_all, contact = system.xy, system.in_contact
    cidx = np.flatnonzero(contact)
    reach = np.max(np.abs(xy_all[contact]), axis=0) + 3.0 * step_m + 1e-12
    near = np.flatnonzero(np.all(np.abs(xy_all) <= reach * np.array([1.0, 1.0]) + 2.0 * step_m, axis=1))
    # transport: u at x_i + dq of the contact nodes, as weights on the near nodes
    moved = xy_all[cidx] + np.array([step_m, 0.0])
    transport = np.zeros((len(cidx), len(near)))
    if rows:
        scale = max(float(np.ptp(xy_all[:, 0])), 1e-300)
        line_of = np.round(xy_all[:, 1] / scale, 9)
        for r, i in enumerate(cidx):
            on = near[line_of[near] == line_of[i]]
            xs = xy_all[on, 0]
            order = np.argsort(xs)
            k = np.searchsorted(xs[order], moved[r, 0])
            if 0 < k < len(on):
                j0, j1 = on[order[k - 1]], on[order[k]]
                t = (moved[r, 0] - xy_all[j0, 0]) / (xy_all[j1, 0] - xy_all[j0, 0])
                transport[r, np.searchsorted(near, j0)] += 1.0 - t
                transport[r, np.searchsorted(near, j1)] += t
            elif not plane_strain:
                system.destroy()
                raise ValueError(f"row_transport: the face row of the contact node {xy_all[i]!r} ends before x + dq")
    else:
        tri = Delaunay(xy_all[near])
        simplex = tri.find_simplex(moved)
        for r, sx in enumerate(simplex):
            if sx < 0:
                continue  # beyond the near face: u = 0 there (far from the patch)
            tr = tri.transform[sx]
            bary = tr[:2] @ (moved[r] - tr[2])
            lam = np.append(bary, 1.0 - bary.sum())
            transport[r, tri.simplices[sx]] += lam
    # compliance of the face: unit tangential forces at the contact nodes -> tangential displacements near
    free_comp = [k for k in (0, 1) if not (plane_strain and k == 1)]
    ncomp = len(free_comp)
    dof_of = (system.xdofs, system.ydofs)
    comp_near = np.zeros((len(near) * ncomp, len(cidx) * ncomp))
    # columns in blocks through the factor's multiple-right-hand-side solve (MUMPS), the same numbers as one solve
    # per column and several times faster on the rolling block's 10^5 unknowns
    ksp = system.ksp
    ksp.setOperators(system.K)
    ksp.setUp()
    factor = ksp.getPC().getFactorMatrix()
    n_rows = system.K.getLocalSize()[0]
    columns = [(c, kk, dof_of[k][i]) for c, i in enumerate(cidx) for kk, k in enumerate(free_comp)]
    near_rows = [dof_of[m][near] for m in free_comp]
    block = 64
    for start in range(0, len(columns), block):
        chunk = columns[start : start + block]
        rhs = np.zeros((n_rows, len(chunk)))
        for col, (_, _, dof) in enumerate(chunk):
            rhs[dof, col] = 1.0
        b_mat = system.PETSc.Mat().createDense((n_rows, len(chunk)), array=rhs, comm=system.comm)
        x_mat = system.PETSc.Mat().createDense((n_rows, len(chunk)), comm=system.comm)
        x_mat.setUp()
        try:
            factor.matSolve(b_mat, x_mat)
        except system.PETSc.Error as exc:
            b_mat.destroy()
            x_mat.destroy()
            system.destroy()
            return _rolling_failure(f"linear solver failed ({exc})", t_start)
        sol = x_mat.getDenseArray(readonly=True)
        if not np.all(np.isfinite(sol)):
            b_mat.destroy()
            x_mat.destroy()
            system.destroy()
            return _rolling_failure("linear solver failed (non-finite compliance)", t_start)
        for col, (c, kk, _) in enumerate(chunk):
            for mm, rows_m in enumerate(near_rows):
                comp_near[mm::ncomp, c * ncomp + kk] = sol[rows_m, col]
        b_mat.destroy()
        x_mat.destroy()
    pos_in_near = np.searchsorted(near, cidx)
    rows_c = (pos_in_near[:, None] * ncomp + np.arange(ncomp)).ravel()
    big_pi = np.kron(transport, np.eye(ncomp))
    matrix = comp_near[rows_c] - big_pi @ comp_near  # u_b - u_b(x + dq) per unit nodal force
    x_c, y_c = xy_all[cidx, 0], xy_all[cidx, 1]
    w_step = (np.column_stack([xi - phi * y_c, eta + phi * x_c]) * step_m)[:, free_comp].ravel()
    limit = system.limit[cidx]
    nc = len(cidx)
    c_scale = 1.0 / np.abs(np.diag(matrix)).reshape(nc, ncomp).max(axis=1)
    stick = np.ones(nc, bool)
    e_dir = np.zeros((nc, ncomp))
    force = np.zeros((nc, ncomp))
    slip = np.zeros((nc, ncomp))
    success, message, it = False, f"stick set did not settle in {max_iterations} iterations", 0
    for it in range(1, max_iterations + 1):
        s_rows = (np.flatnonzero(stick)[:, None] * ncomp + np.arange(ncomp)).ravel()
        f = (limit[:, None] * e_dir * (~stick)[:, None]).ravel()
        if len(s_rows):
            rhs = w_step[s_rows] - matrix[s_rows] @ f
            f[s_rows] = np.linalg.solve(matrix[np.ix_(s_rows, s_rows)], rhs)
        force = f.reshape(nc, ncomp)
        slip = (w_step - matrix @ f).reshape(nc, ncomp) * (~stick)[:, None]
        trial = force + c_scale[:, None] * slip
        norm = np.linalg.norm(trial, axis=1)
        new_stick = norm <= limit
        moving = ~new_stick & (norm > 0)
        new_dir = e_dir.copy()
        new_dir[moving] = trial[moving] / norm[moving, None]
        turned = float(np.max(np.abs(new_dir - e_dir)[moving], initial=0.0))
        changed = int(np.count_nonzero(new_stick != stick))
        stick, e_dir = new_stick, new_dir
        if changed == 0 and turned < direction_tolerance:
            success, message = True, f"stick set and slip directions converged in {it} iterations"
            break
    dofs = system.dofs_global
    system.destroy()
    force2 = np.zeros((nc, 2))
    force2[:, free_comp] = force
    slip2 = np.zeros((nc, 2))
    slip2[:, free_comp] = slip
    weights = system.weights[cidx]
    wheel = (-float(force2[:, 0].sum()), -float(force2[:, 1].sum()))
    moment = -float(np.sum(x_c * force2[:, 1] - y_c * force2[:, 0]))
    return RollingSolution(
        success=success,
        status="ok" if success else "not-converged",
        message=message,
        iterations=it,
        creep_force_N=wheel,
        spin_moment_Nm=moment,
        node_xy_m=xy_all[cidx],
        node_normal_force_N=system.n_force[cidx],
        node_weight_m2=weights,
        node_traction_Pa=-force2 / weights[:, None],
        node_slip_m=-slip2,
        stick=stick,
        in_contact=np.ones(nc, bool),
        dofs=dofs,
        wall_time_s=time.perf_counter() - t_start,
    )


def _rolling_failure(message, t_start):
    empty = np.zeros((0, 2))
    return RollingSolution(
        success=False,
        status="not-converged",
        message=message,
        iterations=0,
        creep_force_N=(math.nan, math.nan),
        spin_moment_Nm=math.nan,
        node_xy_m=empty,
        node_normal_force_N=np.zeros(0),
        node_weight_m2=np.zeros(0),
        node_traction_Pa=empty,
        node_slip_m=empty,
        stick=np.zeros(0, bool),
        in_contact=np.zeros(0, bool),
        dofs=0,
        wall_time_s=time.perf_counter() - t_start,
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


def carter_rolling(creepage: float, friction_coefficient: float, half_width_m: float, radius_m: float) -> dict:
    """Carter's closed form of two-dimensional steady rolling (Carter 1926; Johnson 1985, sec. 8.4).

    Two cylinders of equal elastic constants (the tangential and normal problems uncouple) with the Hertz
    half-width a and relative radius R (the rigid cylinder of the one-block model: gap x^2/(2 R)); longitudinal
    creepage xi, Coulomb coefficient mu, rolling towards +x (leading edge x = +a). With s = |xi| R/(mu a) < 1 the
    patch sticks in a zone of half-length c = a (1 - s) at the leading edge, x in [a - 2c, a], and

        F/(mu P) = 1 - (c/a)^2,
        q(x)/(mu p0) = sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - (x - a + c)^2/c^2)   (second term in the stick zone only),

    p0 = 2 P/(pi a) (per unit length); the force on the wheel opposes xi. s >= 1: the whole patch slides, F = mu P.

    Returns:
        {"force_ratio": |F|/(mu P), "stick_half_length_ratio": c/a, "stick_zone_m": (a - 2c, a),
         "traction_ratio": callable x_m -> |q|/(mu p0)}.
    """
    s = abs(creepage) * radius_m / (friction_coefficient * half_width_m)
    c_ratio = max(0.0, 1.0 - s)
    a, c = half_width_m, c_ratio * half_width_m

    def traction_ratio(x_m):
        x = np.asarray(x_m, float)
        full = np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
        if c <= 0.0:
            return full
        return full - c_ratio * np.sqrt(np.clip(1.0 - ((x - a + c) / c) ** 2, 0.0, None))

    return {
        "force_ratio": 1.0 - c_ratio**2,
        "stick_half_length_ratio": c_ratio,
        "stick_zone_m": (a - 2.0 * c, a),
        "traction_ratio": traction_ratio,
    }
