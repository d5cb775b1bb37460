"""The compiled loop (:func:`embedded_run`), one for every method: an explicit Runge-Kutta tableau, first-same-as-last,
with either step-size control (the embedded pairs: dense output at the output times, contact onset/loss located
within the step) or a fixed step (RK4). It takes records (:class:`Tableau`, :class:`StepControl`, :class:`Outputs`,
:class:`Carried`, :class:`EventLog`, compiled_records.PackedRun) and returns an :class:`Outcome`; drivers.run_compiled
calls it in chunks.

The right-hand side is compiled_rhs._rhs (tables or the compiled 3-D search; the lateral scan ``full`` at each step's
first stage, which for these FSAL tableaux is the previous step's last stage, and at the recorded samples). The
methods (:data:`TABLEAUX`; Butcher tableaux below, module constants with their sources;
tests/test_dynamics_adaptive.py checks their order conditions and observed orders):

* ``DP54``: Dormand & Prince, "A family of embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6 (1980) 19-26
  (the 5th-order solution is propagated, the 4th-order one estimates the error; 6 new right-hand sides per step,
  first-same-as-last), dense output of order 4 by Shampine's interpolant ("Some practical Runge-Kutta formulas",
  Math. Comp. 46 (1986) 135-150; the coefficients of Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., II.6,
  as scipy's RK45 uses them);
* ``BS32``: Bogacki & Shampine, "A 3(2) pair of Runge-Kutta formulas", Appl. Math. Lett. 2 (1989) 321-325
  (3 new right-hand sides per step, first-same-as-last), dense output by cubic Hermite interpolation between the
  step's ends (order 3);
* ``RK4``: the classical Runge-Kutta method of order 4 with a fixed step (:data:`FIXED_STEP`), written
  first-same-as-last with a fifth stage k5 = f(t + h, y4), the next step's k1 (4 new right-hand sides per step, as
  the classical method), its rows as integers over their common denominator, y4 = y + h/6 (k1 + 2 k2 + 2 k3 + k4)
  as the formula is written. Its embedded third-order formula y3 = y + h (k1/6 + k2/3 + k3/3 + k5/6) (Hairer,
  Norsett & Wanner I, II.4) is the error indicator, not a step control: the force error estimate (the per-wheel
  contact forces at y4 and y3, drivers.force_error_check) every ``check_every`` steps and at every sample, a sample
  carrying the largest since the previous one. The step's times are t0 + n h; nothing is rejected or located (a
  failed stage or a non-finite state ends the run with its status); the samples lie on step ends (multiples of the
  step).

Step control (Hairer, Norsett & Wanner I, II.4): the error of a step is err = h sum_i e_i k_i (e = b - b_hat), its
size the root-mean-square over the mechanical and track states of err_j / (atol_j + rtol max(|y_j|, |y_new_j|))
(atol per state from drivers.tolerances: positions atol, rates 100 atol, spin rate 1000 atol; the two work
integrals, diagnostics that do not enter the right-hand side, are not controlled). The positions (wheelset and
track) are controlled by atol alone: their values carry offsets that say nothing about the contact (x and the spin
angle grow along the track, z is about the wheel radius: rtol |z| at rtol 1e-4 would allow 46 um against a Hertz
approach of about 100 um, and the samples of the dense output showed errors of 30 % of the static load in a
wheel-flat impact that way); the rates get atol + rtol |y|. A step with size <= 1 is
accepted; the next step is h (0.9 norm^(-0.7/k) norm_prev^(0.4/k)), a PI controller (Gustafsson 1991; Hairer &
Wanner II, IV.2), k = the order of the error estimate + 1, the factor within [0.2, 10] (not above 1 right after a
rejection). A rejected step is retried with h max(0.2, 0.9 norm^(-1/k)). A stage whose right-hand side fails
(status not 0, or a non-finite state) is retried at a quarter of the step, except a contact model that failed
behind the callback (layout.CALLBACK_FAILED, compiled_rhs._external: not a matter of the step), which ends the
run. A step below ``h_min`` ends the run with layout.UNDERFLOW ("step-size-underflow"), with the status of the
last failure kept for the message.

A step that would end a little past an output time (by less than one stage's share of it) is shortened to end
there, so that the sample needs no right-hand side of its own.

Contact onset and loss: each accepted step compares which candidates are in contact (normal force > 0, i.e.
approach q > 0) at its two ends (the last stage is evaluated with its record). When one switches and the step is
longer than ``event_tol`` (s), the earliest switch is located on the step's dense output (regula falsi on the
switching candidate's approach, safeguarded by bisection on the contact set; each trial a right-hand side with the
lateral scan, the search memory restored after it) to within ``event_tol``, and the step is redone to end just after
it, so that the non-smooth onset or loss of the Hertz force lies at the end of a step and the next step starts on
the other side. The located times and the contact set after each switch go to the event log (ev_t, ev_mask).

The search memory (compiled_search: the warm starts of the contact points) is saved at each step's start and
restored when the step is rejected, and after every evaluation off the step's path (output samples, event
location, the force error estimate's state), so that an accepted step sees the memory of the previous step's end.
One exception, kept from the former RK4 loop: RK4's next step starts from the memory its force error estimate's
evaluation (at y3) leaves. The search's warm start moves its converged contact points slightly: restoring the
step-end memory there moves the states of corrugation (elastic track, 3-D search) by 9.5e-9 of their block's
magnitude, beyond tests/test_dynamics_regression.py's 1e-10, so the references' behaviour is kept.

Status codes: layout.STATUS (0 ok, 1 blow-up, 2 force anomaly, 3 derailed, 4 creepages undefined, 5 callback
failed, 6 step-size underflow).
"""

from __future__ import annotations

import math
from fractions import Fraction as F
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.wheelset.compiled_rhs import _rhs, force_difference, side_forces, workspace
from rigid_dynamics.wheelset.layout import (
    APPROACH,
    BLOW_UP,
    CALLBACK_FAILED,
    DERAILED,
    FORCE_ANOMALY,
    N_FIELDS,
    NORMAL_FORCE,
    OK,
    UNDERFLOW,
)
from rigid_dynamics.wheelset.state import Y

MIN_STEP_S = 1e-10
"""Smallest step of an error-controlled run, s: below it the run ends with status "step-size-underflow" (a contact
mode of 1 kHz needs steps of order 1e-5 s; a controller asking for 1e-10 s has met a discontinuity or a blow-up)."""

EVENT_TIME_TOLERANCE_S = 1e-6
"""Contact onset and loss are located to within this time, s (at 30 m/s, 30 um of travel; at an impact's approach
rate of 0.1 m/s, 0.1 um of approach against a static approach of about 100 um)."""

MAX_EVENTS = 100_000
"""Event log length of one run (the switches beyond it are not logged; the integration is unaffected)."""

STEPS_PER_CALL = 2000
"""Accepted steps per call of the compiled loop (between calls the driver checks wall time and budget)."""


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


class StepControl(NamedTuple):
    """Step-size control of :func:`embedded_run`: rtol, atol per state, the weight per state (0 not controlled,
    1 atol alone, 2 atol + rtol |y|), the smallest and largest step, the event location's time tolerance (s), the
    accepted steps per call, the controller (:data:`PI_CONTROL` or :data:`FIXED_STEP`) and, for the fixed step, the
    steps between force error checks (0: at the output samples only).
    """

    rtol: float
    atol: np.ndarray
    weight: np.ndarray
    h_min: float
    h_max: float
    event_tol: float
    max_steps: int
    controller: int
    check_every: int


PI_CONTROL, FIXED_STEP = range(2)
"""The controllers of :func:`embedded_run`: the PI step-size control with rejections and located contact switches
(the embedded pairs), or the fixed step (RK4: the step never changes, nothing is rejected or located; its error
estimate is the force error check's)."""


class Outputs(NamedTuple):
    """Where the compiled loop records its samples: the output times (for the fixed step, multiples of the step),
    the states, the patch records (samples, candidates + 2, layout.N_FIELDS) and the force error estimates (N).
    """

    times: np.ndarray
    states: np.ndarray
    recs: np.ndarray
    errs: np.ndarray


ERROR_NORM, STARTED = range(2)
"""Entries of Carried.control: the controller's previous error norm; 1 once kst[0], mask0 and gap0 hold t0's."""


class Carried(NamedTuple):
    """What :func:`embedded_run` carries between calls: ``control`` = (the controller's previous error norm, 1 when
    ``kst[0]``, ``mask0`` and ``gap0`` hold f(t0, y), the contact set and the approaches at t0), the stages ``kst``
    (s, states).
    """

    control: np.ndarray
    kst: np.ndarray
    mask0: np.ndarray
    gap0: np.ndarray


class EventLog(NamedTuple):
    """The located contact switches: times, the contact set after each (per candidate), and count[0] entries (entry
    0 is the set at the start).
    """

    times: np.ndarray
    masks: np.ndarray
    count: np.ndarray


class Outcome(NamedTuple):
    """What a call of a compiled loop returns: status (layout.STATUS), t, y, the next step h, accepted and rejected
    steps, the next output index, right-hand-side evaluations, located switches and the status of the last failed
    stage.
    """

    status: int
    t: float
    y: np.ndarray
    h: float
    accepted: int
    rejected: int
    k_out: int
    evaluations: int
    located: int
    last_failure: int


@njit(cache=True)
def _outcome(status, t, y, h, accepted, rejected, k_out, evaluations, located, last_failure):
    """An :class:`Outcome` of one type for every return of the loops (with reference counting: it hands ``y`` back
    to a caller that counts references).
    """
    return Outcome(
        int(status), float(t), y, float(h), int(accepted), int(rejected), int(k_out), int(evaluations), int(located),
        int(last_failure),
    )  # fmt: skip


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
"""Every method of the compiled loop: the embedded pairs and RK4 (fixed step, :data:`FIXED_STEP`; its dense output
the cubic Hermite between the step's ends, as drivers.RK4's)."""

SCIPY_EQUIVALENT = {"DP54": "RK45", "BS32": "RK23"}
"""The same pairs in scipy (the Python path, for scenes the compiled loop cannot run): RK45 is Dormand-Prince 5(4)
with Shampine's dense output, RK23 Bogacki-Shampine 3(2); scipy's controller is an I controller and it does not
locate contact switches."""


@njit(cache=True, _nrt=False)
def _dense(y, h, kst, p, theta, out):
    """The pair's dense output y(t + theta h) into out: y + h sum_i k_i sum_p P[i, p] theta^(p+1)."""
    nst = y.shape[0]
    for i in range(nst):
        out[i] = y[i]
    for s in range(kst.shape[0]):
        total, power = 0.0, theta  # sum_p P[s, p] theta^(p+1), left to right
        for q in range(p.shape[1]):
            total += p[s, q] * power
            power *= theta
        w = h * total
        if w != 0.0:
            for i in range(nst):
                out[i] += w * kst[s, i]


@njit(cache=True, _nrt=False)
def _combine(weights, kst, s, out):
    """The sum over the first s stages of w_j k_j into ``out``, per state, the terms added in the order of j (w_j = 0
    skipped).
    """
    for i in range(out.shape[0]):
        out[i] = 0.0
    for j in range(s):
        w = weights[j]
        if w != 0.0:
            for i in range(out.shape[0]):
                out[i] += w * kst[j, i]


@njit(cache=True, _nrt=False)
def _combine_fractions(numerators, denominators, kst, out):
    """The sum over the stages of (n_j k_j) / d_j into ``out``, per state, the terms added in the order of j (n_j = 0
    skipped).
    """
    for i in range(out.shape[0]):
        out[i] = 0.0
    for j in range(kst.shape[0]):
        w, dj = numerators[j], denominators[j]
        if w != 0.0:
            for i in range(out.shape[0]):
                out[i] += w * kst[j, i] / dj


@njit(cache=True, _nrt=False)
def _contact_mask(rec, ncand, mask, gap):
    """Which candidates are in contact (normal force > 0) and their approach q (NaN: absent), from a record."""
    for c in range(ncand):
        mask[c] = 1 if rec[c, NORMAL_FORCE] > 0.0 else 0
        gap[c] = rec[c, APPROACH]


@njit(cache=True)
def embedded_run(y, t0, t_end, h, tableau, control, run, outputs, k_out, carried, events):
    """Advance from (t0, y) with the method ``tableau`` (:class:`Tableau`, :data:`TABLEAUX`) under the control
    ``control`` (:class:`StepControl`) until t_end or ``control.max_steps`` accepted steps; record the samples at
    outputs.times[k_out:] (dense output, then a right-hand side with record at the interpolated state; a sample on
    the step's end takes the step's last stage) into ``outputs``. ``run``: compiled_records.PackedRun. Module
    docstring for the control, the fixed step and the events.

    Carried between calls (the driver keeps ``carried``, :class:`Carried`, and ``events``, :class:`EventLog`).
    Returns an :class:`Outcome`.
    """
    a, d, cc, e, p, k_order, b_hat_num, b_hat_den = tableau
    rtol, atol, weight, h_min, h_max, event_tol, max_steps, controller, check_every = control
    fixed = controller == FIXED_STEP
    out_times, states, recs, errs = outputs
    carry, kst, mask0, gap0 = carried
    ev_t, ev_mask, n_ev = events
    par, sides = run.par, run.sides
    ncand = sides.shape[0]
    ws = workspace(run, np.empty((ncand + 2, N_FIELDS)))
    rec = ws.rec
    nst = y.shape[0]
    ns = a.shape[0]
    y = y.copy()
    y_new, ys, scratch, combined, stage = np.empty(nst), np.empty(nst), np.empty(nst), np.empty(nst), np.empty(nst)
    rec_end = np.empty((ncand + 2, N_FIELDS))
    mask1, gap1 = np.empty(ncand, np.int64), np.empty(ncand)
    mask_t, gap_t = np.empty(ncand, np.int64), np.empty(ncand)
    gap_lo, gap_hi = np.empty(ncand), np.empty(ncand)
    f4, f3 = np.empty((2, 3)), np.empty((2, 3))
    mem, n_mem = run.search.mem, run.search.n_mem
    mem_save, n_mem_save = mem.copy(), n_mem.copy()
    mem_end, n_mem_end = mem.copy(), n_mem.copy()
    fmax, ymax = par.max_force_N, par.max_lateral_m
    t = t0
    evals, accepted, rejected, located, last_fail = 0, 0, 0, 0, 0
    pending = np.nan  # the largest force error estimate since the last sample (NaN: none)
    if carry[STARTED] == 0.0:
        st = _rhs(t, y, run, ws, True, True, kst[0])
        evals += 1
        if st != 0:
            return _outcome(st, t, y, h, accepted, rejected, k_out, evals, located, st)
        _contact_mask(rec, ncand, mask0, gap0)
        carry[STARTED] = 1.0
        if n_ev[0] == 0 and ev_t.shape[0] > 0:
            ev_t[0] = t
            for c in range(ncand):
                ev_mask[0, c] = mask0[c]
            n_ev[0] = 1
    err_prev = carry[ERROR_NORM]
    tiny = 1e-12 * max(1.0, abs(t_end))
    after_reject = False
    h_event = np.nan  # the controller's step before a step was cut short to end at a switch
    event_t = np.nan  # the located switch that the step being retried is to end just after
    norm = 0.0
    while accepted < max_steps and t < t_end - tiny:
        if not fixed:
            h = min(h, h_max)
            if k_out < out_times.shape[0]:
                # end the step on the next output time when that shortens it by less than one stage's worth: the
                # sample then needs no right-hand side of its own
                gap = out_times[k_out] - t
                if gap < h and gap > h * (1.0 - 1.0 / (ns - 1)):
                    h = gap
            if t + 1.01 * h >= t_end:
                h = t_end - t
        if not h >= h_min:
            return _outcome(UNDERFLOW, t, y, h, accepted, rejected, k_out, evals, located, last_fail)
        # the fixed step's times are t0 + n h (no sum of rounded steps), the controlled steps' t + h
        t_new = t0 + (accepted + 1) * h if fixed else t + h
        # a step that ends on or past a sample (and the fixed step every check_every steps) has a force error estimate
        sample = k_out < out_times.shape[0] and out_times[k_out] <= t_new + tiny
        check = sample or (fixed and check_every > 0 and (accepted + 1) % check_every == 0)
        if not fixed:  # (the fixed step is never retried: no memory to restore)
            mem_save[:, :, :] = mem
            n_mem_save[:] = n_mem
        # the stages; the last one is f(t + h, y_new) (FSAL), evaluated with the lateral scan and with its record
        # (the fixed step's only when it is checked: its record serves the estimate and the sample)
        failed = 0
        for s in range(1, ns):
            _combine(a[s], kst, s, combined)
            hd = h / d[s]
            for i in range(nst):
                ys[i] = y[i] + hd * combined[i]
            last = s == ns - 1
            if last and (check or not fixed):
                st = _rhs(t_new, ys, run, ws, True, True, stage)
            elif last:
                st = _rhs(t_new, ys, run, ws, False, True, stage)
            else:
                st = _rhs(t + cc[s] * h, ys, run, ws, False, False, stage)
            for i in range(nst):
                kst[s, i] = stage[i]
            evals += 1
            if st == CALLBACK_FAILED or (st != 0 and fixed):
                # the contact model behind the callback failed (not a matter of the step), or a fixed step's stage
                return _outcome(st, t, y, h, accepted, rejected, k_out, evals, located, st)
            if st != 0:
                failed = st
                break
        if failed == 0:
            for i in range(nst):
                y_new[i] = ys[i]  # the last row of A is b
        if failed == 0 and not fixed:
            total, wsum = 0.0, 0.0
            for i in range(nst):
                acc = 0.0
                for s in range(ns):
                    acc += e[s] * kst[s, i]
                err = h * acc
                if weight[i] > 0.0:
                    sc = atol[i] + (rtol * max(abs(y[i]), abs(y_new[i])) if weight[i] > 1.0 else 0.0)
                    total += (err / sc) ** 2
                    wsum += 1.0
            norm = math.sqrt(total / wsum)
            if not np.isfinite(norm):
                failed = 1
        if failed != 0:
            # a stage failed or the step is not finite: a quarter of the step, the memory of the step's start
            last_fail = failed
            rejected += 1
            mem[:, :, :] = mem_save
            n_mem[:] = n_mem_save
            h *= 0.25
            after_reject = True
            continue
        if norm > 1.0:
            rejected += 1
            mem[:, :, :] = mem_save
            n_mem[:] = n_mem_save
            h *= max(0.2, 0.9 * norm ** (-1.0 / k_order))
            after_reject = True
            continue
        # accepted by the error control; the memory of the step's end (the last stage's scan) is what the next step
        # starts from: evaluations off the step's path (location, output samples) restore it
        if check or not fixed:
            for i in range(ncand + 2):
                for f in range(N_FIELDS):
                    rec_end[i, f] = rec[i, f]
        switched = False
        if not fixed:
            mem_end[:, :, :] = mem
            n_mem_end[:] = n_mem
            _contact_mask(rec, ncand, mask1, gap1)
            for c in range(ncand):
                if mask1[c] != mask0[c]:
                    switched = True
        if switched and h > event_tol and not event_t == event_t:
            # locate the earliest switch on the dense output: [lo, hi] with the start's set at lo, another at hi
            lo, hi = 0.0, 1.0
            for c in range(ncand):
                gap_lo[c], gap_hi[c] = gap0[c], gap1[c]
            side_lo, side_hi = 0, 0  # Illinois: the end kept twice in a row gets the other end's approach halved
            for _ in range(60):
                if (hi - lo) * h <= event_tol:
                    break
                # regula falsi on the earliest linear crossing of a switching candidate with finite approaches
                theta = np.nan
                for c in range(ncand):
                    if mask1[c] != mask0[c] and gap_lo[c] == gap_lo[c] and gap_hi[c] == gap_hi[c]:
                        if gap_lo[c] != gap_hi[c]:
                            cross = lo + (hi - lo) * gap_lo[c] / (gap_lo[c] - gap_hi[c])
                            if cross > lo and cross < hi and not cross >= theta:
                                theta = cross
                if not theta == theta or side_lo >= 3 or side_hi >= 3:
                    theta = 0.5 * (lo + hi)
                    side_lo, side_hi = 0, 0
                margin = 0.01 * (hi - lo)
                theta = min(max(theta, lo + margin), hi - margin)
                _dense(y, h, kst, p, theta, ys)
                mem[:, :, :] = mem_save
                n_mem[:] = n_mem_save
                st = _rhs(t + theta * h, ys, run, ws, True, True, scratch)
                evals += 1
                if st != 0:
                    break  # the interpolated state cannot be evaluated: keep the bracket found so far
                _contact_mask(rec, ncand, mask_t, gap_t)
                same = True
                for c in range(ncand):
                    if mask_t[c] != mask0[c]:
                        same = False
                if same:
                    lo = theta
                    side_lo += 1
                    side_hi = 0
                    for c in range(ncand):
                        gap_lo[c] = gap_t[c]
                        if side_lo >= 2:
                            gap_hi[c] *= 0.5
                else:
                    hi = theta
                    side_hi += 1
                    side_lo = 0
                    for c in range(ncand):
                        gap_hi[c] = gap_t[c]
                        mask1[c] = mask_t[c]
                        if side_hi >= 2:
                            gap_lo[c] *= 0.5
            if hi < 1.0 - 1e-9:
                # redo the step from its start (and the start's memory) to end just after the switch
                located += 1
                rejected += 1
                mem[:, :, :] = mem_save
                n_mem[:] = n_mem_save
                event_t = t + hi * h
                h_event = h  # the controller's step: the next step after the switch starts from it again
                h = hi * h + 0.5 * event_tol
                continue
            _contact_mask(rec_end, ncand, mask1, gap1)
        for i in range(nst):
            if not np.isfinite(y_new[i]):
                return _outcome(BLOW_UP, t, y, h, accepted, rejected, k_out, evals, located, BLOW_UP)
        # force error estimate of a step with output samples (and of the fixed step every check_every steps): the
        # per-wheel contact forces at the propagated solution against those at the embedded lower-order one,
        # y + h sum_j b_hat_j k_j; a sample carries the largest since the previous sample
        k_first = k_out
        if check:
            side_forces(rec_end, sides, f4)
            _combine_fractions(b_hat_num, b_hat_den, kst, combined)
            for i in range(nst):
                ys[i] = y[i] + h * combined[i]
            st = _rhs(t_new, ys, run, ws, True, False, scratch)
            evals += 1
            estimate = np.inf
            if st == 0:
                side_forces(rec, sides, f3)
                estimate = force_difference(f4, f3)
            if not pending >= estimate:  # also when pending is NaN
                pending = estimate
            if not fixed:
                # (RK4 keeps the memory this evaluation leaves, as the fixed-step loop before it did: the regression
                # references hold it; the memory of the step's end instead moves corrugation's states by 1e-8)
                mem[:, :, :] = mem_end
                n_mem[:] = n_mem_end
        # the output samples within (t, t_new]: dense output and a right-hand side with record there
        while k_out < out_times.shape[0] and out_times[k_out] <= t_new + tiny:
            theta = (out_times[k_out] - t) / h
            if abs(1.0 - theta) * h <= tiny:
                states[k_out, :] = y_new
                recs[k_out, :, :] = rec_end
            else:
                _dense(y, h, kst, p, theta, ys)
                st = _rhs(out_times[k_out], ys, run, ws, True, True, scratch)
                evals += 1
                if st != 0:
                    return _outcome(st, t, y, h, accepted, rejected, k_out, evals, located, st)
                states[k_out, :] = ys
                recs[k_out, :, :] = rec
            side_forces(recs[k_out], sides, f4)
            errs[k_out] = pending if k_out == k_first else np.nan
            pending = np.nan
            k_out += 1
            for sd in range(2):
                if f4[sd, NORMAL_FORCE] > fmax:
                    return _outcome(
                        FORCE_ANOMALY, t_new, y_new, h, accepted + 1, rejected, k_out, evals, located, FORCE_ANOMALY
                    )
            if abs(states[k_out - 1, Y]) > ymax:
                return _outcome(DERAILED, t_new, y_new, h, accepted + 1, rejected, k_out, evals, located, DERAILED)
        if not fixed:
            mem[:, :, :] = mem_end
            n_mem[:] = n_mem_end
            switched = False
            for c in range(ncand):
                if mask1[c] != mask0[c]:
                    switched = True
            if switched and n_ev[0] < ev_t.shape[0]:
                ev_t[n_ev[0]] = event_t if event_t == event_t else t_new
                for c in range(ncand):
                    ev_mask[n_ev[0], c] = mask1[c]
                n_ev[0] += 1
            event_t = np.nan
            for c in range(ncand):
                mask0[c], gap0[c] = mask1[c], gap1[c]
        for i in range(nst):
            kst[0, i] = kst[ns - 1, i]
            y[i] = y_new[i]
        t = t_new
        accepted += 1
        if fixed:
            continue
        norm = max(norm, 1e-4)
        factor = 0.9 * norm ** (-0.7 / k_order) * err_prev ** (0.4 / k_order)
        factor = min(max(factor, 0.2), 1.0 if after_reject else 10.0)
        err_prev = norm
        carry[ERROR_NORM] = err_prev
        h *= factor
        if h_event == h_event:
            # the step was cut short to end at a located switch, not by its error: resume the controller's step
            h = max(h, min(h_event, 10.0 * h_event * factor))
            h_event = np.nan
        after_reject = False
    return _outcome(OK, t, y, h, accepted, rejected, k_out, evals, located, last_fail)
