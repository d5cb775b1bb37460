"""Subsurface stresses of an elastic half-space under surface tractions given on a grid of rectangles.

Frame: x, y in the surface, d the depth into the body (d >= 0). Elasticity is invariant under reflections, so
(x, y, d) may be the contact frame with d = -z for the rail (contact-frame z points from the rail into the
wheel), whatever the handedness. Tractions on the body's surface: pressure p >= 0 pushes into the body;
q_x, q_y are the shear tractions ON THIS body (for the rail: minus the tractions on the wheel).

Point-force kernels (Johnson 1985, Contact Mechanics, sec. 3.2, eqs 3.20 and 3.21, written in Cartesian
form -- s_xy from the polar components, (s_r - s_theta) x y / r^2; rho = sqrt(x^2 + y^2 + d^2),
r^2 = x^2 + y^2, nu Poisson's ratio), stress per unit force, tension > 0:

Boussinesq, a normal force P pressing into the surface at the origin::

    s_xx = P/(2 pi) [ (1-2nu)/r^2 ((1 - d/rho)(x^2 - y^2)/r^2 + d y^2/rho^3) - 3 d x^2/rho^5 ]
    s_yy = P/(2 pi) [ (1-2nu)/r^2 ((1 - d/rho)(y^2 - x^2)/r^2 + d x^2/rho^3) - 3 d y^2/rho^5 ]
    s_dd = -3 P d^3 / (2 pi rho^5)
    s_xy = P/(2 pi) [ (1-2nu)/r^2 (2 (1 - d/rho) x y/r^2 - x y d/rho^3) - 3 x y d/rho^5 ]
    s_xd = -3 P x d^2 / (2 pi rho^5),   s_yd = -3 P y d^2 / (2 pi rho^5)

Cerruti, a tangential force Q along +x at the origin::

    s_xx = -Q x/(2 pi rho^3) [ 3 x^2/rho^2 - (1-2nu)/(rho+d)^2 (rho^2 - y^2 - 2 rho y^2/(rho+d)) ]
    s_yy = -Q x/(2 pi rho^3) [ 3 y^2/rho^2 - (1-2nu)/(rho+d)^2 (3 rho^2 - x^2 - 2 rho x^2/(rho+d)) ]
    s_dd = -3 Q x d^2 / (2 pi rho^5)
    s_xy = -Q y/(2 pi rho^3) [ 3 x^2/rho^2 + (1-2nu)/(rho+d)^2 (rho^2 - x^2 - 2 rho x^2/(rho+d)) ]
    s_xd = -3 Q x^2 d / (2 pi rho^5),   s_yd = -3 Q x y d / (2 pi rho^5)

(the force along y by exchanging x and y). These expressions were typed from the textbook's formulas and are
checked in tests/test_subsurface.py by what they must satisfy rather than by trust: equilibrium
(div s = 0 by finite differences), traction-free surface away from the load, and the force balance of
each depth plane (the integral of s_dd over a plane is -P, of s_xd is -Q).

Assembly (uniform traction on each rectangle): the point-force stresses are integrated over each element
with a tensor Gauss-Legendre rule, subdivided so that the sub-cell size is at most ``depth / 2`` (and at
most 6 x 6 sub-cells); a uniformly loaded rectangle's stresses are thereby accurate to about 1e-4 for
points deeper than about a tenth of the element size. (CONTACT's subsurface module integrates the same
uniform-rectangle loads in closed form -- Love 1929 for the pressure --; the closed forms were not derived
here, quadrature is used instead, so points right at the surface (d << element size) are not accurate.)
"""

from __future__ import annotations

import math

import numpy as np

_COMPONENTS = ("xx", "yy", "dd", "xy", "xd", "yd")


def boussinesq_kernel(x, y, d, poisson_ratio: float) -> np.ndarray:
    """Stress (6, ...) per unit normal force at (x, y, d) (module docstring), 1/m^2; order xx, yy, dd, xy, xd, yd."""
    x, y, d = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(d, float))
    r2 = x * x + y * y
    rho2 = r2 + d * d
    rho = np.sqrt(rho2)
    rho3, rho5 = rho2 * rho, rho2 * rho2 * rho
    k = (1.0 - 2.0 * poisson_ratio) / np.where(r2 > 0, r2, 1.0)
    one = 1.0 - d / rho
    c = 1.0 / (2.0 * math.pi)
    s = np.empty((6, *x.shape))
    safe_r2 = np.where(r2 > 0, r2, 1.0)
    s[0] = c * (k * (one * (x * x - y * y) / safe_r2 + d * y * y / rho3) - 3.0 * d * x * x / rho5)
    s[1] = c * (k * (one * (y * y - x * x) / safe_r2 + d * x * x / rho3) - 3.0 * d * y * y / rho5)
    s[2] = -3.0 * c * d**3 / rho5
    s[3] = c * (k * (2.0 * one * x * y / safe_r2 - x * y * d / rho3) - 3.0 * x * y * d / rho5)
    s[4] = -3.0 * c * x * d * d / rho5
    s[5] = -3.0 * c * y * d * d / rho5
    return s


def cerruti_kernel(x, y, d, poisson_ratio: float) -> np.ndarray:
    """Stress (6, ...) per unit tangential force along +x at (x, y, d) (module docstring), 1/m^2."""
    x, y, d = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(d, float))
    rho2 = x * x + y * y + d * d
    rho = np.sqrt(rho2)
    rho3, rho5 = rho2 * rho, rho2 * rho2 * rho
    m = 1.0 - 2.0 * poisson_ratio
    rd = rho + d
    c = 1.0 / (2.0 * math.pi)
    s = np.empty((6, *x.shape))
    s[0] = -c * x / rho3 * (3.0 * x * x / rho2 - m / rd**2 * (rho2 - y * y - 2.0 * rho * y * y / rd))
    s[1] = -c * x / rho3 * (3.0 * y * y / rho2 - m / rd**2 * (3.0 * rho2 - x * x - 2.0 * rho * x * x / rd))
    s[2] = -3.0 * c * x * d * d / rho5
    s[3] = -c * y / rho3 * (3.0 * x * x / rho2 + m / rd**2 * (rho2 - x * x - 2.0 * rho * x * x / rd))
    s[4] = -3.0 * c * x * x * d / rho5
    s[5] = -3.0 * c * x * y * d / rho5
    return s


def _cerruti_y(x, y, d, poisson_ratio: float) -> np.ndarray:
    """Stress per unit tangential force along +y: the x-kernel with x and y exchanged (and the components)."""
    s = cerruti_kernel(y, x, d, poisson_ratio)
    return s[[1, 0, 2, 3, 5, 4]]


def halfspace_stress(
    x_m: np.ndarray,
    y_m: np.ndarray,
    pressure_Pa: np.ndarray,
    points_m: np.ndarray,
    poisson_ratio: float,
    *,
    traction_x_Pa: np.ndarray | None = None,
    traction_y_Pa: np.ndarray | None = None,
    gauss_points: int = 3,
    pairs_per_batch: int = 1_000_000,
) -> np.ndarray:
    """Stresses at ``points_m`` (N, 3: x, y, depth) from uniform tractions on the grid's rectangles.

    Args:
        x_m, y_m: element centres (uniform spacing), m; fields are indexed [j, i] at (x_m[i], y_m[j]).
        pressure_Pa: p >= 0 pressing into the body, Pa.
        points_m: (N, 3) observation points, depth > 0, m.
        poisson_ratio: nu.
        traction_x_Pa, traction_y_Pa: shear tractions on this body's surface, Pa (None: frictionless).
        gauss_points: Gauss-Legendre points per direction and sub-cell.
        pairs_per_batch: (observation point, source point) pairs evaluated at once (memory ~ 100 bytes each).

    Returns:
        (N, 3, 3) stress tensors in (x, y, d), Pa (tension > 0).
    """
    x_m, y_m = np.asarray(x_m, float), np.asarray(y_m, float)
    points = np.atleast_2d(np.asarray(points_m, float))
    if np.any(points[:, 2] <= 0):
        raise ValueError("points_m: expected depths > 0 (the half-space stresses are singular at the surface)")
    dx = float(x_m[1] - x_m[0]) if x_m.size > 1 else 1.0
    dy = float(y_m[1] - y_m[0]) if y_m.size > 1 else 1.0
    loads = [(np.asarray(pressure_Pa, float), boussinesq_kernel)]
    if traction_x_Pa is not None:
        loads.append((np.asarray(traction_x_Pa, float), cerruti_kernel))
    if traction_y_Pa is not None:
        loads.append((np.asarray(traction_y_Pa, float), _cerruti_y))
    xx, yy = np.meshgrid(x_m, y_m)
    active = np.zeros(xx.shape, bool)
    for field, _ in loads:
        active |= field != 0
    xc, yc = xx[active], yy[active]
    forces = [(field[active] * dx * dy, kernel) for field, kernel in loads]
    out = np.zeros((len(points), 6))
    g, w = np.polynomial.legendre.leggauss(gauss_points)
    depths = points[:, 2]
    # group the points by sub-division level: sub-cells no larger than depth / 2 (at most 6 x 6)
    level = np.clip(np.ceil(2.0 * max(dx, dy) / depths), 1, 6).astype(int)
    for n_sub in np.unique(level):
        idx = np.nonzero(level == n_sub)[0]
        centres = (np.arange(n_sub) + 0.5) / n_sub - 0.5
        u = (centres[:, None] + g[None, :] / (2 * n_sub)).ravel()  # in [-1/2, 1/2]
        wu = np.tile(w / (2 * n_sub), n_sub)
        ou, ov = np.meshgrid(u, u)
        ow = np.outer(wu, wu).ravel()
        sx, sy = (ou.ravel() * dx)[:, None], (ov.ravel() * dy)[:, None]
        src_x, src_y = (xc[None, :] + sx).ravel(), (yc[None, :] + sy).ravel()
        weights = np.repeat(ow[:, None], len(xc), axis=1).ravel()
        batch = max(1, pairs_per_batch // max(1, len(src_x)))
        for start in range(0, len(idx), batch):
            sel = idx[start : start + batch]
            px, py, pd = points[sel, 0][:, None], points[sel, 1][:, None], points[sel, 2][:, None]
            for force, kernel in forces:
                f = np.repeat(force[None, :], len(ow), axis=0).ravel() * weights
                s = kernel(px - src_x[None, :], py - src_y[None, :], pd, poisson_ratio)
                out[sel] += np.einsum("cpk,k->pc", s, f)
    tensor = np.empty((len(points), 3, 3))
    tensor[:, 0, 0], tensor[:, 1, 1], tensor[:, 2, 2] = out[:, 0], out[:, 1], out[:, 2]
    tensor[:, 0, 1] = tensor[:, 1, 0] = out[:, 3]
    tensor[:, 0, 2] = tensor[:, 2, 0] = out[:, 4]
    tensor[:, 1, 2] = tensor[:, 2, 1] = out[:, 5]
    return tensor


def von_mises_Pa(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of (..., 3, 3) tensors, Pa."""
    s = np.asarray(stress)
    dev = s - np.trace(s, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", dev, dev))


def max_shear_Pa(stress: np.ndarray) -> np.ndarray:
    """Tresca maximum shear (s1 - s3)/2 of (..., 3, 3) tensors, Pa."""
    eig = np.linalg.eigvalsh(np.asarray(stress))
    return 0.5 * (eig[..., -1] - eig[..., 0])


def hertz_axis_stresses(depth_over_a: np.ndarray, poisson_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form stresses on the axis of a Hertz circle, over p0 (Johnson 1985 eq 3.45): (s_r, s_z).

    s_z / p0 = -1 / (1 + d^2/a^2);  s_r / p0 = -(1 + nu) (1 - (d/a) atan(a/d)) + 1 / (2 (1 + d^2/a^2)).
    """
    t = np.asarray(depth_over_a, float)
    s_z = -1.0 / (1.0 + t * t)
    s_r = -(1.0 + poisson_ratio) * (1.0 - t * np.arctan(1.0 / t)) + 0.5 / (1.0 + t * t)
    return s_r, s_z
