"""Error-controlled integration in the compiled loop: embedded Runge-Kutta pairs with step-size control, dense
output at the output times and contact onset/loss located within the step.

The right-hand side is compiled._rhs, called exactly as compiled.rk4_run calls it (tables mode 0 or the compiled
3-D search mode 1; the lateral scan ``full`` at each step's first stage, which for these FSAL pairs is the previous
step's last stage, and at the recorded samples). Two pairs (Butcher tableaux below, module constants with their
sources; tests/test_dynamics_adaptive.py checks their order conditions and observed orders):

* ``DP54``: Dormand & Prince, "A family of embedded Runge-Kutta formulae", J. Comput. Appl. Math. 6 (1980) 19-26
  (the 5th-order solution is propagated, the 4th-order one estimates the error; 6 new right-hand sides per step,
  first-same-as-last), dense output of order 4 by Shampine's interpolant ("Some practical Runge-Kutta formulas",
  Math. Comp. 46 (1986) 135-150; the coefficients of Hairer, Norsett & Wanner, Solving ODEs I, 2nd ed., II.6,
  as scipy's RK45 uses them);
* ``BS32``: Bogacki & Shampine, "A 3(2) pair of Runge-Kutta formulas", Appl. Math. Lett. 2 (1989) 321-325
  (3 new right-hand sides per step, first-same-as-last), dense output by cubic Hermite interpolation between the
  step's ends (order 3).

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
behind the callback (status 5, compiled._external: not a matter of the step), which ends the run. A step below
``h_min`` ends the run with status 6 (UNDERFLOW, drivers: "step-size-underflow"), with the status of the last
failure kept for the message.

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
location), so that an accepted step sees the memory of the previous step's end, as in rk4_run.

Status codes: those of compiled.rk4_run (0 ok, 1 blow-up, 2 force anomaly, 3 derailed, 4 creepages undefined) and
5 step-size underflow.
"""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction as F

import numpy as np
from numba import njit

from rigid_dynamics.wheelset.compiled import (
    CALLBACK_FAILED,
    N_FIELDS,
    _force_difference,
    _rhs,
    _side_forces,
    _workspace,
)

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

UNDERFLOW = 6


def _tableau(a_rows, b_hat, p_rows=None):
    """(A (s, s), c (s), e (s), P (s, 4)) of an FSAL pair from its rows of A (the last row is b), the embedded
    weights b_hat and the dense-output matrix P (coefficients of theta, theta^2, theta^3, theta^4; None: cubic
    Hermite between the step's ends, exact in Fractions).
    """
    s = len(a_rows)
    a = [[F(0)] * s for _ in range(s)]
    for i, row in enumerate(a_rows):
        for j, v in enumerate(row):
            a[i][j] = F(v)
    b = a[s - 1]
    c = [sum(row, F(0)) for row in a]
    e = [b[j] - F(b_hat[j]) for j in range(s)]
    if p_rows is None:
        # y(theta) = y0 + h [h01 sum b_i k_i + h10 k_1 + h11 k_s] with the Hermite basis h01 = 3t^2 - 2t^3,
        # h10 = t - 2t^2 + t^3, h11 = t^3 - t^2 (k_1 = f(y0), k_s = f(y1) for an FSAL pair)
        p_rows = [[0, 3 * b[j], -2 * b[j], 0] for j in range(s)]
        p_rows[0] = [p_rows[0][0] + 1, p_rows[0][1] - 2, p_rows[0][2] + 1, 0]
        p_rows[s - 1] = [p_rows[s - 1][0], p_rows[s - 1][1] - 1, p_rows[s - 1][2] + 1, 0]
    as_float = np.array([[float(v) for v in row] for row in a])
    return (
        as_float,
        np.array([float(v) for v in c]),
        np.array([float(v) for v in e]),
        np.array([[float(F(v)) for v in row] for row in p_rows]),
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

PAIRS = {
    # name: (tableau, k = order of the error estimate + 1, new right-hand sides per step)
    "DP54": (_tableau(DP54_A, DP54_B_HAT, DP54_P), 5.0, 6),
    "BS32": (_tableau(BS32_A, BS32_B_HAT), 3.0, 3),
}
"""The embedded pairs by the scene's ``[integrator] method``."""

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
    th1 = theta
    th2 = th1 * theta
    th3 = th2 * theta
    th4 = th3 * theta
    for s in range(kst.shape[0]):
        w = h * (p[s, 0] * th1 + p[s, 1] * th2 + p[s, 2] * th3 + p[s, 3] * th4)
        if w != 0.0:
            for i in range(nst):
                out[i] += w * kst[s, i]


@njit(cache=True, _nrt=False)
def _contact_mask(rec, ncand, mask, gap):
    """Which candidates are in contact (normal force > 0) and their approach q (NaN: absent), from a record."""
    for c in range(ncand):
        mask[c] = 1 if rec[c, 0] > 0.0 else 0
        gap[c] = rec[c, 7]


@njit(cache=True)
def embedded_run(
    y, t0, t_end, h, a, cc, e, p, k_order, rtol, atol, weight, h_min, h_max, event_tol, max_steps,
    par, hz, kk, sides, mode, targs, sargs, out_times, k_out, states, recs, errs, carry, kst, mask0, gap0,
    ev_t, ev_mask, n_ev,
):  # fmt: skip
    """Advance from (t0, y) with the embedded pair (a, cc, e, p) under step-size control until t_end or
    ``max_steps`` accepted steps; record the samples at out_times[k_out:] (dense output, then a right-hand side
    with record at the interpolated state) into states/recs. Module docstring for the control and the events.

    Carried between calls (the driver keeps them): ``kst[0]`` = f(t0, y) and ``mask0``/``gap0`` (the contact set
    and approaches at t0) when carry[1] > 0; carry[0] = the controller's previous error norm; the event log
    ev_t (times), ev_mask (contact set after each switch, per candidate), n_ev[0] (entries; entry 0 is the set at
    the start). Returns (status, t, y, h next, accepted steps, rejected steps, next output index, rhs evaluations,
    located switches, status of the last failed stage).
    """
    ncand = sides.shape[0]
    ws = _workspace(par, targs[0].shape[0], ncand, np.empty((ncand + 2, N_FIELDS)))
    rec = ws[1]
    nst = y.shape[0]
    ns = a.shape[0]
    y = y.copy()
    y_new, ys, err, scratch = np.empty(nst), np.empty(nst), np.empty(nst), np.empty(nst)
    rec_end = np.empty((ncand + 2, N_FIELDS))
    mask1, gap1 = np.empty(ncand, np.int64), np.empty(ncand)
    mask_t, gap_t = np.empty(ncand, np.int64), np.empty(ncand)
    gap_lo, gap_hi = np.empty(ncand), np.empty(ncand)
    f4, f3 = np.empty((2, 3)), np.empty((2, 3))
    force_err = np.nan
    mem, n_mem = sargs[3], sargs[4]
    mem_save, n_mem_save = mem.copy(), n_mem.copy()
    mem_end, n_mem_end = mem.copy(), n_mem.copy()
    fmax, ymax = par.max_force_N, par.max_lateral_m
    t = t0
    evals, accepted, rejected, located, last_fail = 0, 0, 0, 0, 0
    if carry[1] == 0.0:
        st = _rhs(t, y, par, hz, kk, sides, mode, targs, sargs, ws, True, True, kst[0])
        evals += 1
        if st != 0:
            return st, t, y, h, accepted, rejected, k_out, evals, located, st
        _contact_mask(rec, ncand, mask0, gap0)
        carry[1] = 1.0
        if n_ev[0] == 0 and ev_t.shape[0] > 0:
            ev_t[0] = t
            for c in range(ncand):
                ev_mask[0, c] = mask0[c]
            n_ev[0] = 1
    err_prev = carry[0]
    tiny = 1e-12 * max(1.0, abs(t_end))
    after_reject = False
    h_event = np.nan  # the controller's step before a step was cut short to end at a switch
    event_t = np.nan  # the located switch that the step being retried is to end just after
    while accepted < max_steps and t < t_end - tiny:
        h = min(h, h_max)
        if k_out < out_times.shape[0]:
            # end the step on the next output time when that shortens it by less than one stage's worth: the
            # sample then needs no right-hand side of its own
            d = out_times[k_out] - t
            if d < h and d > h * (1.0 - 1.0 / (ns - 1)):
                h = d
        if t + 1.01 * h >= t_end:
            h = t_end - t
        if not h >= h_min:
            return UNDERFLOW, t, y, h, accepted, rejected, k_out, evals, located, last_fail
        mem_save[:, :, :] = mem
        n_mem_save[:] = n_mem
        # the stages; the last one is f(t + h, y_new) (FSAL), evaluated with its record and the lateral scan
        failed = 0
        for s in range(1, ns):
            for i in range(nst):
                acc = 0.0
                for j in range(s):
                    if a[s, j] != 0.0:
                        acc += a[s, j] * kst[j, i]
                ys[i] = y[i] + h * acc
            last = s == ns - 1
            st = _rhs(t + cc[s] * h, ys, par, hz, kk, sides, mode, targs, sargs, ws, last, last, kst[s])
            evals += 1
            if st == CALLBACK_FAILED:  # the contact model behind the callback failed: not a matter of the step
                return st, t, y, h, accepted, rejected, k_out, evals, located, st
            if st != 0:
                failed = st
                break
        if failed == 0:
            for i in range(nst):
                y_new[i] = ys[i]  # the last row of A is b
            total, wsum = 0.0, 0.0
            for i in range(nst):
                acc = 0.0
                for s in range(ns):
                    acc += e[s] * kst[s, i]
                err[i] = h * acc
                if weight[i] > 0.0:
                    sc = atol[i] + (rtol * max(abs(y[i]), abs(y_new[i])) if weight[i] > 1.0 else 0.0)
                    total += (err[i] / sc) ** 2
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
        mem_end[:, :, :] = mem
        n_mem_end[:] = n_mem
        for i in range(ncand + 2):
            for f in range(N_FIELDS):
                rec_end[i, f] = rec[i, f]
        _contact_mask(rec, ncand, mask1, gap1)
        switched = False
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
                st = _rhs(t + theta * h, ys, par, hz, kk, sides, mode, targs, sargs, ws, True, True, scratch)
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
                return 1, t, y, h, accepted, rejected, k_out, evals, located, 1
        t_new = t + h
        # force error estimate of a step with output samples (as rk4_run's): the per-wheel contact forces at the
        # propagated solution against those at the embedded lower-order one, y_new - err
        k_first = k_out
        if k_out < out_times.shape[0] and out_times[k_out] <= t_new + tiny:
            _side_forces(rec_end, sides, f4)
            for i in range(nst):
                ys[i] = y_new[i] - err[i]
            st = _rhs(t_new, ys, par, hz, kk, sides, mode, targs, sargs, ws, True, False, scratch)
            evals += 1
            force_err = np.inf
            if st == 0:
                _side_forces(rec, sides, f3)
                force_err = _force_difference(f4, f3)
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
                st = _rhs(out_times[k_out], ys, par, hz, kk, sides, mode, targs, sargs, ws, True, True, scratch)
                evals += 1
                if st != 0:
                    return st, t, y, h, accepted, rejected, k_out, evals, located, st
                states[k_out, :] = ys
                recs[k_out, :, :] = rec
            _side_forces(recs[k_out], sides, f4)
            errs[k_out] = force_err if k_out == k_first else np.nan
            k_out += 1
            for sd in range(2):
                if f4[sd, 0] > fmax:
                    return 2, t_new, y_new, h, accepted + 1, rejected, k_out, evals, located, 2
            if abs(states[k_out - 1, 1]) > ymax:
                return 3, t_new, y_new, h, accepted + 1, rejected, k_out, evals, located, 3
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
        norm = max(norm, 1e-4)
        factor = 0.9 * norm ** (-0.7 / k_order) * err_prev ** (0.4 / k_order)
        factor = min(max(factor, 0.2), 1.0 if after_reject else 10.0)
        err_prev = norm
        carry[0] = err_prev
        h *= factor
        if h_event == h_event:
            # the step was cut short to end at a located switch, not by its error: resume the controller's step
            h = max(h, min(h_event, 10.0 * h_event * factor))
            h_event = np.nan
        after_reject = False
    return 0, t, y, h, accepted, rejected, k_out, evals, located, last_fail


ADAPTIVE_STATUS = {
    1: "blow-up",
    2: "force-anomaly",
    3: "derailed",
    4: "contact-failed",
    CALLBACK_FAILED: "contact-failed",
    UNDERFLOW: "step-size-underflow",
}
"""Status codes of :func:`embedded_run` -> run statuses."""


def supported(scene, provider, model) -> bool:
    """Whether the compiled loop can run this scene with an embedded pair: its method is one of PAIRS and the
    compiled RK4 loop supports the provider and model (compiled.supported).
    """
    from rigid_dynamics.wheelset import compiled

    if scene.integrator.method not in PAIRS:
        return False
    return compiled.supported(replace(scene, integrator=replace(scene.integrator, method="RK4")), provider, model)


def _arguments(packed, settings, scene):
    """(tableau and control arguments) of embedded_run for a run: (a, c, e, p, k, atol, weight)."""
    from rigid_dynamics.wheelset.drivers import tolerances
    from rigid_dynamics.wheelset.state import POSITIONS, WORK, track_positions

    (a, c, e, p), k_order, _ = PAIRS[settings.method]
    atol = tolerances(settings, scene)
    weight = np.full(len(atol), 2.0)  # 2: atol + rtol |y|
    weight[POSITIONS] = 1.0  # 1: atol alone (offsets: x and the spin angle grow along the track, z is ~ r0)
    weight[track_positions(len(atol))] = 1.0  # (absent on the rigid track)
    weight[WORK] = 0.0  # diagnostics, not in the right-hand side
    return a, c, e, p, k_order, atol, weight


def load(packed, settings, scene) -> None:
    """Load (from numba's cache, or compile) embedded_run for the types of ``packed`` (compiled.pack's result):
    zero steps from the zero state.
    """
    par, hz, kk, sides, _, mode, targs, sargs = packed
    a, c, e, p, k_order, atol, weight = _arguments(packed, settings, scene)
    y = np.zeros(len(atol))
    ncand = len(sides)
    embedded_run(
        y, 0.0, 0.0, 1e-3, a, c, e, p, k_order, 1e-6, atol, weight, MIN_STEP_S, 1e-3, EVENT_TIME_TOLERANCE_S, 0,
        par, hz, kk, sides, mode, targs, sargs, np.zeros(0), 0, np.zeros((0, len(y))),
        np.zeros((0, ncand + 2, N_FIELDS)), np.zeros(0), np.array([1e-4, 1.0]), np.zeros((len(a), len(y))),
        np.zeros(ncand, np.int64), np.zeros(ncand), np.zeros(0), np.zeros((0, ncand), np.int64),
        np.zeros(1, np.int64),
    )  # fmt: skip


def initial_step(rhs, y0, atol, rtol, weight, k_order, h_max) -> float:
    """The starting step of Hairer, Norsett & Wanner I, II.4 (algorithm of "Starting step size"), from two
    right-hand sides ``rhs(t, y)``.
    """
    sc = atol + rtol * np.abs(y0)
    on = weight > 0

    def rms(v):
        return float(np.sqrt(np.mean((v[on] / sc[on]) ** 2)))

    f0 = rhs(0.0, y0)
    d0, d1 = rms(y0), rms(f0)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, h_max)
    f1 = rhs(h0, y0 + h0 * f0)
    d2 = rms(f1 - f0) / h0
    big = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if big <= 1e-15 else (0.01 / big) ** (1.0 / k_order)
    step = min(100.0 * h0, h1, h_max)
    return step if np.isfinite(step) and step > 0 else 1e-6


def side_events(ev_t, ev_mask, n, sides):
    """("wheel-lift" | "contact-restored", side, time_s) from the event log: a side is in contact while any of its
    candidates is.
    """
    from rigid_dynamics.wheelset.providers import SIDES

    events = []
    if n == 0:
        return events
    touching = [bool(np.any(ev_mask[0][sides == s])) for s in range(2)]
    for k in range(1, n):
        for s in range(2):
            now = bool(np.any(ev_mask[k][sides == s]))
            if now != touching[s]:
                events.append(("contact-restored" if now else "wheel-lift", SIDES[s], float(ev_t[k])))
                touching[s] = now
    return events


def run_embedded(model, packed, y0, duration, settings, recorder, report, start) -> int:
    """An embedded pair with step-size control in the compiled loop (:func:`embedded_run`), in calls of
    STEPS_PER_CALL accepted steps so that wall time, budget and progress are watched. Records the samples at the
    output times (multiples of output_step_s, and the end); the wheel-lift and contact-restored events are the
    located switches (their times within EVENT_TIME_TOLERANCE_S), not the samples'. Sets ``model.adaptive_stats``.
    Returns the accepted steps.
    """
    import time

    from rigid_dynamics.wheelset import compiled
    from rigid_dynamics.wheelset.drivers import patch_tables
    from rigid_dynamics.wheelset.recorder import Stop

    scene = model.scene
    par, hz, kk, sides, slots, mode, targs, sargs = packed
    compiled.use_callback(model.callback)
    a, c, e, p, k_order, atol, weight = _arguments(packed, settings, scene)
    rtol = settings.relative_tolerance
    ncand = len(sides)
    n_out = int(math.floor(duration / settings.output_step_s + 1e-9))
    out_times = settings.output_step_s * np.arange(1, n_out + 1)
    if len(out_times) == 0 or out_times[-1] < duration - 1e-12:
        out_times = np.append(out_times, duration)
    states = np.zeros((len(out_times), len(y0)))
    recs = np.zeros((len(out_times), ncand + 2, compiled.N_FIELDS))
    errs = np.full(len(out_times), np.nan)
    rec = np.zeros((ncand + 2, compiled.N_FIELDS))

    def rhs(t, y):
        out = np.zeros(len(y))
        status = compiled.rhs_once(t, y, par, hz, kk, sides, mode, targs, sargs, out, rec)
        return out if status == 0 else np.full(len(y), np.nan)

    h = initial_step(rhs, y0, atol, rtol, weight, k_order, settings.max_step_s)
    model.rhs_evaluations += 2
    carry = np.array([1e-4, 0.0])
    kst = np.zeros((len(a), len(y0)))
    mask0, gap0 = np.zeros(ncand, np.int64), np.zeros(ncand)
    ev_t, ev_mask, n_ev = np.zeros(MAX_EVENTS), np.zeros((MAX_EVENTS, ncand), np.int64), np.zeros(1, np.int64)
    stats = {"accepted_steps": 0, "rejected_steps": 0, "located_switches": 0}
    model.adaptive_stats = stats
    y, t, k_out = y0.copy(), 0.0, 0

    def events_to_recorder():
        kept = [ev for ev in recorder.events if ev[0] not in ("wheel-lift", "contact-restored")]
        recorder.events[:] = sorted(kept + side_events(ev_t, ev_mask, int(n_ev[0]), sides), key=lambda ev: ev[2])

    while True:
        status, t_end, y_end, h_next, acc, rej, k_new, evals, located, last_fail = embedded_run(
            y, t, duration, h, a, c, e, p, k_order, rtol, atol, weight, MIN_STEP_S, settings.max_step_s,
            EVENT_TIME_TOLERANCE_S, STEPS_PER_CALL, par, hz, kk, sides, mode, targs, sargs, out_times, k_out, states,
            recs, errs, carry, kst, mask0, gap0, ev_t, ev_mask, n_ev,
        )  # fmt: skip
        model.rhs_evaluations += int(evals)
        stats["accepted_steps"] += int(acc)
        stats["rejected_steps"] += int(rej)
        stats["located_switches"] += int(located)
        if k_new > k_out:
            block = recs[k_out:k_new]
            tables = patch_tables(model, block, sides, slots)
            try:
                recorder.append_many(
                    out_times[k_out:k_new],
                    states[k_out:k_new],
                    tables,
                    block[:, ncand : ncand + 2, :3].copy(),
                    errs[k_out:k_new],
                )
            except Stop as stop:
                events_to_recorder()
                stop.steps = stats["accepted_steps"]
                raise
        k_out = k_new
        if status != 0:
            events_to_recorder()
            name = ADAPTIVE_STATUS[int(status)]
            why = ""
            if status == CALLBACK_FAILED and model.callback is not None:
                why = f": {model.callback.message}"
            if status == UNDERFLOW:
                why = (
                    f": the step fell below {MIN_STEP_S:g} s"
                    + (f" after a failed stage ({ADAPTIVE_STATUS[int(last_fail)]})" if last_fail else "")
                    + f" (relative_tolerance = {rtol:g}, absolute_tolerance = {settings.absolute_tolerance:g})"
                )
            stop = Stop(
                name,
                f"compiled {settings.method} stopped ({name}) at t = {t_end:.6g} s{why}",
                float(t_end),
                np.array(y_end[:12]),
            )
            stop.steps = stats["accepted_steps"]
            raise stop
        y, t, h = y_end, float(t_end), float(h_next)
        if t >= duration - 1e-12 * max(1.0, duration):
            break
        if model.rhs_evaluations >= settings.max_rhs_evaluations:
            events_to_recorder()
            stop = Stop("budget-exceeded", f"more than {settings.max_rhs_evaluations} RHS evaluations", t, y[:12])
            stop.steps = stats["accepted_steps"]
            raise stop
        if time.perf_counter() - start > settings.max_wall_time_s:
            events_to_recorder()
            stop = Stop("budget-exceeded", f"wall time above {settings.max_wall_time_s} s", t, y[:12])
            stop.steps = stats["accepted_steps"]
            raise stop
        report(t)
    events_to_recorder()
    report(t)
    return stats["accepted_steps"]
