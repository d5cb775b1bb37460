"""Analytic cone and circular-rail surfaces (duck-typed like rigid_dynamics.geometry) for the wheelset tests."""

import math
from types import SimpleNamespace

import numpy as np


class ConeWheel:
    """Right (sign +1) or left (-1) conical wheel: R(y_d) = r0 + lambda (e0 - sign y_d)."""

    def __init__(self, sign, r0, e0, conicity, half_width=0.07):
        self.sign, self.r0, self.e0, self.lam = sign, r0, e0, conicity
        lo, hi = e0 - half_width, e0 + half_width
        self.y_range_m = (lo, hi) if sign > 0 else (-hi, -lo)

    def evaluate(self, alpha, y_d):
        y_d = np.asarray(y_d, float)
        r = self.r0 + self.lam * (self.e0 - self.sign * y_d)
        zero = np.zeros_like(r)
        return r, zero, np.full_like(r, -self.sign * self.lam), zero, zero, zero


class CircleRail:
    """Rail head: circle of radius R_r centred at (y_c, z_c) in the (y, z) plane, straight along x (z down)."""

    def __init__(self, y_centre, z_centre, radius, half_width=0.03):
        self.yc, self.zc, self.rr = y_centre, z_centre, radius
        self.y_range_m = (y_centre - half_width, y_centre + half_width)

    def evaluate(self, x, y):
        y = np.asarray(y, float)
        u = y - self.yc
        w = np.sqrt(self.rr**2 - u**2)
        n = self.zc - w
        n_y = u / w
        n_yy = self.rr**2 / w**3
        zero = np.zeros_like(n)
        return n, zero, n_y, zero, zero, n_yy


def conical_surfaces(r0=0.46, e0=0.75, conicity=0.05, rail_radius=0.3):
    """Surfaces matching rigid_dynamics.wheelset.providers.ConicalProvider's placement."""
    root = math.sqrt(1 + conicity**2)
    wheels, rails = {}, {}
    for side, sign in (("left", -1.0), ("right", 1.0)):
        wheels[side] = ConeWheel(sign, r0, e0, conicity)
        rails[side] = CircleRail(sign * (e0 + rail_radius * conicity / root), rail_radius / root, rail_radius)
    return SimpleNamespace(wheels=wheels, rails=rails)
