"""The "wheelset" contact case: a wheelset on two rails at a given lateral shift and yaw, loaded per wheel.

This is the set-up of the Manchester Contact Benchmark, case A-2.2 (P. Shackleton, S.D. Iwnicki, Vehicle
System Dynamics 46 (2008) 129-149): the wheelset is shifted laterally by ``lateral_shift_m`` (towards main +y,
the right rail) and yawed by ``yaw_rad`` (psi of eq 1: positive turns the wheelset's heading towards +y), and
its vertical position z and roll angle theta are found so that each wheel carries ``wheel_load_N``:

    sum over the wheel's patches of N_k (-n_z,k) = W       (left and right wheel; n_k rail -> wheel, z down)

with the patch forces N_k from Hertz's theory (eq 32-38) for the patch's curvatures A, B and approach q
(contact search, eq 5-33). The two equations are solved by Newton's method in the two wheel sinks
(s_L, s_R) with z = z_0 + (s_L + s_R)/2 and theta = theta_0 + (s_R - s_L)/(2 b) (b half the distance of the
wheels), residuals phi_i = (F_i / W)^(2/3) - 1 in contact (nearly linear in the approach, Hertz: F ~ q^1.5)
and -gap_i / q_W - 1 out of contact (q_W ~ the Hertz approach at load W), with a finite-difference Jacobian.

Load sharing between the patches (option ``load_sharing``):

* ``"hertz"``: each patch is solved with the requested contact model (``registry.get_model``) under force
  control with its Hertz share N_k of the wheel load (so every model carries the same load per patch). Right
  for the analytic models, whose normal part IS Hertz.
* ``"model"`` (the way of the CONTACT program's wheel-rail module, E.A.H. Vollebregt, open source: with the
  total vertical force prescribed it solves the wheel's patches for a wheelset position and iterates that
  position by Newton/secant steps until the force is met, its m_wr_brentmeth/m_wr_solvecp modules): the patch
  forces come from the model itself under approach control. At a pose the search gives every patch's
  rigid approach q_k (and, for ``bem``, its sampled undeformed distance h_k(x, y) - q_k), so all patches of a
  wheel share the one rigid displacement of the wheelset; the model's normal problem then gives N_k(pose), and
  the same two equations above are solved with these N_k. Start: the Hertz equilibrium; then Broyden's method
  (quasi-Newton, "good" rank-one update; Dennis & Schnabel 1983, sec. 8.1) on (s_L, s_R) starting from the Hertz
  Jacobian (finite differences at the Hertz equilibrium), each step one normal solve per patch (zero
  creepage: the normal problem does not depend on the tangential one for quasi-identical materials; with
  Kalker's difference parameter K != 0 in the model options the real creepages are used), until
  |F_i / W - 1| < ``force_tolerance`` on both wheels (``model_max_iterations``). The tangential
  problem is solved once at the end under approach control at the converged pose (so the normal forces are
  those of the equilibrium). Default (None): ``"model"`` when the model is ``bem`` and some patch is not
  elliptic or a wheel has several patches, else ``"hertz"``. Elastic interaction between patches of one
  wheel is neglected (each patch is its own half-space problem), as the patches are solved one by one.

Each patch is solved with the creepages of a freely rolling wheelset (eq 39-49, creepage.py): centre velocity
(V, 0, 0), yaw psi with zero yaw rate, roll theta, spin rate phi' = V / r0 (option
``spin_rate = "mean-rolling-radius"``: V over the mean rolling radius of the two wheels' main patches, the choice
of CONTACT's A-2.2 example input, mbench_a22_right.inp, where the longitudinal creepages of the two wheels are
equal and opposite).

``approach_m`` instead of ``wheel_load_N`` prescribes the deepest approach on each wheel (approach control);
every patch is then solved under approach control (``load_sharing`` is "approach").
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from rigid_dynamics.contact.creepage import wheelset_creepage
from rigid_dynamics.contact.search import SIDES, SideSearch, WheelsetPose
from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

DEFAULT_CASE_OPTIONS: dict = {
    "max_iterations": 40,
    "force_tolerance": 1e-6,  # relative, on each wheel's vertical load
    "approach_tolerance_m": 1e-10,
    "spin_rate": "nominal",  # "nominal": phi' = V/r0; "mean-rolling-radius": V / mean of the wheels' radii
    "search": None,  # options passed to search.search_side
    "model": None,  # options passed to the contact model
    "load_sharing": None,  # "hertz", "model" or None (auto: "model" for bem on non-elliptic/multi-patch wheels)
    "model_max_iterations": 20,  # iterations of the "model" load-sharing phase (one normal solve per patch each)
}
LOAD_SHARING = ("hertz", "model")


@dataclass(frozen=True)
class WheelsetCase:
    """A wheelset contact case (the ``[geometry] kind = "wheelset"`` contract of the contact-case files).

    Attributes:
        wheel_profile: built-in profile name or file path (both wheels; the left one is mirrored).
        rail_profile: built-in profile name or file path (both rails; mirrored on the left).
        lateral_shift_m: wheelset lateral displacement towards main +y (the right rail), m.
        yaw_rad: psi (eq 1), rad.
        gauge_m: track gauge (distance between the gauge faces at gauge_height_m below the rail tops), m.
        gauge_height_m: depth below the top of the rail where the gauge is measured, m (14 mm in EN 13848-1).
        flange_back_distance_m: distance between the two wheels' inner (back) faces, m.
        nominal_radius_m: r0, wheel radius at the tape circle, m.
        rail_inclination_rad: cant of the rails towards the track centre, rad (1:40 -> atan(1/40)). Set 0 when
            the rail profile is already canted (MBench_UIC60_v3.prr): it is applied to the profile as read.
        wheel_load_N: vertical load per wheel, N (force control), or None.
        approach_m: deepest approach per wheel, m (approach control), or None. Exactly one of the two.
        rolling_speed_m_per_s: V, forward speed of the wheelset, m/s.
    """

    wheel_profile: str
    rail_profile: str
    lateral_shift_m: float = 0.0
    yaw_rad: float = 0.0
    gauge_m: float = 1.435
    gauge_height_m: float = 0.014
    flange_back_distance_m: float = 1.360
    nominal_radius_m: float = 0.46
    rail_inclination_rad: float = 0.0
    wheel_load_N: float | None = None
    approach_m: float | None = None
    rolling_speed_m_per_s: float = 1.0

    def __post_init__(self) -> None:
        for name in ("wheel_profile", "rail_profile"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value:
                raise ValueError(f"{name} = {value!r}: expected a built-in profile name or a file path")
        finite = (
            "lateral_shift_m",
            "yaw_rad",
            "gauge_m",
            "gauge_height_m",
            "flange_back_distance_m",
            "nominal_radius_m",
            "rail_inclination_rad",
            "rolling_speed_m_per_s",
        )
        for name in finite:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")
        for name in ("gauge_m", "nominal_radius_m", "rolling_speed_m_per_s", "flange_back_distance_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected > 0")
        if self.gauge_height_m < 0:
            raise ValueError(f"gauge_height_m = {self.gauge_height_m!r}: expected >= 0")
        if self.flange_back_distance_m >= self.gauge_m:
            raise ValueError(
                f"flange_back_distance_m = {self.flange_back_distance_m!r}: "
                f"expected less than gauge_m = {self.gauge_m!r}"
            )
        if abs(self.yaw_rad) > 0.2:
            raise ValueError(f"yaw_rad = {self.yaw_rad!r}: expected |yaw| <= 0.2 rad")
        if abs(self.rail_inclination_rad) > 0.2:
            raise ValueError(f"rail_inclination_rad = {self.rail_inclination_rad!r}: expected |value| <= 0.2 rad")
        if (self.wheel_load_N is None) == (self.approach_m is None):
            raise ValueError(
                f"wheel_load_N = {self.wheel_load_N!r}, approach_m = {self.approach_m!r}: expected exactly one of them"
            )
        for name in ("wheel_load_N", "approach_m"):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0):
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")


@dataclass(frozen=True, eq=False)
class PatchSolution:
    """One solved patch: its side, geometry, creepages and the contact model's result."""

    side: str
    geometry: ContactGeometry
    creepage: Creepage
    result: ContactResult

    @property
    def vertical_force_N(self) -> float:
        """Upward load carried by this patch, N (normal force times -n_z; main z points down)."""
        return float(self.result.normal_force_N * -self.geometry.frame[2, 2])


@dataclass(frozen=True, eq=False)
class WheelsetCaseSolution:
    """Solution of a :class:`WheelsetCase`.

    Attributes:
        success, status, message: status "ok", "not-converged" (equilibrium iteration), "no-contact",
            "search-failed" or "model-failed" (a patch's model did not succeed; see its result).
        wall_time_s: s.
        vertical_position_m: z of the wheelset centre (main frame, z down), m.
        roll_rad: theta, rad.
        patches: all patches, left first, deepest first per side.
        wheel_vertical_load_N: {"left": ..., "right": ...} vertical load carried at the equilibrium, N: sum of
            N_k (-n_z,k) with Hertz's N_k ("hertz" sharing) or the model's ("model" sharing, approach control).
        iterations: equilibrium iterations in all (rigid contact + Hertz + model phase).
        load_sharing: "hertz", "model" or "approach" (approach-controlled case).
        model_iterations: iterations of the model phase ("model" sharing; 0 otherwise), each one normal solve
            per patch.
        equilibrium_residual: max over the wheels of |vertical load / wheel_load_N - 1| at the final pose (with
            the forces of the chosen sharing); nan for approach-controlled cases.
        pose: the final :class:`WheelsetPose`.
    """

    success: bool
    status: str
    message: str
    wall_time_s: float
    vertical_position_m: float
    roll_rad: float
    patches: list[PatchSolution]
    wheel_vertical_load_N: dict
    iterations: int
    load_sharing: str = "hertz"
    model_iterations: int = 0
    equilibrium_residual: float = math.nan
    pose: WheelsetPose | None = None
    extra: dict = field(default_factory=dict)


def _hertz_loads(searches: dict[str, SideSearch], material: Material):
    from rigid_dynamics.contact.hertz import hertz_force_from_approach

    loads, forces = {}, {}
    for side, result in searches.items():
        if not result.patches:
            loads[side], forces[side] = 0.0, np.zeros(0)
            continue
        a = np.array([p.curvature_long_1_per_m for p in result.patches])
        b = np.array([p.curvature_lat_1_per_m for p in result.patches])
        q = np.array([p.approach_m for p in result.patches])
        f = hertz_force_from_approach(
            a, b, q, shear_modulus_Pa=material.shear_modulus_Pa, poisson_ratio=material.poisson_ratio
        )
        up = np.array([-p.frame[2, 2] for p in result.patches])
        loads[side], forces[side] = float(np.sum(f * up)), f
    return loads, forces


def _pose(track, lateral_shift_m: float, yaw_rad: float, sinks) -> WheelsetPose:
    """Pose from the two wheel sinks: z = z_rest + (s_L + s_R)/2, theta = (s_R - s_L)/(2 e_w)."""
    z = track.rest_z_m + 0.5 * (sinks[0] + sinks[1])
    roll = (sinks[1] - sinks[0]) / (2.0 * track.half_wheel_distance_m)
    return WheelsetPose(y_m=lateral_shift_m, z_m=float(z), yaw_rad=yaw_rad, roll_rad=float(roll))


def _search_both(track, lateral_shift_m: float, yaw_rad: float, sinks, search_options):
    pose = _pose(track, lateral_shift_m, yaw_rad, sinks)
    return pose, {side: track.search(pose, side, search_options) for side in SIDES}


def _newton_sinks(searches_of, func, sinks, tolerance, limit, max_iterations):
    """Newton's method on the 2 sinks with a forward-difference Jacobian; returns (sinks, iterations, status)."""
    step = 2.0e-7
    for iteration in range(1, max_iterations + 1):
        searches = searches_of(sinks)
        if not all(np.isfinite(s.min_gap_m) for s in searches.values()):
            return sinks, iteration, "search-failed"
        r = func(searches)
        if np.all(np.abs(r) < tolerance):
            return sinks, iteration, "ok"
        jac = np.zeros((2, 2))
        for j in range(2):
            ds = np.zeros(2)
            ds[j] = step
            jac[:, j] = (func(searches_of(sinks + ds)) - r) / step
        try:
            delta = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            delta = -r * limit
        sinks = sinks + np.clip(np.nan_to_num(delta), -limit, limit)
    return sinks, max_iterations, "not-converged"


@dataclass(frozen=True, eq=False)
class RigidContact:
    """Wheelset position where both wheels just touch their rails (no elastic approach).

    Attributes:
        success, status: "ok", "not-converged" or "search-failed".
        pose: the pose found (z and roll solved, shift and yaw given).
        min_gap_m: side -> smallest gap (0 within the tolerance), m.
        rolling_radius_m: side -> wheel radius at the touching point, m.
        contact_point_m: side -> touching point on the wheel, main frame, m (shape (3,)).
        iterations: Newton iterations.
    """

    success: bool
    status: str
    pose: WheelsetPose
    min_gap_m: dict
    rolling_radius_m: dict
    contact_point_m: dict
    iterations: int


def rigid_contact(
    track, lateral_shift_m: float, yaw_rad: float = 0.0, *, search_options=None, tolerance_m: float = 1e-9
) -> RigidContact:
    """Vertical position and roll of a wheelset (given shift and yaw) touching both rails: smallest gap 0 per side.

    Args:
        track: :class:`~rigid_dynamics.contact.track.WheelsetTrack`.
        lateral_shift_m: y of the wheelset centre, m. yaw_rad: psi, rad.
        search_options: options of the contact search.
        tolerance_m: |smallest gap| accepted, m.
    """
    opts = {"field": False}
    opts.update(search_options or {})

    def searches_of(sinks):
        return _search_both(track, lateral_shift_m, yaw_rad, sinks, opts)[1]

    def gaps(searches):
        return np.array([searches[side].min_gap_m for side in SIDES])

    sinks, iterations, status = _newton_sinks(searches_of, gaps, np.zeros(2), tolerance_m, 2.0e-3, 40)
    pose, searches = _search_both(track, lateral_shift_m, yaw_rad, sinks, opts)
    radius, point, gap = {}, {}, {}
    for side in SIDES:
        cand = searches[side].candidates
        gap[side] = searches[side].min_gap_m
        if len(cand.gap_m) == 0:
            radius[side], point[side] = math.nan, np.full(3, math.nan)
            continue
        k = int(np.argmin(cand.gap_m))
        alpha, y_d = float(cand.alpha_rad[k]), float(cand.lateral_m[k])
        values = track.wheels[side].evaluate(np.array([alpha]), np.array([y_d]))
        r = float(values[0][0])
        radius[side] = r
        x_d = np.array([r * math.cos(alpha), y_d, r * math.sin(alpha)])
        point[side] = pose.rotation @ x_d + pose.centre_m
    return RigidContact(status == "ok", status, pose, gap, radius, point, iterations)


def _model_is_bem(contact_model) -> bool:
    return getattr(contact_model, "name", "") == "bem"


def _vertical_loads(searches: dict[str, SideSearch], forces: dict[str, np.ndarray]) -> dict[str, float]:
    """Per side: sum over its patches of N_k (-n_z,k), N (main z points down, n_k from the rail into the wheel)."""
    return {
        side: float(sum(f * -p.frame[2, 2] for f, p in zip(forces[side], searches[side].patches, strict=True)))
        for side in SIDES
    }


def _spin_rate(case: WheelsetCase, searches: dict[str, SideSearch], forces, spin_rate: str) -> float:
    """Spin rate phi' (rad/s): V/r0 ("nominal") or V over the mean rolling radius of each wheel's most loaded patch."""
    if spin_rate == "nominal":
        return case.rolling_speed_m_per_s / case.nominal_radius_m
    radii = []
    for side in SIDES:
        if searches[side].patches:
            k = int(np.argmax(forces[side])) if len(forces[side]) else 0
            radii.append(searches[side].patches[k].rolling_radius_m)
    mean_radius = float(np.mean(radii)) if radii else case.nominal_radius_m
    return case.rolling_speed_m_per_s / mean_radius


def _creepage(case: WheelsetCase, pose: WheelsetPose, geometry: ContactGeometry, omega_spin: float) -> Creepage:
    """Creepages of the freely rolling wheelset at the patch (eq 39-49, creepage.py)."""
    x_d = pose.rotation.T @ (geometry.point_m - pose.centre_m)
    kin = wheelset_creepage(
        x_d,
        geometry.frame[:, 2],
        yaw_rad=case.yaw_rad,
        roll_rad=pose.roll_rad,
        centre_velocity_m_per_s=[case.rolling_speed_m_per_s, 0.0, 0.0],
        spin_rate_rad_per_s=omega_spin,
    )
    return kin.creepage()


def _load_residual(searches, loads, target, q_ref) -> np.ndarray:
    """phi_i = (F_i/W)^(2/3) - 1 on a wheel in contact, -gap_i/q_W - 1 on a wheel without a patch."""
    out = np.zeros(2)
    for i, side in enumerate(SIDES):
        if searches[side].patches:
            out[i] = (max(loads[side], 0.0) / target) ** (2.0 / 3.0) - 1.0
        else:
            out[i] = -searches[side].min_gap_m / q_ref - 1.0
    return out


def solve_wheelset_case(
    case: WheelsetCase,
    material: Material,
    model="hertz",
    options: Mapping | None = None,
    *,
    track=None,
) -> WheelsetCaseSolution:
    """Find the wheelset's vertical position and roll carrying the load, then solve every patch.

    Args:
        case: the case.
        material: elastic constants and friction of the pair.
        model: contact model name (registry) or instance, used for the final patch solutions (and for the
            normal forces of the equilibrium with ``load_sharing = "model"``, module docstring).
        options: ``DEFAULT_CASE_OPTIONS`` keys; ``load_sharing`` "hertz", "model" or None (automatic).
        track: optional pre-built :class:`~rigid_dynamics.contact.track.WheelsetTrack` (else built from the case).

    Returns:
        :class:`WheelsetCaseSolution` (never raises for non-convergence: ``success`` False, status
        "not-converged", "search-failed" or "model-failed").

    Raises:
        ValueError: bad case, option or model name; unreadable profile.
    """
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.track import build_track

    started = time.perf_counter()
    opts = dict(DEFAULT_CASE_OPTIONS)
    for key, value in (options or {}).items():
        if key not in DEFAULT_CASE_OPTIONS:
            raise ValueError(f"wheelset case option {key!r}: expected one of {', '.join(DEFAULT_CASE_OPTIONS)}")
        opts[key] = value
    if opts["spin_rate"] not in ("nominal", "mean-rolling-radius"):
        raise ValueError(f"spin_rate = {opts['spin_rate']!r}: expected 'nominal' or 'mean-rolling-radius'")
    value = opts["model_max_iterations"]
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"model_max_iterations = {value!r}: expected an integer >= 1")
    if opts["load_sharing"] is not None and opts["load_sharing"] not in LOAD_SHARING:
        raise ValueError(f"load_sharing = {opts['load_sharing']!r}: expected 'hertz', 'model' or None (automatic)")
    contact_model = get_model(model)
    if track is None:
        track = build_track(case)
    search_options = dict(opts["search"] or {})
    search_options.setdefault("field", False)
    field_sampling = bool((opts["search"] or {}).get("field", True))

    def run(sinks, field_sampling=False):
        so = dict(search_options, field=field_sampling)
        return _search_both(track, case.lateral_shift_m, case.yaw_rad, sinks, so)

    q_ref = track.reference_approach_m(case, material)
    target = case.wheel_load_N

    def residual(searches):
        if target is not None:
            return _load_residual(searches, _hertz_loads(searches, material)[0], target, q_ref)
        out = np.zeros(2)
        for i, side in enumerate(SIDES):
            result = searches[side]
            if result.patches:
                out[i] = max(p.approach_m for p in result.patches) / case.approach_m - 1.0
            else:
                out[i] = -result.min_gap_m / q_ref - 1.0
        return out

    def gaps(searches):
        return np.array([searches[side].min_gap_m for side in SIDES]) / q_ref

    def newton(func, sinks, tolerance, limit, max_iterations):
        return _newton_sinks(lambda x: run(x)[1], func, sinks, tolerance, limit, max_iterations)

    # Phase 1: rigid contact, both wheels just touching (smallest gap 0 on each side).
    sinks, it1, status = newton(gaps, np.zeros(2), 1e-4, 2.0e-3, opts["max_iterations"])
    # Phase 2: sink into the rails until each wheel carries its load by Hertz (or the prescribed approach).
    iterations = it1
    if status == "ok":
        tolerance = opts["force_tolerance"] if target is not None else opts["approach_tolerance_m"] / case.approach_m
        sinks, it2, status = newton(residual, sinks, tolerance, 5.0 * q_ref, opts["max_iterations"])
        iterations += it2
    messages = {
        "ok": f"equilibrium found in {iterations} iterations",
        "search-failed": "the wheel misses its rail (no finite gap on one side)",
        "not-converged": "equilibrium iteration did not converge",
    }
    message = messages[status]
    pose, searches = run(sinks, field_sampling=field_sampling)
    loads, forces = _hertz_loads(searches, material)

    # Which load sharing.
    if target is None:
        sharing = "approach"
    elif opts["load_sharing"] is not None:
        sharing = opts["load_sharing"]
    else:
        several = any(len(searches[side].patches) > 1 for side in SIDES)
        non_elliptic = any(not p.is_elliptic for side in SIDES for p in searches[side].patches)
        sharing = "model" if _model_is_bem(contact_model) and (several or non_elliptic) else "hertz"

    # Phase 3 ("model" sharing): Broyden iteration with the model's normal forces under approach control.
    model_iterations = 0
    normal_results: dict | None = None  # side -> results of the last normal solves (at `searches`)
    coupled = bool((opts["model"] or {}).get("difference_parameter", 0.0))
    failed: list[str] = []
    if sharing == "model" and status == "ok":
        jac = np.zeros((2, 2))
        base = residual(searches)
        step = 2.0e-7
        for j in range(2):
            ds = np.zeros(2)
            ds[j] = step
            jac[:, j] = (residual(run(sinks + ds)[1]) - base) / step
        limit = 5.0 * q_ref
        previous = None
        status = "not-converged"
        for model_iterations in range(1, opts["model_max_iterations"] + 1):  # noqa: B007 (reported)
            if model_iterations > 1:
                pose, searches = run(sinks, field_sampling=field_sampling)
            if not all(np.isfinite(s.min_gap_m) for s in searches.values()):
                status = "search-failed"
                break
            if coupled:
                omega = _spin_rate(case, searches, _hertz_loads(searches, material)[1], opts["spin_rate"])
            normal_results, forces, failed = {}, {}, []
            for side in SIDES:
                normal_results[side] = []
                for k, geometry in enumerate(searches[side].patches):
                    if coupled:
                        creepage = _creepage(case, pose, geometry, omega)
                    else:
                        creepage = Creepage(rolling_speed_m_per_s=case.rolling_speed_m_per_s)
                    result = contact_model.solve(
                        geometry, creepage, material, normal_force_N=None, options=opts["model"]
                    )
                    if not result.success:
                        failed.append(f"{side} patch {k}: {result.message}")
                    normal_results[side].append(result)
                forces[side] = np.array([r.normal_force_N for r in normal_results[side]], float)
            loads = _vertical_loads(searches, forces)
            if failed:
                status = "model-failed"
                break
            r = _load_residual(searches, loads, target, q_ref)
            if not np.all(np.isfinite(r)):
                break
            # converged when each wheel's vertical load is within force_tolerance of W (relative)
            error = [abs(loads[side] / target - 1.0) if searches[side].patches else math.inf for side in SIDES]
            if max(error) < opts["force_tolerance"]:
                status = "ok"
                break
            if previous is not None:
                d_s, d_r = sinks - previous[0], r - previous[1]
                denom = float(d_s @ d_s)
                if denom > 0:
                    jac = jac + np.outer(d_r - jac @ d_s, d_s) / denom
            try:
                delta = np.linalg.solve(jac, -r)
            except np.linalg.LinAlgError:
                delta = -r * limit
            previous = (sinks.copy(), r)
            sinks = sinks + np.clip(np.nan_to_num(delta), -limit, limit)
        iterations += model_iterations
        model_name = getattr(contact_model, "name", type(contact_model).__name__)
        if status == "ok":
            message = (
                f"equilibrium found in {iterations} iterations ({model_iterations} with the {model_name} "
                "model's normal forces, load sharing 'model')"
            )
        elif status == "model-failed":
            message = "load sharing 'model': normal solve failed: " + "; ".join(failed)
        elif status == "search-failed":
            message = messages["search-failed"] + " (load sharing 'model')"
        else:
            message = (
                f"load sharing 'model': equilibrium with the {model_name} model's normal forces did not "
                f"converge in {model_iterations} iterations (force tolerance {opts['force_tolerance']:g})"
            )
    if target is not None:
        if sharing == "hertz":
            loads = _hertz_loads(searches, material)[0]
        equilibrium_residual = float(max(abs(loads[side] / target - 1.0) for side in SIDES))
    else:
        equilibrium_residual = math.nan

    # Final patch solutions (tangential problem at the final pose).
    patches: list[PatchSolution] = []
    failed = []
    omega_spin = _spin_rate(case, searches, forces, opts["spin_rate"])
    for side in SIDES:
        for k, geometry in enumerate(searches[side].patches):
            creepage = _creepage(case, pose, geometry, omega_spin)
            if sharing == "model" and normal_results is not None and coupled:
                result = normal_results[side][k]  # solved with the real creepages already
            else:
                force = float(forces[side][k]) if sharing == "hertz" else None
                result = contact_model.solve(geometry, creepage, material, normal_force_N=force, options=opts["model"])
            if not result.success:
                failed.append(f"{side} patch {k}: {result.message}")
            patches.append(PatchSolution(side, geometry, creepage, result))
    if status == "ok" and failed:
        status, message = "model-failed", "; ".join(failed)
    if status == "ok" and not patches:
        status, message = "no-contact", "no patch found"
    return WheelsetCaseSolution(
        success=status == "ok",
        status=status,
        message=message,
        wall_time_s=time.perf_counter() - started,
        vertical_position_m=pose.z_m,
        roll_rad=pose.roll_rad,
        patches=patches,
        wheel_vertical_load_N=loads,
        iterations=iterations,
        load_sharing=sharing,
        model_iterations=model_iterations,
        equilibrium_residual=equilibrium_residual,
        pose=pose,
    )
