"""Closed-form Hertz solutions used to size FE meshes and to verify the FE results.

Elliptic contact (Johnson 1985, *Contact Mechanics*, sec. 3.6 and 4.2): gap h = A x^2 + B y^2,
normal force P, combined modulus E* (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2). With a >= b the
semi-axes along the directions of the smaller (A_s) and larger (B_s) curvature, e^2 = 1 - b^2/a^2
and K, E the complete elliptic integrals of parameter m = e^2::

    B_s / A_s = ((a/b)^2 E - K) / (K - E)             (fixes e)
    a^3 = 3 P (K - E) / (2 pi E* e^2 A_s)             (from A_s = p0 b (K - E)/(E* a^2 e^2))
    p0 = 3 P / (2 pi a b),   approach delta = p0 b K / E*

Circular contact, stresses on the axis below the centre (Johnson 1985, eq 3.45)::

    sigma_z / p0 = -1 / (1 + z^2/a^2)
    sigma_r / p0 = sigma_theta / p0 = -(1 + nu) (1 - (z/a) arctan(a/z)) + 1 / (2 (1 + z^2/a^2))
    tau_1 = |sigma_z - sigma_r| / 2,   von Mises = |sigma_z - sigma_r|

For nu = 0.3 the maximum of tau_1 is 0.31 p0 at z = 0.48 a (Johnson 1985, sec. 3.4).
z is the depth below the surface (> 0), m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HertzSolution:
    """Hertz solution of an elliptic patch.

    Attributes:
        semi_axis_long_m: semi-axis along x (direction of the curvature A), m.
        semi_axis_lat_m: semi-axis along y (curvature B), m.
        max_pressure_Pa: p0, Pa.
        approach_m: delta, rigid approach of the bodies, m.
        normal_force_N: P, N.
    """

    semi_axis_long_m: float
    semi_axis_lat_m: float
    max_pressure_Pa: float
    approach_m: float
    normal_force_N: float


def _eccentricity_parameter(ratio: float) -> float:
    """Return m = e^2 such that ((1/(1-m)) E(m) - K(m)) / (K(m) - E(m)) = ratio (>= 1)."""
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipk

    if ratio < 1.0 + 1e-12:
        return 0.0

    def f(m):
        k, e = ellipk(m), ellipe(m)
        return (e / (1.0 - m) - k) / (k - e) - ratio

    return float(brentq(f, 1e-9, 1.0 - 1e-15, xtol=1e-15, rtol=1e-14, maxiter=200))


def hertz_elliptic(
    curvature_long_1_per_m: float, curvature_lat_1_per_m: float, normal_force_N: float, combined_modulus_Pa: float
) -> HertzSolution:
    """Hertz patch for h = A x^2 + B y^2 under the normal force P (see the module docstring).

    Args:
        curvature_long_1_per_m: A, 1/m (> 0).
        curvature_lat_1_per_m: B, 1/m (> 0).
        normal_force_N: P, N (> 0).
        combined_modulus_Pa: E*, Pa (> 0).
    """
    from scipy.special import ellipe, ellipk

    for name, value in (
        ("curvature_long_1_per_m", curvature_long_1_per_m),
        ("curvature_lat_1_per_m", curvature_lat_1_per_m),
        ("normal_force_N", normal_force_N),
        ("combined_modulus_Pa", combined_modulus_Pa),
    ):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    a_small = min(curvature_long_1_per_m, curvature_lat_1_per_m)
    b_large = max(curvature_long_1_per_m, curvature_lat_1_per_m)
    m = _eccentricity_parameter(b_large / a_small)
    if m == 0.0:
        k_minus_e_over_m = math.pi / 4.0
        k = math.pi / 2.0
    else:
        k = float(ellipk(m))
        k_minus_e_over_m = (k - float(ellipe(m))) / m
    major = (3.0 * normal_force_N * k_minus_e_over_m / (2.0 * math.pi * combined_modulus_Pa * a_small)) ** (1.0 / 3.0)
    minor = major * math.sqrt(1.0 - m)
    p0 = 3.0 * normal_force_N / (2.0 * math.pi * major * minor)
    approach = p0 * minor * k / combined_modulus_Pa
    if curvature_long_1_per_m <= curvature_lat_1_per_m:
        a_x, b_y = major, minor
    else:
        a_x, b_y = minor, major
    return HertzSolution(a_x, b_y, p0, approach, normal_force_N)


def hertz_force_from_approach(
    curvature_long_1_per_m: float, curvature_lat_1_per_m: float, approach_m: float, combined_modulus_Pa: float
) -> HertzSolution:
    """Hertz patch for a given approach delta (P scales as delta^(3/2))."""
    if not (math.isfinite(approach_m) and approach_m > 0):
        raise ValueError(f"approach_m = {approach_m!r}: expected a finite number > 0")
    unit = hertz_elliptic(curvature_long_1_per_m, curvature_lat_1_per_m, 1.0, combined_modulus_Pa)
    force = (approach_m / unit.approach_m) ** 1.5
    return hertz_elliptic(curvature_long_1_per_m, curvature_lat_1_per_m, force, combined_modulus_Pa)


def circular_axis_stresses(depth_over_radius: np.ndarray, poisson_ratio: float) -> dict[str, np.ndarray]:
    """Stresses / p0 on the axis of a circular Hertz contact (Johnson 1985, eq 3.45).

    Args:
        depth_over_radius: z/a >= 0, any shape.
        poisson_ratio: nu.

    Returns:
        dict with "sigma_z", "sigma_r", "max_shear" (tau_1) and "von_mises", each / p0, same shape.
    """
    zeta = np.asarray(depth_over_radius, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        z_atan = np.where(zeta > 0, zeta * np.arctan(1.0 / np.where(zeta > 0, zeta, 1.0)), 0.0)
    sigma_z = -1.0 / (1.0 + zeta**2)
    sigma_r = -(1.0 + poisson_ratio) * (1.0 - z_atan) + 0.5 / (1.0 + zeta**2)
    diff = np.abs(sigma_z - sigma_r)
    return {"sigma_z": sigma_z, "sigma_r": sigma_r, "max_shear": 0.5 * diff, "von_mises": diff}


def circular_axis_maximum(poisson_ratio: float, quantity: str = "max_shear") -> tuple[float, float]:
    """(max value / p0, depth / a) of ``quantity`` on the axis of a circular Hertz contact."""
    from scipy.optimize import minimize_scalar

    res = minimize_scalar(
        lambda z: -circular_axis_stresses(z, poisson_ratio)[quantity],
        bounds=(0.05, 2.0),
        method="bounded",
        options={"xatol": 1e-10},
    )
    return float(-res.fun), float(res.x)
