"""The traction controller of the dynamics (rigid_dynamics/wheelset/traction.py, scene table ``[traction]``).

* Below the adhesion limit (traction-adhesion with a force demand of 40 kN, about 0.23 of the normal force on
  Polach's falling law with mu_0 = 0.40): the held force equals the demand (steady state of a controller with an
  integral term), and the steady longitudinal creepage equals the root of the static law, FASTSIM
  (contact.fastsim.fastsim_batch, the static rung) at the recorded patches, at that force: an independent solve of
  the steady state, not the loop's own number.
* Above it (the shipped scene, adhesion demand 0.45 > mu_0): the adhesion-limit event, then wheel slide, the torque
  at its limit.
* The sampled PI law against its closed form on a static plant, and its anti-windup.
* Bad [traction] input exits 2 with one line.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hardening_helpers import assert_bad_scene, run

from rigid_dynamics.wheelset.traction import TractionControl, TractionController

FORCE_DEMAND_N = 40.0e3


@pytest.fixture(scope="module")
def held():
    """traction-adhesion with a force demand of 40 kN held for 0.3 s (ramp 50 ms)."""
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    scene = load_scene("traction-adhesion")
    control = replace(scene.traction, mode="force", force_demand_N=FORCE_DEMAND_N)
    return simulate(replace(scene, duration_s=0.3, traction=control))


@pytest.fixture(scope="module")
def limited():
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    return simulate(load_scene("traction-adhesion"))


def _total(result, name):
    return np.nansum(result.patches[name], axis=(1, 2))


def test_force_demand_is_held(held):
    """Over the last 50 ms the total longitudinal creep force stays within 1e-4 of the demand (measured: 5e-6),
    below the adhesion limit: no adhesion event."""
    assert held.status == "ok", held.message
    late = held.t >= 0.25
    force = _total(held, "creep_force_long_N")
    assert np.max(np.abs(force[late] - FORCE_DEMAND_N)) < 1e-4 * FORCE_DEMAND_N
    series = held.traction
    np.testing.assert_allclose(series["traction_measured_force_N"], force, rtol=1e-12, atol=1e-9)
    assert np.all(series["traction_demand_N"][late] == FORCE_DEMAND_N)
    # the steady torque against the force: the rolling radius (0.46 m nominal)
    torque = series["traction_torque_N_m"][-1]
    assert torque / FORCE_DEMAND_N == pytest.approx(0.46, rel=2e-3)
    assert not [e for e in held.events if e[0] in ("adhesion-limit", "wheel-slide")]


def test_braking_adhesion_demand_is_held():
    """A braking adhesion demand of -0.3 (below mu_0 = 0.4): the ratio of the total longitudinal creep force to the
    total normal force holds -0.3 within 1e-4 over the last 50 ms, the torque brakes (< 0), no adhesion event."""
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    scene = load_scene("traction-adhesion")
    result = simulate(replace(scene, duration_s=0.3, traction=replace(scene.traction, adhesion_demand=-0.3)))
    assert result.status == "ok", result.message
    late = result.t >= 0.25
    ratio = _total(result, "creep_force_long_N") / _total(result, "normal_force_N")
    assert np.max(np.abs(ratio[late] + 0.3)) < 1e-4
    assert np.all(result.traction["traction_torque_N_m"][late] < 0.0)
    assert not [e for e in result.events if e[0] in ("adhesion-limit", "wheel-slide")]


def test_steady_creepage_is_the_static_root(held):
    """The creepage the controller settles at is where the static FASTSIM of both recorded patches (same grid
    20 x 20, same Polach law at the rolling speed) gives the demanded force. The two wheels' creepages differ by
    their kinematics (0.4 % here: rolling radii, yaw), so the static root is sought for a common shift s of both,
    xi_i + s: it is zero to within 1e-3 of xi (measured in the message)."""
    from scipy.optimize import brentq

    from rigid_dynamics.contact.fastsim import fastsim_batch

    scene = held.scene
    p = {name: values[-1, :, 0] for name, values in held.patches.items()}  # (2 sides,) tread patches
    law = scene.material.friction_law()
    xi_loop = p["creepage_long"]

    def static_force(shift):
        forces = fastsim_batch(
            p["semi_axis_long_m"], p["semi_axis_lat_m"], p["normal_force_N"], xi_loop + shift, p["creepage_lat"],
            p["spin_creepage_1_per_m"], shear_modulus_Pa=scene.material.shear_modulus_Pa,
            poisson_ratio=scene.material.poisson_ratio, friction_coefficient=law,
            rolling_speed_m_per_s=scene.speed_m_per_s, nx=scene.fastsim_elements_per_strip, ny=scene.fastsim_strips,
        ).creep_force_long_N  # fmt: skip
        return float(np.sum(forces))

    xi = float(np.mean(xi_loop))
    sign = math.copysign(1.0, static_force(0.0))  # which way the static law's force points at the loop's creepage
    shift = brentq(lambda s: sign * static_force(s) - FORCE_DEMAND_N, -0.5 * xi, 0.5 * xi, xtol=1e-14)
    print(f"steady xi: loop {xi_loop}, static root shift {shift:.3g} ({shift / abs(xi):.3g} of xi)")
    assert abs(shift) < 1e-3 * abs(xi)


def test_adhesion_limit_then_slide(limited):
    """traction-adhesion (demand 0.45 > mu_0 = 0.40): the creep force peaks below mu_0 N (the adhesion-limit event),
    falls while the slip grows, the torque sits at its limit and the wheels slide, in that order on both sides."""
    result = limited
    assert result.status == "ok", result.message
    kinds = [(kind, side) for kind, side, _ in result.events]
    for side in ("left", "right"):
        assert kinds.index(("adhesion-limit", side)) < kinds.index(("wheel-slide", side))
    ratio = _total(result, "creep_force_long_N") / _total(result, "normal_force_N")
    peak = int(np.argmax(ratio))
    assert 0.3 < ratio[peak] < 0.40
    assert ratio[-1] < 0.5 * ratio[peak]
    torque = result.traction["traction_torque_N_m"]
    assert torque[-1] == result.scene.traction.torque_limit_N_m
    assert np.all(np.abs(torque) <= result.scene.traction.torque_limit_N_m)
    summary = result.summary()
    assert summary["traction"]["mode"] == "adhesion"
    assert {e["kind"] for e in summary["events"]} >= {"adhesion-limit", "wheel-slide"}


def test_slip_protection_holds_the_slip_limit():
    """slip_limit = 0.01 (beyond the creep curve's maximum): past the adhesion limit the wheels are held at
    |xi| = 0.01 (within 3e-3 of it over the last 50 ms), no wheel slide;
    the force on the falling branch, below the maximum."""
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    scene = load_scene("traction-adhesion")
    result = simulate(replace(scene, duration_s=0.3, traction=replace(scene.traction, slip_limit=0.01)))
    assert result.status == "ok", result.message
    kinds = {kind for kind, _, _ in result.events}
    assert "adhesion-limit" in kinds and "wheel-slide" not in kinds
    late = result.t >= 0.25
    xi = np.abs(result.patches["creepage_long"][:, :, 0])
    deviation = np.max(np.abs(xi[late].max(axis=1) - 0.01)) / 0.01
    print(f"slip held at 0.01 to {deviation:.3g} (relative) over 0.25-0.3 s; overshoot {xi.max() / 0.01 - 1:.3g}")
    assert deviation < 3e-3
    ratio = _total(result, "creep_force_long_N") / _total(result, "normal_force_N")
    assert ratio[-1] < np.max(ratio)
    assert np.all(result.traction["traction_torque_N_m"] < scene.traction.torque_limit_N_m)


def test_dp54_runs_the_controller_as_rk4(limited):
    """Regression of the two integrators of the compiled loop under the controller (DP54 stops at each sample as RK4
    does): the same events and the peak adhesion ratio to 1e-4."""
    from rigid_dynamics.wheelset import simulate

    scene = limited.scene
    dp54 = simulate(replace(scene, integrator=replace(scene.integrator, method="DP54")), companions=False)
    assert dp54.status == "ok", dp54.message
    assert dp54.events == limited.events

    def peak(result):
        return np.max(_total(result, "creep_force_long_N") / _total(result, "normal_force_N"))

    assert peak(dp54) == pytest.approx(peak(limited), abs=1e-4)


def test_the_python_path_refuses_the_controller():
    """compiled = False: the controller runs in the compiled loop only; a ValueError naming the key."""
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    with pytest.raises(ValueError, match=r"traction\.mode = 'adhesion': the traction controller runs in the compiled"):
        simulate(replace(load_scene("traction-adhesion"), duration_s=0.01), compiled=False)


def test_cli_prints_the_events(tmp_path, capsys):
    """``wheelrail run`` prints the events it writes to summary.json, and the controller's last sample."""
    import json

    code, out, _ = run(capsys, "run", "traction-adhesion", "--out", tmp_path / "run", "--quiet", "--no-plots")
    assert code == 0, out
    line = next(line for line in out.splitlines() if line.startswith("events: "))
    assert "adhesion-limit left at" in line and "wheel-slide right at" in line
    assert "traction controller (adhesion 0.45 of the normal force)" in out
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert len(summary["events"]) == line.count(" at ")
    arrays = np.load(tmp_path / "run" / "timeseries.npz")
    assert arrays["traction_torque_N_m"].shape == arrays["t"].shape
    header = (tmp_path / "run" / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert {"traction_torque_N_m", "traction_demand_N", "traction_measured_force_N"} <= set(header)


def test_pi_law_on_a_static_plant():
    """The sampled PI law against its closed form on a plant F_k = c T_(k-1) / r_0 (c = 0.9: a 10 % bias the
    feed-forward cannot see): the fixed point F = D, T = r_0 D / c, reached geometrically at the rate of the dominant
    root of z^2 + (c K_p / r_0 - 1) z + c (K_i dt - K_p) / r_0 = 0 (the error recursion of the law)."""
    kp, ki, r0, c, dt = 0.1, 20.0, 0.46, 0.9, 1e-3
    control = TractionControl(mode="force", force_demand_N=1.0e4, proportional_gain_m=kp, integral_gain_m_per_s=ki)
    controller = TractionController(control, r0)
    torque, errors = 0.0, []
    for k in range(800):
        force = c * torque / r0
        torque = controller.update(k * dt, force, 1.0e5)
        errors.append(abs(1.0e4 - force))
    assert torque == pytest.approx(r0 * 1.0e4 / c, rel=1e-9)
    dominant = max(abs(np.roots([1.0, c * kp / r0 - 1.0, c * (ki * dt - kp) / r0])))
    rate = (errors[300] / errors[200]) ** (1 / 100)
    assert rate == pytest.approx(dominant, rel=1e-6)


def test_anti_windup_at_the_torque_limit():
    """A demand the limit cannot give: the torque sits at the limit and the integral does not grow (it would reach
    K_i t e = 2.3e5 N m in 0.2 s), so that when the demand becomes possible the torque leaves the limit at once."""
    control = TractionControl(mode="force", force_demand_N=1.0e5, torque_limit_N_m=2.0e4)
    controller = TractionController(control, 0.46)
    for k in range(200):
        assert controller.update(k * 1e-3, 2.0e4 / 0.46, 1.0e5) == 2.0e4
    assert controller.integral == 0.0
    controller.control = replace(control, force_demand_N=1.0e4)
    assert controller.update(0.2, 2.0e4 / 0.46, 1.0e5) < 2.0e4


@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        ('mode = "adhesion"', 'mode = "torque"',
         r"\[traction\] mode = 'torque': expected one of none, force, adhesion"),
        ("torque_limit_N_m = 45000.0", "torque_limit_N_m = 0.0",
         r"\[traction\] torque_limit_N_m = 0\.0: expected a number > 0"),
        ("adhesion_demand = 0.45", "adhesion_demand = 1.5", r"\[traction\] adhesion_demand = 1\.5: expected a ratio"),
        ("proportional_gain_m = 0.1", "proportional_gain_m = -0.1",
         r"\[traction\] proportional_gain_m = -0\.1: expected a number >= 0"),
        ('mode = "adhesion"', 'mode = "adhesion"\nspeed = 3.0', r"unknown key 'traction\.speed' in table \[traction\]"),
    ],
)  # fmt: skip
def test_bad_traction_table_exits_2(tmp_path, capsys, old, new, pattern):
    assert_bad_scene(tmp_path, capsys, "traction-adhesion", old, new, pattern)


def test_traction_with_a_constant_torque_exits_2(tmp_path, capsys):
    assert_bad_scene(
        tmp_path, capsys, "traction-adhesion", "axle_load_N = 160000.0",
        "axle_load_N = 160000.0\ntraction_torque_N_m = 1000.0",
        r"'loads\.traction_torque_N_m' = 1000\.0: expected 0 with traction\.mode = 'adhesion'",
    )  # fmt: skip


def test_traction_with_a_scipy_method_exits_2(tmp_path, capsys):
    assert_bad_scene(
        tmp_path, capsys, "traction-adhesion", 'method = "RK4"', 'method = "RK45"',
        r"'integrator\.method' = 'RK45': expected one of RK4, DP54, BS32 with traction\.mode",
    )  # fmt: skip
