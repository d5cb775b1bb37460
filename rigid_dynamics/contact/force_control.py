"""Traction and braking to a prescribed longitudinal force: the creepage that transmits a given force.

CONTACT's force control (its F = 1 digit: the total longitudinal force prescribed, the longitudinal creepage
solved) as a one-dimensional root: F_x(xi) = F_target, with F_x the creep force on the wheel along the rolling
direction (N; it falls as xi rises: F_x = -mu N in full slip at xi > 0). The root is bracketed by creepages
growing geometrically from zero in the direction that moves F_x towards the target, and then found by Brent's
method (scipy.optimize.brentq). The first bracket is taken, so the root is the smallest creepage that transmits the
force: the stable one on the rising branch of a falling creep curve (beyond its maximum a falling law has a second
root, not sought). When the force turns away from the target between two bracket points (a falling curve passed
its maximum), the extremum between them is found (scipy.optimize.minimize_scalar, bounded) and either brackets the
root with the point before, or is the largest force the curve transmits. A force beyond the largest the curve
reaches within ``max_creepage`` is a status, not a number.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

STATUSES = ("ok", "not-attainable", "not-converged")


class ForceControlOutcome(NamedTuple):
    """The solved creepage and how well it holds.

    Fields:

    * ``status``: "ok", "not-attainable" (no creepage up to ``max_creepage`` reaches the force: ``creepage`` is the
      one of the largest force found) or "not-converged" (the creep-force evaluation failed);
    * ``creepage``: the solved longitudinal creepage xi (-);
    * ``force_N``: F_x at that creepage, N; ``residual_N``: force_N - target, N;
    * ``evaluations``: creep-force evaluations; ``message``: one line saying what happened.
    """

    status: str
    creepage: float
    force_N: float
    residual_N: float
    evaluations: int
    message: str


def solve_for_force(
    force_of: Callable[[float], float],
    target_N: float,
    *,
    force_tolerance_N: float,
    first_creepage: float = 1e-5,
    max_creepage: float = 0.2,
) -> ForceControlOutcome:
    """The longitudinal creepage xi with ``force_of(xi)`` = ``target_N`` (module docstring).

    Args:
        force_of: xi -> F_x on the wheel (N), decreasing with xi near the root; may raise ValueError or return nan
            when its solve fails (-> "not-converged").
        target_N: the prescribed F_x, N.
        force_tolerance_N: accepted |F_x - target|, N (> 0), e.g. 1e-4 mu N.
        first_creepage: the first creepage of the bracket search (> 0).
        max_creepage: the largest |xi| tried.
    """
    if not (math.isfinite(target_N) and force_tolerance_N > 0 and 0 < first_creepage < max_creepage):
        raise ValueError(
            f"target_N = {target_N!r}, force_tolerance_N = {force_tolerance_N!r}, first_creepage = "
            f"{first_creepage!r}, max_creepage = {max_creepage!r}: expected a finite target, a tolerance > 0 and "
            "0 < first_creepage < max_creepage"
        )
    from scipy.optimize import brentq, minimize_scalar

    count = 0

    def residual(xi: float) -> float:
        nonlocal count
        count += 1
        value = float(force_of(xi))
        if not math.isfinite(value):
            raise ValueError(f"the creep force at xi = {xi!r} is {value!r}")
        return value - target_N

    def outcome(status, xi, res, message):
        return ForceControlOutcome(status, float(xi), float(res + target_N), float(res), count, message)

    def self_root(a: float, b: float) -> ForceControlOutcome:
        """Brent's method on the bracket [a, b] (residuals of opposite signs at its ends)."""
        ra = residual(a)
        rb = residual(b)
        if abs(rb) <= force_tolerance_N:
            return outcome("ok", b, rb, f"the force holds at xi = {b:.6g}")
        root = brentq(residual, a, b, xtol=1e-12, rtol=1e-10, maxiter=100)
        r_root = residual(root)
        if abs(r_root) > force_tolerance_N and (ra > 0) != (rb > 0):  # the creepage tolerance met first: refine
            root = brentq(residual, a, b, xtol=1e-15, rtol=4.5e-16, maxiter=200)
            r_root = residual(root)
        status = "ok" if abs(r_root) <= force_tolerance_N else "not-converged"
        return outcome(status, root, r_root, f"Brent's method on xi in [{a:.6g}, {b:.6g}]")

    try:
        r0 = residual(0.0)
        if abs(r0) <= force_tolerance_N:
            return outcome("ok", 0.0, r0, "the force holds at zero creepage")
        direction = 1.0 if r0 > 0 else -1.0  # F_x falls with xi: a force above the target needs xi > 0
        low, r_low = 0.0, r0
        previous = 0.0
        best = (abs(r0), 0.0, r0)
        xi = first_creepage
        while xi <= max_creepage * (1 + 1e-12):
            r = residual(direction * xi)
            best = min(best, (abs(r), direction * xi, r))
            if abs(r) <= force_tolerance_N:
                return outcome("ok", direction * xi, r, "the force holds at a bracket point")
            if (r > 0) != (r_low > 0):
                return self_root(low, direction * xi)
            if abs(r) > abs(r_low) and low != 0.0:
                # moving away from the target: the creep curve passed its extremum in (previous, xi)
                sign = 1.0 if r > 0 else -1.0
                turn = minimize_scalar(
                    lambda s, sign=sign: sign * residual(s),
                    bounds=sorted((previous, direction * xi)),
                    method="bounded",
                    options={"xatol": 1e-3 * first_creepage},
                )
                r_turn = residual(float(turn.x))
                best = min(best, (abs(r_turn), float(turn.x), r_turn))
                if (r_turn > 0) != (r_low > 0) or abs(r_turn) <= force_tolerance_N:
                    return self_root(previous, float(turn.x))
                break
            previous = low
            low, r_low = direction * xi, r
            xi *= 2.0
    except ValueError as exc:
        return ForceControlOutcome("not-converged", math.nan, math.nan, math.nan, count, str(exc))
    _, xi_best, r_best = best
    return outcome(
        "not-attainable",
        xi_best,
        r_best,
        f"no creepage up to {max_creepage:g} transmits {target_N:.6g} N (closest: {r_best + target_N:.6g} N at "
        f"xi = {xi_best:.6g})",
    )
