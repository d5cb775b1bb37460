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

import numpy as np


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
    t = np.hypot(tx, ty)
    limit = f * n
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(limit > 0, t / (3.0 * limit), np.inf)
        one_minus = np.clip(1.0 - w, 0.0, None)
        t_bar = limit * (1.0 - one_minus**3)
        scale = np.where(t > 0, t_bar / t, 0.0)
    return tx * scale, ty * scale
