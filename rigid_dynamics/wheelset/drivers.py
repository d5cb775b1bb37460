"""The integrators over the right-hand side: scipy's adaptive ``OdeSolver`` methods stepped one step at a time
(:func:`run_scipy`, with the Jacobian of :func:`state_jacobian` for Radau and BDF, and the fixed-step RK4 as one more
``OdeSolver``, :func:`_rk4_class`) and the compiled loop (:func:`run_compiled`: one loop for the embedded pairs
DP54/BS32 with step-size control and RK4 with its fixed step, compiled_loop.py), with the force error estimate and
its check (:func:`force_error_check`). Run statuses of the compiled codes: layout.STATUS.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from functools import cache

import numpy as np

from rigid_dynamics.wheelset.equilibrium import contact_force_sums
from rigid_dynamics.wheelset.layout import (
    CALLBACK_FAILED,
    CREEP_FORCE_LONG,
    CREEPAGE_LONG,
    MAX_SLOTS,
    N_FIELDS,
    NORMAL_FORCE,
    STATUS,
    UNDERFLOW,
    record_columns,
    status_name,
)
from rigid_dynamics.wheelset.recorder import Stop
from rigid_dynamics.wheelset.state import (
    N_MECHANICAL,
    N_RIGID,
    POSITIONS,
    SPIN,
    SPIN_RATE,
    VELOCITIES,
    WORK,
    n_states,
    state_names,
    track_positions,
    track_velocities,
)
from rigid_dynamics.wheelset.wheelset_model import ContactFailure

ADAPTIVE_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


def force_error_check(errors: np.ndarray, t: np.ndarray, settled: np.ndarray, settings, message: str):
    """(status, message) of a finished fixed-step run from its force error estimates (relative to the static wheel
    load): "warning" when the largest after the settling distance (``settled``) exceeds ``settings.force_tolerance``
    (or an estimate failed there), else "ok"; when only the start-up exceeds it, the message says that the
    full-run peaks are not converged.

    The estimate is the contact-force difference between RK4 and its embedded third-order solution over the step
    ending at each recorded sample (compiled_loop.embedded_run, :func:`run_scipy`). On the embedded scenes it
    separates the steps whose force results move by more than a few per cent of the static load from those that do
    not, where the contact-passage time against the step misses the creep-force bias of polygonal-wheel at 1 ms and
    step doubling underestimates it (benchmarks/results/step_sensitivity.md).
    """

    def worst(mask):
        values = np.where(mask & ~np.isnan(errors), errors, -np.inf)
        k = int(np.argmax(values)) if len(values) else 0
        return (values[k], k) if len(values) else (-np.inf, 0)

    tol = settings.force_tolerance
    if settings.method == "RK4":
        advice, failed = f"reduce fixed_step_s = {settings.fixed_step_s:g} s", "the third-order state failed"
    else:  # the embedded pairs of compiled_loop.py
        advice = (
            f"tighten relative_tolerance = {settings.relative_tolerance:g} / absolute_tolerance = "
            f"{settings.absolute_tolerance:g}"
        )
        failed = "the embedded lower-order state failed"
    value, k = worst(settled)
    if value > tol:
        what = f"{value:.3g}" if np.isfinite(value) else f"not computable ({failed})"
        return "warning", (
            f"{message}; force error estimate {what} of the static wheel load at t = {t[k]:.6g} s exceeds "
            f"force_tolerance = {tol:g}: {advice}"
        )
    value, k = worst(~settled)
    if value > tol:
        return "ok", (
            f"{message}; the start-up before the settling distance has a force error estimate {value:.3g} at "
            f"t = {t[k]:.6g} s above force_tolerance = {tol:g}: its peaks (full_run_peaks) are not converged"
        )
    return "ok", message


def tolerances(settings, scene):
    """Absolute tolerances per state (atol = ``absolute_tolerance``).

    atol for x, y, z, yaw and roll; 100 atol for the spin angle and the rates; 1000 atol for the spin rate;
    1e-3 J for the two work integrals (diagnostics that do not enter the right-hand side; loosening their
    tolerance 1e4-fold or tightening it to atol (m g + axle load) changes the steps of RK45, BDF, Radau and
    LSODA on hunting-conical by under 2 %: the mechanical states set the steps).
    """
    from rigid_dynamics.wheelset.track import n_positions, travel_m

    n = n_states(n_positions(scene.track_dynamics, travel_m(scene)))
    atol = np.full(n, settings.absolute_tolerance)
    atol[VELOCITIES] = settings.absolute_tolerance * 100.0
    atol[SPIN] = settings.absolute_tolerance * 100.0
    atol[SPIN_RATE] = settings.absolute_tolerance * 1e3
    atol[WORK] = 1e-3
    atol[track_velocities(n)] = settings.absolute_tolerance * 100.0  # the track's rates (absent for the rigid track)
    return atol


_JACOBIAN_RELATIVE_STEP = math.sqrt(np.finfo(float).eps)


def state_jacobian(fun: Callable, velocity_columns: Callable | None = None) -> Callable:
    """Jacobian d f / d y of the 14-state function ``fun`` for the implicit methods Radau and BDF.

    ``velocity_columns``: optional (t, y) -> (n, 6) columns of the velocities (:func:`sensitivity_velocity_columns`:
    from the creep-force sensitivities, for a rung the loop calls back); where it raises ValueError or ContactFailure
    or returns a non-finite entry, those columns are differenced as the others.

    scipy's own finite-difference Jacobian (``num_jac``) perturbs column j by ``factor_j max(atol_j, |y_j|)``
    and multiplies ``factor_j`` by 10 at every evaluation where the column's difference is negligible, with no
    upper bound. The right-hand side does not depend on the two work integrals at all, nor on the spin angle
    without wheel irregularities, so their factors grow tenfold per Jacobian until the step overflows to inf
    after about 300 Jacobians; the perturbed state is then not finite and the Jacobian NaN (BDF on the scene
    hunting-conical stopped at t = 1.58 s with "array must not contain infs or NaNs").

    This Jacobian uses the structure of the equations and steps that do not adapt:

    * rows 0-5 are exact: d/dt (x, y, z, psi, theta, phi) = (x', y', z', psi', theta', phi'), so [0 I 0];
    * columns 12-13 are zero: the work integrals do not enter the right-hand side;
    * columns 0-11 by forward differences with the step sqrt(eps) max(|y_j|, 1) in SI units (1 m, 1 rad,
      1 m/s, 1 rad/s). The step grows with |y_j| for the states that grow without bound (x, spin angle), so
      that (y_j + h) - y_j keeps about half the digits, and does not depend on the tolerances.

    A perturbed state that ``fun`` rejects (NaN, see ``trouble`` in :func:`simulate`) is retried with the
    step reversed. When ``fun`` rejects the state itself (BDF asks for the Jacobian at its predicted state,
    which can be wild after a failed Newton iteration) the last Jacobian is returned: the Newton iteration
    then fails at that state too and the solver halves its step.

    Raises:
        Stop: "solver-failed" when a column cannot be differenced in either direction.
    """
    last = [None]

    def jac(t, y):
        y = np.asarray(y, float)
        n = len(y)
        f0 = fun(t, y)
        if not np.all(np.isfinite(f0)):
            if last[0] is not None:
                return last[0]
            raise Stop("solver-failed", f"no Jacobian: the state function is not finite at t = {t:.6g} s", t, y)
        jac_matrix = np.zeros((n, n))
        jac_matrix[POSITIONS, VELOCITIES] = np.eye(6)
        if n > N_RIGID:
            jac_matrix[track_positions(n), track_velocities(n)] = np.eye((n - N_RIGID) // 2)
        given = None
        if velocity_columns is not None:
            try:
                given = np.asarray(velocity_columns(t, y), float)
            except (ValueError, ContactFailure):
                given = None
            if given is not None and not np.all(np.isfinite(given)):
                given = None
        if given is not None:
            jac_matrix[6:, VELOCITIES] = given[6:]
        differenced = [j for j in range(N_MECHANICAL) if given is None or not VELOCITIES.start <= j < VELOCITIES.stop]
        for j in [*differenced, *range(N_RIGID, n)]:  # not the work integrals
            for sign in (1.0, -1.0):
                trial = y.copy()
                trial[j] += sign * _JACOBIAN_RELATIVE_STEP * max(abs(y[j]), 1.0)
                step = trial[j] - y[j]
                f1 = fun(t, trial)
                if np.all(np.isfinite(f1)):
                    break
            else:
                raise Stop(
                    "solver-failed",
                    f"no Jacobian: the state function is not finite next to the state at t = {t:.6g} s "
                    f"(column {j}, {state_names(n)[j]})",
                    t,
                    y,
                )
            jac_matrix[6:, j] = (f1[6:] - f0[6:]) / step
        last[0] = jac_matrix
        return jac_matrix

    return jac


@cache
def _rk4_class():
    """:class:`RK4` (scipy imported only when a Python-side run needs it)."""
    from scipy.integrate import DenseOutput, OdeSolver

    class RK4Dense(DenseOutput):
        """Cubic Hermite between the step's ends (derivatives k1 at the start and k4, the last stage, at the end)."""

        def __init__(self, t_old, t, y_old, y, k1, k4):
            super().__init__(t_old, t)
            self.y_old, self.y, self.k1, self.k4 = y_old, y, k1, k4

        def _call_impl(self, t):
            h = self.t - self.t_old
            s = (np.asarray(t) - self.t_old) / h
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
            return h00 * self.y_old + h10 * h * self.k1 + h01 * self.y + h11 * h * self.k4

    class RK4(OdeSolver):
        """The classical Runge-Kutta method of order 4 with a fixed step as a scipy ``OdeSolver``: the Python
        right-hand side's RK4 runs through the same driver as scipy's methods (:func:`run_scipy`).

        The step is ``step`` shortened to divide the interval into whole steps; t after n steps is t0 + n h. The
        embedded third-order solution of the same stages and the derivative at the step's end, k5 = f(t + h, y4)
        (the next step's k1), y3 = y + h (k1/6 + k2/3 + k3/3 + k5/6) (Hairer, Norsett & Wanner, Solving ODEs I,
        2nd ed., II.4), is :meth:`third_order`: the force error estimate's second state. Dense output: cubic Hermite
        between the step's ends with k1 and k4.
        """

        def __init__(self, fun, t0, y0, t_bound, step, vectorized=False, **extraneous):
            super().__init__(fun, t0, y0, t_bound, vectorized)
            self.n_steps = max(1, int(math.ceil((t_bound - t0) / step - 1e-9)))
            self.h = (t_bound - t0) / self.n_steps
            self.t_start = t0
            self.steps_done = 0
            self.k_next = None  # f at the current state once evaluated: the next step's k1
            self.stages = None
            self.y_old = None

        def _step_impl(self):
            h, t, y = self.h, self.t, self.y
            k1 = self.k_next if self.k_next is not None else self.fun(t, y)
            k2 = self.fun(t + 0.5 * h, y + 0.5 * h * k1)
            k3 = self.fun(t + 0.5 * h, y + 0.5 * h * k2)
            k4 = self.fun(t + h, y + h * k3)
            self.y_old, self.stages, self.k_next = y, (k1, k2, k3, k4), None
            self.steps_done += 1
            self.y = y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            self.t = self.t_start + self.steps_done * h
            if self.steps_done == self.n_steps:
                self.t_bound = self.t  # n h may round past or short of the interval's end: this is the end
            return True, None

        def derivative_at_end(self):
            """The derivative f at the current state (evaluated once: it is the next step's k1)."""
            if self.k_next is None:
                self.k_next = self.fun(self.t, self.y)
            return self.k_next

        def third_order(self):
            """The embedded third-order solution of the last step (one right-hand side: the next step's k1)."""
            k1, k2, k3, _ = self.stages
            k5 = self.derivative_at_end()
            return self.y_old + self.h * (k1 / 6.0 + k2 / 3.0 + k3 / 3.0 + k5 / 6.0)

        def _dense_output_impl(self):
            return RK4Dense(self.t_old, self.t, self.y_old, self.y, self.stages[0], self.stages[3])

    return RK4


def _force_error(model, solver) -> float:
    """The force error estimate of the last RK4 step: the largest difference of the per-wheel contact forces at the
    propagated state and at the embedded third-order one (inf when one cannot be evaluated), N.
    """
    y3 = solver.third_order()
    try:
        error = float(np.max(np.abs(contact_force_sums(model, solver.y) - contact_force_sums(model, y3))))
    except (ContactFailure, ValueError, ArithmeticError):
        error = math.inf
    return math.inf if math.isnan(error) else error  # NaN: forces not computable at one of the two states


def sensitivity_velocity_columns(model) -> Callable | None:
    """The velocity columns from the creep-force sensitivities (wheelset.creep_jacobian) for the implicit methods'
    Jacobian, when they are sound and pay: a rung the loop calls back (bem, fea, a user model) on the straight rigid
    track; else None (the differences of a compiled law are as accurate and 10-200 times cheaper).

    Measured (benchmarks/results/creep_sensitivities.md, radau_bem_jacobian.md): the BEM's velocity columns by
    forward differences at sqrt(eps) are 150 % off (its tolerance and warm starts), from the sensitivities 0.5 %;
    Radau on hunting-conical with the BEM for 0.01 s took 297 right-hand sides and 165 s with the differences, 112
    and 72 s with the sensitivity columns (final states within 12 x the tolerance: the BEM's noise).
    """
    from rigid_dynamics.wheelset.compiled_laws import LAW_CALLBACK
    from rigid_dynamics.wheelset.compiled_records import law_code

    if model is None or model.elastic or model.par["track_frame"] > 0:
        return None
    if law_code(model.model, model.scene.patch_geometry) != LAW_CALLBACK:
        return None
    from rigid_dynamics.wheelset.creep_jacobian import creep_velocity_columns

    return lambda t, y: creep_velocity_columns(model, t, y).columns


def run_scipy(fun, y0, duration, settings, out_times, recorder, report, model) -> int:
    """The Python right-hand side ``fun`` stepped one step at a time by a scipy ``OdeSolver``: RK45, DOP853, Radau
    (with :func:`state_jacobian`), BDF, LSODA, DP54 / BS32 off the compiled loop (scipy's RK45 / RK23), and RK4
    (:class:`RK4`, fixed step). The samples at ``out_times`` come from the step's dense output (the step's end
    itself when a sample falls on it).

    RK4 also estimates its force error (as compiled_loop.embedded_run): every :func:`steps_between_checks` steps and at
    a sample on the step's end, the contact forces at the propagated and at the embedded third-order state
    (:func:`_force_error`, two extra contact evaluations); a sample on the step's end carries the estimate of that
    step, other samples the largest of the checks since the previous sample. Samples are recorded (and checked for
    anomalies) before the estimate is evaluated.
    """
    from scipy import integrate

    from rigid_dynamics.wheelset.tableaux import SCIPY_EQUIVALENT

    fixed = settings.method == "RK4"
    if fixed:
        cls = _rk4_class()
    else:  # DP54 / BS32 off the compiled loop: the same pairs in scipy (RK45 / RK23), without located switches
        cls = getattr(integrate, SCIPY_EQUIVALENT.get(settings.method, settings.method))
    options = {}
    if settings.method in ("Radau", "BDF"):
        options = {"jac": state_jacobian(fun, sensitivity_velocity_columns(model))}
    if fixed:
        options = {"step": settings.fixed_step_s}
    atol = tolerances(settings, model.scene)
    solver = cls(
        fun, 0.0, y0, duration, rtol=settings.relative_tolerance, atol=atol, max_step=settings.max_step_s, **options
    )
    check_every = steps_between_checks(settings, solver.h) if fixed else 0
    steps = 0
    next_out = 1
    pending = math.nan
    while solver.status == "running":
        t_before = solver.t
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                message = solver.step()
        except Stop as stop:
            stop.steps = steps
            raise
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            # e.g. a Jacobian with non-finite entries after a wild trial step of an implicit method
            stop = Stop("solver-failed", f"{settings.method} failed at t = {solver.t:.6g} s: {exc}", solver.t, solver.y)
            stop.steps = steps
            raise stop from None
        steps += 1
        if solver.status == "failed":
            exc = Stop("solver-failed", f"{settings.method}: {message} (t = {t_before:.6g} s)", t_before, solver.y)
            exc.steps = steps
            raise exc
        if not np.all(np.isfinite(solver.y)):
            exc = Stop("blow-up", f"non-finite state at t = {solver.t:.6g} s", solver.t, solver.y)
            exc.steps = steps
            raise exc
        at_end = False
        try:
            if next_out < len(out_times) and out_times[next_out] <= solver.t + 1e-12 * max(1.0, duration):
                dense = solver.dense_output()
                h = solver.t - solver.t_old
                while next_out < len(out_times) and out_times[next_out] <= solver.t + 1e-12 * max(1.0, duration):
                    t_out = out_times[next_out]
                    at_end = abs((t_out - solver.t_old) / h - 1.0) < 1e-9
                    recorder.record(t_out, solver.y if at_end else dense(t_out), math.nan if at_end else pending)
                    if not at_end:
                        pending = math.nan
                    next_out += 1
            if fixed and (steps % check_every == 0 or at_end):
                error = _force_error(model, solver)
                pending = error if math.isnan(pending) else max(pending, error)
        except Stop as stop:
            stop.steps = steps
            raise
        if at_end and fixed:
            recorder.set_last_error(pending)
            pending = math.nan
        report(solver.t)
    return steps


def patch_tables(model, block, sides, slots) -> dict:
    """The compiled loop's records of a block of output samples (n, candidates + 2, layout.N_FIELDS) as the
    recorder's per-patch tables: field -> (n, 2 sides, MAX_SLOTS), NaN where no candidate sits (PATCH_FIELDS,
    AUTO_PATCH_FIELDS for ``auto``, and FORMED_PATCH_FIELDS: the recorder puts a formed patch's own quantities in
    place of its candidate's, formed_patches.recorded).
    """
    columns = record_columns(model.auto)
    tables = {name: np.full((len(block), 2, MAX_SLOTS), np.nan) for _, name in columns}
    for c in range(len(sides)):
        if slots[c] < MAX_SLOTS:
            for f, name in columns:
                tables[name][:, sides[c], slots[c]] = block[:, c, f]
    return tables


def _stop_from_status(model, status, t_end, y_end, method, steps, why=""):
    """The :class:`Stop` of a compiled loop that ended with a status other than ok (layout.STATUS)."""
    name = status_name(status)
    if status == CALLBACK_FAILED and model.callback is not None:
        why = f": {model.callback.message}"
    elif not why:
        why = f": {STATUS[status][1]}"  # what happened, from the one status table
    message = f"compiled {method} stopped ({name}) at t = {t_end:.6g} s{why}"
    stop = Stop(name, message, float(t_end), np.array(y_end[:12]))
    stop.steps = steps
    return stop


def _watch(model, settings, start, t, y, steps):
    """Raise "budget-exceeded" when the run's right-hand-side budget or wall time is spent."""
    if model.rhs_evaluations >= settings.max_rhs_evaluations:
        stop = Stop("budget-exceeded", f"more than {settings.max_rhs_evaluations} RHS evaluations", t, y[:12])
    elif time.perf_counter() - start > settings.max_wall_time_s:
        stop = Stop("budget-exceeded", f"wall time above {settings.max_wall_time_s} s", t, y[:12])
    else:
        return
    stop.steps = steps
    raise stop


def _append_samples(model, recorder, outputs, k_out, k_new, times):
    """The compiled loop's samples k_out..k_new-1 (at ``times``) to the recorder."""
    ncand = len(model.packed.sides)
    block = outputs.recs[k_out:k_new]
    tables = patch_tables(model, block, model.packed.sides, model.packed.slots)
    recorder.append_many(
        times, outputs.states[k_out:k_new], tables, block[:, ncand : ncand + 2, :3].copy(), outputs.errs[k_out:k_new]
    )


FORCE_CHECK_INTERVAL_S = 1e-3
"""Largest simulated time between two force error checks of an RK4 run, s: with sparse output (say 10 ms) a
wheel-flat impact (about 3 ms at 60 km/h) still meets a check."""


def steps_between_checks(settings, step_s: float) -> int:
    """Steps between force error checks: every output step, at most FORCE_CHECK_INTERVAL_S apart."""
    out_every = max(1, int(round(settings.output_step_s / step_s)))
    return max(1, min(out_every, int(round(FORCE_CHECK_INTERVAL_S / step_s))))


def step_control(settings, scene, max_steps: int, check_every: int = 0):
    """The compiled_loop.StepControl of a run: for an embedded pair, atol per state (:func:`tolerances`) and its
    weights (positions by atol alone: their values carry offsets, x and the spin angle grow along the track, z is
    about r0; the rates by atol + rtol |y|; the work integrals, diagnostics, not controlled); for RK4 the fixed step
    with a force error check every ``check_every`` steps.
    """
    from rigid_dynamics.wheelset.compiled_loop import (
        EVENT_TIME_TOLERANCE_S,
        FIXED_STEP,
        MIN_STEP_S,
        PI_CONTROL,
        StepControl,
    )
    from rigid_dynamics.wheelset.state import track_positions

    atol = tolerances(settings, scene)
    weight = np.full(len(atol), 2.0)  # 2: atol + rtol |y|
    weight[POSITIONS] = 1.0  # 1: atol alone
    weight[track_positions(len(atol))] = 1.0  # (absent on the rigid track)
    weight[WORK] = 0.0  # diagnostics, not in the right-hand side
    controller = FIXED_STEP if settings.method == "RK4" else PI_CONTROL
    return StepControl(
        settings.relative_tolerance, atol, weight, MIN_STEP_S, settings.max_step_s, EVENT_TIME_TOLERANCE_S, max_steps,
        controller, check_every,
    )  # fmt: skip


def initial_step(rhs, y0, control, k_order) -> float:
    """The starting step of Hairer, Norsett & Wanner I, II.4 (algorithm of "Starting step size"), from two
    right-hand sides ``rhs(t, y)``, under the compiled_loop.StepControl ``control``.
    """
    sc = control.atol + control.rtol * np.abs(y0)
    on = control.weight > 0

    def rms(v):
        return float(np.sqrt(np.mean((v[on] / sc[on]) ** 2)))

    f0 = rhs(0.0, y0)
    d0, d1 = rms(y0), rms(f0)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, control.h_max)
    f1 = rhs(h0, y0 + h0 * f0)
    d2 = rms(f1 - f0) / h0
    big = max(d1, d2)
    h1 = max(1e-6, h0 * 1e-3) if big <= 1e-15 else (0.01 / big) ** (1.0 / k_order)
    step = min(100.0 * h0, h1, control.h_max)
    return step if np.isfinite(step) and step > 0 else 1e-6


def side_events(events, sides):
    """("wheel-lift" | "contact-restored", side, time_s) from the compiled loop's event log
    (compiled_loop.EventLog): a side is in contact while any of its candidates is.
    """
    from rigid_dynamics.wheelset.providers import SIDES

    n = int(events.count[0])
    found = []
    if n == 0:
        return found
    touching = [bool(np.any(events.masks[0][sides == s])) for s in range(2)]
    for k in range(1, n):
        for s in range(2):
            now = bool(np.any(events.masks[k][sides == s]))
            if now != touching[s]:
                found.append(("contact-restored" if now else "wheel-lift", SIDES[s], float(events.times[k])))
                touching[s] = now
    return found


def _fixed_step_plan(settings, duration):
    """RK4's step h (``fixed_step_s`` shortened to divide the run into whole steps), its output times (every
    ``out_every`` steps: multiples of h, the last sample at or before the end), the steps between force error checks
    and the steps per call of the compiled loop (a multiple of both, about 2000).
    """
    n_steps = max(1, int(math.ceil(duration / settings.fixed_step_s - 1e-9)))
    h = duration / n_steps
    out_every = max(1, int(round(settings.output_step_s / h)))
    check_every = steps_between_checks(settings, h)
    period = math.lcm(out_every, check_every)
    out_times = np.arange(1, n_steps // out_every + 1) * out_every * h
    return h, out_times, check_every, max(period, (2000 // period) * period)


def _longitudinal_sums(rec: np.ndarray, ncand: int) -> tuple[float, float, float]:
    """(total longitudinal creep force, N; total normal force, N; the largest |xi| of the candidates in contact) of
    one record (ncand + 2, layout.N_FIELDS): what the traction controller measures (traction.py).
    """
    block = rec[:ncand]
    touching = block[:, NORMAL_FORCE] > 0.0
    creepage = float(np.max(np.abs(block[touching, CREEPAGE_LONG]))) if np.any(touching) else 0.0
    return float(np.nansum(block[:, CREEP_FORCE_LONG])), float(np.nansum(block[:, NORMAL_FORCE])), creepage


def run_compiled(model, y0, duration, settings, recorder, report, start) -> int:
    """The compiled loop (compiled_loop.embedded_run) for every method of tableaux.TABLEAUX: the embedded pairs
    DP54/BS32 with step-size control, in calls of compiled_loop.STEPS_PER_CALL accepted steps, and RK4 with its
    fixed step (:func:`_fixed_step_plan`), so that wall time, budget and progress are watched between calls.
    Records the samples at the output times (the pairs: multiples of output_step_s, and the end; RK4: every
    ``out_every`` steps); for the pairs the wheel-lift and contact-restored events are the located switches (their
    times within compiled_loop.EVENT_TIME_TOLERANCE_S), not the samples', and ``model.adaptive_stats`` is set.
    Returns the accepted steps.
    """
    from rigid_dynamics.wheelset.compiled_loop import (
        MAX_EVENTS,
        MIN_STEP_S,
        STARTED,
        STEPS_PER_CALL,
        Carried,
        EventLog,
        Outputs,
        embedded_run,
    )
    from rigid_dynamics.wheelset.compiled_rhs import rhs_once, use_callback
    from rigid_dynamics.wheelset.tableaux import TABLEAUX

    scene, run = model.scene, model.packed
    use_callback(model.callback)
    tableau, _ = TABLEAUX[settings.method]
    fixed = settings.method == "RK4"
    ncand = len(run.sides)
    if fixed:
        h, out_times, check_every, per_call = _fixed_step_plan(settings, duration)
        control = step_control(settings, scene, per_call, check_every)
    else:
        control = step_control(settings, scene, STEPS_PER_CALL)
        n_out = int(math.floor(duration / settings.output_step_s + 1e-9))
        out_times = settings.output_step_s * np.arange(1, n_out + 1)
        if len(out_times) == 0 or out_times[-1] < duration - 1e-12:
            out_times = np.append(out_times, duration)
    outputs = Outputs(
        out_times,
        np.zeros((len(out_times), len(y0))),
        np.zeros((len(out_times), ncand + 2, N_FIELDS)),
        np.full(len(out_times), np.nan),
    )
    rec = np.zeros((ncand + 2, N_FIELDS))

    def rhs(t, y):
        out = np.zeros(len(y))
        status = rhs_once(t, y, run, out, rec)
        return out if status == 0 else np.full(len(y), np.nan)

    if not fixed:
        h = initial_step(rhs, y0, control, tableau.k_order)
        model.rhs_evaluations += 2
    carried = Carried(np.array([1e-4, 0.0]), np.zeros((len(tableau.a), len(y0))), np.zeros(ncand, np.int64),
                      np.zeros(ncand))  # fmt: skip
    n_events = 0 if fixed else MAX_EVENTS  # RK4 locates no switch: its events are the samples' (recorder.py)
    events = EventLog(np.zeros(n_events), np.zeros((n_events, ncand), np.int64), np.zeros(1, np.int64))
    stats = {"accepted_steps": 0, "rejected_steps": 0, "located_switches": 0}
    if not fixed:
        model.adaptive_stats = stats
    y, t, k_out = y0.copy(), 0.0, 0
    traction = getattr(model, "traction", None)
    if traction is not None:
        # the controller samples at the output times: each call of the loop ends on the next one (RK4: per_call
        # is the steps between samples), and the torque is set from the sample's record (traction.py)
        rhs(0.0, y0)
        model.rhs_evaluations += 1
        run.par["torque_N_m"] = traction.update(0.0, *_longitudinal_sums(rec, ncand))
        if fixed and len(out_times):  # (a run shorter than one output step has no sample after t = 0)
            control = control._replace(max_steps=max(1, int(round(out_times[0] / h))))

    def events_to_recorder():
        if not fixed:
            kept = [ev for ev in recorder.events if ev[0] not in ("wheel-lift", "contact-restored")]
            recorder.events[:] = sorted(kept + side_events(events, run.sides), key=lambda ev: ev[2])

    while True:
        t_end = duration if traction is None or fixed else float(out_times[min(k_out, len(out_times) - 1)])
        outcome = embedded_run(y, t, t_end, h, tableau, control, run, outputs, k_out, carried, events)
        model.rhs_evaluations += outcome.evaluations
        stats["accepted_steps"] += outcome.accepted
        stats["rejected_steps"] += outcome.rejected
        stats["located_switches"] += outcome.located
        try:
            if outcome.k_out > k_out:
                _append_samples(model, recorder, outputs, k_out, outcome.k_out, out_times[k_out : outcome.k_out])
        except Stop as stop:
            events_to_recorder()
            stop.steps = stats["accepted_steps"]
            raise
        k_out = outcome.k_out
        if outcome.status != 0:
            events_to_recorder()
            why = ""
            if outcome.status == UNDERFLOW:
                last = outcome.last_failure
                why = (
                    f": the step fell below {MIN_STEP_S:g} s"
                    + (f" after a failed stage ({status_name(last)})" if last else "")
                    + f" (relative_tolerance = {control.rtol:g}, absolute_tolerance = {settings.absolute_tolerance:g})"
                )
            raise _stop_from_status(
                model, outcome.status, outcome.t, outcome.y, settings.method, stats["accepted_steps"], why
            )
        y, t, h = outcome.y, outcome.t, outcome.h
        if traction is not None and k_out > 0 and abs(out_times[k_out - 1] - t) <= 1e-12 * max(1.0, duration):
            run.par["torque_N_m"] = traction.update(t, *_longitudinal_sums(outputs.recs[k_out - 1], ncand))
            carried.control[STARTED] = 0.0  # the first stage f(t, y) again, with the new torque
        if t >= duration - 1e-12 * max(1.0, duration):
            break
        try:
            _watch(model, settings, start, t, y, stats["accepted_steps"])
        except Stop:
            events_to_recorder()
            raise
        report(t)
    events_to_recorder()
    report(t)
    return stats["accepted_steps"]
