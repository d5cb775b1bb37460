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

Assembly (uniform traction on each rectangle, compiled with numba): the point-force stresses are integrated
over each element with a tensor Gauss-Legendre rule (3 x 3), the element split into n x n sub-cells with
n = ceil(1.5 h / r) (1..6; h the element size, r the distance of the point to the element centre), so the
rule sees sub-cells no larger than about r/1.5 (tests/test_subsurface.py: Johnson's axis stresses within
1 % of p0). CONTACT's subsurface module integrates the same uniform-rectangle loads in closed form (Love 1929
for the pressure); those closed forms were not derived here, quadrature is used instead, so points right at
the surface (depth well below the element size) are not accurate.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def _boussinesq(x, y, d, nu, out):
    """Boussinesq kernel at one point (module docstring) into out[0:6] (xx, yy, dd, xy, xd, yd), per unit force."""
    r2 = x * x + y * y
    rho2 = r2 + d * d
    rho = math.sqrt(rho2)
    rho3 = rho2 * rho
    rho5 = rho2 * rho3
    c = 1.0 / (2.0 * math.pi)
    if r2 > 0.0:
        k = (1.0 - 2.0 * nu) / r2
        one = (1.0 - d / rho) / r2
        out[0] = c * (k * (one * (x * x - y * y) + d * y * y / rho3) - 3.0 * d * x * x / rho5)
        out[1] = c * (k * (one * (y * y - x * x) + d * x * x / rho3) - 3.0 * d * y * y / rho5)
        out[3] = c * (k * (2.0 * one * x * y - x * y * d / rho3) - 3.0 * x * y * d / rho5)
    else:  # on the axis: 1 - d/rho ~ r^2/(2 d^2), so the (1-2nu) terms tend to (1-2nu)/(2 d^2) and 0 (xy)
        out[0] = c * (1.0 - 2.0 * nu) / (2.0 * d * d)
        out[1] = out[0]
        out[3] = 0.0
    out[2] = -3.0 * c * d * d * d / rho5
    out[4] = -3.0 * c * x * d * d / rho5
    out[5] = -3.0 * c * y * d * d / rho5


@njit(cache=True, error_model="numpy", inline="always")
def _cerruti(x, y, d, nu, out):
    """Cerruti kernel (force along +x) at one point (module docstring) into out[0:6], per unit force."""
    rho2 = x * x + y * y + d * d
    rho = math.sqrt(rho2)
    rho3 = rho2 * rho
    rho5 = rho2 * rho3
    m = 1.0 - 2.0 * nu
    rd = rho + d
    c = 1.0 / (2.0 * math.pi)
    out[0] = -c * x / rho3 * (3.0 * x * x / rho2 - m / (rd * rd) * (rho2 - y * y - 2.0 * rho * y * y / rd))
    out[1] = -c * x / rho3 * (3.0 * y * y / rho2 - m / (rd * rd) * (3.0 * rho2 - x * x - 2.0 * rho * x * x / rd))
    out[2] = -3.0 * c * x * d * d / rho5
    out[3] = -c * y / rho3 * (3.0 * x * x / rho2 + m / (rd * rd) * (rho2 - x * x - 2.0 * rho * x * x / rd))
    out[4] = -3.0 * c * x * x * d / rho5
    out[5] = -3.0 * c * x * y * d / rho5


@njit(cache=True)
def _kernel_many(x, y, d, nu, which, out):
    tmp = np.empty(6)
    for k in range(x.size):
        if which == 0:
            _boussinesq(x[k], y[k], d[k], nu, tmp)
        elif which == 1:
            _cerruti(x[k], y[k], d[k], nu, tmp)
        else:  # force along +y: the x-kernel with x and y exchanged, components mapped back
            _cerruti(y[k], x[k], d[k], nu, tmp)
            tmp[0], tmp[1], tmp[4], tmp[5] = tmp[1], tmp[0], tmp[5], tmp[4]
        for c in range(6):
            out[c, k] = tmp[c]


def _kernel(which: int, x, y, d, poisson_ratio: float) -> np.ndarray:
    x, y, d = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(d, float))
    out = np.empty((6, x.size))
    _kernel_many(np.ascontiguousarray(x).ravel(), np.ascontiguousarray(y).ravel(), np.ascontiguousarray(d).ravel(),
                 float(poisson_ratio), which, out)  # fmt: skip
    return out.reshape((6, *x.shape))


def boussinesq_kernel(x, y, d, poisson_ratio: float) -> np.ndarray:
    """Stress (6, ...) per unit normal force at (x, y, d) (module docstring), 1/m^2; order xx, yy, dd, xy, xd, yd."""
    return _kernel(0, x, y, d, poisson_ratio)


def cerruti_kernel(x, y, d, poisson_ratio: float) -> np.ndarray:
    """Stress (6, ...) per unit tangential force along +x at (x, y, d) (module docstring), 1/m^2."""
    return _kernel(1, x, y, d, poisson_ratio)


@njit(cache=True, error_model="numpy")
def _assemble(points, xc, yc, dx, dy, forces, nu, gauss, weights, out):
    """Sum over elements of the kernel integrated over each (uniform-traction) rectangle, per point.

    Per (point, element) pair the rectangle is split into n x n sub-cells with n = ceil(1.5 h / r) (1..6; h the
    larger element side, r the distance to the element centre) and each sub-cell integrated by the tensor
    Gauss rule ``gauss``/``weights`` on [-1, 1].
    """
    tmp = np.empty(6)
    h = max(dx, dy)
    ng = gauss.size
    for p in range(points.shape[0]):
        px, py, pd = points[p, 0], points[p, 1], points[p, 2]
        for e in range(xc.size):
            ex, ey = px - xc[e], py - yc[e]
            r = math.sqrt(ex * ex + ey * ey + pd * pd)
            n = min(6, max(1, int(math.ceil(1.5 * h / r))))
            for iu in range(n):
                for jv in range(n):
                    cu = ((iu + 0.5) / n - 0.5) * dx
                    cv = ((jv + 0.5) / n - 0.5) * dy
                    for a in range(ng):
                        for b in range(ng):
                            sx = ex - (cu + 0.5 * gauss[a] * dx / n)
                            sy = ey - (cv + 0.5 * gauss[b] * dy / n)
                            w = 0.25 * weights[a] * weights[b] / (n * n)
                            for load in range(3):
                                f = forces[load, e] * w
                                if f == 0.0:
                                    continue
                                if load == 0:
                                    _boussinesq(sx, sy, pd, nu, tmp)
                                elif load == 1:
                                    _cerruti(sx, sy, pd, nu, tmp)
                                else:
                                    _cerruti(sy, sx, pd, nu, tmp)
                                    tmp[0], tmp[1], tmp[4], tmp[5] = tmp[1], tmp[0], tmp[5], tmp[4]
                                for c in range(6):
                                    out[load, p, c] += f * tmp[c]


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
    separate: bool = False,
) -> np.ndarray:
    """Stresses at ``points_m`` (N, 3: x, y, depth) from uniform tractions on the grid's rectangles.

    Args:
        x_m, y_m: element centres (uniform spacing), m; fields are indexed [j, i] at (x_m[i], y_m[j]).
        pressure_Pa: p >= 0 pressing into the body, Pa.
        points_m: (N, 3) observation points, depth > 0, m.
        poisson_ratio: nu.
        traction_x_Pa, traction_y_Pa: shear tractions on this body's surface, Pa (None: frictionless).
        gauss_points: Gauss-Legendre points per direction and sub-cell.
        separate: return the parts of the pressure and of the two tractions apart, shape (3, N, 3, 3).

    Returns:
        (N, 3, 3) stress tensors in (x, y, d), Pa (tension > 0); (3, N, 3, 3) with ``separate``.
    """
    x_m, y_m = np.asarray(x_m, float), np.asarray(y_m, float)
    points = np.ascontiguousarray(np.atleast_2d(np.asarray(points_m, float)))
    if np.any(points[:, 2] <= 0):
        raise ValueError("points_m: expected depths > 0 (the half-space stresses are singular at the surface)")
    dx = float(x_m[1] - x_m[0]) if x_m.size > 1 else 1.0
    dy = float(y_m[1] - y_m[0]) if y_m.size > 1 else 1.0
    fields = [np.asarray(pressure_Pa, float)]
    for t in (traction_x_Pa, traction_y_Pa):
        fields.append(np.zeros_like(fields[0]) if t is None else np.asarray(t, float))
    xx, yy = np.meshgrid(x_m, y_m)
    active = (fields[0] != 0) | (fields[1] != 0) | (fields[2] != 0)
    forces = np.ascontiguousarray(np.stack([f[active] * dx * dy for f in fields]))
    g, w = np.polynomial.legendre.leggauss(gauss_points)
    out = np.zeros((3, len(points), 6))
    _assemble(points, xx[active].copy(), yy[active].copy(), dx, dy, forces, float(poisson_ratio), g, w, out)
    tensor = np.empty((3, len(points), 3, 3))
    tensor[..., 0, 0], tensor[..., 1, 1], tensor[..., 2, 2] = out[..., 0], out[..., 1], out[..., 2]
    tensor[..., 0, 1] = tensor[..., 1, 0] = out[..., 3]
    tensor[..., 0, 2] = tensor[..., 2, 0] = out[..., 4]
    tensor[..., 1, 2] = tensor[..., 2, 1] = out[..., 5]
    return tensor if separate else tensor.sum(axis=0)


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
