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


def curve_flange_bem_at(state_values: dict):
    """curve-flange with ``contact_model = "bem"`` (patches formed as CONTACT's module 1 forms them), no settling
    distance, started at ``state_values`` (benchmarks/make_contact_curve_flange.py STATE: CONTACT's deck state):
    (WheelsetModel, the 12-state vector)."""
    import numpy as np

    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    s = state_values
    path = resolve_scene_path("curve-flange")
    doc = read_toml(path, "scene file")
    doc["settling_distance_m"], doc["contact_model"] = 0.0, "bem"
    doc["initial"] = {**doc.get("initial", {}), "lateral_displacement_m": s["y_m"], "yaw_rad": s["yaw_rad"]}
    scene = parse_scene(doc, base_dir=path.parent)
    model = WheelsetModel(scene, build_provider(scene), get_contact_model("bem"), model_options("bem", scene))
    state = np.zeros(12)
    state[1:5] = s["y_m"], s["z_m"], s["yaw_rad"], s["roll_rad"]
    state[6], state[11] = s["x_velocity_m_per_s"], s["spin_rate_rad_per_s"]
    return model, state
