"""Analytic standard profiles: S1002 wheel, UIC60 (60E1) rail, conical and circular wheels and rails.

All curves use the internal profile convention (y_p towards the field side, z_p down; wheel origin
at the tape circle, rail z_p = 0 at the top on the centre line) and evaluate z_p and its first and
second derivatives exactly (closed forms), vectorised: ``z(y_m, derivative)``, ``evaluate(y_m)``,
``y_min_m``, ``y_max_m``, ``kind``, ``to_profile(spacing_m)``. They can be passed directly to
`WheelsetGeometry` / `TrackGeometry` (exact surfaces) or sampled into a `Profile`.

S1002 (EN 13715; UIC 510-2). Eight sections A..H of polynomials and circular arcs, with S the
lateral coordinate in mm from the tape circle (flange at S < 0) and F(S) the height in mm, positive
downwards (towards the rail), exactly the internal convention:

    A:  60        >= S >= 32.15796       F = AA - BA S
    B:  32.15796  >= S >= -26            F = AB - BB S + CB S^2 - DB S^3 + EB S^4 - FB S^5 + GB S^6 - HB S^7 + IB S^8
    C:  -26       >= S >= -35            F = -AC - BC S - CC S^2 - DC S^3 - EC S^4 - FC S^5 - GC S^6 - HC S^7
    D:  -35       >= S >= -38.426669071  F = AD - sqrt(BD^2 - (S + CD)^2)     (R13 flange root)
    E:  -38.426669071 >= S >= -39.764473993   F = -AE - BE S               (flange flank, 70 deg)
    F:  -39.764473993 >= S >= -49.662510381   F = AF + sqrt(BF^2 - (S + CF)^2)   (R20)
    G:  -49.662510381 >= S >= -62.764705882   F = AG + sqrt(BG^2 - (S + CG)^2)   (R12 flange tip)
    H:  -62.764705882 >= S >= -70             F = AH + sqrt(BH^2 - (S + CH)^2)   (R20.5 flange back)

Coefficients: as published with the "wheelset" problem of the Test Set for IVP Solvers
(F. Mazzia, C. Magherini et al., Univ. Bari / CWI; problem contributed by H. Netter, DLR
Oberpfaffenhofen), the S1002 definition of UIC 510-2 / EN 13715 written as polynomials; read in a
public copy (repository path .../s1002 function "courtesy to Dr. H. Netter, DLR"). Key published
dimensions: flange height 28 mm (F(-55) = AG + BG = 28), flange thickness 32.5 mm measured 10 mm
above the tape circle (F(-37.5) = 10, flange back at S = -70).

UIC60 / 60E1 rail head (EN 13674-1): crown R300, then R80, then R13, each tangent to the previous,
then the side straight with inclination 1:20 (widening downwards). Break points at half widths
X1 = 20.456/2, X2 = 52.053/2 and X3 = 72.000/2 mm (head width 72 mm), as in the GENSYS
documentation "create_UIC60" (gensys.se, kpf/create_UIC60): centres
c1 = (0, 300), c2 = c1 + (300 - 80)(sin f1, -cos f1) with f1 = asin(X1/300),
c3 = c2 + (80 - 13)(sin f2, -cos f2) with f2 = asin((X2 - c2_y)/80), and the R13 arc ends at
|y| = X3, where its tangent is 1:20 from the vertical to 3.3e-4 rad (checked in the tests). The side is
continued ``side_depth_m`` (16 mm) further down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .profile import MIN_PROFILE_POINTS, CircularArcCurve, Profile, _outside

__all__ = [
    "ANALYTIC_PROFILES",
    "S1002_COEFFICIENTS",
    "S1002_SECTION_BOUNDS_MM",
    "ConicalWheelCurve",
    "S1002Curve",
    "UIC60Curve",
    "analytic_profile",
    "circular_rail",
    "circular_wheel",
    "conical_wheel",
    "s1002_wheel",
    "uic60_rail",
]

_MM = 1000.0

# S1002 coefficients (mm), see module docstring for the source.
S1002_COEFFICIENTS = {
    "AA": 1.364323640,
    "BA": 0.066666667,
    "AB": 0.000000000,
    "BB": 3.358537058e-02,
    "CB": 1.565681624e-03,
    "DB": 2.810427944e-05,
    "EB": 5.844240864e-08,
    "FB": 1.562379023e-08,
    "GB": 5.309217349e-15,
    "HB": 5.957839843e-12,
    "IB": 2.646656573e-13,
    "AC": 4.320221063e03,
    "BC": 1.038384026e03,
    "CC": 1.065501873e02,
    "DC": 6.051367875,
    "EC": 2.054332446e-01,
    "FC": 4.169739389e-03,
    "GC": 4.687195829e-05,
    "HC": 2.252755540e-07,
    "AD": 16.446,
    "BD": 13.0,
    "CD": 26.210665,
    "AE": 93.576667419,
    "BE": 2.747477419,
    "AF": 8.834924130,
    "BF": 20.0,
    "CF": 58.558326413,
    "AG": 16.0,
    "BG": 12.0,
    "CG": 55.0,
    "AH": 9.519259302,
    "BH": 20.5,
    "CH": 49.5,
}
# section bounds in mm, ascending: H G F E D C B A
S1002_SECTION_BOUNDS_MM = (
    -70.0,
    -62.764705882,
    -49.662510381,
    -39.764473993,
    -38.426669071,
    -35.0,
    -26.0,
    32.15796,
    60.0,
)


def _poly3(coef_ascending, s):
    """p(s), p'(s), p''(s) for ascending coefficients."""
    p = np.polynomial.polynomial
    c = np.asarray(coef_ascending, float)
    return p.polyval(s, c), p.polyval(s, p.polyder(c)), p.polyval(s, p.polyder(c, 2))


def _arc3(a, b, c, s, sign):
    """F = a + sign*sqrt(b^2 - (s + c)^2) and its two derivatives."""
    u = s + c
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(np.maximum(b * b - u * u, 0.0))
        return a + sign * root, -sign * u / root, -sign * b * b / root**3


class _AnalyticCurve:
    """Shared evaluation helpers: subclasses implement _mm(s) -> (F, F', F'') in mm units."""

    kind = "wheel"

    def _eval_all(self, y):
        y = np.asarray(y, dtype=float)
        outside = _outside(y, self.y_min_m, self.y_max_m)
        F, dF, d2F = self._mm(np.clip(y, self.y_min_m, self.y_max_m) * _MM)
        nan = np.nan
        return (
            np.where(outside, nan, F / _MM),
            np.where(outside, nan, dF),
            np.where(outside, nan, d2F * _MM),
        )

    def z(self, y_m, derivative: int = 0):
        """z_p (m), dz_p/dy_p (-) or d2z_p/dy_p2 (1/m) at y_p = ``y_m``; NaN outside [y_min_m, y_max_m]."""
        if derivative not in (0, 1, 2):
            raise ValueError(f"derivative must be 0, 1 or 2, got {derivative!r}")
        return self._eval_all(y_m)[derivative]

    def evaluate(self, y_m):
        """(z_p, dz_p/dy_p, d2z_p/dy_p2) at y_p = ``y_m``."""
        return self._eval_all(y_m)

    def to_profile(self, spacing_m: float = 5e-5, name: str | None = None) -> Profile:
        """Sample into a `Profile` with points every ``spacing_m`` (m) in y."""
        if not (math.isfinite(spacing_m) and spacing_m > 0):
            raise ValueError(f"spacing_m must be a finite number > 0 (m), got {spacing_m!r}")
        n = max(MIN_PROFILE_POINTS, int(math.ceil((self.y_max_m - self.y_min_m) / spacing_m)) + 1)
        y = np.linspace(self.y_min_m, self.y_max_m, n)
        return Profile(y, self.z(y), self.kind, name or self.name, f"analytic: {self!r}")


@dataclass(frozen=True)
class S1002Curve(_AnalyticCurve):
    """S1002 wheel profile (EN 13715), exact piecewise definition (module docstring).

    Attributes:
        y_min_m: lower end of the domain, m (-69.9 mm: at -70 mm, the flange back, the slope is infinite).
        y_max_m: upper end, m (60 mm, end of section A).
    """

    y_min_m: float = -0.0699
    y_max_m: float = 0.060
    kind = "wheel"
    name = "S1002"

    def __post_init__(self):
        lo, hi = S1002_SECTION_BOUNDS_MM[0] / _MM, S1002_SECTION_BOUNDS_MM[-1] / _MM
        if not (lo < self.y_min_m < self.y_max_m <= hi):
            raise ValueError(
                f"S1002 domain must satisfy {lo} < y_min_m < y_max_m <= {hi} (m), got [{self.y_min_m}, {self.y_max_m}]"
            )

    def _mm(self, s):
        k = S1002_COEFFICIENTS
        b = S1002_SECTION_BOUNDS_MM
        sections = [
            _arc3(k["AH"], k["BH"], k["CH"], s, +1.0),
            _arc3(k["AG"], k["BG"], k["CG"], s, +1.0),
            _arc3(k["AF"], k["BF"], k["CF"], s, +1.0),
            _poly3([-k["AE"], -k["BE"]], s),
            _arc3(k["AD"], k["BD"], k["CD"], s, -1.0),
            _poly3([-k["AC"], -k["BC"], -k["CC"], -k["DC"], -k["EC"], -k["FC"], -k["GC"], -k["HC"]], s),
            _poly3([k["AB"], -k["BB"], k["CB"], -k["DB"], k["EB"], -k["FB"], k["GB"], -k["HB"], k["IB"]], s),
            _poly3([k["AA"], -k["BA"]], s),
        ]
        idx = np.clip(np.searchsorted(np.asarray(b), s, side="right") - 1, 0, 7)
        out = []
        for d in range(3):
            stacked = np.stack([np.broadcast_to(sec[d], np.shape(s)) for sec in sections])
            out.append(np.take_along_axis(stacked, idx[None, ...], axis=0)[0])
        return tuple(out)


def _uic60_geometry():
    """Centres and break points of the 60E1 head (mm, y lateral, z down), GENSYS construction."""
    r1, r2, r3 = 300.0, 80.0, 13.0
    x1, x2, x3 = 20.456 / 2, 52.053 / 2, 72.000 / 2
    c1 = (0.0, r1)
    f1 = math.asin(x1 / r1)
    c2 = (c1[0] + (r1 - r2) * math.sin(f1), c1[1] - (r1 - r2) * math.cos(f1))
    f2 = math.asin((x2 - c2[0]) / r2)
    c3 = (c2[0] + (r2 - r3) * math.sin(f2), c2[1] - (r2 - r3) * math.cos(f2))
    f3 = math.asin((x3 - c3[0]) / r3)
    p4 = (c3[0] + r3 * math.sin(f3), c3[1] - r3 * math.cos(f3))
    return {"radii": (r1, r2, r3), "breaks": (x1, x2, x3), "centres": (c1, c2, c3), "side_start": p4, "f3": f3}


UIC60_HEAD = _uic60_geometry()
UIC60_SIDE_INCLINATION = 1.0 / 20.0


@dataclass(frozen=True)
class UIC60Curve(_AnalyticCurve):
    """UIC60 / 60E1 rail head (EN 13674-1), symmetric, not canted (module docstring).

    z_p(y) for |y| <= X1: R300 arc; X1..X2: R80; X2..X3: R13; beyond X3 the 1:20 side
    z = z_4 + (|y| - X3) * 20 down to ``side_depth_m`` below the side start.

    Attributes:
        side_depth_m: how far the straight 1:20 side is continued below the end of the R13 arc, m.
    """

    side_depth_m: float = 0.016
    kind = "rail"
    name = "UIC60"

    def __post_init__(self):
        if not (math.isfinite(self.side_depth_m) and 0 <= self.side_depth_m <= 0.03):
            raise ValueError(f"side_depth_m must be in [0, 0.03] m, got {self.side_depth_m!r}")

    @property
    def y_max_m(self) -> float:
        return (UIC60_HEAD["side_start"][0] + self.side_depth_m * _MM * UIC60_SIDE_INCLINATION) / _MM

    @property
    def y_min_m(self) -> float:
        return -self.y_max_m

    def _mm(self, s):
        (c1, c2, c3), (x1, x2, x3) = UIC60_HEAD["centres"], UIC60_HEAD["breaks"]
        r1, r2, r3 = UIC60_HEAD["radii"]
        a = np.abs(s)
        sgn = np.where(s < 0, -1.0, 1.0)
        secs = [
            _arc3(c1[1], r1, -c1[0], a, -1.0),
            _arc3(c2[1], r2, -c2[0], a, -1.0),
            _arc3(c3[1], r3, -c3[0], a, -1.0),
        ]
        z4 = UIC60_HEAD["side_start"][1]
        k = 1.0 / UIC60_SIDE_INCLINATION
        secs.append((z4 + k * (a - x3), np.full_like(a, k), np.zeros_like(a)))
        idx = np.searchsorted(np.array([x1, x2, x3]), a, side="right")
        out = []
        for d in range(3):
            stacked = np.stack([np.broadcast_to(sec[d], np.shape(a)) for sec in secs])
            v = np.take_along_axis(stacked, idx[None, ...], axis=0)[0]
            out.append(v * sgn if d == 1 else v)  # z even in y: z' odd, z'' even
        return tuple(out)


@dataclass(frozen=True)
class ConicalWheelCurve(_AnalyticCurve):
    """Conical wheel tread: z_p = -conicity * y_p (the radius R = r0 + z_p falls towards the field side).

    Attributes:
        conicity: lambda = tan(cone angle), - (e.g. 1/40, 1/20).
        y_min_m, y_max_m: lateral extent of the tread, m (must contain 0, the tape circle).
    """

    conicity: float
    y_min_m: float = -0.050
    y_max_m: float = 0.060
    kind = "wheel"

    def __post_init__(self):
        if not (math.isfinite(self.conicity) and 0 <= self.conicity < 1):
            raise ValueError(f"conicity must be a finite number in [0, 1), got {self.conicity!r}")
        if not (math.isfinite(self.y_min_m) and math.isfinite(self.y_max_m) and self.y_min_m < 0 < self.y_max_m):
            raise ValueError(f"need y_min_m < 0 < y_max_m (m), got [{self.y_min_m!r}, {self.y_max_m!r}]")

    @property
    def name(self) -> str:
        return f"conical_{self.conicity:g}"

    def _mm(self, s):
        return -self.conicity * s, np.full_like(s, -self.conicity), np.zeros_like(s)


def s1002_wheel() -> S1002Curve:
    """The S1002 wheel profile curve (exact)."""
    return S1002Curve()


def uic60_rail(side_depth_m: float = 0.016) -> UIC60Curve:
    """The UIC60 / 60E1 rail head curve (exact, not canted)."""
    return UIC60Curve(side_depth_m)


def conical_wheel(conicity: float, y_min_m: float = -0.050, y_max_m: float = 0.060) -> ConicalWheelCurve:
    """A conical wheel tread of the given conicity (no flange)."""
    return ConicalWheelCurve(conicity, y_min_m, y_max_m)


def circular_wheel(radius_m: float, half_width_m: float = 0.05) -> CircularArcCurve:
    """A crowned wheel whose profile is a circle of ``radius_m`` (convex, apex at the tape circle)."""
    return CircularArcCurve(radius_m, half_width_m, "wheel")


def circular_rail(radius_m: float, half_width_m: float = 0.04) -> CircularArcCurve:
    """A rail head whose profile is a circle of ``radius_m`` (convex, apex at the top)."""
    return CircularArcCurve(radius_m, half_width_m, "rail")


# name -> (description, factory returning a sampled Profile)
ANALYTIC_PROFILES = {
    "S1002": (
        "S1002 wheel, EN 13715, from its analytic definition (sampled every 0.05 mm)",
        lambda: s1002_wheel().to_profile(),
    ),
    "UIC60": (
        "UIC60 / 60E1 rail, EN 13674-1 head arcs R300/R80/R13 and 1:20 sides (sampled every 0.05 mm)",
        lambda: uic60_rail().to_profile(),
    ),
    "60E1": ("alias of UIC60", lambda: uic60_rail().to_profile(name="60E1")),
}

_CURVES = {"s1002": s1002_wheel, "uic60": uic60_rail, "60e1": uic60_rail}


def analytic_profile(name: str):
    """The exact curve of an analytic built-in profile ("S1002", "UIC60", "60E1"), case-insensitive."""
    key = str(name).lower()
    if key not in _CURVES:
        raise ValueError(f"unknown analytic profile {name!r}; expected one of {sorted(ANALYTIC_PROFILES)}")
    return _CURVES[key]()
