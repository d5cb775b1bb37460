"""NORM: the normal contact problem on a grid of rectangular elements.

Find the pressure p (Pa, piecewise constant per element) with::

    e = h + A p - d >= 0,   p >= 0,   p e = 0   (element-wise, at element centres)

h the undeformed distance (m, with the geometry's approach already subtracted), A the
normal influence operator (:class:`~.influence.InfluenceGrid`, m/Pa), e the deformed distance.
Approach control: d = 0 (the approach is the geometry's). Force control: d (m) is an extra
unknown fixed by ``dA sum p = F_N`` (the approach becomes q + d).

Two methods (``method`` of :func:`solve_norm`):

* ``"normcg"`` (default): preconditioned bound-constrained conjugate gradients in the manner of
  Vollebregt's NormCG (E.A.H. Vollebregt, "The bound-constrained conjugate gradient method for
  non-negative matrices", J. Optim. Theory Appl. 162 (2014) 931-953; "A new solver for the elastic
  normal contact problem using conjugate gradients, deflation, and an FFT-based preconditioner",
  J. Comput. Phys. 257 (2014) 333-351). CG on the current contact set C with the residual
  r = -(h + A p) (its mean over C removed in force control), preconditioned by the inverse of the
  circulant of A_zz (:meth:`~.influence.InfluenceGrid.normal_preconditioner`), Polak-Ribiere
  beta >= 0; after every step elements with p < 0 leave C (p set to 0) and elements outside C
  with e < 0 enter it, without restarting the recursion. The displacement A p is updated with
  the step (A v is computed for the step length anyway) and corrected by A of the removed
  pressures. Start (approach control): C = {h < 0.4 min h} (the elements whose undeformed
  overlap exceeds 60 % of the largest), p = 0. Stop: no change of C in the step and
  rms_C(p_k - p_{k-1}) <= tolerance rms_C(p_k). Per step: one convolution with A on the
  zero-padded grid, one preconditioner FFT on the grid itself (a quarter of the size), and one more
  convolution in steps that remove elements. Iterations on CONTACT's perfc grids:
  benchmarks/results/bem_norm_scaling.md.
* ``"polonsky-keer"``: the unpreconditioned CG restricted to the current contact set with
  projection onto p >= 0 and re-entry of overlapping elements, force control built in
  (Polonsky & Keer, Wear 231 (1999) 206-219, section 3); two convolutions per iteration. Kept
  as the second method the first is checked against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from rigid_dynamics.contact.bem.influence import InfluenceGrid


@numba.njit(cache=True)
def _direction(u, h, p, t, delta, g_old, force_control, gap):
    """First half of a CG step: gap = A p + h (minus its mean over the active set in force control), new direction t.

    Writes gap and t in place; returns (shift, g_now) with g_now = sum over the active set of gap^2.
    """
    ny, nx = p.shape
    shift = 0.0
    count = 0
    for j in range(ny):
        for i in range(nx):
            gap[j, i] = u[j, i] + h[j, i]
            if p[j, i] > 0:
                shift += gap[j, i]
                count += 1
    if force_control and count > 0:
        shift /= count
        for j in range(ny):
            for i in range(nx):
                gap[j, i] -= shift
    else:
        shift = 0.0
    g_now = 0.0
    for j in range(ny):
        for i in range(nx):
            if p[j, i] > 0:
                g_now += gap[j, i] * gap[j, i]
    beta = delta * g_now / g_old
    for j in range(ny):
        for i in range(nx):
            t[j, i] = gap[j, i] + beta * t[j, i] if p[j, i] > 0 else 0.0
    return shift, g_now


@numba.njit(cache=True)
def _update(r, u, gap, t, p, allowed, force_control, normal_force, area, p_new):
    """Second half of a CG step: step length, projection onto p >= 0, re-entry of overlaps, force scaling.

    ``r`` = A t. Writes the new pressure into p_new; returns (delta, step, residual) as in solve_norm.
    """
    ny, nx = p.shape
    r_mean = 0.0
    count = 0
    for j in range(ny):
        for i in range(nx):
            if p[j, i] > 0:
                r_mean += r[j, i]
                count += 1
    if force_control and count > 0:
        r_mean /= count
    else:
        r_mean = 0.0
    denom = 0.0
    numer = 0.0
    for j in range(ny):
        for i in range(nx):
            if p[j, i] > 0:
                denom += (r[j, i] - r_mean) * t[j, i]
                numer += gap[j, i] * t[j, i]
    tau = numer / denom if denom != 0.0 else 0.0
    overlap = False
    for j in range(ny):
        for i in range(nx):
            q = max(p[j, i] - tau * t[j, i], 0.0) if p[j, i] > 0 else 0.0
            if q == 0.0 and gap[j, i] < 0.0 and allowed[j, i]:
                overlap = True
            p_new[j, i] = q
    if overlap:
        for j in range(ny):
            for i in range(nx):
                if p_new[j, i] == 0.0 and gap[j, i] < 0.0 and allowed[j, i]:
                    p_new[j, i] = -tau * gap[j, i]
    total = 0.0
    for j in range(ny):
        for i in range(nx):
            total += p_new[j, i]
    if force_control:
        factor = normal_force / (area * total)
        total = 0.0
        for j in range(ny):
            for i in range(nx):
                p_new[j, i] *= factor
                total += p_new[j, i]
    diff = 0.0
    u_max = 0.0
    viol = 0.0
    for j in range(ny):
        for i in range(nx):
            diff += abs(p_new[j, i] - p[j, i])
            u_max = max(u_max, abs(u[j, i]))
            if p_new[j, i] > 0:
                viol = max(viol, abs(gap[j, i]))
            elif allowed[j, i]:
                viol = max(viol, -gap[j, i])
    step = diff / max(abs(total), 1e-300)
    residual = viol / max(u_max, 1e-300)
    return (0.0 if overlap else 1.0), step, residual


@numba.njit(cache=True)
def _pcg_direction(z, res, r_prv, v, active, force_control, rz_old, restart):
    """NormCG direction: z (preconditioned residual) masked to C (and mean-free in force control), then
    v = z + beta v with Polak-Ribiere beta = max(0, (z.r - z.r_prev)/rz_old) (beta = 0 on restart).

    Writes z and v in place; returns rz = z.r.
    """
    ny, nx = z.shape
    mean = 0.0
    if force_control:
        count = 0
        for j in range(ny):
            for i in range(nx):
                if active[j, i]:
                    mean += z[j, i]
                    count += 1
        mean = mean / count if count > 0 else 0.0
    rz = 0.0
    zr = 0.0
    for j in range(ny):
        for i in range(nx):
            if active[j, i]:
                z[j, i] -= mean
                rz += z[j, i] * res[j, i]
                zr += z[j, i] * r_prv[j, i]
            else:
                z[j, i] = 0.0
    beta = 0.0 if (restart or rz_old <= 1e-300) else max(0.0, (rz - zr) / rz_old)
    total = 0.0
    count = 0
    for j in range(ny):
        for i in range(nx):
            if active[j, i]:
                v[j, i] = z[j, i] + beta * v[j, i]
                total += v[j, i]
                count += 1
            else:
                v[j, i] = 0.0
    if force_control and count > 0:
        total /= count
        for j in range(ny):
            for i in range(nx):
                if active[j, i]:
                    v[j, i] -= total
    return rz


@numba.njit(cache=True)
def _pcg_step(q, v, res, p, u, r_prv, active, removed):
    """NormCG step: alpha = (r.v)/(v.A v) over C, p += alpha v, u += alpha A v, r_prev = r; elements with p < 0
    leave C (their pressure goes to ``removed``, p to 0).

    Returns (alpha, rms_C(alpha v), rms_C(p), number removed). In force control v is mean-free on C, so
    projecting A v adds nothing to v.A v.
    """
    ny, nx = p.shape
    rv = 0.0
    vav = 0.0
    for j in range(ny):
        for i in range(nx):
            if active[j, i]:
                rv += res[j, i] * v[j, i]
                vav += q[j, i] * v[j, i]
    alpha = rv / vav if vav > 1e-300 else 0.0
    v2 = 0.0
    p2 = 0.0
    count = 0
    n_removed = 0
    for j in range(ny):
        for i in range(nx):
            u[j, i] += alpha * q[j, i]
            r_prv[j, i] = res[j, i]
            removed[j, i] = 0.0
            if active[j, i]:
                p[j, i] += alpha * v[j, i]
                v2 += v[j, i] * v[j, i]
                count += 1
                if p[j, i] < 0.0:
                    removed[j, i] = p[j, i]
                    p[j, i] = 0.0
                    active[j, i] = False
                    n_removed += 1
                p2 += p[j, i] * p[j, i]
    count = max(count, 1)
    return alpha, abs(alpha) * math.sqrt(v2 / count), math.sqrt(p2 / count), n_removed


@numba.njit(cache=True)
def _pcg_gap(u, h, active, allowed, force_control, res, v, allow_entry):
    """Deformed distance e = u + h (minus its mean over C in force control) into res = -e on C; elements
    outside C with e < 0 enter C (with res = -e > 0) if ``allow_entry``; v = 0 outside C.

    Returns (shift, number entered); shift is the mean subtracted (0 in approach control).
    """
    ny, nx = u.shape
    shift = 0.0
    if force_control:
        count = 0
        for j in range(ny):
            for i in range(nx):
                if active[j, i]:
                    shift += u[j, i] + h[j, i]
                    count += 1
        shift = shift / count if count > 0 else 0.0
    entered = 0
    for j in range(ny):
        for i in range(nx):
            gap = u[j, i] + h[j, i] - shift
            if active[j, i]:
                res[j, i] = -gap
            elif allow_entry and allowed[j, i] and gap < 0.0:
                active[j, i] = True
                res[j, i] = -gap
                entered += 1
            else:
                res[j, i] = 0.0
                v[j, i] = 0.0
    return shift, entered


@numba.njit(cache=True)
def _subtract_sparse(u, removed, kernel):
    """Subtract A removed from u in place, for a field ``removed`` with few non-zeros.

    Direct sums over the kernel (offsets [dj + ny - 1, di + nx - 1]); cheaper than a convolution for up to a
    few dozen non-zeros.
    """
    ny, nx = u.shape
    for jk in range(ny):
        for ik in range(nx):
            value = removed[jk, ik]
            if value != 0.0:
                for j in range(ny):
                    row = j - jk + ny - 1
                    for i in range(nx):
                        u[j, i] -= kernel[row, i - ik + nx - 1] * value


@dataclass(frozen=True, eq=False)
class NormSolution:
    """Result of :func:`solve_norm`.

    Attributes:
        pressure_Pa: p, shape (ny, nx), Pa.
        deformed_distance_m: e = h + A p - d, shape (ny, nx), m (inf where h is inf).
        approach_shift_m: d, the extra approach found in force control (0 in approach control), m.
        normal_force_N: dA sum p, N (N/m in the 2-D mode).
        iterations: CG iterations.
        residual: max complementarity violation max(max_{p>0}|e|, max_{p=0} -e) over max|A p|.
        converged: residual and step below the tolerance within the iteration limit.
    """

    pressure_Pa: np.ndarray
    deformed_distance_m: np.ndarray
    approach_shift_m: float
    normal_force_N: float
    iterations: int
    residual: float
    converged: bool


SPARSE_CORRECTION_LIMIT = 24
"""NormCG corrects A p for up to this many removed elements by direct sums, beyond by a convolution."""

START_SET_FRACTION = 0.6
"""NormCG's first contact set {h - min h < 0.6 delta} (delta the approach; Hertz's contact is 0.5 delta)."""

METHODS = ("normcg", "polonsky-keer")
"""Names of the NORM solvers (module docstring)."""


def solve_norm(
    influence: InfluenceGrid,
    undeformed_distance_m: np.ndarray,
    *,
    normal_force_N: float | None = None,
    tolerance: float = 1e-9,
    max_iterations: int = 1000,
    tractions_Pa: tuple[np.ndarray, np.ndarray] | None = None,
    initial_pressure_Pa: np.ndarray | None = None,
    method: str = "normcg",
) -> NormSolution:
    """Solve NORM (module docstring) by preconditioned NormCG-type CG or the Polonsky-Keer CG.

    Args:
        influence: grid and influence coefficients (nx x ny).
        undeformed_distance_m: h at element centres, shape (ny, nx), m; +inf where the
            surfaces are not defined (those elements never carry pressure).
        normal_force_N: None for approach control, else the total normal force F_N > 0, N.
        tolerance: relative tolerance on the pressure update (rms over the contact set for
            ``"normcg"``, l1 for ``"polonsky-keer"``, whose complementarity residual must also be
            below 100 tolerance).
        max_iterations: iteration limit (non-convergence is reported, not raised).
        tractions_Pa: (t_x, t_y) whose normal displacement (Kalker's K != 0) is added to h.
        initial_pressure_Pa: starting pressure (e.g. the previous solution), optional.
        method: ``"normcg"`` (default) or ``"polonsky-keer"``.

    Returns:
        :class:`NormSolution`.
    """
    h = np.asarray(undeformed_distance_m, float)
    shape = (influence.ny, influence.nx)
    if h.shape != shape:
        raise ValueError(f"undeformed_distance_m has shape {h.shape}: expected (ny, nx) = {shape}")
    if normal_force_N is not None and (not math.isfinite(normal_force_N) or normal_force_N <= 0):
        raise ValueError(f"normal_force_N = {normal_force_N!r}: expected None or a finite number > 0")
    if not tolerance > 0:
        raise ValueError(f"tolerance = {tolerance!r}: expected > 0")
    if int(max_iterations) < 1:
        raise ValueError(f"max_iterations = {max_iterations!r}: expected >= 1")
    if method not in METHODS:
        raise ValueError(f"method = {method!r}: expected one of {', '.join(METHODS)}")
    allowed = np.isfinite(h)
    if np.isnan(h).any():
        raise ValueError("undeformed_distance_m contains NaN: expected finite values or +inf")
    h = np.where(allowed, h, 0.0)
    if tractions_Pa is not None and influence.difference_parameter != 0.0:
        h = h + influence.normal(np.zeros(shape), tractions_Pa[0], tractions_Pa[1])
    area = influence.dx_m * (1.0 if influence.plane else influence.dy_m)
    force_control = normal_force_N is not None

    if initial_pressure_Pa is not None:
        p = np.where(allowed, np.maximum(np.asarray(initial_pressure_Pa, float), 0.0), 0.0)
    else:
        p = np.zeros(shape)
    start_set = None
    if not p.any():
        if method == "normcg" and not influence.plane:
            e_star = influence.shear_modulus_Pa / (1.0 - influence.poisson_ratio)
            p = _hertz_start(h, allowed, area, e_star, normal_force_N)
        elif force_control:
            # Hertz-like start: p ~ sqrt(level - h) inside the level set halfway between min h and max h
            # (for a quadric h over its ellipse's bounding box this is the Hertz pressure's shape)
            level = np.min(h[allowed]) + 0.5 * (np.max(h[allowed]) - np.min(h[allowed]))
            candidates = allowed & (h < level)
            p = np.where(candidates, np.sqrt(np.where(candidates, level - h, 0.0)), 0.0)
            if not p.any():
                p = np.where(allowed & (h <= level), 1.0, 0.0)
        else:
            p = np.where(allowed & (h < 0), -h / influence.self_coefficient("zz"), 0.0)
    if force_control:
        p *= normal_force_N / (area * p.sum())
    if not p.any() and start_set is None:
        # approach control with no overlap: the bodies do not touch
        return NormSolution(np.zeros(shape), np.where(allowed, h, np.inf), 0.0, 0.0, 0, 0.0, True)
    normal_force = float(normal_force_N) if force_control else 0.0
    solver = _normcg if method == "normcg" else _polonsky_keer
    p, it, residual, converged, shift = solver(
        influence, h, p, allowed, start_set, force_control, normal_force, area, tolerance, int(max_iterations)
    )
    u = influence.normal(p)
    gap = u + h - shift
    if method == "normcg":
        residual = _complementarity_residual(p, gap, allowed, u)
    gap = np.where(allowed, gap, np.inf)
    force = float(area * p.sum())
    return NormSolution(p, gap, shift, force, it, residual, converged)


def _hertz_start(h, allowed, cell_area, e_star, normal_force_N) -> np.ndarray:
    """Starting pressure from Hertz's relations applied to the sampled h.

    For an approach delta (the largest overlap -min h in approach control; in force control the delta
    whose estimate below gives F_N, by bisection) Hertz's contact is {h - min h < delta/2}, of area A, and
    F = 4/(3 sqrt(pi)) E* sqrt(A) delta (Johnson 1985, eq 4.22-4.23 with A = pi a^2, delta = a^2/R). The
    start is the Hertz-shaped p ~ sqrt(1 - (h - min h)/(0.6 delta)) with that force, on a set a little
    larger than Hertz's ({h - min h < 0.6 delta}, the 60 % of CONTACT's first guess of the contact set):
    the method removes surplus elements in one step but adds missing ones ring by ring (on CONTACT's perfc
    grids 0.6 needs 0-4 iterations fewer than 0.5). Returns zeros if nothing overlaps.
    """
    h_min = float(np.min(h[allowed]))
    rise = np.sort(h[allowed] - h_min)

    def force(delta: float) -> tuple[float, int]:
        count = int(np.searchsorted(rise, 0.5 * delta))
        return 4.0 / (3.0 * math.sqrt(math.pi)) * e_star * math.sqrt(max(count, 1) * cell_area) * delta, count

    if normal_force_N is None:
        delta = -h_min
        if delta <= 0.0:
            return np.zeros(h.shape)
    else:
        low, high = 0.0, max(float(rise[-1]), 1e-300)
        while force(high)[0] < normal_force_N and high < 1e3:
            high *= 2.0
        for _ in range(60):
            delta = 0.5 * (low + high)
            if force(delta)[0] < normal_force_N:
                low = delta
            else:
                high = delta
        delta = high
    total, _ = force(delta)
    inside = allowed & (h - h_min < START_SET_FRACTION * delta)
    shape = np.sqrt(np.clip(1.0 - (h - h_min) / (START_SET_FRACTION * delta), 0.0, None))
    p = np.where(inside, shape, 0.0)
    if not p.any():
        p = np.where(allowed & (h <= h_min), 1.0, 0.0)
    return p * (total / (cell_area * p.sum()))


def _complementarity_residual(p, gap, allowed, u) -> float:
    """max(max_{p>0} |e|, max_{p=0} -e) over max |A p| (0 for no contact)."""
    u_max = float(np.abs(u).max())
    if u_max == 0.0:
        return 0.0
    viol = 0.0
    loaded = p > 0
    if loaded.any():
        viol = float(np.abs(gap[loaded]).max())
    free = allowed & ~loaded
    if free.any():
        viol = max(viol, float(-gap[free].min()))
    return viol / u_max


def _normcg(influence, h, p, allowed, start_set, force_control, normal_force, area, tolerance, max_iterations):
    """Preconditioned bound-constrained CG (module docstring); returns (p, iterations, residual, converged, shift)."""
    shape = p.shape
    active = (p > 0) if start_set is None else start_set.copy()
    u = influence.normal(p) if p.any() else np.zeros(shape)
    res = np.empty(shape)
    v = np.zeros(shape)
    r_prv = np.zeros(shape)
    removed = np.empty(shape)
    kernel = influence.kernel("zz")
    shift, _ = _pcg_gap(u, h, active, allowed, force_control, res, v, False)
    rz = 0.0
    restart = True
    converged = False
    rms_upd = rms_p = math.inf
    it = 0
    for it in range(1, max_iterations + 1):  # noqa: B007 (the count is returned)
        z = influence.normal_preconditioner(res, reuse=True)  # both consumed at once: in the grid's buffers
        rz = _pcg_direction(z, res, r_prv, v, active, force_control, rz, restart)
        restart = False
        q = influence.normal(v, reuse=True)
        _alpha, rms_upd, rms_p, n_removed = _pcg_step(q, v, res, p, u, r_prv, active, removed)
        if n_removed:
            if n_removed <= SPARSE_CORRECTION_LIMIT and not getattr(influence, "reduced_interaction", False):
                _subtract_sparse(u, removed, kernel)
            else:
                u -= influence.normal(removed)
            if not active.any():
                # every element left: restart from the deepest overlap (CONTACT does the same)
                h_min = float(np.min(h[allowed]))
                active = allowed & (h <= h_min + 1e-9 * max(abs(h_min), 1e-12))
                restart = True
            if force_control:
                total = float(p.sum())
                if total <= 0.0:
                    p = np.where(active, 1.0, 0.0)
                    total = float(p.sum())
                    u = influence.normal(p)
                factor = normal_force / (area * total)
                p *= factor
                u *= factor
        shift, n_entered = _pcg_gap(u, h, active, allowed, force_control, res, v, True)
        if n_removed == 0 and n_entered == 0 and rms_upd <= tolerance * rms_p:
            converged = True
            break
    return p, it, math.nan, converged, shift


def _polonsky_keer(influence, h, p, allowed, start_set, force_control, normal_force, area, tolerance, max_iterations):
    """Polonsky-Keer CG (module docstring); returns (p, iterations, residual, converged, shift)."""
    shape = p.shape
    t = np.zeros(shape)
    gap = np.empty(shape)
    p_new = np.empty(shape)
    g_old = 1.0
    delta = 0.0
    shift = 0.0
    converged = False
    residual = math.inf
    it = 0
    for it in range(1, max_iterations + 1):  # noqa: B007 (the count is returned)
        u = influence.normal(p)
        shift, g_now = _direction(u, h, p, t, delta, g_old, force_control, gap)
        g_old = max(g_now, 1e-300)
        r = influence.normal(t)
        delta, step, residual = _update(r, u, gap, t, p, allowed, force_control, normal_force, area, p_new)
        p, p_new = p_new, p
        if step < tolerance and residual < 100 * tolerance:
            converged = True
            break
        if not p.any():
            break
    return p, it, residual, converged, shift
