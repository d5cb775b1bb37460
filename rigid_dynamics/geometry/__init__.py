"""Wheel and rail geometry: profiles, readers, placement on wheelset and track, surfaces (seed eq 5-10).

Conventions (project-wide): main frame x along the track, y to the right, z DOWN; profiles in
(y_p towards the field side, z_p down), wheel origin at the tape circle, rail z_p = 0 at the top.
Wheel: R_id(y_d) = r0 + z_p(y_p) - z_p(0) with y_p = s y_d - e_w (s = +1 right, -1 left; z_p points
away from the axle, so the S1002 flange tip has R = r0 + 28 mm). Rail: the profile is canted towards
the track centre and placed so that the gauge faces (innermost points within gauge_height_m of the
top) are gauge_m apart; rail tops at z = 0. Profiles built from points are smoothed by a C2
spline with L_filt = 2 mm by default (smoothing_wavelength_m=0 interpolates); analytic curves
(standard_profiles, CircularArcCurve) are evaluated exactly.

Public API (stable):

Profiles (profile.py)
    Profile(y_m, z_m, kind, name="profile", source="", outline_y_m=(), outline_z_m=())
        frozen, validated point set; .curve(smoothing_wavelength_m=0.002) -> ProfileCurve
    ProfileCurve(profile, smoothing_wavelength_m=0.002)
        .z(y_m, derivative=0|1|2), .evaluate(y_m) -> (z, dz, d2z), .y_min_m, .y_max_m, .kind
    CircularArcCurve(radius_m, half_width_m, kind, centre_y_m=0, apex_z_m=0)  closed-form circle
    find_self_intersection(y, z) -> (i, j) | None

Readers (readers.py)
    read_profile(path, kind=None) -> Profile      (.prw/.prr SIMPACK, .whl/.ban MiniProf, .csv/.txt)
    load_profile(name_or_path, kind=None) -> Profile   (built-in name or file)
    builtin_profiles() -> dict[name, description]
    write_profile_csv(path, profile) -> Path

Placement and surfaces (placement.py)
    WheelsetGeometry(wheel_profile, flange_back_distance_m=1.360, nominal_radius_m=0.46,
                     tape_circle_to_flange_back_m=0.070, smoothing_wavelength_m=0.002)
        .wheel_surface(side, irregularities=()) -> WheelSurface; .wheel_radius(side, y_d_m)
        .tape_circle_offset_m
    TrackGeometry(rail_profile, gauge_m=1.435, gauge_height_m=0.014, rail_inclination_rad=atan(1/40),
                  profile_is_canted=False, smoothing_wavelength_m=0.002)
        .rail_surface(side, irregularities=(), deflection=None) -> RailSurface; .rail_height(side, y_m)
        .rail_offset_m, .measured_gauge_m()
    WheelSurface.evaluate(angle_rad, y_d_m) -> WheelSurfaceValues(R, R_a, R_y, R_aa, R_ay, R_yy)
        .ideal_radius(y_d_m) -> (R_id, dR/dy, d2R/dy2), .y_range_m, .to_profile_coordinates(y_d, R)
    RailSurface.evaluate(x_m, y_m) -> RailSurfaceValues(N, N_x, N_y, N_xx, N_xy, N_yy)
        .ideal_height(y_m) -> (N_id, dN/dy, d2N/dy2), .y_range_m, .to_profile_coordinates(y, z)
    side is "left" or "right". Values are NaN outside y_range_m.

Analytic standard profiles (standard_profiles.py), exact curves usable wherever a profile is taken
    s1002_wheel(), uic60_rail(side_depth_m=0.016), conical_wheel(conicity, y_min_m, y_max_m),
    circular_wheel(radius_m, half_width_m), circular_rail(radius_m, half_width_m),
    analytic_profile(name) ("S1002", "UIC60", "60E1"); each has .to_profile(spacing_m) -> Profile.
    load_profile("S1002") / ("UIC60") / ("60E1") return them sampled every 0.05 mm.

Irregularities (irregularities.py), frozen and validated, evaluate -> (value, 5 derivatives)
    wheel, (angle_rad, y_p):  HarmonicOutOfRoundness(order, amplitude_m, phase_rad=0),
        WheelFlat(length_m, wheel_radius_m, depth_m=None, centre_angle_rad=pi/2, shape="rounded"|"new"),
        MeasuredWheelIrregularity(angle_rad, y_m, values_m)       (periodic in angle)
    rail, (x_m, y_r):  RailCorrugation(wavelength_m, amplitude_m, phase_rad=0, centre_y_m=0,
        half_width_m=0.015, taper_m=0.005), MeasuredRailIrregularity(x_m, y_m, values_m)
    rail deflection N_d(x): TabulatedRailDeflection(x_m, deflection_m),
        WinklerRailDeflection(load_N, load_position_m, bending_stiffness_Nm2, foundation_modulus_N_per_m2)
    Pass them to WheelsetGeometry.wheel_surface(side, irregularities=[...]) and
    TrackGeometry.rail_surface(side, irregularities=[...], deflection=...).
"""

from .irregularities import (
    HarmonicOutOfRoundness,
    MeasuredRailIrregularity,
    MeasuredWheelIrregularity,
    RailCorrugation,
    TabulatedRailDeflection,
    WheelFlat,
    WinklerRailDeflection,
)
from .placement import (
    SIDES,
    RailSurface,
    RailSurfaceValues,
    TrackGeometry,
    WheelsetGeometry,
    WheelSurface,
    WheelSurfaceValues,
)
from .profile import (
    DEFAULT_SMOOTHING_WAVELENGTH_M,
    CircularArcCurve,
    Profile,
    ProfileCurve,
    find_self_intersection,
)
from .readers import builtin_profiles, load_profile, read_profile, write_profile_csv
from .standard_profiles import (
    ConicalWheelCurve,
    S1002Curve,
    UIC60Curve,
    analytic_profile,
    circular_rail,
    circular_wheel,
    conical_wheel,
    s1002_wheel,
    uic60_rail,
)

__all__ = [
    "ConicalWheelCurve",
    "HarmonicOutOfRoundness",
    "MeasuredRailIrregularity",
    "MeasuredWheelIrregularity",
    "RailCorrugation",
    "S1002Curve",
    "TabulatedRailDeflection",
    "UIC60Curve",
    "WheelFlat",
    "WinklerRailDeflection",
    "analytic_profile",
    "circular_rail",
    "circular_wheel",
    "conical_wheel",
    "s1002_wheel",
    "uic60_rail",
    "DEFAULT_SMOOTHING_WAVELENGTH_M",
    "SIDES",
    "CircularArcCurve",
    "Profile",
    "ProfileCurve",
    "RailSurface",
    "RailSurfaceValues",
    "TrackGeometry",
    "WheelSurface",
    "WheelSurfaceValues",
    "WheelsetGeometry",
    "builtin_profiles",
    "find_self_intersection",
    "load_profile",
    "read_profile",
    "write_profile_csv",
]
