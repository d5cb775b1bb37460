"""Vermeulen-Johnson saturation of the linear creep forces (seed eq 53-58, with the cube).

From the linear-theory forces (Tx, Ty) (seed eq 50-51, :mod:`rigid_dynamics.contact.linear`)::

    T  = sqrt(Tx^2 + Ty^2)                                 (eq 54)
    w' = T / (3 f N)                                       (eq 55)
    T_bar = f N [1 - (1 - w')^3]   for w' <= 1             (eq 56, corrected: the seed prints
          = f N                    for w' > 1               the square; REFERENCES.md)
    T_bar_x = Tx T_bar / T,  T_bar_y = Ty T_bar / T        (eq 57-58)

f is the friction coefficient mu, N the normal force. With the cube, T_bar = T (1 - w' + w'^2/3)
-> T for small creepage (the linear theory) and T_bar -> f N at large creepage. The law is meant
for zero or small spin (Vermeulen & Johnson 1964; Kalker 1990): the spin enters only through
its linear contribution to Ty. No spin moment is produced.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.contact.lazy_kernels import compiled_copies, run_as_python


def _saturate_one(tx, ty, limit):
    """(T_bar_x, T_bar_y) of linear forces (tx, ty) under the limit f N (eq 53-58) for one patch: the one
    implementation (the batch :func:`vermeulen_johnson_saturation` and the compiled dynamics loop call it;
    ``saturate_one`` is its compiled copy).
    """
    tt = math.hypot(tx, ty)
    if tt > 0.0:
        wprime = tt / (3.0 * limit) if limit > 0 else np.inf
        one = max(1.0 - wprime, 0.0)
        scale = limit * (1.0 - one * (one * one)) / tt  # one**3 as numba compiles it (same bits as Python)
        return tx * scale, ty * scale
    return tx, ty


def _saturate_many(tx, ty, limit, out):
    """:func:`_saturate_one` over flat arrays into out (2, n)."""
    for k in range(tx.shape[0]):
        out[0, k], out[1, k] = _saturate_one(tx[k], ty[k], limit[k])


def compiled_kernels() -> dict:
    """Name -> numba-compiled copy of ``_saturate_one`` (inlined, no NRT: the compiled dynamics loop's law) and
    ``_saturate_many`` (lazy_kernels.compiled_copies; imports numba).
    """
    inline = {"_nrt": False, "inline": "always"}
    return compiled_copies(__name__, ("_saturate_one", "_saturate_many"), options={"_saturate_one": inline})


def __getattr__(name):
    """``saturate_one``: the compiled copy of :func:`_saturate_one` (imports numba when first asked for)."""
    if name == "saturate_one":
        return compiled_kernels()["_saturate_one"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def vermeulen_johnson_saturation(
    linear_force_long_N, linear_force_lat_N, normal_force_N, friction_coefficient
) -> tuple[np.ndarray, np.ndarray]:
    """Saturate linear-theory forces (Tx, Ty) by the Vermeulen-Johnson cubic law (eq 53-58).

    Args:
        linear_force_long_N: Tx of the linear theory, N (array or scalar).
        linear_force_lat_N: Ty of the linear theory, N.
        normal_force_N: N, N (>= 0).
        friction_coefficient: f = mu (>= 0).

    Returns:
        (T_bar_x, T_bar_y), N, same direction as (Tx, Ty), magnitude <= f N.
    """
    tx, ty, n, f = np.broadcast_arrays(
        *(
            np.asarray(v, dtype=float)
            for v in (linear_force_long_N, linear_force_lat_N, normal_force_N, friction_coefficient)
        )
    )
    if np.any(n < 0) or np.any(f < 0):
        raise ValueError("normal_force_N and friction_coefficient: expected values >= 0")
    shape = tx.shape
    out = np.empty((2, tx.size))
    kernel = _saturate_many if run_as_python(out.shape[1], __name__) else compiled_kernels()["_saturate_many"]
    kernel(*(np.ascontiguousarray(v, dtype=float).ravel() for v in (tx, ty, f * n)), out)
    return out[0].reshape(shape), out[1].reshape(shape)
