"""Running a wheelset scene: provider and model selection, the start, the choice of driver, the result.

Where the parts live: the drivers (scipy's adaptive methods and RK4 on the Python right-hand side, the compiled
loop for RK4, DP54 and BS32) in drivers.py; the output samples, events and anomaly checks in recorder.py; the start
(static equilibrium, free rolling, elastic track at rest) in equilibrium.py; :class:`SimulationResult`, its summary
and the time-series files in results.py. This module re-exports the public names of those (``SimulationResult``,
``STATUSES``, ``save_timeseries``, ``timeseries_arrays``, ``dominant_wavelength_m``, ``initial_state``).

``simulate(scene, progress=None) -> SimulationResult``. The adaptive methods are scipy's
``OdeSolver`` classes (RK45, DOP853, Radau, BDF, LSODA) stepped one step at a time, so that the run
can be watched: output samples are taken from each step's dense output at the fixed output times,
and after every step the state is checked. The implicit Radau and BDF get the Jacobian of
``state_jacobian`` (exact kinematic rows, fixed finite-difference steps) instead of scipy's own.
``RK4`` is the classical fourth-order Runge-Kutta method with a fixed step (Butcher 1987 tableau:
c = (0, 1/2, 1/2, 1), b = (1/6, 1/3, 1/3, 1/6)). ``DP54`` and ``BS32`` are the embedded pairs Dormand-Prince 5(4)
and Bogacki-Shampine 3(2) with step-size control inside the compiled loop (compiled_loop.py: PI controller,
dense output at the output times, contact onset and loss located within the step and reported as the events'
times); a scene the compiled loop cannot run takes scipy's RK45 / RK23 (the same pairs) on the Python path.

Safety (a run never hangs and never writes NaN silently): the run ends with a status
(``SimulationResult.status``) and the time and state where it happened when

* ``"blow-up"``: the state or its derivative is not finite;
* ``"force-anomaly"``: a normal force exceeds ``max_force_factor`` times the static wheel load;
* ``"derailed"``: |y| exceeds ``max_lateral_displacement_m``;
* ``"contact-failed"``: a contact model failed or the creepages became undefined (rolling speed 0);
* ``"solver-failed"``: the adaptive solver could not continue (step size too small), or a numerical exception
  was raised below the driver (:data:`NUMERICAL_ERRORS`, e.g. the curvature code for a huge stiffness with RK4);
* ``"step-size-underflow"``: DP54/BS32 in the compiled loop needed a step below compiled_loop.MIN_STEP_S;
* ``"budget-exceeded"``: more than ``max_rhs_evaluations`` evaluations or ``max_wall_time_s``;
* ``"wheel-lift"``: a wheel lost contact and ``stop_at_wheel_lift`` is set;
* ``"invalid-initial-state"``: no static equilibrium was found for the initial state (also when its search
  raised one of :data:`NUMERICAL_ERRORS`, e.g. for a tiny shear modulus);
* ``"step-unstable"``: a fixed-step RK4 run ended as a blow-up, force anomaly, derailment or solver failure and
  its step is beyond RK4's stability limit of the run linearised at its start (:mod:`.stability`): the failure
  is the integrator's, not the wheelset's (the message keeps the original status and gives the limit);

``"warning"`` when a fixed-step RK4 run reaches the end but its error estimate of the contact forces
(:func:`force_error_check`) exceeds the scene's ``force_tolerance``, or its step is beyond that stability limit
(the numbers are there, but the step is too coarse to trust them), or when a run of scipy's methods (no force
error estimate) reaches the end with an energy balance above :data:`ENERGY_TOLERANCE_RELATIVE` (a tolerance too
loose for the run), or when the beam's modal cut-off error (discretisation.modal_cutoff_check, a measured rule)
exceeds ``force_tolerance``, or when a BEM patch's own grid-error estimate of its forces exceeds the BEM's
``grid_tolerance`` (discretisation.contact_grid_check), or when a companion estimate (the contact grid, the geometry
tables, scipy's step: discretisation.companion_check) exceeds ``force_tolerance``, or when ``auto`` reused BEM patches
and a correction measured at a re-solve departed from the fresh solution by more than ``contact_tolerance``
(discretisation.auto_reuse_check), or when ``auto`` served recorded patches on Hertz's ellipse whose sampled gap
departs from it beyond the rung's measured box (discretisation.auto_geometry_check); and ``"ok"`` when it reaches the
end without any of these (one function judges a run's step or tolerances this way: :func:`judge_step`; the
companions follow it). Events (wheel lift, contact restored, flange contact onset, adhesion limit and wheel slide) are
detected on the output samples, so their times are known to one output step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from rigid_dynamics.wheelset.discretisation import (
    Companions,
    auto_geometry_check,
    auto_reuse_check,
    companion_check,
    companion_errors,
    contact_grid_check,
    modal_cutoff_check,
)
from rigid_dynamics.wheelset.drivers import ADAPTIVE_METHODS, force_error_check, run_compiled, run_scipy
from rigid_dynamics.wheelset.equilibrium import elastic_start, initial_state
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import ConicalProvider, TableProvider
from rigid_dynamics.wheelset.recorder import NUMERICAL_ERRORS, Recorder, Stop, adhesion_events
from rigid_dynamics.wheelset.results import (
    STATUSES,
    SimulationResult,
    dominant_wavelength_m,
    save_timeseries,
    timeseries_arrays,
)
from rigid_dynamics.wheelset.stability import NUMERICAL_LOOKING, judge_fixed_step, rk4_stable_step
from rigid_dynamics.wheelset.traction import TractionController
from rigid_dynamics.wheelset.wheelset_model import ContactFailure, WheelsetModel

__all__ = [
    "ADAPTIVE_METHODS",
    "NUMERICAL_ERRORS",
    "STATUSES",
    "SimulationResult",
    "build_provider",
    "dominant_wavelength_m",
    "get_contact_model",
    "initial_state",
    "model_options",
    "save_timeseries",
    "simulate",
    "timeseries_arrays",
]


# ------------------------------------------------------------------------------------------------
def build_provider(scene: DynamicsScene):
    """The contact-geometry provider of a scene (``contact_provider``, "auto" rules in DynamicsScene).

    Raises:
        ValueError: the provider cannot serve the scene (the message says why).
    """
    choice = scene.contact_provider
    track, irr = scene.track, scene.irregularities
    if choice == "auto":
        if track.is_conical and not irr.needs_search:
            choice = "conical"
        elif irr.joint_dip_angle_rad > 0:  # the 3-D search does not evaluate the dipped joint
            choice = "tables"
        elif irr.any:
            choice = "search"
        else:
            choice = "tables"
    if choice == "conical":
        if not track.is_conical:
            raise ValueError(
                f"contact_provider = 'conical': needs wheel_profile = 'conical' and rail_profile = 'circular', "
                f"got {track.wheel_profile!r} and {track.rail_profile!r}"
            )
        return ConicalProvider(scene.wheelset, track, irr)
    if choice == "tables":
        if track.is_conical:
            section = ConicalProvider(scene.wheelset, track)
        else:
            from rigid_dynamics.wheelset.providers import ProfileSectionProvider

            section = ProfileSectionProvider(scene.wheelset, track)
        return TableProvider(
            section, scene.wheelset.nominal_radius_m, irregularities=irr, cache_parameters=(scene.wheelset, track)
        )
    if choice == "search":
        from rigid_dynamics.wheelset.providers import SearchProvider

        return SearchProvider(scene.wheelset, track, irr)
    raise ValueError(f"contact_provider = {choice!r}: unknown")  # pragma: no cover (validated by the scene)


def get_contact_model(name_or_model):
    """A contact model instance from a registered name or an instance (registry.get_model)."""
    from rigid_dynamics.contact.registry import get_model

    return get_model(name_or_model)


def model_options(name: str, scene: DynamicsScene) -> dict | None:
    """Options handed to the contact model in a run: the scene's FASTSIM grid, no FASTSIM fields (``table``: its
    source's); auto gets the scene's tolerance.
    """
    fastsim = {"fields": False, "nx": scene.fastsim_elements_per_strip, "ny": scene.fastsim_strips}
    if name in ("fastsim", "table"):
        return fastsim
    if name == "auto":
        return {"tolerance": scene.contact_tolerance, "model_options": {"fastsim": fastsim}}
    return None


def simulate(
    scene: DynamicsScene,
    progress: Callable[[float], None] | None = None,
    *,
    provider=None,
    contact_model=None,
    compiled: bool | None = None,
    companions: bool = True,
) -> SimulationResult:
    """Run a scene and return its :class:`SimulationResult` (never raises for numerical trouble).

    Args:
        scene: the scene.
        progress: optional callable(fraction in [0, 1]) called as the run advances (about 100 times).
        provider: optional provider instance overriding the scene's ``contact_provider`` (e.g. a
            prebuilt TableProvider reused across runs).
        contact_model: optional model instance or registered name overriding ``scene.contact_model``.
        compiled: use the compiled loop (rigid_dynamics.wheelset.compiled_loop) when it supports the run
            (None: whenever it does; False: never; True: required, ValueError if unsupported).
        companions: state the discretisation errors by companion evaluations (discretisation.companion_errors;
            False inside a companion run).

    Raises:
        ValueError: the scene cannot be set up (unknown model, provider that cannot serve it).
    """
    provider = provider if provider is not None else build_provider(scene)
    model_obj = get_contact_model(contact_model if contact_model is not None else scene.contact_model)
    from rigid_dynamics.wheelset.compiled_records import geometry_mode, load, supported
    from rigid_dynamics.wheelset.layout import GEOMETRY_SEARCH
    from rigid_dynamics.wheelset.tableaux import PAIRS

    embedded = scene.integrator.method in PAIRS
    can_compile = supported(scene, provider)
    if compiled and not can_compile:
        raise ValueError(
            "compiled = True: the compiled loop needs method RK4, DP54 or BS32 and a TableProvider or a "
            "SearchProvider on tabulated surfaces"
        )
    use_compiled = can_compile and compiled is not False
    options = model_options(getattr(model_obj, "name", ""), scene)
    # the compiled 3-D search tracks its contact points between RK4 stages: outside the compiled loop (and for the
    # finite-difference Jacobian of the stability check) the contact package's search gives the geometry
    search_in_python = geometry_mode(provider) == GEOMETRY_SEARCH
    if scene.traction.active and not use_compiled:
        raise ValueError(
            f"traction.mode = {scene.traction.mode!r}: the traction controller runs in the compiled loop only "
            "(method RK4, DP54 or BS32 with a TableProvider or a SearchProvider on tabulated surfaces)"
        )
    model = WheelsetModel(scene, provider, model_obj, options, python_geometry=search_in_python and not use_compiled)
    traction = scene.traction
    model.traction = TractionController(traction, scene.wheelset.nominal_radius_m) if traction.active else None
    settings = scene.integrator
    duration = scene.duration_s
    packed = model.packed
    if use_compiled:
        # the compiled code (from numba's cache) is loaded before the clock starts
        load(packed)
    start = time.perf_counter()
    recorder = Recorder(model, scene)
    status, message, fail_t, fail_state = "ok", "", None, None
    steps = 0

    try:
        state0, ok, why = elastic_start(model, initial_state(scene))
    except NUMERICAL_ERRORS as exc:  # e.g. a tiny shear modulus: the wheel sinks until the curvatures turn negative
        state0, ok, why = initial_state(scene), False, f"{type(exc).__name__}: {exc}"
    model.frame_x0 = float(state0[0])
    packed.par["frame_x0_m"] = model.frame_x0  # the suspension frame starts where the wheelset does
    model.rhs_evaluations = 0
    full0 = model.full_state(state0)
    last_fraction = [-1.0]

    def report(t):
        if progress is not None:
            fraction = min(1.0, t / duration)
            if fraction - last_fraction[0] >= 0.01 or fraction >= 1.0 and last_fraction[0] < 1.0:
                last_fraction[0] = fraction
                progress(fraction)

    implicit = settings.method in ("Radau", "BDF")
    bad_trials = [0]

    def trouble(status, message, t, y):
        # Implicit methods evaluate trial states inside their Newton iterations; a wild trial is
        # answered with NaN so that the solver rejects the step and retries smaller. Only many such
        # answers in a row (or trouble on an accepted step, checked after each step) end the run.
        if implicit and bad_trials[0] < 50:
            bad_trials[0] += 1
            return np.full(len(y), np.nan)
        raise Stop(status, message, t, y[:12])

    def fun(t, y):
        if model.rhs_evaluations >= settings.max_rhs_evaluations:
            raise Stop("budget-exceeded", f"more than {settings.max_rhs_evaluations} RHS evaluations", t, y[:12])
        if time.perf_counter() - start > settings.max_wall_time_s:
            raise Stop("budget-exceeded", f"wall time above {settings.max_wall_time_s} s", t, y[:12])
        if not np.all(np.isfinite(y)):
            return trouble("blow-up", f"non-finite state at t = {t:.6g} s", t, y)
        try:
            d = model.derivative(t, y)
        except ContactFailure as exc:
            return trouble("contact-failed", f"{exc} (t = {t:.6g} s)", t, y)
        if not np.all(np.isfinite(d)):
            return trouble("blow-up", f"non-finite state derivative at t = {t:.6g} s", t, y)
        bad_trials[0] = 0
        return d

    n_out = int(math.floor(duration / settings.output_step_s + 1e-9))
    out_times = settings.output_step_s * np.arange(n_out + 1)
    if out_times[-1] < duration - 1e-12:
        out_times = np.append(out_times, duration)

    try:
        if not ok:
            raise Stop("invalid-initial-state", f"no static equilibrium of z and roll found: {why}", 0.0, state0)
        recorder.record(0.0, full0)
        next_out = 1
        if use_compiled:
            steps = run_compiled(model, full0, duration, settings, recorder, report, start)
        else:
            steps = run_scipy(fun, full0, duration, settings, out_times, recorder, report, model)
        message = f"reached t = {duration:g} s"
        stats = getattr(model, "adaptive_stats", None)
        if use_compiled and embedded and stats:
            message += (
                f" ({settings.method}: {stats['accepted_steps']} steps, {stats['rejected_steps']} rejected, "
                f"{stats['located_switches']} contact switches located)"
            )
        del next_out
    except Stop as stop:
        status, message, fail_t, fail_state = stop.status, stop.message, stop.t, stop.state
        steps = steps or getattr(stop, "steps", 0)
    except ContactFailure as exc:
        status, message = "contact-failed", str(exc)
    except NUMERICAL_ERRORS as exc:  # raised below the driver (e.g. the curvature code for a huge stiffness with RK4)
        status, message = "solver-failed", f"numerical failure: {type(exc).__name__}: {exc}"
    wall = time.perf_counter() - start
    t, states, patches, forces, kin, pot, wc, we, errors, track_full = recorder.arrays()
    track_names, track_states = recorder.summary_arrays()
    checked = settings.method == "RK4" or (use_compiled and embedded)  # a force error estimate at the samples

    def probe():
        # the Python face of the right-hand side at the run's start, for RK4's stability limit (stability.py)
        if use_compiled and search_in_python:
            python = WheelsetModel(scene, provider, model_obj, options, python_geometry=True)
            python.frame_x0, python.track_rest = model.frame_x0, model.track_rest
            return python
        return model

    result = SimulationResult(
        status=status,
        message=message,
        t=t,
        states=states,
        patches=patches,
        contact_force_N=forces,
        kinetic_energy_J=kin,
        potential_energy_J=pot,
        work_contact_J=wc,
        work_exterior_J=we,
        events=tuple(sorted(recorder.events + _adhesion(scene, t, patches), key=lambda e: e[2])),
        rhs_evaluations=model.rhs_evaluations,
        steps=steps,
        wall_time_s=wall,
        failure_time_s=None if fail_t is None else float(fail_t),
        failure_state=None if fail_state is None else np.array(fail_state[:12], float),
        provider=getattr(provider, "name", type(provider).__name__),
        contact_model=getattr(model_obj, "name", type(model_obj).__name__),
        method=settings.method,
        compiled=use_compiled,
        force_error_estimate=errors / scene.static_wheel_load_N if checked else None,
        scene=scene,
        track_states=track_states,
        track_state_names=tuple(track_names or ()),
        track_full_states=track_full,
        callback_stats=model.callback.stats() if model.callback is not None else None,
        traction=model.traction.series(t) if model.traction is not None else None,
    )
    result = judge_step(result, _Rerun(provider, model_obj, compiled), probe if ok else None, full0)
    if companions:  # the discretisations the step's judgement cannot see (discretisation.companion_errors)
        stated = companion_errors(
            result,
            Companions(
                provider,
                lambda p: WheelsetModel(scene, p, model_obj, options, python_geometry=False),
                lambda s: simulate(s, provider=provider, contact_model=model_obj, compiled=compiled, companions=False),
            ),
        )
        status, message = companion_check(result.status, result.message, stated, settings.force_tolerance)
        result = replace(result, status=status, message=message, companion_errors=stated)
    cache = getattr(provider, "cache", None)  # the contact tables' disk cache (providers/table_cache.py)
    if cache is not None and cache.note:
        result = replace(result, message=f"{result.message}; {cache.note}")
    return result


class _Rerun(NamedTuple):
    """What a second run of the same scene (the half-step check) takes: the provider, the contact model and
    ``compiled`` as :func:`simulate` was called.
    """

    provider: object
    model_obj: object
    compiled: bool | None


def judge_step(result: SimulationResult, rerun: _Rerun, probe, full0: np.ndarray) -> SimulationResult:
    """The one judgement of a run's step (RK4) or tolerances (every other method), after the run, in this order:

    1. a run with a force error estimate (RK4, the compiled pairs) that reached its end: the estimate after the
       settling distance against ``force_tolerance`` (drivers.force_error_check, "warning" above it);
    2. RK4 from a consistent start (``probe``: a callable giving the model whose Jacobian is linearised; None when
       the start was not consistent): the step against RK4's stability limit at the start, or at the recorded state
       of the largest contact force when the run failed, or ended above ``force_tolerance`` in step 1, within the
       start's limit (:func:`_limit_at_largest_force`);
       a numerical-looking failure beyond the limit becomes "step-unstable" (stability.judge_fixed_step);
    3. a run with a force error estimate in which a wheel lifted after the settling distance: the run again at half
       the step or a tenth of the tolerances (:func:`_half_step_check`);
    4. scipy's methods (no force error estimate): the energy balance (:func:`_energy_check`);
    5. the beam's modal cut-off error (discretisation.modal_cutoff_check);
    6. the BEM patches' own grid-error estimates (discretisation.contact_grid_check);
    7. auto's reused BEM patches' measured corrections (discretisation.auto_reuse_check);
    8. auto's patches served on the ellipse against their sampled gap (discretisation.auto_geometry_check).
    """
    scene = result.scene
    settings = scene.integrator
    status, message = result.status, result.message
    t, states = result.t, result.states
    checked = result.force_error_estimate is not None
    if checked and status == "ok":
        settled = states[:, 0] - states[0, 0] >= scene.settling_distance_m if len(t) else np.zeros(0, bool)
        status, message = force_error_check(result.force_error_estimate, t, settled, settings, message)
    if settings.method == "RK4" and probe is not None:
        try:
            model = probe()
            limit = rk4_stable_step(lambda y: model.derivative(0.0, y), full0, jac=model.state_jacobian)
        except (ContactFailure, *NUMERICAL_ERRORS):
            limit = None
        diverged = checked and bool(np.any(np.nan_to_num(result.force_error_estimate, nan=0.0) > STEP_ERROR_DIVERGED))
        failed = status in NUMERICAL_LOOKING or diverged
        # a run that reached its end with its force error above force_tolerance may owe it to the step's stability
        # at its largest force, as a failed one does: it stays "warning", with that limit in its message
        inaccurate = checked and status == "warning" and result.status == "ok"
        if limit is not None and (failed or inaccurate) and not settings.fixed_step_s > limit.max_step_s:
            limit = _limit_at_largest_force(model, result, limit, failed)
        if limit is not None:
            status, message = judge_fixed_step(status, message, settings.fixed_step_s, limit, diverged)
    if (status, message) != (result.status, result.message):
        result = replace(result, status=status, message=message)
    if checked and status == "ok" and settings.lift_half_step_check and _lifted_after_settling(result):
        result = _half_step_check(result, *rerun)
    if not checked and result.status == "ok":
        result = _energy_check(result, settings)
    status, message = modal_cutoff_check(result.status, result.message, scene, settings.force_tolerance)
    status, message = contact_grid_check(status, message, result.callback_stats)
    status, message = auto_reuse_check(status, message, result.callback_stats)
    status, message = auto_geometry_check(status, message, result.auto_geometry())
    return result if status == result.status else replace(result, status=status, message=message)


STEP_ERROR_DIVERGED = 10.0
"""A fixed-step run whose force error estimate exceeds this (ten static wheel loads) somewhere has diverged there
rather than made a truncation error: it is judged as a failed run (stability.judge_fixed_step: "step-unstable" when
the step is beyond RK4's limit at its start or at its largest contact force), not as an error above tolerance.
wheel-flat on the lumped track at 0.5 ms ran to its end with an estimate of 25.5 static loads at t = 0.114 s after
the first impact, and at 5 ms on the rigid track with 1.8e3 (tests/test_dynamics_error_estimate.py); steps just
beyond the limit give estimates of 1.4-2.3 there and stay "warning", with the limit in the message."""

ENERGY_TOLERANCE_RELATIVE = 0.01
"""The energy balance (SimulationResult.energy_balance_relative) above which a run without a force error estimate
(scipy's methods) ends "warning": 1 % of the largest kinetic energy unaccounted for. hunting-conical with RK45 at
rtol 1e-6: 6e-8 over 1 s; at rtol 1e-2 over 3 s: 0.65, with a peak normal force of 240 kN against 89 kN."""


def _energy_check(result: SimulationResult, settings) -> SimulationResult:
    """A scipy-integrated run that reached its end: "warning" when its energy balance exceeds the tolerance (its
    error control held each step's local error, not the solution: a loose rtol lets the run drift far off).
    """
    balance = result.energy_balance_relative
    if not balance > ENERGY_TOLERANCE_RELATIVE:
        return result
    return replace(
        result,
        status="warning",
        message=f"{result.message}; energy balance {balance:.3g} of the largest kinetic energy (above "
        f"{ENERGY_TOLERANCE_RELATIVE:g}): {settings.method} at relative_tolerance {settings.relative_tolerance:g} "
        "is too loose for this run; tighten integrator.relative_tolerance",
    )


def _adhesion(scene, t, patches) -> list[tuple]:
    """The adhesion-limit and wheel-slide events (recorder.adhesion_events) of a driven or braked wheelset (scene
    traction_torque_N_m != 0 or a [traction] controller); none otherwise.
    """
    driven = scene.loads.traction_torque_N_m != 0.0 or scene.traction.active
    if not driven or patches is None or "creepage_long" not in patches:
        return []
    return adhesion_events(t, patches)


def _limit_at_largest_force(model, result: SimulationResult, start_limit, failed: bool = True):
    """RK4's stability limit at the recorded state of the largest contact force, if smaller than ``start_limit``.

    A fixed-step run that failed (blow-up, force anomaly, derailment, solver failure) with a step within the limit
    of its start may still have failed numerically: the Hertz spring stiffens as N^(1/3), so at an impact of k times
    the static load the contact mode is k^(1/6) faster and the limit that much smaller (wheel-flat on the elastic
    track at 0.5 ms: within the start's 0.568 ms, derailed after its first impact; step_sensitivity.md). The state
    of the largest normal force recorded before the failure is a state the run visited; beyond the limit there the
    failure is the integrator's too. A run that reached its end with its force error above ``force_tolerance``
    (``failed`` False) is judged at the same state: the same run at the default ``max_force_factor`` ends with an
    estimate of 1.38 static loads, its step 2 x the limit at its largest force. Returns ``start_limit`` when that
    limit is not smaller or cannot be computed.
    """
    t, states, patches = result.t, result.states, result.patches
    work_contact, work_exterior, track_states = result.work_contact_J, result.work_exterior_J, result.track_full_states
    normal = np.nan_to_num(patches["normal_force_N"], nan=0.0).sum(axis=2).max(axis=1) if len(t) else np.zeros(0)
    finite = np.isfinite(normal) & np.all(np.isfinite(states), axis=1)
    if not np.any(finite):
        return start_limit
    k = int(np.argmax(np.where(finite, normal, -np.inf)))
    parts = [states[k], [work_contact[k], work_exterior[k]]]
    if track_states is not None:
        parts.append(track_states[k])
    y = np.concatenate(parts)
    try:
        limit = rk4_stable_step(lambda yy: model.derivative(float(t[k]), yy), y, jac=model.state_jacobian)
    except (ContactFailure, *NUMERICAL_ERRORS):
        return start_limit
    if not limit.max_step_s < start_limit.max_step_s:
        return start_limit
    where = f"at t = {t[k]:.6g} s, the largest contact force ({normal[k]:.4g} N)"
    where += " before the failure" if failed else ""
    return replace(limit, where=where)


def _lifted_after_settling(result: SimulationResult) -> bool:
    """Whether a wheel lost contact after the settling distance (a "wheel-lift" event there)."""
    if len(result.t) == 0:
        return False
    settled_from = result.t[np.argmax(result.settled)] if np.any(result.settled) else math.inf
    return any(kind == "wheel-lift" and time_s >= settled_from for kind, _, time_s in result.events)


def _half_step_check(result: SimulationResult, provider, model_obj, compiled) -> SimulationResult:
    """The global check of a fixed-step run in which a wheel lifted off: the run again at half the step, and the
    settled peaks compared (normal, longitudinal and lateral creep force per wheel, relative to the static load).

    After a wheel lift the re-impact depends on the flight: the local force error estimate stays small while the
    later impacts move (wheel-flat on the rigid track at 0.1 ms: estimate 1e-3, re-impact peaks 3.6 % of the static
    load against a 0.025 ms run; benchmarks/results/step_sensitivity.md). The difference of the two runs is an upper
    estimate of the half-step run's error and about the error of this run. "warning" when it exceeds
    ``force_tolerance``; the wall time and RHS evaluations include the second run. The compiled embedded pairs
    (DP54/BS32) get the same check with the run again at a tenth of both tolerances, judged against a quarter of
    ``force_tolerance``: a tenth of the tolerances does not make the second run's error negligible. The sampled
    impact peak of wheel-flat (lumped track) falls only 1.65-fold from rtol 1e-2 to 1e-3 (2.26 % and 1.37 % of the
    static load; 2.6-fold, to 0.87 %, before a round-off-level change of the start): the difference, 0.89 %,
    understates the first run's error. If the error falls r-fold per tenfold tolerance, the first run's error is
    d r / (r - 1) for a difference d: a quarter of the tolerance keeps it within the tolerance wherever r >= 4/3.
    """
    scene = result.scene
    settings = scene.integrator
    limit, limit_words = settings.force_tolerance, f"force_tolerance = {settings.force_tolerance:g}"
    if settings.method == "RK4":
        finer = replace(settings, fixed_step_s=0.5 * settings.fixed_step_s, lift_half_step_check=False)
        where, advice = "at half the step", f"reduce fixed_step_s = {settings.fixed_step_s:g} s"
    else:
        limit = 0.25 * settings.force_tolerance
        limit_words = f"a quarter of force_tolerance = {settings.force_tolerance:g}"  # the pairs: tenth tolerances
        finer = replace(
            settings,
            relative_tolerance=0.1 * settings.relative_tolerance,
            absolute_tolerance=0.1 * settings.absolute_tolerance,
            lift_half_step_check=False,
        )
        where = "at a tenth of the tolerances"
        advice = (
            f"tighten relative_tolerance = {settings.relative_tolerance:g} / absolute_tolerance = "
            f"{settings.absolute_tolerance:g}"
        )
    finer_scene = replace(scene, integrator=finer)
    half = simulate(finer_scene, provider=provider, contact_model=model_obj, compiled=compiled, companions=False)
    total = {
        "wall_time_s": result.wall_time_s + half.wall_time_s,
        "rhs_evaluations": result.rhs_evaluations + half.rhs_evaluations,
    }
    if half.status not in ("ok", "warning"):
        return replace(
            result,
            status="warning",
            message=f"{result.message}; a wheel lifted off, and the check {where} ended {half.status}: {half.message}",
            **total,
        )
    load = scene.static_wheel_load_N
    mine, theirs = result.peaks(settled=True), half.peaks(settled=True)
    moved = 0.0
    for name, sides in mine.items():
        for side, entry in sides.items():
            a, b = entry["value"], theirs[name][side]["value"]
            if a is not None and b is not None:
                moved = max(moved, abs(a - b) / load)
    message = (
        f"{result.message}; a wheel lifted off: the settled peaks {where} differ by {moved:.3g} of the "
        f"static wheel load"
    )
    status = "ok"
    if moved > limit:
        status = "warning"
        message += f", above {limit_words}: {advice}"
    return replace(result, status=status, message=message, half_step_peak_difference=moved, **total)
