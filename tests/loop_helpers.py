"""Shared helpers of the tests/test_loop_sampled_*.py modules (the dynamics loop's contact against CONTACT's)."""

from __future__ import annotations


def height_at_load(right_wheel, target_N, z_lo, z_hi, tolerance, max_iterations, label):
    """The height (between ``z_lo``, out of contact, and ``z_hi``, deeper) at which the right wheel carries
    ``target_N``, by the Illinois method (regula falsi, the retained end's value halved when the same end is kept
    twice) on load^(2/3), linear in the height for a Hertzian contact. ``right_wheel(z)`` returns (contact, right,
    load_N); the result is (z, contact, right) of the first evaluation within ``tolerance`` of the load (relative).
    ``label`` names the case in the failure messages."""
    target = target_N ** (2 / 3)
    f_lo = -target
    f_hi = right_wheel(z_hi)[2] ** (2 / 3) - target
    assert f_hi > 0, f"{label}: the deep height {z_hi} m carries less than {target_N} N"
    side = 0
    for _ in range(max_iterations):
        z = z_hi - f_hi * (z_hi - z_lo) / (f_hi - f_lo)
        contact, right, load = right_wheel(z)
        f = load ** (2 / 3) - target
        if abs(load / target_N - 1.0) < tolerance:
            return z, contact, right
        if f > 0:
            z_hi, f_hi = z, f
            f_lo = 0.5 * f_lo if side == 1 else f_lo
            side = 1
        else:
            z_lo, f_lo = z, f
            f_hi = 0.5 * f_hi if side == -1 else f_hi
            side = -1
    raise AssertionError(f"{label}: the height iteration did not reach {target_N} N: {load} N")
