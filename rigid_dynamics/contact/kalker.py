"""Kalker's creepage and spin coefficients C11, C22, C23, C33 of the linear theory (seed eq 50-52).

Linear theory of rolling contact for an elliptic patch (semi-axes a along the rolling direction x,
b lateral; shear modulus G; forces on the wheel, opposing the creepage)::

    Fx = -G a b C11 xi
    Fy = -G a b C22 eta - G (ab)^1.5 C23 phi
    Mz =  G (ab)^1.5 C23 eta - G (ab)^2 C33 phi        (C32 = -C23; REFERENCES.md, eq 50-52)

Data: Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact* (Kluwer 1990), Table E.3, as
copied into ``data/kalker_creep_coefficients.csv`` (attribution in its header). The table has
rows g = a/b = 0.1..1 and g = b/a = 1..0.1 and columns nu = 0, 0.25, 0.5.

Interpolation (the scheme is ours and documented here):

* in the axis ratio: monotone cubic (PCHIP) interpolation of ln C against ln(a/b) over the 19
  table rows (0.1 <= a/b <= 10). In log-log axes the coefficients are smooth and nearly
  linear (C33 ~ b/a, C23 ~ (a/b)^(1/2) at the ends), which linear interpolation in g would not
  follow (10 % error for C33 between a/b = 0.1 and 0.2);
* in Poisson's ratio: quadratic (Lagrange) interpolation of 1/C through nu = 0, 0.25, 0.5. This
  is exact where 1/C is linear in nu, as for Kalker's slender-ellipse limit
  1/C11 = 4 (1 - nu)/pi^2; values of nu outside [0, 0.5] are extrapolated by the same quadratic.

Outside the table (a/b < 0.1 or b/a < 0.1) Kalker's slender-ellipse asymptotes are used, with
g = min(a/b, b/a) and Lambda = ln(16/g^2) (Kalker 1990, App. E; the same expressions are in the
open-source CONTACT program, eve70a/CONTACT ``src/m_hertz.f90``, subroutine ``linrol``):

* a/b -> 0:  C11 = pi^2/(4(1-nu)),  C22 = pi^2/4,
  C23 = pi sqrt(g) / (3(1-nu)) * (1 + nu (ln(16/g) - 5)),
  C33 = pi^2 / (16 (1-nu) g)  -- not given by CONTACT; derived here by Kalker's strip argument
  (each lateral strip at y rolls like Carter's 2-D cylinder with local creepage -phi y and half
  length a(y); the same argument gives C11 = pi^2/(4(1-nu)) exactly). tests/test_kalker.py
  checks it against the table at a/b = 0.1 (4 %) and by numerical strip integration.
* b/a -> 0:  C11 = 2 pi / ((Lambda - 2 nu) g) * (1 + (3 - ln 4)/(Lambda - 2 nu)),
  C22 = 2 pi / g * (1 + (1-nu)(3 - ln 4)/((1-nu) Lambda + 2 nu)) / ((1-nu) Lambda + 2 nu),
  C23 = 2 pi / (3 g^1.5 ((1-nu) Lambda - 2 + 4 nu)),
  C33: no published asymptote was available to us; C33 is held at its table value at b/a = 0.1
  (a known weakness; C33 only enters the linear spin moment).

To make the coefficients continuous at the table edge, the asymptote is scaled by a correction
that is exact at g = 0.1 and vanishes linearly as g -> 0 (the asymptotes' own error is O(g)):
C(g) = C_asym(g) * (1 + (rho - 1) g/0.1), rho = C_table(0.1)/C_asym(0.1) (|rho - 1| < 6 %).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

_DATA_FILE = Path(__file__).resolve().parent / "data" / "kalker_creep_coefficients.csv"
COEFFICIENT_NAMES = ("C11", "C22", "C23", "C33")
TABLE_POISSON_RATIOS = (0.0, 0.25, 0.5)
_EDGE = 0.1


@dataclass(frozen=True, eq=False)
class KalkerTable:
    """Kalker's Table E.3 on one axis.

    Attributes:
        a_over_b: a/b of each row, ascending from 0.1 to 10 (19 rows).
        poisson_ratios: (0, 0.25, 0.5).
        values: array (19, 4, 3): [row, coefficient C11/C22/C23/C33, nu column].
        source: citation.
    """

    a_over_b: np.ndarray
    poisson_ratios: tuple[float, float, float]
    values: np.ndarray
    source: str

    def coefficient(self, name: str) -> np.ndarray:
        """Table column block (19, 3) of coefficient ``name`` ('C11', 'C22', 'C23' or 'C33')."""
        if name not in COEFFICIENT_NAMES:
            raise ValueError(f"coefficient name = {name!r}: expected one of {', '.join(COEFFICIENT_NAMES)}")
        return self.values[:, COEFFICIENT_NAMES.index(name), :]


def _load_table(path: Path = _DATA_FILE) -> KalkerTable:
    rows = []
    with open(path, encoding="utf-8") as f:
        lines = [ln.strip() for ln in f if ln.strip() and not ln.startswith("#")]
    header = lines[0].split(",")
    if header[:2] != ["ratio_kind", "ratio"] or len(header) != 14:
        raise ValueError(f"{path}: unexpected header {header!r}")
    for line in lines[1:]:
        kind, ratio, *vals = line.split(",")
        ratio = float(ratio)
        a_over_b = ratio if kind == "ab" else 1.0 / ratio
        rows.append((a_over_b, np.array(vals, dtype=float).reshape(4, 3)))
    rows.sort(key=lambda r: r[0])
    # the circular row appears once per kind; keep one
    unique = [rows[0]]
    for r in rows[1:]:
        if not math.isclose(r[0], unique[-1][0]):
            unique.append(r)
    a_over_b = np.array([r[0] for r in unique])
    values = np.stack([r[1] for r in unique])
    return KalkerTable(
        a_over_b=a_over_b,
        poisson_ratios=TABLE_POISSON_RATIOS,
        values=values,
        source="J.J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact (1990), Table E.3",
    )


KALKER_TABLE = _load_table()
"""Kalker's creepage/spin coefficient table (module constant, loaded once from the package data)."""

_LOG_INTERP = PchipInterpolator(
    np.log(KALKER_TABLE.a_over_b), np.log(KALKER_TABLE.values.reshape(len(KALKER_TABLE.a_over_b), 12)), axis=0
)


def _nu_weights(nu: np.ndarray) -> np.ndarray:
    """Lagrange weights (n, 3) of the quadratic through nu = 0, 0.25, 0.5."""
    n0, n1, n2 = TABLE_POISSON_RATIOS
    w0 = (nu - n1) * (nu - n2) / ((n0 - n1) * (n0 - n2))
    w1 = (nu - n0) * (nu - n2) / ((n1 - n0) * (n1 - n2))
    w2 = (nu - n0) * (nu - n1) / ((n2 - n0) * (n2 - n1))
    return np.stack([w0, w1, w2], axis=-1)


def _table_interp(a_over_b: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """Interpolated table (n, 4) at a/b inside [0.1, 10]."""
    logc = _LOG_INTERP(np.log(a_over_b)).reshape(-1, 4, 3)
    inv = np.exp(-logc)
    w = _nu_weights(nu)[:, None, :]
    return 1.0 / np.sum(w * inv, axis=-1)


def slender_asymptotes(a_over_b: np.ndarray, poisson_ratio) -> np.ndarray:
    """Kalker's slender-ellipse asymptotes (n, 4) of (C11, C22, C23, C33); see the module docstring.

    For a/b <= 1 the a/b -> 0 expressions are used, for a/b > 1 the b/a -> 0 ones (C33 there is nan:
    no asymptote available).
    """
    a_over_b = np.atleast_1d(np.asarray(a_over_b, dtype=float))
    nu = np.broadcast_to(np.asarray(poisson_ratio, dtype=float), a_over_b.shape)
    out = np.empty(a_over_b.shape + (4,))
    short = a_over_b <= 1.0
    g = np.where(short, a_over_b, 1.0 / a_over_b)
    # a/b -> 0 (rolling direction short)
    c11_s = math.pi**2 / (4.0 * (1.0 - nu))
    c22_s = np.full_like(g, math.pi**2 / 4.0)
    c23_s = math.pi * np.sqrt(g) / (3.0 * (1.0 - nu)) * (1.0 + nu * (np.log(16.0 / g) - 5.0))
    c33_s = math.pi**2 / (16.0 * (1.0 - nu) * g)
    # b/a -> 0 (rolling direction long)
    lam = np.log(16.0 / g**2)
    k = 3.0 - math.log(4.0)
    c11_l = 2.0 * math.pi / ((lam - 2.0 * nu) * g) * (1.0 + k / (lam - 2.0 * nu))
    den = (1.0 - nu) * lam + 2.0 * nu
    c22_l = 2.0 * math.pi / g * (1.0 + (1.0 - nu) * k / den) / den
    c23_l = 2.0 * math.pi / (3.0 * g**1.5 * ((1.0 - nu) * lam - 2.0 + 4.0 * nu))
    out[..., 0] = np.where(short, c11_s, c11_l)
    out[..., 1] = np.where(short, c22_s, c22_l)
    out[..., 2] = np.where(short, c23_s, c23_l)
    out[..., 3] = np.where(short, c33_s, np.nan)
    return out


@dataclass(frozen=True, eq=False)
class CreepCoefficients:
    """Kalker's coefficients for a batch of patches (arrays of one shape, dimensionless)."""

    c11: np.ndarray
    c22: np.ndarray
    c23: np.ndarray
    c33: np.ndarray


def kalker_coefficients(a_over_b, poisson_ratio) -> CreepCoefficients:
    """C11, C22, C23, C33 for semi-axis ratios a/b (a along rolling) and Poisson's ratio nu.

    Args:
        a_over_b: a/b > 0, scalar or array (any shape).
        poisson_ratio: nu in (-1, 0.5], scalar or array broadcastable to a_over_b.

    Returns:
        :class:`CreepCoefficients` with arrays of the broadcast shape.

    Raises:
        ValueError: non-finite or non-positive a/b, or nu outside (-1, 0.5].
    """
    a_over_b, nu = np.broadcast_arrays(np.asarray(a_over_b, dtype=float), np.asarray(poisson_ratio, dtype=float))
    shape = a_over_b.shape
    if not (np.all(np.isfinite(a_over_b)) and np.all(a_over_b > 0)):
        raise ValueError(f"a_over_b = {a_over_b!r}: expected finite values > 0")
    if not (np.all(np.isfinite(nu)) and np.all((nu > -1.0) & (nu <= 0.5))):
        raise ValueError(f"poisson_ratio = {poisson_ratio!r}: expected values in (-1, 0.5]")
    r = a_over_b.ravel()
    nu = nu.ravel()
    out = np.empty((r.size, 4))
    inside = (r >= _EDGE) & (r <= 1.0 / _EDGE)
    if np.any(inside):
        out[inside] = _table_interp(r[inside], nu[inside])
    for mask, edge in ((r < _EDGE, _EDGE), (r > 1.0 / _EDGE, 1.0 / _EDGE)):
        if not np.any(mask):
            continue
        rm, num = r[mask], nu[mask]
        edge_r = np.full_like(rm, edge)
        at_edge = _table_interp(edge_r, num)
        asym_edge = slender_asymptotes(edge_r, num)
        asym = slender_asymptotes(rm, num)
        g_frac = np.where(rm < 1.0, rm, 1.0 / rm) / _EDGE
        rho = at_edge / asym_edge
        matched = asym * (1.0 + (rho - 1.0) * g_frac[:, None])
        # C33 for b/a < 0.1: no asymptote -> held at the table edge
        matched[:, 3] = np.where(np.isnan(asym[:, 3]), at_edge[:, 3], matched[:, 3])
        out[mask] = matched
    return CreepCoefficients(*(out[:, i].reshape(shape) for i in range(4)))
