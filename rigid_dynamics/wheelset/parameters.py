"""Parameters of a wheelset dynamics run, as frozen dataclasses with SI units in the field names.

Every field is a plain type (float, int, str, bool) or a nested frozen dataclass, so a TOML scene
maps onto :class:`DynamicsScene` table by table, field by field. Invalid values raise ``ValueError``
naming the field, its value and what was expected.

Frames (fixed by the project): main (track) frame x along the track in the direction of travel,
y lateral to the right, z vertically downward; gravity is +g e_z; the left rail is at y < 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

from rigid_dynamics.materials import STEEL, Material
from rigid_dynamics.wheelset.fields import check_finite
from rigid_dynamics.wheelset.track import TrackDynamics
from rigid_dynamics.wheelset.traction import TractionControl

CONTACT_PROVIDERS = ("auto", "conical", "tables", "search")
"""Names of the contact-geometry providers (see :mod:`rigid_dynamics.wheelset.providers`)."""

PATCH_GEOMETRIES = ("sampled", "ellipse", "formed")
"""What a gap-solving contact model sees per patch in dynamics (DynamicsScene.patch_geometry)."""

INTEGRATORS = ("RK45", "DOP853", "Radau", "BDF", "LSODA", "RK4", "DP54", "BS32")
"""scipy.integrate.solve_ivp methods plus the fixed-step classical Runge-Kutta method ``RK4``."""

IRREGULARITY_SIDES = ("both", "left", "right")


@dataclass(frozen=True)
class WheelsetParameters:
    """Rigid wheelset: mass, inertia and the nominal wheel/contact geometry.

    Defaults: the wheelset of the Manchester benchmark vehicle (S. Iwnicki, "Manchester benchmarks
    for rail vehicle simulation", Vehicle System Dynamics 30 (1998) 295-313): m = 1813 kg,
    I_xx = I_zz = 1120 kg m^2, I_yy = 112 kg m^2, wheel radius 0.46 m, half distance between the
    nominal contact points 0.75 m.

    Attributes:
        mass_kg: m, wheelset mass, kg.
        transverse_inertia_kg_m2: J_t, moment of inertia about any axis through the centre of mass
            perpendicular to the axle (roll and yaw), kg m^2.
        axle_inertia_kg_m2: J_a, moment of inertia about the axle, kg m^2.
        nominal_radius_m: r0, rolling radius at the nominal contact point (tape circle), m.
        contact_half_distance_m: e0, half the lateral distance between the nominal contact points, m.
        suspension_half_spacing_m: b_s, lateral distance from the centre to the primary suspension
            attachment on each side (springs act at y_d = +-b_s on the axle), m.
    """

    mass_kg: float = 1813.0
    transverse_inertia_kg_m2: float = 1120.0
    axle_inertia_kg_m2: float = 112.0
    nominal_radius_m: float = 0.46
    contact_half_distance_m: float = 0.75
    suspension_half_spacing_m: float = 1.0

    def __post_init__(self) -> None:
        check_finite(self, positive=[f.name for f in fields(self)])


MAX_FRAME_YAW_RAD = 0.1
"""SuspensionParameters.frame_yaw_rad's bound: a bogie's angle of attack is tens of mrad (a/R: 2.5 m wheelbase, 25 m
radius: 50 mrad)."""


@dataclass(frozen=True)
class SuspensionParameters:
    """Primary suspension between the axle and a frame moving at constant speed along the track.

    Per side, three linear springs and dampers act between the axle point y_d = +-b_s (wheelset
    frame) and the frame point above it (main-frame directions x, y, z), plus a torsional yaw
    spring/damper about z per side. The frame moves at the scene speed along x and stays at y = 0
    and at the nominal centre height. The force on the wheelset of side s is
    F = -k (x_axle - x_frame) - c (v_axle - v_frame), per direction.

    Attributes:
        longitudinal_stiffness_N_per_m, lateral_stiffness_N_per_m, vertical_stiffness_N_per_m: k per side, N/m.
        longitudinal_damping_N_s_per_m, lateral_damping_N_s_per_m, vertical_damping_N_s_per_m: c per side, N s/m.
        yaw_stiffness_N_m_per_rad: torsional yaw stiffness per side, N m/rad.
        yaw_damping_N_m_s_per_rad: torsional yaw damping per side, N m s/rad.
        frame_yaw_rad: the frame's yaw about z against the track (in a curve against the radial direction through
            the frame), held through the run, rad: the frame points of side s sit at (x_frame - s b sin, s b cos)
            and the torsional springs act on the wheelset's yaw less it. A bogie frame's angle at one of its axles:
            the leading axle of a bogie of semi-wheelbase a, the frame tangent to a curve of radius R, is held
            about a/R under-radial (negative in a right-hand curve, positive in a left-hand one: the angle of
            attack of flange climbing). 0: the frame follows the track (or the curve's radial).
    """

    longitudinal_stiffness_N_per_m: float = 0.0
    lateral_stiffness_N_per_m: float = 0.0
    vertical_stiffness_N_per_m: float = 0.0
    longitudinal_damping_N_s_per_m: float = 0.0
    lateral_damping_N_s_per_m: float = 0.0
    vertical_damping_N_s_per_m: float = 0.0
    yaw_stiffness_N_m_per_rad: float = 0.0
    yaw_damping_N_m_s_per_rad: float = 0.0
    frame_yaw_rad: float = 0.0

    def __post_init__(self) -> None:
        check_finite(self, nonnegative=[f.name for f in fields(self) if f.name != "frame_yaw_rad"])
        if not abs(self.frame_yaw_rad) <= MAX_FRAME_YAW_RAD:
            raise ValueError(
                f"frame_yaw_rad = {self.frame_yaw_rad!r}: expected |value| <= {MAX_FRAME_YAW_RAD} (a bogie's angle of "
                "attack: tens of mrad)"
            )

    @property
    def is_damped(self) -> bool:
        """True when any damper is present."""
        return any(getattr(self, f.name) > 0 for f in fields(self) if "damping" in f.name)


@dataclass(frozen=True)
class LoadParameters:
    """Constant exterior loads on the wheelset (eq 63-64).

    Attributes:
        axle_load_N: vertical force of the vehicle on the axle (without the wheelset's own weight),
            acting downward (+z) at the centre, N.
        traction_torque_N_m: torque about the axle driving forward rolling (> 0 traction, < 0 braking), N m.
    """

    axle_load_N: float = 160.0e3
    traction_torque_N_m: float = 0.0

    def __post_init__(self) -> None:
        check_finite(self, nonnegative=["axle_load_N"])


@dataclass(frozen=True)
class TrackGeometry:
    """Wheel and rail profiles and their placement.

    ``wheel_profile`` = "conical" with ``rail_profile`` = "circular" selects the analytic conical
    provider (exactly linear rolling-radius difference, see providers.ConicalProvider); other names
    are built-in profiles or profile files read by rigid_dynamics.geometry.

    Attributes:
        wheel_profile: wheel profile name or file ("conical", "S1002", path).
        rail_profile: rail profile name or file ("circular", "UIC60", path).
        conicity: lambda, cone slope of the conical wheel (dimensionless, tan of the cone angle).
        rail_head_radius_m: transverse radius of the circular rail head, m.
        rail_inclination_rad: cant of the rails towards the track centre, rad (1:40 -> 0.025).
        gauge_m: track gauge, m.
        gauge_height_m: depth below the rail top where the gauge is measured, m.
        flange_back_distance_m: distance between the flange backs of the wheelset, m.
        flange_contact_angle_rad: patches with a contact angle above this are flange contacts, rad.
        left_wheel_profile, right_wheel_profile, left_rail_profile, right_rail_profile: the profile of one side
            (name or file, as ``wheel_profile`` / ``rail_profile``); "" (the default) = the two-sided key, mirrored
            to the left. Not with the analytic conical pair.
        left_rail_inclination_rad, right_rail_inclination_rad: the inclination of one rail towards the track
            centre, rad; None (the default) = ``rail_inclination_rad``.
        curve_direction: "straight" (the default), "right" or "left": the direction in which a horizontal curve of
            constant radius turns (seen in the direction of travel; y to the right, so a right curve's centre is at
            +y and its outer rail is the left one).
        curve_radius_m: R of the curve at the track centreline, m (> 0 for a curve; 0 = straight).
        cant_m: cant (superelevation): the height of the outer rail above the inner one, m (0 = none; a curve only;
            at most ``MAX_CANT_M``).
        cant_reference_width_m: the lateral distance over which ``cant_m`` is measured (EN 13803: 1500 mm for
            standard gauge, the distance between the rail centres): the cant angle is asin(cant / width), m.
    """

    wheel_profile: str = "conical"
    rail_profile: str = "circular"
    conicity: float = 0.05
    rail_head_radius_m: float = 0.3
    rail_inclination_rad: float = 0.0
    gauge_m: float = 1.435
    gauge_height_m: float = 0.014
    flange_back_distance_m: float = 1.360
    flange_contact_angle_rad: float = 0.5
    left_wheel_profile: str = ""
    right_wheel_profile: str = ""
    left_rail_profile: str = ""
    right_rail_profile: str = ""
    left_rail_inclination_rad: float | None = None
    right_rail_inclination_rad: float | None = None
    curve_direction: str = "straight"
    curve_radius_m: float = 0.0
    cant_m: float = 0.0
    cant_reference_width_m: float = 1.5

    def __post_init__(self) -> None:
        check_finite(
            self,
            positive=[
                "rail_head_radius_m",
                "gauge_m",
                "flange_back_distance_m",
                "flange_contact_angle_rad",
                "cant_reference_width_m",
            ],
            nonnegative=["gauge_height_m"],
        )
        for name in ("left_wheel_profile", "right_wheel_profile", "left_rail_profile", "right_rail_profile"):
            if not isinstance(getattr(self, name), str):
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected a profile name or file path, or ''")
            if getattr(self, name) and self.is_conical:
                raise ValueError(
                    f"{name} = {getattr(self, name)!r}: expected '' with the analytic conical wheel on circular rails "
                    "(separate sides need profiles: wheel_profile / rail_profile names or files)"
                )
        for name in ("left_rail_inclination_rad", "right_rail_inclination_rad"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, (int, float)) and abs(value) <= 0.2):
                raise ValueError(f"{name} = {value!r}: expected |value| <= 0.2 rad (1:40 is 0.025) or no value")
        if self.curve_direction not in CURVE_DIRECTIONS:
            raise ValueError(
                f"curve_direction = {self.curve_direction!r}: expected one of {', '.join(CURVE_DIRECTIONS)}"
            )
        if self.curve_direction == "straight":
            if self.curve_radius_m != 0.0:
                raise ValueError(
                    f"curve_radius_m = {self.curve_radius_m!r}: expected no curve radius on straight track, or "
                    "curve_direction = 'right' or 'left'"
                )
        elif not self.curve_radius_m >= MIN_CURVE_RADIUS_M:
            raise ValueError(
                f"curve_radius_m = {self.curve_radius_m!r}: expected a radius >= {MIN_CURVE_RADIUS_M:g} m for the "
                f"{self.curve_direction} curve (0 and negative radii are not curves; tighter ones are not running "
                "track)"
            )
        if not 0.0 <= self.cant_m <= MAX_CANT_M:
            raise ValueError(
                f"cant_m = {self.cant_m!r}: expected a cant from 0 to {MAX_CANT_M:g} m (the outer rail's height above "
                "the inner one; EN 13803 allows up to 0.18 m)"
            )
        if self.cant_m > 0 and self.curve_direction == "straight":
            raise ValueError(
                f"cant_m = {self.cant_m!r}: expected 0 on straight track (cant raises the outer rail of a curve: set "
                "curve_direction and curve_radius_m)"
            )
        if self.cant_m >= self.cant_reference_width_m:
            raise ValueError(
                f"cant_reference_width_m = {self.cant_reference_width_m!r}: expected a width above cant_m = "
                f"{self.cant_m!r} m"
            )
        for name in ("wheel_profile", "rail_profile"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected a profile name or file path")
        if not 0 <= self.conicity < 1:
            raise ValueError(f"conicity = {self.conicity!r}: expected a value in [0, 1)")
        if abs(self.rail_inclination_rad) > 0.2:
            raise ValueError(f"rail_inclination_rad = {self.rail_inclination_rad!r}: expected |value| <= 0.2")

    @property
    def is_conical(self) -> bool:
        """True for the analytic conical wheel on circular rail heads."""
        return self.wheel_profile.lower() == "conical" and self.rail_profile.lower() == "circular"

    @property
    def curvature_1_per_m(self) -> float:
        """Signed curvature of the track centreline, 1/m: +1/R for a right curve, -1/R for a left one, 0 straight."""
        if self.curve_direction == "straight":
            return 0.0
        return (1.0 if self.curve_direction == "right" else -1.0) / self.curve_radius_m

    @property
    def cant_rad(self) -> float:
        """Signed cant angle of the track plane about the track's x axis, rad: > 0 when the left rail is the higher
        (a right curve's cant), < 0 when the right one is; asin(cant_m / cant_reference_width_m).
        """
        angle = math.asin(self.cant_m / self.cant_reference_width_m)
        return -angle if self.curve_direction == "left" else angle

    def cant_deficiency_m(self, speed_m_per_s: float, gravity_m_per_s2: float) -> float:
        """The cant deficiency at a speed: the cant that would balance V^2/R less ``cant_m``, m (EN 13803's I =
        w V^2 / (g R) - D with w the cant reference width; 0 on straight track).
        """
        if self.curve_direction == "straight":
            return 0.0
        return self.cant_reference_width_m * speed_m_per_s**2 / (gravity_m_per_s2 * self.curve_radius_m) - self.cant_m

    @property
    def curved(self) -> bool:
        """True for a curve or cant (the track-following frame's terms are on)."""
        return self.curve_direction != "straight" or self.cant_m > 0

    def side_profile(self, kind: str, side: str) -> str:
        """The wheel or rail (``kind``) profile of ``side`` ("left" / "right"): the side's own key, else the
        two-sided one.
        """
        own = getattr(self, f"{side}_{kind}_profile")
        return own or getattr(self, f"{kind}_profile")

    def side_inclination_rad(self, side: str) -> float:
        """The inclination of the rail of ``side`` towards the track centre, rad."""
        own = getattr(self, f"{side}_rail_inclination_rad")
        return self.rail_inclination_rad if own is None else float(own)


CURVE_DIRECTIONS = ("straight", "right", "left")
"""Values of TrackGeometry.curve_direction."""
MIN_CURVE_RADIUS_M = 50.0
"""The tightest curve radius a scene accepts, m (tram and depot curves go down to about 20-50 m; main lines
rarely below 150 m; the rigid-frame model of a single wheelset in a large curve is meant for running track)."""
MAX_CANT_M = 0.2
"""The largest cant (superelevation) a scene accepts, m (EN 13803: at most 0.16-0.18 m on ballasted track)."""


@dataclass(frozen=True)
class Harmonic:
    """One harmonic of wheel out-of-roundness, R_irr = A cos(n alpha + phase), uniform across the tread.

    Attributes:
        order: n, waves per revolution, integer >= 1.
        amplitude_m: A, m (>= 0).
        phase_rad: phase, rad.
    """

    order: int
    amplitude_m: float
    phase_rad: float = 0.0

    def __post_init__(self) -> None:
        check_finite(self, nonnegative=["amplitude_m"])
        if isinstance(self.order, bool) or not isinstance(self.order, int) or self.order < 1:
            raise ValueError(f"order = {self.order!r}: expected an integer >= 1")


@dataclass(frozen=True)
class Irregularities:
    """Shape irregularities of the wheels (eq 5: R_irr) and rails (eq 6: N_irr). Zero amplitude = none.

    Attributes:
        polygon_order: n, number of harmonics round the wheel (out-of-roundness order); 0 = none.
        polygon_amplitude_m: amplitude of R_irr = A cos(n alpha + phase), m.
        polygon_phase_rad: phase, rad.
        flat_length_m: L, length of the (rounded) wheel flat along the circumference, m; 0 = none.
        flat_depth_m: d, depth of the flat, m; 0 means d = L^2 / (16 r0) (irregular.py).
        flat_angle_rad: wheel angle alpha_d of the flat centre, rad. The wheel's lowest point is at
            alpha_d = pi/2 - phi and phi grows by x / r0 when rolling a distance x, so a flat at
            pi/2 - x_f / r0 reaches the rail after about x_f of travel.
        corrugation_wavelength_m: wavelength of sinusoidal rail corrugation, m; 0 = none.
        corrugation_amplitude_m: amplitude of N_irr = A cos(2 pi x / wavelength), m (z down).
        side: which wheels/rails carry the irregularities: "both", "left" or "right".
        harmonics: further out-of-roundness harmonics, added to the polygon (TOML: ``[[irregularities.harmonics]]``
            tables with ``order``, ``amplitude_m``, ``phase_rad``).
        wheel_grid_file: measured out-of-roundness R_irr(alpha, y_p): a CSV grid
            (:func:`rigid_dynamics.geometry.measured.read_wheel_grid_csv`); "" = none.
        corrugation_file: measured rail irregularity N_irr(x, y_r) (corrugation): a CSV grid
            (:func:`rigid_dynamics.geometry.measured.read_rail_grid_csv`); "" = none.
        joint_dip_angle_rad: 2 alpha, total angle of a dipped rail joint (Jenkins et al. 1974): the rail surface
            falls at the slope alpha over ``joint_ramp_length_m`` before the joint at ``joint_position_m`` and
            rises at alpha after it, N_irr = alpha (S(u - L)/2 + S(u + L)/2 - S_j(u)) with u = x - x_joint,
            L the ramp length, S(v) = sqrt(v^2 + e^2) a rounded |v| (e = ``joint_entry_rounding_m`` at the ramps'
            ends, a gentle entry that leaves the response to the joint alone; e = ``joint_rounding_m`` at the joint,
            above alpha r0 so that the wheel touches the rounded bottom at one point). The slope changes by 2 alpha at
            the joint; the depth there is alpha (sqrt(L^2 + e^2) - e_j), about alpha L. 0 = none. Evaluated by the
            tables and conical providers (Python and compiled), not by the 3-D search.
        Harmonics and measured grids are evaluated by the 3-D contact search (``contact_provider`` "search", the
        choice of "auto" for them); measured grids run on the Python path.
    """

    polygon_order: int = 0
    polygon_amplitude_m: float = 0.0
    polygon_phase_rad: float = 0.0
    flat_length_m: float = 0.0
    flat_depth_m: float = 0.0
    flat_angle_rad: float = 0.0
    corrugation_wavelength_m: float = 0.0
    corrugation_amplitude_m: float = 0.0
    side: str = "both"
    harmonics: tuple[Harmonic, ...] = ()
    wheel_grid_file: str = ""
    corrugation_file: str = ""
    joint_dip_angle_rad: float = 0.0
    joint_position_m: float = 0.0
    joint_ramp_length_m: float = 3.0
    joint_rounding_m: float = 0.01
    joint_entry_rounding_m: float = 1.0

    def __post_init__(self) -> None:
        check_finite(
            self,
            positive=["joint_ramp_length_m", "joint_rounding_m", "joint_entry_rounding_m"],
            nonnegative=[
                "joint_dip_angle_rad",
                "polygon_order",
                "polygon_amplitude_m",
                "flat_length_m",
                "flat_depth_m",
                "corrugation_wavelength_m",
                "corrugation_amplitude_m",
            ],
        )
        if isinstance(self.polygon_order, bool) or not isinstance(self.polygon_order, int):
            raise ValueError(f"polygon_order = {self.polygon_order!r}: expected an integer >= 0")
        if self.side not in IRREGULARITY_SIDES:
            raise ValueError(f"side = {self.side!r}: expected one of {', '.join(IRREGULARITY_SIDES)}")
        if self.corrugation_amplitude_m > 0 and self.corrugation_wavelength_m <= 0:
            raise ValueError(
                f"corrugation_wavelength_m = {self.corrugation_wavelength_m!r}: expected > 0 with corrugation"
            )

    @property
    def any(self) -> bool:
        """True when any irregularity is present."""
        return (
            (self.polygon_order > 0 and self.polygon_amplitude_m > 0)
            or self.flat_length_m > 0
            or self.corrugation_amplitude_m > 0
            or self.joint_dip_angle_rad > 0
            or self.needs_search
        )

    @property
    def needs_search(self) -> bool:
        """True when only the 3-D contact search evaluates them (harmonics, measured grids)."""
        return any(h.amplitude_m > 0 for h in self.harmonics) or bool(self.wheel_grid_file or self.corrugation_file)


@dataclass(frozen=True)
class IntegratorSettings:
    """Time integration, output and safety limits.

    Attributes:
        method: one of RK45, DOP853, Radau, BDF, LSODA (scipy.integrate), RK4 (fixed step), or DP54 / BS32 (the
            embedded pairs Dormand-Prince 5(4) / Bogacki-Shampine 3(2) with step-size control in the compiled loop,
            compiled_loop.py; scipy's RK45 / RK23 where the scene does not run compiled).
        relative_tolerance, absolute_tolerance: error tolerances of the adaptive methods.
        fixed_step_s: step of RK4, s.
        max_step_s: largest step of the adaptive methods, s.
        output_step_s: spacing of the output samples, s (RK4: rounded to a multiple of the step).
        max_rhs_evaluations: the run stops with status "budget-exceeded" after this many evaluations.
        max_wall_time_s: the run stops with status "budget-exceeded" after this wall time, s.
        max_force_factor: a normal force above this multiple of the static wheel load is a force
            anomaly (status "force-anomaly").
        max_lateral_displacement_m: |y| beyond this ends the run (status "derailed"), m.
        stop_at_wheel_lift: end the run (status "wheel-lift") when a wheel loses contact.
        force_tolerance: RK4 and the compiled DP54/BS32: the largest accepted force error estimate of a step (the
            per-wheel normal, longitudinal and lateral creep force of RK4 against its embedded third-order solution,
            drivers.py; of a pair's solution against its embedded lower-order one, compiled_loop.py),
            relative to the static wheel load, over the samples after the scene's settling distance (the start-up
            before it is reported apart); a run that finishes above it ends with status "warning". The default
            0.02 passes the embedded scenes at their own steps and flags the coarser steps at which their force
            results move (benchmarks/results/step_sensitivity.md).
        lift_half_step_check: RK4 and the compiled DP54/BS32: when a wheel lifts off after the settling distance,
            run the scene again at half the step (DP54/BS32: a tenth of both tolerances) and compare the settled
            peaks against ``force_tolerance`` (the re-impacts after a lift move with the step while the local
            estimate stays small; about three times the cost of the run).
    """

    method: str = "RK45"
    relative_tolerance: float = 1e-6
    absolute_tolerance: float = 1e-9
    fixed_step_s: float = 1e-4
    max_step_s: float = 2e-3
    output_step_s: float = 1e-3
    max_rhs_evaluations: int = 2_000_000
    max_wall_time_s: float = 600.0
    max_force_factor: float = 50.0
    max_lateral_displacement_m: float = 0.05
    stop_at_wheel_lift: bool = False
    force_tolerance: float = 0.02
    lift_half_step_check: bool = True

    def __post_init__(self) -> None:
        check_finite(
            self,
            positive=[
                "force_tolerance",
                "relative_tolerance",
                "absolute_tolerance",
                "fixed_step_s",
                "max_step_s",
                "output_step_s",
                "max_rhs_evaluations",
                "max_wall_time_s",
                "max_force_factor",
                "max_lateral_displacement_m",
            ],
        )
        if self.method not in INTEGRATORS:
            raise ValueError(f"method = {self.method!r}: expected one of {', '.join(INTEGRATORS)}")


@dataclass(frozen=True)
class InitialConditions:
    """Initial state; vertical position and roll are set to static equilibrium by simulate().

    Attributes:
        lateral_displacement_m: y(0), m.
        yaw_rad: psi(0), rad.
        lateral_velocity_m_per_s: y'(0), m/s.
        yaw_rate_rad_per_s: psi'(0), rad/s.
        vertical_velocity_m_per_s: z'(0), m/s (z down).
        longitudinal_creepage: xi0, initial slip of the spin, phi'(0) = (1 - xi0) V / r_roll (dimensionless), r_roll
            the mean rolling radius of the two wheels at the initial equilibrium pose (simulate.consistent_start):
            0 starts rolling without a common longitudinal creepage.
        free_rolling: start on the free-rolling path: the yaw rate is solved together with the spin rate so that
            the creep forces exert no yaw and no spin moment at t = 0 (no creep-force spike;
            simulate.consistent_start); ``yaw_rate_rad_per_s`` is then the starting guess. False keeps the given
            yaw rate (an offset wheelset then starts with the creepages of its rolling-radius difference).
    """

    lateral_displacement_m: float = 0.0
    yaw_rad: float = 0.0
    lateral_velocity_m_per_s: float = 0.0
    yaw_rate_rad_per_s: float = 0.0
    vertical_velocity_m_per_s: float = 0.0
    longitudinal_creepage: float = 0.0
    free_rolling: bool = True

    def __post_init__(self) -> None:
        check_finite(self)
        if abs(self.yaw_rad) > 0.2:
            raise ValueError(f"yaw_rad = {self.yaw_rad!r}: expected |value| <= 0.2")


@dataclass(frozen=True)
class DynamicsScene:
    """Everything a wheelset dynamics run needs.

    Attributes:
        name: scene name. description: one line for listings.
        wheelset, suspension, loads, track, irregularities, integrator, initial: nested parameters.
        traction: the traction or braking controller (traction.TractionControl; mode "none": the constant
            loads.traction_torque_N_m).
        material: elastic constants and friction of the wheel-rail pair.
        speed_m_per_s: V, forward speed of the suspension frame and initial speed of the wheelset, m/s.
        duration_s: simulated time, s.
        contact_model: registered contact model name (rigid_dynamics.contact.registry), or "auto".
        contact_provider: "auto" (conical analytic for conical wheels, tables for ideal geometry,
            3-D search with irregularities), "conical", "tables" or "search".
        contact_tolerance: relative force tolerance handed to the "auto" contact model.
        patch_geometry: what a contact model that solves a gap sees per patch (:data:`PATCH_GEOMETRIES`):
            "sampled" (default) the undeformed distance sampled from the real surfaces around the patch (the
            flange's, a flat edge's or a worn pair's non-elliptic patch), "ellipse" the quadric of the relative
            curvatures at the contact point (multi-Hertzian), "formed" every gap-solving model through the callback
            on the patches formed as the static wheelset case forms them (CONTACT's module 1: regions joined or
            split, each solved in the plane of its weighted contact angle; wheelset/formed_patches.py). For the
            ``bem`` "sampled" already forms them; for ``kpec``, whose compiled law with "sampled" samples each
            candidate on its own plane at its deepest point, "formed" solves the static KPEC on the formed patch
            instead (a conformal region from the flange root to the flank is then one patch at its weighted angle,
            not at the deepest point's: benchmarks/results/flange_rungs.md), at Python's cost per patch; ``auto``
            treats it as "sampled". The Hertzian laws (hertz, linear, vermeulen-johnson, fastsim) see the quadric
            either way.
        settling_distance_m: distance travelled from the start after which the summary's peaks are taken (the
            start-up from the initial offset is not a result), m; the full-run peaks are reported beside them.
            The default 10 m covers the start-up of the embedded polygonal-wheel scene from its 1 mm offset (two-point
            contact flips move its peaks with the step over the first 10 m, benchmarks/results/step_sensitivity.md);
            scenes that start centred set less.
        fastsim_elements_per_strip, fastsim_strips: FASTSIM's grid (nx, ny) when the model is "fastsim" or "auto"
            picks it. 20 x 20 keeps the creep forces within ~0.5 % of a 200 x 200 grid, 15 x 10 within 1 %,
            9 x 8 within 2 % (benchmarks/results/fastsim_grid.md) at 1/2, 1/3 and 1/9 of the cost.
        kpec_points: grid points per direction of the sampled gap (and of the quadric's) that the compiled KPEC
            law ("kpec") solves per patch in the loop (compiled_patch.py); the error of the default against a
            grid twice as fine is in benchmarks/results/kpec_loop.md.
        creep_table: with contact_model "auto": its FASTSIM rung served by FASTSIM's creep-force table
            (contact.creep_table; contact_model "table" is that table for every patch). False for other models.
        auto_reuse: with contact_model "auto": a patch it gives to BEM is solved once and served on later
            right-hand sides by FASTSIM corrected by that solution while its inputs stay in a trust region whose
            radius follows the correction's error measured at each re-solve (wheelset/auto_reuse.py); false: every
            such patch solved by BEM. Other models ignore it.
    """

    name: str = "scene"
    description: str = ""
    wheelset: WheelsetParameters = field(default_factory=WheelsetParameters)
    suspension: SuspensionParameters = field(default_factory=SuspensionParameters)
    loads: LoadParameters = field(default_factory=LoadParameters)
    track: TrackGeometry = field(default_factory=TrackGeometry)
    irregularities: Irregularities = field(default_factory=Irregularities)
    track_dynamics: TrackDynamics = field(default_factory=TrackDynamics)
    material: Material = STEEL
    speed_m_per_s: float = 20.0
    duration_s: float = 1.0
    contact_model: str = "linear"
    contact_provider: str = "auto"
    contact_tolerance: float = 0.05
    patch_geometry: str = "sampled"
    fastsim_elements_per_strip: int = 20
    fastsim_strips: int = 20
    kpec_points: int = 24
    creep_table: bool = False
    auto_reuse: bool = True
    settling_distance_m: float = 10.0
    integrator: IntegratorSettings = field(default_factory=IntegratorSettings)
    initial: InitialConditions = field(default_factory=InitialConditions)
    traction: TractionControl = field(default_factory=TractionControl)

    def __post_init__(self) -> None:
        check_finite(
            self, positive=["speed_m_per_s", "duration_s", "contact_tolerance"], nonnegative=["settling_distance_m"]
        )
        if self.contact_provider not in CONTACT_PROVIDERS:
            raise ValueError(
                f"contact_provider = {self.contact_provider!r}: expected one of {', '.join(CONTACT_PROVIDERS)}"
            )
        if not isinstance(self.contact_model, str) or not self.contact_model:
            raise ValueError(f"contact_model = {self.contact_model!r}: expected a registered model name")
        if self.patch_geometry not in PATCH_GEOMETRIES:
            raise ValueError(f"patch_geometry = {self.patch_geometry!r}: expected one of {', '.join(PATCH_GEOMETRIES)}")
        for name in ("fastsim_elements_per_strip", "fastsim_strips"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 1000:
                raise ValueError(f"{name} = {value!r}: expected an integer from 1 to 1000")
        if not isinstance(self.creep_table, bool):
            raise ValueError(f"creep_table = {self.creep_table!r}: expected true or false")
        if not isinstance(self.auto_reuse, bool):
            raise ValueError(f"auto_reuse = {self.auto_reuse!r}: expected true or false")
        value = self.kpec_points
        if isinstance(value, bool) or not isinstance(value, int) or not 8 <= value <= 256:
            raise ValueError(f"kpec_points = {value!r}: expected an integer from 8 to 256")
        for name, cls in (
            ("wheelset", WheelsetParameters),
            ("suspension", SuspensionParameters),
            ("loads", LoadParameters),
            ("track", TrackGeometry),
            ("irregularities", Irregularities),
            ("track_dynamics", TrackDynamics),
            ("material", Material),
            ("integrator", IntegratorSettings),
            ("initial", InitialConditions),
            ("traction", TractionControl),
        ):
            if not isinstance(getattr(self, name), cls):
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected a {cls.__name__}")
        if self.contact_provider in ("conical", "tables") and self.irregularities.needs_search:
            raise ValueError(
                f"contact_provider = {self.contact_provider!r} with irregularities harmonics / wheel_grid_file / "
                "corrugation_file: expected contact_provider 'search' or 'auto' (only the 3-D search evaluates them)"
            )

        if self.track_dynamics.model == "beam":
            from rigid_dynamics.wheelset.track import MAX_BEAM_STATES, beam_layout, travel_m

            layout = beam_layout(self.track_dynamics, travel_m(self))
            if 2 * layout.n_positions > MAX_BEAM_STATES:
                raise ValueError(
                    f"track_dynamics.model = 'beam' over {travel_m(self):.4g} m "
                    f"(speed_m_per_s x duration_s): a beam of {layout.n_sleepers} seats and at least {layout.n_modes} "
                    f"modes per rail, at least {2 * layout.n_positions} states: expected at most {MAX_BEAM_STATES} "
                    "(its cost grows "
                    "with the square of the length: shorten the run, lower cutoff_frequency_Hz, or use model 'lumped')"
                )
        if self.irregularities.joint_dip_angle_rad > 0 and (
            self.contact_provider == "search" or self.irregularities.needs_search
        ):
            raise ValueError(
                f"irregularities.joint_dip_angle_rad = {self.irregularities.joint_dip_angle_rad!r} with "
                f"contact_provider "
                f"{self.contact_provider!r}: expected contact_provider 'tables', 'conical' or 'auto' without harmonics "
                "or measured grids (the 3-D search does not evaluate the dipped joint)"
            )

    @property
    def static_wheel_load_N(self) -> float:
        """Vertical load per wheel at rest, (m g + axle load)/2, N."""
        from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2

        return 0.5 * (self.wheelset.mass_kg * STANDARD_GRAVITY_M_PER_S2 + self.loads.axle_load_N)
