"""Placement of the profiles on the wheelset and the track: wheel surface R(a, y_d) and rail surface N(x, y).

Frames (fixed by the project, see rigid_dynamics/kinematics.py): main (track) frame x along the
track, y lateral to the RIGHT, z DOWN; rail tops at z ~ 0. Wheelset frame: y_d along the axle from
the wheelset centre; a wheel point is x_d = [R cos a, y_d, R sin a] (eq 7), the lowest point at
a = +pi/2.

Wheel (eq 5): R(a, y_d) = R_id(y_d) + R_irr(a, y_d), with

    R_id(y_d) = r0 + (z_p(y_p) - z_p(0)),   y_p = s * y_d - e_w,   e_w = d_fb / 2 + d_tf,

s = +1 for the right wheel, -1 for the left wheel (the left profile is the mirror image), r0 the
nominal rolling radius at the tape circle (the curve is re-referenced by its own z_p(0), which a
smoothing spline may move by ~1e-7 m, so that R_id = r0 exactly there), d_fb the flange-back
distance and d_tf the lateral distance from the flange back to the tape circle. Hence dR_id/dy_d = s z_p'(y_p),
d2R_id/dy_d2 = z_p''(y_p). The sign is + because z_p points down, away from the axle: the flange
tip (z_p = +28 mm for S1002) has the larger radius r0 + 28 mm. (The lead's brief wrote
R_id = r0 - z_p, which holds for a z_p pointing up.)

Rail (eq 6): N(x, y) = N_d(x) + N_id(y) + N_irr(x, y). The rail profile (y_p, z_p) is first canted
by the inclination beta towards the track centre (a rotation about the profile origin, so that the
running surface faces the track centre), then moved so that its highest point is at z = 0 and its
gauge point is at y = +/- G/2:

    [Y(t), Z(t)] = Q [t, z_p(t)],   Q = [[cos b, sin b], [-sin b, cos b]],
    y = s * (e_r + Y),   z = N_id = Z - Z_top,

with t = y_p the profile parameter, Z_top = min Z, and e_r chosen so that the gauge point lies at
y = s * G / 2. The gauge point is the innermost point of the canted profile (smallest Y) within the
band 0 <= Z - Z_top <= h_g below the top (EN 13848-1 definition: the track gauge is the smallest
distance between the rail heads in the range 0 to h_g = 14 mm below the running surface; CONTACT
places its rails the same way, with GAUGHT, GAUGWD and CANT). For a profile given by points the gauge
point is taken on the cubic spline through its canted points over their chord length, as CONTACT does,
when the profile is interpolated (smoothing 0; on the nearly vertical gauge face that spline follows the
points more closely than the z_p(y_p) spline: 0.3 um apart on MBench_UIC60_v3); a smoothed profile is
measured on its smoothed curve. N_id(y) is evaluated exactly on the spline: Y(t) = s y - e_r is solved
for t by Newton's method, then

    dN_id/dy = s Z'/Y',   d2N_id/dy2 = (Z'' Y' - Z' Y'') / Y'^3.

N_id is defined where the canted profile is still a function of y (Y' >= ``MIN_CANTED_DY_DT``).

Irregularities are objects with ``evaluate(...)`` returning (value, d1, d2, d11, d12, d22):
wheel irregularities as functions of (a [rad], y_p [m]) with y_p the wheel-profile lateral
coordinate (same for left and right wheels), rail irregularities as functions of (x [m], y_r [m])
with y_r = s y - e_r the lateral coordinate of the placed rail (towards the field side); the rail
deflection N_d(x) has ``evaluate(x)`` returning (value, d_x, d_xx). See irregularities.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from .profile import DEFAULT_SMOOTHING_WAVELENGTH_M, Profile, ProfileCurve

__all__ = [
    "SIDES",
    "MIN_CANTED_DY_DT",
    "TrackGeometry",
    "WheelsetGeometry",
    "WheelSurface",
    "RailSurface",
    "WheelSurfaceValues",
    "RailSurfaceValues",
    "as_profile_curve",
]

SIDES = ("left", "right")
MIN_CANTED_DY_DT = 0.02
_N_TABLE = 4001


class WheelSurfaceValues(NamedTuple):
    """R(a, y_d) (m) and its partial derivatives: R_a (m/rad), R_y (-), R_aa (m/rad^2), R_ay (1/rad), R_yy (1/m)."""

    R: np.ndarray
    R_a: np.ndarray
    R_y: np.ndarray
    R_aa: np.ndarray
    R_ay: np.ndarray
    R_yy: np.ndarray


class RailSurfaceValues(NamedTuple):
    """N(x, y) (m, z of the rail surface, z down) and its partial derivatives N_x, N_y (-), N_xx, N_xy, N_yy (1/m)."""

    N: np.ndarray
    N_x: np.ndarray
    N_y: np.ndarray
    N_xx: np.ndarray
    N_xy: np.ndarray
    N_yy: np.ndarray


def _side_sign(side):
    if side not in SIDES:
        raise ValueError(f"side must be one of {SIDES}, got {side!r}")
    return 1.0 if side == "right" else -1.0


def as_profile_curve(profile, smoothing_wavelength_m=DEFAULT_SMOOTHING_WAVELENGTH_M, *, kind=None, name="profile"):
    """A curve object (``z``, ``evaluate``, ``y_min_m``, ``y_max_m``, ``kind``) from a `Profile` or a curve.

    A `Profile` becomes a `ProfileCurve` with the given smoothing; objects that already behave as
    curves (`ProfileCurve`, `CircularArcCurve`, analytic standard profiles) are returned unchanged.
    """
    if isinstance(profile, Profile):
        curve = ProfileCurve(profile, smoothing_wavelength_m)
    elif all(hasattr(profile, a) for a in ("evaluate", "z", "y_min_m", "y_max_m", "kind")):
        curve = profile
    else:
        raise ValueError(f"{name} must be a Profile or a profile curve, got {type(profile).__name__}")
    if kind is not None and curve.kind != kind:
        raise ValueError(f"{name} must be a {kind} profile, got a {curve.kind} profile")
    return curve


def _check_positive(name, value, allow_zero=False):
    ok = isinstance(value, (int, float)) and math.isfinite(value) and (value >= 0 if allow_zero else value > 0)
    if not ok:
        raise ValueError(f"{name} must be a finite number {'>=' if allow_zero else '>'} 0, got {value!r}")


def _sum_irregularities(items, u, v, what):
    total = [np.zeros(np.broadcast(u, v).shape) for _ in range(6)]
    for irr in items:
        vals = irr.evaluate(u, v)
        if len(vals) != 6:
            raise ValueError(f"{what} {irr!r}: evaluate() must return 6 arrays (value and 5 derivatives)")
        for k in range(6):
            total[k] = total[k] + vals[k]
    return total


# --------------------------------------------------------------------------------------------- wheel
@dataclass(frozen=True, eq=False)
class WheelSurface:
    """Surface of one wheel, R(a, y_d) = R_id(y_d) + R_irr(a, y_d) (eq 5), in the wheelset frame.

    Attributes:
        side: "left" or "right".
        curve: wheel profile curve z_p(y_p) (internal profile convention).
        nominal_radius_m: r0, m (radius at the tape circle, where z_p = 0).
        tape_circle_offset_m: e_w = |y_d| of the tape circle, m.
        irregularities: wheel irregularities R_irr(a, y_p) (see module docstring), summed.
    """

    side: str
    curve: object
    nominal_radius_m: float
    tape_circle_offset_m: float
    irregularities: tuple = ()
    _z_tape: float = field(init=False, repr=False, compare=False, default=0.0)

    def __post_init__(self):
        _side_sign(self.side)
        _check_positive("nominal_radius_m", self.nominal_radius_m)
        _check_positive("tape_circle_offset_m", self.tape_circle_offset_m)
        curve = as_profile_curve(self.curve, kind="wheel", name="curve")
        if not (curve.y_min_m <= 0.0 <= curve.y_max_m):
            raise ValueError(
                f"the wheel profile must contain the tape circle y_p = 0, "
                f"its range is [{curve.y_min_m}, {curve.y_max_m}] m"
            )
        object.__setattr__(self, "curve", curve)
        object.__setattr__(self, "_z_tape", float(curve.z(0.0)))
        object.__setattr__(self, "irregularities", tuple(self.irregularities))
        for irr in self.irregularities:
            if not hasattr(irr, "evaluate"):
                raise ValueError(f"irregularities must have an evaluate(angle_rad, y_m) method, got {irr!r}")

    @property
    def sign(self) -> float:
        """S = +1 (right) or -1 (left): y_p = s y_d - e_w."""
        return _side_sign(self.side)

    @property
    def y_range_m(self) -> tuple[float, float]:
        """(min, max) of y_d where the wheel surface is defined, m."""
        s, e = self.sign, self.tape_circle_offset_m
        a, b = s * (e + self.curve.y_min_m), s * (e + self.curve.y_max_m)
        return (min(a, b), max(a, b))

    def profile_coordinate(self, y_d_m):
        """y_p = s y_d - e_w (m) for wheelset-frame lateral coordinates ``y_d_m``."""
        return self.sign * np.asarray(y_d_m, dtype=float) - self.tape_circle_offset_m

    def to_profile_coordinates(self, y_d_m, radius_m):
        """(y_p, z_p) in wheel-profile coordinates of a point at lateral y_d and radius R: z_p = R - r0 (+ z_p(0))."""
        return self.profile_coordinate(y_d_m), np.asarray(radius_m, dtype=float) - self.nominal_radius_m + self._z_tape

    def ideal_radius(self, y_d_m):
        """2-D profile function (R_id, dR_id/dy_d, d2R_id/dy_d2) at ``y_d_m`` (m, -, 1/m); NaN outside y_range_m."""
        z, dz, d2z = self.curve.evaluate(self.profile_coordinate(y_d_m))
        return self.nominal_radius_m + (z - self._z_tape), self.sign * dz, d2z

    def evaluate(self, angle_rad, y_d_m) -> WheelSurfaceValues:
        """R and its first and second partial derivatives at (a, y_d); arrays broadcast together.

        Args:
            angle_rad: a, angle about the axle (eq 7), rad.
            y_d_m: y_d, lateral coordinate along the axle, m.

        Returns:
            `WheelSurfaceValues` (R, R_a, R_y, R_aa, R_ay, R_yy), each of the broadcast shape; NaN where
            y_d lies outside y_range_m.
        """
        a, y = np.broadcast_arrays(np.asarray(angle_rad, dtype=float), np.asarray(y_d_m, dtype=float))
        R, R_y, R_yy = self.ideal_radius(y)
        R_a = np.zeros_like(R)
        R_aa = np.zeros_like(R)
        R_ay = np.zeros_like(R)
        if self.irregularities:
            s = self.sign
            v, va, vy, vaa, vay, vyy = _sum_irregularities(
                self.irregularities, a, self.profile_coordinate(y), "wheel irregularity"
            )
            R, R_a, R_y, R_aa, R_ay, R_yy = R + v, R_a + va, R_y + s * vy, R_aa + vaa, R_ay + s * vay, R_yy + vyy
        return WheelSurfaceValues(R, R_a, R_y, R_aa, R_ay, R_yy)


@dataclass(frozen=True, eq=False)
class WheelsetGeometry:
    """Wheelset dimensions and wheel profile (the same profile on both wheels, mirrored on the left).

    Attributes:
        wheel_profile: `Profile` (kind "wheel") or a wheel profile curve.
        flange_back_distance_m: d_fb, lateral distance between the flange backs (inner faces), m.
        nominal_radius_m: r0, rolling radius at the tape circle, m.
        tape_circle_to_flange_back_m: d_tf, lateral distance from the flange back to the tape circle, m
            (70 mm for standard wheels, EN 13715).
        smoothing_wavelength_m: L_filt of the profile spline when wheel_profile is a `Profile`, m.

    Defaults: the Manchester Contact Benchmark wheelset (d_fb = 1360 mm, r0 = 460 mm).
    """

    wheel_profile: object
    flange_back_distance_m: float = 1.360
    nominal_radius_m: float = 0.46
    tape_circle_to_flange_back_m: float = 0.070
    smoothing_wavelength_m: float = DEFAULT_SMOOTHING_WAVELENGTH_M
    curve: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        _check_positive("flange_back_distance_m", self.flange_back_distance_m)
        _check_positive("nominal_radius_m", self.nominal_radius_m)
        _check_positive("tape_circle_to_flange_back_m", self.tape_circle_to_flange_back_m, allow_zero=True)
        _check_positive("smoothing_wavelength_m", self.smoothing_wavelength_m, allow_zero=True)
        curve = as_profile_curve(self.wheel_profile, self.smoothing_wavelength_m, kind="wheel", name="wheel_profile")
        object.__setattr__(self, "curve", curve)
        self.wheel_surface("right")  # validates the curve (tape circle inside the profile)

    @property
    def tape_circle_offset_m(self) -> float:
        """e_w = d_fb / 2 + d_tf: |y_d| of the tape circles, m."""
        return 0.5 * self.flange_back_distance_m + self.tape_circle_to_flange_back_m

    def wheel_surface(self, side: str, irregularities=()) -> WheelSurface:
        """The `WheelSurface` of the ``side`` ("left"/"right") wheel, with optional irregularities."""
        return WheelSurface(side, self.curve, self.nominal_radius_m, self.tape_circle_offset_m, tuple(irregularities))

    def wheel_radius(self, side: str, y_d_m):
        """2-D wheel profile in wheelset coordinates: (R_id, dR_id/dy_d, d2R_id/dy_d2) at ``y_d_m``."""
        return self.wheel_surface(side).ideal_radius(y_d_m)


# --------------------------------------------------------------------------------------------- rail
@dataclass(frozen=True, eq=False)
class _CantedRail:
    """The canted rail profile as a parametric curve (Y(t), Z(t)) with a lookup table for inversion."""

    curve: object
    cant_rad: float
    t_min: float
    t_max: float
    t_table: np.ndarray
    Y_table: np.ndarray
    z_top: float
    t_top: float

    def YZ(self, t):
        c, s = math.cos(self.cant_rad), math.sin(self.cant_rad)
        z, dz, d2z = self.curve.evaluate(t)
        Y = c * t + s * z
        Z = -s * t + c * z
        return Y, Z, c + s * dz, -s + c * dz, s * d2z, c * d2z

    def invert(self, Y):
        """T with Y(t) = Y (Newton from a table guess); NaN outside the function domain."""
        Y = np.asarray(Y, dtype=float)
        tol = 1e-12 * max(1.0, abs(self.Y_table[0]), abs(self.Y_table[-1]))
        inside = (Y >= self.Y_table[0] - tol) & (Y <= self.Y_table[-1] + tol)
        t = np.interp(Y, self.Y_table, self.t_table)
        for _ in range(8):
            Yt, _, dY, *_ = self.YZ(np.clip(t, self.t_min, self.t_max))
            step = (Yt - Y) / dY
            t = np.clip(t - np.where(inside, step, 0.0), self.t_min, self.t_max)
            if np.all(np.abs(np.where(inside, step, 0.0)) <= 1e-15 + 1e-13 * np.abs(t)):
                break
        return np.where(inside, t, np.nan)


def _canted_rail(curve, cant_rad):
    c, s = math.cos(cant_rad), math.sin(cant_rad)
    t = np.linspace(curve.y_min_m, curve.y_max_m, _N_TABLE)
    z, dz, d2z = curve.evaluate(t)
    Z = -s * t + c * z
    dY = c + s * dz
    i_top = int(np.argmin(Z))
    # refine the top: Z'(t) = -s + c z'(t) = 0
    t_top = t[i_top]
    if 0 < i_top < len(t) - 1:
        g = lambda tt: -s + c * float(curve.z(tt, 1))  # noqa: E731
        if g(t[i_top - 1]) < 0 < g(t[i_top + 1]):
            t_top = brentq(g, t[i_top - 1], t[i_top + 1], xtol=1e-15)
    z_top = float(-s * t_top + c * curve.z(t_top))
    ok = dY >= MIN_CANTED_DY_DT
    if not ok[i_top]:
        raise ValueError("the canted rail profile is not a function of y at its top; check rail_inclination_rad")
    a = i_top
    while a > 0 and ok[a - 1]:
        a -= 1
    b = i_top
    while b < len(t) - 1 and ok[b + 1]:
        b += 1
    tt = t[a : b + 1]
    Y = c * tt + s * z[a : b + 1]
    return _CantedRail(curve, cant_rad, float(tt[0]), float(tt[-1]), tt, Y, z_top, float(t_top))


def _gauge_point(canted: _CantedRail, gauge_height_m):
    """Smallest Y of the canted profile within 0 <= Z - Z_top <= h (whole profile, overhangs included).

    A profile whose spline interpolates its points (``knots_m``, no smoothing) is measured on the interpolating
    cubic spline of its canted points over their chord length (:func:`_gauge_point_of_points`); a smoothed or an
    analytic curve on itself.
    """
    curve = canted.curve
    knots = getattr(curve, "knots_m", None)
    if knots is not None:
        return _gauge_point_of_points(canted, knots, gauge_height_m)
    t = np.linspace(curve.y_min_m, curve.y_max_m, _N_TABLE)
    Y, Z, dY, dZ, *_ = canted.YZ(t)
    depth = Z - canted.z_top - gauge_height_m
    inband = depth <= 0
    gauge_side = t <= canted.t_top
    if inband[0] and gauge_side[0]:
        raise ValueError(
            f"the rail profile does not reach gauge_height_m={gauge_height_m} below the top on the gauge side "
            f"(its gauge-side end is {float(Z[0] - canted.z_top) * 1000:.3f} mm below the top)"
        )
    cands = []
    # crossings of the depth h
    idx = np.nonzero(np.diff(np.sign(depth)) != 0)[0]
    for i in idx:
        f = lambda tt: float(canted.YZ(np.asarray(tt))[1] - canted.z_top - gauge_height_m)  # noqa: E731
        tc = brentq(f, t[i], t[i + 1], xtol=1e-15)
        cands.append(float(canted.YZ(np.asarray(tc))[0]))
    # interior minima of Y inside the band (vertical tangents after canting)
    idx = np.nonzero((dY[:-1] < 0) & (dY[1:] >= 0) & inband[:-1] & inband[1:])[0]
    for i in idx:
        f = lambda tt: float(canted.YZ(np.asarray(tt))[2])  # noqa: E731
        tm = brentq(f, t[i], t[i + 1], xtol=1e-15)
        cands.append(float(canted.YZ(np.asarray(tm))[0]))
    cands.append(float(Y[inband].min()))
    return min(cands)


def _gauge_point_of_points(canted: _CantedRail, knots, gauge_height_m):
    """The gauge point of a profile given by points: on the cubic spline (Y(s), Z(s)) through the canted points over
    their chord length s. The gauge face 14 mm below the top is nearly vertical (|dz/dy| 10-40 on UIC60), where
    the spline z_p(y_p) that N_id evaluates follows the points less closely: on MBench_UIC60_v3 (points 0.02-0.04
    mm apart in y there) its gauge point lies 0.31 um further out than the chord-length spline's, which is
    CONTACT's (its gauge point, -43.032558 mm, printed with X_PROFIL = 3; ours now -43.032565). The rail's N_id
    then measures the gauge within 1 um of G (``TrackGeometry.measured_gauge_m``).
    """
    from scipy.interpolate import make_interp_spline

    c, s = math.cos(canted.cant_rad), math.sin(canted.cant_rad)
    t, z = (np.asarray(v, float) for v in knots)
    Y, Z = c * t + s * z, -s * t + c * z
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(Y), np.diff(Z)))])
    keep = np.concatenate([[True], np.diff(arc) > 0])
    arc, Y, Z = arc[keep], Y[keep], Z[keep]
    fy, fz = make_interp_spline(arc, Y, k=3), make_interp_spline(arc, Z, k=3)
    dfy = fy.derivative()
    if Z[0] - canted.z_top - gauge_height_m <= 0 and Y[0] <= Y[int(np.argmin(Z))]:
        raise ValueError(
            f"the rail profile does not reach gauge_height_m={gauge_height_m} below the top on the gauge side "
            f"(its gauge-side end is {float(Z[0] - canted.z_top) * 1000:.3f} mm below the top)"
        )
    a = np.linspace(arc[0], arc[-1], 8 * arc.size)
    ya, depth = fy(a), fz(a) - canted.z_top - gauge_height_m
    inband = depth <= 0
    cands = [float(ya[inband].min())]
    for i in np.nonzero(np.diff(np.sign(depth)) != 0)[0]:
        root = brentq(lambda q: float(fz(q)) - canted.z_top - gauge_height_m, a[i], a[i + 1], xtol=1e-15)
        cands.append(float(fy(root)))
    slope = dfy(a)
    for i in np.nonzero((slope[:-1] < 0) & (slope[1:] >= 0) & inband[:-1] & inband[1:])[0]:
        root = brentq(lambda q: float(dfy(q)), a[i], a[i + 1], xtol=1e-15)
        cands.append(float(fy(root)))
    return min(cands)


@dataclass(frozen=True, eq=False)
class RailSurface:
    """Surface of one rail, N(x, y) = N_d(x) + N_id(y) + N_irr(x, y) (eq 6), in the main frame (z down).

    Build it with `TrackGeometry.rail_surface`. The rail material is at z > N.

    Attributes:
        side: "left" or "right".
        canted: the canted rail profile (internal).
        lateral_offset_m: e_r, m (y = s (e_r + Y)).
        irregularities: rail irregularities N_irr(x, y_r) (module docstring), summed.
        deflection: rail deflection N_d(x) (``evaluate(x)`` -> value, d_x, d_xx) or None.
    """

    side: str
    canted: _CantedRail
    lateral_offset_m: float
    irregularities: tuple = ()
    deflection: object = None

    def __post_init__(self):
        _side_sign(self.side)
        object.__setattr__(self, "irregularities", tuple(self.irregularities))
        for irr in self.irregularities:
            if not hasattr(irr, "evaluate"):
                raise ValueError(f"irregularities must have an evaluate(x_m, y_m) method, got {irr!r}")
        if self.deflection is not None and not hasattr(self.deflection, "evaluate"):
            raise ValueError(f"deflection must have an evaluate(x_m) method or be None, got {self.deflection!r}")

    @property
    def sign(self) -> float:
        """S = +1 (right) or -1 (left)."""
        return _side_sign(self.side)

    @property
    def cant_rad(self) -> float:
        """Cant applied to the profile, rad (0 if the profile was already canted)."""
        return self.canted.cant_rad

    @property
    def y_range_m(self) -> tuple[float, float]:
        """(min, max) of y where N is defined, m."""
        s, e = self.sign, self.lateral_offset_m
        a, b = s * (e + self.canted.Y_table[0]), s * (e + self.canted.Y_table[-1])
        return (min(a, b), max(a, b))

    def rail_coordinate(self, y_m):
        """y_r = s y - e_r: lateral coordinate of the placed rail, towards the field side, m."""
        return self.sign * np.asarray(y_m, dtype=float) - self.lateral_offset_m

    def to_profile_coordinates(self, y_m, z_m):
        """Main-frame (y, z) of points on/near the rail -> rail-profile coordinates (y_p, z_p), m."""
        Y = self.rail_coordinate(y_m)
        Z = np.asarray(z_m, dtype=float) + self.canted.z_top
        c, s = math.cos(self.cant_rad), math.sin(self.cant_rad)
        return c * Y - s * Z, s * Y + c * Z

    def ideal_height(self, y_m):
        """2-D rail profile in track coordinates: (N_id, dN_id/dy, d2N_id/dy2) at ``y_m`` (m, -, 1/m); NaN outside."""
        t = self.canted.invert(self.rail_coordinate(y_m))
        _, Z, dY, dZ, d2Y, d2Z = self.canted.YZ(t)
        return Z - self.canted.z_top, self.sign * dZ / dY, (d2Z * dY - dZ * d2Y) / dY**3

    def evaluate(self, x_m, y_m) -> RailSurfaceValues:
        """N and its first and second partial derivatives at (x, y); arrays broadcast together.

        Returns:
            `RailSurfaceValues` (N, N_x, N_y, N_xx, N_xy, N_yy), z down; NaN where y lies outside y_range_m.
        """
        x, y = np.broadcast_arrays(np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))
        N, N_y, N_yy = self.ideal_height(y)
        N_x = np.zeros_like(N)
        N_xx = np.zeros_like(N)
        N_xy = np.zeros_like(N)
        if self.deflection is not None:
            d, dx, dxx = self.deflection.evaluate(x)
            N, N_x, N_xx = N + d, N_x + dx, N_xx + dxx
        if self.irregularities:
            s = self.sign
            v, vx, vy, vxx, vxy, vyy = _sum_irregularities(
                self.irregularities, x, self.rail_coordinate(y), "rail irregularity"
            )
            N, N_x, N_y, N_xx, N_xy, N_yy = N + v, N_x + vx, N_y + s * vy, N_xx + vxx, N_xy + s * vxy, N_yy + vyy
        return RailSurfaceValues(N, N_x, N_y, N_xx, N_xy, N_yy)


@dataclass(frozen=True, eq=False)
class TrackGeometry:
    """Track: rail profile, gauge, gauge height and rail inclination (the same rail on both sides, mirrored left).

    Attributes:
        rail_profile: `Profile` (kind "rail") or a rail profile curve, internal profile convention.
        gauge_m: G, distance between the gauge faces measured gauge_height_m below the top, m.
        gauge_height_m: h_g, m (14 mm: EN 13848-1).
        rail_inclination_rad: beta, cant of the rails towards the track centre, rad
            (atan(1/40) default; atan(1/20) and 0 are common).
        profile_is_canted: True if the profile points are already canted (e.g. MBench_UIC60_v3): then no
            further rotation is applied and rail_inclination_rad is only recorded.
        smoothing_wavelength_m: L_filt of the profile spline when rail_profile is a `Profile`, m.

    Raises:
        ValueError: bad numbers; a profile that does not reach gauge_height_m below its top on the gauge side.
    """

    rail_profile: object
    gauge_m: float = 1.435
    gauge_height_m: float = 0.014
    rail_inclination_rad: float = math.atan(1.0 / 40.0)
    profile_is_canted: bool = False
    smoothing_wavelength_m: float = DEFAULT_SMOOTHING_WAVELENGTH_M
    curve: object = field(init=False, repr=False, compare=False)
    _canted: _CantedRail = field(init=False, repr=False, compare=False)
    _lateral_offset_m: float = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        _check_positive("gauge_m", self.gauge_m)
        _check_positive("gauge_height_m", self.gauge_height_m)
        _check_positive("smoothing_wavelength_m", self.smoothing_wavelength_m, allow_zero=True)
        b = self.rail_inclination_rad
        if not (isinstance(b, (int, float)) and math.isfinite(b) and abs(b) < 0.2):
            raise ValueError(f"rail_inclination_rad must be a finite angle with |angle| < 0.2 rad, got {b!r}")
        if not isinstance(self.profile_is_canted, bool):
            raise ValueError(f"profile_is_canted must be True or False, got {self.profile_is_canted!r}")
        curve = as_profile_curve(self.rail_profile, self.smoothing_wavelength_m, kind="rail", name="rail_profile")
        object.__setattr__(self, "curve", curve)
        canted = _canted_rail(curve, 0.0 if self.profile_is_canted else float(b))
        y_gauge = _gauge_point(canted, self.gauge_height_m)
        object.__setattr__(self, "_canted", canted)
        object.__setattr__(self, "_lateral_offset_m", 0.5 * self.gauge_m - y_gauge)

    @property
    def rail_offset_m(self) -> float:
        """e_r: the profile origin of the right rail is at y = e_r after canting (left: -e_r), m."""
        return self._lateral_offset_m

    def rail_surface(self, side: str, irregularities=(), deflection=None) -> RailSurface:
        """The `RailSurface` of the ``side`` ("left"/"right") rail, with optional irregularities and deflection."""
        return RailSurface(side, self._canted, self._lateral_offset_m, tuple(irregularities), deflection)

    def rail_height(self, side: str, y_m):
        """2-D rail profile in track coordinates: (N_id, dN_id/dy, d2N_id/dy2) at ``y_m``."""
        return self.rail_surface(side).ideal_height(y_m)

    def measured_gauge_m(self) -> float:
        """Gauge measured on the placed surfaces N_id(y): distance between the points at depth h_g on the gauge sides.

        An independent check of the placement (it uses the evaluated surfaces, not the placement
        computation); assumes the gauge faces do not overhang within the band (then the innermost point
        lies at the depth h_g).
        """
        ys = {}
        for side in SIDES:
            surf = self.rail_surface(side)
            lo, hi = surf.y_range_m
            y = np.linspace(lo, hi, 4001)
            n = surf.ideal_height(y)[0]
            i_top = int(np.nanargmin(n))
            f = lambda yy, surf=surf: float(surf.ideal_height(np.asarray(yy))[0]) - self.gauge_height_m  # noqa: E731
            if side == "right":
                i = int(np.nonzero(n[: i_top + 1] > self.gauge_height_m)[0][-1])
            else:
                i = i_top + int(np.nonzero(n[i_top:] > self.gauge_height_m)[0][0]) - 1
            ys[side] = brentq(f, y[i], y[i + 1], xtol=1e-14, rtol=1e-15)
        return float(ys["right"] - ys["left"])
