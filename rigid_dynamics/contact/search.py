"""3-D wheel-rail contact search on real geometry (seed eq 5-11) with every patch's local geometry (eq 12-33).

For a wheelset pose (centre x_t, yaw psi, roll theta, spin angle phi) and one side, a grid of wheel points
(alpha, y_d) is mapped to the main frame (eq 7-8: x_w = C_D x_d + x_t) with the wheel's outward unit normal
n_w (eq 9; pointing out of the wheel, towards the rail). Eq 10-11 then ask for the distance h along the normal
to the rail surface z = N(x, y):

    f(h) = (x_w + h n_w)_z - N((x_w + h n_w)_x, (x_w + h n_w)_y) = 0,

solved for all grid points at once by Newton's method (f'(h) = n_z - N_x n_x - N_y n_y). h > 0 is a gap,
h < 0 an interpenetration (the rail's material is at z > N, the main z axis points down).

Every local minimum of h(alpha, y_d) on the grid below ``candidate_gap_m`` is refined by a damped Newton
iteration on (alpha, y_d) (gradient and Hessian of h by central differences of the vectorised distance
function, all candidates at once); where h is convex along the rolling direction but not across it (e.g. along
the conformal arcs of S1002's flange root and UIC60's gauge corner, both R13, where h is nearly flat) the step goes
down the gradient with a line search (first trial 5e-5 m, doubled while h decreases up to 3e-3 m, else halved to an
Armijo decrease); where it is concave along the rolling direction (between a wheel flat's edges) the step is 1e-3
times the gradient. Minima that
end in the same interpenetration region (h < 0 along the segment joining them) are merged, so tread and flange
contact give two patches and one patch is never counted twice. At each patch:

* normal n = -n_w (from the rail into the wheel), contact frame e_x = rolling direction (main x projected on the
  contact plane, eq 39-43), e_y = n x e_x, e_z = n;
* relative curvature D = (K_w - K_r)/2 (eq 33) from the wheel's and the rail's curvature tensors (curvature.py)
  in (e_x, e_y), split into A, B and the ellipse angle;
* approach q = -h_min (> 0 in contact); contact point = midpoint of the wheel point and its rail point;
* contact angle: angle of n from the track's upward vertical, positive when n tilts towards the track centre
  (large and positive at a flange contact on either side);
* the undeformed distance sampled on a grid of the contact plane (gap along n between the two surfaces, minus
  nothing: it is h(x, y) - q, negative where the undeformed bodies overlap) and the Hertz-validity test
  ``is_elliptic`` (see :func:`ellipticity_error`).

Speed. The ideal profiles of rigid_dynamics.geometry's surfaces (R_id(y_d), N_id(y)) are replaced for the search
by fine cubic-Hermite tables (:func:`fast_surfaces`, 20 um spacing, value error ~1e-14 m) and the grid evaluation
and the refinement then run in compiled numba kernels (_search_kernels.py): about 1 ms per side for the
S1002/UIC60 pair (benchmarks/results/search.md). The irregularities of the rolling angle (harmonic
out-of-roundness, wheel flats) and rail corrugation are added in the kernels in closed form (the formulas of
rigid_dynamics.geometry.irregularities), about 1.3 ms per side, equal to the numpy path on the exact surfaces
to ~1e-12 m in the approach (tests/test_search_irregular.py). Other surfaces (measured irregularity grids, rail
deflection, duck-typed surfaces) take the general numpy path with their own ``evaluate`` (6-10 ms per side).
The patch's point, normal and curvatures always come from the exact surfaces.
Option ``profile_only`` is the fast path for tables of ideal geometry without yaw: alpha is fixed at the lowest
point and only y_d is searched (the problem reduces to the two profiles).

Gap field. By default (``field_scale`` None) the sampled undeformed distance is fitted to the rigid-overlap
region h < 0 actually found: it starts at +-1.6 times the quadric's overlap semi-axes sqrt(q/A), sqrt(q/B)
(at least +-1 mm), pushes out every side the overlap touches, then shrinks to the overlap's extent plus
``field_margin`` (25 %) of it on each side and two sample spacings, so long non-elliptic patches (e.g. the
Manchester A-2.2 tread patch at zero shift) are not truncated. A number ``field_scale`` gives the fixed box
+-field_scale times the quadric semi-axes (for Hertz, a^2 ~ q/(2A)). ``field_points`` (31) per direction.

Surfaces are duck-typed (rigid_dynamics.geometry provides them): the wheel's ``evaluate(alpha, y_d)`` returns R
and its first and second partial derivatives (R, R_a, R_y, R_aa, R_ay, R_yy) in the wheelset frame; the rail's
``evaluate(x, y)`` returns (N, N_x, N_y, N_xx, N_xy, N_yy) in the main frame.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from rigid_dynamics.contact.curvature import curvature_tensor, principal_relative_curvature, relative_curvature
from rigid_dynamics.contact.types import ContactGeometry, UndeformedDistance
from rigid_dynamics.kinematics import wheelset_rotation

SIDES = ("left", "right")
_FAR_M = 0.05  # |h| beyond this is not a contact candidate (another branch of the rail surface, or far away)

DEFAULT_OPTIONS: dict = {
    "alpha_half_range_rad": 0.10,  # grid of alpha around the lowest point
    "alpha_points": 11,
    "lateral_step_m": 1.0e-3,  # grid step along the axle
    "candidate_gap_m": 2.0e-3,  # grid minima above this gap are not refined
    "newton_iterations": 8,  # distance (eq 11)
    "refine_iterations": 12,
    "refine_tolerance_m": 1.0e-9,
    "field": True,  # sample the undeformed distance
    "field_points": 31,  # per direction
    "field_scale": None,  # None: fitted to the rigid overlap (see _fitted_field); a number: fixed half-size =
    # field_scale x the rigid-overlap semi-axes sqrt(q/A), sqrt(q/B)
    "field_margin": 0.25,  # fitted field: margin on each side of the overlap, as a fraction of its extent
    "field_min_half_size_m": 1.0e-3,
    "ellipticity_tolerance": 0.2,
    "rolling_direction": (1.0, 0.0, 0.0),  # eq 39: main x
    "profile_only": False,  # fast path for ideal geometry: alpha fixed at the lowest point, search in y_d only
}


@dataclass(frozen=True)
class WheelsetPose:
    """Position and orientation of the wheelset.

    Attributes:
        x_m, y_m, z_m: centre x_t in the main frame (z down; z ~ -r0 on the rails), m.
        yaw_rad: psi. roll_rad: theta. spin_rad: phi (eq 1), rad.
    """

    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    yaw_rad: float = 0.0
    roll_rad: float = 0.0
    spin_rad: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x_m", "y_m", "z_m", "yaw_rad", "roll_rad", "spin_rad"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")

    @property
    def centre_m(self) -> np.ndarray:
        return np.array([self.x_m, self.y_m, self.z_m])

    @property
    def rotation(self) -> np.ndarray:
        """C_D (eq 1)."""
        return wheelset_rotation(self.yaw_rad, self.roll_rad, self.spin_rad)


@dataclass(frozen=True, eq=False)
class ContactCandidates:
    """All refined local minima of h on one side (including those not in contact).

    Attributes:
        alpha_rad, lateral_m: wheel parameters (alpha, y_d) of each minimum, shape (k,).
        gap_m: h at each minimum (negative: interpenetration), shape (k,).
        converged: whether the refinement converged, shape (k,).
    """

    alpha_rad: np.ndarray
    lateral_m: np.ndarray
    gap_m: np.ndarray
    converged: np.ndarray


@dataclass(frozen=True, eq=False)
class SideSearch:
    """Contact search result of one side.

    Attributes:
        side: "left" or "right".
        success, status, message: status "ok", "no-contact" (every minimum has a gap: no patch) or
            "not-converged" (a refinement did not converge; its patch is still returned).
        patches: one :class:`ContactGeometry` per interpenetration region, deepest first.
        candidates: all refined minima.
        min_gap_m: smallest h found (negative when in contact), m.
        wheel_parameters: (alpha, y_d) of each patch, shape (n_patches, 2).
        wall_time_s: s.
    """

    side: str
    success: bool
    status: str
    message: str
    patches: list[ContactGeometry]
    candidates: ContactCandidates
    min_gap_m: float
    wheel_parameters: np.ndarray
    wall_time_s: float = 0.0
    extra: dict = field(default_factory=dict)


def _merge_options(options: Mapping | None) -> dict:
    merged = dict(DEFAULT_OPTIONS)
    for key, value in (options or {}).items():
        if key not in DEFAULT_OPTIONS:
            raise ValueError(f"contact search option {key!r}: expected one of {', '.join(DEFAULT_OPTIONS)}")
        merged[key] = value
    return merged


class _LateralTable:
    """Cubic Hermite table of a function of y alone: value and slope exact at the nodes, curvature linear.

    Error of the value O(dy^4 |f^(4)|), of the slope O(dy^3); used only to locate minima (the patch's
    geometry is then evaluated on the exact surface).
    """

    def __init__(self, func, lower, upper, spacing):
        n = max(int(math.ceil((upper - lower) / spacing)) + 1, 4)
        y = np.linspace(lower, upper, n)
        value, slope, curvature = (np.asarray(v, float) for v in func(y))
        self.lower, self.upper, self.step, self.n = float(lower), float(upper), (upper - lower) / (n - 1), n
        self.value, self.slope, self.curvature = value, slope * self.step, curvature

    def as_tuple(self):
        """(lower, step, values, slopes x step, curvatures) for the compiled kernels."""
        return (self.lower, self.step, self.value, self.slope, self.curvature)

    def __call__(self, y):
        u = (np.asarray(y, float) - self.lower) / self.step
        i = np.clip(np.floor(np.nan_to_num(u)), 0, self.n - 2).astype(np.intp)
        t = u - i
        v0, v1, m0, m1 = self.value[i], self.value[i + 1], self.slope[i], self.slope[i + 1]
        t2 = t * t
        value = v0 + t * (m0 + t * (3 * (v1 - v0) - 2 * m0 - m1 + t * (2 * (v0 - v1) + m0 + m1)))
        slope = (m0 + t * (6 * (v1 - v0) - 4 * m0 - 2 * m1) + t2 * (6 * (v0 - v1) + 3 * m0 + 3 * m1)) / self.step
        curvature = self.curvature[i] * (1 - t) + self.curvature[i + 1] * t
        outside = ~((u >= 0) & (u <= self.n - 1))
        if np.any(outside):
            value, slope, curvature = (np.where(outside, np.nan, a) for a in (value, slope, curvature))
        return value, slope, curvature


def compiled_wheel_irregularities(irregularities) -> np.ndarray | None:
    """Rows of the compiled kernels (_search_kernels module docstring) for wheel irregularities, or None.

    Supported (closed forms evaluated in numba): rigid_dynamics.geometry's ``HarmonicOutOfRoundness`` and
    ``WheelFlat`` (both shapes): irregularities of the rolling angle a alone. Any other irregularity (e.g. a
    measured grid R_irr(a, y)) gives None: the search then takes the general numpy path.
    """
    from rigid_dynamics.geometry.irregularities import HarmonicOutOfRoundness, WheelFlat

    rows = []
    for irr in irregularities:
        if type(irr) is HarmonicOutOfRoundness:
            rows.append([0.0, float(irr.order), irr.amplitude_m, irr.phase_rad, 0.0, 0.0, 0.0])
        elif type(irr) is WheelFlat and irr.shape == "rounded":
            rows.append([1.0, irr.centre_angle_rad, irr.wheel_radius_m, irr.length_m, irr.depth, 0.0, 0.0])
        elif type(irr) is WheelFlat and irr.shape == "new":
            r, d = irr.wheel_radius_m, irr.depth
            rows.append([2.0, irr.centre_angle_rad, r, d, math.acos((r - d) / r), 0.0, 0.0])
        else:
            return None
    return np.array(rows, float).reshape(-1, 7)


def compiled_rail_irregularities(irregularities) -> np.ndarray | None:
    """Rows of the compiled kernels for rail irregularities (``RailCorrugation`` only), or None (numpy path)."""
    from rigid_dynamics.geometry.irregularities import RailCorrugation

    rows = []
    for irr in irregularities:
        if type(irr) is not RailCorrugation:
            return None
        rows.append(
            [0.0, 2.0 * math.pi / irr.wavelength_m, irr.amplitude_m, irr.phase_rad, irr.centre_y_m]
            + [irr.half_width_m, irr.taper_m]
        )
    return np.array(rows, float).reshape(-1, 7)


def _irregularity_sum(irregularities, u, v):
    total = [np.zeros(np.broadcast(u, v).shape) for _ in range(6)]
    for irr in irregularities:
        for k, value in enumerate(irr.evaluate(u, v)):
            total[k] = total[k] + value
    return total


class TabulatedWheel:
    """Fast stand-in for a wheel surface R(a, y_d) = R_id(y_d) + R_irr(a): R_id from a fine Hermite table.

    ``exact`` is the surface it was built from; the contact search uses the table to find the minima and the
    exact surface for each patch's geometry. Irregularities (``exact.irregularities``) must be of the rolling
    angle alone (:func:`compiled_wheel_irregularities`); ``evaluate`` adds their exact values, the compiled
    kernels the same closed forms (``irregularity_rows``).
    """

    def __init__(self, surface, spacing_m: float = 2.0e-5):
        self.exact = surface
        self.y_range_m = tuple(float(v) for v in surface.y_range_m)
        self._table = _LateralTable(surface.ideal_radius, *self.y_range_m, spacing_m)
        self.table_tuple = self._table.as_tuple()
        self.irregularities = tuple(getattr(surface, "irregularities", ()))
        rows = compiled_wheel_irregularities(self.irregularities)
        if rows is None:
            raise ValueError(f"irregularities = {self.irregularities!r}: expected HarmonicOutOfRoundness/WheelFlat")
        self.irregularity_rows = rows

    def evaluate(self, angle_rad, y_d_m):
        angle_rad, y_d_m = np.broadcast_arrays(np.asarray(angle_rad, float), np.asarray(y_d_m, float))
        r, r_y, r_yy = self._table(y_d_m)
        zero = np.zeros_like(r)
        if not self.irregularities:
            return (r, zero, r_y, zero, zero, r_yy)
        v, va, _, vaa, _, _ = _irregularity_sum(self.irregularities, angle_rad, zero)  # no y dependence
        return (r + v, va, r_y, vaa, zero, r_yy)


class TabulatedRail:
    """Fast stand-in for a rail surface N(x, y) = N_id(y) + N_irr(x, y_r) (no deflection): N_id from a Hermite
    table, corrugation (:func:`compiled_rail_irregularities`) added exactly; y_r = s y - e_r (placement.py).
    """

    def __init__(self, surface, spacing_m: float = 2.0e-5):
        self.exact = surface
        self.y_range_m = tuple(float(v) for v in surface.y_range_m)
        self._table = _LateralTable(surface.ideal_height, *self.y_range_m, spacing_m)
        self.table_tuple = self._table.as_tuple()
        self.irregularities = tuple(getattr(surface, "irregularities", ()))
        rows = compiled_rail_irregularities(self.irregularities)
        if rows is None:
            raise ValueError(f"irregularities = {self.irregularities!r}: expected RailCorrugation")
        self.irregularity_rows = rows
        self.lateral_map = np.array(
            [float(getattr(surface, "sign", 1.0)), float(getattr(surface, "lateral_offset_m", 0.0))]
        )

    def evaluate(self, x_m, y_m):
        x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        n, n_y, n_yy = self._table(y_m)
        zero = np.zeros_like(n)
        if not self.irregularities:
            return (n, zero, n_y, zero, zero, n_yy)
        s = self.lateral_map[0]
        v, vx, vy, vxx, vxy, vyy = _irregularity_sum(self.irregularities, x_m, s * y_m - self.lateral_map[1])
        return (n + v, vx, n_y + s * vy, vxx, s * vxy, n_yy + vyy)


def fast_surfaces(wheel, rail):
    """Tabulated stand-ins (compiled search) for rigid_dynamics.geometry surfaces.

    A wheel is tabulated when it has ``ideal_radius`` and its irregularities are all of the rolling angle alone
    (harmonic out-of-roundness, wheel flats; none: ideal); a rail when it has ``ideal_height``, no deflection and
    only corrugation irregularities (or none). Any other surface is returned unchanged (numpy path). The
    compiled search runs only when both stand-ins of a side are tabulated.
    """
    from rigid_dynamics.geometry.placement import RailSurface, WheelSurface

    wheel_irr = getattr(wheel, "irregularities", None)
    if hasattr(wheel, "ideal_radius") and (
        wheel_irr == () or (isinstance(wheel, WheelSurface) and compiled_wheel_irregularities(wheel_irr) is not None)
    ):
        wheel = TabulatedWheel(wheel)
    rail_irr = getattr(rail, "irregularities", None)
    if (
        hasattr(rail, "ideal_height")
        and getattr(rail, "deflection", 0) is None
        and (rail_irr == () or (isinstance(rail, RailSurface) and compiled_rail_irregularities(rail_irr) is not None))
    ):
        rail = TabulatedRail(rail)
    return wheel, rail


class _SideGeometry:
    """Wheel and rail surfaces of one side at one pose: vectorised point / normal / distance evaluation."""

    def __init__(self, wheel, rail, pose: WheelsetPose, side: str, lateral_range_m, rail_lateral_range_m, rot=None):
        self.wheel, self.rail, self.side = wheel, rail, side
        self.rot = pose.rotation if rot is None else rot
        self.centre = pose.centre_m
        self.pose = pose
        self.y_range = lateral_range_m
        self.rail_range = rail_lateral_range_m

    def wheel_point(self, alpha, y, second: bool = False):
        """Wheel points (main frame), outward unit normal, and optionally tangents and second derivatives."""
        r, r_a, r_y, r_aa, r_ay, r_yy = self.wheel.evaluate(alpha, y)
        ca, sa = np.cos(alpha), np.sin(alpha)
        zero = np.zeros_like(r)
        x_d = np.stack([r * ca, y + zero, r * sa], -1)
        t_a = np.stack([r_a * ca - r * sa, zero, r_a * sa + r * ca], -1)  # eq 9
        t_y = np.stack([r_y * ca, zero + 1.0, r_y * sa], -1)
        rot_t = self.rot.T
        point = x_d @ rot_t + self.centre  # eq 8
        t_a, t_y = t_a @ rot_t, t_y @ rot_t
        normal = np.cross(t_y, t_a)  # outward (towards the rail) for a wheel below its axle
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        if not second:
            return point, normal, x_d
        x_aa = np.stack([r_aa * ca - 2 * r_a * sa - r * ca, zero, r_aa * sa + 2 * r_a * ca - r * sa], -1) @ rot_t
        x_ay = np.stack([r_ay * ca - r_y * sa, zero, r_ay * sa + r_y * ca], -1) @ rot_t
        x_yy = np.stack([r_yy * ca, zero, r_yy * sa], -1) @ rot_t
        return point, normal, x_d, (t_a, t_y, x_aa, x_ay, x_yy), r

    def distance(self, alpha, y, iterations: int):
        """Distance h along the outward wheel normal to the rail (eq 10-11); +inf where the normal misses the rail."""
        point, normal, _ = self.wheel_point(alpha, y)
        h = self._distance_along(point, normal, iterations)
        inside = (y >= self.y_range[0]) & (y <= self.y_range[1])
        return np.where(inside, h, np.inf), point, normal

    def _distance_along(self, point, direction, iterations: int):
        n_x, n_y, n_z = direction[..., 0], direction[..., 1], direction[..., 2]
        h = np.zeros(point.shape[:-1])
        y_lo, y_hi = self.rail_range
        for _ in range(iterations):
            px, py, pz = point[..., 0] + h * n_x, point[..., 1] + h * n_y, point[..., 2] + h * n_z
            big_n, n_dx, n_dy = self.rail.evaluate(px, np.clip(py, y_lo, y_hi))[:3]
            f = pz - big_n
            slope = n_z - n_dx * n_x - n_dy * n_y
            step = f / np.where(np.abs(slope) > 1e-3, slope, np.copysign(1e-3, slope))
            h = h - step
            if not np.any(np.abs(step) > 1e-13):  # converged everywhere (nan: off the rail, handled below)
                break
        py = point[..., 1] + h * n_y
        on_rail = (py >= y_lo) & (py <= y_hi) & np.isfinite(h) & (np.abs(h) <= _FAR_M)
        with np.errstate(invalid="ignore"):
            residual = point[..., 2] + h * n_z - self.rail.evaluate(point[..., 0] + h * n_x, np.clip(py, y_lo, y_hi))[0]
        on_rail &= np.abs(residual) < 1e-10  # else not converged: the normal leaves the rail before meeting it
        return np.where(on_rail, h, np.inf)


def _grid_minima(values: np.ndarray) -> np.ndarray:
    """Indices (i, j) of local minima of a 2-D array (<= all 8 neighbours, < at least the lower-index ones)."""
    padded = np.pad(values, 1, constant_values=np.inf)
    core = padded[1:-1, 1:-1]
    is_min = np.isfinite(core)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di == 0 and dj == 0:
                continue
            neighbour = padded[1 + di : padded.shape[0] - 1 + di, 1 + dj : padded.shape[1] - 1 + dj]
            # strict on one half of the neighbourhood so a flat pair yields one minimum
            if (di, dj) < (0, 0):
                is_min &= core < neighbour
            else:
                is_min &= core <= neighbour
    return np.argwhere(is_min)


def _refine(geo: _SideGeometry, alpha, y, opts, radius_guess):
    """Damped Newton on h(alpha, y) for all candidates at once; FD gradient and Hessian in arc length."""
    step = 1.0e-5  # m, FD step along both parameters
    da = step / radius_guess
    converged = np.zeros(alpha.shape, bool)
    offsets = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]], float)
    for _ in range(opts["refine_iterations"]):
        aa = alpha[:, None] + offsets[None, :, 0] * da
        yy = y[:, None] + offsets[None, :, 1] * step
        h = geo.distance(aa, yy, opts["newton_iterations"])[0]
        h = np.where(np.isfinite(h), h, 1.0)  # off the surfaces: a large gap, so the step leads back
        g = np.stack([(h[:, 1] - h[:, 2]) / (2 * step), (h[:, 3] - h[:, 4]) / (2 * step)], -1)
        haa = (h[:, 1] - 2 * h[:, 0] + h[:, 2]) / step**2
        hyy = (h[:, 3] - 2 * h[:, 0] + h[:, 4]) / step**2
        hay = (h[:, 5] - h[:, 6] - h[:, 7] + h[:, 8]) / (4 * step**2)
        if opts["profile_only"]:
            haa, hay, g[:, 0] = np.ones_like(haa), np.zeros_like(hay), 0.0
        det = haa * hyy - hay**2
        ok = (haa > 0) & (det > 0) & np.all(np.isfinite(h), axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            s_a = np.where(ok, -(hyy * g[:, 0] - hay * g[:, 1]) / det, -g[:, 0] * 1e-3)
            s_y = np.where(ok, -(haa * g[:, 1] - hay * g[:, 0]) / det, -g[:, 1] * 1e-3)
        s_a, s_y = np.nan_to_num(s_a), np.nan_to_num(s_y)
        # convex along the rolling direction, not across it (e.g. the conformal R13 arcs of a flange root and a
        # gauge corner): a descent step with a line search (_search_kernels.refine_point, the same rule); concave
        # along the rolling direction (between a wheel flat's edges, each seeded by the angle grid): the short step
        for k in np.flatnonzero(~ok & ~converged & (haa > 0)):
            s_a[k], s_y[k] = _descent_step(geo, alpha[k], y[k], g[k], h[k, 0], opts, radius_guess)
        norm = np.hypot(s_a, s_y)
        limit = 3.0e-3
        scale = np.where(norm > limit, limit / np.maximum(norm, 1e-300), 1.0)
        s_a, s_y = s_a * scale, s_y * scale
        alpha = alpha + np.where(converged, 0.0, s_a / radius_guess)
        y = np.clip(y + np.where(converged, 0.0, s_y), geo.y_range[0], geo.y_range[1])
        converged |= ok & (norm < opts["refine_tolerance_m"])
        if np.all(converged):
            break
    return alpha, y, converged


def _descent_step(geo: _SideGeometry, alpha, y, grad, h0, opts, radius_guess):
    """Step (arc length, y) along -grad h of _refine where h is not convex, its length by the line search of
    _search_kernels._descent_length (first trial 5e-5 m doubled while h decreases, up to 3e-3 m, else halved to
    the Armijo decrease; no step when nothing decreases h).
    """
    g_norm = math.hypot(grad[0], grad[1])
    if not (g_norm > 0 and math.isfinite(g_norm)):
        return 0.0, 0.0
    u_a, u_y = -grad[0] / g_norm, -grad[1] / g_norm

    def along(length):
        yt = min(max(y + u_y * length, geo.y_range[0]), geo.y_range[1])
        v = float(
            geo.distance(np.array([alpha + u_a * length / radius_guess]), np.array([yt]), opts["newton_iterations"])[0][
                0
            ]
        )
        return v if math.isfinite(v) else 1.0

    length = 5.0e-5
    h_l = along(length)
    if h_l < h0 - 1e-4 * g_norm * length:
        while 2 * length <= 3.0e-3:
            h_2 = along(2 * length)
            if not h_2 < h_l:
                break
            length, h_l = 2 * length, h_2
        return u_a * length, u_y * length
    while length > 1.0e-9:
        length *= 0.5
        if along(length) < h0 - 1e-4 * g_norm * length:
            return u_a * length, u_y * length
    return 0.0, 0.0


def ellipticity_error(undeformed: UndeformedDistance, a_1_per_m, b_1_per_m, angle_rad, approach_m) -> float:
    """How far the sampled gap departs from the quadric of the patch's curvatures, relative to the approach.

    The quadric gap is g_q(x, y) = A x'^2 + B y'^2 - q (x', y' rotated by the ellipse angle). Over the points
    where either the sampled or the quadric gap is negative (the union of the two rigid-overlap regions, which
    contains the Hertz ellipse), the error is max |g - g_q| / q. It is of the order of the cubic terms of the
    surfaces over the patch, relative to q: a few % for a Hertzian patch (crowned wheel on a crowned rail:
    < 5 %), tens of % where the curvature changes across the patch (S1002 tread on UIC60 at zero shift: about 2,
    the patch spans several profile arcs). ``is_elliptic`` is error <= ``ellipticity_tolerance`` (default 0.2).
    """
    x, y = np.meshgrid(undeformed.x_m, undeformed.y_m)
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    xr, yr = c * x + s * y, -s * x + c * y
    quadric = a_1_per_m * xr**2 + b_1_per_m * yr**2 - approach_m
    g = undeformed.distance_m
    region = (np.minimum(g, quadric) < 0) & np.isfinite(g)
    if approach_m <= 0 or not np.any(region):
        return math.inf
    return float(np.max(np.abs(g[region] - quadric[region])) / approach_m)


def _gap_at(geo: _SideGeometry, alpha0, y0, centre, frame, gx, gy, iterations):
    """Gap along n between the wheel and the rail surfaces at contact-plane points (gx, gy) (vectorised).

    ``gx``, ``gy``: contact-frame coordinates, m, arrays of one shape; the same shape is returned (+inf where the
    wheel point leaves the profile). Each point is solved from the surfaces themselves (no interpolation), so a
    solver's elements see the exact undeformed distance at their centres.
    """
    gx, gy = np.broadcast_arrays(np.asarray(gx, float), np.asarray(gy, float))
    if isinstance(geo.wheel, TabulatedWheel) and isinstance(geo.rail, TabulatedRail):
        # the tabulated surfaces: the compiled sampler (contact._gap_kernels), the one the dynamics loop uses
        from rigid_dynamics.contact import _gap_kernels as gk

        surf, patch = _gap_records(geo, alpha0, y0, centre, frame, iterations)
        out = np.empty(gx.size)
        gk.gap_points(
            np.ascontiguousarray(gx, float).ravel(), np.ascontiguousarray(gy, float).ravel(), surf, patch, out
        )
        return out.reshape(gx.shape)
    return _gap_at_python(geo, alpha0, y0, centre, frame, gx, gy, iterations)


def _gap_at_python(geo: _SideGeometry, alpha0, y0, centre, frame, gx, gy, iterations):
    """:func:`_gap_at` in numpy with the surfaces' own ``evaluate`` (any surface; the reference of the compiled
    sampler's regression test).
    """
    gx, gy = np.broadcast_arrays(np.asarray(gx, float), np.asarray(gy, float))
    e_x, e_y, n = frame[:, 0], frame[:, 1], frame[:, 2]
    base = centre + gx[..., None] * e_x + gy[..., None] * e_y
    # Rail: p = base + t n on z = N(x, y)  (n points from the rail into the wheel).
    t_rail = geo._distance_along(base, n, iterations)
    # Wheel: x_w(alpha, y) = base + s n, Newton on (alpha, y, s) from the patch parameters.
    radius = geo.wheel.evaluate(np.array([alpha0]), np.array([y0]))[0][0]
    alpha = np.full(gx.shape, alpha0) + gx / radius
    lat = np.full(gx.shape, y0) + gy * np.dot(e_y, geo.rot[:, 1])
    s = np.zeros(gx.shape)
    for _ in range(iterations):
        point, _, _, (t_a, t_y, *_), _ = geo.wheel_point(alpha, lat, second=True)
        residual = point - base - s[..., None] * n
        jac = np.stack([t_a, t_y, np.broadcast_to(-n, t_a.shape)], -1)
        delta = np.linalg.solve(jac, -residual[..., None])[..., 0]
        alpha, lat, s = alpha + delta[..., 0], lat + delta[..., 1], s + delta[..., 2]
    inside = (lat >= geo.y_range[0]) & (lat <= geo.y_range[1])
    return np.where(inside, s - t_rail, np.inf)


def _gap_records(geo: _SideGeometry, alpha0, y0, centre, frame, iterations):
    """The records (_gap_kernels.GapSurfaces, GapPatch) of a tabulated side geometry and a patch."""
    from rigid_dynamics.contact._gap_kernels import GapPatch, GapSurfaces

    wheel, rail = geo.wheel, geo.rail
    surf = GapSurfaces(
        wheel.table_tuple, rail.table_tuple, np.ascontiguousarray(wheel.irregularity_rows, float).reshape(-1, 7),
        np.ascontiguousarray(rail.irregularity_rows, float).reshape(-1, 7), np.asarray(rail.lateral_map, float),
        np.array(geo.y_range, float), np.array(geo.rail_range, float),
    )  # fmt: skip
    vec = [tuple(float(v) for v in frame[:, k]) for k in range(3)]
    patch = GapPatch(
        np.ascontiguousarray(geo.rot, float), np.asarray(geo.centre, float), tuple(float(v) for v in centre), *vec,
        float(alpha0), float(y0), int(iterations),
    )  # fmt: skip
    return surf, patch


def _sample_field(geo: _SideGeometry, alpha0, y0, centre, frame, x_range, y_range, npts, iterations):
    """The gap (:func:`_gap_at`) on an npts x npts grid of the contact plane, with ``exact`` evaluating any point.

    ``x_range``, ``y_range``: (lower, upper) contact-frame coordinates of the grid, m. The grid sizes the potential
    contact area and serves the ellipticity check; a solver evaluates its element centres through ``exact``
    (bilinear interpolation of the grid overestimates a convex gap between its nodes: the pressure then peaks on
    the grid's node lines, in stripes that grow with the solver's refinement).
    """
    xs = np.linspace(x_range[0], x_range[1], npts)
    ys = np.linspace(y_range[0], y_range[1], npts)
    gx, gy = np.meshgrid(xs, ys)

    def exact(x_m, y_m):
        return _gap_at(geo, alpha0, y0, centre, frame, x_m, y_m, iterations)

    return UndeformedDistance(x_m=xs, y_m=ys, distance_m=exact(gx, gy), exact=exact)


_FIELD_LIMITS_M = (0.05, 0.03)  # largest |x|, |y| of the sampled field, m


def _fitted_field(sample, half_x: float, half_y: float, margin: float, max_passes: int = 4):
    """Sample the gap on a box that holds the whole rigid-overlap region (gap < 0) with a margin.

    ``sample(x_range, y_range)`` returns an :class:`UndeformedDistance`. Starting from +-half_x, +-half_y, a side
    of the box that the overlap touches is pushed out by the box's width (up to ``_FIELD_LIMITS_M``); then the
    box is shrunk to the overlap's extent plus ``margin`` times that extent plus two sample spacings on each side
    (the sampled outline is exact to one spacing), and sampled again when that saves over 20 % of a side.
    """
    x_rng, y_rng = [-half_x, half_x], [-half_y, half_y]
    lim_x, lim_y = _FIELD_LIMITS_M
    field = sample(tuple(x_rng), tuple(y_rng))
    for _ in range(max_passes):
        over = np.isfinite(field.distance_m) & (field.distance_m < 0)
        if not over.any():
            return field
        cols, rows = np.flatnonzero(over.any(axis=0)), np.flatnonzero(over.any(axis=1))
        grown = False
        for rng, idx, count, lim in ((x_rng, cols, field.x_m.size, lim_x), (y_rng, rows, field.y_m.size, lim_y)):
            width = rng[1] - rng[0]
            if idx[0] == 0 and rng[0] > -lim:
                rng[0], grown = max(rng[0] - width, -lim), True
            if idx[-1] == count - 1 and rng[1] < lim:
                rng[1], grown = min(rng[1] + width, lim), True
        if not grown:
            break
        field = sample(tuple(x_rng), tuple(y_rng))
    over = np.isfinite(field.distance_m) & (field.distance_m < 0)
    if not over.any():
        return field
    cols, rows = np.flatnonzero(over.any(axis=0)), np.flatnonzero(over.any(axis=1))
    fitted = []
    for coords, idx, rng, lim in ((field.x_m, cols, x_rng, lim_x), (field.y_m, rows, y_rng, lim_y)):
        spacing = (rng[1] - rng[0]) / max(coords.size - 1, 1)
        lo, hi = coords[idx[0]], coords[idx[-1]]
        pad = margin * (hi - lo) + 2 * spacing
        fitted.append((max(min(lo - pad, -spacing), -lim, rng[0]), min(max(hi + pad, spacing), lim, rng[1])))
    (fx, fy) = fitted
    if fx[1] - fx[0] < 0.8 * (x_rng[1] - x_rng[0]) or fy[1] - fy[0] < 0.8 * (y_rng[1] - y_rng[0]):
        field = sample(fx, fy)
    return field


def patch_undeformed_distance(
    wheel,
    rail,
    pose: WheelsetPose,
    side: str,
    point_m,
    frame,
    wheel_lateral_m: float,
    approach_m: float,
    curvatures,
    options=None,
) -> UndeformedDistance:
    """The sampled undeformed distance of one patch at a given pose: the field :func:`search_side` gives its
    patches (:func:`_fitted_field` of :func:`_sample_field`, the gap of :func:`_gap_at` evaluated exactly at any
    point), for a patch found elsewhere (e.g. the compiled search of the dynamics loop).

    Args:
        wheel, rail: the side's surfaces (the search's: fast stand-ins or exact ones).
        pose: wheelset pose. side: "left" or "right".
        point_m: the patch's contact point (main frame), m; the plane's origin.
        frame: (3, 3) columns e_x, e_y, n (n from the rail into the wheel).
        wheel_lateral_m: y_d of the wheel's contact point, m.
        approach_m: the patch's rigid approach q, m (> 0 in contact; sizes the first box with ``curvatures``).
        curvatures: (A, B) of the patch's quadric, 1/m.
        options: search options (``field_points``, ``field_scale``, ``field_margin``, ``field_min_half_size_m``,
            ``newton_iterations``; DEFAULT_OPTIONS).
    """
    if side not in SIDES:
        raise ValueError(f"side = {side!r}: expected one of {', '.join(SIDES)}")
    opts = _merge_options(options)
    geo = _SideGeometry(wheel, rail, pose, side, tuple(wheel.y_range_m), tuple(rail.y_range_m))
    centre = np.asarray(point_m, float)
    frame = np.asarray(frame, float)
    x_d = geo.rot.T @ (centre - geo.centre)
    alpha0 = math.atan2(x_d[2], x_d[0])
    a_use, b_use = (max(float(c), 1e-6) for c in curvatures)
    scale = 1.6 if opts["field_scale"] is None else opts["field_scale"]
    q = max(float(approach_m), 0.0)
    half_x = min(max(scale * math.sqrt(q / a_use), opts["field_min_half_size_m"]), _FIELD_LIMITS_M[0])
    half_y = min(max(scale * math.sqrt(q / b_use), opts["field_min_half_size_m"]), _FIELD_LIMITS_M[1])

    def sample(x_range, y_range):
        return _sample_field(
            geo, alpha0, float(wheel_lateral_m), centre, frame, x_range, y_range, opts["field_points"],
            opts["newton_iterations"],
        )  # fmt: skip

    if opts["field_scale"] is None:
        return _fitted_field(sample, half_x, half_y, opts["field_margin"])
    return sample((-half_x, half_x), (-half_y, half_y))


def search_side(
    wheel, rail, pose: WheelsetPose, side: str, *, wheel_lateral_range_m, rail_lateral_range_m, options=None
) -> SideSearch:
    """Find every contact patch between one wheel and its rail (eq 5-11) and its local geometry (eq 12-33).

    Args:
        wheel: wheel surface of this side, ``evaluate(alpha, y_d) -> (R, R_a, R_y, R_aa, R_ay, R_yy)`` (eq 5, 7),
            y_d along the axle from the wheelset centre, m.
        rail: rail surface of this side, ``evaluate(x, y) -> (N, N_x, N_y, N_xx, N_xy, N_yy)`` (eq 6), main frame.
        pose: wheelset pose.
        side: "left" or "right" (only used for the sign of the contact angle and the patch label).
        wheel_lateral_range_m: (y_min, y_max) of y_d where the wheel surface is defined, m.
        rail_lateral_range_m: (y_min, y_max) of the main-frame y where the rail surface is defined, m.
        options: see ``DEFAULT_OPTIONS``.

    Returns:
        :class:`SideSearch`. Patches carry A, B in the rolling-direction frame, the approach, and (option
        ``field``) the sampled undeformed distance; ``contact_point_rail_m``/``contact_point_wheel_m`` are filled
        when the surfaces have ``to_profile_coordinates`` (rigid_dynamics.geometry's do), else nan.

    Raises:
        ValueError: unknown side or option.
    """
    started = time.perf_counter()
    if side not in SIDES:
        raise ValueError(f"side = {side!r}: expected one of {', '.join(SIDES)}")
    opts = _merge_options(options)
    geo = _SideGeometry(wheel, rail, pose, side, tuple(wheel_lateral_range_m), tuple(rail_lateral_range_m))
    exact_wheel, exact_rail = getattr(wheel, "exact", wheel), getattr(rail, "exact", rail)
    if exact_wheel is wheel and exact_rail is rail:
        geo_exact = geo
    else:
        geo_exact = _SideGeometry(exact_wheel, exact_rail, pose, side, geo.y_range, geo.rail_range, geo.rot)

    # Grid around the lowest point alpha = pi/2 - phi (spin angle, see kinematics: R_y(-phi)).
    alpha_mid = 0.5 * np.pi - pose.spin_rad
    half = opts["alpha_half_range_rad"]
    if opts["profile_only"]:
        alphas = np.array([alpha_mid])
    else:
        alphas = alpha_mid + np.linspace(-half, half, opts["alpha_points"])
    y_lo, y_hi = geo.y_range
    n_y = max(int(round((y_hi - y_lo) / opts["lateral_step_m"])) + 1, 3)
    ys = np.linspace(y_lo, y_hi, n_y)
    iters = opts["newton_iterations"]
    radius_guess = float(np.median(wheel.evaluate(np.array([alpha_mid]), np.array([0.5 * (y_lo + y_hi)]))[0]))
    compiled = isinstance(wheel, TabulatedWheel) and isinstance(rail, TabulatedRail)
    if compiled:
        from rigid_dynamics.contact import _search_kernels as kern

        surf = kern.Surfaces(
            wheel=wheel.table_tuple,
            rail=rail.table_tuple,
            wheel_irr=wheel.irregularity_rows,
            rail_irr=rail.irregularity_rows,
            rail_map=rail.lateral_map,
            y_range=np.array(geo.y_range),
            rail_range=np.array(geo.rail_range),
        )
        args = (geo.rot, geo.centre, surf)

        def points(a, y, n_iter=iters):
            return kern.distance_points(np.ascontiguousarray(a, float), np.ascontiguousarray(y, float), *args, n_iter)

        h_grid = kern.distance_grid(alphas, ys, *args, iters)
    else:

        def points(a, y, n_iter=iters):
            return geo.distance(np.asarray(a, float), np.asarray(y, float), n_iter)[0]

        grid_a, grid_y = np.meshgrid(alphas, ys, indexing="ij")
        h_grid = points(grid_a, grid_y)
    minima = _grid_minima(h_grid)
    minima = minima[h_grid[minima[:, 0], minima[:, 1]] < opts["candidate_gap_m"]]
    if len(minima) == 0:
        min_gap = float(np.min(h_grid)) if np.any(np.isfinite(h_grid)) else math.inf
        empty = ContactCandidates(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0, bool))
        return SideSearch(
            side, True, "no-contact", f"no wheel-rail gap below {opts['candidate_gap_m']} m on the {side} side",
            [], empty, min_gap, np.zeros((0, 2)), time.perf_counter() - started,
        )  # fmt: skip
    start_a, start_y = alphas[minima[:, 0]], ys[minima[:, 1]]
    if compiled:
        alpha_c, y_c, h_c, converged = kern.refine(
            start_a, start_y, *args, iters, radius_guess, opts["refine_iterations"], opts["refine_tolerance_m"],
            bool(opts["profile_only"]),
        )  # fmt: skip
    else:
        alpha_c, y_c, converged = _refine(geo, start_a, start_y, opts, radius_guess)
        h_c = points(alpha_c, y_c)

    # Deduplicate: same point, or the same interpenetration region (h < 0 along the joining segment).
    order = np.argsort(h_c)
    kept: list[int] = []
    for k in order:
        if not np.isfinite(h_c[k]):
            continue
        duplicate = False
        for j in kept:
            if abs(y_c[k] - y_c[j]) < 1e-6 and abs(alpha_c[k] - alpha_c[j]) * radius_guess < 1e-6:
                duplicate = True
                break
            if h_c[k] < 0:
                t = np.linspace(0, 1, 25)
                seg = points(alpha_c[j] + t * (alpha_c[k] - alpha_c[j]), y_c[j] + t * (y_c[k] - y_c[j]))
                if np.all(seg < 0):
                    duplicate = True
                    break
        if not duplicate:
            kept.append(k)
    kept_arr = np.array(kept, int)
    candidates = ContactCandidates(alpha_c[kept_arr], y_c[kept_arr], h_c[kept_arr], converged[kept_arr])
    in_contact = kept_arr[h_c[kept_arr] < 0]
    patches = [_patch(geo_exact, alpha_c[k], y_c[k], opts, float(h_c[k]), geo) for k in in_contact]
    min_gap = float(np.min(h_c[kept_arr])) if len(kept_arr) else math.inf
    all_converged = bool(np.all(converged[in_contact]))
    if not patches:
        status, message = "no-contact", f"smallest gap on the {side} side is {min_gap:.3e} m"
    elif all_converged:
        status, message = "ok", f"{len(patches)} patch(es) on the {side} side"
    else:
        status, message = "not-converged", "a contact-point refinement did not converge"
    return SideSearch(
        side=side,
        success=status != "not-converged",
        status=status,
        message=message,
        patches=patches,
        candidates=candidates,
        min_gap_m=min_gap,
        wheel_parameters=np.stack([alpha_c[in_contact], y_c[in_contact]], -1),
        wall_time_s=time.perf_counter() - started,
    )


def _patch(geo: _SideGeometry, alpha0: float, y0: float, opts, h: float, geo_field=None) -> ContactGeometry:
    """Geometry of the patch at the refined minimum (alpha0, y0) with distance h (from the search).

    Point, normal and curvatures come from ``geo`` (the exact surfaces); the sampled gap from ``geo_field``
    (the search's surfaces, e.g. the Hermite tables of ideal profiles, accurate to ~1e-13 m) when given.
    """
    a_arr, y_arr = np.array([alpha0]), np.array([y0])
    point, n_out, _, (t_a, t_y, x_aa, x_ay, x_yy), radius = geo.wheel_point(a_arr, y_arr, second=True)
    point, n_out = point[0], n_out[0]
    rail_point = point + h * n_out
    n = -n_out
    rolling = np.asarray(opts["rolling_direction"], float)
    e_x = rolling - np.dot(rolling, n) * n
    e_x /= np.linalg.norm(e_x)
    e_y = np.cross(n, e_x)
    frame = np.stack([e_x, e_y, n], -1)
    k_w = curvature_tensor(t_a[0], t_y[0], x_aa[0], x_ay[0], x_yy[0], n, e_x, e_y)
    _, n_dx, n_dy, n_xx, n_xy, n_yy = (
        v[0] for v in geo.rail.evaluate(np.array([rail_point[0]]), np.array([rail_point[1]]))
    )
    k_r = curvature_tensor(
        np.array([1.0, 0.0, n_dx]),
        np.array([0.0, 1.0, n_dy]),
        np.array([0.0, 0.0, n_xx]),
        np.array([0.0, 0.0, n_xy]),
        np.array([0.0, 0.0, n_yy]),
        n,
        e_x,
        e_y,
    )
    a_rel, b_rel, angle = principal_relative_curvature(relative_curvature(k_w, k_r))
    a_rel, b_rel, angle = float(a_rel), float(b_rel), float(angle)
    approach = float(-h)
    lateral_tilt = -n[1] if geo.side == "right" else n[1]
    contact_angle = math.atan2(lateral_tilt, -n[2])
    convex = a_rel > 0 and b_rel > 0
    a_use, b_use = max(a_rel, 1e-6), max(b_rel, 1e-6)
    undeformed = None
    elliptic = convex
    if opts["field"]:
        scale = 1.6 if opts["field_scale"] is None else opts["field_scale"]
        half_x = max(scale * math.sqrt(max(approach, 0) / a_use), opts["field_min_half_size_m"])
        half_y = max(scale * math.sqrt(max(approach, 0) / b_use), opts["field_min_half_size_m"])
        half_x, half_y = min(half_x, _FIELD_LIMITS_M[0]), min(half_y, _FIELD_LIMITS_M[1])
        centre = 0.5 * (point + rail_point)

        def sample(x_range, y_range):
            return _sample_field(
                geo_field or geo, alpha0, y0, centre, frame, x_range, y_range, opts["field_points"],
                opts["newton_iterations"],
            )  # fmt: skip

        if opts["field_scale"] is None:
            undeformed = _fitted_field(sample, half_x, half_y, opts["field_margin"])
        else:
            undeformed = sample((-half_x, half_x), (-half_y, half_y))
        error = ellipticity_error(undeformed, a_use, b_use, angle, approach)
        elliptic = convex and error <= opts["ellipticity_tolerance"]
    rail_profile_point = (math.nan, math.nan)
    wheel_profile_point = (math.nan, math.nan)
    if hasattr(geo.rail, "to_profile_coordinates"):
        yp, zp = geo.rail.to_profile_coordinates(rail_point[1], rail_point[2])
        rail_profile_point = (float(yp), float(zp))
    if hasattr(geo.wheel, "to_profile_coordinates"):
        yp, zp = geo.wheel.to_profile_coordinates(y0, radius[0])
        wheel_profile_point = (float(yp), float(zp))
    return ContactGeometry(
        curvature_long_1_per_m=a_use,
        curvature_lat_1_per_m=b_use,
        approach_m=approach,
        side=geo.side,
        point_m=0.5 * (point + rail_point),
        frame=frame,
        contact_angle_rad=contact_angle,
        rolling_radius_m=float(radius[0]),
        contact_point_rail_m=rail_profile_point,
        contact_point_wheel_m=wheel_profile_point,
        ellipse_angle_rad=angle,
        undeformed=undeformed,
        is_elliptic=bool(elliptic),
    )
