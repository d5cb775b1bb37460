"""Running-direction irregularities used by the analytic providers: R_irr(alpha) (eq 5) and N_irr(x) (eq 6).

These are the three irregularities of the embedded scenes, with value, first and second derivative
(analytic), vectorised over arrays. They depend on the running coordinate only (the wheel angle
alpha_d, the track coordinate x): the lateral extent is the whole tread.

* Harmonic out-of-roundness (polygonisation) of order n: R_irr = A cos(n alpha + phase).
* Rounded wheel flat of length L and depth d centred at alpha_f, arc coordinate s = r0 wrap(alpha - alpha_f):
  R_irr = -(d/2) (1 + cos(2 pi s / L)) for |s| < L/2, else 0. This is the rounded ("haversine") flat
  profile used for worn flats by Newton & Clark (1979, J. Mech. Eng. Sci. 21, 287-297) and by
  Wu & Thompson (2002, J. Sound Vib. 251, 115-139). With d = 0 the default depth d = L^2/(16 r0) is used,
  the depth of a fresh chord flat of length L/sqrt(2) (rounding keeps the depth and lengthens the flat by
  sqrt(2)), as in rigid_dynamics.geometry.WheelFlat.
* Sinusoidal rail corrugation of wavelength w and amplitude A: N_irr = A cos(2 pi x / w)
  (z down: the rail is lowest at x = 0 and highest at x = w/2), as geometry.RailCorrugation.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.parameters import Irregularities


def flat_depth_m(irregularities: Irregularities, nominal_radius_m: float) -> float:
    """Depth d of the flat: the given one, or L^2/(16 r0) when 0 (module docstring), m."""
    if irregularities.flat_depth_m > 0:
        return irregularities.flat_depth_m
    return irregularities.flat_length_m**2 / (16.0 * nominal_radius_m)


def wheel_radius_irregularity(irregularities: Irregularities, nominal_radius_m: float, alpha_rad):
    """R_irr(alpha) and its first two derivatives with respect to alpha (m, m/rad, m/rad^2).

    Args:
        irregularities: the scene's irregularities.
        nominal_radius_m: r0, m (converts the flat's arc length to angle).
        alpha_rad: wheel angle alpha_d (wheelset frame), array.

    Returns:
        (value, d/dalpha, d2/dalpha2), arrays of the shape of alpha_rad.
    """
    alpha = np.asarray(alpha_rad, float)
    value = np.zeros_like(alpha)
    first = np.zeros_like(alpha)
    second = np.zeros_like(alpha)
    irr = irregularities
    if irr.polygon_order > 0 and irr.polygon_amplitude_m > 0:
        n, amp = irr.polygon_order, irr.polygon_amplitude_m
        arg = n * alpha + irr.polygon_phase_rad
        value += amp * np.cos(arg)
        first += -amp * n * np.sin(arg)
        second += -amp * n * n * np.cos(arg)
    if irr.flat_length_m > 0:
        length = irr.flat_length_m
        depth = flat_depth_m(irr, nominal_radius_m)
        s = nominal_radius_m * (np.mod(alpha - irr.flat_angle_rad + math.pi, 2 * math.pi) - math.pi)
        inside = np.abs(s) < 0.5 * length
        k = 2 * math.pi / length
        value += np.where(inside, -0.5 * depth * (1 + np.cos(k * s)), 0.0)
        first += np.where(inside, 0.5 * depth * k * np.sin(k * s) * nominal_radius_m, 0.0)
        second += np.where(inside, 0.5 * depth * k * k * np.cos(k * s) * nominal_radius_m**2, 0.0)
    return value, first, second


def dip_depth_m(irregularities: Irregularities) -> float:
    """Depth of the dipped joint below the rail's level far away, at most alpha sqrt(L^2 + e^2) (0 without a dip), m."""
    irr = irregularities
    return 0.5 * irr.joint_dip_angle_rad * math.hypot(irr.joint_ramp_length_m, irr.joint_entry_rounding_m)


def rail_irregularity(irregularities: Irregularities, x_m):
    """N_irr(x) and its first two derivatives with respect to x (m, 1, 1/m)."""
    x = np.asarray(x_m, float)
    irr = irregularities
    value, first, second = np.zeros_like(x), np.zeros_like(x), np.zeros_like(x)
    if irr.corrugation_amplitude_m > 0:
        k = 2 * math.pi / irr.corrugation_wavelength_m
        amp = irr.corrugation_amplitude_m
        value, first, second = amp * np.cos(k * x), -amp * k * np.sin(k * x), -amp * k * k * np.cos(k * x)
    if irr.joint_dip_angle_rad > 0:
        alpha = 0.5 * irr.joint_dip_angle_rad
        u = x - irr.joint_position_m
        length = irr.joint_ramp_length_m
        for shift, weight, e in (
            (length, 0.5, irr.joint_entry_rounding_m),
            (-length, 0.5, irr.joint_entry_rounding_m),
            (0.0, -1.0, irr.joint_rounding_m),
        ):
            v = u - shift
            root = np.sqrt(v * v + e * e)
            value = value + alpha * weight * root
            first = first + alpha * weight * v / root
            second = second + alpha * weight * e * e / root**3
    return value, first, second


def applies_to(irregularities: Irregularities, side: str) -> bool:
    """Whether the irregularities apply to the wheel/rail of ``side`` ("left" or "right")."""
    return irregularities.side in ("both", side)
