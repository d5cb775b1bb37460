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
is a linear system solved by GMRES whose matrix-vector products are FFT convolutions (O(N log N),
no dense matrix). Between steps, adhesion elements whose traction exceeds the bound move to S
and slip elements whose slip has turned along their traction (e . s > 0) move back to H.
Linearisation of the slip-element equation (derivative of e_perp . s with respect to theta)::

    d(e_perp . s)/d theta = -e . s + e_perp . (L g e_perp)      (-e . s = |s| > 0 at a solution)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.bem.influence import InfluenceGrid


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
) -> TangSolution:
    """Solve TANG for steady rolling or the shift problem (module docstring).

    Args:
        influence: grid and influence coefficients.
        pressure_Pa: p (ny, nx), Pa (the normal solution).
        friction_coefficient: mu >= 0 (Coulomb, static = kinetic).
        rigid_slip_x, rigid_slip_y: w (ny, nx); creepage field (rolling, -) or rigid shift (shift, m).
        problem: "rolling" (steady state) or "shift" (Cattaneo: one step from the unloaded state).
        tolerance: relative tolerance on the slip residual (and GMRES).
        max_iterations: Newton iteration limit (non-convergence is reported in the result).

    Returns:
        :class:`TangSolution`.
    """
    from scipy.sparse.linalg import LinearOperator, gmres

    shape = (influence.ny, influence.nx)
    if problem not in ("rolling", "shift"):
        raise ValueError(f"problem = {problem!r}: expected 'rolling' or 'shift'")
    p = np.asarray(pressure_Pa, float)
    for name, arr in (("pressure_Pa", p), ("rigid_slip_x", rigid_slip_x), ("rigid_slip_y", rigid_slip_y)):
        if np.shape(arr) != shape:
            raise ValueError(f"{name} has shape {np.shape(arr)}: expected (ny, nx) = {shape}")
    if not math.isfinite(friction_coefficient) or friction_coefficient < 0:
        raise ValueError(f"friction_coefficient = {friction_coefficient!r}: expected a finite number >= 0")
    if not tolerance > 0:
        raise ValueError(f"tolerance = {tolerance!r}: expected > 0")
    if int(max_iterations) < 1:
        raise ValueError(f"max_iterations = {max_iterations!r}: expected >= 1")
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
    bound = friction_coefficient * np.where(contact, p, 0.0)
    zeros = np.zeros(shape)
    if not contact.any() or friction_coefficient == 0.0:
        sx, sy = np.where(contact, wx, 0.0), np.where(contact, wy, 0.0)
        return TangSolution(zeros, zeros.copy(), sx, sy, contact.copy(), 0, 0, 0.0, True)
    scale = float(np.max(np.hypot(wx, wy)[contact]))
    if scale == 0.0:
        return TangSolution(zeros, zeros.copy(), zeros.copy(), zeros.copy(), np.zeros(shape, bool), 0, 0, 0.0, True)
    m_x = influence.self_coefficient("xx", rolling)

    def slip_of(tx: np.ndarray, ty: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ux, uy = influence.tangential(tx, ty, rolling=rolling)
        return wx + ux, wy + uy

    tx = np.zeros(shape)
    ty = np.zeros(shape)
    stick = contact.copy()
    slip = np.zeros(shape, bool)
    theta = np.zeros(shape)
    converged = False
    residual = math.inf
    lin_total = 0
    it = 0
    for it in range(1, int(max_iterations) + 1):
        sx, sy = slip_of(tx, ty)
        ex, ey = np.cos(theta), np.sin(theta)
        # residual: adhesion s (2 rows), slip e_perp . s (1 row); e_perp = (-ey, ex)
        s_perp = -ey * sx + ex * sy
        s_par = ex * sx + ey * sy
        res_h = np.hypot(sx, sy)[stick]
        res_s = np.abs(s_perp[slip])
        residual = max(res_h.max() if res_h.size else 0.0, res_s.max() if res_s.size else 0.0) / scale
        ih = np.flatnonzero(stick.ravel())
        is_ = np.flatnonzero(slip.ravel())
        nh, ns = ih.size, is_.size
        if residual < tolerance and it > 1:
            converged = True
            break
        gs = bound.ravel()[is_]
        epx, epy = -ey.ravel()[is_], ex.ravel()[is_]
        diag_s = np.maximum(-s_par.ravel()[is_], 0.0)  # |s| for correctly oriented slip

        def matvec(v: np.ndarray, ih=ih, is_=is_, nh=nh, gs=gs, epx=epx, epy=epy, diag_s=diag_s) -> np.ndarray:
            dtx = np.zeros(shape[0] * shape[1])
            dty = np.zeros(shape[0] * shape[1])
            dtx[ih] = v[:nh]
            dty[ih] = v[nh : 2 * nh]
            alpha = v[2 * nh :]
            dtx[is_] = gs * epx * alpha
            dty[is_] = gs * epy * alpha
            ux, uy = influence.tangential(dtx.reshape(shape), dty.reshape(shape), rolling=rolling)
            ux, uy = ux.ravel(), uy.ravel()
            out_s = epx * ux[is_] + epy * uy[is_] + diag_s * alpha
            return np.concatenate([ux[ih], uy[ih], out_s])

        n_unknown = 2 * nh + ns
        # scale the unknowns: tractions by 1/m, angles by 1/(g m) (Jacobi-like right preconditioner)
        d = np.concatenate([np.full(2 * nh, 1.0), 1.0 / np.maximum(gs * m_x + diag_s, 1e-300) * m_x])
        op = LinearOperator((n_unknown, n_unknown), matvec=lambda v, d=d, mv=matvec: mv(d * v) / m_x)
        rhs = -np.concatenate([sx.ravel()[ih], sy.ravel()[ih], s_perp.ravel()[is_]]) / m_x
        count = [0]

        def cb(_, count=count):
            count[0] += 1

        sol, _ = gmres(
            op,
            rhs,
            rtol=max(min(1e-2, 0.1 * residual), 0.01 * tolerance),
            atol=0.0,
            restart=200,
            maxiter=5,
            callback=cb,
            callback_type="pr_norm",
        )
        lin_total += count[0]
        sol = d * sol
        txf, tyf = tx.ravel().copy(), ty.ravel().copy()
        txf[ih] += sol[:nh]
        tyf[ih] += sol[nh : 2 * nh]
        th = theta.ravel().copy()
        th[is_] += sol[2 * nh :]
        txf[is_] = bound.ravel()[is_] * np.cos(th[is_])
        tyf[is_] = bound.ravel()[is_] * np.sin(th[is_])
        tx, ty, theta = txf.reshape(shape), tyf.reshape(shape), th.reshape(shape)
        # set changes
        sx, sy = slip_of(tx, ty)
        tmag = np.hypot(tx, ty)
        to_slip = stick & (tmag > bound)
        wrong = slip & ((np.cos(theta) * sx + np.sin(theta) * sy) > 0)
        if to_slip.any():
            theta = np.where(to_slip, np.arctan2(ty, tx), theta)
            tx = np.where(to_slip, bound * np.cos(theta), tx)
            ty = np.where(to_slip, bound * np.sin(theta), ty)
        stick = (stick & ~to_slip) | wrong
        slip = (slip & ~wrong) | to_slip
    sx, sy = slip_of(tx, ty)
    sx = np.where(slip, sx, 0.0)
    sy = np.where(slip, sy, 0.0)
    return TangSolution(tx, ty, sx, sy, slip, it, lin_total, residual, converged)
