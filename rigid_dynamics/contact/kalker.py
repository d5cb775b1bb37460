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

from rigid_dynamics.contact.lazy_kernels import compiled_copies, run_as_python

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


def pchip_coefficients(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Coefficients of the monotone piecewise cubic Hermite interpolant (PCHIP) of the columns of ``y`` over ``x``.

    The interpolant of scipy's ``PchipInterpolator`` (Fritsch & Butland 1984: at an interior point the weighted
    harmonic mean of the neighbouring slopes, 0 where they differ in sign; the one-sided three-point ends of
    Moler, Numerical Computing with MATLAB, sec. 3.4), in numpy only, so that importing the creep coefficients
    does not import scipy.interpolate (a third of a small command's start-up). ``tests/test_kalker.py`` checks it
    against scipy's.

    Args:
        x: (n,) increasing breakpoints, n >= 3.
        y: (n, m) values.

    Returns:
        c: (4, n - 1, m), the interval k's cubic c[0] t^3 + c[1] t^2 + c[2] t + c[3] in t = x - x[k] (scipy's
        ``PPoly.c`` layout).
    """
    h = np.diff(x)[:, None]
    slope = np.diff(y, axis=0) / h
    d = np.zeros_like(y)
    w1, w2 = 2.0 * h[1:] + h[:-1], h[1:] + 2.0 * h[:-1]
    same = (np.sign(slope[1:]) == np.sign(slope[:-1])) & (slope[1:] != 0) & (slope[:-1] != 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = (w1 / slope[:-1] + w2 / slope[1:]) / (w1 + w2)
        d[1:-1] = np.where(same, 1.0 / mean, 0.0)

    def edge(h0, h1, m0, m1):
        end = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
        end = np.where(np.sign(end) != np.sign(m0), 0.0, end)
        return np.where((np.sign(m0) != np.sign(m1)) & (np.abs(end) > 3.0 * np.abs(m0)), 3.0 * m0, end)

    d[0] = edge(h[0], h[1], slope[0], slope[1])
    d[-1] = edge(h[-1], h[-2], slope[-1], slope[-2])
    c = np.empty((4, len(x) - 1, y.shape[1]))
    t = (d[:-1] + d[1:] - 2.0 * slope) / h  # scipy's order of operations: bit-identical coefficients
    c[0] = t / h
    c[1] = (slope - d[:-1]) / h - t
    c[2] = d[:-1]
    c[3] = y[:-1]
    return c


# the piecewise cubics in log(a/b) of log C_ij as plain arrays for the compiled kernels: breakpoints, coefficients
_PP_X = np.ascontiguousarray(np.log(KALKER_TABLE.a_over_b))
_PP_C = np.ascontiguousarray(  # (4, 18, 12): column = 3 * coefficient + nu column
    pchip_coefficients(_PP_X, np.log(KALKER_TABLE.values.reshape(len(KALKER_TABLE.a_over_b), 12)))
)
_NU0, _NU1, _NU2 = TABLE_POISSON_RATIOS
_LOG4 = math.log(4.0)


def _table_one(log_r, nu, out):
    """Interpolated table at ln(a/b) inside the table: PCHIP in ln(a/b), quadratic of 1/C in nu."""
    i = np.searchsorted(_PP_X, log_r) - 1
    i = min(max(i, 0), _PP_X.shape[0] - 2)
    t = log_r - _PP_X[i]
    w0 = (nu - _NU1) * (nu - _NU2) / ((_NU0 - _NU1) * (_NU0 - _NU2))
    w1 = (nu - _NU0) * (nu - _NU2) / ((_NU1 - _NU0) * (_NU1 - _NU2))
    w2 = (nu - _NU0) * (nu - _NU1) / ((_NU2 - _NU0) * (_NU2 - _NU1))
    for c in range(4):
        inv = 0.0
        for j in range(3):
            col = 3 * c + j
            v = ((_PP_C[0, i, col] * t + _PP_C[1, i, col]) * t + _PP_C[2, i, col]) * t + _PP_C[3, i, col]
            w = w0 if j == 0 else (w1 if j == 1 else w2)
            inv += w * math.exp(-v)
        out[c] = 1.0 / inv


def _asymptote_one(a_over_b, nu, out):
    """Kalker's slender-ellipse asymptotes (module docstring); C33 = nan for b/a -> 0."""
    if a_over_b <= 1.0:
        g = a_over_b
        out[0] = math.pi**2 / (4.0 * (1.0 - nu))
        out[1] = math.pi**2 / 4.0
        out[2] = math.pi * math.sqrt(g) / (3.0 * (1.0 - nu)) * (1.0 + nu * (math.log(16.0 / g) - 5.0))
        out[3] = math.pi**2 / (16.0 * (1.0 - nu) * g)
    else:
        g = 1.0 / a_over_b
        lam = math.log(16.0 / (g * g))
        k = 3.0 - _LOG4
        out[0] = 2.0 * math.pi / ((lam - 2.0 * nu) * g) * (1.0 + k / (lam - 2.0 * nu))
        den = (1.0 - nu) * lam + 2.0 * nu
        out[1] = 2.0 * math.pi / g * (1.0 + (1.0 - nu) * k / den) / den
        out[2] = 2.0 * math.pi / (3.0 * g**1.5 * ((1.0 - nu) * lam - 2.0 + 4.0 * nu))
        out[3] = math.nan


def _coefficients_many(a_over_b, nu, out):
    edge = np.empty(4)
    asym_edge = np.empty(4)
    asym = np.empty(4)
    lo = _PP_X[0]
    hi = _PP_X[-1]
    for i in range(a_over_b.shape[0]):
        r = a_over_b[i]
        log_r = math.log(r)
        if lo <= log_r <= hi:
            _table_one(log_r, nu[i], out[i])
            continue
        edge_r = _EDGE if r < 1.0 else 1.0 / _EDGE
        _table_one(lo if r < 1.0 else hi, nu[i], edge)
        _asymptote_one(edge_r, nu[i], asym_edge)
        _asymptote_one(r, nu[i], asym)
        g_frac = (r if r < 1.0 else 1.0 / r) / _EDGE
        for c in range(4):
            if math.isnan(asym[c]):
                out[i, c] = edge[c]  # C33 for b/a < 0.1: held at the table edge
            else:
                out[i, c] = asym[c] * (1.0 + (edge[c] / asym_edge[c] - 1.0) * g_frac)


def _asymptotes_many(a_over_b, nu, out):
    for i in range(a_over_b.shape[0]):
        _asymptote_one(a_over_b[i], nu[i], out[i])


def compiled_kernels() -> dict:
    """Name -> numba-compiled copy of this module's loops (``_table_one``, ``_asymptote_one``,
    ``_coefficients_many``, ``_asymptotes_many``; lazy_kernels.compiled_copies; imports numba).
    """
    return compiled_copies(__name__, ("_table_one", "_asymptote_one", "_coefficients_many", "_asymptotes_many"))


def slender_asymptotes(a_over_b: np.ndarray, poisson_ratio) -> np.ndarray:
    """Kalker's slender-ellipse asymptotes (n, 4) of (C11, C22, C23, C33); see the module docstring.

    For a/b <= 1 the a/b -> 0 expressions are used, for a/b > 1 the b/a -> 0 ones (C33 there is nan:
    no asymptote available).
    """
    a_over_b = np.atleast_1d(np.asarray(a_over_b, dtype=float))
    nu = np.broadcast_to(np.asarray(poisson_ratio, dtype=float), a_over_b.shape)
    out = np.empty((a_over_b.size, 4))
    (_asymptotes_many if run_as_python(out.shape[0], __name__) else compiled_kernels()["_asymptotes_many"])(
        np.array(a_over_b.ravel(), dtype=float), np.array(nu.ravel(), dtype=float), out
    )
    return out.reshape(a_over_b.shape + (4,))


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
    out = np.empty((a_over_b.size, 4))
    (_coefficients_many if run_as_python(out.shape[0], __name__) else compiled_kernels()["_coefficients_many"])(
        np.array(a_over_b.ravel(), dtype=float), np.array(nu.ravel(), dtype=float), out
    )
    return CreepCoefficients(*(out[:, i].reshape(shape) for i in range(4)))
