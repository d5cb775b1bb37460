"""A quadric patch with a wheel flat or rail corrugation: the sampled undeformed distance of one contact.

Contact frame as everywhere (:mod:`rigid_dynamics.contact.types`): x along rolling, y lateral, z the
normal. The rail is straight along x and the wheel a circle of radius r_w (= the relative radius along x
of the quadric), so without irregularities the gap is the quadric h = x^2/(2 r_w) + y^2/(2 R_lat).

* Wheel flat (:class:`~rigid_dynamics.geometry.irregularities.WheelFlat`, centred a distance
  ``flat_offset_m`` along x from the wheel's lowest point): a wheel point at the angle t from the
  bottom lies at radius rho(t) = r_w + R_irr(t), i.e. at x = rho sin t and at the height
  z(t) = r_w - rho cos t above the lowest point of the round wheel. The gap along x is this exact rigid
  shape z(x) (not its parabola), sampled on a fine t grid and interpolated in x.
* Rail corrugation (:class:`~rigid_dynamics.geometry.irregularities.RailCorrugation`, lateral band
  wide enough to cover the patch): N_irr(x) > 0 lowers the rail (z down), so it adds to the gap:
  h += N_irr(x). Phase pi puts a crest at x = 0.

The gap h(x, y) = z(x) + N_irr(x) + y^2/(2 R_lat) is shifted so that its minimum is 0 and stored as the
:class:`~rigid_dynamics.contact.types.UndeformedDistance` of a :class:`ContactGeometry` whose quadric
curvatures A, B are the LOCAL ones at that minimum (A = h_xx/2 by central differences of the exact
shape, B = 1/(2 R_lat)): what a rigid-body contact search hands a Hertzian model, which then knows
nothing of the shape beyond the curvature. ``is_elliptic`` is False.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.contact.types import ContactGeometry, UndeformedDistance
from rigid_dynamics.geometry.irregularities import RailCorrugation, WheelFlat


def wheel_flat_profile_m(x_m: np.ndarray, flat: WheelFlat, flat_offset_m: float = 0.0) -> np.ndarray:
    """Height z(x) of the wheel surface above the lowest point of the round wheel (module docstring), m.

    Args:
        x_m: positions along the rolling direction, m (|x| well below the wheel radius).
        flat: the flat; its ``centre_angle_rad`` is ignored, the flat is centred at ``flat_offset_m``.
        flat_offset_m: x of the flat's centre, m.
    """
    r = flat.wheel_radius_m
    x_m = np.asarray(x_m, float)
    span = float(np.abs(x_m).max()) + abs(flat_offset_m) + flat.length_m
    t_max = math.asin(min(span / r, 0.9))
    t = np.linspace(-t_max, t_max, 40001)
    # WheelFlat's angle a: a0 = pi/2 is the wheel bottom; angle t from the bottom is a = pi/2 + t
    centre = math.pi / 2 + math.asin(flat_offset_m / r)
    shaped = WheelFlat(flat.length_m, r, flat.depth_m, centre, flat.shape)
    rho = r + shaped.evaluate(math.pi / 2 + t, 0.0)[0]
    x_w, z_w = rho * np.sin(t), r - rho * np.cos(t)
    return np.interp(x_m, x_w, z_w)


def irregular_quadric_geometry(
    radius_long_m: float,
    radius_lat_m: float,
    *,
    flat: WheelFlat | None = None,
    flat_offset_m: float = 0.0,
    corrugation: RailCorrugation | None = None,
    half_length_m: float = 0.03,
    half_width_m: float = 0.012,
    spacing_m: float = 1.0e-4,
) -> ContactGeometry:
    """ContactGeometry of a wheel (radius ``radius_long_m``) with a flat and/or a corrugated rail.

    Args:
        radius_long_m: r_w, wheel radius = relative radius along x without irregularities, m.
        radius_lat_m: R_lat, relative radius across, m.
        flat: optional wheel flat (its ``wheel_radius_m`` must equal ``radius_long_m``).
        flat_offset_m: x of the flat's centre from the wheel's lowest point, m.
        corrugation: optional rail corrugation (only its x dependence is used: the patch lies in the band).
        half_length_m, half_width_m: extent of the sampled field in x and y, m.
        spacing_m: sampling step, m (bilinear interpolation error of the quadric part A spacing^2/4).

    Returns:
        ContactGeometry with ``undeformed`` set, ``is_elliptic`` False, approach 0 at the minimum of h and
        the local curvatures at that minimum (module docstring).
    """
    for name, value in (("radius_long_m", radius_long_m), ("radius_lat_m", radius_lat_m)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    if flat is not None and abs(flat.wheel_radius_m - radius_long_m) > 1e-12 * radius_long_m:
        raise ValueError(
            f"flat.wheel_radius_m = {flat.wheel_radius_m!r}: expected radius_long_m = {radius_long_m!r} "
            "(the rail is straight along x, so the relative radius along x is the wheel's)"
        )
    nx = int(round(2 * half_length_m / spacing_m)) + 1
    ny = int(round(2 * half_width_m / spacing_m)) + 1
    x = np.linspace(-half_length_m, half_length_m, nx)
    y = np.linspace(-half_width_m, half_width_m, ny)

    def along(xv: np.ndarray) -> np.ndarray:
        xv = np.asarray(xv, float)
        if flat is not None:
            h = wheel_flat_profile_m(xv, flat, flat_offset_m)
        else:
            r = radius_long_m
            h = r - np.sqrt(r * r - xv * xv)
        if corrugation is not None:
            h = h + corrugation.evaluate(xv, np.full_like(xv, corrugation.centre_y_m))[0]
        return h

    hx = along(x)
    i0 = int(np.argmin(hx))
    x0 = float(x[i0])
    step = 2.0e-4
    curv = along(np.array([x0 - step, x0, x0 + step]))
    a_local = 0.5 * (curv[0] - 2 * curv[1] + curv[2]) / step**2
    if not a_local > 0:
        raise ValueError(
            f"the gap is not convex at its minimum x = {x0:.4g} m (h_xx/2 = {a_local:.3g} 1/m): the irregularity "
            "gives several contact points; choose a shallower flat or corrugation"
        )
    distance = (hx - hx[i0])[None, :] + (y**2 / (2.0 * radius_lat_m))[:, None]
    return ContactGeometry(
        curvature_long_1_per_m=float(a_local),
        curvature_lat_1_per_m=0.5 / radius_lat_m,
        approach_m=0.0,
        undeformed=UndeformedDistance(x, y, distance),
        is_elliptic=False,
    )
