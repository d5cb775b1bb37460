"""TANG: the tangential contact problem with Coulomb friction on a grid of rectangular elements.

Unknown: the traction t = (t_x, t_y) on the wheel (Pa, per element). The slip s of the wheel over
the rail (relative velocity divided by the rolling speed V for rolling, a displacement in m for
the shift problem) is, element-wise (Kalker 1990, sec. 5.2)::

    steady rolling:  s = w - du/dx ~ w + L t,  L = (C(I - K) - C(I - K + e_x))/dx   (s dimensionless)
    shift:           s = w + C t                                                   (s in m)

with the rigid slip w = (xi - phi y, eta + phi x) (xi, eta creepages, phi spin in 1/m, x, y the
element centre in m) for rolling, or the rigid shift w (m) for the shift problem; C the tangential
influence operator (:class:`~.influence.InfluenceGrid`), and the upwind difference taken towards
the leading edge at +x (particles enter the patch at +x). Coulomb's law with the traction bound
g = mu p::

    |t| <= g;   |t| < g  =>  s = 0 (adhesion);   s != 0  =>  t = -g s/|s| (slip; traction opposes slip).

Method: an active-set Newton iteration in the manner of Kalker's TANG (Kalker 1990, sec. 5.3):
the elements are split into adhesion H and slip S; in H the two traction components are unknown
and s = 0 is imposed, in S the traction lies on the bound, t = g e(theta), and its direction angle
theta is unknown with the equation e_perp . s = 0 (slip antiparallel to traction). Each Newton step
is a linear system solved by restarted GMRES (inexact Newton: relative tolerance 0.1 while the sets change,
then min(0.1, max(0.1 residual, 0.3 tolerance/residual)))
whose matrix-vector products are FFT convolutions (O(N log N), no dense matrix). Right preconditioner:
for rolling the operator factors exactly as L = C o D, D t = (t_I - t_(I+e_x))/dx (the upwind difference
acting on the traction; both are convolutions), so D^-1 is a cumulative sum from the leading edge;
C^-1 is approximated by the inverse of the circulant on the grid's own (ny, nx) period with the kernels
folded onto it (Vollebregt's FFT preconditioner, as NORM's; a quarter of the padded FFT size:
:meth:`~.influence.InfluenceGrid.inverse_static_period_spectra`). The slip rows keep their
diagonal and their strong coupling to the slip element ahead (the rolling kernel at offset -e_x is
about minus the self-coefficient): that bidiagonal part is solved exactly along each row from the
leading edge (for the shift problem only the diagonal). The scatter/gather and the 2 x 2 spectral
products of each GMRES step are numba kernels around two batched real FFT pairs (one for the
operator, zero-padded with the padding rows skipped along x; one for the preconditioner, unpadded).
Between steps, adhesion elements whose traction exceeds the bound move to S and slip elements whose
slip has turned along their traction (e . s > 0) move back to H. A warm start (``initial_traction``,
``initial_slip``: the solution of a nearby problem) replaces the nested-iteration start; times:
benchmarks/results/bem_tang.md.
Linearisation of the slip-element equation (derivative of e_perp . s with respect to theta)::

    d(e_perp . s)/d theta = -e . s + e_perp . (L g e_perp)      (-e . s = |s| > 0 at a solution)
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numba
import numpy as np

from rigid_dynamics.contact.bem.influence import InfluenceGrid, period_irfft2, period_rfft2


@numba.njit(cache=True, fastmath=True)
def _orthogonalize(basis, count, w):
    """Classical Gram-Schmidt twice of w (in place) against basis[:count]; returns (coefficients, norm)."""
    h = np.zeros(count)
    n = w.size
    for _ in range(2):
        for i in range(count):
            acc = 0.0
            for j in range(n):
                acc += basis[i, j] * w[j]
            h[i] += acc
            for j in range(n):
                w[j] -= acc * basis[i, j]
    norm = 0.0
    for j in range(n):
        norm += w[j] * w[j]
    return h, math.sqrt(norm)


@numba.njit(cache=True, fastmath=True)
def _combine(basis, y):
    """sum_i y[i] basis[i] (single-threaded)."""
    out = np.zeros(basis.shape[1])
    for i in range(y.size):
        for j in range(basis.shape[1]):
            out[j] += y[i] * basis[i, j]
    return out


@numba.njit(cache=True)
def _spread(v, kind, idx, nh, gex, gey, buf):
    """Write the traction increments of the compact vector v into the padded buffer buf (2, ly, lx).

    kind[j, i]: 0 outside the unknowns, 1 adhesion (v[idx], v[nh + idx] are t_x, t_y), 2 slip
    (v[idx] is the angle increment, traction g e_perp times it: gex, gey). Only the (ny, nx) corner is written.
    """
    ny, nx = kind.shape
    for j in range(ny):
        for i in range(nx):
            k = kind[j, i]
            if k == 1:
                buf[0, j, i] = v[idx[j, i]]
                buf[1, j, i] = v[nh + idx[j, i]]
            elif k == 2:
                a = v[idx[j, i]]
                buf[0, j, i] = gex[j, i] * a
                buf[1, j, i] = gey[j, i] * a
            else:
                buf[0, j, i] = 0.0
                buf[1, j, i] = 0.0


@numba.njit(cache=True)
def _mix(spec, kxx, kxy, kyy, out):
    """Multiply by the symmetric 2 x 2 symbol per frequency: out = [[kxx, kxy], [kxy, kyy]] spec (complex)."""
    ly, lc = kxx.shape
    for j in range(ly):
        for i in range(lc):
            a = spec[0, j, i]
            b = spec[1, j, i]
            out[0, j, i] = kxx[j, i] * a + kxy[j, i] * b
            out[1, j, i] = kxy[j, i] * a + kyy[j, i] * b


@numba.njit(cache=True)
def _gather_residual(u, v, kind, idx, nh, epx, epy, diag, out):
    """Jacobian rows from the displacement (rate) u (2, ly, lx): adhesion s_x, s_y; slip e_perp . s + |s| alpha."""
    ny, nx = kind.shape
    for j in range(ny):
        for i in range(nx):
            k = kind[j, i]
            if k == 1:
                out[idx[j, i]] = u[0, j, i]
                out[nh + idx[j, i]] = u[1, j, i]
            elif k == 2:
                m = idx[j, i]
                out[m] = epx[j, i] * u[0, j, i] + epy[j, i] * u[1, j, i] + diag[j, i] * v[m]


@numba.njit(cache=True)
def _spread_adhesion(v, kind, idx, nh, buf):
    """Adhesion rows of v into the padded buffer (slip and outside elements zero)."""
    ny, nx = kind.shape
    for j in range(ny):
        for i in range(nx):
            if kind[j, i] == 1:
                buf[0, j, i] = v[idx[j, i]]
                buf[1, j, i] = v[nh + idx[j, i]]
            else:
                buf[0, j, i] = 0.0
                buf[1, j, i] = 0.0


@numba.njit(cache=True)
def _precondition_out(u, v, kind, idx, nh, self_s, ahead, dx, rolling, out):
    """Preconditioned vector from u = C^-1 r (2, ly, lx) and the slip rows of v.

    Adhesion: u itself (shift) or D^-1 u, the sum from the leading edge (rolling). Slip: the
    bidiagonal part of the slip rows solved exactly along each row from the leading edge,
    alpha_I = (v_I - ahead_I alpha_(I+e_x))/self_I (ahead = 0 where the element ahead is not in slip).
    """
    ny, nx = kind.shape
    for j in range(ny):
        cx = 0.0
        cy = 0.0
        alpha = 0.0
        for i in range(nx - 1, -1, -1):
            k = kind[j, i]
            if rolling:
                if k == 1:
                    cx += u[0, j, i] * dx
                    cy += u[1, j, i] * dx
                    out[idx[j, i]] = cx
                    out[nh + idx[j, i]] = cy
            elif k == 1:
                out[idx[j, i]] = u[0, j, i]
                out[nh + idx[j, i]] = u[1, j, i]
            if k == 2:
                m = idx[j, i]
                alpha = (v[m] - ahead[j, i] * alpha) / self_s[j, i]
                out[m] = alpha
            else:
                alpha = 0.0


def _gmres(apply, rhs: np.ndarray, rtol: float, max_iterations: int, restart: int = 40) -> tuple[np.ndarray, int]:
    """Restarted GMRES (Saad & Schultz 1986) with classical Gram-Schmidt applied twice; x0 = 0.

    ``apply`` is the (right-preconditioned) operator. Returns the solution and the iteration count.
    """
    n = rhs.size
    x = np.zeros(n)
    b_norm = math.sqrt(float((rhs * rhs).sum()))
    if b_norm == 0.0:
        return x, 0
    total = 0
    r = rhs.copy()
    while total < max_iterations:
        beta = math.sqrt(float((r * r).sum()))
        if beta <= rtol * b_norm:
            break
        basis = np.zeros((restart + 1, n))
        hess = np.zeros((restart + 1, restart))
        cs = np.zeros(restart)
        sn = np.zeros(restart)
        g = np.zeros(restart + 1)
        g[0] = beta
        basis[0] = r / beta
        k_used = 0
        for k in range(restart):
            w = apply(basis[k])
            h, hn = _orthogonalize(basis, k + 1, w)
            hess[: k + 1, k] = h
            hess[k + 1, k] = hn
            for i in range(k):
                a, c = hess[i, k], hess[i + 1, k]
                hess[i, k] = cs[i] * a + sn[i] * c
                hess[i + 1, k] = -sn[i] * a + cs[i] * c
            denom = math.hypot(hess[k, k], hess[k + 1, k])
            cs[k], sn[k] = (hess[k, k] / denom, hess[k + 1, k] / denom) if denom > 0 else (1.0, 0.0)
            hess[k, k] = denom
            hess[k + 1, k] = 0.0
            g[k + 1] = -sn[k] * g[k]
            g[k] = cs[k] * g[k]
            total += 1
            k_used = k + 1
            if abs(g[k + 1]) <= rtol * b_norm or hn == 0.0 or total >= max_iterations:
                break
            basis[k + 1] = w / hn
        y = np.linalg.solve(
            np.triu(hess[:k_used, :k_used]) + np.diag(np.where(np.diag(hess[:k_used, :k_used]) == 0, 1.0, 0.0)),
            g[:k_used],
        )
        x = x + _combine(basis, y)
        if abs(g[k_used]) <= rtol * b_norm or hn == 0.0 or total >= max_iterations:
            break  # converged: the estimate |g| is the residual of x (exact arithmetic); no extra product
        r = rhs - apply(x)
    return x, total


def rigid_slip(
    x_m: np.ndarray, y_m: np.ndarray, longitudinal: float, lateral: float, spin_1_per_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Rigid slip per unit rolling distance w = (xi - phi y, eta + phi x) on the grid (Kalker 1990, eq 1.3.8).

    ``x_m`` (nx,), ``y_m`` (ny,): element centres in the contact frame, m. Returns two (ny, nx) arrays.
    """
    xx, yy = np.meshgrid(np.asarray(x_m, float), np.asarray(y_m, float))
    return longitudinal - spin_1_per_m * yy, lateral + spin_1_per_m * xx


@dataclass(frozen=True, eq=False)
class TangSolution:
    """Result of :func:`solve_tang`.

    Attributes:
        traction_x_Pa, traction_y_Pa: t on the wheel, shape (ny, nx), Pa.
        slip_x, slip_y: s, shape (ny, nx), zero in adhesion and outside contact; dimensionless
            (slip velocity / V) for rolling, m for the shift problem.
        in_slip: bool (ny, nx), elements at the traction bound (p > 0).
        iterations: Newton (active-set) iterations.
        linear_iterations: GMRES iterations summed over the Newton steps.
        residual: max over the contact of |s| (adhesion) and |e_perp . s| (slip) over max |w|.
        converged: residual below the tolerance with unchanged sets within the iteration limit.
        friction_iterations: outer iterations of a falling friction law (:func:`solve_tang_law`; 0: none).
        friction_change: the last outer iteration's largest change of the traction bound over max mu(0) p.
    """

    traction_x_Pa: np.ndarray
    traction_y_Pa: np.ndarray
    slip_x: np.ndarray
    slip_y: np.ndarray
    in_slip: np.ndarray
    iterations: int
    linear_iterations: int
    residual: float
    converged: bool
    friction_iterations: int = 0
    friction_change: float = 0.0


def solve_tang(
    influence: InfluenceGrid,
    pressure_Pa: np.ndarray,
    friction_coefficient: float,
    rigid_slip_x: np.ndarray,
    rigid_slip_y: np.ndarray,
    *,
    problem: str = "rolling",
    tolerance: float = 1e-8,
    max_iterations: int = 60,
    coarse_start: bool = True,
    kinetic_friction_coefficient: float | None = None,
    initial_traction: tuple[np.ndarray, np.ndarray] | None = None,
    initial_slip: np.ndarray | None = None,
) -> TangSolution:
    """Solve TANG for steady rolling or the shift problem (module docstring).

    Nested iteration: on grids of at least 32 x 32 elements, the problem is first solved on the grid of
    2 x 2 merged elements (pressure and rigid slip averaged; odd counts padded with one element of zero
    pressure) and its tractions and slip area start the Newton iteration on the fine grid; this keeps the
    number of Newton steps small. The coarse problem is solved to a relative residual of 1e-2 only (its
    discretisation error is larger than that).

    Args:
        influence: grid and influence coefficients.
        pressure_Pa: p (ny, nx), Pa (the normal solution).
        friction_coefficient: mu >= 0, the static coefficient (adhesion holds while |t| <= mu p): one number or
            an (ny, nx) array, element-wise (friction varying in place).
        kinetic_friction_coefficient: mu_k > 0 (<= mu expected), the traction in slip |t| = mu_k p, one number or
            an (ny, nx) array; None: mu_k = mu (Coulomb with one coefficient). This is the inner step of falling
            friction (:func:`solve_tang_law` sets mu_k = mu(slip velocity) element-wise and iterates); a constant
            mu_k < mu on its own is CONTACT's Coulomb law before v23.1, which CONTACT no longer takes.
        rigid_slip_x, rigid_slip_y: w (ny, nx); creepage field (rolling, -) or rigid shift (shift, m).
        problem: "rolling" (steady state) or "shift" (Cattaneo: one step from the unloaded state).
        tolerance: relative tolerance on the slip residual (and GMRES).
        max_iterations: Newton iteration limit (non-convergence is reported in the result).
        coarse_start: use the nested-iteration start described above (not with ``initial_traction``).
        initial_traction: warm start (t_x, t_y), each (ny, nx), Pa, e.g. the solution of a nearby problem on the
            same grid (the previous iteration of a load equilibrium). Zeroed outside the contact; the elements of
            ``initial_slip`` (default: those with |t| >= 0.99 mu_k p) start in slip with the traction scaled onto the
            bound in its direction, the other contact elements in adhesion. Only the start changes: the solution
            is the same to the tolerance.
        initial_slip: bool (ny, nx), the slip area of the warm start (e.g. ``TangSolution.in_slip``); only with
            ``initial_traction``.

    Returns:
        :class:`TangSolution`.
    """
    shape = (influence.ny, influence.nx)
    if problem not in ("rolling", "shift"):
        raise ValueError(f"problem = {problem!r}: expected 'rolling' or 'shift'")
    p = np.asarray(pressure_Pa, float)
    for name, arr in (("pressure_Pa", p), ("rigid_slip_x", rigid_slip_x), ("rigid_slip_y", rigid_slip_y)):
        if np.shape(arr) != shape:
            raise ValueError(f"{name} has shape {np.shape(arr)}: expected (ny, nx) = {shape}")
    mu_s = np.broadcast_to(np.asarray(friction_coefficient, float), shape)
    if not np.all(np.isfinite(mu_s)) or np.any(mu_s < 0):
        raise ValueError(f"friction_coefficient = {friction_coefficient!r}: expected finite numbers >= 0")
    mu_k = (
        mu_s
        if kinetic_friction_coefficient is None
        else np.broadcast_to(np.asarray(kinetic_friction_coefficient, float), shape)
    )
    if not np.all(np.isfinite(mu_k)) or np.any(mu_k < 0) or np.any((mu_k == 0) & (mu_s > 0)):
        raise ValueError(
            f"kinetic_friction_coefficient = {kinetic_friction_coefficient!r}: expected finite numbers > 0 "
            "(or None: the static coefficient)"
        )
    if not tolerance > 0:
        raise ValueError(f"tolerance = {tolerance!r}: expected > 0")
    if int(max_iterations) < 1:
        raise ValueError(f"max_iterations = {max_iterations!r}: expected >= 1")
    if initial_traction is not None:
        if len(initial_traction) != 2 or any(np.shape(a) != shape for a in initial_traction):
            raise ValueError(f"initial_traction: expected a pair of (ny, nx) = {shape} arrays")
        if not all(np.isfinite(a).all() for a in initial_traction):
            raise ValueError("initial_traction: expected finite values")
    if initial_slip is not None and (initial_traction is None or np.shape(initial_slip) != shape):
        raise ValueError(f"initial_slip: expected a (ny, nx) = {shape} bool array, with initial_traction")
    rolling = problem == "rolling"
    wx = np.asarray(rigid_slip_x, float)
    wy = np.asarray(rigid_slip_y, float)
    if influence.difference_parameter != 0.0:
        # normal-to-tangential coupling of different materials: a known slip contribution from p
        zero = np.zeros(shape)
        cx, cy = influence.tangential(zero, zero, rolling=rolling, pressure_Pa=p)
        wx = wx + cx
        wy = wy + cy
    contact = p > 0
    bound = mu_k * np.where(contact, p, 0.0)  # traction in slip
    bound_static = mu_s * np.where(contact, p, 0.0)  # adhesion holds up to this
    zeros = np.zeros(shape)
    if not contact.any() or not np.any(mu_s[contact] > 0.0):
        sx, sy = np.where(contact, wx, 0.0), np.where(contact, wy, 0.0)
        return TangSolution(zeros, zeros.copy(), sx, sy, contact.copy(), 0, 0, 0.0, True)
    scale = float(np.max(np.hypot(wx, wy)[contact]))
    if scale == 0.0:
        return TangSolution(zeros, zeros.copy(), zeros.copy(), zeros.copy(), np.zeros(shape, bool), 0, 0, 0.0, True)

    m_x = influence.self_coefficient("xx", rolling)
    m_y = influence.self_coefficient("yy", rolling)
    l_xx = float(influence.kernel("xx", rolling)[influence.ny - 1, influence.nx - 2]) if influence.nx > 1 else 0.0
    l_yy = float(influence.kernel("yy", rolling)[influence.ny - 1, influence.nx - 2]) if influence.nx > 1 else 0.0

    def slip_of(tx: np.ndarray, ty: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ux, uy = influence.tangential(tx, ty, rolling=rolling)
        return wx + ux, wy + uy

    lin_total = 0
    n = shape[0] * shape[1]
    padded = influence.padded_shape
    buf = np.zeros((2, *shape))  # traction pair on the grid (zero-padded by the pruned FFT passes)
    mixed = np.empty((2, padded[0], padded[1] // 2 + 1), complex)
    mixed_p = np.empty((2, shape[0], shape[1] // 2 + 1), complex)
    spec_p = np.empty_like(mixed_p)  # the preconditioner's spectrum and result, consumed at once
    u_p = np.empty((2, *shape))
    k_roll = influence.tangential_spectra(rolling)
    k_inv = influence.inverse_static_period_spectra()
    tx = np.zeros(shape)
    ty = np.zeros(shape)
    stick = contact.copy()
    slip = np.zeros(shape, bool)
    theta = np.zeros(shape)
    nx, ny = influence.nx, influence.ny
    if initial_traction is not None:
        tx = np.where(contact, np.asarray(initial_traction[0], float), 0.0)
        ty = np.where(contact, np.asarray(initial_traction[1], float), 0.0)
        if initial_slip is None:
            slip = contact & (np.hypot(tx, ty) >= 0.99 * bound)
        else:
            slip = contact & np.asarray(initial_slip, bool)
        stick = contact & ~slip
        theta = np.where(slip, np.arctan2(ty, tx), 0.0)
        tx = np.where(slip, bound * np.cos(theta), tx)
        ty = np.where(slip, bound * np.sin(theta), ty)
    elif coarse_start and nx >= 32 and (ny == 1 and influence.plane or ny >= 32):
        fy = 1 if influence.plane else 2
        px, py = nx % 2, ny % fy  # odd counts: one element of zero pressure appended for the merging
        coarse = InfluenceGrid(
            (nx + px) // 2,
            (ny + py) // fy,
            2 * influence.dx_m,
            fy * influence.dy_m,
            influence.shear_modulus_Pa,
            influence.poisson_ratio,
            influence.difference_parameter,
            influence.plane,
        )

        def restrict(a: np.ndarray) -> np.ndarray:
            a = np.pad(a, ((0, py), (0, px)))
            return a.reshape((ny + py) // fy, fy, (nx + px) // 2, 2).mean(axis=(1, 3))

        def prolong(a: np.ndarray) -> np.ndarray:
            return np.repeat(np.repeat(a, fy, axis=0), 2, axis=1)[:ny, :nx]

        first = solve_tang(
            coarse,
            restrict(p),
            restrict(np.array(mu_s)),
            restrict(np.asarray(rigid_slip_x, float)),
            restrict(np.asarray(rigid_slip_y, float)),
            problem=problem,
            tolerance=max(tolerance, 1e-2),  # coarse start only: its discretisation error is larger
            max_iterations=max_iterations,
            kinetic_friction_coefficient=restrict(np.array(mu_k)),
        )
        tx = np.where(contact, prolong(first.traction_x_Pa), 0.0)
        ty = np.where(contact, prolong(first.traction_y_Pa), 0.0)
        slip = contact & prolong(first.in_slip)
        stick = contact & ~slip
        theta = np.arctan2(ty, tx)
        tx = np.where(slip, bound * np.cos(theta), tx)
        ty = np.where(slip, bound * np.sin(theta), ty)
        lin_total += first.linear_iterations

    def _sets_hold() -> bool:
        """The warm start's sets are consistent: adhesion within the bound, slip opposing the traction."""
        sx, sy = fresh if fresh is not None else slip_of(tx, ty)
        over = stick & (np.hypot(tx, ty) > bound_static)
        wrong = slip & ((np.cos(theta) * sx + np.sin(theta) * sy) > 0)
        return not (over.any() or wrong.any())

    converged = False
    residual = math.inf
    it = 0
    changed = True  # loose linear solves while the adhesion/slip sets still change
    fresh = None  # slip of the current tractions, when already known
    for it in range(1, int(max_iterations) + 1):
        sx, sy = slip_of(tx, ty) if fresh is None else fresh
        fresh = (sx, sy)
        ex, ey = np.cos(theta), np.sin(theta)
        # residual: adhesion s (2 rows), slip e_perp . s (1 row); e_perp = (-ey, ex)
        s_perp = -ey * sx + ex * sy
        s_par = ex * sx + ey * sy
        res_h = np.hypot(sx, sy)[stick]
        res_s = np.abs(s_perp[slip])
        residual = max(res_h.max() if res_h.size else 0.0, res_s.max() if res_s.size else 0.0) / scale
        if residual < tolerance and (it > 1 or (initial_traction is not None and _sets_hold())):
            converged = True
            break
        # compact unknowns: adhesion (t_x, t_y) increments, then slip angle increments
        ih = np.flatnonzero(stick.ravel())
        isl = np.flatnonzero(slip.ravel())
        nh = ih.size
        epx, epy = -ey.ravel()[isl], ex.ravel()[isl]
        diag_s = np.maximum(-s_par.ravel()[isl], 0.0)  # |s| for correctly oriented slip
        gb = bound.ravel()[isl]
        self_s = gb * (epx * epx * m_x + epy * epy * m_y) + diag_s
        kind = np.where(stick, 1, np.where(slip, 2, 0)).astype(np.int64)
        idx = np.zeros(shape, np.int64)
        idx.ravel()[ih] = np.arange(nh)
        idx.ravel()[isl] = 2 * nh + np.arange(isl.size)
        grid_of = np.zeros(n)

        def on_grid(values: np.ndarray, isl=isl, grid_of=grid_of) -> np.ndarray:
            out = grid_of.copy()
            out[isl] = values
            return out.reshape(shape)

        gex, gey = on_grid(gb * epx), on_grid(gb * epy)
        epx_g, epy_g, diag_g, self_g = on_grid(epx), on_grid(epy), on_grid(diag_s), on_grid(self_s)
        size = 2 * nh + isl.size
        # coupling of a slip row to the slip angle of the element ahead (+x), the rolling kernel at offset -e_x
        ahead_g = np.zeros(shape)
        if rolling and nx > 1:
            gpx, gpy = gex[:, 1:], gey[:, 1:]
            ahead_g[:, :-1] = np.where(
                slip[:, :-1] & slip[:, 1:], epx_g[:, :-1] * gpx * l_xx + epy_g[:, :-1] * gpy * l_yy, 0.0
            )

        def matvec(v, kind=kind, idx=idx, nh=nh, gex=gex, gey=gey, e=(epx_g, epy_g, diag_g), size=size):
            _spread(v, kind, idx, nh, gex, gey, buf)
            _mix(influence._forward(buf), *k_roll, mixed)
            u = influence._backward(mixed, reuse=True)
            out = np.empty(size)
            _gather_residual(u, v, kind, idx, nh, *e, out)
            return out

        def precondition(v, kind=kind, idx=idx, nh=nh, self_g=self_g, ahead_g=ahead_g, size=size):
            _spread_adhesion(v, kind, idx, nh, buf)
            _mix(period_rfft2(buf, spec_p), *k_inv, mixed_p)
            u = period_irfft2(mixed_p, shape[1], u_p)
            out = np.empty(size)
            _precondition_out(u, v, kind, idx, nh, self_g, ahead_g, influence.dx_m, rolling, out)
            return out

        def op(z, mv=matvec, pc=precondition):
            return mv(pc(z))

        rhs = -np.concatenate([sx.ravel()[ih], sy.ravel()[ih], s_perp.ravel()[isl]])
        sol, count = _gmres(
            op,
            rhs,
            rtol=0.1 if changed else min(0.1, max(0.1 * residual, 0.3 * tolerance / residual)),
            max_iterations=400,
        )
        lin_total += count
        sol = precondition(sol)
        txf, tyf, thf = tx.ravel().copy(), ty.ravel().copy(), theta.ravel().copy()
        txf[ih] += sol[:nh]
        tyf[ih] += sol[nh : 2 * nh]
        thf[isl] += sol[2 * nh :]
        tx, ty, theta = txf.reshape(shape), tyf.reshape(shape), thf.reshape(shape)
        tx = np.where(slip, bound * np.cos(theta), tx)
        ty = np.where(slip, bound * np.sin(theta), ty)
        # set changes
        sx, sy = slip_of(tx, ty)
        tmag = np.hypot(tx, ty)
        to_slip = stick & (tmag > bound_static)
        wrong = slip & ((np.cos(theta) * sx + np.sin(theta) * sy) > 0)
        if to_slip.any():
            theta = np.where(to_slip, np.arctan2(ty, tx), theta)
            tx = np.where(to_slip, bound * np.cos(theta), tx)
            ty = np.where(to_slip, bound * np.sin(theta), ty)
        changed = bool(to_slip.any() or wrong.any())
        fresh = None if to_slip.any() else (sx, sy)
        stick = (stick & ~to_slip) | wrong
        slip = (slip & ~wrong) | to_slip
    if not converged:
        sx, sy = slip_of(tx, ty)
    sx = np.where(slip, sx, 0.0)
    sy = np.where(slip, sy, 0.0)
    return TangSolution(tx, ty, sx, sy, slip, it, lin_total, residual, converged)


FRICTION_TOLERANCE = 1e-6
"""The outer iteration of a falling law stops when the traction bound changes by less than max(10 tolerance, this)
times max mu_s p (a finer bound changes the forces below the grid's own error by orders of magnitude)."""


def solve_tang_law(
    influence: InfluenceGrid,
    pressure_Pa: np.ndarray,
    law,
    place: np.ndarray,
    rigid_slip_x: np.ndarray,
    rigid_slip_y: np.ndarray,
    rolling_speed_m_per_s: float,
    *,
    tolerance: float = 1e-8,
    max_iterations: int = 60,
    max_friction_iterations: int = 100,
    initial_traction: tuple[np.ndarray, np.ndarray] | None = None,
    initial_slip: np.ndarray | None = None,
) -> TangSolution:
    """Steady rolling with a friction law (:class:`~rigid_dynamics.contact.friction.FrictionLaw`) element-wise.

    The static coefficient mu_s = mu(0, place) bounds adhesion in each element; an element in slip carries
    |t| = mu(V |s|, place) p, with V |s| its local slip velocity (m/s). Coulomb's law (varying in place or not) is
    one :func:`solve_tang`. A falling law is solved as CONTACT solves its steady state: the traction bound of the
    slip elements is fixed, TANG solved, the bound updated from the new slip velocities, and so on (each solve
    warm-started from the last), until the bound changes by less than :data:`FRICTION_TOLERANCE` (or 10
    ``tolerance``) times max mu_s p in an iteration; the update is under-relaxed (halved) if the change grows. No
    friction memory (the steady law).

    The other arguments are those of :func:`solve_tang` (steady rolling only).

    Args:
        law: the FrictionLaw.
        place: the law's variable at each element (ny, nx), rad or m (ignored when the law does not vary).
        rolling_speed_m_per_s: V > 0 (slip velocity = V times the dimensionless slip).
        max_friction_iterations: outer iteration limit; not converged -> ``converged`` False.
    """
    shape = (influence.ny, influence.nx)
    record = law.record()
    places = np.broadcast_to(np.asarray(place, float), shape)
    if law.is_coulomb and not law.varies:  # one coefficient everywhere (one evaluation of the law: as Python or
        mu_s = np.full(shape, law.static_coefficient())  # compiled, the same bits, friction.py / lazy_kernels.py)
    else:
        from rigid_dynamics.contact.friction import friction_coefficient

        coefficient = np.vectorize(lambda s, x: friction_coefficient(record, s, x), otypes=[float])
        mu_s = coefficient(np.zeros(shape), places)
    common = {"problem": "rolling", "tolerance": tolerance, "max_iterations": max_iterations}
    start = {"initial_traction": initial_traction, "initial_slip": initial_slip} if initial_traction else {}
    tang = solve_tang(influence, pressure_Pa, mu_s, rigid_slip_x, rigid_slip_y, **common, **start)
    if law.is_coulomb or not tang.converged:
        return tang
    if not (math.isfinite(rolling_speed_m_per_s) and rolling_speed_m_per_s > 0):
        raise ValueError(f"rolling_speed_m_per_s = {rolling_speed_m_per_s!r}: expected > 0 for a falling law")
    p = np.where(pressure_Pa > 0, pressure_Pa, 0.0)
    scale = float((mu_s * p).max()) or 1.0
    mu_k = mu_s.copy()
    relax, last_change, change = 1.0, math.inf, math.inf
    lin = tang.linear_iterations
    for outer in range(1, int(max_friction_iterations) + 1):
        speed = rolling_speed_m_per_s * np.hypot(tang.slip_x, tang.slip_y)
        target = np.where(tang.in_slip, coefficient(speed, places), mu_s)
        change = float((np.abs(target - mu_k) * p).max()) / scale
        if change <= max(10.0 * tolerance, FRICTION_TOLERANCE):
            return dataclasses.replace(tang, linear_iterations=lin, friction_iterations=outer, friction_change=change)
        if change > last_change:
            relax = max(0.5 * relax, 0.125)
        last_change = change
        mu_k = np.maximum(mu_k + relax * (target - mu_k), 1e-12)
        tang = solve_tang(
            influence, pressure_Pa, mu_s, rigid_slip_x, rigid_slip_y, kinetic_friction_coefficient=mu_k, **common,
            initial_traction=(tang.traction_x_Pa, tang.traction_y_Pa), initial_slip=tang.in_slip,
        )  # fmt: skip
        lin += tang.linear_iterations
        if not tang.converged:
            break
    return dataclasses.replace(
        tang, converged=False, linear_iterations=lin, friction_iterations=outer, friction_change=change
    )
