"""The "wheelset" contact case: one wheelset on two rails at a given lateral shift and yaw (CONTACT's module 1).

This is the set-up of the Manchester Contact Benchmark, case A-2.2 (P. Shackleton, S.D. Iwnicki, Vehicle
System Dynamics 46 (2008) 129-149) and of the wheel-rail module of the CONTACT program (E.A.H. Vollebregt,
J.J. Kalker; open source): the wheelset is shifted laterally by ``lateral_shift_m`` (towards main +y, the right
rail) and yawed by ``yaw_rad`` (psi of eq 1), and its vertical position is found so that each wheel carries
``wheel_load_N``, the **total vertical contact force** on the wheel, creep forces included:

    W = - e_z . sum over the wheel's patches of (F_x e_x + F_y e_y + N n)      (main z down, forces on the wheel)

Patches (option ``patches``): ``"contact"`` (default) forms them as CONTACT does, from the vertical gap under the
wheel's contact locus, joining close interpenetration regions into one patch (A_SEP, D_SEP, D_COMB) with the
contact plane at the weighted centre (rigid_dynamics.contact.wheelset_patches, where the undeformed distance is
evaluated exactly at any point; regions are joined only for a model that solves the joined gap itself, ``bem``
and ``fea``, or any model with ``solves_undeformed_distance = True``: the analytic rungs take each region as its
own patch); ``"search"`` takes the 3-D search's patches (one per local minimum of the
normal distance, plane at the deepest point; the geometry the dynamics uses). Every patch is solved by the
requested model under approach control at the wheelset's pose, so all patches of a wheel share its rigid
displacement and each model carries the load with its own normal forces (Hertz for the analytic rungs).

Kinematics (``roll_rad`` of the case):

* ``roll_rad`` None — whole-wheelset equilibrium: z and roll theta are solved so that both wheels carry W
  (two unknowns, the wheel sinks s_L, s_R: z = z_0 + (s_L + s_R)/2, theta = theta_0 + (s_R - s_L)/(2 b)).
* ``roll_rad`` given — per wheel, as CONTACT's deck: the roll is prescribed and each wheel's vertical position
  is solved on its own (one unknown per wheel).

Residuals phi_i = (F_i / W)^(2/3) - 1 (nearly linear in the sink: F ~ q^1.5); the first step scales the sink by
(W / F)^(2/3), then secant (per wheel) or Broyden's method (both wheels), until |F_i / W - 1| <
``force_tolerance``, or the patches' stated relative error of their normal forces when larger (a model with a
discretisation error, the FEA: see ``_load_tolerance``). A model with ``coarse_options(options)`` (the FEA: its
first mesh, without the refinement series) is balanced first with those, then with its own options from there,
passed through ``load_balanced_options(options)`` when it has it (the FEA: its max pressure and area are then
judged at its own force and it states the load error they afford, ``load_tolerance``, which the equilibrium meets
instead of the force's error: fea.refinement, load-balanced use).
The tangential problem is part of every evaluation, since its forces carry part of W.
A model that estimates its grid error (``bem``, grid not named) is balanced on its default grid without the
estimate; each final patch is then solved once with the model's own refinement, and where that refines the grid
(until ``grid_tolerance`` is met) the equilibrium is rebalanced on the refined grid of that side (``nx``, ``ny``
over the potential area) from there, so the final patches' numbers are the ones their stated error belongs to
(Manchester A-2.2's flange patch: 40 x 40 -> 320 x 320, max pressure estimate 20 % -> 1.2 %).

Pitch rate: the case's ``pitch_rate_rad_per_s`` (the wheelset's angular velocity about its axle, with CONTACT's
sign: negative for forward rolling; spin rate phi' = -pitch rate), else option ``spin_rate``:
``"zero-axle-moment"`` (default; a freely rolling wheelset without traction torque settles where the moments of
all contact forces about the axle cancel: secant iteration on phi', each step a full equilibrium; a model without
creep forces, ``hertz``, has no moment and keeps V / r0),
``"nominal"`` (V / r0) or ``"mean-rolling-radius"`` (V over the mean rolling radius of the wheels' main patches).
Creepages (eq 39-49, creepage.py) of the wheel's material point on the normal through each patch's reference
point; centre velocity (V, 0, 0), yaw and roll rates 0; relative to the mean rolling speed of the two bodies as
Kalker and CONTACT define them (option ``rolling_speed``, see ``_creepage``). Which point of that normal (option
``creepage_point``, patches "contact"): ``"wheel-surface"`` (default) the wheel's surface point, at the local
interpenetration d from the rail's reference point; ``"approach"`` the point at the patch's approach q from it
(CONTACT's wheel-rail module: its point Q at PEN from the rail's reference point, m_wr_rigslip). They differ where
the reference point is not the deepest point (d < q): on Manchester A-2.2 at 5 mm shift d = 0.011 mm,
q = 0.030 mm, and xi differs by 4e-5 (1.1 %; CONTACT's CKSI is matched to 0.06 % with "approach").

``approach_m`` instead of ``wheel_load_N`` prescribes the largest approach on each wheel (approach control).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from rigid_dynamics.contact.creepage import wheelset_creepage
from rigid_dynamics.contact.search import SIDES, WheelsetPose
from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

DEFAULT_CASE_OPTIONS: dict = {
    "max_iterations": 40,  # equilibrium iterations (per wheel, or of the whole wheelset)
    "force_tolerance": 1e-6,  # relative, on each wheel's vertical load
    "approach_tolerance_m": 1e-10,
    "spin_rate": "zero-axle-moment",  # without a prescribed pitch rate: "zero-axle-moment", "nominal",
    # "mean-rolling-radius"
    "axle_moment_tolerance": 1e-6,  # zero-axle-moment: |M| / (W r0) below this
    "patches": "contact",  # "contact" (CONTACT's module 1) or "search" (the 3-D search's patches)
    "patch": None,  # options of wheelset_patches.wheel_patches (angle_separation_rad, distance_*_m, ...)
    "search": None,  # options passed to search.search_side ("search" patches)
    "model": None,  # options passed to the contact model
    "creepage_point": "wheel-surface",  # the wheel point of the creepages: "wheel-surface" or "approach" (CONTACT)
    "rolling_speed": "mean",  # creepages relative to the bodies' mean rolling speed ("mean", Kalker, CONTACT)
    # or to the wheelset centre's speed ("centre", eq 41); see _creepage
    "sides": SIDES,  # per-wheel kinematics: the wheels to solve (CONTACT's deck solves the right one)
    "friction_place": "patch",  # a friction law varying in place: "patch" (one value at the patch's reference
    # point, as CONTACT for a planar patch) or "element" (the rail's inclination / lateral coordinate under each
    # element): friction_place_of
}
FRICTION_PLACES = ("patch", "element")
COARSE_FORCE_TOLERANCE = 1e-3
"""The load tolerance of the coarse phase of a model with ``coarse_options`` (the FEA): the full solve's force
differs from the coarse one by its discretisation error, several per cent on the A-2.2 patches, so balancing the
coarse load further is wasted (manchester-a22: 14 coarse evaluations to 1e-6, the last 6 of them below 1e-3)."""
SPIN_RATES = ("zero-axle-moment", "nominal", "mean-rolling-radius")
CREEPAGE_POINTS = ("wheel-surface", "approach")
"""Option ``creepage_point`` (module docstring): the wheel's material point of a patch's creepages."""
PATCH_MODES = ("contact", "search")


def case_options(method: str, check_model=None) -> dict:
    """Declaration (rigid_dynamics.contact.options) of :func:`solve_wheelset_case`'s options for the model
    ``method``: the case's own, the search's and the patches' nested, and the model's under ``model`` (checked by
    ``check_model(value, key)`` when given, else against the model's declaration).
    """
    from rigid_dynamics.contact.options import Option, declare, validate_options
    from rigid_dynamics.contact.registry import model_options
    from rigid_dynamics.contact.search import DEFAULT_OPTIONS as SEARCH_OPTIONS
    from rigid_dynamics.contact.wheelset_patches import DEFAULT_PATCH_OPTIONS

    def nested(defaults, what):
        def kind(v):
            if v is None or isinstance(v, float):
                return float
            return tuple if isinstance(v, (tuple, list)) else type(v)

        def bounds(k, v):
            """Counts, lengths, angles, tolerances, margins and scales are not negative; steps are > 0."""
            if isinstance(v, bool) or not isinstance(v, (int, float)) and v is not None:
                return {}
            if k.endswith("_points"):
                return {"minimum": 3, "maximum": 1001}
            if k.endswith("_iterations"):
                return {"minimum": 1, "maximum": 1000}
            if "step" in k:
                return {"minimum": 0, "exclusive_minimum": True}
            if k.endswith(("_m", "_rad", "tolerance", "_margin", "_scale")):
                return {"minimum": 0}
            return {}

        declared = declare(
            *(
                Option(k, kind(v), v, f"{what} option", allow_none=v is None, **bounds(k, v))
                for k, v in defaults.items()
            )
        )

        def check(value, key):
            validate_options(declared, value, what, prefix=f"{key}.")

        return check

    if check_model is None:

        def check_model(value, key):
            validate_options(model_options(method), value, method, prefix=f"{key}.")

    d = DEFAULT_CASE_OPTIONS
    return declare(
        Option("max_iterations", int, d["max_iterations"], "equilibrium iterations", minimum=1),
        Option("force_tolerance", float, d["force_tolerance"], "relative, on each wheel's vertical load", minimum=0,
               exclusive_minimum=True),
        Option("approach_tolerance_m", float, d["approach_tolerance_m"], "m", minimum=0, exclusive_minimum=True),
        Option("spin_rate", str, d["spin_rate"], "pitch rate without a prescribed one", choices=SPIN_RATES),
        Option("axle_moment_tolerance", float, d["axle_moment_tolerance"], "|M| / (W r0)", minimum=0,
               exclusive_minimum=True),
        Option("patches", str, d["patches"], "how patches are formed", choices=PATCH_MODES),
        Option("patch", dict, d["patch"], "options of the CONTACT-style patches (A_SEP, D_SEP, D_COMB, ...)",
               allow_none=True, check=nested(DEFAULT_PATCH_OPTIONS, "patch")),
        Option("search", dict, d["search"], "contact search options", allow_none=True,
               check=nested(SEARCH_OPTIONS, "contact search")),
        Option("model", dict, d["model"], f"options of the contact model {method!r}", allow_none=True,
               check=check_model),
        Option("rolling_speed", str, d["rolling_speed"], "creepages relative to", choices=("mean", "centre")),
        Option("creepage_point", str, d["creepage_point"], "the wheel point of the creepages on the patch normal",
               choices=CREEPAGE_POINTS),
        Option("sides", tuple, d["sides"], "per-wheel kinematics: the wheels solved"),
        Option("friction_place", str, d["friction_place"], "where a friction law varying in place is evaluated",
               choices=FRICTION_PLACES),
    )  # fmt: skip


def friction_place_of(geometry: ContactGeometry, rail, side: str):
    """The place function of a wheelset patch (``ContactGeometry.friction_place``): at a point (x, y) of the contact
    plane, the rail surface under it (the same main-frame y) gives the surface inclination atan(-+ dN/dy) (N the
    rail height, z down; - on the right rail, + on the left: the sign of the contact angle, positive towards the
    gauge face, so that it equals ``contact_angle_rad`` where the rail's normal is the patch's) or the lateral
    coordinate on the rail profile; "track_distance" is the patch's ``track_distance_m`` plus x along the track.
    """
    exact = getattr(rail, "exact", rail)
    sign = -1.0 if side == "right" else 1.0
    origin, frame = np.asarray(geometry.point_m, float), np.asarray(geometry.frame, float)

    def place(varies_with: str, x_m, y_m):
        x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        points = origin + x_m[..., None] * frame[:, 0] + y_m[..., None] * frame[:, 1]
        if varies_with == "track_distance":
            return geometry.track_distance_m + points[..., 0]
        values = rail.evaluate(points[..., 0], points[..., 1])
        if varies_with == "surface_inclination":
            return np.arctan(sign * np.asarray(values[2], float))
        return np.asarray(exact.to_profile_coordinates(points[..., 1], np.asarray(values[0], float))[0], float)

    return place


@dataclass(frozen=True)
class WheelsetCase:
    """A wheelset contact case (the ``[geometry] kind = "wheelset"`` contract of the contact-case files).

    Attributes:
        wheel_profile: built-in profile name or file path (the right wheel; also the left one, mirrored, unless
            ``wheel_profile_left`` is given).
        rail_profile: built-in profile name or file path (the right rail; also the left, mirrored).
        lateral_shift_m: wheelset lateral displacement towards main +y (the right rail), m.
        yaw_rad: psi (eq 1), rad.
        gauge_m: track gauge (distance between the gauge faces at gauge_height_m below the rail tops), m.
        gauge_height_m: depth below the top of the rail where the gauge is measured, m (14 mm in EN 13848-1).
        flange_back_distance_m: distance between the two wheels' inner (back) faces, m.
        nominal_radius_m: r0, wheel radius at the tape circle, m.
        rail_inclination_rad: cant of the rails in the track towards the track centre, rad (1:40 -> atan(1/40));
            only its difference to the profile's own cant (``rail_profile_cant_rad``) is applied to the points.
        wheel_load_N: vertical load per wheel, N (force control), or None.
        approach_m: deepest approach per wheel, m (approach control), or None. Exactly one of the two.
        rolling_speed_m_per_s: V, forward speed of the wheelset, m/s.
        roll_rad: prescribed roll angle theta (per-wheel kinematics, module docstring), rad; None: solved.
        pitch_rate_rad_per_s: prescribed angular velocity of the wheelset about its axle, rad/s, with CONTACT's
            sign (forward rolling is negative; phi' = -pitch rate); None: option ``spin_rate``.
        wheel_profile_left, rail_profile_left: the left wheel's and rail's profiles when they differ from the
            right ones (None: the right ones, mirrored).
        rail_profile_cant_rad: cant already contained in the rail profile's points, rad; None: the profile's own
            (built-in profiles know theirs, e.g. MBench_UIC60_v3 1:40; a file has 0 unless stated here).
        profile_smoothing_m: smoothing wavelength L_filt of the profile splines, m (default 2 mm; 0 interpolates).
        rail_profile_smoothing_m: the rails' L_filt when it differs from the wheels' (CONTACT smooths each profile
            with its own SMOOTH: its wheelflat example the wheel with 5 mm, the rail not at all), m; None:
            profile_smoothing_m.
        wheel_profile_mirror_y, wheel_profile_mirror_z, rail_profile_mirror_y, rail_profile_mirror_z: turn a
            profile file of another orientation into the internal one (y towards the field side, z down), as
            CONTACT's MIRRORY / MIRRORZ.
        wheel_rotation_rad: phi, the wheels' rotation angle about the axle (eq 1; the pose's ``spin_rad``), rad:
            the wheel's material angle alpha (eq 7) at its lowest point is pi/2 - phi, so an irregularity centred
            at alpha_0 is at the contact when phi = pi/2 - alpha_0. Moves nothing on a round wheel.
        wheel_irregularities_right, wheel_irregularities_left: out-of-roundness of each wheel, a tuple of
            rigid_dynamics.geometry wheel irregularities (``HarmonicOutOfRoundness``, ``WheelFlat``,
            ``MeasuredWheelIrregularity``: anything with ``evaluate(angle_rad, y_m)``); () is a round wheel.
        track_distance_m: the wheelset's position along the track, m (CONTACT's S_WS): the place of a friction law
            that varies along the track (every patch's ``track_distance_m``); moves nothing else.
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
    track_distance_m: float = 0.0
    wheel_load_N: float | None = None
    approach_m: float | None = None
    rolling_speed_m_per_s: float = 1.0
    roll_rad: float | None = None
    pitch_rate_rad_per_s: float | None = None
    wheel_profile_left: str | None = None
    rail_profile_left: str | None = None
    rail_profile_cant_rad: float | None = None
    profile_smoothing_m: float = 0.002
    rail_profile_smoothing_m: float | None = None
    wheel_profile_mirror_y: bool = False
    wheel_profile_mirror_z: bool = False
    rail_profile_mirror_y: bool = False
    rail_profile_mirror_z: bool = False
    wheel_rotation_rad: float = 0.0
    wheel_irregularities_right: tuple = ()
    wheel_irregularities_left: tuple = ()

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
            "wheel_rotation_rad",
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
        for name in ("wheel_profile_left", "rail_profile_left"):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, str) or not value):
                raise ValueError(f"{name} = {value!r}: expected None, a built-in profile name or a file path")
        for name in (
            "wheel_profile_mirror_y",
            "wheel_profile_mirror_z",
            "rail_profile_mirror_y",
            "rail_profile_mirror_z",
        ):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected true or false")
        value = self.rail_profile_cant_rad
        if value is not None and (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
            or abs(value) >= 0.2
        ):
            raise ValueError(f"rail_profile_cant_rad = {value!r}: expected None or an angle with |angle| < 0.2 rad")
        for name in ("profile_smoothing_m", "rail_profile_smoothing_m"):
            value = getattr(self, name)
            if value is None and name == "rail_profile_smoothing_m":
                continue
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float))
                or not math.isfinite(value)
                or not 0 <= value <= 0.05
            ):
                raise ValueError(f"{name} = {value!r}: expected a length in [0, 0.05] m")
        if self.roll_rad is not None and (
            isinstance(self.roll_rad, bool)
            or not isinstance(self.roll_rad, (int, float))
            or not math.isfinite(self.roll_rad)
            or abs(self.roll_rad) > 0.1
        ):
            raise ValueError(f"roll_rad = {self.roll_rad!r}: expected None or a finite number with |roll| <= 0.1 rad")
        value = self.pitch_rate_rad_per_s
        if value is not None:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"pitch_rate_rad_per_s = {value!r}: expected None or a finite number")
            free = self.rolling_speed_m_per_s / self.nominal_radius_m
            if not -2.0 * free < value < -0.5 * free:
                raise ValueError(
                    f"pitch_rate_rad_per_s = {value!r}: expected forward rolling, between {-2 * free:.6g} and "
                    f"{-0.5 * free:.6g} rad/s (-V/r0 = {-free:.6g}; CONTACT's sign: negative forward)"
                )
        for name in ("wheel_load_N", "approach_m"):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0):
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        for name in ("wheel_irregularities_right", "wheel_irregularities_left"):
            value = getattr(self, name)
            if not isinstance(value, tuple) or not all(callable(getattr(v, "evaluate", None)) for v in value):
                raise ValueError(
                    f"{name} = {value!r}: expected a tuple of wheel irregularities (rigid_dynamics.geometry)"
                )

    @property
    def wheel_irregularities(self) -> dict:
        """Side -> the wheel's irregularities (only the sides that have some), as build_track takes them."""
        sides = {"right": self.wheel_irregularities_right, "left": self.wheel_irregularities_left}
        return {side: value for side, value in sides.items() if value}


@dataclass(frozen=True, eq=False)
class PatchSolution:
    """One solved patch: its side, geometry, creepages and the contact model's result.

    Attributes:
        side: "left" or "right".
        geometry: the patch geometry (reference point, contact frame, undeformed distance).
        creepage: creepages at the reference point.
        result: the model's result (forces on the wheel in the contact frame).
        combination: "single", "combined" or "blended" (several interpenetration regions in one patch;
            wheelset_patches), "search" (a search patch).
        deepest_point_rail_m: (y, z) in rail-profile coordinates of the largest vertical interpenetration, m
            (the reference point is ``geometry.contact_point_rail_m``).
    """

    side: str
    geometry: ContactGeometry
    creepage: Creepage
    result: ContactResult
    combination: str = "single"
    deepest_point_rail_m: tuple[float, float] = (math.nan, math.nan)

    @property
    def force_main_N(self) -> np.ndarray:
        """Contact force on the wheel in the main (track) frame, N, shape (3,).

        A model that gives no creep forces (None: frictionless, e.g. ``fea``) transmits no tangential force: 0.
        """
        r = self.result
        fx, fy = (0.0 if v is None else v for v in (r.creep_force_long_N, r.creep_force_lat_N))
        local = np.array([fx, fy, r.normal_force_N], float)
        return self.geometry.frame @ local

    @property
    def vertical_force_N(self) -> float:
        """Upward load carried by this patch, creep forces included, N (main z points down)."""
        return float(-self.force_main_N[2])


@dataclass(frozen=True, eq=False)
class WheelsetCaseSolution:
    """Solution of a :class:`WheelsetCase`.

    Attributes:
        success, status, message: status "ok", "not-converged" (equilibrium iteration), "no-contact",
            "search-failed" or "model-failed" (a patch's model did not succeed; see its result).
        wall_time_s: s.
        vertical_position_m: z of the wheelset centre (main frame, z down), m; per-wheel kinematics: the mean of
            the two wheels' (see ``wheel_vertical_position_m``).
        roll_rad: theta, rad.
        patches: all patches, left first, along the axle per side.
        wheel_vertical_load_N: side -> total vertical contact force on the wheel, creep forces included, N.
        wheel_force_N: side -> total contact force on the wheel in the main frame (x, y, z; z down), N.
        wheel_vertical_position_m: side -> z of the wheelset centre at which that wheel is in equilibrium, m.
        iterations: equilibrium iterations in all (model evaluations of the wheels).
        kinematics: "equilibrium" (z and roll solved) or "per-wheel" (roll prescribed).
        spin_rate_rad_per_s: phi' used, rad/s. spin_rate_mode: "prescribed" or the ``spin_rate`` option.
        axle_moment_Nm: moment of all contact forces on the wheelset about its axle (y_d), N m.
        equilibrium_residual: max over the wheels of |vertical load / wheel_load_N - 1|; nan under approach control.
        load_tolerance: the relative tolerance the residual was accepted at (the largest over the wheels of
            ``force_tolerance`` and the patches' stated force error, see ``_load_tolerance``); nan under approach
            control.
        pose: the final :class:`WheelsetPose` (per-wheel kinematics: the last solved wheel's).
        Per-wheel kinematics with option ``sides`` solves only those wheels: the dicts hold only them.
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
    kinematics: str = "equilibrium"
    spin_rate_rad_per_s: float = math.nan
    spin_rate_mode: str = "prescribed"
    axle_moment_Nm: float = math.nan
    equilibrium_residual: float = math.nan
    load_tolerance: float = math.nan
    wheel_force_N: dict = field(default_factory=dict)
    wheel_vertical_position_m: dict = field(default_factory=dict)
    pose: WheelsetPose | None = None
    extra: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class _WheelState:
    """One wheel evaluated at one pose: its solved patches and sums."""

    side: str
    pose: WheelsetPose
    patches: list[PatchSolution]
    min_gap_m: float
    vertical_load_N: float
    force_N: np.ndarray
    axle_moment_Nm: float
    max_approach_m: float
    failed: list[str]


def _creepage(
    case: WheelsetCase, pose: WheelsetPose, point_m, normal, omega_spin: float, rolling_speed: str = "mean"
) -> Creepage:
    """Creepages of the wheel's material point ``point_m`` (main frame) with the patch normal (eq 39-49).

    ``rolling_speed = "centre"``: divided by V = |v_p| of the wheelset centre (eq 41). ``"mean"`` (Kalker's and
    CONTACT's definition): divided by the mean of the two bodies' rolling speeds through the contact, the rail's V
    and the wheel's V (1 - xi), i.e. V (2 - xi)/2 with xi the eq-41 creepage; the slip velocities are the same,
    the creepages differ by the factor 2 / (2 - xi) (1.2 % at a flange contact that rolls 2.4 % faster than r0).
    """
    x_d = pose.rotation.T @ (np.asarray(point_m, float) - pose.centre_m)
    kin = wheelset_creepage(
        x_d,
        normal,
        yaw_rad=case.yaw_rad,
        roll_rad=pose.roll_rad,
        spin_angle_rad=pose.spin_rad,
        centre_velocity_m_per_s=[case.rolling_speed_m_per_s, 0.0, 0.0],
        spin_rate_rad_per_s=omega_spin,
    )
    creepage = kin.creepage()
    if rolling_speed == "centre":
        return creepage
    factor = 2.0 / (2.0 - creepage.longitudinal)
    return Creepage(
        longitudinal=creepage.longitudinal * factor,
        lateral=creepage.lateral * factor,
        spin_1_per_m=creepage.spin_1_per_m * factor,
        rolling_speed_m_per_s=creepage.rolling_speed_m_per_s / factor,
    )


FIELD_MODELS = ("bem", "fea")
"""Models that solve the sampled undeformed distance itself (joined patches are theirs; module docstring)."""


def _solves_undeformed_distance(model) -> bool:
    return bool(getattr(model, "solves_undeformed_distance", getattr(model, "name", "") in FIELD_MODELS))


class _Evaluator:
    """Patches, model solutions and sums of one wheel at a pose (counting the evaluations)."""

    def __init__(self, case, material, model, track, opts, progress=None):
        self.case, self.material, self.model, self.track, self.opts = case, material, model, track, opts
        # a model that estimates its grid error (bem) does so for the final patches only (final_patches)
        self.estimates = hasattr(model, "with_grid_error")
        self.progress = progress
        self.model_options = opts["model"]  # switched to a coarse mesh's during a first pass (the FEA)
        self.side_grids: dict[str, dict] = {}  # per side, the grid its final patches were refined to (bem)
        self.phase = ""
        self.count = 0
        self.started = time.perf_counter()

    def final_patches(self, patches: list) -> list:
        """The equilibrium's patches with the model's grid-error estimate (bem; the numbers are unchanged)."""
        if not self.estimates:
            return patches
        return [
            dataclasses.replace(
                p,
                result=self.model.with_grid_error(
                    p.geometry, p.creepage, self.material, p.result, options=self._options(p.side)
                ),
            )
            for p in patches
        ]

    def _options(self, side: str) -> dict:
        """The model's options for one side's patches (with the grid its final patches were refined to)."""
        return {**(self.model_options or {}), **self.side_grids.get(side, {})}

    def refined_grids(self, patches: list) -> dict[str, dict]:
        """Per side, the grid (``nx``, ``ny`` over the potential area) at which the model's own refinement meets its
        ``grid_tolerance`` on every final patch of that side, for the sides where the equilibrium's default grid
        does not (bem; {} when the caller named a grid or the model refines nothing). Each patch is solved once more
        with the model's refinement at its equilibrium pose; the equilibrium is then rebalanced on these grids.
        """
        from rigid_dynamics.contact.bem.model import GRID_OPTIONS

        options = self.opts["model"] or {}
        if not self.estimates or any(k in options for k in GRID_OPTIONS):
            return {}
        grids: dict[str, dict] = {}
        for p in patches:
            if not p.result.success or p.result.status == "no-contact" or "nx" not in p.result.extra:
                continue
            refined = self.model.solve(p.geometry, p.creepage, self.material, normal_force_N=None, options=options)
            nx, ny = refined.extra.get("nx", 0), refined.extra.get("ny", 0)
            if nx > p.result.extra["nx"] or ny > p.result.extra["ny"]:
                old = grids.get(p.side, {"nx": 0, "ny": 0})
                grids[p.side] = {"nx": max(old["nx"], int(nx)), "ny": max(old["ny"], int(ny))}
        return grids

    def geometry(self, pose: WheelsetPose, side: str):
        """(list of (geometry, combination, deepest rail point)), smallest gap (vertical or normal), m."""
        track, opts = self.track, self.opts
        if opts["patches"] == "search":
            search_options = dict(opts["search"] or {})
            result = track.search(pose, side, search_options)
            return [(g, "search", g.contact_point_rail_m, g.point_m) for g in result.patches], result.min_gap_m
        from rigid_dynamics.contact.wheelset_patches import wheel_patches

        wheel, rail = track.fast[side]
        patch_options = dict(opts["patch"] or {})
        if not _solves_undeformed_distance(self.model):
            # regions are joined only for a model that solves the joined gap (bem, fea); the analytic rungs take
            # each interpenetration region as its own patch (a joined patch is no ellipse)
            patch_options["distance_separation_m"] = 0.0
            patch_options["distance_turning_m"] = 0.0  # and each keeps its own plane (no turning)
        patches, locus = wheel_patches(
            wheel, rail, pose, side, wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m,
            nominal_radius_m=track.nominal_radius_m, options=patch_options,
        )  # fmt: skip
        finite = locus.gap_m[np.isfinite(locus.gap_m)]
        min_gap = float(finite.min()) if finite.size else math.inf
        return [(p.geometry, p.combination, p.deepest_point_rail_m, p.wheel_point_m) for p in patches], min_gap

    def min_gap(self, pose: WheelsetPose, side: str) -> float:
        """Smallest gap of one wheel (vertical, from the contact locus; the search's normal gap for "search")."""
        if self.opts["patches"] == "search":
            return self.geometry(pose, side)[1]
        from rigid_dynamics.contact.search import _SideGeometry
        from rigid_dynamics.contact.wheelset_patches import DEFAULT_PATCH_OPTIONS, contact_locus

        wheel, rail = self.track.fast[side]
        geo = _SideGeometry(wheel, rail, pose, side, wheel.y_range_m, rail.y_range_m)
        step = (self.opts["patch"] or {}).get("locus_step_m", DEFAULT_PATCH_OPTIONS["locus_step_m"])
        gap = contact_locus(geo, step).gap_m
        finite = gap[np.isfinite(gap)]
        return float(finite.min()) if finite.size else math.inf

    def wheel(self, pose: WheelsetPose, side: str, omega: float) -> _WheelState:
        self.count += 1
        geometries, min_gap = self.geometry(pose, side)
        patches, failed = [], []
        for k, (geometry, how, deepest, material_point) in enumerate(geometries):
            if self.opts["creepage_point"] == "approach":
                # CONTACT's Q: the approach q from the rail's reference point along the normal, towards the wheel's
                # overlapping side (where the wheel's surface point lies, at the local interpenetration d <= q)
                normal = np.asarray(geometry.frame[:, 2], float)
                material_point = np.asarray(geometry.point_m, float) - float(geometry.approach_m) * normal
            creepage = _creepage(
                self.case, pose, material_point, geometry.frame[:, 2], omega, self.opts["rolling_speed"]
            )
            options = self._options(side)
            if self.estimates:
                options = {**(options or {}), "estimate_grid_error": False}
            if self.case.track_distance_m != 0.0:
                geometry = dataclasses.replace(geometry, track_distance_m=float(self.case.track_distance_m))
            if self.opts["friction_place"] == "element" and self.material.friction is not None:
                rail = self.track.fast[side][1]
                geometry = dataclasses.replace(geometry, friction_place=friction_place_of(geometry, rail, side))
            result = self.model.solve(geometry, creepage, self.material, normal_force_N=None, options=options)
            if not result.success:
                failed.append(f"{side} patch {k}: {result.message}")
            patches.append(PatchSolution(side, geometry, creepage, result, how, tuple(deepest)))
        force = np.zeros(3)
        moment = 0.0
        axle = pose.rotation[:, 1]
        for p in patches:
            f = p.force_main_N if math.isfinite(p.result.normal_force_N) else np.zeros(3)
            force += f
            moment += float(np.cross(p.geometry.point_m - pose.centre_m, f) @ axle)
        approach = max((p.geometry.approach_m for p in patches), default=-min_gap)
        state = _WheelState(side, pose, patches, min_gap, float(-force[2]), force, moment, approach, failed)
        if self.progress is not None:
            target = self.case.wheel_load_N
            load = f"vertical load {state.vertical_load_N:.6g} N" + (f" (target {target:.6g} N)" if target else "")
            self.progress(
                f"wheel evaluation {self.count}{self.phase}: {side} wheel, {len(patches)} patch(es), {load}, "
                f"tolerance {_load_tolerance(state, self.opts):.3g}, {time.perf_counter() - self.started:.1f} s"
            )
        return state


def _load_tolerance(state: _WheelState, opts) -> float:
    """Relative tolerance on a wheel's vertical load: ``force_tolerance``, or the stated relative error of the
    patches' normal forces (force-weighted; ``extra["discretisation_error"]["relative_error"]["normal_force"]`` of
    a model that states it, the FEA) when that is larger: converging the load beyond what the forces are known to
    chases the mesh's scatter (the FEA's remeshed force scattered by about 3 % against a tolerance of 1e-6).
    """
    weighted = total = 0.0
    for p in state.patches:
        info = p.result.extra.get("discretisation_error") or {}
        error = (info.get("relative_error") or {}).get("normal_force")
        if info.get("load_tolerance") is not None:
            error = info["load_tolerance"]  # a load-balanced solve states the load error its p and area afford
        force = abs(p.result.normal_force_N)
        if error is not None and math.isfinite(error) and math.isfinite(force):
            weighted += error * force
            total += force
    return max(opts["force_tolerance"], weighted / total if total > 0 else 0.0)


def _phi(state: _WheelState, target: float) -> float:
    return (max(state.vertical_load_N, 0.0) / target) ** (2.0 / 3.0) - 1.0


def _solve_one_wheel(evaluator: _Evaluator, pose_of, side: str, omega: float, q_ref: float, start, opts):
    """Per-wheel kinematics: the sink s of one wheel (pose_of(s)) carrying the load (or the approach)."""
    case = evaluator.case
    target = case.wheel_load_N
    tolerance = opts["force_tolerance"]
    # rigid touch: the smallest gap moves one-to-one with the vertical position (exact for the vertical gap)
    if start is None:
        s = 0.0
        for _ in range(6):
            gap = evaluator.min_gap(pose_of(s), side)
            if not math.isfinite(gap):
                return None, 0, "search-failed"
            s += gap
            if abs(gap) < 1e-12:
                break
        s_touch = s
        s = s_touch + (q_ref if target is not None else case.approach_m)
    else:
        s_touch, s = start
    previous = low = high = None
    state = None
    for iteration in range(1, opts["max_iterations"] + 1):
        state = evaluator.wheel(pose_of(s), side, omega)
        if state.failed:
            return (state, (s_touch, s)), iteration, "model-failed"
        if target is not None:
            if not state.patches:
                r = -state.min_gap_m / q_ref - 1.0
                done = False
            else:
                r = _phi(state, target)
                done = abs(state.vertical_load_N / target - 1.0) < max(tolerance, _load_tolerance(state, opts))
        else:
            r = state.max_approach_m / case.approach_m - 1.0 if state.patches else -state.min_gap_m / q_ref - 1.0
            done = state.patches and abs(state.max_approach_m - case.approach_m) < opts["approach_tolerance_m"]
        if done:
            return (state, (s_touch, s)), iteration, "ok"
        # bracket of the root (phi rises with the sink): safeguarded secant (bisection when it leaves the bracket)
        if r < 0:
            low = (s, r) if low is None or s > low[0] else low
        else:
            high = (s, r) if high is None or s < high[0] else high
        if previous is None or previous[1] == r:
            # phi ~ (s - s_touch)/(s* - s_touch) - 1 for a Hertzian wheel: scale the sink below the touch
            step = -r * max(s - s_touch, 0.2 * q_ref)
        else:
            step = -r * (s - previous[0]) / (r - previous[1])
        previous = (s, r)
        step = float(np.clip(step, -5.0 * q_ref, 5.0 * q_ref))
        new = s + step
        if low is not None and high is not None and not low[0] < new < high[0]:
            new = 0.5 * (low[0] + high[0])
        step, s = new - s, new
        if abs(step) < 1e-15:
            return (state, (s_touch, s)), iteration, "ok" if target is None else "not-converged"
    return (state, (s_touch, s)), opts["max_iterations"], "not-converged"


def _spin_rate_estimate(case: WheelsetCase, states, mode: str) -> float:
    if mode != "mean-rolling-radius" or not states:
        return case.rolling_speed_m_per_s / case.nominal_radius_m
    radii = []
    for state in states:
        if state.patches:
            main = max(state.patches, key=lambda p: p.result.normal_force_N)
            radii.append(main.geometry.rolling_radius_m)
    radius = float(np.mean(radii)) if radii else case.nominal_radius_m
    return case.rolling_speed_m_per_s / radius


def solve_wheelset_case(
    case: WheelsetCase,
    material: Material,
    model="hertz",
    options: Mapping | None = None,
    *,
    track=None,
    progress=None,
) -> WheelsetCaseSolution:
    """Find the wheelset's vertical position (and roll) carrying the load and solve every patch (module docstring).

    Args:
        case: the case.
        material: elastic constants and friction of the pair.
        model: contact model name (registry) or instance; it gives the forces of the equilibrium too.
        options: ``DEFAULT_CASE_OPTIONS`` keys.
        track: optional pre-built :class:`~rigid_dynamics.contact.track.WheelsetTrack` (else built from the case).
        progress: optional callable taking one line of text per wheel evaluation (the evaluation count, side,
            vertical load against the target, the load tolerance in force, elapsed time), e.g. for a progress line
            on stderr while a slow model (the FEA) works; library code never prints itself.

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
    if opts["spin_rate"] not in SPIN_RATES:
        raise ValueError(f"spin_rate = {opts['spin_rate']!r}: expected one of {', '.join(map(repr, SPIN_RATES))}")
    if opts["rolling_speed"] not in ("mean", "centre"):
        raise ValueError(f"rolling_speed = {opts['rolling_speed']!r}: expected 'mean' or 'centre'")
    if opts["creepage_point"] not in CREEPAGE_POINTS:
        raise ValueError(
            f"creepage_point = {opts['creepage_point']!r}: expected one of {', '.join(map(repr, CREEPAGE_POINTS))}"
        )
    if opts["creepage_point"] == "approach" and opts["patches"] != "contact":
        raise ValueError(
            f"creepage_point = 'approach' with patches = {opts['patches']!r}: expected patches 'contact' (the "
            "approach point is CONTACT's module-1 definition)"
        )
    if opts["patches"] not in PATCH_MODES:
        raise ValueError(f"patches = {opts['patches']!r}: expected one of {', '.join(map(repr, PATCH_MODES))}")
    for name in ("max_iterations",):
        value = opts[name]
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{name} = {value!r}: expected an integer >= 1")
    for name in ("force_tolerance", "approach_tolerance_m", "axle_moment_tolerance"):
        value = opts[name]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    sides = tuple(opts["sides"]) if isinstance(opts["sides"], (tuple, list)) else (opts["sides"],)
    if not sides or any(side not in SIDES for side in sides) or len(set(sides)) != len(sides):
        raise ValueError(f"sides = {opts['sides']!r}: expected a non-empty selection of 'left', 'right'")
    if case.roll_rad is None and len(sides) != 2:
        raise ValueError(f"sides = {opts['sides']!r}: the whole-wheelset equilibrium (roll_rad None) needs both wheels")
    contact_model = get_model(model)
    if track is None:
        track = build_track(case, wheel_irregularities=case.wheel_irregularities)
    if opts["patches"] == "contact" and opts["patch"]:
        from rigid_dynamics.contact.wheelset_patches import DEFAULT_PATCH_OPTIONS

        for key in opts["patch"]:
            if key not in DEFAULT_PATCH_OPTIONS:
                raise ValueError(f"patch option {key!r}: expected one of {', '.join(DEFAULT_PATCH_OPTIONS)}")
    evaluator = _Evaluator(case, material, contact_model, track, opts, progress)
    q_ref = track.reference_approach_m(case, material)
    per_wheel = case.roll_rad is not None

    def solve_pose(omega, warm):
        """Equilibrium at spin rate omega: (states per side, warm-start data, iterations, status)."""
        if per_wheel:
            states, starts, total, status = {}, {}, 0, "ok"
            for side in sides:

                def pose_of(s):
                    return WheelsetPose(
                        y_m=case.lateral_shift_m, z_m=track.rest_z_m + s, yaw_rad=case.yaw_rad,
                        roll_rad=case.roll_rad, spin_rad=case.wheel_rotation_rad,
                    )  # fmt: skip

                out, its, st = _solve_one_wheel(evaluator, pose_of, side, omega, q_ref, (warm or {}).get(side), opts)
                total += its
                if out is None:
                    return None, None, total, st
                states[side], starts[side] = out
                if st != "ok" and status == "ok":
                    status = st
            return states, starts, total, status
        return _solve_whole(evaluator, track, case, omega, q_ref, warm, opts)

    mode = "prescribed" if case.pitch_rate_rad_per_s is not None else opts["spin_rate"]
    if mode == "prescribed":
        omega = -float(case.pitch_rate_rad_per_s)
    else:
        omega = case.rolling_speed_m_per_s / case.nominal_radius_m
    coarse = getattr(contact_model, "coarse_options", None)
    coarse = coarse(opts["model"]) if coarse is not None and case.wheel_load_N is not None else None
    if coarse is not None:
        # a model whose every solve refines its own mesh (the FEA): the equilibrium first on its coarsest mesh,
        # then from there with the full solve (usually accepted at once within its stated force error)
        evaluator.model_options, evaluator.phase = coarse, " (coarse mesh)"
        tolerance = opts["force_tolerance"]
        opts["force_tolerance"] = max(tolerance, COARSE_FORCE_TOLERANCE)
        states, warm, iterations, status = solve_pose(omega, None)
        balanced = getattr(contact_model, "load_balanced_options", None)
        evaluator.model_options = balanced(opts["model"]) if balanced is not None else opts["model"]
        evaluator.phase = ""
        opts["force_tolerance"] = tolerance
        if states is not None and status == "ok":
            states, warm, its, status = solve_pose(omega, warm)
            iterations += its
    else:
        states, warm, iterations, status = solve_pose(omega, None)
        if states is not None and status == "ok":
            # a model that estimates its grid error (bem): the final patches refined to its grid_tolerance, and
            # the equilibrium rebalanced on those grids from the default grid's (the forces move with the grid)
            grids = evaluator.refined_grids([p for side in sides for p in states[side].patches])
            if grids:
                evaluator.side_grids, evaluator.phase = grids, " (refined grid)"
                states, warm, its, status = solve_pose(omega, warm)
                iterations += its
    if states is not None and status == "ok" and mode == "mean-rolling-radius":
        omega = _spin_rate_estimate(case, list(states.values()), mode)
        states, warm, its, status = solve_pose(omega, warm)
        iterations += its
    elif states is not None and status == "ok" and mode == "zero-axle-moment":
        scale = case.rolling_speed_m_per_s * (case.wheel_load_N or 1.0e4) * case.nominal_radius_m
        previous = None
        for _ in range(12):
            creep = [p.result.creep_force_long_N for st in states.values() for p in st.patches]
            if not any(c is not None and c != 0.0 for c in creep):
                break  # no creep forces (hertz, frictionless fea): the pitch rate changes nothing; V / r0 is kept
            moment = sum(s.axle_moment_Nm for s in states.values())
            if abs(moment) <= opts["axle_moment_tolerance"] * scale / case.rolling_speed_m_per_s:
                break
            if previous is None or previous[1] == moment:
                new_omega = omega * (1.0 + 1e-4)
            else:
                new_omega = omega - moment * (omega - previous[0]) / (moment - previous[1])
            previous = (omega, moment)
            omega = float(np.clip(new_omega, 0.9 * omega, 1.1 * omega))
            states, warm, its, status = solve_pose(omega, warm)
            iterations += its
            if states is None or status != "ok":
                break
        else:
            status = "not-converged"

    messages = {
        "ok": "equilibrium found",
        "search-failed": "the wheel misses its rail (no finite gap on one side)",
        "not-converged": "equilibrium iteration did not converge",
        "model-failed": "a patch's model failed",
    }
    if states is None:
        return WheelsetCaseSolution(
            False, status, messages.get(status, status), time.perf_counter() - started, math.nan, math.nan, [], {},
            iterations, "per-wheel" if per_wheel else "equilibrium", omega, mode,
        )  # fmt: skip
    patches = evaluator.final_patches([p for side in sides for p in states[side].patches])
    failed = [f for side in sides for f in states[side].failed]
    message = messages.get(status, status)
    if failed:
        status, message = "model-failed", "; ".join(failed)
    elif status == "ok" and not patches:
        status, message = "no-contact", "no patch found"
    elif status == "ok":
        message = f"equilibrium found in {iterations} wheel evaluations"
        if evaluator.side_grids:
            refined = ", ".join(f"{side} {g['nx']} x {g['ny']}" for side, g in evaluator.side_grids.items())
            message += f" (rebalanced on the grids its patches were refined to: {refined})"
    target = case.wheel_load_N
    loads = {side: states[side].vertical_load_N for side in sides}
    residual = max(abs(loads[side] / target - 1.0) for side in sides) if target is not None else math.nan
    z = {side: states[side].pose.z_m for side in sides}
    pose = states[sides[-1]].pose
    return WheelsetCaseSolution(
        success=status == "ok",
        status=status,
        message=message,
        wall_time_s=time.perf_counter() - started,
        vertical_position_m=float(np.mean(list(z.values()))),
        roll_rad=pose.roll_rad,
        patches=patches,
        wheel_vertical_load_N=loads,
        iterations=iterations,
        kinematics="per-wheel" if per_wheel else "equilibrium",
        spin_rate_rad_per_s=float(omega),
        spin_rate_mode=mode,
        axle_moment_Nm=float(sum(s.axle_moment_Nm for s in states.values())),
        equilibrium_residual=float(residual),
        load_tolerance=max(_load_tolerance(states[side], opts) for side in sides) if target is not None else math.nan,
        wheel_force_N={side: states[side].force_N.copy() for side in sides},
        wheel_vertical_position_m=z,
        pose=pose,
    )


def _solve_whole(evaluator, track, case, omega, q_ref, warm, opts):
    """Whole-wheelset equilibrium: sinks (s_L, s_R) so that both wheels carry the load (Broyden's method)."""
    target = case.wheel_load_N

    def pose_of(sinks):
        return _pose(track, case.lateral_shift_m, case.yaw_rad, sinks, case.wheel_rotation_rad)

    iterations = 0
    if warm is None:
        # rigid touch of both wheels (smallest gap 0 per side): Newton with a finite-difference Jacobian

        def gaps(sinks):
            return np.array([evaluator.min_gap(pose_of(sinks), side) for side in SIDES])

        sinks = np.zeros(2)
        for _ in range(opts["max_iterations"]):
            g = gaps(sinks)
            if not np.all(np.isfinite(g)):
                return None, None, iterations, "search-failed"
            if np.all(np.abs(g) < 1e-11):
                break
            jac = np.zeros((2, 2))
            for j in range(2):
                ds = np.zeros(2)
                ds[j] = 1e-6
                jac[:, j] = (gaps(sinks + ds) - g) / 1e-6
            try:
                delta = np.linalg.solve(jac, -g)
            except np.linalg.LinAlgError:
                return None, None, iterations, "not-converged"
            sinks = sinks + np.clip(delta, -2e-3, 2e-3)
        touch = sinks.copy()
        depth = q_ref if target is not None else case.approach_m
        sinks = touch + depth
        jac = np.eye(2) / depth
    else:
        touch, sinks, jac = warm

    def residual(states):
        out = np.zeros(2)
        for i, side in enumerate(SIDES):
            st = states[side]
            if not st.patches:
                out[i] = -st.min_gap_m / q_ref - 1.0
            elif target is not None:
                out[i] = _phi(st, target)
            else:
                out[i] = st.max_approach_m / case.approach_m - 1.0
        return out

    def done(states):
        if not all(states[side].patches for side in SIDES):
            return False
        if target is not None:
            return all(abs(states[s].vertical_load_N / target - 1.0) < _load_tolerance(states[s], opts) for s in SIDES)
        return all(abs(states[s].max_approach_m - case.approach_m) < opts["approach_tolerance_m"] for s in SIDES)

    previous = None
    states = None
    for _ in range(opts["max_iterations"]):
        pose = pose_of(sinks)
        states = {side: evaluator.wheel(pose, side, omega) for side in SIDES}
        iterations += 2
        if any(states[s].failed for s in SIDES):
            return states, (touch, sinks, jac), iterations, "model-failed"
        r = residual(states)
        if done(states):
            return states, (touch, sinks, jac), iterations, "ok"
        if previous is not None:
            d_s, d_r = sinks - previous[0], r - previous[1]
            denom = float(d_s @ d_s)
            if denom > 0:
                jac = jac + np.outer(d_r - jac @ d_s, d_s) / denom
        try:
            delta = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            delta = -r * q_ref
        previous = (sinks.copy(), r)
        sinks = sinks + np.clip(np.nan_to_num(delta), -5.0 * q_ref, 5.0 * q_ref)
    return states, (touch, sinks, jac), iterations, "not-converged"


def _pose(track, lateral_shift_m: float, yaw_rad: float, sinks, spin_rad: float = 0.0) -> WheelsetPose:
    """Pose from the two wheel sinks: z = z_rest + (s_L + s_R)/2, theta = (s_R - s_L)/(2 e_w); phi = spin_rad."""
    z = track.rest_z_m + 0.5 * (sinks[0] + sinks[1])
    roll = (sinks[1] - sinks[0]) / (2.0 * track.half_wheel_distance_m)
    return WheelsetPose(y_m=lateral_shift_m, z_m=float(z), yaw_rad=yaw_rad, roll_rad=float(roll), spin_rad=spin_rad)


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
