"""The compiled loop (:func:`embedded_run`), one for every method: an explicit Runge-Kutta tableau, first-same-as-last,
with either step-size control (the embedded pairs: dense output at the output times, contact onset/loss located
within the step) or a fixed step (RK4). It takes records (:class:`Tableau`, :class:`StepControl`, :class:`Outputs`,
:class:`Carried`, :class:`EventLog`, compiled_records.PackedRun) and returns an :class:`Outcome`; drivers.run_compiled
calls it in chunks.

The right-hand side is compiled_rhs._rhs (tables or the compiled 3-D search; the lateral scan ``full`` at each step's
first stage, which for these FSAL tableaux is the previous step's last stage, and at the recorded samples). The
methods and their sources: :mod:`rigid_dynamics.wheelset.tableaux` (:data:`~rigid_dynamics.wheelset.tableaux.TABLEAUX`).

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
    GAP_LAW_FAILED,
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


class LoopWork(NamedTuple):
    """The work arrays of :func:`_advance` (allocated by :func:`embedded_run`, once per call): the right-hand side's
    workspace (compiled_rhs.Workspace), the new state, a stage's state, a scratch right-hand side, the stage sum, a
    stage's right-hand side (states,), the record at the step's end, the contact set and approaches at the step's
    end, at a trial point and at the ends of the location's bracket (candidates,), the per-wheel forces at y4 and
    y3 (2, 3), and the search memory saved at the step's start and at its end (compiled_search.SearchArgs' mem,
    n_mem).
    """

    ws: tuple
    y_new: np.ndarray
    ys: np.ndarray
    scratch: np.ndarray
    combined: np.ndarray
    stage: np.ndarray
    rec_end: np.ndarray
    mask1: np.ndarray
    gap1: np.ndarray
    mask_t: np.ndarray
    gap_t: np.ndarray
    gap_lo: np.ndarray
    gap_hi: np.ndarray
    f4: np.ndarray
    f3: np.ndarray
    mem_save: np.ndarray
    n_mem_save: np.ndarray
    mem_end: np.ndarray
    n_mem_end: np.ndarray


@njit(cache=True)
def _outcome(status, t, y, h, accepted, rejected, k_out, evaluations, located, last_failure):
    """An :class:`Outcome` of one type for every return of the loops (with reference counting: it hands ``y`` back
    to a caller that counts references).
    """
    return Outcome(
        int(status), float(t), y, float(h), int(accepted), int(rejected), int(k_out), int(evaluations), int(located),
        int(last_failure),
    )  # fmt: skip


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
    Returns an :class:`Outcome`. The work arrays are allocated here, once per call; the steps run in
    :func:`_advance`, compiled without reference counting.
    """
    ncand = run.sides.shape[0]
    nst = y.shape[0]
    y = y.copy()
    mem, n_mem = run.search.mem, run.search.n_mem
    work = LoopWork(
        workspace(run, np.empty((ncand + 2, N_FIELDS))), np.empty(nst), np.empty(nst), np.empty(nst), np.empty(nst),
        np.empty(nst), np.empty((ncand + 2, N_FIELDS)), np.empty(ncand, np.int64), np.empty(ncand),
        np.empty(ncand, np.int64), np.empty(ncand), np.empty(ncand), np.empty(ncand), np.empty((2, 3)),
        np.empty((2, 3)), mem.copy(), n_mem.copy(), mem.copy(), n_mem.copy(),
    )  # fmt: skip
    status, t, h, accepted, rejected, k_out, evals, located, last_fail = _advance(
        y, (t0, t_end, h, k_out), tableau, control, run, outputs, carried, events, work
    )
    return _outcome(status, t, y, h, accepted, rejected, k_out, evals, located, last_fail)


@njit(cache=True, _nrt=False, inline="always")
def _ended(status, t, h, accepted, rejected, k_out, evaluations, located, last_failure):
    """What :func:`_advance` returns: the scalars of an :class:`Outcome` (its state is the caller's y)."""
    return (
        int(status), float(t), float(h), int(accepted), int(rejected), int(k_out), int(evaluations), int(located),
        int(last_failure),
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def _copy_into(src, dst):
    """dst[...] = src, element by element (no temporary: this module's loop runs without reference counting)."""
    for i in np.ndindex(src.shape):
        dst[i] = src[i]


@njit(cache=True, _nrt=False)
def _advance(y, span, tableau, control, run, outputs, carried, events, work):
    """The steps of :func:`embedded_run` from (span[0], y) to span[1] with the first step span[2] and the next
    output index span[3], y advanced in place; compiled without reference counting (numba's reference counts on
    the run's and the workspace's arrays, taken at every inlined right-hand side, cost a third of an RK4 step:
    benchmarks/results/compile_and_speed_issue25.md). Returns the scalars of the :class:`Outcome` (:func:`_ended`).
    """
    t0, t_end, h, k_out = span
    a, d, cc, e, p, k_order, b_hat_num, b_hat_den = tableau
    rtol, atol, weight, h_min, h_max, event_tol, max_steps, controller, check_every = control
    fixed = controller == FIXED_STEP
    out_times, states, recs, errs = outputs
    carry, kst, mask0, gap0 = carried
    ev_t, ev_mask, n_ev = events
    ws, y_new, ys, scratch, combined, stage, rec_end, mask1, gap1, mask_t, gap_t, gap_lo, gap_hi, f4, f3, mem_save, \
        n_mem_save, mem_end, n_mem_end = work  # fmt: skip
    sides = run.sides
    ncand = sides.shape[0]
    rec = ws.rec
    nst = y.shape[0]
    ns = a.shape[0]
    mem, n_mem = run.search.mem, run.search.n_mem
    fmax, ymax = run.par.max_force_N, run.par.max_lateral_m
    t = t0
    evals, accepted, rejected, located, last_fail = 0, 0, 0, 0, 0
    pending = np.nan  # the largest force error estimate since the last sample (NaN: none)
    if carry[STARTED] == 0.0:
        st = _rhs(t, y, run, ws, True, True, kst[0])
        evals += 1
        if st != 0:
            return _ended(st, t, h, accepted, rejected, k_out, evals, located, st)
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
            return _ended(UNDERFLOW, t, h, accepted, rejected, k_out, evals, located, last_fail)
        # the fixed step's times are t0 + n h (no sum of rounded steps), the controlled steps' t + h
        t_new = t0 + (accepted + 1) * h if fixed else t + h
        # a step that ends on or past a sample (and the fixed step every check_every steps) has a force error estimate
        sample = k_out < out_times.shape[0] and out_times[k_out] <= t_new + tiny
        check = sample or (fixed and check_every > 0 and (accepted + 1) % check_every == 0)
        if not fixed:  # (the fixed step is never retried: no memory to restore)
            _copy_into(mem, mem_save)
            _copy_into(n_mem, n_mem_save)
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
            if st == CALLBACK_FAILED or st == GAP_LAW_FAILED or (st != 0 and fixed):
                # the contact model behind the callback failed (not a matter of the step), or a fixed step's stage
                return _ended(st, t, h, accepted, rejected, k_out, evals, located, st)
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
            _copy_into(mem_save, mem)
            _copy_into(n_mem_save, n_mem)
            h *= 0.25
            after_reject = True
            continue
        if norm > 1.0:
            rejected += 1
            _copy_into(mem_save, mem)
            _copy_into(n_mem_save, n_mem)
            h *= max(0.2, 0.9 * norm ** (-1.0 / k_order))
            after_reject = True
            continue
        # accepted by the error control; the memory of the step's end (the last stage's scan) is what the next step
        # starts from: evaluations off the step's path (location, output samples) restore it
        if check or not fixed:
            _copy_into(rec, rec_end)
        switched = False
        if not fixed:
            _copy_into(mem, mem_end)
            _copy_into(n_mem, n_mem_end)
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
                _copy_into(mem_save, mem)
                _copy_into(n_mem_save, n_mem)
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
                _copy_into(mem_save, mem)
                _copy_into(n_mem_save, n_mem)
                event_t = t + hi * h
                h_event = h  # the controller's step: the next step after the switch starts from it again
                h = hi * h + 0.5 * event_tol
                continue
            _contact_mask(rec_end, ncand, mask1, gap1)
        for i in range(nst):
            if not np.isfinite(y_new[i]):
                return _ended(BLOW_UP, t, h, accepted, rejected, k_out, evals, located, BLOW_UP)
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
                _copy_into(mem_end, mem)
                _copy_into(n_mem_end, n_mem)
        # the output samples within (t, t_new]: dense output and a right-hand side with record there
        while k_out < out_times.shape[0] and out_times[k_out] <= t_new + tiny:
            theta = (out_times[k_out] - t) / h
            if abs(1.0 - theta) * h <= tiny:
                _copy_into(y_new, states[k_out])
                _copy_into(rec_end, recs[k_out])
            else:
                _dense(y, h, kst, p, theta, ys)
                st = _rhs(out_times[k_out], ys, run, ws, True, True, scratch)
                evals += 1
                if st != 0:
                    return _ended(st, t, h, accepted, rejected, k_out, evals, located, st)
                _copy_into(ys, states[k_out])
                _copy_into(rec, recs[k_out])
            side_forces(recs[k_out], sides, f4)
            errs[k_out] = pending if k_out == k_first else np.nan
            pending = np.nan
            k_out += 1
            for sd in range(2):
                if f4[sd, NORMAL_FORCE] > fmax:
                    _copy_into(y_new, y)
                    return _ended(FORCE_ANOMALY, t_new, h, accepted + 1, rejected, k_out, evals, located, FORCE_ANOMALY)
            if abs(states[k_out - 1, Y]) > ymax:
                _copy_into(y_new, y)
                return _ended(DERAILED, t_new, h, accepted + 1, rejected, k_out, evals, located, DERAILED)
        if not fixed:
            _copy_into(mem_end, mem)
            _copy_into(n_mem_end, n_mem)
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
    return _ended(OK, t, h, accepted, rejected, k_out, evals, located, last_fail)
