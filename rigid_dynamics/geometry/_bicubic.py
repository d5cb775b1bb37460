"""Compiled (numba) evaluation of a tensor-product cubic B-spline and its derivatives to second order, touching only
the 4 x 4 coefficients that are nonzero at a point (MeasuredWheelIrregularity.evaluate).

The basis functions and their derivatives are the Cox-de Boor recursion with the derivative formula of Piegl and
Tiller, The NURBS Book (2nd ed., 1997), algorithm A2.3 (the mathematics, written here for degree 3 and 2
derivatives). Value at (a, y): sum_ij N_i(a) M_j(y) C[i, j]; the first axis may be periodic (a mapped into the base
interval [t[3], t[n]] as scipy's ``extrapolate="periodic"``). The cost per point is independent of the grid's size;
the dense evaluation it replaces (every basis function of y at every point) cost n_y times more.
"""

from __future__ import annotations

import numpy as np
from numba import njit

DEGREE = 3


@njit(cache=True)
def _span(t, n_coef, x):
    """Index i with t[i] <= x < t[i + 1], clipped to [3, n_coef - 1] (the last interval includes its right end)."""
    lo, hi = DEGREE, n_coef  # t[lo] <= x < t[hi] after clipping x
    if x >= t[n_coef]:
        return n_coef - 1
    if x <= t[lo]:
        return lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if x < t[mid]:
            hi = mid
        else:
            lo = mid
    return lo


@njit(cache=True)
def _basis_ders(t, i, x, ders):
    """ders[k, j]: the k-th derivative (k = 0, 1, 2) of the basis function N_{i-3+j} at x (The NURBS Book, A2.3)."""
    p = DEGREE
    ndu = np.empty((p + 1, p + 1))
    left = np.empty(p + 1)
    right = np.empty(p + 1)
    a = np.empty((2, p + 1))
    ndu[0, 0] = 1.0
    for j in range(1, p + 1):
        left[j] = x - t[i + 1 - j]
        right[j] = t[i + j] - x
        saved = 0.0
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]
            temp = ndu[r, j - 1] / ndu[j, r]
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved
    for j in range(p + 1):
        ders[0, j] = ndu[j, p]
    for r in range(p + 1):
        s1, s2 = 0, 1
        a[0, 0] = 1.0
        for k in range(1, 3):
            d = 0.0
            rk, pk = r - k, p - k
            if r >= k:
                a[s2, 0] = a[s1, 0] / ndu[pk + 1, rk]
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2, j] = (a[s1, j] - a[s1, j - 1]) / ndu[pk + 1, rk + j]
                d += a[s2, j] * ndu[rk + j, pk]
            if r <= pk:
                a[s2, k] = -a[s1, k - 1] / ndu[pk + 1, r]
                d += a[s2, k] * ndu[r, pk]
            ders[k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, 3):
        for j in range(p + 1):
            ders[k, j] *= factor
        factor *= p - k


@njit(cache=True)
def evaluate_bicubic(ta, tb, coef, periodic_a, a, y, out):
    """out[m, q] for points q: m = 0 value, 1 d/da, 2 d/dy, 3 d2/da2, 4 d2/dady, 5 d2/dy2 (y within tb's range:
    the caller clips it).
    """
    na, nb = coef.shape
    lo_a, hi_a = ta[DEGREE], ta[na]
    da = np.empty((3, DEGREE + 1))
    db = np.empty((3, DEGREE + 1))
    for q in range(a.size):
        x = a[q]
        if periodic_a:
            x = lo_a + (x - lo_a) % (hi_a - lo_a)
        ia = _span(ta, na, x)
        ib = _span(tb, nb, y[q])
        _basis_ders(ta, ia, x, da)
        _basis_ders(tb, ib, y[q], db)
        v = np.zeros(6)
        for j in range(DEGREE + 1):
            row = ia - DEGREE + j
            for m in range(DEGREE + 1):
                c = coef[row, ib - DEGREE + m]
                v[0] += da[0, j] * db[0, m] * c
                v[1] += da[1, j] * db[0, m] * c
                v[2] += da[0, j] * db[1, m] * c
                v[3] += da[2, j] * db[0, m] * c
                v[4] += da[1, j] * db[1, m] * c
                v[5] += da[0, j] * db[2, m] * c
        for m in range(6):
            out[m, q] = v[m]
