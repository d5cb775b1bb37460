"""Elastic and frictional material data of a wheel-rail pair.

Both bodies are taken as quasi-identical (same elastic constants), the usual
assumption of Kalker's theories; a pair of different materials is described
by the combined constants (see :func:`combined_from_pair`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rigid_dynamics.contact.friction import FrictionLaw, uniform

STANDARD_GRAVITY_M_PER_S2 = 9.80665
"""Standard acceleration of gravity (CGPM 1901), m/s^2."""


@dataclass(frozen=True)
class Material:
    """Elastic constants and Coulomb friction of a quasi-identical wheel-rail pair.

    Attributes:
        shear_modulus_Pa: G, shear modulus of both bodies, Pa.
        poisson_ratio: nu, Poisson's ratio of both bodies, in (-1, 0.5).
        friction_coefficient: mu, Coulomb friction coefficient (static = kinetic), >= 0; with ``friction`` given,
            that law's largest static coefficient (for the rungs that take one number).
        friction: the pair's friction law (:class:`~rigid_dynamics.contact.friction.FrictionLaw`: falling friction,
            variation in place), or None: Coulomb with ``friction_coefficient``. Build it with :meth:`with_friction`.
    """

    shear_modulus_Pa: float = 82.0e9
    poisson_ratio: float = 0.28
    friction_coefficient: float = 0.3
    friction: FrictionLaw | None = None

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
        if self.friction is not None:
            if not isinstance(self.friction, FrictionLaw):
                raise ValueError(f"friction = {self.friction!r}: expected a FrictionLaw or None")
            if self.friction_coefficient != self.friction.max_static:
                raise ValueError(
                    f"friction_coefficient = {self.friction_coefficient!r}: expected the friction law's largest "
                    f"static coefficient {self.friction.max_static!r} (build the material with with_friction)"
                )

    def with_friction(self, law: FrictionLaw | None) -> Material:
        """This material with the friction law ``law`` (None: Coulomb with the current ``friction_coefficient``)."""
        if law is None:
            return Material(self.shear_modulus_Pa, self.poisson_ratio, self.friction_coefficient)
        return Material(self.shear_modulus_Pa, self.poisson_ratio, law.max_static, law)

    def friction_law(self) -> FrictionLaw:
        """The friction law: ``friction``, or one Coulomb coefficient ``friction_coefficient`` everywhere."""
        return self.friction if self.friction is not None else uniform(self.friction_coefficient)

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


def combined_from_pair(
    shear_modulus_1_Pa: float,
    poisson_ratio_1: float,
    shear_modulus_2_Pa: float,
    poisson_ratio_2: float,
    friction_coefficient: float,
) -> Material:
    """Combined constants of two different elastic bodies (Kalker 1990, section 1.4).

    1/G = (1/G1 + 1/G2)/2 and nu/G = (nu1/G1 + nu2/G2)/2. With these, G/(1 - nu) equals Hertz's
    combined modulus E* of the pair, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson 1985, eq 4.22),
    so :attr:`Material.combined_modulus_Pa` holds for the pair. The difference parameter
    K = (G/4) ((1 - 2 nu1)/G1 - (1 - 2 nu2)/G2), which couples normal and tangential problems, is
    neglected by the quasi-identical theories and not represented.

    Args:
        shear_modulus_1_Pa, poisson_ratio_1: G1 (Pa) and nu1 of the first body (e.g. the wheel).
        shear_modulus_2_Pa, poisson_ratio_2: G2 (Pa) and nu2 of the second body (e.g. the rail).
        friction_coefficient: mu of the pair.

    Raises:
        ValueError: a modulus is not a finite number > 0 or a Poisson ratio is outside (-1, 0.5).
    """
    for name, value in (("shear_modulus_1_Pa", shear_modulus_1_Pa), ("shear_modulus_2_Pa", shear_modulus_2_Pa)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    for name, value in (("poisson_ratio_1", poisson_ratio_1), ("poisson_ratio_2", poisson_ratio_2)):
        if not (isinstance(value, (int, float)) and -1.0 < value < 0.5):
            raise ValueError(f"{name} = {value!r}: expected a value in (-1, 0.5)")
    shear = 2.0 / (1.0 / shear_modulus_1_Pa + 1.0 / shear_modulus_2_Pa)
    poisson = 0.5 * shear * (poisson_ratio_1 / shear_modulus_1_Pa + poisson_ratio_2 / shear_modulus_2_Pa)
    return Material(shear, poisson, friction_coefficient)
