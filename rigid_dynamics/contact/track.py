"""Wheel and rail surfaces of both sides for the contact search, built from profiles (rigid_dynamics.geometry).

Rail inclination. ``rail_inclination_rad`` is the inclination of the rail IN THE TRACK. Some profile files
are already canted (``CANTED_PROFILES``: the Manchester benchmark's MBench_UIC60_v3 rail is canted 1:40,
its file says so); for those only the difference between the requested inclination and the file's own cant
is applied, so a 1:40 case with the 1:40 file is not canted twice, and 0 turns it back to vertical.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from rigid_dynamics.contact.search import SIDES, SideSearch, WheelsetPose, fast_surfaces, search_side
from rigid_dynamics.materials import Material

CANTED_PROFILES: dict[str, float] = {
    "MBench_UIC60_v3": math.atan(1.0 / 40.0),
    "MBench_UIC60_v3_ban": math.atan(1.0 / 40.0),
}
"""Profile name (built-in name or file stem) -> cant already contained in its points, rad."""


class _RadiusFromProfileDown:
    """Wheel surface with R = r0 + (z_p - z_p(0)) built from a surface that returned R = r0 - (z_p - z_p(0)).

    With z_p pointing DOWN (profile convention) the flange, at positive z_p, is further from the axle than the
    tape circle, so R_id = r0 + z_p - z_p(0): the flange tip of an S1002 wheel is 28 mm beyond r0. This adapter
    mirrors R about r0 (R' = 2 r0 - R, derivatives negated) for a geometry stage that used the opposite sign;
    :func:`build_track` applies it only when the flange of the placed wheel comes out smaller than r0.
    """

    def __init__(self, surface):
        self.surface = surface
        self.side = surface.side
        self.nominal_radius_m = surface.nominal_radius_m

    @property
    def y_range_m(self):
        return self.surface.y_range_m

    def evaluate(self, angle_rad, y_d_m):
        r, r_a, r_y, r_aa, r_ay, r_yy = self.surface.evaluate(angle_rad, y_d_m)
        return (2.0 * self.nominal_radius_m - r, -r_a, -r_y, -r_aa, -r_ay, -r_yy)

    @property
    def irregularities(self):
        return self.surface.irregularities

    def ideal_radius(self, y_d_m):
        r, r_y, r_yy = self.surface.ideal_radius(y_d_m)
        return 2.0 * self.nominal_radius_m - r, -r_y, -r_yy

    def to_profile_coordinates(self, y_d_m, radius_m):
        y_p, z_p = self.surface.to_profile_coordinates(y_d_m, radius_m)
        z_tape = float(self.surface.curve.z(0.0))
        return y_p, 2.0 * z_tape - z_p


def _wheel_with_flange_outside(surface, curve):
    """The wheel surface, mirrored about r0 if its flange tip (max z_p) has a radius below r0 (see adapter)."""
    import numpy as np

    y = np.linspace(curve.y_min_m, curve.y_max_m, 2001)
    tip = y[int(np.nanargmax(curve.z(y)))]
    y_d = surface.sign * (tip + surface.tape_circle_offset_m)
    radius = float(surface.ideal_radius(y_d)[0])
    return surface if radius >= surface.nominal_radius_m else _RadiusFromProfileDown(surface)


def profile_cant_rad(profile) -> float:
    """Cant already contained in a rail profile's points (0 unless listed in ``CANTED_PROFILES``), rad."""
    return CANTED_PROFILES.get(getattr(profile, "name", ""), 0.0)


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
            gauge_height_m, flange_back_distance_m, nominal_radius_m, rail_inclination_rad.
        wheel_irregularities, rail_irregularities: optional side -> tuple of irregularities (geometry module).

    Raises:
        ValueError: unknown profile, bad placement (from rigid_dynamics.geometry).
    """
    from rigid_dynamics.geometry import TrackGeometry, WheelsetGeometry, load_profile

    wheel = load_profile(case.wheel_profile, "wheel") if isinstance(case.wheel_profile, str) else case.wheel_profile
    rail = load_profile(case.rail_profile, "rail") if isinstance(case.rail_profile, str) else case.rail_profile
    wheelset = WheelsetGeometry(
        wheel, flange_back_distance_m=case.flange_back_distance_m, nominal_radius_m=case.nominal_radius_m
    )
    track = TrackGeometry(
        rail,
        gauge_m=case.gauge_m,
        gauge_height_m=case.gauge_height_m,
        rail_inclination_rad=case.rail_inclination_rad - profile_cant_rad(rail),
    )
    wheel_irregularities = wheel_irregularities or {}
    rail_irregularities = rail_irregularities or {}
    return WheelsetTrack(
        wheels={
            s: _wheel_with_flange_outside(wheelset.wheel_surface(s, wheel_irregularities.get(s, ())), wheelset.curve)
            for s in SIDES
        },
        rails={s: track.rail_surface(s, rail_irregularities.get(s, ())) for s in SIDES},
        nominal_radius_m=case.nominal_radius_m,
        half_wheel_distance_m=wheelset.tape_circle_offset_m,
    )
