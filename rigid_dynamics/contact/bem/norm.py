"""NORM: the normal contact problem on a grid of rectangular elements.

Find the pressure p (Pa, piecewise constant per element) with::

    e = h + A p - d >= 0,   p >= 0,   p e = 0   (element-wise, at element centres)

h the undeformed distance (m, with the geometry's approach already subtracted), A the
normal influence operator (:class:`~.influence.InfluenceGrid`, m/Pa), e the deformed distance.
Approach control: d = 0 (the approach is the geometry's). Force control: d (m) is an extra
unknown fixed by ``dA sum p = F_N`` (the approach becomes q + d).

Method: conjugate gradients restricted to the current contact set with projection onto p >= 0
and re-entry of overlapping elements, force control built in (Polonsky & Keer, Wear 231 (1999)
206-219, section 3). Each iteration costs two FFT convolutions (O(N log N)) and two numba passes over
the grid (direction, then step/projection/force scaling); the iteration count
grows only mildly with N (see benchmarks/results/bem.md).
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


def solve_norm(
    influence: InfluenceGrid,
    undeformed_distance_m: np.ndarray,
    *,
    normal_force_N: float | None = None,
    tolerance: float = 1e-9,
    max_iterations: int = 1000,
    tractions_Pa: tuple[np.ndarray, np.ndarray] | None = None,
    initial_pressure_Pa: np.ndarray | None = None,
) -> NormSolution:
    """Solve NORM by the Polonsky-Keer CG active-set method.

    Args:
        influence: grid and influence coefficients (nx x ny).
        undeformed_distance_m: h at element centres, shape (ny, nx), m; +inf where the
            surfaces are not defined (those elements never carry pressure).
        normal_force_N: None for approach control, else the total normal force F_N > 0, N.
        tolerance: relative tolerance on the pressure update and the complementarity residual.
        max_iterations: iteration limit (non-convergence is reported, not raised).
        tractions_Pa: (t_x, t_y) whose normal displacement (Kalker's K != 0) is added to h.
        initial_pressure_Pa: starting pressure (e.g. the previous solution), optional.

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
    if not p.any():
        if force_control:
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
    if not p.any():
        # approach control with no overlap: the bodies do not touch
        return NormSolution(np.zeros(shape), np.where(allowed, h, np.inf), 0.0, 0.0, 0, 0.0, True)

    t = np.zeros(shape)
    gap = np.empty(shape)
    p_new = np.empty(shape)
    g_old = 1.0
    delta = 0.0
    shift = 0.0
    converged = False
    residual = math.inf
    it = 0
    normal_force = float(normal_force_N) if force_control else 0.0
    for it in range(1, int(max_iterations) + 1):  # noqa: B007 (the count is returned)
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
    u = influence.normal(p)
    gap = u + h - shift
    gap = np.where(allowed, gap, np.inf)
    force = float(area * p.sum())
    return NormSolution(p, gap, shift, force, it, residual, converged)
