"""Running-direction irregularities (R_irr(alpha) of the wheel, N_irr(x) of the rail; irregular.py) are
added by a section in the rolling plane: the wheel point at beta from the lowest point (material angle
alpha = pi/2 + beta - phi, kinematics.py) has radius r(beta) = R + R_irr(alpha) and reaches
(r cos(beta) - R) further down than the ideal lowest point, at x offset -r sin(beta); the approach is
q(beta) = q0 + [r cos(beta) - R - N_irr(x + x_offset)] cos(gamma), maximised over beta (grid, then Newton;
the bracket is the extra vertical overlap, projected on the contact normal of contact angle gamma). The
normal is the rail's, (N_irr', N_y, -1) normalised; A is built from the polar curvature of r(beta)
and N_irr''. Where a flat makes the wheel locally concave, A is floored at ``MIN_LONGITUDINAL_CURVATURE_FRACTION``
times its nominal value (a Hertzian stand-in for what is a two-point, non-Hertzian contact).
"""

from __future__ import annotations

import math

import numpy as np

from rigid_dynamics.wheelset.irregular import dip_depth_m, rail_irregularity, wheel_radius_irregularity
from rigid_dynamics.wheelset.parameters import Irregularities
from rigid_dynamics.wheelset.providers.patches import MIN_LONGITUDINAL_CURVATURE_FRACTION, PatchSet


def running_irregularity(patches: PatchSet, sides_mask, centre_m, spin_rad, irr: Irregularities, r0: float):
    """Add R_irr(alpha), N_irr(x) to the candidates of the sides in ``sides_mask`` (module docstring).

    Vectorised over the candidates; candidates with a gap larger than twice the irregularity amplitude are
    left alone (the irregularity cannot close it).
    """
    wheel_on = (irr.polygon_order > 0 and irr.polygon_amplitude_m > 0) or irr.flat_length_m > 0
    rail_on = irr.corrugation_amplitude_m > 0 or irr.joint_dip_angle_rad > 0
    reach = 2.0 * (irr.polygon_amplitude_m + irr.corrugation_amplitude_m + dip_depth_m(irr)) + 1e-4
    half = 0.02
    if irr.flat_length_m > 0:
        from rigid_dynamics.wheelset.irregular import flat_depth_m

        reach += 2.0 * flat_depth_m(irr, r0)
        half = max(half, 1.5 * irr.flat_length_m / r0)
    if irr.corrugation_amplitude_m > 0:
        half = max(half, 0.6 * irr.corrugation_wavelength_m / r0)
    sel = np.flatnonzero(sides_mask[patches.side] & (patches.approach_m > -reach))
    if len(sel) == 0:
        return patches
    radius = patches.rolling_radius_m[sel][:, None]
    x0 = patches.point_m[sel, 0][:, None]

    def parts(beta):
        if wheel_on:
            rv, r1, r2 = wheel_radius_irregularity(irr, r0, 0.5 * math.pi + beta - spin_rad)
        else:
            rv = r1 = r2 = np.zeros_like(beta)
        r = radius + rv
        sb, cb = np.sin(beta), np.cos(beta)
        xo = -r * sb
        x1 = -(r1 * sb + r * cb)
        x2 = -(r2 * sb + 2 * r1 * cb - r * sb)
        if rail_on:
            n0, n1, n2 = rail_irregularity(irr, x0 + xo)
        else:
            n0 = n1 = n2 = np.zeros_like(r)
        q = r * cb - radius - n0
        q1 = r1 * cb - r * sb - n1 * x1
        q2 = r2 * cb - 2 * r1 * sb - r * cb - n2 * x1 * x1 - n1 * x2
        return q, q1, q2, r, r1, r2, xo, n1, n2

    grid = np.linspace(-half, half, 81)[None, :]
    q = parts(np.broadcast_to(grid, (len(sel), grid.shape[1])))[0]
    beta = grid[0, np.argmax(q, axis=1)][:, None]
    step_size = 2 * half / 80
    for _ in range(3):
        _, q1, q2, *_ = parts(beta)
        ok = q2 < 0
        step = np.where(ok, -q1 / np.where(ok, q2, -1.0), 0.0)
        beta = np.clip(beta + np.clip(step, -step_size, step_size), -half, half)
    qv, _, _, r, r1, r2, xo, n1, n2 = (np.asarray(v)[:, 0] for v in parts(beta))
    beta = beta[:, 0]
    kappa_w = (r * r + 2 * r1 * r1 - r * r2) / (r * r + r1 * r1) ** 1.5
    # scale the wheel's polar curvature like the ideal one (cone: cos(gamma_w) = 2 A R)
    scale = 2.0 * patches.curvature_long_1_per_m[sel] * radius[:, 0]
    a_long = 0.5 * (kappa_w * scale + n2 / (1 + n1 * n1) ** 1.5)
    normal = patches.normal[sel]
    slope_y = normal[:, 1] / -normal[:, 2]
    new_normal = np.stack([n1, slope_y, -np.ones_like(n1)], axis=-1)
    new_normal /= np.linalg.norm(new_normal, axis=1, keepdims=True)
    floor = MIN_LONGITUDINAL_CURVATURE_FRACTION * 0.5 / r0
    # qv is the extra overlap measured vertically; the approach is along the normal (cos(gamma) = -n_z)
    patches.approach_m[sel] = patches.approach_m[sel] + qv * -normal[:, 2]
    patches.point_m[sel, 0] += xo
    patches.point_m[sel, 2] += r * np.cos(beta) - radius[:, 0]
    patches.normal[sel] = new_normal
    patches.rolling_radius_m[sel] = r
    patches.curvature_long_1_per_m[sel] = np.maximum(a_long, floor)
    return patches
