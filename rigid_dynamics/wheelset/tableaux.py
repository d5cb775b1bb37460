"""The explicit Runge-Kutta methods of the compiled loop (compiled_loop.embedded_run) as :class:`Tableau` records
(:data:`TABLEAUX`; Butcher tableaux below, module constants with their sources;
tests/test_dynamics_adaptive.py checks their order conditions and observed orders):

* ``DP54``: Dormand & Prince, "A family of embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6 (1980) 19-26
  (the 5th-order solution is propagated, the 4th-order one estimates the error; 6 new right-hand sides per step,
  first-same-as-last), dense output of order 4 by Shampine's interpolant ("Some practical Runge-Kutta formulas",
  Math. Comp. 46 (1986) 135-150; the coefficients of Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., II.6,
  as scipy's RK45 uses them);
* ``BS32``: Bogacki & Shampine, "A 3(2) pair of Runge-Kutta formulas", Appl. Math. Lett. 2 (1989) 321-325
  (3 new right-hand sides per step, first-same-as-last), dense output by cubic Hermite interpolation between the
  step's ends (order 3);
* ``RK4``: the classical Runge-Kutta method of order 4 with a fixed step (compiled_loop.FIXED_STEP), written
  first-same-as-last with a fifth stage k5 = f(t + h, y4), the next step's k1 (4 new right-hand sides per step, as
  the classical method), its rows as integers over their common denominator, y4 = y + h/6 (k1 + 2 k2 + 2 k3 + k4)
  as the formula is written. Its embedded third-order formula y3 = y + h (k1/6 + k2/3 + k3/3 + k5/6) (Hairer,
  Norsett & Wanner I, II.4) is the error indicator, not a step control: the force error estimate (the per-wheel
  contact forces at y4 and y3, drivers.force_error_check) every ``check_every`` steps and at every sample, a sample
  carrying the largest since the previous one. The step's times are t0 + n h; nothing is rejected or located (a
  failed stage or a non-finite state ends the run with its status); the samples lie on step ends (multiples of the
  step).
"""

from __future__ import annotations

import math
from fractions import Fraction as F
from typing import NamedTuple

import numpy as np


class Tableau(NamedTuple):
    """An explicit Runge-Kutta method as the compiled loop takes it (:func:`_tableau`): A (s, s) whose last row is
    the propagated weights b, each row i as ``a[i] / d[i]`` (the stage's state is y + (h / d_i) sum_j a_ij k_j;
    d = 1 for the pairs, RK4's rows as integers over their common denominator), the nodes c, the error weights
    e = b - b_hat, the dense output P (s, 4), k = the order of the error estimate + 1 (the controller's exponent),
    and b_hat once more as each weight's numerator over its denominator (the embedded solution of the force error
    estimate, y + h sum_j (n_j k_j) / d_j: RK4's y + h (k1/6 + k2/3 + k3/3 + k5/6) as the formula is written).
    """

    a: np.ndarray
    d: np.ndarray
    c: np.ndarray
    e: np.ndarray
    p: np.ndarray
    k_order: float
    b_hat_num: np.ndarray
    b_hat_den: np.ndarray


def _tableau(a_rows, b_hat, k_order, p_rows=None, integer_rows=False):
    """The :class:`Tableau` of an FSAL pair from its rows of A (the last row is b), the embedded weights b_hat, k (the
    order of the error estimate + 1) and the dense-output matrix P (coefficients of theta, theta^2, theta^3,
    theta^4; None: cubic Hermite between the step's ends, exact in Fractions). ``integer_rows``: each row of A as
    integers over its common denominator d_i (RK4: y + h/6 (k1 + 2 k2 + 2 k3 + k4) as the formula is written);
    else d = 1 and the rows as their fractions' floats.
    """
    s = len(a_rows)
    a = [[F(0)] * s for _ in range(s)]
    for i, row in enumerate(a_rows):
        for j, v in enumerate(row):
            a[i][j] = F(v)
    b = a[s - 1]
    d = [math.lcm(*(v.denominator for v in row)) if integer_rows else 1 for row in a]
    c = [sum(row, F(0)) for row in a]
    e = [b[j] - F(b_hat[j]) for j in range(s)]
    if p_rows is None:
        # y(theta) = y0 + h [h01 sum b_i k_i + h10 k_1 + h11 k_s] with the Hermite basis h01 = 3t^2 - 2t^3,
        # h10 = t - 2t^2 + t^3, h11 = t^3 - t^2 (k_1 = f(y0), k_s = f(y1) for an FSAL pair)
        p_rows = [[0, 3 * b[j], -2 * b[j], 0] for j in range(s)]
        p_rows[0] = [p_rows[0][0] + 1, p_rows[0][1] - 2, p_rows[0][2] + 1, 0]
        p_rows[s - 1] = [p_rows[s - 1][0], p_rows[s - 1][1] - 1, p_rows[s - 1][2] + 1, 0]
    as_float = np.array([[float(v * d[i]) for v in row] for i, row in enumerate(a)])
    return Tableau(
        as_float,
        np.array([float(v) for v in d]),
        np.array([float(v) for v in c]),
        np.array([float(v) for v in e]),
        np.array([[float(F(v)) for v in row] for row in p_rows]),
        float(k_order),
        np.array([float(F(v).numerator) for v in b_hat]),
        np.array([float(F(v).denominator) for v in b_hat]),
    )


DP54_A = (
    (),
    (F(1, 5),),
    (F(3, 40), F(9, 40)),
    (F(44, 45), F(-56, 15), F(32, 9)),
    (F(19372, 6561), F(-25360, 2187), F(64448, 6561), F(-212, 729)),
    (F(9017, 3168), F(-355, 33), F(46732, 5247), F(49, 176), F(-5103, 18656)),
    (F(35, 384), F(0), F(500, 1113), F(125, 192), F(-2187, 6784), F(11, 84)),
)
"""Dormand-Prince 5(4): rows of A; the last row is the 5th-order weights b (FSAL) (Dormand & Prince 1980, table 2)."""
DP54_B_HAT = (F(5179, 57600), 0, F(7571, 16695), F(393, 640), F(-92097, 339200), F(187, 2100), F(1, 40))
"""Dormand-Prince 5(4): the embedded 4th-order weights."""
DP54_P = (
    (1, F(-8048581381, 2820520608), F(8663915743, 2820520608), F(-12715105075, 11282082432)),
    (0, 0, 0, 0),
    (0, F(131558114200, 32700410799), F(-68118460800, 10900136933), F(87487479700, 32700410799)),
    (0, F(-1754552775, 470086768), F(14199869525, 1410260304), F(-10690763975, 1880347072)),
    (0, F(127303824393, 49829197408), F(-318862633887, 49829197408), F(701980252875, 199316789632)),
    (0, F(-282668133, 205662961), F(2019193451, 616988883), F(-1453857185, 822651844)),
    (0, F(40617522, 29380423), F(-110615467, 29380423), F(69997945, 29380423)),
)
"""Dormand-Prince 5(4): Shampine's 4th-order dense output, y(t + theta h) = y + h sum_i k_i sum_p P[i, p]
theta^(p+1) (Shampine 1986; Hairer, Norsett & Wanner I, II.6)."""

BS32_A = ((), (F(1, 2),), (0, F(3, 4)), (F(2, 9), F(1, 3), F(4, 9)))
"""Bogacki-Shampine 3(2): rows of A; the last row is the 3rd-order weights b (FSAL) (Bogacki & Shampine 1989)."""
BS32_B_HAT = (F(7, 24), F(1, 4), F(1, 3), F(1, 8))
"""Bogacki-Shampine 3(2): the embedded 2nd-order weights."""

RK4_A = ((), (F(1, 2),), (0, F(1, 2)), (0, 0, 1), (F(1, 6), F(1, 3), F(1, 3), F(1, 6)))
"""The classical Runge-Kutta method of order 4, written first-same-as-last: its four stages and a fifth, the
derivative at the step's end k5 = f(t + h, y4) (the next step's k1), whose row of A is RK4's weights b."""
RK4_B_HAT = (F(1, 6), F(1, 3), F(1, 3), 0, F(1, 6))
"""The third-order formula embedded in RK4's stages with k5: y3 = y + h (k1/6 + k2/3 + k3/3 + k5/6), so
y4 - y3 = h/6 (k4 - k5) (Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., II.4, embedded formulas of order 4(3)):
the force error estimate's second state (drivers.force_error_check)."""

PAIRS = {
    # name: (tableau, new right-hand sides per step)
    "DP54": (_tableau(DP54_A, DP54_B_HAT, 5, DP54_P), 6),
    "BS32": (_tableau(BS32_A, BS32_B_HAT, 3), 3),
}
"""The embedded pairs by the scene's ``[integrator] method`` (PI step-size control)."""

TABLEAUX = {**PAIRS, "RK4": (_tableau(RK4_A, RK4_B_HAT, 4, integer_rows=True), 4)}
"""Every method of the compiled loop: the embedded pairs and RK4 (fixed step, compiled_loop.FIXED_STEP; its dense output
the cubic Hermite between the step's ends, as drivers.RK4's)."""

SCIPY_EQUIVALENT = {"DP54": "RK45", "BS32": "RK23"}
"""The same pairs in scipy (the Python path, for scenes the compiled loop cannot run): RK45 is Dormand-Prince 5(4)
with Shampine's dense output, RK23 Bogacki-Shampine 3(2); scipy's controller is an I controller and it does not
locate contact switches."""
