"""The largest stable fixed step of the classical RK4 method for a run, from its linearisation at the start.

A fixed-step run whose step is beyond the stability limit of its stiffest mode does not give a wrong number
slowly: the mode grows without bound and the run ends as a "blow-up", "force-anomaly" or "derailed" that has
nothing to do with the physics. The stiff modes of a wheelset run are the contact springs (Hertz, linearised at
the static load) against the wheelset and, on an elastic track, against the rail mass (~700 Hz).

:func:`rk4_stable_step` linearises the right-hand side ``f(y)`` at a state by central differences (the Jacobian),
takes its eigenvalues and returns the largest h with |R(h lambda)| <= 1 for all of them, where
R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 is RK4's stability function (Hairer & Wanner, Solving ODEs II, IV.2):
on the imaginary axis |R(iy)| <= 1 up to y = 2 sqrt(2), on the negative real axis up to 2.785. Eigenvalues of
modulus below ``floor_1_per_s`` (rigid-body and work-integral states) are ignored.

The limit is that of the linearisation at the given state: the Hertz spring stiffens as N^(1/3), so at an
impact of k times the static load the stiffest contact mode is k^(1/6) faster (1.23x at 3.5x the load) and
the limit that much smaller.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

_RADII = np.linspace(1e-3, 3.0, 3000)
"""Scan of |z| along each eigenvalue's ray (RK4's stability region lies within |z| < 3)."""


def rk4_amplification(z: np.ndarray | complex) -> np.ndarray:
    """RK4's stability function R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24."""
    z = np.asarray(z, dtype=complex)
    return 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)))


def _ray_limit(direction: complex) -> float:
    """The largest r with |R(r e)| <= 1 on [0, r] for the unit direction e (0 if the ray leaves at once)."""
    inside = np.abs(rk4_amplification(_RADII * direction)) <= 1.0 + 1e-12
    if inside.all():
        return float(_RADII[-1])
    first_out = int(np.argmin(inside))
    return float(_RADII[first_out - 1]) if first_out > 0 else 0.0


@dataclass(frozen=True)
class StepLimit:
    """The RK4 stability limit of a linearised run.

    Attributes:
        max_step_s: the largest stable fixed step, s (inf when no eigenvalue is above the floor).
        frequency_hz: |Im lambda| / 2 pi of the eigenvalue that sets it, Hz.
        damping_ratio: -Re lambda / |lambda| of that eigenvalue.
        eigenvalue: that eigenvalue, 1/s.
        where: the state linearised, in words ("at the start" unless said otherwise).
    """

    max_step_s: float
    frequency_hz: float
    damping_ratio: float
    eigenvalue: complex
    where: str = "at the start"

    def describe(self) -> str:
        """The limit and the mode that sets it, in words."""
        if self.frequency_hz > 0.0:
            mode = f"the {self.frequency_hz:.0f} Hz mode, damping ratio {self.damping_ratio:.2g}"
        else:
            mode = f"a non-oscillating mode decaying at {abs(self.eigenvalue.real):.3g} 1/s"
        return f"RK4's stability limit {1e3 * self.max_step_s:.3g} ms (set by {mode}, linearised {self.where})"


def jacobian(
    fun: Callable[[np.ndarray], np.ndarray], y: np.ndarray, rel_step: float = 1e-8, columns=None
) -> np.ndarray:
    """Central-difference Jacobian of ``fun`` at ``y``; column j with the step rel_step (1 + |y_j|). ``columns``:
    only these columns (the others are left zero).
    """
    y = np.asarray(y, dtype=float)
    jac = np.zeros((len(fun(y)), len(y)))
    for j in range(len(y)) if columns is None else columns:
        h = rel_step * (1.0 + abs(y[j]))
        up, down = y.copy(), y.copy()
        up[j] += h
        down[j] -= h
        jac[:, j] = (np.asarray(fun(up)) - np.asarray(fun(down))) / (2.0 * h)
    return jac


LARGEST_EIGENVALUES = 24
"""Above 200 states (an elastic beam track) only this many eigenvalues of largest magnitude are computed (ARPACK)."""


def _largest_eigenvalues(matrix: np.ndarray) -> np.ndarray:
    """The eigenvalues that can set RK4's limit: all of them up to 200 states; above, the LARGEST_EIGENVALUES of
    largest magnitude (scipy.sparse.linalg.eigs), all of them if ARPACK does not converge. RK4's stability region
    reaches between 2.785 (negative real axis) and 2.828 (imaginary axis) times 1/|lambda| along every ray of the
    left half-plane, so the limit comes from the largest |lambda| to within 2 %; a growing (right half-plane) mode
    is an oscillation of the wheelset, slow against the track's modes.
    """
    n = len(matrix)
    if n <= 200:
        return np.linalg.eigvals(matrix)
    from scipy.sparse.linalg import ArpackNoConvergence, eigs

    try:
        return eigs(matrix, k=LARGEST_EIGENVALUES, which="LM", return_eigenvectors=False, tol=1e-8)
    except ArpackNoConvergence:
        return np.linalg.eigvals(matrix)


def rk4_stable_step(
    fun: Callable[[np.ndarray], np.ndarray], y: np.ndarray, floor_1_per_s: float = 1.0, jac: Callable | None = None
) -> StepLimit:
    """The RK4 stability limit of ``y' = fun(y)`` linearised at ``y`` (module docstring). ``jac(fun, y)``: the
    Jacobian if not :func:`jacobian` (e.g. one that uses the structure of the state,
    wheelset_model.WheelsetModel.state_jacobian).
    """
    eigenvalues = _largest_eigenvalues((jac or jacobian)(fun, y))
    best = StepLimit(math.inf, 0.0, 1.0, 0j)
    for lam in eigenvalues:
        size = abs(lam)
        if not np.isfinite(size) or size < floor_1_per_s:
            continue
        if lam.real > 0:
            # a growing mode is physics (hunting above the critical speed), not the integrator's: its step limit is
            # that of the oscillation (the imaginary axis); a real growing mode has none
            if lam.imag == 0:
                continue
            step = _ray_limit(1j * math.copysign(1.0, lam.imag)) / abs(lam.imag)
        else:
            step = _ray_limit(lam / size) / size
        if step < best.max_step_s:
            best = StepLimit(float(step), float(abs(lam.imag)) / (2.0 * math.pi), float(-lam.real / size), complex(lam))
    return best


NUMERICAL_LOOKING = ("blow-up", "force-anomaly", "derailed", "solver-failed")
"""Run statuses that an unstable fixed step produces without any physics behind them."""


def judge_fixed_step(
    status: str, message: str, step_s: float, limit: StepLimit, diverged: bool = False
) -> tuple[str, str]:
    """(status, message) of a fixed-step run given its step and its :class:`StepLimit`.

    A step within the limit changes nothing. Beyond it: a blow-up, force anomaly, derailment or solver failure, or
    a run that reached its end with a diverged force error estimate (``diverged``: above ten static wheel loads,
    simulate.STEP_ERROR_DIVERGED) becomes ``"step-unstable"`` (the integrator, not the wheelset, diverged; the
    original status is kept in the message); an ``ok`` run becomes ``"warning"`` (a stiff mode is integrated
    outside RK4's stability region, so its numbers are not to be trusted even when nothing grew); any other status
    keeps its name and gets the note.
    """
    if not step_s > limit.max_step_s:
        return status, message
    note = (
        f"the fixed step {1e3 * step_s:.3g} ms is {step_s / limit.max_step_s:.2g} x {limit.describe()}; "
        f"use fixed_step_s <= {limit.max_step_s:.2g} s"
    )
    if status in NUMERICAL_LOOKING or diverged:
        return "step-unstable", f"{status} ({message}) is numerical: {note}"
    if status == "ok":
        return "warning", f"{message}; {note}" if message else note
    return status, f"{message}; {note}"
