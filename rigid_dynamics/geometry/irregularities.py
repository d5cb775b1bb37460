"""Wheel and rail irregularities (seed eq 5 and 6): R_irr(a, y), N_irr(x, y) and the rail deflection N_d(x).

All classes are frozen dataclasses validated in ``__post_init__``; ``evaluate`` is vectorised
(arrays broadcast together) and returns the value and its first and second partial derivatives.

Wheel irregularities: ``evaluate(angle_rad, y_m)`` -> (R_irr, dR/da, dR/dy, d2R/da2, d2R/dady, d2R/dy2)
in m, m/rad, -, m/rad^2, 1/rad, 1/m; a is the angle of eq 7 (the lowest wheel point is at
a = +pi/2 when the wheel is not rotated) and y = y_p the wheel-profile lateral coordinate (towards
the field side, same for both wheels). A positive R_irr adds material (larger radius).

Rail irregularities: ``evaluate(x_m, y_m)`` -> (N_irr, dN/dx, dN/dy, d2N/dx2, d2N/dxdy, d2N/dy2)
with x along the track and y = y_r the lateral coordinate of the placed rail (towards the field
side, same for both rails; see placement.py). z is down: a positive N_irr LOWERS the rail surface,
an irregularity that raises the rail top makes N smaller.

Rail deflection: ``evaluate(x_m)`` -> (N_d, dN_d/dx, d2N_d/dx2), positive downwards.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, RectBivariateSpline, make_interp_spline

__all__ = [
    "HarmonicOutOfRoundness",
    "WheelFlat",
    "MeasuredWheelIrregularity",
    "RailCorrugation",
    "MeasuredRailIrregularity",
    "TabulatedRailDeflection",
    "WinklerRailDeflection",
    "smooth_step",
]

TWO_PI = 2.0 * math.pi


def _finite(name, value, *, positive=False, nonnegative=False):
    ok = (
        isinstance(value, (int, float, np.floating, np.integer))
        and not isinstance(value, bool)
        and math.isfinite(value)
    )
    cond = ""
    if positive:
        ok, cond = ok and value > 0, " > 0"
    elif nonnegative:
        ok, cond = ok and value >= 0, " >= 0"
    if not ok:
        raise ValueError(f"{name} must be a finite number{cond}, got {value!r}")


def _zeros(*arrays):
    shape = np.broadcast(*arrays).shape
    return np.zeros(shape)


def _wrap_pi(angle):
    """Angle wrapped to [-pi, pi)."""
    return (np.asarray(angle, dtype=float) + math.pi) % TWO_PI - math.pi


def smooth_step(xi):
    """Quintic smooth step S(xi) = 10 xi^3 - 15 xi^4 + 6 xi^5 on [0, 1] (0 below, 1 above), with S', S''.

    S is C2: S'(0) = S'(1) = S''(0) = S''(1) = 0.
    """
    xi = np.asarray(xi, dtype=float)
    t = np.clip(xi, 0.0, 1.0)
    inside = (xi > 0) & (xi < 1)
    s = t**3 * (10 - 15 * t + 6 * t * t)
    ds = np.where(inside, 30 * t * t * (1 - t) ** 2, 0.0)
    d2s = np.where(inside, 60 * t * (1 - t) * (1 - 2 * t), 0.0)
    return s, ds, d2s


# --------------------------------------------------------------------------------------------- wheel
@dataclass(frozen=True)
class HarmonicOutOfRoundness:
    """Harmonic out-of-roundness (polygonisation) of order n:  R_irr = A cos(n a + phi), uniform across the tread.

    Attributes:
        order: n, number of polygon sides (waves per revolution), integer >= 1.
        amplitude_m: A, m (>= 0).
        phase_rad: phi, rad.
    Several orders: pass several objects (their sum is used).
    """

    order: int
    amplitude_m: float
    phase_rad: float = 0.0

    def __post_init__(self):
        if not (isinstance(self.order, (int, np.integer)) and not isinstance(self.order, bool) and self.order >= 1):
            raise ValueError(f"order must be an integer >= 1, got {self.order!r}")
        _finite("amplitude_m", self.amplitude_m, nonnegative=True)
        _finite("phase_rad", self.phase_rad)

    def evaluate(self, angle_rad, y_m):
        a = np.asarray(angle_rad, dtype=float)
        z = _zeros(a, y_m)
        n, A = float(self.order), self.amplitude_m
        arg = n * a + self.phase_rad
        c, s = np.cos(arg) + z, np.sin(arg) + z
        return A * c, -A * n * s, z.copy(), -A * n * n * c, z.copy(), z.copy()


@dataclass(frozen=True)
class WheelFlat:
    """A wheel flat centred at angle a0, uniform across the tread.

    Shapes (s = r_w * wrap(a - a0): arc length from the flat centre, r_w the wheel radius):

    * ``"rounded"`` (after wear, the haversine shape used in the wheel-flat literature for flats that
      have run for some time, e.g. T.X. Wu & D.J. Thompson, "A hybrid model for the noise generation
      due to railway wheel flats", J. Sound Vib. 251 (2002) 115-139 -- cited from memory, the paper
      was not available here):
          R_irr = -(d/2) (1 + cos(2 pi s / L))   for |s| <= L/2, else 0,
      C1 at the ends; default depth d = L^2 / (16 r_w), the relation given in the project brief: it is
      the depth of a new (chord) flat of length L/sqrt(2), d = (L/sqrt 2)^2 / (8 r_w), i.e. rounding
      keeps the depth and lengthens the flat by sqrt(2). (A fresh chord flat of length L has
      d = L^2/(8 r_w), not L^2/(16 r_w).)
    * ``"new"`` (freshly worn chord): the wheel is cut by the plane at distance r_w - d from the axle:
          R_irr = (r_w - d) / cos(a - a0) - r_w   for |a - a0| <= theta/2, cos(theta/2) = (r_w - d)/r_w,
      with the exact chord depth d = r_w - sqrt(r_w^2 - L^2/4) (~ L^2/(8 r_w)) by default. Kinks at the
      edges (slope jumps), as for a real fresh flat.

    Attributes:
        length_m: L, m (> 0, < 2 r_w).
        wheel_radius_m: r_w, m (the nominal radius).
        depth_m: d, m; None derives it from L (see above).
        centre_angle_rad: a0, rad (pi/2 = at the bottom of the non-rotated wheel).
        shape: "rounded" or "new".
    """

    length_m: float
    wheel_radius_m: float
    depth_m: float | None = None
    centre_angle_rad: float = math.pi / 2
    shape: str = "rounded"

    def __post_init__(self):
        _finite("wheel_radius_m", self.wheel_radius_m, positive=True)
        _finite("length_m", self.length_m, positive=True)
        if self.length_m >= 2 * self.wheel_radius_m:
            raise ValueError(
                f"length_m must be < 2 * wheel_radius_m = {2 * self.wheel_radius_m}, got {self.length_m!r}"
            )
        _finite("centre_angle_rad", self.centre_angle_rad)
        if self.shape not in ("rounded", "new"):
            raise ValueError(f"shape must be 'rounded' or 'new', got {self.shape!r}")
        if self.depth_m is not None:
            _finite("depth_m", self.depth_m, positive=True)
            if self.depth_m >= self.wheel_radius_m:
                raise ValueError(f"depth_m must be < wheel_radius_m, got {self.depth_m!r}")

    @property
    def depth(self) -> float:
        """d, m (given or derived from the length)."""
        if self.depth_m is not None:
            return float(self.depth_m)
        r, L = self.wheel_radius_m, self.length_m
        if self.shape == "rounded":
            return L * L / (16.0 * r)
        return r - math.sqrt(r * r - L * L / 4.0)

    def evaluate(self, angle_rad, y_m):
        a = np.asarray(angle_rad, dtype=float)
        z = _zeros(a, y_m)
        da = _wrap_pi(a - self.centre_angle_rad) + z
        r, L, d = self.wheel_radius_m, self.length_m, self.depth
        if self.shape == "rounded":
            s = r * da
            inside = np.abs(s) <= L / 2
            k = TWO_PI / L
            v = np.where(inside, -0.5 * d * (1 + np.cos(k * s)), 0.0)
            va = np.where(inside, 0.5 * d * k * r * np.sin(k * s), 0.0)
            vaa = np.where(inside, 0.5 * d * (k * r) ** 2 * np.cos(k * s), 0.0)
        else:
            half = math.acos((r - d) / r)
            inside = np.abs(da) <= half
            c = np.cos(np.where(inside, da, 0.0))
            t = np.tan(np.where(inside, da, 0.0))
            f = (r - d) / c
            v = np.where(inside, f - r, 0.0)
            va = np.where(inside, f * t, 0.0)
            vaa = np.where(inside, f * (1 + 2 * t * t), 0.0)
        return v, va, z.copy(), vaa, z.copy(), z.copy()


def _check_grid(name, grid, minimum=4):
    g = np.asarray(grid, dtype=float)
    if g.ndim != 1 or g.size < minimum:
        raise ValueError(f"{name} must be a 1-D array with at least {minimum} values, got shape {g.shape}")
    if not np.all(np.isfinite(g)):
        raise ValueError(f"{name} must be finite")
    if np.any(np.diff(g) <= 0):
        raise ValueError(f"{name} must be strictly increasing")
    return g


@dataclass(frozen=True, eq=False)
class MeasuredWheelIrregularity:
    """Measured R_irr(a, y) on a grid, periodic in a: bicubic spline, periodic cubic in a, cubic (not-a-knot) in y.

    Attributes:
        angle_rad: a grid, shape (n_a,), strictly increasing, spanning less than 2 pi (the period is 2 pi;
            the value at angle_rad[0] + 2 pi is that at angle_rad[0]).
        y_m: lateral grid (wheel-profile y_p), shape (n_y,), strictly increasing, n_y >= 4.
        values_m: R_irr, shape (n_a, n_y), m.
    Outside [y_m[0], y_m[-1]] the irregularity is 0 (taper measured data to 0 at its lateral edges).
    """

    angle_rad: np.ndarray
    y_m: np.ndarray
    values_m: np.ndarray
    _spline_a: object = field(init=False, repr=False, compare=False)
    _basis_y: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        a = _check_grid("angle_rad", self.angle_rad)
        y = _check_grid("y_m", self.y_m)
        if a[-1] - a[0] >= TWO_PI:
            raise ValueError(f"angle_rad must span less than 2 pi (one period), spans {a[-1] - a[0]!r}")
        v = np.asarray(self.values_m, dtype=float)
        if v.shape != (a.size, y.size):
            raise ValueError(f"values_m must have shape (len(angle_rad), len(y_m)) = {(a.size, y.size)}, got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("values_m must be finite")
        # spline in y of each angle row -> coefficient rows; then periodic spline in a of the coefficients
        sy = make_interp_spline(y, v.T, k=3)  # coefficients (n_cy, n_a)
        coef = np.asarray(sy.c).T  # (n_a, n_cy)
        a_ext = np.append(a, a[0] + TWO_PI)
        coef_ext = np.vstack([coef, coef[:1]])
        sa = make_interp_spline(a_ext, coef_ext, k=3, bc_type="periodic")
        sa = BSpline(sa.t, sa.c, sa.k, extrapolate="periodic")
        basis = BSpline(sy.t, np.eye(coef.shape[1]), sy.k, extrapolate=False)
        for name, val in (("angle_rad", a), ("y_m", y), ("values_m", v)):
            val.setflags(write=False)
            object.__setattr__(self, name, val)
        object.__setattr__(self, "_spline_a", sa)
        object.__setattr__(self, "_basis_y", basis)

    def evaluate(self, angle_rad, y_m):
        """(R, R_a, R_y, R_aa, R_ay, R_yy) at the points: the bicubic spline's 4 x 4 coefficients nonzero at each
        point (compiled, geometry._bicubic); the same spline as ``_spline_a`` x ``_basis_y`` evaluated densely.
        """
        from rigid_dynamics.geometry._bicubic import evaluate_bicubic

        a, y = np.broadcast_arrays(np.asarray(angle_rad, dtype=float), np.asarray(y_m, dtype=float))
        shape = a.shape
        a, y = np.ascontiguousarray(a.ravel()), y.ravel()
        inside = (y >= self.y_m[0]) & (y <= self.y_m[-1])
        yc = np.clip(y, self.y_m[0], self.y_m[-1])
        sa, sy = self._spline_a, self._basis_y
        out = np.empty((6, a.size))
        evaluate_bicubic(sa.t, sy.t, np.ascontiguousarray(sa.c, float), True, a, yc, out)
        out[:, ~inside] = 0.0
        return tuple(row.reshape(shape) for row in out)


# --------------------------------------------------------------------------------------------- rail
@dataclass(frozen=True)
class RailCorrugation:
    """Sinusoidal rail corrugation over a lateral band with smooth (C2) tapers:

        N_irr(x, y) = A cos(2 pi x / lambda + phi) * w(y),
        w = 1 for |y - y_c| <= b,  w = 1 - S((|y - y_c| - b) / t) for b < |y - y_c| < b + t,  0 beyond,

    S the quintic smooth step (`smooth_step`). A > 0 at x = 0, phi = 0 lowers the rail there (z down).

    Attributes:
        wavelength_m: lambda, m (> 0). amplitude_m: A, m (>= 0). phase_rad: phi, rad.
        centre_y_m: y_c, lateral centre of the corrugated band in rail coordinates, m.
        half_width_m: b, half width of the fully corrugated band, m (>= 0).
        taper_m: t, length of each lateral taper, m (> 0).
    """

    wavelength_m: float
    amplitude_m: float
    phase_rad: float = 0.0
    centre_y_m: float = 0.0
    half_width_m: float = 0.015
    taper_m: float = 0.005

    def __post_init__(self):
        _finite("wavelength_m", self.wavelength_m, positive=True)
        _finite("amplitude_m", self.amplitude_m, nonnegative=True)
        _finite("phase_rad", self.phase_rad)
        _finite("centre_y_m", self.centre_y_m)
        _finite("half_width_m", self.half_width_m, nonnegative=True)
        _finite("taper_m", self.taper_m, positive=True)

    def lateral_weight(self, y_m):
        """(w, w', w'') of the lateral band at rail coordinate ``y_m``."""
        u = np.asarray(y_m, dtype=float) - self.centre_y_m
        sgn = np.where(u < 0, -1.0, 1.0)
        s, ds, d2s = smooth_step((np.abs(u) - self.half_width_m) / self.taper_m)
        return 1.0 - s, -sgn * ds / self.taper_m, -d2s / self.taper_m**2

    def evaluate(self, x_m, y_m):
        x, y = np.broadcast_arrays(np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))
        k = TWO_PI / self.wavelength_m
        A = self.amplitude_m
        c, s = np.cos(k * x + self.phase_rad), np.sin(k * x + self.phase_rad)
        w, dw, d2w = self.lateral_weight(y)
        return A * c * w, -A * k * s * w, A * c * dw, -A * k * k * c * w, -A * k * s * dw, A * c * d2w


@dataclass(frozen=True, eq=False)
class MeasuredRailIrregularity:
    """Measured N_irr(x, y) on a grid: interpolating bicubic spline (scipy RectBivariateSpline, s = 0).

    Attributes:
        x_m: longitudinal grid, shape (n_x,), strictly increasing, n_x >= 4.
        y_m: lateral grid (rail coordinate y_r), shape (n_y,), strictly increasing, n_y >= 4.
        values_m: N_irr, shape (n_x, n_y), m (z down: positive lowers the rail).
    Outside the grid the irregularity is 0 (taper measured data to 0 at its edges).
    """

    x_m: np.ndarray
    y_m: np.ndarray
    values_m: np.ndarray
    _spline: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        x = _check_grid("x_m", self.x_m)
        y = _check_grid("y_m", self.y_m)
        v = np.asarray(self.values_m, dtype=float)
        if v.shape != (x.size, y.size):
            raise ValueError(f"values_m must have shape (len(x_m), len(y_m)) = {(x.size, y.size)}, got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("values_m must be finite")
        for name, val in (("x_m", x), ("y_m", y), ("values_m", v)):
            val.setflags(write=False)
            object.__setattr__(self, name, val)
        object.__setattr__(self, "_spline", RectBivariateSpline(x, y, v, kx=3, ky=3, s=0))

    def evaluate(self, x_m, y_m):
        x, y = np.broadcast_arrays(np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))
        inside = (x >= self.x_m[0]) & (x <= self.x_m[-1]) & (y >= self.y_m[0]) & (y <= self.y_m[-1])
        out = []
        for dx, dy in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            val = self._spline.ev(x, y, dx=dx, dy=dy)
            out.append(np.where(inside, val, 0.0))
        return tuple(out)


@dataclass(frozen=True, eq=False)
class TabulatedRailDeflection:
    """Rail deflection N_d(x) from a table: interpolating cubic spline (not-a-knot); constant beyond the ends.

    Attributes:
        x_m: positions, shape (n,), strictly increasing, n >= 4. deflection_m: N_d, shape (n,), m (positive down).
    """

    x_m: np.ndarray
    deflection_m: np.ndarray
    _spline: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        x = _check_grid("x_m", self.x_m)
        d = np.asarray(self.deflection_m, dtype=float)
        if d.shape != x.shape or not np.all(np.isfinite(d)):
            raise ValueError(f"deflection_m must be finite with the shape of x_m {x.shape}, got {d.shape}")
        for name, val in (("x_m", x), ("deflection_m", d)):
            val.setflags(write=False)
            object.__setattr__(self, name, val)
        object.__setattr__(self, "_spline", make_interp_spline(x, d, k=3))

    def evaluate(self, x_m):
        x = np.asarray(x_m, dtype=float)
        xc = np.clip(x, self.x_m[0], self.x_m[-1])
        inside = (x >= self.x_m[0]) & (x <= self.x_m[-1])
        return (
            self._spline(xc),
            np.where(inside, self._spline(xc, nu=1), 0.0),
            np.where(inside, self._spline(xc, nu=2), 0.0),
        )


@dataclass(frozen=True)
class WinklerRailDeflection:
    """Static deflection of a rail (Euler-Bernoulli beam on a Winkler foundation) under a point load.

        N_d(x) = F beta / (2 k) e^{-u} (cos u + sin u),   u = beta |x - x_F|,   beta = (k / (4 E I))^{1/4}

    (M. Hetenyi, "Beams on Elastic Foundation", 1946; S. Timoshenko, "Strength of Materials" II).
    Positive down (the load pushes the rail down, N grows). Derivatives:
    N_d' = -(F beta^2 / k) sgn(x - x_F) e^{-u} sin u,  N_d'' = -(F beta^3 / k) e^{-u} (cos u - sin u).

    Attributes:
        load_N: F, vertical load on the rail, N (>= 0, pushing down).
        load_position_m: x_F, m.
        bending_stiffness_Nm2: E I of the rail, N m^2 (> 0; 60E1 about the horizontal axis: 210 GPa * 3038 cm^4
            = 6.38e6 N m^2).
        foundation_modulus_N_per_m2: k, support stiffness per unit length of rail, N/m^2 (> 0).
    """

    load_N: float
    load_position_m: float
    bending_stiffness_Nm2: float
    foundation_modulus_N_per_m2: float

    def __post_init__(self):
        _finite("load_N", self.load_N, nonnegative=True)
        _finite("load_position_m", self.load_position_m)
        _finite("bending_stiffness_Nm2", self.bending_stiffness_Nm2, positive=True)
        _finite("foundation_modulus_N_per_m2", self.foundation_modulus_N_per_m2, positive=True)

    @property
    def beta_1_per_m(self) -> float:
        """Beta = (k / (4 E I))^{1/4}, 1/m."""
        return (self.foundation_modulus_N_per_m2 / (4.0 * self.bending_stiffness_Nm2)) ** 0.25

    def evaluate(self, x_m):
        xi = np.asarray(x_m, dtype=float) - self.load_position_m
        b, k, F = self.beta_1_per_m, self.foundation_modulus_N_per_m2, self.load_N
        u = b * np.abs(xi)
        e = np.exp(-u)
        c, s = np.cos(u), np.sin(u)
        sgn = np.sign(xi)
        w = F * b / (2 * k) * e * (c + s)
        dw = -(F * b * b / k) * sgn * e * s
        d2w = -(F * b**3 / k) * e * (c - s)
        return w, dw, d2w
