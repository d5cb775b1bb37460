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
    """Steady rolling with creepage by a sequence of shifts (the same on every rank).

    Attributes:
        success, status, message: "ok" (steady within the tolerance), "not-steady" (the step budget ran out before
            the creep force settled) or "not-converged" (a step's active set did not settle).
        steps: number of shifts solved; rolled_m: distance rolled, m.
        creep_force_N: (F_x, F_y) on the WHEEL (the indenter), contact frame, N.
        spin_moment_Nm: moment about the normal on the wheel, N m.
        steady_error_N: estimated distance of the last creep force from the steady one (Aitken), N.
        force_history_N: (steps, 2) the wheel's creep force after each shift (its approach to the steady state).
        node_xy_m, node_normal_force_N, node_weight_m2: the contact-face nodes of the normal solution.
        node_traction_Pa: (n, 2) tangential traction on the wheel, F_i / w_i (its sign reversed: on the wheel), Pa.
        node_slip_m: (n, 2) slip of the wheel over the rail in the last step, m (zero where it sticks).
        stick, in_contact: (n,) bool.
        dofs: global number of displacement unknowns.
        wall_time_s: s.
    """

    success: bool
    status: str
    message: str
    steps: int
    rolled_m: float
    creep_force_N: tuple
    spin_moment_Nm: float
    steady_error_N: float
    force_history_N: np.ndarray
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
    patch_length_m: float,
    length_scale_m: float = 1e-3,
    steady_tolerance: float = 1e-3,
    max_steps: int = 200,
    progress=None,
) -> RollingSolution:
    """Steady rolling of the rigid indenter (the wheel) over ``domain`` with creepages, as transient shifts.

    Kalker's transient rolling (Kalker 1990, "Three-dimensional elastic bodies in rolling contact", ch. 5): the
    patch stands still, the material of both bodies passes through it in -x by ``step_m`` per step; a particle at x
    was at x + step_m one step before. The slip of the wheel over the rail in a step is
    s = w step_m + u(x) - u_prev(x + step_m), with w = (xi - phi y, eta + phi x) the rigid creepage and u the
    combined surface displacement (wheel minus rail, = minus the equivalent block's); a node sticks where s = 0,
    i.e. the block's displacement is prescribed to u_b,prev(x + step_m) + w step_m (interpolated linearly between
    the face nodes), and slips elsewhere with the traction mu p opposing s. The shifts are repeated from rest until
    the material has crossed the patch (rolled >= ``patch_length_m``) and the creep force is within
    ``steady_tolerance`` mu P of its steady value (the force settles geometrically, ratio r per step, because a
    particle's displacement on entering depends on the whole traction field: the remaining change is estimated
    as |dF| r/(1 - r), Aitken). Chosen over a steady-state (Eulerian) formulation because it reuses the
    shift problem's solver unchanged (stick values become per-node targets) and needs no derivative of the
    surface displacement along x on the unstructured face; its cost is the number of steps (about
    patch_length/step + a few), each a warm-started active-set solve.

    Args:
        domain: full block (no symmetry: rolling with creepage breaks the quarter model's symmetries).
        normal: converged frictionless normal solution on ``domain`` (P1), held fixed (equal materials).
        creepage: (xi, eta, phi): longitudinal, lateral creepage and spin (1/m) of the wheel over the rail.
        step_m: distance rolled per shift, m (about the element size at the patch).
        patch_length_m: the patch's length along x, m (2 a).
        progress: optional callable(str) told after every step.

    Returns:
        :class:`RollingSolution`; numerical failure and no steady state are statuses.
    """
    from scipy.interpolate import LinearNDInterpolator

    if domain.symmetry != "full":
        raise ValueError(f"domain symmetry {domain.symmetry!r}: rolling with creepage needs the full block")
    if not (math.isfinite(friction_coefficient) and friction_coefficient > 0):
        raise ValueError(f"friction_coefficient = {friction_coefficient!r}: expected a finite number > 0")
    xi, eta, phi = (float(c) for c in creepage)
    if not all(math.isfinite(c) for c in (xi, eta, phi)):
        raise ValueError(f"creepage = {creepage!r}: expected three finite numbers")
    for name, value in (("step_m", step_m), ("patch_length_m", patch_length_m)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    if not normal.success:
        raise ValueError(f"normal solution status {normal.status!r}: expected a converged normal solve")
    t_start = time.perf_counter()
    system = _TangentialSystem(
        domain, normal, young_modulus_Pa, poisson_ratio, friction_coefficient, length_scale_m, {}
    )
    comm = system.comm
    n = len(system.xy)
    start = comm.exscan(n) or 0
    xy_all = system.gather(system.xy).reshape(-1, 2)
    x, y = system.xy[:, 0], system.xy[:, 1]
    creep_step = np.column_stack([xi - phi * y, eta + phi * x]) * step_m
    contact_all = system.gather(system.in_contact).astype(bool)
    reach = np.max(np.abs(xy_all[contact_all]), axis=0) + 3.0 * step_m if contact_all.any() else np.zeros(2)
    near = np.all(np.abs(xy_all) <= reach, axis=1)
    u_prev_all = np.zeros((len(xy_all), 2))
    stick, e_dir = None, None
    history = []
    mu_p = friction_coefficient * system.total_normal_N
    status, message, out = "not-steady", f"the creep force did not settle in {max_steps} steps", None
    steps, remaining = 0, math.inf
    for steps in range(1, max_steps + 1):
        interp = LinearNDInterpolator(xy_all[near], u_prev_all[near], fill_value=0.0)
        target = interp(system.xy + np.array([step_m, 0.0])) + creep_step
        out = system.iterate(target, stick=stick, e_dir=e_dir)
        if not out["success"]:
            status, message = "not-converged", f"step {steps}: {out['message']}"
            break
        stick, e_dir = out["stick"], out["e_dir"]
        u_prev_all = system.gather(out["u_t"]).reshape(-1, 2)
        force = out["force"]
        wheel = (-comm.allreduce(float(force[:, 0].sum())), -comm.allreduce(float(force[:, 1].sum())))
        history.append(wheel)
        if progress is not None:
            progress(f"rolling step {steps}: creep force on the wheel ({wheel[0]:.6g}, {wheel[1]:.6g}) N")
        if len(history) >= 3:
            # the force approaches its steady value geometrically (ratio r per step): what remains is
            # |dF_k| r / (1 - r), Aitken's estimate
            change = math.hypot(history[-1][0] - history[-2][0], history[-1][1] - history[-2][1])
            before = math.hypot(history[-2][0] - history[-3][0], history[-2][1] - history[-3][1])
            ratio = change / before if before > 0 else 0.0
            remaining = change * ratio / (1.0 - ratio) if ratio < 1.0 else math.inf
            if steps * step_m >= patch_length_m and remaining <= steady_tolerance * mu_p:
                status, message = (
                    "ok",
                    (
                        f"steady after {steps} shifts ({steps * step_m:.4g} m rolled; the creep force within "
                        f"{remaining / mu_p:.2g} mu P of its steady value, Aitken's estimate)"
                    ),
                )
                break
    force = out["force"] if out is not None else np.zeros((n, 2))
    moment = -comm.allreduce(float(np.sum(x * force[:, 1] - y * force[:, 0])))
    with np.errstate(divide="ignore", invalid="ignore"):
        traction = np.where(system.weights[:, None] > 0, -force / system.weights[:, None], 0.0)
    slip = -(out["slip"] if out is not None else np.zeros((n, 2)))
    result = RollingSolution(
        success=status == "ok",
        status=status,
        message=message,
        steps=steps,
        rolled_m=steps * step_m,
        creep_force_N=history[-1] if history else (math.nan, math.nan),
        steady_error_N=remaining,
        spin_moment_Nm=moment,
        force_history_N=np.array(history).reshape(-1, 2),
        node_xy_m=xy_all,
        node_normal_force_N=system.gather(system.n_force),
        node_weight_m2=system.gather(system.weights),
        node_traction_Pa=system.gather(traction).reshape(-1, 2),
        node_slip_m=system.gather(slip).reshape(-1, 2),
        stick=system.gather(out["stick"] if out is not None else np.zeros(n, bool)).astype(bool),
        in_contact=contact_all,
        dofs=system.dofs_global,
        wall_time_s=time.perf_counter() - t_start,
    )
    del start
    system.destroy()
    return result


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
