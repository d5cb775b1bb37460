"""The result of a wheelset run: :class:`SimulationResult` (status, time series, summary, peaks), the dominant
wavelength of the lateral motion, and the time series as named arrays / an atomic NPZ file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rigid_dynamics.wheelset.discretisation import discretisation_errors
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.providers import SIDES
from rigid_dynamics.wheelset.state import STATE_NAMES

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
    "step-unstable",
    "step-size-underflow",
    "warning",
)


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
            contact_model "auto" also AUTO_PATCH_FIELDS (layout.py: the rung chosen per patch and why).
        contact_force_N: sum of the contact forces on each wheel, main frame, shape (n, 2, 3).
        kinetic_energy_J, potential_energy_J: T and V_g = -m g z at the output times, (n,); with the elastic track
            they include the track masses' kinetic energy and the pad and ballast springs' energy.
        work_contact_J, work_exterior_J: work done on the wheelset since t = 0 by contact forces and
            by exterior forces (suspension, axle load, torque), (n,); with the elastic track the contact work is
            that on wheel and rail together and the exterior work includes the track dampers'.
        track_states: what the run records of the elastic track at the output times, named by
            ``track_state_names`` (z down): the lumped track's 8 states (state.TRACK_STATE_NAMES), or the beam's
            rail deflection and velocity under each wheel (track_matrices.BEAM_SUMMARY_NAMES); with the lateral track
            its states too (state.LATERAL_STATE_NAMES); None for the rigid track.
        track_state_names: the names of ``track_states``' columns.
        track_full_states: every state of the elastic track at the output times (n, k) (the beam's modes and rail
            seats: track.BeamLayout); None for the rigid track.
        events: tuples (kind, side, time_s): "wheel-lift", "contact-restored", "flange-contact"; with a traction or
            braking torque "adhesion-limit" (the creep curve's maximum passed) and "wheel-slide"
            (recorder.adhesion_events).
        rhs_evaluations, steps: counters. wall_time_s: wall time of the run (static equilibrium, integration,
            recording), s; loading the compiled code from numba's cache (once per process, ~0.1 s) is not counted.
        failure_time_s, failure_state: where the run ended abnormally (None when it did not).
        provider, contact_model, method: what was used; compiled: whether the compiled loop ran it (RK4, or DP54/BS32:
            compiled_loop.py).
        force_error_estimate: RK4 runs: per output sample, the estimated error of one step in the per-wheel contact
            forces (normal, longitudinal and lateral creep force) divided by the static wheel load, (n,); NaN where
            no step ends at the sample (t = 0, interpolated samples); compiled DP54/BS32 runs: per output sample,
            that of the step containing it (the pair's solution against its embedded lower-order one; NaN for
            further samples in the same step); None for scipy's adaptive methods.
        half_step_peak_difference: RK4 runs in which a wheel lifted off after the settling distance: the largest
            difference of the settled peaks from a run at half the step, relative to the static wheel load
            (:func:`_half_step_check`; compiled DP54/BS32 runs: from a run at a tenth of both tolerances); None
            otherwise.
        scene: the scene that ran.
        companion_errors: the contact grid's and the geometry tables' error statements of the run's companions
            (discretisation.companion_errors); None before they are computed.
        traction: runs with a [traction] controller: traction.TRACTION_SERIES -> (n,) at the output times (the torque
            held from each sample on, N m; the demand and the measured total longitudinal creep force, N); None
            otherwise.
        callback_stats: runs with a contact model solved through the callback (callback.PatchCallback): its solves,
            seconds, the seconds spent sampling patches and the BEM warm start's counts; None otherwise.
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
    track_state_names: tuple = ()
    track_full_states: np.ndarray | None = field(default=None, repr=False)
    callback_stats: dict | None = None
    companion_errors: dict | None = field(default=None, repr=False)
    traction: dict | None = None

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

    @property
    def energy_balance_relative(self) -> float:
        """The largest |energy_residual_J| over the largest kinetic energy (at least 1 J); NaN without samples."""
        if len(self.t) == 0:
            return math.nan
        scale = max(float(np.max(np.abs(self.kinetic_energy_J))), 1.0)
        return float(np.max(np.abs(self.energy_residual_J))) / scale

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

    def _curve_summary(self, num):
        """The scene's curve and cant (None on straight track): direction, radius, cant, the cant angle, the cant
        deficiency (EN 13803: w V^2/(g R) - D) and the unbalanced lateral acceleration in the track plane,
        V^2/R cos(c) - g sin(c), m/s^2 (> 0 outwards).
        """
        if self.scene is None or not self.scene.track.curved:
            return None
        from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2 as g

        track, speed = self.scene.track, self.scene.speed_m_per_s
        cant = abs(track.cant_rad)
        return {
            "direction": track.curve_direction,
            "radius_m": num(track.curve_radius_m),
            "cant_m": num(track.cant_m),
            "cant_rad": num(cant),
            "cant_deficiency_m": num(track.cant_deficiency_m(speed, g)),
            "unbalanced_lateral_acceleration_m_per_s2": num(
                speed**2 / track.curve_radius_m * math.cos(cant) - g * math.sin(cant)
            ),
        }

    def summary(self) -> dict:
        """JSON-serialisable summary (NaN -> None); keys listed in the issue and a few diagnostics.

        Peaks (``peaks``, ``peak_normal_force_N``) are taken after the scene's settling distance, with the time and
        position of each; ``full_run_peaks`` and ``full_run_peak_normal_force_N`` include the start.
        """
        lateral = self.states[:, 1] if len(self.t) else np.zeros(0)
        wavelength = dominant_wavelength_m(self.states[:, 0], lateral) if len(self.t) > 4 else math.nan

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
            "energy_balance_relative": num(self.energy_balance_relative) if len(self.t) else None,
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
            "curve": self._curve_summary(num),
            "peak_rail_deflection_m": (
                {side: num(np.max(self.track_states[:, i])) for i, side in enumerate(SIDES)}
                if self.track_states is not None and len(self.track_states)
                else None
            ),
            "peak_rail_lateral_displacement_m": self._lateral_rail_peaks(num),
            **self._error_summary(num),
            "discretisation_errors": discretisation_errors(self),
            **self._auto_summary(),
            "patch_summary": self.patch_summary(),
            "callback": self.callback_stats,
            "traction": self._traction_summary(num),
        }

    def _traction_summary(self, num) -> dict | None:
        """The traction controller's mode and demand, and its last sample (torque, demand, measured force)."""
        if self.traction is None or self.scene is None:
            return None
        control = self.scene.traction
        last = {name: num(values[-1]) if len(values) else None for name, values in self.traction.items()}
        return {"mode": control.mode, "force_demand_N": control.force_demand_N,
                "adhesion_demand": control.adhesion_demand, "last_sample": last}  # fmt: skip

    def patch_summary(self) -> dict:
        """Per patch slot in contact (``"left tread"``, ``"right second"``, ...): which geometry the model saw
        (layout.PATCH_GEOMETRY_NAMES: its share of the recorded samples in contact), which law served it
        (compiled_laws.LAW_CODES names), whether it is a flange or a tread contact (its median contact angle against
        the track's ``flange_contact_angle_rad``), the ellipticity residual of a sampled gap (median and largest),
        and the largest max pressure (Pa) and contact area (m^2); slots never in contact are left out.
        """
        from rigid_dynamics.wheelset.compiled_laws import LAW_BEM_CORRECTED, LAW_CALLBACK, LAW_CODES
        from rigid_dynamics.wheelset.layout import PATCH_GEOMETRY_NAMES
        from rigid_dynamics.wheelset.table import SLOT_NAMES

        if "patch_geometry_code" not in self.patches or not len(self.t):
            return {}
        law_names = {code: name for name, code in LAW_CODES.items()}
        # the callback's model; auto's BEM rung (auto.AUTO_RUNGS' last, recorded as LAW_LINEAR + 3 = LAW_CALLBACK)
        law_names[LAW_CALLBACK] = "bem" if self.contact_model == "auto" else self.contact_model or "callback"
        law_names[LAW_BEM_CORRECTED] = "bem-corrected"  # auto's BEM patch reused (wheelset/auto_reuse.py)
        flange_angle = self.scene.track.flange_contact_angle_rad if self.scene is not None else 0.5
        out = {}
        for i, side in enumerate(SIDES):
            for j, slot in enumerate(SLOT_NAMES):
                touching = np.nan_to_num(np.asarray(self.patches["normal_force_N"], float)[:, i, j]) > 0
                if not touching.any():
                    continue

                def column(name, touching=touching, i=i, j=j):
                    return np.asarray(self.patches[name], float)[:, i, j][touching]

                geometry, law, residual = column("patch_geometry_code"), column("contact_law_code"), None
                res = column("ellipticity_residual")
                res = res[np.isfinite(res)]
                if res.size:
                    residual = {"median": float(np.median(res)), "max": float(res.max())}
                pmax, area = column("max_pressure_Pa"), column("contact_area_m2")
                angle = float(np.median(column("contact_angle_rad")))
                out[f"{side} {slot}"] = {
                    "samples_in_contact": int(touching.sum()),
                    "contact": "flange" if angle > flange_angle else "tread",
                    "median_contact_angle_rad": angle,
                    "geometry": {
                        n: float(np.mean(geometry == k)) for k, n in enumerate(PATCH_GEOMETRY_NAMES)
                        if np.any(geometry == k)
                    },
                    "law": sorted({law_names.get(int(c), str(int(c))) for c in law[np.isfinite(law)]}),
                    "ellipticity_residual": residual,
                    "max_pressure_Pa": float(np.nanmax(pmax)) if np.isfinite(pmax).any() else None,
                    "contact_area_m2": float(np.nanmax(area)) if np.isfinite(area).any() else None,
                }  # fmt: skip
        return out

    def _lateral_rail_peaks(self, num):
        """Per rail the largest |lateral displacement| of the lateral track (signed, y along the track's lateral
        axis), m; None without the lateral track.
        """
        names = list(self.track_state_names) if self.track_state_names is not None else []
        if self.track_states is None or not len(self.track_states) or "rail_left_lateral_m" not in names:
            return None
        out = {}
        for side in SIDES:
            column = self.track_states[:, names.index(f"rail_{side}_lateral_m")]
            out[side] = num(column[int(np.argmax(np.abs(column)))])
        return out

    def _auto_summary(self) -> dict:
        """``auto``'s choices over the run (empty for other models): per rung (contact.auto.AUTO_RUNGS) the share of
        the recorded patches in contact, per feature (contact.auto.FEATURES) the share it decided, the tolerance
        level used and the thresholds' identity; per patch and sample in timeseries.npz (``patch_auto_*``).
        """
        if "auto_rung" not in self.patches:
            return {}
        from rigid_dynamics.contact.auto import AUTO_RUNGS, FEATURES, load_thresholds
        from rigid_dynamics.contact.models import thresholds_identity

        rung = np.asarray(self.patches["auto_rung"], float)
        touching = np.isfinite(rung) & (np.nan_to_num(np.asarray(self.patches["normal_force_N"], float)) > 0)
        codes = rung[touching].astype(int)
        deciding = np.asarray(self.patches["auto_deciding_feature"], float)[touching].astype(int)
        level = np.asarray(self.patches["auto_level"], float)[touching]
        n = max(len(codes), 1)
        return {
            "auto": {
                "patches": len(codes),
                "level": float(np.nanmax(level)) if np.any(np.isfinite(level)) else None,
                "rung_share": {r: float(np.count_nonzero(codes == i) / n) for i, r in enumerate(AUTO_RUNGS)},
                "deciding_feature_share": {
                    f: float(np.count_nonzero(deciding == i) / n) for i, f in enumerate(FEATURES)
                },
                "thresholds": thresholds_identity(load_thresholds()),
                "geometry": self.auto_geometry(),
            }
        }

    def auto_geometry(self) -> dict | None:
        """discretisation.auto_geometry at the scene's FASTSIM grid: auto's ellipse-served patches against their
        sampled gap.
        """
        from rigid_dynamics.wheelset.discretisation import auto_geometry

        scene = self.scene
        return None if scene is None else auto_geometry(self, (scene.fastsim_elements_per_strip, scene.fastsim_strips))

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


def timeseries_arrays(result: SimulationResult) -> dict[str, np.ndarray]:
    """The time series of a result as named arrays (what :func:`save_timeseries` writes).

    Arrays: ``t`` (n,), ``states`` (n, 12) with ``state_names``, ``patch_<field>`` (n, 2, 2) for every
    PATCH_FIELDS entry (sides left/right, slots tread/flange) and, for contact_model "auto", every
    AUTO_PATCH_FIELDS entry (the choice per patch) with ``auto_rung_names`` and ``auto_feature_names`` (what
    the codes of ``patch_auto_rung`` and ``patch_auto_deciding_feature`` index), ``contact_force_N`` (n, 2, 3),
    ``force_error_estimate`` (n,) for RK4 runs (SimulationResult), ``track_states`` (n, k) with
    ``track_state_names`` for the elastic track (SimulationResult.track_states),
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
        arrays["track_state_names"] = np.array(result.track_state_names)
    for name, values in (result.traction or {}).items():
        arrays[name] = values
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
    from rigid_dynamics.files import write_npz

    return write_npz(path, **timeseries_arrays(result))  # the one atomic write (usual permissions, no half file)
