"""Providers for real wheel and rail profiles: a 2-D profile section (for the tables) and the 3-D search.

Both take the wheel and rail *surfaces* of both sides (duck-typed as in rigid_dynamics.contact.search:
``wheel.evaluate(alpha, y_d) -> (R, R_a, R_y, R_aa, R_ay, R_yy)``, ``rail.evaluate(x, y) -> (N, N_x, N_y,
N_xx, N_xy, N_yy)``, both with ``y_range_m``), by default built from the scene's profiles with
rigid_dynamics.contact.track.build_track.

This module: the surfaces of both sides from the scene (:func:`build_surfaces`, :func:`conical_track`,
:func:`geometry_irregularities`).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from rigid_dynamics.wheelset.parameters import Irregularities, TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers.patches import SIDE_SIGNS, SIDES

ABSENT_GAP_M = 0.01
MIN_LATERAL_CURVATURE_1_PER_M = 0.05


def build_surfaces(wheelset: WheelsetParameters, track: TrackGeometry, irregularities: Irregularities | None = None):
    """Wheel and rail surfaces of both sides from the scene's profiles (contact.track.build_track).

    Each side takes its own wheel and rail profile and rail inclination (TrackGeometry.side_profile,
    side_inclination_rad; the two-sided keys by default, the left side mirrored).
    A conical track (wheel_profile "conical", rail_profile "circular") is built by :func:`conical_track`,
    placed exactly as the analytic ConicalProvider places it (contact points at +-e0, radius r0).

    Returns:
        The WheelsetTrack (``wheels``, ``rails`` dicts by side, ``search(pose, side, options)``).
    """
    from rigid_dynamics.contact.track import build_track

    if track.is_conical:
        return conical_track(wheelset, track, irregularities)
    case = SimpleNamespace(
        wheel_profile=track.side_profile("wheel", "right"),
        wheel_profile_left=track.side_profile("wheel", "left"),
        rail_profile=track.side_profile("rail", "right"),
        rail_profile_left=track.side_profile("rail", "left"),
        gauge_m=track.gauge_m,
        gauge_height_m=track.gauge_height_m,
        flange_back_distance_m=track.flange_back_distance_m,
        nominal_radius_m=wheelset.nominal_radius_m,
        rail_inclination_rad=track.rail_inclination_rad,
        rail_inclination_left_rad=track.side_inclination_rad("left"),
        rail_inclination_right_rad=track.side_inclination_rad("right"),
    )
    wheel_irr, rail_irr = {}, {}
    if irregularities is not None and irregularities.any:
        wheel_irr, rail_irr = geometry_irregularities(irregularities, wheelset.nominal_radius_m)
    return build_track(case, wheel_irregularities=wheel_irr, rail_irregularities=rail_irr)


class ConicalWheelSurface:
    """Conical wheel of side ``sign`` (-1 left, +1 right): R(alpha, y_d) = r0 + lambda (e0 - sign y_d) + R_irr(alpha).

    Duck-typed like rigid_dynamics.geometry.WheelSurface: ``evaluate(alpha, y_d)`` returns R and its partial
    derivatives (R, R_a, R_y, R_aa, R_ay, R_yy); ``y_range_m`` is the tread, e0 +- ``half_width_m``.
    """

    def __init__(self, sign, nominal_radius_m, contact_half_distance_m, conicity, irregularities=(), half_width_m=0.07):
        self.sign, self.r0, self.e0, self.lam = float(sign), nominal_radius_m, contact_half_distance_m, conicity
        self.irregularities = tuple(irregularities)
        lo, hi = self.e0 - half_width_m, self.e0 + half_width_m
        self.y_range_m = (lo, hi) if sign > 0 else (-hi, -lo)

    def ideal_radius(self, y_d_m):
        """The cone's profile (R, dR/dy_d, d2R/dy_d2) at ``y_d_m`` without irregularities (m, -, 1/m).

        With it an ideal cone is tabulated for the compiled search (contact.search.fast_surfaces).
        """
        y_d = np.asarray(y_d_m, float)
        r = self.r0 + self.lam * (self.e0 - self.sign * y_d)
        return r, np.full_like(r, -self.sign * self.lam), np.zeros_like(r)

    def evaluate(self, angle_rad, y_d_m):
        alpha, y_d = np.broadcast_arrays(np.asarray(angle_rad, float), np.asarray(y_d_m, float))
        r, r_y, r_yy = self.ideal_radius(y_d)
        zero = np.zeros_like(r)
        out = [r, zero.copy(), r_y, zero.copy(), zero.copy(), r_yy]
        for item in self.irregularities:
            for k, v in enumerate(item.evaluate(alpha, y_d)):
                out[k] = out[k] + v
        return tuple(out)


class CircularRailSurface:
    """Rail head of side ``sign``: a circle of radius R_r in the (y, z) plane, straight along x (z down).

    N(x, y) = z_c - sqrt(R_r^2 - (y - y_c)^2) + N_irr(x, y), with the centre (y_c, z_c) of ConicalProvider.
    """

    def __init__(self, sign, centre_y_m, centre_z_m, radius_m, irregularities=(), half_width_m=0.03):
        self.yc, self.zc, self.rr, self.sign = centre_y_m, centre_z_m, radius_m, float(sign)
        self.irregularities = tuple(irregularities)
        self.y_range_m = (centre_y_m - half_width_m, centre_y_m + half_width_m)

    deflection = None
    """No rail deflection (the compiled search's tabulated rail: contact.search.fast_surfaces)."""

    def ideal_height(self, y_m):
        """The rail head's profile (N, dN/dy, d2N/dy2) at ``y_m`` without irregularities (m, -, 1/m)."""
        u = np.asarray(y_m, float) - self.yc
        w = np.sqrt(self.rr**2 - u**2)
        return self.zc - w, u / w, self.rr**2 / w**3

    def evaluate(self, x_m, y_m):
        x, y = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        n, n_y, n_yy = self.ideal_height(y)
        zero = np.zeros_like(n)
        out = [n, zero.copy(), n_y, zero.copy(), zero.copy(), n_yy]
        u = y - self.yc
        for item in self.irregularities:
            # rail irregularities take the lateral coordinate relative to the rail-head centre
            for k, v in enumerate(item.evaluate(x, self.sign * u)):
                out[k] = out[k] + (self.sign * v if k in (2, 4) else v)
        return tuple(out)


def conical_track(wheelset: WheelsetParameters, track: TrackGeometry, irregularities: Irregularities | None = None):
    """WheelsetTrack (contact.track) of conical wheels on circular rail heads, placed as ConicalProvider does."""
    from rigid_dynamics.contact.track import WheelsetTrack

    lam, r0, e0, rail_r = (
        track.conicity,
        wheelset.nominal_radius_m,
        wheelset.contact_half_distance_m,
        track.rail_head_radius_m,
    )
    root = math.sqrt(1 + lam * lam)
    wheel_irr, rail_irr = {}, {}
    if irregularities is not None and irregularities.any:
        wheel_irr, rail_irr = geometry_irregularities(irregularities, r0)
    wheels, rails = {}, {}
    for side, sign in zip(SIDES, SIDE_SIGNS, strict=True):
        wheels[side] = ConicalWheelSurface(sign, r0, e0, lam, wheel_irr.get(side, ()))
        rails[side] = CircularRailSurface(
            sign, sign * (e0 + rail_r * lam / root), rail_r / root, rail_r, rail_irr.get(side, ())
        )
    return WheelsetTrack(wheels=wheels, rails=rails, nominal_radius_m=r0, half_wheel_distance_m=e0)


def geometry_irregularities(irregularities: Irregularities, nominal_radius_m: float):
    """Map the scene's irregularities to rigid_dynamics.geometry irregularity objects per side.

    Returns:
        (wheel side -> tuple, rail side -> tuple).

    The rounded flat, the polygon and the corrugation are the same functions as in
    rigid_dynamics.wheelset.irregular (which the analytic providers use): geometry.WheelFlat "rounded",
    HarmonicOutOfRoundness, RailCorrugation (A cos(2 pi x / wavelength), over the rail head's central band).
    Further harmonics are more HarmonicOutOfRoundness objects; measured grids are read from their CSV files
    (rigid_dynamics.geometry.measured).
    """
    from rigid_dynamics import geometry as geo
    from rigid_dynamics.wheelset.irregular import applies_to

    wheel, rail = [], []
    irr = irregularities
    if irr.polygon_order > 0 and irr.polygon_amplitude_m > 0:
        wheel.append(
            geo.HarmonicOutOfRoundness(
                order=irr.polygon_order, amplitude_m=irr.polygon_amplitude_m, phase_rad=irr.polygon_phase_rad
            )
        )
    if irr.flat_length_m > 0:
        wheel.append(
            geo.WheelFlat(
                length_m=irr.flat_length_m,
                wheel_radius_m=nominal_radius_m,
                depth_m=irr.flat_depth_m if irr.flat_depth_m > 0 else None,
                centre_angle_rad=irr.flat_angle_rad,
                shape="rounded",
            )
        )
    if irr.corrugation_amplitude_m > 0:
        rail.append(
            geo.RailCorrugation(wavelength_m=irr.corrugation_wavelength_m, amplitude_m=irr.corrugation_amplitude_m)
        )
    for harmonic in irr.harmonics:
        if harmonic.amplitude_m > 0:
            wheel.append(geo.HarmonicOutOfRoundness(harmonic.order, harmonic.amplitude_m, harmonic.phase_rad))
    if irr.wheel_grid_file or irr.corrugation_file:
        from rigid_dynamics.geometry.measured import read_rail_grid_csv, read_wheel_grid_csv

        if irr.wheel_grid_file:
            wheel.append(read_wheel_grid_csv(irr.wheel_grid_file))
        if irr.corrugation_file:
            rail.append(read_rail_grid_csv(irr.corrugation_file))
    sides_w = {s: tuple(wheel) for s in SIDES if applies_to(irr, s)}
    sides_r = {s: tuple(rail) for s in SIDES if applies_to(irr, s)}
    return sides_w, sides_r
