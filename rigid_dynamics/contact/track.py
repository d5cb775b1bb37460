"""Wheel and rail surfaces of both sides for the contact search, built from profiles (rigid_dynamics.geometry).

Rail inclination. ``rail_inclination_rad`` is the inclination of the rail IN THE TRACK. A profile's points may
already contain a cant (the Manchester benchmark's MBench_UIC60_v3 rail is canted 1:40, its file says so): that
cant is data of the profile (``Profile.cant_rad``: the built-in profiles carry theirs, readers.BUILTIN_CANT_RAD;
for a file the case states it, ``rail_profile_cant_rad``), never inferred from a name. Only the difference between
the requested inclination and the profile's own cant is applied, so a 1:40 case with the 1:40 file is not canted
twice, and 0 turns it back to vertical.

Orientation. Profiles are read in the internal convention (readers.py: y towards the field side, z down); a file
of another orientation is turned by the case's ``*_profile_mirror_y`` / ``*_profile_mirror_z`` (as CONTACT's
MIRRORY, MIRRORZ). A wheel whose flange comes out inside the tape circle is an error that says so, not something
mended silently. Left and right profiles may differ (``wheel_profile_left``, ``rail_profile_left``; default the
right ones, mirrored); ``profile_smoothing_m`` sets the profile splines' smoothing wavelength (default 2 mm),
``rail_profile_smoothing_m`` the rails' when it differs (CONTACT's per-profile SMOOTH).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rigid_dynamics.contact.search import SIDES, SideSearch, WheelsetPose, fast_surfaces, search_side
from rigid_dynamics.materials import Material


def _mirrored(profile, mirror_y: bool, mirror_z: bool):
    """The profile with y -> -y and/or z -> -z (as CONTACT's MIRRORY / MIRRORZ), for files of other orientations."""
    import numpy as np

    from rigid_dynamics.geometry.profile import Profile

    if not (mirror_y or mirror_z):
        return profile
    sy, sz = (-1.0 if mirror_y else 1.0), (-1.0 if mirror_z else 1.0)
    y, z = sy * profile.y_m, sz * profile.z_m
    oy, oz = sy * profile.outline_y_m, sz * profile.outline_z_m
    order = np.argsort(y)
    what = " and ".join(n for n, f in (("y", mirror_y), ("z", mirror_z)) if f)
    return Profile(
        y[order], z[order], profile.kind, profile.name, f"{profile.source}; mirrored in {what}", oy, oz,
        cant_rad=sy * profile.cant_rad,
    )  # fmt: skip


def _load(value, kind: str, mirror_y: bool, mirror_z: bool):
    from rigid_dynamics.geometry import load_profile

    profile = load_profile(value, kind) if isinstance(value, str) else value
    if hasattr(profile, "y_m"):
        profile = _mirrored(profile, mirror_y, mirror_z)
    return profile


def _check_flange_outside(curve, name) -> None:
    """A flanged wheel's flange (inner side of the tape circle, y_p < 0) must rise beyond the tape circle (z_p down,
    away from the axle). A deep dip towards the axle on the inner side only (the outer side not dipping alike, as a
    crowned or circular profile does on both sides) means the file's z points up.
    """
    import numpy as np

    lo, hi = max(curve.y_min_m, -0.08), min(curve.y_max_m, 0.08)
    if lo >= -0.005:
        return
    z0 = float(curve.z(0.0))
    inner = curve.z(np.linspace(lo, -0.005, 601)) - z0
    outer = curve.z(np.linspace(0.005, hi, 601)) - z0 if hi > 0.005 else np.zeros(1)
    dip_inner, rise_inner = float(-np.nanmin(inner)), float(np.nanmax(inner))
    dip_outer = max(float(-np.nanmin(outer)), 0.0)
    if dip_inner > 0.005 and dip_inner > 2.0 * rise_inner and dip_inner > 2.0 * dip_outer:
        raise ValueError(
            f"wheel profile {name!r}: its flange dips {1e3 * dip_inner:.1f} mm towards the axle from the tape circle: "
            "the file's z axis points up; expected z down (away from the axle), or set wheel_profile_mirror_z = true"
        )


@dataclass(frozen=True, eq=False)
class WheelsetTrack:
    """Surfaces of both wheels and rails, and what the wheelset-case solver needs to know about them.

    Attributes:
        wheels, rails: side -> WheelSurface / RailSurface (rigid_dynamics.geometry).
        nominal_radius_m: r0, m.
        half_wheel_distance_m: e_w, |y_d| of the tape circles, m.
    """

    wheels: dict
    rails: dict
    nominal_radius_m: float
    half_wheel_distance_m: float
    fast: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for side in SIDES:
            self.fast[side] = fast_surfaces(self.wheels[side], self.rails[side])

    @property
    def rest_z_m(self) -> float:
        """Starting guess of the centre's z: tape circles on the rail tops (z = 0), m."""
        return -self.nominal_radius_m

    def search(self, pose: WheelsetPose, side: str, options=None) -> SideSearch:
        """Contact search of one side (search.search_side) with the surfaces' lateral ranges."""
        wheel, rail = self.fast[side]
        return search_side(
            wheel,
            rail,
            pose,
            side,
            wheel_lateral_range_m=wheel.y_range_m,
            rail_lateral_range_m=rail.y_range_m,
            options=options,
        )

    def reference_approach_m(self, case, material: Material) -> float:
        """Approach scale q_W: Hertz approach of a tread contact (A = 1/(2 r0), B = 1/(2 x 0.3 m)) at the load."""
        if case.approach_m is not None:
            return float(case.approach_m)
        from rigid_dynamics.contact.hertz import hertz_approach_from_force

        return float(
            hertz_approach_from_force(
                0.5 / self.nominal_radius_m,
                0.5 / 0.3,
                case.wheel_load_N,
                shear_modulus_Pa=material.shear_modulus_Pa,
                poisson_ratio=material.poisson_ratio,
            )
        )


def build_track(case, *, wheel_irregularities=None, rail_irregularities=None) -> WheelsetTrack:
    """Surfaces for a :class:`~rigid_dynamics.contact.wheelset_case.WheelsetCase` (or anything with its fields).

    Args:
        case: provides wheel_profile, rail_profile (names or paths, Profile objects or profile curves), gauge_m,
            gauge_height_m, flange_back_distance_m, nominal_radius_m, rail_inclination_rad; optionally (getattr,
            defaults in brackets) wheel_profile_left, rail_profile_left [the right ones, mirrored],
            rail_profile_cant_rad [the profile's own ``cant_rad``], rail_inclination_left_rad /
            rail_inclination_right_rad [rail_inclination_rad], profile_smoothing_m [2 mm],
            rail_profile_smoothing_m [profile_smoothing_m],
            wheel_profile_mirror_y/_z, rail_profile_mirror_y/_z [False].
        wheel_irregularities, rail_irregularities: optional side -> tuple of irregularities (geometry module).

    Raises:
        ValueError: unknown profile, bad placement (from rigid_dynamics.geometry), a wheel whose flange comes out
            inside the tape circle (a file with z up: set wheel_profile_mirror_z).
    """
    from rigid_dynamics.geometry import TrackGeometry, WheelsetGeometry
    from rigid_dynamics.geometry.placement import DEFAULT_SMOOTHING_WAVELENGTH_M

    smoothing = getattr(case, "profile_smoothing_m", None)
    smoothing = DEFAULT_SMOOTHING_WAVELENGTH_M if smoothing is None else smoothing
    rail_smoothing = getattr(case, "rail_profile_smoothing_m", None)
    rail_smoothing = smoothing if rail_smoothing is None else rail_smoothing
    wheel_mirror = (
        bool(getattr(case, "wheel_profile_mirror_y", False)),
        bool(getattr(case, "wheel_profile_mirror_z", False)),
    )
    rail_mirror = (
        bool(getattr(case, "rail_profile_mirror_y", False)),
        bool(getattr(case, "rail_profile_mirror_z", False)),
    )
    names = {
        "wheel": {"right": case.wheel_profile, "left": getattr(case, "wheel_profile_left", None) or case.wheel_profile},
        "rail": {"right": case.rail_profile, "left": getattr(case, "rail_profile_left", None) or case.rail_profile},
    }
    stated_cant = getattr(case, "rail_profile_cant_rad", None)
    wheel_irregularities = wheel_irregularities or {}
    rail_irregularities = rail_irregularities or {}
    wheels, rails, offset = {}, {}, None
    for side in SIDES:
        wheel = _load(names["wheel"][side], "wheel", *wheel_mirror)
        rail = _load(names["rail"][side], "rail", *rail_mirror)
        wheelset = WheelsetGeometry(
            wheel, flange_back_distance_m=case.flange_back_distance_m, nominal_radius_m=case.nominal_radius_m,
            smoothing_wavelength_m=smoothing,
        )  # fmt: skip
        cant = stated_cant if stated_cant is not None else float(getattr(rail, "cant_rad", 0.0))
        inclination = getattr(case, f"rail_inclination_{side}_rad", None)
        inclination = case.rail_inclination_rad if inclination is None else inclination
        track = TrackGeometry(
            rail, gauge_m=case.gauge_m, gauge_height_m=case.gauge_height_m,
            rail_inclination_rad=inclination - cant, smoothing_wavelength_m=rail_smoothing,
        )  # fmt: skip
        wheels[side] = wheelset.wheel_surface(side, wheel_irregularities.get(side, ()))
        _check_flange_outside(wheelset.curve, getattr(wheel, "name", names["wheel"][side]))
        rails[side] = track.rail_surface(side, rail_irregularities.get(side, ()))
        offset = wheelset.tape_circle_offset_m
    return WheelsetTrack(
        wheels=wheels,
        rails=rails,
        nominal_radius_m=case.nominal_radius_m,
        half_wheel_distance_m=offset,
    )
