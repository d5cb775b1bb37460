"""Elastic and frictional material data of a wheel-rail pair.

Both bodies are taken as quasi-identical (same elastic constants), the usual
assumption of Kalker's theories; a pair of different materials is described
by the combined constants (see :func:`combined_from_pair`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

STANDARD_GRAVITY_M_PER_S2 = 9.80665
"""Standard acceleration of gravity (CGPM 1901), m/s^2."""


@dataclass(frozen=True)
class Material:
    """Elastic constants and Coulomb friction of a quasi-identical wheel-rail pair.

    Attributes:
        shear_modulus_Pa: G, shear modulus of both bodies, Pa.
        poisson_ratio: nu, Poisson's ratio of both bodies, in (-1, 0.5).
        friction_coefficient: mu, Coulomb friction coefficient (static = kinetic), >= 0.
    """

    shear_modulus_Pa: float = 82.0e9
    poisson_ratio: float = 0.28
    friction_coefficient: float = 0.3

    def __post_init__(self) -> None:
        for name in ("shear_modulus_Pa", "poisson_ratio", "friction_coefficient"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")
        if self.shear_modulus_Pa <= 0:
            raise ValueError(f"shear_modulus_Pa = {self.shear_modulus_Pa!r}: expected > 0")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ValueError(f"poisson_ratio = {self.poisson_ratio!r}: expected a value in (-1, 0.5)")
        if self.friction_coefficient < 0:
            raise ValueError(f"friction_coefficient = {self.friction_coefficient!r}: expected >= 0")

    @property
    def young_modulus_Pa(self) -> float:
        """E = 2 G (1 + nu), Pa."""
        return 2.0 * self.shear_modulus_Pa * (1.0 + self.poisson_ratio)

    @property
    def combined_modulus_Pa(self) -> float:
        """E* with 1/E* = 2 (1 - nu^2)/E for two equal bodies, i.e. E* = G/(1 - nu), Pa (Johnson 1985, eq 4.22)."""
        return self.shear_modulus_Pa / (1.0 - self.poisson_ratio)

    @classmethod
    def from_young(cls, young_modulus_Pa: float, poisson_ratio: float, friction_coefficient: float) -> Material:
        """Build from Young's modulus E: G = E / (2 (1 + nu))."""
        if not math.isfinite(young_modulus_Pa) or young_modulus_Pa <= 0:
            raise ValueError(f"young_modulus_Pa = {young_modulus_Pa!r}: expected a finite number > 0")
        if not -1.0 < poisson_ratio < 0.5:
            raise ValueError(f"poisson_ratio = {poisson_ratio!r}: expected a value in (-1, 0.5)")
        return cls(young_modulus_Pa / (2.0 * (1.0 + poisson_ratio)), poisson_ratio, friction_coefficient)


STEEL = Material()
"""Wheel and rail steel as in the Manchester Contact Benchmark: G = 82 GPa, nu = 0.28, mu = 0.3."""
