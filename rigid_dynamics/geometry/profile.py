"""Wheel and rail profiles: the validated point set (`Profile`) and its smooth curve (`ProfileCurve`).

Profile coordinates (internal convention, fixed by the project):

* y_p lateral, increasing towards the FIELD side (away from the flange / the gauge face);
* z_p vertical, pointing DOWN (as in SIMPACK, MiniProf and CONTACT files);
* wheel: y_p = 0 at the tape circle (nominal rolling circle), z_p = 0 there; the flange is at
  negative y_p and reaches positive z_p (down, towards the rail);
* rail: y_p = 0 at the rail-head centre line (or the file's own lateral reference), z_p = 0 at
  the top; the gauge face is at negative y_p; the rail material is at z_p > z_p(y_p).

Symbols: y_p -> ``y_m`` (m), z_p -> ``z_m`` (m).

The curve z_p(y_p) is a cubic spline (C2: continuous slope and curvature):

* ``smoothing_wavelength_m = 0``: interpolating cubic spline with not-a-knot end conditions
  (scipy ``make_interp_spline``): reproduces exact (e.g. analytic) data to O(h^4).
* ``smoothing_wavelength_m = L > 0``: weighted penalised smoothing spline (scipy
  ``make_smoothing_spline``), minimising

      sum_i w_i (z_i - f(y_i))^2 + lambda * integral f''(y)^2 dy,   w_i = (y_{i+1} - y_{i-1}) / 2,
      lambda = (L / (2 pi))^4,

  which is the discrete form of a low-pass filter with transfer 1 / (1 + lambda k^4) for the
  wavenumber k = 2 pi / wavelength: ripples with wavelength L are halved, longer ones kept,
  shorter ones suppressed as (wavelength / L)^4. The spacing weights make the result independent
  of the sampling density. Idea after the weighted smoothing spline of the CONTACT user guide
  (E.A.H. Vollebregt, "User guide for CONTACT", Vtech CMCC, report 20-01, section on profile
  smoothing; L_filt there). The natural end conditions of this spline force f'' -> 0 at the two
  ends of the profile; curvature within about L of an end is therefore not reliable.

Measured profiles carry measurement noise of ~0.01 mm at ~0.3 mm spacing; an interpolating
spline turns that into curvature noise of order 0.1 1/mm (radius 10 mm) and rings. The default
``DEFAULT_SMOOTHING_WAVELENGTH_M`` = 2 mm suppresses that noise while keeping the 13 mm and larger
radii of standard profiles (their curvature is changed by far less than 1 % away from the arc
junctions, where it is smeared over about L).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_interp_spline, make_smoothing_spline

__all__ = [
    "DEFAULT_SMOOTHING_WAVELENGTH_M",
    "MIN_PROFILE_POINTS",
    "PROFILE_KINDS",
    "Profile",
    "ProfileCurve",
    "CircularArcCurve",
    "find_self_intersection",
]

PROFILE_KINDS = ("wheel", "rail")
MIN_PROFILE_POINTS = 5
DEFAULT_SMOOTHING_WAVELENGTH_M = 0.002
_MM_PER_M = 1000.0


def _as_1d_float(values, name):
    try:
        arr = np.array(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a 1-D array of numbers, got {values!r:.80}") from exc
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    arr.setflags(write=False)
    return arr


def find_self_intersection(y, z):
    """Indices (i, j) of the first pair of non-adjacent polyline segments that touch or cross, else None.

    The polyline is P_0 ... P_{n-1}; segment i joins P_i and P_{i+1}. Segments that share an end
    point (|i - j| = 1) are not tested. Uses the orientation (cross-product) test, chunked so that
    memory stays O(n * chunk).

    Args:
        y, z: coordinates, shape (n,), any length unit.

    Returns:
        tuple[int, int] | None.
    """
    p = np.column_stack([np.asarray(y, float), np.asarray(z, float)])
    n_seg = len(p) - 1
    if n_seg < 3:
        return None
    a, b = p[:-1], p[1:]
    scale = max(np.ptp(p[:, 0]), np.ptp(p[:, 1]), 1e-300)
    eps = 1e-12 * scale * scale

    def orient(p1, p2, q):
        return (p2[..., 0] - p1[..., 0]) * (q[..., 1] - p1[..., 1]) - (p2[..., 1] - p1[..., 1]) * (
            q[..., 0] - p1[..., 0]
        )

    chunk = 256
    idx_all = np.arange(n_seg)
    for start in range(0, n_seg, chunk):
        ii = idx_all[start : start + chunk]
        ai, bi = a[ii][:, None, :], b[ii][:, None, :]
        aj, bj = a[None, :, :], b[None, :, :]
        # bounding-box prefilter
        box = (
            (np.minimum(ai[..., 0], bi[..., 0]) <= np.maximum(aj[..., 0], bj[..., 0]))
            & (np.minimum(aj[..., 0], bj[..., 0]) <= np.maximum(ai[..., 0], bi[..., 0]))
            & (np.minimum(ai[..., 1], bi[..., 1]) <= np.maximum(aj[..., 1], bj[..., 1]))
            & (np.minimum(aj[..., 1], bj[..., 1]) <= np.maximum(ai[..., 1], bi[..., 1]))
        )
        box &= np.abs(ii[:, None] - idx_all[None, :]) >= 2
        if not box.any():
            continue
        ci, cj = np.nonzero(box)
        gi, gj = ii[ci], cj
        d1 = orient(a[gj], b[gj], a[gi])
        d2 = orient(a[gj], b[gj], b[gi])
        d3 = orient(a[gi], b[gi], a[gj])
        d4 = orient(a[gi], b[gi], b[gj])
        d1, d2, d3, d4 = (np.where(np.abs(d) <= eps, 0.0, d) for d in (d1, d2, d3, d4))
        hit = (d1 * d2 <= 0) & (d3 * d4 <= 0)
        if hit.any():
            k = int(np.argmax(hit))
            return int(min(gi[k], gj[k])), int(max(gi[k], gj[k]))
    return None


@dataclass(frozen=True, eq=False)
class Profile:
    """A wheel or rail profile as points z_p(y_p) in the internal profile convention (module docstring).

    Attributes:
        y_m: y_p, lateral coordinate, m, shape (n,), strictly increasing, n >= 5.
        z_m: z_p, vertical coordinate (down), m, shape (n,).
        kind: "wheel" or "rail".
        name: short name (file stem or built-in name).
        source: where the points came from and what was done to them (file, conversions, trimming).
        outline_y_m, outline_z_m: optional full outline in the same coordinates, including the parts
            trimmed away because they were vertical or overhanging (shape (m,), or empty). Useful for
            meshing and for gauge measurement; must not self-intersect.
        cant_rad: cant of the rail already contained in the points (rail profiles), rad: the rail is placed
            in the track with the inclination the case asks for minus this. 0 unless stated (readers.py:
            built-in profiles carry their own; a file's is its user's to state).

    Equality and hashing are by identity (the arrays are read-only).

    Raises:
        ValueError: non-finite points, unsorted or duplicate abscissae, fewer than 5 points,
            shape mismatch, unknown kind, self-intersecting outline.
    """

    y_m: np.ndarray
    z_m: np.ndarray
    kind: str
    name: str = "profile"
    source: str = ""
    outline_y_m: np.ndarray = field(default_factory=lambda: np.zeros(0))
    outline_z_m: np.ndarray = field(default_factory=lambda: np.zeros(0))
    cant_rad: float = 0.0

    def __post_init__(self):
        if not (isinstance(self.cant_rad, (int, float)) and math.isfinite(self.cant_rad) and abs(self.cant_rad) < 0.2):
            raise ValueError(f"cant_rad = {self.cant_rad!r}: expected a finite angle with |angle| < 0.2 rad")
        if self.kind not in PROFILE_KINDS:
            raise ValueError(f"kind must be one of {PROFILE_KINDS}, got {self.kind!r}")
        y = _as_1d_float(self.y_m, "y_m")
        z = _as_1d_float(self.z_m, "z_m")
        if y.shape != z.shape:
            raise ValueError(f"y_m and z_m must have the same length, got {y.size} and {z.size}")
        if y.size < MIN_PROFILE_POINTS:
            raise ValueError(f"profile {self.name!r} has {y.size} points; at least {MIN_PROFILE_POINTS} are needed")
        bad = ~(np.isfinite(y) & np.isfinite(z))
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(
                f"profile {self.name!r}: point {i} is not finite (y_m={y[i]!r}, z_m={z[i]!r}); "
                "all points must be finite"
            )
        dy = np.diff(y)
        if (dy == 0).any():
            i = int(np.argmax(dy == 0))
            raise ValueError(
                f"profile {self.name!r}: duplicate abscissa y_m={y[i]!r} at points {i} and {i + 1}; "
                "y_m must be strictly increasing"
            )
        if (dy < 0).any():
            i = int(np.argmax(dy < 0))
            raise ValueError(
                f"profile {self.name!r}: y_m is not sorted (y_m[{i}]={y[i]!r} > y_m[{i + 1}]={y[i + 1]!r}); "
                "y_m must be strictly increasing"
            )
        oy = _as_1d_float(self.outline_y_m, "outline_y_m")
        oz = _as_1d_float(self.outline_z_m, "outline_z_m")
        if oy.shape != oz.shape:
            raise ValueError(f"outline_y_m and outline_z_m must have the same length, got {oy.size} and {oz.size}")
        if oy.size:
            if not (np.isfinite(oy).all() and np.isfinite(oz).all()):
                raise ValueError(f"profile {self.name!r}: outline has non-finite points")
            hit = find_self_intersection(oy, oz)
            if hit is not None:
                raise ValueError(
                    f"profile {self.name!r}: outline intersects itself (segments {hit[0]} and {hit[1]}, "
                    f"near y_m={oy[hit[0]]:.6g}, z_m={oz[hit[0]]:.6g}); a profile must be a simple curve"
                )
        object.__setattr__(self, "y_m", y)
        object.__setattr__(self, "z_m", z)
        object.__setattr__(self, "outline_y_m", oy)
        object.__setattr__(self, "outline_z_m", oz)

    @property
    def y_min_m(self) -> float:
        return float(self.y_m[0])

    @property
    def y_max_m(self) -> float:
        return float(self.y_m[-1])

    def curve(self, smoothing_wavelength_m: float = DEFAULT_SMOOTHING_WAVELENGTH_M) -> ProfileCurve:
        """The smooth curve z_p(y_p) through (or near) these points; see `ProfileCurve`."""
        return ProfileCurve(self, smoothing_wavelength_m)


_RESAMPLE_SPACING_MM = 0.05


def _parametric_smoothing(y, z, wavelength_mm):
    """Smooth y(s), z(s) over the chord length s, resample every 0.05 mm, keep y strictly increasing."""
    ds = np.hypot(np.diff(y), np.diff(z))
    s = np.concatenate([[0.0], np.cumsum(ds)])
    w = np.empty_like(s)
    w[1:-1] = 0.5 * (s[2:] - s[:-2])
    w[0], w[-1] = 0.5 * ds[0], 0.5 * ds[-1]
    wbar = w.mean()
    lam = (wavelength_mm / (2.0 * np.pi)) ** 4 / wbar
    fy = make_smoothing_spline(s, y, w=w / wbar, lam=lam)
    fz = make_smoothing_spline(s, z, w=w / wbar, lam=lam)
    n = max(MIN_PROFILE_POINTS, int(np.ceil(s[-1] / _RESAMPLE_SPACING_MM)) + 1)
    sd = np.linspace(0.0, s[-1], n)
    ys, zs = fy(sd), fz(sd)
    keep = np.concatenate([[True], np.diff(np.maximum.accumulate(ys)) > 0])
    ys, zs = ys[keep], zs[keep]
    if ys.size < MIN_PROFILE_POINTS:
        raise ValueError("the smoothed profile is not a function of y; use a smaller smoothing_wavelength_m")
    return ys, zs


DOMAIN_TOLERANCE_M = 1e-12


def _outside(y, lo, hi):
    """True where y lies outside [lo, hi] by more than DOMAIN_TOLERANCE_M (rounding at the ends is accepted)."""
    return ~((y >= lo - DOMAIN_TOLERANCE_M) & (y <= hi + DOMAIN_TOLERANCE_M))


def _eval_checked(fun, y, derivative):
    if derivative not in (0, 1, 2):
        raise ValueError(f"derivative must be 0, 1 or 2, got {derivative!r}")
    return fun(np.asarray(y, dtype=float), derivative)


@dataclass(frozen=True, eq=False)
class ProfileCurve:
    """Smooth C2 curve z_p(y_p) of a `Profile`, with analytic first and second derivatives.

    ``z(y, derivative)`` returns z_p (m), dz_p/dy_p (-) or d2z_p/dy_p2 (1/m) at y_p (m), any array
    shape; outside [y_min_m, y_max_m] the result is NaN (the profile is not defined there).
    Spline choice and smoothing: see the module docstring.

    Attributes:
        profile: the points.
        smoothing_wavelength_m: L_filt, m; 0 = interpolating spline.
    """

    profile: Profile
    smoothing_wavelength_m: float = DEFAULT_SMOOTHING_WAVELENGTH_M
    _spline: object = field(init=False, repr=False, compare=False)
    _y_range: tuple = field(init=False, repr=False, compare=False)
    _knots: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if not isinstance(self.profile, Profile):
            raise ValueError(f"profile must be a Profile, got {type(self.profile).__name__}")
        L = self.smoothing_wavelength_m
        if not (isinstance(L, (int, float)) and np.isfinite(L) and L >= 0):
            raise ValueError(f"smoothing_wavelength_m must be a finite number >= 0 (m), got {L!r}")
        # fit in mm: better scaled normal equations
        y = self.profile.y_m * _MM_PER_M
        z = self.profile.z_m * _MM_PER_M
        if L > 0:
            y, z = _parametric_smoothing(y, z, L * _MM_PER_M)
        spline = make_interp_spline(y, z, k=3)
        object.__setattr__(self, "_spline", spline)
        object.__setattr__(self, "_y_range", (float(y[0]) / _MM_PER_M, float(y[-1]) / _MM_PER_M))
        object.__setattr__(self, "_knots", None if L > 0 else (y / _MM_PER_M, z / _MM_PER_M))

    @property
    def knots_m(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The profile's points (y_p, z_p) when the spline interpolates them (no smoothing), m; None when smoothed
        (the smoothed curve is then the profile's shape, measured on itself).
        """
        return self._knots

    @property
    def kind(self) -> str:
        return self.profile.kind

    @property
    def y_min_m(self) -> float:
        return self._y_range[0]

    @property
    def y_max_m(self) -> float:
        return self._y_range[1]

    def _eval(self, y, derivative):
        outside = _outside(y, self.y_min_m, self.y_max_m)
        y_mm = np.clip(y, self.y_min_m, self.y_max_m) * _MM_PER_M
        out = self._spline(y_mm, nu=derivative)
        # z[m](y[m]) = z_mm(1000 y)/1000: d^k/dy^k scales by 1000^(k-1)
        out = out * _MM_PER_M ** (derivative - 1)
        return np.where(outside, np.nan, out)

    def z(self, y_m, derivative: int = 0):
        """z_p (derivative=0, m), dz_p/dy_p (1, -) or d2z_p/dy_p2 (2, 1/m) at y_p = ``y_m``; NaN outside."""
        return _eval_checked(self._eval, y_m, derivative)

    def evaluate(self, y_m):
        """(z, dz/dy, d2z/dy2) at y_p = ``y_m`` in one call, each of the shape of ``y_m``."""
        y = np.asarray(y_m, dtype=float)
        return self._eval(y, 0), self._eval(y, 1), self._eval(y, 2)


@dataclass(frozen=True)
class CircularArcCurve:
    """Closed-form circular profile z_p(y_p) with exact derivatives (for tests and circular wheels/rails).

    z_p(y) = z0 + sign * (R - sqrt(R^2 - (y - y0)^2)),  |y - y0| <= half_width_m < R.
    A convex rail head (material below, z down) has sign = +1 (the surface drops away from the top);
    a convex (crowned) wheel tread has sign = -1 (the surface rises towards the axle away from the
    tape circle). Curvature at the apex: z'' = sign / R.

    Attributes:
        radius_m: R, m (> 0).
        half_width_m: half of the lateral extent, m (0 < half_width_m < R).
        kind: "wheel" (sign -1) or "rail" (sign +1).
        centre_y_m: y0, m. apex_z_m: z0, m.
    """

    radius_m: float
    half_width_m: float
    kind: str
    centre_y_m: float = 0.0
    apex_z_m: float = 0.0

    def __post_init__(self):
        if self.kind not in PROFILE_KINDS:
            raise ValueError(f"kind must be one of {PROFILE_KINDS}, got {self.kind!r}")
        if not (np.isfinite(self.radius_m) and self.radius_m > 0):
            raise ValueError(f"radius_m must be a finite number > 0 (m), got {self.radius_m!r}")
        if not (np.isfinite(self.half_width_m) and 0 < self.half_width_m < self.radius_m):
            raise ValueError(f"half_width_m must be in (0, radius_m={self.radius_m}) (m), got {self.half_width_m!r}")
        for name in ("centre_y_m", "apex_z_m"):
            if not np.isfinite(getattr(self, name)):
                raise ValueError(f"{name} must be finite (m), got {getattr(self, name)!r}")

    @property
    def sign(self) -> float:
        return 1.0 if self.kind == "rail" else -1.0

    @property
    def y_min_m(self) -> float:
        return self.centre_y_m - self.half_width_m

    @property
    def y_max_m(self) -> float:
        return self.centre_y_m + self.half_width_m

    def _eval(self, y, derivative):
        R = self.radius_m
        outside = _outside(y, self.y_min_m, self.y_max_m)
        u = np.clip(y, self.y_min_m, self.y_max_m) - self.centre_y_m
        with np.errstate(invalid="ignore"):
            root = np.sqrt(R * R - u * u)
            if derivative == 0:
                out = self.apex_z_m + self.sign * (R - root)
            elif derivative == 1:
                out = self.sign * u / root
            else:
                out = self.sign * R * R / root**3
        return np.where(outside, np.nan, out)

    def z(self, y_m, derivative: int = 0):
        """z_p and its derivatives at y_p = ``y_m`` (see `ProfileCurve.z`)."""
        return _eval_checked(self._eval, y_m, derivative)

    def evaluate(self, y_m):
        y = np.asarray(y_m, dtype=float)
        return self._eval(y, 0), self._eval(y, 1), self._eval(y, 2)

    def to_profile(self, spacing_m: float = 1e-4, name: str | None = None) -> Profile:
        """Sample the arc into a `Profile` (points every ``spacing_m`` in y)."""
        n = max(MIN_PROFILE_POINTS, int(np.ceil(2 * self.half_width_m / spacing_m)) + 1)
        y = np.linspace(self.y_min_m, self.y_max_m, n)
        return Profile(
            y,
            self.z(y),
            self.kind,
            name or f"circular_{self.kind}_R{self.radius_m * 1000:g}mm",
            f"CircularArcCurve(radius_m={self.radius_m}, half_width_m={self.half_width_m})",
        )
