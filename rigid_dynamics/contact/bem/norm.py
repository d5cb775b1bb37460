"""NORM: the normal contact problem on a grid of rectangular elements.

Find the pressure p (Pa, piecewise constant per element) with::

    e = h + A p - d >= 0,   p >= 0,   p e = 0   (element-wise, at element centres)

h the undeformed distance (m, with the geometry's approach already subtracted), A the
normal influence operator (:class:`~.influence.InfluenceGrid`, m/Pa), e the deformed distance.
Approach control: d = 0 (the approach is the geometry's). Force control: d (m) is an extra
unknown fixed by ``dA sum p = F_N`` (the approach becomes q + d).

Method: conjugate gradients restricted to the current contact set with projection onto p >= 0
and re-entry of overlapping elements, force control built in (Polonsky & Keer, Wear 231 (1999)
206-219, section 3). Each iteration costs two FFT convolutions (O(N log N)); the iteration count
grows only mildly with N (see benchmarks/results/bem.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.bem.influence import InfluenceGrid


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
            candidates = allowed & (h <= np.min(h[allowed]) + 0.5 * (np.max(h[allowed]) - np.min(h[allowed])))
            p = np.where(candidates, 1.0, 0.0)
        else:
            p = np.where(allowed & (h < 0), -h / influence.self_coefficient("zz"), 0.0)
    if force_control:
        p *= normal_force_N / (area * p.sum())
    if not p.any():
        # approach control with no overlap: the bodies do not touch
        return NormSolution(np.zeros(shape), np.where(allowed, h, np.inf), 0.0, 0.0, 0, 0.0, True)

    t = np.zeros(shape)
    g_old = 1.0
    delta = 0.0
    shift = 0.0
    converged = False
    residual = math.inf
    it = 0
    for it in range(1, int(max_iterations) + 1):  # noqa: B007 (the count is returned)
        u = influence.normal(p)
        gap = u + h
        active = p > 0
        if force_control:
            shift = float(gap[active].mean())
            gap = gap - shift
        g_now = float(np.sum(gap[active] ** 2))
        t = np.where(active, gap + (delta * g_now / g_old) * t, 0.0)
        g_old = max(g_now, 1e-300)
        r = influence.normal(t)
        if force_control:
            r = r - r[active].mean()
        denom = float(np.sum(r[active] * t[active]))
        tau = float(np.sum(gap[active] * t[active])) / denom if denom != 0.0 else 0.0
        p_old = p
        p = np.where(active, p - tau * t, 0.0)
        p = np.maximum(p, 0.0)
        overlap = (p == 0.0) & (gap < 0.0) & allowed
        if overlap.any():
            delta = 0.0
            p = np.where(overlap, p - tau * gap, p)
        else:
            delta = 1.0
        if force_control:
            p *= normal_force_N / (area * p.sum())
        step = float(np.abs(p - p_old).sum() / max(np.abs(p).sum(), 1e-300))
        scale = max(float(np.abs(u).max()), 1e-300)
        in_c = p > 0
        viol_c = float(np.abs(gap[in_c]).max()) if in_c.any() else 0.0
        viol_n = float(np.maximum(-gap[~in_c & allowed], 0.0).max()) if (~in_c & allowed).any() else 0.0
        residual = max(viol_c, viol_n) / scale
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
