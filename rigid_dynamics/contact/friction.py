"""Friction laws of the wheel-rail pair: Coulomb, falling friction with slip velocity, and friction varying in place.

One coefficient per case is the textbook assumption; measured creep curves fall beyond their maximum, and a
gauge face is lubricated while the rail head is dry. This module holds the laws as data and one scalar kernel that
evaluates them, so every rung (BEM element-wise, FASTSIM and the strip methods strip-wise, the analytic rungs at
the contact point) uses the same formula.

**Falling friction** (the steady-sliding coefficient as a function of the local slip velocity s >= 0, m/s). With
the kinetic coefficient mu_k (the value at large slip) and two terms of sizes f1, f2 that halve at the slip
velocities s1, s2 (the parametrisation of Vollebregt's CONTACT, user guide section "friction law"):

* ``linear`` (CONTACT's L = 2): mu(s) = mu_k + f1 max(0, 1 - s / (2 s1)) + f2 max(0, 1 - s / (2 s2));
* ``rational`` (L = 3): mu(s) = mu_k + f1 / (1 + s / s1) + f2 / (1 + (s / s2)^2);
* ``exponential`` (L = 4): mu(s) = mu_k + f1 2^(-s / s1) + f2 2^(-s / s2);
* ``polach``: Polach's exponential law (Polach 2005, eq 13), mu(s) = mu_0 ((1 - A) exp(-B s) + A), the
  exponential form with mu_k = A mu_0, f1 = mu_0 - mu_k, s1 = ln 2 / B, f2 = 0 (as CONTACT's L = 5 converts it);
* ``coulomb`` (L = 0): mu(s) = mu for every s.

The static coefficient (adhesion holds while |t| <= mu_s p) is mu(0) = mu_k + f1 + f2: one coefficient
governs adhesion and the onset of slip, as in CONTACT since version 23.1. CONTACT's friction memory (the
coefficient lagging the slip velocity over a distance d_c) is not represented: the laws here are the steady ones.

**Variation in place**: the law's parameters given at nodes of one variable (the rail surface's inclination, the
lateral coordinate on the rail profile, or the distance along the track) and interpolated linearly between nodes,
held constant beyond the end nodes (as CONTACT's V = 1, 2 inputs are).

The records are NamedTuples of float64 arrays and integers, so a compiled kernel takes them whole
(:func:`friction_coefficient`, numba's compiled copy of :func:`_friction_coefficient`, made when first asked for:
a command that only reads a law does not import numba, rigid_dynamics.contact.lazy_kernels).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from rigid_dynamics.contact.lazy_kernels import compiled_copies, run_as_python

# --- codes ---------------------------------------------------------------------------------------------------------
FRICTION_COULOMB, FRICTION_LINEAR, FRICTION_RATIONAL, FRICTION_EXPONENTIAL = range(4)
"""Law codes of :class:`FrictionRecord` (Polach's law is stored in the exponential form)."""
LAW_NAMES = {"coulomb": FRICTION_COULOMB, "linear": FRICTION_LINEAR, "rational": FRICTION_RATIONAL}
LAW_NAMES.update({"exponential": FRICTION_EXPONENTIAL, "polach": FRICTION_EXPONENTIAL})

VARIES_NOWHERE, VARIES_WITH_INCLINATION, VARIES_WITH_RAIL_LATERAL, VARIES_ALONG_TRACK = range(4)
"""What the nodes of a varying law are given in: nothing (one law), the rail surface's inclination (rad, the angle
of the rail profile's tangent to the track plane, positive towards the gauge face), the lateral coordinate on the
rail profile (m, positive to the field side as the profile file's y), the distance along the track (m)."""
VARIES_NAMES = {
    "none": VARIES_NOWHERE,
    "surface_inclination": VARIES_WITH_INCLINATION,
    "rail_lateral": VARIES_WITH_RAIL_LATERAL,
    "track_distance": VARIES_ALONG_TRACK,
}


class FrictionRecord(NamedTuple):
    """A friction law as compiled kernels take it: one row per node (one node when nothing varies).

    Fields:

    * ``law_code``: FRICTION_COULOMB, FRICTION_LINEAR, FRICTION_RATIONAL or FRICTION_EXPONENTIAL;
    * ``varies_code``: VARIES_NOWHERE, VARIES_WITH_INCLINATION, VARIES_WITH_RAIL_LATERAL or VARIES_ALONG_TRACK;
    * ``node``: (n,) the variable at the nodes, ascending (rad or m); (1,) zero when nothing varies;
    * ``kinetic``: (n,) mu_k, the coefficient at large slip velocity;
    * ``term_1``, ``half_velocity_1_m_per_s``, ``term_2``, ``half_velocity_2_m_per_s``: (n,) f1, s1, f2, s2 of the
      falling law (zero sizes for Coulomb).
    """

    law_code: int
    varies_code: int
    node: np.ndarray
    kinetic: np.ndarray
    term_1: np.ndarray
    half_velocity_1_m_per_s: np.ndarray
    term_2: np.ndarray
    half_velocity_2_m_per_s: np.ndarray


@dataclass(frozen=True)
class FallingLaw:
    """One node's law: mu_k and the two falling terms (sizes f1, f2 >= 0; half velocities s1, s2 > 0, m/s).

    Build it with :func:`coulomb`, :func:`polach` or :func:`falling`.
    """

    law: str = "coulomb"
    kinetic: float = 0.3
    term_1: float = 0.0
    half_velocity_1_m_per_s: float = 1.0
    term_2: float = 0.0
    half_velocity_2_m_per_s: float = 1.0

    def __post_init__(self) -> None:
        if self.law not in LAW_NAMES or self.law == "polach":
            raise ValueError(f"law = {self.law!r}: expected one of coulomb, linear, rational, exponential")
        for name in ("kinetic", "term_1", "term_2"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise ValueError(f"{name} = {value!r}: expected a finite number >= 0")
        for name in ("half_velocity_1_m_per_s", "half_velocity_2_m_per_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0 (m/s)")
        if self.law == "coulomb" and (self.term_1 != 0.0 or self.term_2 != 0.0):
            raise ValueError(f"term_1 = {self.term_1!r}, term_2 = {self.term_2!r}: a coulomb law has no falling terms")

    @property
    def static(self) -> float:
        """mu_s = mu(0) = mu_k + f1 + f2, the coefficient that bounds adhesion."""
        return self.kinetic + self.term_1 + self.term_2

    def coefficient(self, slip_velocity_m_per_s: float) -> float:
        """The coefficient mu at the steady slip velocity s (m/s)."""
        return float(
            _law_value(
                LAW_NAMES[self.law],
                self.kinetic,
                self.term_1,
                self.half_velocity_1_m_per_s,
                self.term_2,
                self.half_velocity_2_m_per_s,
                abs(slip_velocity_m_per_s),
            )
        )


def coulomb(coefficient: float) -> FallingLaw:
    """Coulomb's law: mu(s) = ``coefficient`` at every slip velocity."""
    return FallingLaw("coulomb", coefficient)


def polach(static_coefficient: float, ratio_a: float, decay_b_s_per_m: float) -> FallingLaw:
    """Polach's exponential falling friction (Polach 2005, eq 13): mu(s) = mu_0 ((1 - A) exp(-B s) + A).

    Args:
        static_coefficient: mu_0, the coefficient at zero slip velocity, >= 0.
        ratio_a: A = mu_inf / mu_0 in [0, 1].
        decay_b_s_per_m: B > 0, the exponential decay rate of friction with slip velocity, s/m.
    """
    if not math.isfinite(ratio_a) or not 0.0 <= ratio_a <= 1.0:
        raise ValueError(f"polach_a = {ratio_a!r}: expected a number in [0, 1]")
    if not math.isfinite(decay_b_s_per_m) or decay_b_s_per_m <= 0.0:
        raise ValueError(f"polach_b_s_per_m = {decay_b_s_per_m!r}: expected a finite number > 0 (s/m)")
    kinetic = ratio_a * static_coefficient
    return FallingLaw("exponential", kinetic, static_coefficient - kinetic, math.log(2.0) / decay_b_s_per_m)


def falling(
    law: str,
    kinetic: float,
    term_1: float,
    half_velocity_1_m_per_s: float,
    term_2: float = 0.0,
    half_velocity_2_m_per_s: float = 1.0,
) -> FallingLaw:
    """A falling law of CONTACT's forms (``law`` = "linear", "rational" or "exponential"), see the module text."""
    return FallingLaw(law, kinetic, term_1, half_velocity_1_m_per_s, term_2, half_velocity_2_m_per_s)


@dataclass(frozen=True)
class FrictionLaw:
    """The pair's friction: one law, or laws at nodes of a variable interpolated linearly between them.

    Attributes:
        laws: the law at each node (one law when ``varies_with`` is "none"); all of one kind (all Coulomb, or all
            of one falling form), as CONTACT requires.
        varies_with: "none", "surface_inclination" (rad), "rail_lateral" (m) or "track_distance" (m).
        nodes: the variable at each node, strictly ascending; empty when nothing varies.
    """

    laws: tuple[FallingLaw, ...] = (FallingLaw(),)
    varies_with: str = "none"
    nodes: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.varies_with not in VARIES_NAMES:
            raise ValueError(f"varies_with = {self.varies_with!r}: expected one of {', '.join(VARIES_NAMES)}")
        if not self.laws:
            raise ValueError("laws = (): expected at least one law")
        kinds = {law.law for law in self.laws}
        if len(kinds) > 1:
            raise ValueError(f"laws = {sorted(kinds)}: expected laws of one kind at every node")
        if self.varies_with == "none":
            if len(self.laws) != 1 or self.nodes:
                raise ValueError(f"nodes = {list(self.nodes)!r}: a law that varies with nothing has one law, no nodes")
            return
        if len(self.nodes) != len(self.laws) or len(self.nodes) < 1:
            raise ValueError(
                f"nodes = {list(self.nodes)!r}: expected one node per law ({len(self.laws)} laws) for "
                f"varies_with = {self.varies_with!r}"
            )
        values = np.asarray(self.nodes, dtype=float)
        if not np.all(np.isfinite(values)) or np.any(np.diff(values) <= 0.0):
            raise ValueError(f"nodes = {list(self.nodes)!r}: expected finite, strictly ascending values")

    @property
    def is_coulomb(self) -> bool:
        """True for Coulomb's law (at every node)."""
        return self.laws[0].law == "coulomb"

    @property
    def varies(self) -> bool:
        """True when the law changes with place."""
        return self.varies_with != "none"

    @property
    def max_static(self) -> float:
        """The largest static coefficient over the nodes (bounds every traction)."""
        return max(law.static for law in self.laws)

    def record(self) -> FrictionRecord:
        """The law as compiled kernels take it."""
        laws = self.laws
        return FrictionRecord(
            LAW_NAMES[laws[0].law],
            VARIES_NAMES[self.varies_with],
            np.asarray(self.nodes if self.varies else (0.0,), dtype=np.float64),
            np.array([law.kinetic for law in laws], dtype=np.float64),
            np.array([law.term_1 for law in laws], dtype=np.float64),
            np.array([law.half_velocity_1_m_per_s for law in laws], dtype=np.float64),
            np.array([law.term_2 for law in laws], dtype=np.float64),
            np.array([law.half_velocity_2_m_per_s for law in laws], dtype=np.float64),
        )

    def coefficient(self, slip_velocity_m_per_s: float = 0.0, place: float = 0.0) -> float:
        """The coefficient mu at slip velocity s (m/s) and at ``place``.

        ``place`` is the variable the nodes are given in (ignored when nothing varies).
        """
        return _evaluate(self.record(), abs(slip_velocity_m_per_s), place)

    def static_coefficient(self, place: float = 0.0) -> float:
        """The static coefficient mu_s = mu(0) at ``place``."""
        return self.coefficient(0.0, place)


def uniform(coefficient: float) -> FrictionLaw:
    """One Coulomb coefficient everywhere (the toolkit's default friction)."""
    return FrictionLaw((coulomb(coefficient),))


def varying(varies_with: str, nodes: Sequence[float], laws: Sequence[FallingLaw]) -> FrictionLaw:
    """Laws given at ``nodes`` of ``varies_with``, interpolated linearly between them."""
    return FrictionLaw(tuple(laws), varies_with, tuple(float(v) for v in nodes))


# --- the kernels (plain Python, compiled by numba on demand) ----------------------------------------------------
def _law_value(law_code, kinetic, term_1, half_1, term_2, half_2, slip_velocity):
    """mu(s) of one node's law at the slip velocity s >= 0 (m/s); see the module text for the forms."""
    if law_code == FRICTION_LINEAR:
        return (
            kinetic
            + term_1 * max(0.0, 1.0 - 0.5 * slip_velocity / half_1)
            + term_2 * max(0.0, 1.0 - 0.5 * slip_velocity / half_2)
        )
    if law_code == FRICTION_RATIONAL:
        ratio_2 = slip_velocity / half_2
        return kinetic + term_1 / (1.0 + slip_velocity / half_1) + term_2 / (1.0 + ratio_2 * ratio_2)
    if law_code == FRICTION_EXPONENTIAL:
        return kinetic + term_1 * 2.0 ** (-slip_velocity / half_1) + term_2 * 2.0 ** (-slip_velocity / half_2)
    return kinetic


def _friction_coefficient(record, slip_velocity_m_per_s, place):
    """The coefficient mu of ``record`` (a :class:`FrictionRecord`) at slip velocity s >= 0 (m/s) and at ``place``.

    ``place`` is the variable of the nodes (rad or m); the parameters are interpolated linearly between nodes and
    held beyond the ends.
    """
    node = record.node
    n = node.shape[0]
    if n == 1 or place <= node[0]:
        i, w = 0, 0.0
    elif place >= node[n - 1]:
        i, w = n - 2, 1.0
    else:
        i = int(np.searchsorted(node, place, side="right")) - 1
        w = (place - node[i]) / (node[i + 1] - node[i])
    j = min(i + 1, n - 1)
    kinetic = (1.0 - w) * record.kinetic[i] + w * record.kinetic[j]
    term_1 = (1.0 - w) * record.term_1[i] + w * record.term_1[j]
    half_1 = (1.0 - w) * record.half_velocity_1_m_per_s[i] + w * record.half_velocity_1_m_per_s[j]
    term_2 = (1.0 - w) * record.term_2[i] + w * record.term_2[j]
    half_2 = (1.0 - w) * record.half_velocity_2_m_per_s[i] + w * record.half_velocity_2_m_per_s[j]
    return _law_value(record.law_code, kinetic, term_1, half_1, term_2, half_2, slip_velocity_m_per_s)


# --- the [friction] table of case files and scenes -----------------------------------------------------------------
TABLE_LAW_KEYS = {
    "coulomb": ("coefficient",),
    "linear": ("kinetic", "term_1", "half_velocity_1_m_per_s", "term_2", "half_velocity_2_m_per_s"),
    "polach": ("static", "polach_a", "polach_b_s_per_m"),
}
TABLE_LAW_KEYS["rational"] = TABLE_LAW_KEYS["exponential"] = TABLE_LAW_KEYS["linear"]
OPTIONAL_TABLE_KEYS = {"term_2": 0.0, "half_velocity_2_m_per_s": 1.0}
"""Keys of a ``[friction]`` table per law (besides ``law``, ``varies_with`` and ``nodes_rad`` / ``nodes_m``), and the
defaults of the optional ones. The names follow CONTACT v25.1's friction input (user guide, "friction law"):
coefficient = FSTAT = FKIN (L = 0); kinetic, term_1, half_velocity_1, term_2, half_velocity_2 = FKIN, FLIN1, SABS1,
FLIN2, SABS2 (L = 2, 3, 4; SABS in m/s here, mm/s in CONTACT); static, polach_a, polach_b = Polach's mu_0, A, B
(L = 5: CONTACT's FSTAT, POLACH_A, POLACH_B with B in s/mm there)."""


def friction_law_from_table(table: dict, prefix: str = "friction") -> FrictionLaw:
    """A ``[friction]`` table (the keys of :data:`TABLE_LAW_KEYS`; docs/files.md) -> :class:`FrictionLaw`.

    With ``varies_with`` other than "none", ``nodes_rad`` (surface_inclination) or ``nodes_m`` (rail_lateral,
    track_distance) gives the nodes, and every law parameter is one number (the same at every node) or a list of
    one number per node. Raises ValueError with one line naming the key, its value and what was expected.
    """
    if not isinstance(table, dict):
        raise ValueError(f"key '{prefix}' = {table!r}: expected a table")
    law = table.get("law", "coulomb")
    if law not in TABLE_LAW_KEYS:
        raise ValueError(f"key '{prefix}.law' = {law!r}: expected one of {', '.join(TABLE_LAW_KEYS)}")
    varies_with = table.get("varies_with", "none")
    if varies_with not in VARIES_NAMES:
        raise ValueError(f"key '{prefix}.varies_with' = {varies_with!r}: expected one of {', '.join(VARIES_NAMES)}")
    node_key = {"none": None, "surface_inclination": "nodes_rad"}.get(varies_with, "nodes_m")
    allowed = {"law", "varies_with", *TABLE_LAW_KEYS[law]} | ({node_key} if node_key else set())
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise ValueError(
            f"key '{prefix}.{unknown[0]}' = {table[unknown[0]]!r}: not a key of law = {law!r} with varies_with = "
            f"{varies_with!r} (expected {', '.join(sorted(allowed))})"
        )
    nodes: tuple[float, ...] = ()
    count = 1
    if node_key is not None:
        raw = table.get(node_key)
        if not isinstance(raw, list) or not raw or not all(_is_number(v) for v in raw):
            raise ValueError(f"key '{prefix}.{node_key}' = {raw!r}: expected a list of numbers for {varies_with}")
        nodes = tuple(float(v) for v in raw)
        if any(b <= a for a, b in zip(nodes, nodes[1:], strict=False)):
            raise ValueError(f"key '{prefix}.{node_key}' = {raw!r}: expected strictly ascending values")
        count = len(nodes)
    values = {}
    for name in TABLE_LAW_KEYS[law]:
        if name not in table:
            if name in OPTIONAL_TABLE_KEYS:
                values[name] = [OPTIONAL_TABLE_KEYS[name]] * count
                continue
            raise ValueError(f"key '{prefix}.{name}' is missing: law = {law!r} needs {', '.join(TABLE_LAW_KEYS[law])}")
        raw = table[name]
        items = raw if isinstance(raw, list) else [raw] * count
        if len(items) != count or not all(_is_number(v) for v in items):
            expected = f"a number or a list of {count} numbers (one per node)" if node_key else "a number"
            raise ValueError(f"key '{prefix}.{name}' = {raw!r}: expected {expected}")
        values[name] = [float(v) for v in items]
    laws = []
    for i in range(count):
        try:
            if law == "coulomb":
                laws.append(coulomb(values["coefficient"][i]))
            elif law == "polach":
                laws.append(polach(values["static"][i], values["polach_a"][i], values["polach_b_s_per_m"][i]))
            else:
                laws.append(falling(law, *(values[name][i] for name in TABLE_LAW_KEYS[law])))
        except ValueError as exc:
            raise ValueError(f"table [{prefix}]{f' node {i + 1}' if node_key else ''}: {exc}") from None
    if node_key is None:
        return FrictionLaw((laws[0],))
    return varying(varies_with, nodes, laws)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def compiled_kernels() -> dict:
    """Numba's compiled copies of the kernels (rigid_dynamics.contact.lazy_kernels.compiled_copies)."""
    return compiled_copies(__name__, ("_law_value", "_friction_coefficient"))


def _evaluate(record: FrictionRecord, slip_velocity_m_per_s: float, place: float) -> float:
    """The coefficient by the Python kernel before numba is loaded, else by the compiled one (same bits)."""
    kernel = _friction_coefficient if run_as_python(1, __name__) else compiled_kernels()["_friction_coefficient"]
    return float(kernel(record, slip_velocity_m_per_s, place))


def __getattr__(name):
    """``friction_coefficient``: the compiled copy of :func:`_friction_coefficient` (imports numba when first asked
    for).
    """
    if name == "friction_coefficient":
        return compiled_kernels()["_friction_coefficient"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
