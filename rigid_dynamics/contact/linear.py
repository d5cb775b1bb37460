"""Kalker's linear theory of rolling contact (full adhesion), seed eq 50-52, vectorised.

Forces and spin moment on the wheel, contact frame (x rolling, y lateral, z normal rail -> wheel)::

    Fx = -G a b C11 xi                                   (eq 50)
    Fy = -G a b C22 eta - G (ab)^1.5 C23 phi             (eq 51)
    Mz =  G (ab)^1.5 C23 eta - G (ab)^2 C33 phi          (eq 52 with C32 = -C23, REFERENCES.md)

Symbols: a, b semi-axes along x and y (m); G shear modulus (Pa); xi, eta longitudinal and
lateral creepage (-); phi spin creepage (1/m); C_ij from :mod:`rigid_dynamics.contact.kalker`.
Positive lateral creepage and positive spin both give a negative lateral force (the same signs
as the open-source CONTACT program). Valid for small creepages only: no saturation at mu N.
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.contact.kalker import CreepCoefficients, kalker_coefficients
from rigid_dynamics.contact.lazy_kernels import compiled_copies, run_as_python


def _linear_one(shear_modulus_Pa, a, b, c11, c22, c23, c33, xi, eta, phi):
    """(Fx, Fy, Mz) of the linear theory (eq 50-52) for one patch: the one implementation (the batch
    :func:`linear_creep_forces` and the compiled dynamics loop call it; ``linear_one`` is its compiled copy).
    """
    ab = a * b
    g_ab = shear_modulus_Pa * ab
    g_ab15 = g_ab * math.sqrt(ab)
    return -g_ab * c11 * xi, -g_ab * c22 * eta - g_ab15 * c23 * phi, g_ab15 * c23 * eta - g_ab * ab * c33 * phi


def _linear_many(shear_modulus_Pa, a, b, c, xi, eta, phi, out):
    """:func:`_linear_one` over flat arrays; c = (C11, C22, C23, C33) arrays; out (3, n)."""
    c11, c22, c23, c33 = c
    for k in range(a.shape[0]):
        out[0, k], out[1, k], out[2, k] = _linear_one(
            shear_modulus_Pa, a[k], b[k], c11[k], c22[k], c23[k], c33[k], xi[k], eta[k], phi[k]
        )


def compiled_kernels() -> dict:
    """Name -> numba-compiled copy of ``_linear_one`` (inlined, no NRT: the compiled dynamics loop's law) and
    ``_linear_many`` (lazy_kernels.compiled_copies; imports numba).
    """
    inline = {"_nrt": False, "inline": "always"}
    return compiled_copies(__name__, ("_linear_one", "_linear_many"), options={"_linear_one": inline})


def __getattr__(name):
    """``linear_one``: the compiled copy of :func:`_linear_one` (imports numba when first asked for)."""
    if name == "linear_one":
        return compiled_kernels()["_linear_one"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def linear_creep_forces(
    semi_axis_long_m,
    semi_axis_lat_m,
    longitudinal,
    lateral,
    spin_1_per_m,
    *,
    shear_modulus_Pa: float,
    poisson_ratio: float,
    coefficients: CreepCoefficients | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Creep forces Fx, Fy (N) and spin moment Mz (N m) of the linear theory for many patches.

    Args:
        semi_axis_long_m: a, m (> 0), array or scalar.
        semi_axis_lat_m: b, m (> 0).
        longitudinal: xi, longitudinal creepage.
        lateral: eta, lateral creepage.
        spin_1_per_m: phi, spin creepage, 1/m.
        shear_modulus_Pa: G, Pa.
        poisson_ratio: nu (selects the C_ij).
        coefficients: precomputed C_ij for these patches (else interpolated from Kalker's table).

    Returns:
        (Fx, Fy, Mz) arrays of the broadcast shape (on the wheel, contact frame).
    """
    a, b, xi, eta, phi = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (semi_axis_long_m, semi_axis_lat_m, longitudinal, lateral, spin_1_per_m))
    )
    if not (np.all(a > 0) and np.all(b > 0)):
        raise ValueError("semi-axes: expected semi_axis_long_m > 0 and semi_axis_lat_m > 0")
    c = coefficients if coefficients is not None else kalker_coefficients(a / b, poisson_ratio)
    flat = [np.ascontiguousarray(np.broadcast_to(v, a.shape), dtype=float).ravel() for v in (a, b, xi, eta, phi)]
    coef = tuple(
        np.ascontiguousarray(np.broadcast_to(v, a.shape), dtype=float).ravel() for v in (c.c11, c.c22, c.c23, c.c33)
    )
    out = np.empty((3, flat[0].size))
    kernel = _linear_many if run_as_python(out.shape[1], __name__) else compiled_kernels()["_linear_many"]
    kernel(float(shear_modulus_Pa), flat[0], flat[1], coef, flat[2], flat[3], flat[4], out)
    return out[0].reshape(a.shape), out[1].reshape(a.shape), out[2].reshape(a.shape)
