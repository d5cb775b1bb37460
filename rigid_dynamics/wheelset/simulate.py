"""Running a wheelset scene: provider and model selection, integration, events, results.

``simulate(scene, progress=None) -> SimulationResult``. The adaptive methods are scipy's
``OdeSolver`` classes (RK45, DOP853, Radau, BDF, LSODA) stepped one step at a time, so that the run
can be watched: output samples are taken from each step's dense output at the fixed output times,
and after every step the state is checked. The implicit Radau and BDF get the Jacobian of
``_state_jacobian`` (exact kinematic rows, fixed finite-difference steps) instead of scipy's own.
``RK4`` is the classical fourth-order Runge-Kutta method with a fixed step (Butcher 1987 tableau:
c = (0, 1/2, 1/2, 1), b = (1/6, 1/3, 1/3, 1/6)).

Safety (a run never hangs and never writes NaN silently): the run ends with a status
(``SimulationResult.status``) and the time and state where it happened when

* ``"blow-up"``: the state or its derivative is not finite;
* ``"force-anomaly"``: a normal force exceeds ``max_force_factor`` times the static wheel load;
* ``"derailed"``: |y| exceeds ``max_lateral_displacement_m``;
* ``"contact-failed"``: a contact model failed or the creepages became undefined (rolling speed 0);
* ``"solver-failed"``: the adaptive solver could not continue (step size too small), or a numerical exception
  was raised below the driver (:data:`NUMERICAL_ERRORS`, e.g. the curvature code for a huge stiffness with RK4);
* ``"budget-exceeded"``: more than ``max_rhs_evaluations`` evaluations or ``max_wall_time_s``;
* ``"wheel-lift"``: a wheel lost contact and ``stop_at_wheel_lift`` is set;
* ``"invalid-initial-state"``: no static equilibrium was found for the initial state (also when its search
  raised one of :data:`NUMERICAL_ERRORS`, e.g. for a tiny shear modulus);

``"warning"`` when a fixed-step RK4 run reaches the end but its error estimate of the contact forces
(:func:`_force_error_check`) exceeds the scene's ``force_tolerance`` (the numbers are there, but the step is too
coarse to trust them); and ``"ok"`` when it reaches the end without either. Events (wheel lift, contact
restored, flange contact onset) are detected on the output samples, so their times are known to one output step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from rigid_dynamics.wheelset.equations import (
    AUTO_PATCH_FIELDS,
    MAX_SLOTS,
    PATCH_FIELDS,
    STATE_NAMES,
    TRACK,
    TRACK_STATE_NAMES,
    ContactFailure,
    WheelsetModel,
)
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import SIDES, ConicalProvider, TableProvider

ADAPTIVE_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")
STATUSES = (
    "ok",
    "wheel-lift",
    "blow-up",
    "force-anomaly",
    "derailed",
    "contact-failed",
    "solver-failed",
    "budget-exceeded",
    "invalid-initial-state",
    "warning",
)


NUMERICAL_ERRORS = (ValueError, ArithmeticError, np.linalg.LinAlgError)
"""Exceptions that the static equilibrium or the integration can raise from below for numerical trouble: turned
into a status (``invalid-initial-state``, ``solver-failed``) at the driver, never a traceback."""


class _Stop(Exception):
    def __init__(self, status: str, message: str, t: float | None = None, state=None):
        super().__init__(message)
        self.status, self.message, self.t, self.state = status, message, t, state


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Outcome of a wheelset run (time series on the output grid, diagnostics, status).

    Attributes:
        status: one of STATUSES (module docstring). success: status == "ok".
        message: what happened, in words.
        t: output times, s, shape (n,).
        states: the 12 states (STATE_NAMES) at the output times, shape (n, 12).
        patches: PATCH_FIELDS -> array (n, 2 sides [left, right], 2 slots [tread, flange/second]);
            NaN where a candidate does not exist or is not in contact (normal_force_N is 0 there); with
            contact_model "auto" also AUTO_PATCH_FIELDS (equations.py: the rung chosen per patch and why).
        contact_force_N: sum of the contact forces on each wheel, main frame, shape (n, 2, 3).
        kinetic_energy_J, potential_energy_J: T and V_g = -m g z at the output times, (n,); with the elastic track
            they include the track masses' kinetic energy and the pad and ballast springs' energy.
        work_contact_J, work_exterior_J: work done on the wheelset since t = 0 by contact forces and
            by exterior forces (suspension, axle load, torque), (n,); with the elastic track the contact work is
            that on wheel and rail together and the exterior work includes the track dampers'.
        track_states: the elastic track's states (TRACK_STATE_NAMES, z down) at the output times, (n, 8); None
            for the rigid track.
        events: tuples (kind, side, time_s): "wheel-lift", "contact-restored", "flange-contact".
        rhs_evaluations, steps: counters. wall_time_s: wall time of the run (static equilibrium, integration,
            recording), s; loading the compiled code from numba's cache (once per process, ~0.1 s) is not counted.
        failure_time_s, failure_state: where the run ended abnormally (None when it did not).
        provider, contact_model, method: what was used; compiled: whether the compiled RK4 loop ran it.
        force_error_estimate: RK4 runs: per output sample, the estimated error of one step in the per-wheel contact
            forces (normal, longitudinal and lateral creep force) divided by the static wheel load, (n,); NaN where
            no step ends at the sample (t = 0, interpolated samples); None for the adaptive methods (their
            error is controlled by their tolerances).
        half_step_peak_difference: RK4 runs in which a wheel lifted off after the settling distance: the largest
            difference of the settled peaks from a run at half the step, relative to the static wheel load
            (:func:`_half_step_check`); None otherwise.
        scene: the scene that ran.
    """

    status: str
    message: str
    t: np.ndarray
    states: np.ndarray
    patches: dict
    contact_force_N: np.ndarray
    kinetic_energy_J: np.ndarray
    potential_energy_J: np.ndarray
    work_contact_J: np.ndarray
    work_exterior_J: np.ndarray
    events: tuple = ()
    rhs_evaluations: int = 0
    steps: int = 0
    wall_time_s: float = 0.0
    failure_time_s: float | None = None
    failure_state: np.ndarray | None = None
    provider: str = ""
    contact_model: str = ""
    method: str = ""
    compiled: bool = False
    force_error_estimate: np.ndarray | None = None
    half_step_peak_difference: float | None = None
    scene: DynamicsScene | None = field(default=None, repr=False)
    track_states: np.ndarray | None = None

    @property
    def success(self) -> bool:
        """True when the run reached its end time without trouble."""
        return self.status == "ok"

    @property
    def simulated_time_s(self) -> float:
        """Last output time, s."""
        return float(self.t[-1]) if len(self.t) else 0.0

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.simulated_time_s / self.wall_time_s if self.wall_time_s > 0 else math.inf

    @property
    def wheel_normal_force_N(self) -> np.ndarray:
        """Total normal force per wheel, (n, 2), N."""
        return np.nansum(self.patches["normal_force_N"], axis=2)

    @property
    def energy_residual_J(self) -> np.ndarray:
        """(T + V_g)(t) - (T + V_g)(0) - W_contact(t) - W_exterior(t), J (0 for exact integration)."""
        energy = self.kinetic_energy_J + self.potential_energy_J
        if len(energy) == 0:
            return energy
        return energy - energy[0] - self.work_contact_J - self.work_exterior_J

    def to_dataframe(self):
        """The time series as a tidy pandas DataFrame, one column per named quantity (see wheelset.table)."""
        from rigid_dynamics.wheelset.table import to_dataframe

        return to_dataframe(self)

    def to_dict(self) -> dict:
        """The summary with the tidy time-series columns under ``"timeseries"`` (name -> (n,) array)."""
        from rigid_dynamics.wheelset.table import result_columns

        return {**self.summary(), "timeseries": result_columns(self)}

    def __repr__(self) -> str:
        return (
            f"SimulationResult(status={self.status!r}, simulated_time_s={self.simulated_time_s:.4g}, "
            f"samples={len(self.t)}, wall_time_s={self.wall_time_s:.3g}, contact_model={self.contact_model!r}, "
            f"provider={self.provider!r}, compiled={self.compiled}, message={self.message!r})"
        )

    @property
    def settling_distance_m(self) -> float:
        """The scene's settling distance (DynamicsScene.settling_distance_m; 0 without a scene), m."""
        return self.scene.settling_distance_m if self.scene is not None else 0.0

    @property
    def settled(self) -> np.ndarray:
        """Mask of the output samples after the settling distance (travelled distance x(t) - x(0)), (n,)."""
        if len(self.t) == 0:
            return np.zeros(0, bool)
        return self.states[:, 0] - self.states[0, 0] >= self.settling_distance_m

    def peaks(self, settled: bool = True) -> dict:
        """Peaks of the per-wheel contact forces on the wheel: for ``normal_force_N`` the largest total normal
        force, for ``creep_force_long_N`` and ``creep_force_lat_N`` the largest magnitude of the summed creep force
        (with its sign; patch contact frames), each per side as {"value", "time_s", "position_m"} (position: the
        distance travelled since t = 0, m); values None when there is no sample. ``settled``: only the samples
        after the settling distance (:attr:`settled`), else the full run.
        """
        mask = self.settled if settled else np.ones(len(self.t), bool)
        distance = self.states[:, 0] - self.states[0, 0] if len(self.t) else np.zeros(0)
        out = {}
        for name in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N"):
            values = self.patches[name]
            touching = np.nan_to_num(self.patches["normal_force_N"], nan=0.0) > 0
            wheel = np.where(touching, np.nan_to_num(values, nan=0.0), 0.0).sum(axis=2) if len(self.t) else values
            out[name] = {}
            for i, side in enumerate(SIDES):
                entry = {"value": None, "time_s": None, "position_m": None}
                if np.any(mask):
                    series = np.where(mask, wheel[:, i], np.nan)
                    key = series if name == "normal_force_N" else np.abs(series)
                    if np.any(np.isfinite(key)):
                        k = int(np.nanargmax(key))
                        entry = {
                            "value": float(series[k]),
                            "time_s": float(self.t[k]),
                            "position_m": float(distance[k]),
                        }
                out[name][side] = entry
        return out

    def summary(self) -> dict:
        """JSON-serialisable summary (NaN -> None); keys listed in the issue and a few diagnostics.

        Peaks (``peaks``, ``peak_normal_force_N``) are taken after the scene's settling distance, with the time and
        position of each; ``full_run_peaks`` and ``full_run_peak_normal_force_N`` include the start.
        """
        lateral = self.states[:, 1] if len(self.t) else np.zeros(0)
        wavelength = dominant_wavelength_m(self.states[:, 0], lateral) if len(self.t) > 4 else math.nan
        residual = self.energy_residual_J
        scale = max(float(np.max(np.abs(self.kinetic_energy_J))) if len(self.t) else 0.0, 1.0)

        def num(value):
            value = float(value)
            return value if math.isfinite(value) else None

        peaks = self.peaks(settled=True)
        full = self.peaks(settled=False)
        return {
            "status": self.status,
            "message": self.message,
            "success": self.success,
            "simulated_time_s": num(self.simulated_time_s),
            "wall_time_s": num(self.wall_time_s),
            "real_time_factor": num(self.real_time_factor),
            "settling_distance_m": num(self.settling_distance_m),
            "peak_normal_force_N": {side: peaks["normal_force_N"][side]["value"] for side in SIDES},
            "peaks": peaks,
            "full_run_peak_normal_force_N": {side: full["normal_force_N"][side]["value"] for side in SIDES},
            "full_run_peaks": full,
            "max_abs_lateral_displacement_m": num(np.max(np.abs(lateral))) if len(self.t) else None,
            "dominant_lateral_wavelength_m": num(wavelength),
            "distance_travelled_m": num(self.states[-1, 0] - self.states[0, 0]) if len(self.t) else None,
            "energy_balance_relative": num(np.max(np.abs(residual)) / scale) if len(self.t) else None,
            "events": [{"kind": k, "side": s, "time_s": num(t)} for k, s, t in self.events],
            "rhs_evaluations": int(self.rhs_evaluations),
            "steps": int(self.steps),
            "failure_time_s": None if self.failure_time_s is None else num(self.failure_time_s),
            "failure_state": None if self.failure_state is None else [num(v) for v in self.failure_state],
            "provider": self.provider,
            "contact_model": self.contact_model,
            "method": self.method,
            "compiled": self.compiled,
            "track_model": self.scene.track_dynamics.model if self.scene is not None else None,
            "peak_rail_deflection_m": (
                {side: num(np.max(self.track_states[:, i])) for i, side in enumerate(SIDES)}
                if self.track_states is not None and len(self.track_states)
                else None
            ),
            **self._error_summary(num),
        }

    def _error_summary(self, num) -> dict:
        """The force error estimate of a fixed-step run in the summary: the largest after the settling distance
        (what the status judges) and over the full run, each with its time, and the tolerance.
        """
        est = self.force_error_estimate
        if est is None:
            return {"force_error_estimate": None}
        out = {"force_tolerance": num(self.scene.integrator.force_tolerance) if self.scene is not None else None}
        diff = self.half_step_peak_difference
        out["half_step_peak_difference"] = None if diff is None else num(diff)
        for key, mask in (("force_error_estimate", self.settled), ("full_run_force_error_estimate", None)):
            values = est if mask is None else np.where(mask, est, np.nan)
            if np.all(np.isnan(values)):
                out[key], out[f"{key}_time_s"] = None, None
                continue
            k = int(np.argmax(np.where(np.isnan(values), -np.inf, values)))
            out[key], out[f"{key}_time_s"] = num(values[k]), num(self.t[k])
        return out


def dominant_wavelength_m(distance_m, lateral_m) -> float:
    """Dominant wavelength of y(x): mean spacing of successive same-direction crossings of y - mean(y).

    Crossings are located by linear interpolation in the travelled distance x; upward crossings are
    compared with upward ones and downward with downward ones, so an offset of the mean (a record that
    is not a whole number of cycles) does not bias the result. Falls back to the
    peak of the FFT of y resampled on a uniform x grid when there are fewer than 3 crossings
    (then the resolution is the record length). NaN when neither gives an answer.

    Args:
        distance_m: x, travelled distance (monotonic), m.
        lateral_m: y, lateral displacement, m.
    """
    x = np.asarray(distance_m, float)
    y = np.asarray(lateral_m, float)
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if len(x) < 5 or np.ptp(x) <= 0 or np.ptp(y) <= 0:
        return math.nan
    y = y - np.mean(y)
    sign = np.signbit(y)
    idx = np.flatnonzero(sign[1:] != sign[:-1])
    if len(idx) >= 3:
        x0, x1, y0, y1 = x[idx], x[idx + 1], y[idx], y[idx + 1]
        crossings = x0 - y0 * (x1 - x0) / (y1 - y0)
        upward = y1 > y0
        spacings = np.concatenate([np.diff(crossings[upward]), np.diff(crossings[~upward])])
        return float(np.mean(spacings))
    grid = np.linspace(x[0], x[-1], max(len(x), 64))
    yy = np.interp(grid, x, y)
    spectrum = np.abs(np.fft.rfft(yy))
    k = int(np.argmax(spectrum[1:])) + 1
    if spectrum[k] <= 0:
        return math.nan
    return float((grid[-1] - grid[0]) * len(grid) / (len(grid) - 1) / k)


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
            from rigid_dynamics.wheelset.profiles import ProfileSectionProvider

            section = ProfileSectionProvider(scene.wheelset, track)
        return TableProvider(section, scene.wheelset.nominal_radius_m, irregularities=irr)
    if choice == "search":
        from rigid_dynamics.wheelset.profiles import SearchProvider

        return SearchProvider(scene.wheelset, track, irr)
    raise ValueError(f"contact_provider = {choice!r}: unknown")  # pragma: no cover (validated by the scene)


def get_contact_model(name_or_model):
    """A contact model instance from a registered name or an instance (registry.get_model)."""
    from rigid_dynamics.contact.registry import get_model

    return get_model(name_or_model)


def model_options(name: str, scene: DynamicsScene) -> dict | None:
    """Options handed to the contact model in a run: the scene's FASTSIM grid, no FASTSIM fields; auto gets the
    scene's tolerance.
    """
    fastsim = {"fields": False, "nx": scene.fastsim_elements_per_strip, "ny": scene.fastsim_strips}
    if name == "fastsim":
        return fastsim
    if name == "auto":
        return {"tolerance": scene.contact_tolerance, "model_options": {"fastsim": fastsim}}
    return None


def initial_state(scene: DynamicsScene) -> np.ndarray:
    """The 12-state at t = 0 before the static equilibrium of z and theta (see InitialConditions)."""
    ic = scene.initial
    r0 = scene.wheelset.nominal_radius_m
    v = scene.speed_m_per_s
    state = np.zeros(12)
    state[1] = ic.lateral_displacement_m
    state[2] = -r0 + 1e-4
    state[3] = ic.yaw_rad
    state[6] = v
    state[7] = ic.lateral_velocity_m_per_s
    state[8] = ic.vertical_velocity_m_per_s
    state[9] = ic.yaw_rate_rad_per_s
    state[11] = (1.0 - ic.longitudinal_creepage) * v / r0
    return state


def _side_force_sums(table: dict) -> np.ndarray:
    """Per wheel (left, right) the normal, longitudinal and lateral creep forces summed over the patches in contact,
    (2, 3), N, from a patch table (PATCH_FIELDS -> (2, MAX_SLOTS)).
    """
    names = ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")
    touching = np.nan_to_num(table["normal_force_N"], nan=0.0) > 0
    return np.stack([np.where(touching, np.nan_to_num(table[n], nan=0.0), 0.0).sum(axis=1) for n in names], axis=1)


def _contact_force_sums(model: WheelsetModel, state: np.ndarray) -> np.ndarray:
    """:func:`_side_force_sums` of the contact at a 12-state (the Python path's force error estimate)."""
    contact = model.contact(state[:12], record=True, track=state[TRACK] if model.elastic else None)
    table = {
        name: np.full((2, MAX_SLOTS), np.nan) for name in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")
    }
    for k in range(len(contact.side)):
        side, slot = int(contact.side[k]), int(contact.slot[k])
        if slot < MAX_SLOTS:
            for name in table:
                table[name][side, slot] = contact.values[name][k]
    return _side_force_sums(table)


def _rolling_radii(sides, normal_N, radius_m) -> np.ndarray:
    """Rolling radius of each wheel (left, right), m: the radii of its patches in contact weighted by their normal
    forces; NaN for a wheel without contact.
    """
    sides = np.asarray(sides)
    normal = np.nan_to_num(np.asarray(normal_N, float), nan=0.0)
    radius = np.nan_to_num(np.asarray(radius_m, float), nan=0.0)
    out = np.full(2, np.nan)
    for i in (0, 1):
        w = np.where((sides == i) & (normal > 0), normal, 0.0)
        if w.sum() > 0:
            out[i] = float(np.sum(w * radius) / w.sum())
    return out


def elastic_start(model: WheelsetModel, state: np.ndarray, derivative=None, deepest=None, rolling=None):
    """:func:`consistent_start` with the elastic track at rest under the wheels (the rigid track: that alone).

    The track starts deflected by the static wheel load (``model.track_rest``), then wheelset equilibrium and
    track deflection under the contact forces found are alternated until the rail forces change by < 1e-6 of the
    static wheel load (at most 8 rounds; each round solves the wheelset's equilibrium on a fixed track).
    """
    if not model.elastic:
        return consistent_start(model, state, derivative, deepest, rolling)
    load = model.scene.static_wheel_load_N
    model.track_rest = model.static_track([load, load])
    derivative_ = model.derivative if derivative is None else derivative
    out = (state, False, "no rounds")
    for _ in range(8):
        out = consistent_start(model, state, derivative, deepest, rolling)
        if not out[1]:
            return out
        force = _rail_forces(model, out[0], derivative_)
        before = model.track_rest.copy()
        model.track_rest = model.static_track(force)
        state = out[0]
        if np.max(np.abs(model.track_rest[0:2] - before[0:2])) * model.track.static_stiffness_N_per_m < 1e-6 * load:
            break
    return consistent_start(model, state, derivative, deepest, rolling)


def _rail_forces(model: WheelsetModel, state: np.ndarray, derivative) -> np.ndarray:
    """Vertical contact force on each rail (left, right) at a 12-state on ``track_rest``, N, from the track
    acceleration the right-hand side gives (m_r z_r'' = F_r - pad force; the pad is at rest: F_r = m_r z_r'' +
    k_p (z_r - z_s)).
    """
    d = derivative(0.0, model.full_state(state))
    tr, rest = model.track, model.track_rest
    return tr.rail_mass_kg * d[TRACK][4:6] + tr.pad_stiffness_N_per_m * (rest[0:2] - rest[2:4])


def consistent_start(model: WheelsetModel, state: np.ndarray, derivative=None, deepest=None, rolling=None):
    """A consistent rolling start from the 12-state of :func:`initial_state`: (state, success, message).

    1. Static equilibrium of z and roll at the initial lateral offset and yaw (WheelsetModel.static_state).
    2. Free rolling: the spin rate phi' (and, with ``initial.free_rolling``, the yaw rate psi') at which the
       spin and yaw accelerations vanish, by Newton steps from V / r_roll (r_roll the mean of the two wheels'
       rolling radii, each the normal-force-weighted mean over its patches) and the given yaw rate; phi' is then
       scaled by (1 - xi0) with xi0 the scene's ``initial.longitudinal_creepage``. With V / r0 (r0 the nominal
       radius) a profiled wheel off its tape circle starts with a common longitudinal creepage (r_roll - r0)/r0;
       with psi' = 0 an offset wheelset starts with the creepages +-(r_right - r_left)/(2 r_roll): both a
       creep-force spike at t = 0. With the solved psi' the wheelset starts on its kinematic (Klingel) path,
       psi' = -V (r_right - r_left)/(2 e0 r_roll) to first order, at the extreme of the offset.
    3. The static equilibrium again at that spin rate.

    ``derivative``, ``deepest``, ``rolling``: the compiled right-hand side's versions (_compiled_static_functions);
    None: the Python path's.
    """
    state, ok, why = model.static_state(state, derivative, deepest)
    if not ok:
        return state, ok, why
    if rolling is None:
        contact = model.contact(state[:12], record=True)  # on model.track_rest
        radii = _rolling_radii(contact.side, contact.values["normal_force_N"], contact.values["rolling_radius_m"])
    else:
        radii = rolling(state)
    if not np.all(np.isfinite(radii)):
        return state, False, f"a wheel has no contact at the static equilibrium (rolling radii {radii} m)"
    derivative = model.derivative if derivative is None else derivative
    state = state.copy()
    ic = model.scene.initial
    solve_yaw = ic.free_rolling
    rolling_rate = model.scene.speed_m_per_s / float(np.mean(radii))

    def residual(rates):
        trial = model.full_state(state)
        trial[11] = rates[0]
        if solve_yaw:
            trial[9] = rates[1]
        try:
            d = derivative(0.0, trial)
        except ContactFailure:
            return np.full(2, np.nan)
        return np.array([d[11], d[9] if solve_yaw else 0.0])

    # Newton with a forward-difference Jacobian on (spin rate, yaw rate): the creep forces are about linear in them
    rates = np.array([rolling_rate, state[9]])
    steps = np.array([1e-6 * rolling_rate, 1e-6 * rolling_rate * model.scene.wheelset.nominal_radius_m])
    r = residual(rates)
    for _ in range(8):
        if not np.all(np.isfinite(r)):
            break
        jac = np.eye(2)
        for k in range(2 if solve_yaw else 1):
            trial = rates.copy()
            trial[k] += steps[k]
            jac[:, k] = (residual(trial) - r) / steps[k]
        try:
            delta = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(delta)):
            break
        rates = rates + delta
        r = residual(rates)
        if abs(delta[0]) < 1e-12 * rolling_rate and abs(delta[1]) < 1e-12 * rolling_rate:
            break
    if not np.all(np.isfinite(rates)) or abs(rates[0] / rolling_rate - 1.0) > 0.01:
        rates = np.array([rolling_rate, state[9]])  # no free-rolling solution nearby: the rolling radii alone
    state[11] = (1.0 - ic.longitudinal_creepage) * rates[0]
    state[9] = rates[1]
    return model.static_state(state, derivative, deepest)


class _Recorder:
    """Collects output samples and detects events and anomalies on them. Samples are kept as blocks of rows (one
    row from :meth:`append`, many from :meth:`append_many`), joined by :meth:`arrays`.
    """

    def __init__(self, model: WheelsetModel, scene: DynamicsScene):
        self.model = model
        self.scene = scene
        self.t: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        auto = getattr(model.model, "name", "") == "auto"
        self.fields = PATCH_FIELDS + (AUTO_PATCH_FIELDS if auto else ())
        self.patches = {name: [] for name in self.fields}
        self.forces: list[np.ndarray] = []
        self.kinetic: list[np.ndarray] = []
        self.potential: list[np.ndarray] = []
        self.work_contact: list[np.ndarray] = []
        self.work_exterior: list[np.ndarray] = []
        self.errors: list[np.ndarray] = []
        self.track: list[np.ndarray] = []
        self.events: list[tuple] = []
        self.in_contact = None
        self.flange = None
        self.limit_force = scene.integrator.max_force_factor * scene.static_wheel_load_N
        self.limit_y = scene.integrator.max_lateral_displacement_m
        self.flange_angle = scene.track.flange_contact_angle_rad

    def record(self, t: float, full_state: np.ndarray, error: float = math.nan) -> None:
        """Check and store the sample at (t, full_state) with the force error estimate of the steps since the last
        sample (N; NaN: none).
        """
        state = full_state[:12]
        if not np.all(np.isfinite(full_state)):
            raise _Stop("blow-up", f"non-finite state at t = {t:.6g} s", t, state)
        contact = self.model.contact(state, record=True, track=full_state[TRACK] if self.model.elastic else None)
        table = {name: np.full((2, MAX_SLOTS), np.nan) for name in self.fields}
        for k in range(len(contact.side)):
            side, slot = int(contact.side[k]), int(contact.slot[k])
            if slot >= MAX_SLOTS:
                continue
            for name in self.fields:
                if name in contact.values:
                    table[name][side, slot] = contact.values[name][k]
        forces = np.zeros((2, 3))
        np.add.at(forces, contact.side, contact.force_N)
        self.append(t, full_state, table, forces, error)

    def append(
        self, t: float, full_state: np.ndarray, table: dict, forces: np.ndarray, error: float = math.nan
    ) -> None:
        """Check and store one sample (patch table: PATCH_FIELDS -> (2, 2); forces per side (2, 3); the force error
        estimate of the step ending there, relative to the static wheel load).
        """
        state = full_state[:12]
        normal = np.nansum(table["normal_force_N"], axis=1)
        if not (np.all(np.isfinite(forces)) and np.all(np.isfinite(normal))):
            raise _Stop("blow-up", f"non-finite contact force at t = {t:.6g} s", t, state)
        if np.max(normal) > self.limit_force:
            raise _Stop(
                "force-anomaly",
                f"normal force {np.max(normal):.4g} N exceeds {self.limit_force:.4g} N "
                f"(max_force_factor x static wheel load) at t = {t:.6g} s",
                t,
                state,
            )
        if abs(state[1]) > self.limit_y:
            raise _Stop(
                "derailed", f"|y| = {abs(state[1]):.4g} m exceeds {self.limit_y:.4g} m at t = {t:.6g} s", t, state
            )
        touching = normal > 0
        flange = np.array(
            [
                bool(np.any((table["contact_angle_rad"][i] > self.flange_angle) & (table["normal_force_N"][i] > 0)))
                for i in range(2)
            ]
        )
        if self.in_contact is not None:
            for i, side in enumerate(SIDES):
                if self.in_contact[i] and not touching[i]:
                    self.events.append(("wheel-lift", side, t))
                elif touching[i] and not self.in_contact[i]:
                    self.events.append(("contact-restored", side, t))
                if flange[i] and not self.flange[i]:
                    self.events.append(("flange-contact", side, t))
        self.in_contact, self.flange = touching, flange
        self.t.append(np.array([t], float))
        self.states.append(state[None].copy())
        for name in self.fields:
            self.patches[name].append(np.asarray(table.get(name, np.full((2, MAX_SLOTS), np.nan)), float)[None])
        self.forces.append(np.asarray(forces, float)[None])
        track_kinetic, track_potential = self.model.track_energy_J(full_state[TRACK])
        self.kinetic.append(np.array([self.model.kinetic_energy_J(state) + track_kinetic], float))
        self.potential.append(np.array([self.model.potential_energy_J(state) + track_potential], float))
        if self.model.elastic:
            self.track.append(np.asarray(full_state[TRACK], float)[None].copy())
        self.work_contact.append(np.array([full_state[12]], float))
        self.work_exterior.append(np.array([full_state[13]], float))
        self.errors.append(np.array([error], float))
        if self.scene.integrator.stop_at_wheel_lift and not np.all(touching):
            side = SIDES[int(np.argmin(touching))]
            raise _Stop("wheel-lift", f"the {side} wheel lost contact at t = {t:.6g} s", t, state)

    def set_last_error(self, error: float) -> None:
        """Set the force error estimate of the last sample (N; NaN: none)."""
        self.errors[-1] = np.array([error], float)

    def append_many(self, times, full_states, tables: dict, forces, errors) -> None:
        """Vectorised :meth:`append` for many samples (tables: name -> (n, 2, 2); forces (n, 2, 3); errors (n,))."""
        n = len(times)
        if n == 0:
            return
        normal = np.nansum(tables["normal_force_N"], axis=2)
        bad = ~(np.all(np.isfinite(full_states), axis=1) & np.all(np.isfinite(forces), axis=(1, 2)))
        bad |= ~np.all(np.isfinite(normal), axis=1)
        bad |= np.max(normal, axis=1) > self.limit_force
        bad |= np.abs(full_states[:, 1]) > self.limit_y
        touching = normal > 0
        if self.scene.integrator.stop_at_wheel_lift:
            bad |= ~np.all(touching, axis=1)
        stop = int(np.argmax(bad)) if np.any(bad) else n
        if stop < n:
            # store the good samples, then let append() raise with the right status on the bad one
            if stop:
                self.append_many(
                    times[:stop],
                    full_states[:stop],
                    {k: v[:stop] for k, v in tables.items()},
                    forces[:stop],
                    errors[:stop],
                )
            self.append(
                float(times[stop]),
                full_states[stop],
                {k: v[stop] for k, v in tables.items()},
                forces[stop],
                float(errors[stop]),
            )
            return
        flange = np.any((tables["contact_angle_rad"] > self.flange_angle) & (tables["normal_force_N"] > 0), axis=2)
        prev_touch = np.vstack([self.in_contact if self.in_contact is not None else touching[:1], touching[:-1]])
        prev_flange = np.vstack([self.flange if self.flange is not None else flange[:1], flange[:-1]])
        for k, i in zip(*np.nonzero(prev_touch & ~touching), strict=True):
            self.events.append(("wheel-lift", SIDES[i], float(times[k])))
        for k, i in zip(*np.nonzero(~prev_touch & touching), strict=True):
            self.events.append(("contact-restored", SIDES[i], float(times[k])))
        for k, i in zip(*np.nonzero(flange & ~prev_flange), strict=True):
            self.events.append(("flange-contact", SIDES[i], float(times[k])))
        self.events.sort(key=lambda e: e[2])
        self.in_contact, self.flange = touching[-1], flange[-1]
        states = full_states[:, :12]
        self.t.append(np.asarray(times, float).copy())
        self.states.append(states.copy())
        for name in self.fields:
            self.patches[name].append(np.asarray(tables.get(name, np.full((n, 2, MAX_SLOTS), np.nan)), float).copy())
        self.forces.append(np.asarray(forces, float).copy())
        # kinetic energy m|v|^2/2 + omega.J omega/2, J = R diag(Jt, Ja, Jt) R^T (R = R_z R_x), vectorised
        psi, theta = states[:, 3], states[:, 4]
        yr, rr, sr = states[:, 9], states[:, 10], states[:, 11]
        cps, sps, cth, sth = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta)
        omega = np.stack([rr * cps + sr * sps * cth, rr * sps - sr * cps * cth, yr - sr * sth], axis=-1)
        rzx = np.stack(
            [
                np.stack([cps, -sps * cth, sps * sth], -1),
                np.stack([sps, cps * cth, -cps * sth], -1),
                np.stack([np.zeros_like(cps), sth, cth], -1),
            ],
            -2,
        )
        body = np.einsum("nji,nj->ni", rzx, omega)
        j_diag = np.diag(self.model.j_body)
        kinetic = 0.5 * self.model.mass * np.sum(states[:, 6:9] ** 2, axis=1) + 0.5 * np.sum(j_diag * body**2, axis=1)
        track_kinetic, track_potential = self.model.track_energy_J(full_states[:, TRACK])
        self.kinetic.append(kinetic + track_kinetic)
        self.potential.append(-self.model.mass * self.model.gravity * states[:, 2] + track_potential)
        if self.model.elastic:
            self.track.append(np.asarray(full_states[:, TRACK], float).copy())
        self.work_contact.append(full_states[:, 12].copy())
        self.work_exterior.append(full_states[:, 13].copy())
        self.errors.append(np.asarray(errors, float).copy())

    def arrays(self):
        def joined(blocks, empty_shape):
            return np.concatenate(blocks) if blocks else np.zeros(empty_shape)

        patches = {name: joined(v, (0, 2, MAX_SLOTS)) for name, v in self.patches.items()}
        return (
            joined(self.t, (0,)),
            joined(self.states, (0, 12)),
            patches,
            joined(self.forces, (0, 2, 3)),
            joined(self.kinetic, (0,)),
            joined(self.potential, (0,)),
            joined(self.work_contact, (0,)),
            joined(self.work_exterior, (0,)),
            joined(self.errors, (0,)),
            joined(self.track, (0, 8)) if self.model.elastic else None,
        )


def simulate(
    scene: DynamicsScene,
    progress: Callable[[float], None] | None = None,
    *,
    provider=None,
    contact_model=None,
    compiled: bool | None = None,
) -> SimulationResult:
    """Run a scene and return its :class:`SimulationResult` (never raises for numerical trouble).

    Args:
        scene: the scene.
        progress: optional callable(fraction in [0, 1]) called as the run advances (about 100 times).
        provider: optional provider instance overriding the scene's ``contact_provider`` (e.g. a
            prebuilt TableProvider reused across runs).
        contact_model: optional model instance or registered name overriding ``scene.contact_model``.
        compiled: use the compiled RK4 loop (rigid_dynamics.wheelset.compiled) when it supports the run
            (None: whenever it does; False: never; True: required, ValueError if unsupported).

    Raises:
        ValueError: the scene cannot be set up (unknown model, provider that cannot serve it).
    """
    provider = provider if provider is not None else build_provider(scene)
    model_obj = get_contact_model(contact_model if contact_model is not None else scene.contact_model)
    model = WheelsetModel(scene, provider, model_obj, model_options(getattr(model_obj, "name", ""), scene))
    from rigid_dynamics.wheelset import compiled as _compiled

    can_compile = _compiled.supported(scene, provider, model_obj) and model.batch is not None
    if compiled and not can_compile:
        raise ValueError(
            "compiled = True: the compiled path needs method RK4, a TableProvider or a SearchProvider on tabulated "
            "surfaces, and one of "
            f"the models {', '.join(_compiled.MODEL_CODES)}"
        )
    use_compiled = can_compile and compiled is not False
    settings = scene.integrator
    duration = scene.duration_s
    packed = None
    if use_compiled:
        packed = _compiled.pack(model, provider, model.batch.tables, model.model.name, model.batch.options)
        _compiled.load(packed)  # the compiled code (from numba's cache) is loaded before the clock starts
    start = time.perf_counter()
    recorder = _Recorder(model, scene)
    status, message, fail_t, fail_state = "ok", "", None, None
    steps = 0

    try:
        if use_compiled:
            derivative, deepest, rolling = _compiled_static_functions(packed, model)
            state0, ok, why = elastic_start(model, initial_state(scene), derivative, deepest, rolling)
        else:
            state0, ok, why = elastic_start(model, initial_state(scene))
    except NUMERICAL_ERRORS as exc:  # e.g. a tiny shear modulus: the wheel sinks until the curvatures turn negative
        state0, ok, why = initial_state(scene), False, f"{type(exc).__name__}: {exc}"
    model.frame_x0 = float(state0[0])
    if packed is not None:
        packed[0][_compiled.P_XF0] = model.frame_x0  # the suspension frame starts where the wheelset does
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
        raise _Stop(status, message, t, y[:12])

    def fun(t, y):
        if model.rhs_evaluations >= settings.max_rhs_evaluations:
            raise _Stop("budget-exceeded", f"more than {settings.max_rhs_evaluations} RHS evaluations", t, y[:12])
        if time.perf_counter() - start > settings.max_wall_time_s:
            raise _Stop("budget-exceeded", f"wall time above {settings.max_wall_time_s} s", t, y[:12])
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
            raise _Stop("invalid-initial-state", f"no static equilibrium of z and roll found: {why}", 0.0, state0)
        recorder.record(0.0, full0)
        next_out = 1
        if use_compiled:
            steps = _run_compiled(model, packed, full0, duration, settings, recorder, report, start)
        elif settings.method == "RK4":
            steps = _run_rk4(fun, full0, duration, settings, out_times, recorder, report, model)
        else:
            steps = _run_adaptive(fun, full0, duration, settings, out_times, recorder, report, scene)
        message = f"reached t = {duration:g} s"
        del next_out
    except _Stop as stop:
        status, message, fail_t, fail_state = stop.status, stop.message, stop.t, stop.state
        steps = steps or getattr(stop, "steps", 0)
    except ContactFailure as exc:
        status, message = "contact-failed", str(exc)
    except NUMERICAL_ERRORS as exc:  # raised below the driver (e.g. the curvature code for a huge stiffness with RK4)
        status, message = "solver-failed", f"numerical failure: {type(exc).__name__}: {exc}"
    wall = time.perf_counter() - start
    t, states, patches, forces, kin, pot, wc, we, errors, track_states = recorder.arrays()
    fixed_step = settings.method == "RK4"
    if fixed_step:
        errors = errors / scene.static_wheel_load_N
        if status == "ok":
            settled = states[:, 0] - states[0, 0] >= scene.settling_distance_m if len(t) else np.zeros(0, bool)
            status, message = _force_error_check(errors, t, settled, settings, message)
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
        events=tuple(recorder.events),
        rhs_evaluations=model.rhs_evaluations,
        steps=steps,
        wall_time_s=wall,
        failure_time_s=None if fail_t is None else float(fail_t),
        failure_state=None if fail_state is None else np.array(fail_state[:12], float),
        provider=getattr(provider, "name", type(provider).__name__),
        contact_model=getattr(model_obj, "name", type(model_obj).__name__),
        method=settings.method,
        compiled=use_compiled,
        force_error_estimate=errors if fixed_step else None,
        scene=scene,
        track_states=track_states,
    )
    if fixed_step and status == "ok" and settings.lift_half_step_check and _lifted_after_settling(result):
        result = _half_step_check(result, provider, model_obj, compiled)
    return result


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
    ``force_tolerance``; the wall time and RHS evaluations include the second run.
    """
    scene = result.scene
    settings = scene.integrator
    half = simulate(
        replace(
            scene, integrator=replace(settings, fixed_step_s=0.5 * settings.fixed_step_s, lift_half_step_check=False)
        ),
        provider=provider,
        contact_model=model_obj,
        compiled=compiled,
    )
    total = {
        "wall_time_s": result.wall_time_s + half.wall_time_s,
        "rhs_evaluations": result.rhs_evaluations + half.rhs_evaluations,
    }
    if half.status not in ("ok", "warning"):
        return replace(
            result,
            status="warning",
            message=f"{result.message}; a wheel lifted off, and the check at half the step ended {half.status}: "
            f"{half.message}",
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
        f"{result.message}; a wheel lifted off: the settled peaks at half the step differ by {moved:.3g} of the "
        f"static wheel load"
    )
    status = "ok"
    if moved > settings.force_tolerance:
        status = "warning"
        message += (
            f", above force_tolerance = {settings.force_tolerance:g}: reduce fixed_step_s = {settings.fixed_step_s:g} s"
        )
    return replace(result, status=status, message=message, half_step_peak_difference=moved, **total)


def _force_error_check(errors: np.ndarray, t: np.ndarray, settled: np.ndarray, settings, message: str):
    """(status, message) of a finished fixed-step run from its force error estimates (relative to the static wheel
    load): "warning" when the largest after the settling distance (``settled``) exceeds ``settings.force_tolerance``
    (or an estimate failed there), else "ok"; when only the start-up exceeds it, the message says that the
    full-run peaks are not converged.

    The estimate is the contact-force difference between RK4 and its embedded third-order solution over the step
    ending at each recorded sample (compiled.rk4_run, :func:`_run_rk4`). On the embedded scenes it separates the
    steps whose force results move by more than a few per cent of the static load from those that do not, where the
    contact-passage time against the step misses the creep-force bias of polygonal-wheel at 1 ms and step doubling
    underestimates it (benchmarks/results/step_sensitivity.md).
    """

    def worst(mask):
        values = np.where(mask & ~np.isnan(errors), errors, -np.inf)
        k = int(np.argmax(values)) if len(values) else 0
        return (values[k], k) if len(values) else (-np.inf, 0)

    tol = settings.force_tolerance
    value, k = worst(settled)
    if value > tol:
        what = f"{value:.3g}" if np.isfinite(value) else "not computable (the third-order state failed)"
        return "warning", (
            f"{message}; force error estimate {what} of the static wheel load at t = {t[k]:.6g} s exceeds "
            f"force_tolerance = {tol:g}: reduce fixed_step_s = {settings.fixed_step_s:g} s"
        )
    value, k = worst(~settled)
    if value > tol:
        return "ok", (
            f"{message}; the start-up before the settling distance has a force error estimate {value:.3g} at "
            f"t = {t[k]:.6g} s above force_tolerance = {tol:g}: its peaks (full_run_peaks) are not converged"
        )
    return "ok", message


def _tolerances(settings, scene):
    """Absolute tolerances per state (atol = ``absolute_tolerance``).

    atol for x, y, z, yaw and roll; 100 atol for the spin angle and the rates; 1000 atol for the spin rate;
    1e-3 J for the two work integrals (diagnostics that do not enter the right-hand side; loosening their
    tolerance 1e4-fold or tightening it to atol (m g + axle load) changes the steps of RK45, BDF, Radau and
    LSODA on hunting-conical by under 2 %: the mechanical states set the steps).
    """
    atol = np.full(22 if scene.track_dynamics.elastic else 14, settings.absolute_tolerance)
    atol[6:12] = settings.absolute_tolerance * 100.0
    atol[5] = settings.absolute_tolerance * 100.0
    atol[11] = settings.absolute_tolerance * 1e3
    atol[12:14] = 1e-3
    atol[18:] = settings.absolute_tolerance * 100.0  # the track's rates (absent for the rigid track)
    return atol


_JACOBIAN_RELATIVE_STEP = math.sqrt(np.finfo(float).eps)


def _state_jacobian(fun: Callable) -> Callable:
    """Jacobian d f / d y of the 14-state function ``fun`` for the implicit methods Radau and BDF.

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
        _Stop: "solver-failed" when a column cannot be differenced in either direction.
    """
    last = [None]

    def jac(t, y):
        y = np.asarray(y, float)
        n = len(y)
        f0 = fun(t, y)
        if not np.all(np.isfinite(f0)):
            if last[0] is not None:
                return last[0]
            raise _Stop("solver-failed", f"no Jacobian: the state function is not finite at t = {t:.6g} s", t, y)
        jac_matrix = np.zeros((n, n))
        jac_matrix[0:6, 6:12] = np.eye(6)
        if n > 14:
            jac_matrix[14:18, 18:22] = np.eye(4)
        for j in [*range(12), *range(14, n)]:  # not the work integrals
            for sign in (1.0, -1.0):
                trial = y.copy()
                trial[j] += sign * _JACOBIAN_RELATIVE_STEP * max(abs(y[j]), 1.0)
                step = trial[j] - y[j]
                f1 = fun(t, trial)
                if np.all(np.isfinite(f1)):
                    break
            else:
                raise _Stop(
                    "solver-failed",
                    f"no Jacobian: the state function is not finite next to the state at t = {t:.6g} s "
                    f"(column {j}, {(STATE_NAMES + ('', '') + TRACK_STATE_NAMES)[j]})",
                    t,
                    y,
                )
            jac_matrix[6:, j] = (f1[6:] - f0[6:]) / step
        last[0] = jac_matrix
        return jac_matrix

    return jac


def _run_adaptive(fun, y0, duration, settings, out_times, recorder, report, scene) -> int:
    from scipy import integrate

    cls = getattr(integrate, settings.method)
    options = {"jac": _state_jacobian(fun)} if settings.method in ("Radau", "BDF") else {}
    solver = cls(
        fun,
        0.0,
        y0,
        duration,
        rtol=settings.relative_tolerance,
        atol=_tolerances(settings, scene),
        max_step=settings.max_step_s,
        **options,
    )
    steps = 0
    next_out = 1
    while solver.status == "running":
        t_before = solver.t
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                message = solver.step()
        except _Stop as stop:
            stop.steps = steps
            raise
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            # e.g. a Jacobian with non-finite entries after a wild trial step of an implicit method
            stop = _Stop(
                "solver-failed", f"{settings.method} failed at t = {solver.t:.6g} s: {exc}", solver.t, solver.y
            )
            stop.steps = steps
            raise stop from None
        steps += 1
        if solver.status == "failed":
            exc = _Stop("solver-failed", f"{settings.method}: {message} (t = {t_before:.6g} s)", t_before, solver.y)
            exc.steps = steps
            raise exc
        if not np.all(np.isfinite(solver.y)):
            exc = _Stop("blow-up", f"non-finite state at t = {solver.t:.6g} s", solver.t, solver.y)
            exc.steps = steps
            raise exc
        if next_out < len(out_times) and out_times[next_out] <= solver.t + 1e-12:
            dense = solver.dense_output()
            while next_out < len(out_times) and out_times[next_out] <= solver.t + 1e-12:
                t_out = out_times[next_out]
                try:
                    recorder.record(t_out, dense(t_out) if t_out < solver.t else solver.y)
                except _Stop as stop:
                    stop.steps = steps
                    raise
                next_out += 1
        report(solver.t)
    return steps


_COMPILED_STATUS = {1: "blow-up", 2: "force-anomaly", 3: "derailed", 4: "contact-failed"}


def _compiled_static_functions(packed, model):
    """(derivative, deepest approach per wheel, rolling radius per wheel) by the compiled right-hand side, for
    :func:`consistent_start`.
    """
    from rigid_dynamics.wheelset import compiled

    par, hz, kk, sides, _, mode, targs, sargs = packed
    ncand = len(sides)
    rec = np.zeros((ncand + 2, compiled.N_FIELDS))

    def derivative(t, full_state):
        out = np.zeros(len(full_state))
        status = compiled.rhs_once(
            float(t), np.asarray(full_state, float), par, hz, kk, sides, mode, targs, sargs, out, rec
        )
        if status != 0:
            raise ContactFailure(f"compiled right-hand side: {_COMPILED_STATUS[int(status)]}")
        return out

    def deepest(state):
        derivative(0.0, model.full_state(state))
        approach = np.nan_to_num(rec[:ncand, 7], nan=-np.inf)
        return [float(np.max(approach[sides == i])) if np.any(sides == i) else 0.0 for i in (0, 1)]

    def rolling(state):
        derivative(0.0, model.full_state(state))
        return _rolling_radii(sides, rec[:ncand, 0], rec[:ncand, 10])

    return derivative, deepest, rolling


def _run_compiled(model, packed, y0, duration, settings, recorder, report, start) -> int:
    """RK4 in the compiled loop (compiled.rk4_run), in chunks so that wall time and progress are watched."""
    from rigid_dynamics.wheelset import compiled

    par, hz, kk, sides, slots, mode, targs, sargs = packed
    n_steps = max(1, int(math.ceil(duration / settings.fixed_step_s - 1e-9)))
    h = duration / n_steps
    out_every = max(1, int(round(settings.output_step_s / h)))
    check_every = _check_every(settings, h)
    n_out = n_steps // out_every
    ncand = len(sides)
    states = np.zeros((n_out, len(y0)))
    recs = np.zeros((n_out, ncand + 2, compiled.N_FIELDS))
    errs = np.full(n_out, np.nan)
    y, t, done, k_out = y0.copy(), 0.0, 0, 0
    chunk = max(out_every, (2000 // out_every) * out_every)
    fields_ = PATCH_FIELDS
    while done < n_steps:
        todo = min(chunk, n_steps - done)
        status, did, k_new, t_end, y_end, evals = compiled.rk4_run(
            y, t, h, todo, out_every, check_every, par, hz, kk, sides, mode, targs, sargs, states, recs, errs, k_out
        )
        model.rhs_evaluations += int(evals)
        if k_new > k_out:
            block = recs[k_out:k_new]
            tables = {name: np.full((k_new - k_out, 2, MAX_SLOTS), np.nan) for name in fields_}
            for c in range(ncand):
                if slots[c] < MAX_SLOTS:
                    for f, name in enumerate(fields_):
                        tables[name][:, sides[c], slots[c]] = block[:, c, f]
            times = (done // out_every + np.arange(1, k_new - k_out + 1)) * out_every * h
            recorder.append_many(
                times, states[k_out:k_new], tables, block[:, ncand : ncand + 2, :3].copy(), errs[k_out:k_new]
            )
        k_out = k_new
        if status != 0:
            stop = _Stop(
                _COMPILED_STATUS[int(status)],
                f"compiled RK4 stopped ({_COMPILED_STATUS[int(status)]}) at t = {t_end:.6g} s",
                float(t_end),
                np.array(y_end[:12]),
            )
            stop.steps = done + int(did)
            raise stop
        done += todo
        y, t = y_end, t_end
        if model.rhs_evaluations >= settings.max_rhs_evaluations:
            stop = _Stop("budget-exceeded", f"more than {settings.max_rhs_evaluations} RHS evaluations", t, y[:12])
            stop.steps = done
            raise stop
        if time.perf_counter() - start > settings.max_wall_time_s:
            stop = _Stop("budget-exceeded", f"wall time above {settings.max_wall_time_s} s", t, y[:12])
            stop.steps = done
            raise stop
        report(t)
    return n_steps


FORCE_CHECK_INTERVAL_S = 1e-3
"""Largest simulated time between two force error checks of an RK4 run, s: with sparse output (say 10 ms) a
wheel-flat impact (about 3 ms at 60 km/h) still meets a check."""


def _check_every(settings, step_s: float) -> int:
    """Steps between force error checks: every output step, at most FORCE_CHECK_INTERVAL_S apart."""
    out_every = max(1, int(round(settings.output_step_s / step_s)))
    return max(1, min(out_every, int(round(FORCE_CHECK_INTERVAL_S / step_s))))


def _run_rk4(fun, y0, duration, settings, out_times, recorder, report, model) -> int:
    """Classical RK4 with a fixed step on the Python right-hand side ``fun``, output by cubic Hermite interpolation.

    Force error estimate (as compiled.rk4_run): every :func:`_check_every` steps the step is also advanced
    by the embedded third-order formula, y3 = y + h (k1/6 + k2/3 + k3/3 + k5/6) with k5 = f(t + h, y4) (the next
    step's k1), and the largest difference of the per-wheel contact forces at y4 and y3 is kept (two extra contact
    evaluations per check). An output sample at the step's end carries the estimate of that step, other samples
    the largest of the checks since the previous sample. The samples are recorded (and checked for anomalies)
    before the estimate is evaluated; a third-order state whose contact cannot be evaluated gives an infinite one.
    """
    n_steps = max(1, int(math.ceil(duration / settings.fixed_step_s - 1e-9)))
    h = duration / n_steps
    check_every = _check_every(settings, h)
    y = y0.copy()
    t = 0.0
    next_out = 1
    k1 = None
    pending = math.nan
    for i in range(n_steps):
        try:
            k1 = fun(t, y) if k1 is None else k1
            k2 = fun(t + 0.5 * h, y + 0.5 * h * k1)
            k3 = fun(t + 0.5 * h, y + 0.5 * h * k2)
            k4 = fun(t + h, y + h * k3)
        except _Stop as stop:
            stop.steps = i
            raise
        y_new = y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        t_new = (i + 1) * h
        at_end = False
        while next_out < len(out_times) and out_times[next_out] <= t_new + 1e-12 * max(1.0, duration):
            t_out = out_times[next_out]
            # cubic Hermite between the step ends (derivatives k1 and f(t_new) approximated by k4)
            s = (t_out - t) / h
            if abs(s - 1.0) < 1e-9:
                y_out, at_end = y_new, True
            else:
                h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
                h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
                y_out = h00 * y + h10 * h * k1 + h01 * y_new + h11 * h * k4
            try:
                recorder.record(t_out, y_out, math.nan if at_end else pending)
            except _Stop as stop:
                stop.steps = i + 1
                raise
            if not at_end:
                pending = math.nan
            next_out += 1
        k_next = None
        if (i + 1) % check_every == 0 or at_end:
            try:
                k_next = fun(t_new, y_new)
            except _Stop as stop:
                stop.steps = i + 1
                raise
            y3 = y + h * (k1 / 6.0 + k2 / 3.0 + k3 / 3.0 + k_next / 6.0)
            try:
                error = float(np.max(np.abs(_contact_force_sums(model, y_new) - _contact_force_sums(model, y3))))
            except (ContactFailure, ValueError, ArithmeticError):
                error = math.inf
            if math.isnan(error):  # forces not computable at one of the two states
                error = math.inf
            pending = error if math.isnan(pending) else max(pending, error)
        if at_end:
            recorder.set_last_error(pending)
            pending = math.nan
        y, t, k1 = y_new, t_new, k_next
        report(t)
    return n_steps


def timeseries_arrays(result: SimulationResult) -> dict[str, np.ndarray]:
    """The time series of a result as named arrays (what :func:`save_timeseries` writes).

    Arrays: ``t`` (n,), ``states`` (n, 12) with ``state_names``, ``patch_<field>`` (n, 2, 2) for every
    PATCH_FIELDS entry (sides left/right, slots tread/flange) and, for contact_model "auto", every
    AUTO_PATCH_FIELDS entry (the choice per patch) with ``auto_rung_names`` and ``auto_feature_names`` (what
    the codes of ``patch_auto_rung`` and ``patch_auto_deciding_feature`` index), ``contact_force_N`` (n, 2, 3),
    ``force_error_estimate`` (n,) for RK4 runs (SimulationResult), ``track_states`` (n, 8) with
    ``track_state_names`` for the elastic track,
    ``kinetic_energy_J``, ``potential_energy_J``, ``work_contact_J``, ``work_exterior_J``, and
    ``status``/``message``/``sides`` as strings. NaN marks candidates without contact, never a failed number:
    a failed run stops at its last good sample and says so in ``status``.
    """
    arrays = {
        "t": result.t,
        "states": result.states,
        "state_names": np.array(STATE_NAMES),
        "contact_force_N": result.contact_force_N,
        "kinetic_energy_J": result.kinetic_energy_J,
        "potential_energy_J": result.potential_energy_J,
        "work_contact_J": result.work_contact_J,
        "work_exterior_J": result.work_exterior_J,
        "status": np.array(result.status),
        "message": np.array(result.message),
        "sides": np.array(SIDES),
    }
    if result.force_error_estimate is not None:
        arrays["force_error_estimate"] = result.force_error_estimate
    if result.track_states is not None:
        arrays["track_states"] = result.track_states
        arrays["track_state_names"] = np.array(TRACK_STATE_NAMES)
    for name, values in result.patches.items():
        arrays[f"patch_{name}"] = values
    if "auto_rung" in result.patches:
        from rigid_dynamics.contact.auto import AUTO_RUNGS, FEATURES

        arrays["auto_rung_names"] = np.array(AUTO_RUNGS)
        arrays["auto_feature_names"] = np.array(FEATURES)
    return arrays


def save_timeseries(result: SimulationResult, path: str | Path) -> Path:
    """Write the time series of a result to an NPZ file atomically (:func:`rigid_dynamics.files.atomic_write`).

    The arrays are those of :func:`timeseries_arrays`.

    Returns:
        The path written (suffix .npz added when missing).
    """
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_suffix(".npz")
    from rigid_dynamics.files import atomic_write

    arrays = timeseries_arrays(result)

    def writer(tmp: Path) -> None:
        with open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)

    return atomic_write(path, writer)  # the one atomic write (usual permissions, no half file on a kill)
