"""RK4's stability limit of a linearised run (rigid_dynamics/wheelset/stability.py) against closed forms."""

import math

import numpy as np
import pytest

from rigid_dynamics.wheelset.stability import jacobian, rk4_amplification, rk4_stable_step


def test_stability_function_boundaries():
    # Hairer & Wanner II, IV.2: RK4's region meets the imaginary axis at 2 sqrt(2) and the real axis at -2.785
    assert abs(rk4_amplification(1j * math.sqrt(8.0))) == pytest.approx(1.0, abs=1e-12)
    assert abs(rk4_amplification(1j * 2.9)) > 1.0
    assert abs(rk4_amplification(-2.785)) < 1.0 < abs(rk4_amplification(-2.786))


def test_undamped_oscillator_limit_is_2_sqrt2_over_omega():
    omega = 2.0 * math.pi * 700.0
    limit = rk4_stable_step(lambda y: np.array([y[1], -(omega**2) * y[0]]), np.zeros(2))
    assert limit.max_step_s == pytest.approx(math.sqrt(8.0) / omega, rel=2e-3)
    assert limit.frequency_hz == pytest.approx(700.0, rel=1e-6)


def test_overdamped_mode_limit_is_2785_over_rate():
    rate = 5000.0
    limit = rk4_stable_step(lambda y: np.array([-rate * y[0], 0.0 * y[1]]), np.array([1e-3, 0.0]))
    assert limit.max_step_s == pytest.approx(2.785 / rate, rel=2e-3)
    assert limit.damping_ratio == pytest.approx(1.0)


def test_the_stiffest_of_several_modes_decides_and_slow_modes_are_ignored():
    def fun(y):
        # a 50 Hz and a 900 Hz oscillator (damping ratio 0.05), and a free coordinate (eigenvalue 0)
        out = np.zeros(5)
        for k, f in ((0, 50.0), (2, 900.0)):
            w = 2.0 * math.pi * f
            out[k], out[k + 1] = y[k + 1], -(w**2) * y[k] - 2.0 * 0.05 * w * y[k + 1]
        return out

    limit = rk4_stable_step(fun, np.zeros(5))
    assert limit.frequency_hz == pytest.approx(900.0 * math.sqrt(1 - 0.05**2), rel=1e-6)
    assert limit.damping_ratio == pytest.approx(0.05, rel=1e-6)
    # the exact limit on the ray of the damped eigenvalue, found by bisection on |R| = 1
    lam = complex(-0.05 * 2 * math.pi * 900, 2 * math.pi * 900 * math.sqrt(1 - 0.05**2))
    lo, hi = 0.0, 3.0 / abs(lam)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(rk4_amplification(mid * lam)) <= 1 else (lo, mid)
    assert limit.max_step_s == pytest.approx(lo, rel=2e-3)


def test_a_growing_oscillation_is_physics_and_limited_by_its_frequency_only():
    w, sigma = 2.0 * math.pi * 2.0, 0.5  # hunting-like: 2 Hz, growing
    limit = rk4_stable_step(lambda y: np.array([sigma * y[0] - w * y[1], w * y[0] + sigma * y[1]]), np.zeros(2))
    assert limit.max_step_s == pytest.approx(math.sqrt(8.0) / w, rel=2e-3)


def test_jacobian_of_a_nonlinear_function():
    fun = lambda y: np.array([y[0] ** 2 * y[1], math.sin(y[1])])  # noqa: E731
    y = np.array([1.5, 0.3])
    exact = np.array([[2 * 1.5 * 0.3, 1.5**2], [0.0, math.cos(0.3)]])
    assert np.allclose(jacobian(fun, y), exact, rtol=1e-7, atol=1e-9)


def test_judge_fixed_step():
    from rigid_dynamics.wheelset.stability import StepLimit, judge_fixed_step

    limit = StepLimit(5.68e-4, 822.0, 0.08, complex(-400.0, 5165.0))
    assert judge_fixed_step("ok", "reached t = 1 s", 1e-4, limit) == ("ok", "reached t = 1 s")
    status, message = judge_fixed_step("derailed", "|y| = 0.06 m exceeds 0.05 m", 5e-3, limit)
    assert status == "step-unstable"
    assert "derailed" in message and "5 ms" in message and "822 Hz" in message and "0.00057" in message
    status, message = judge_fixed_step("ok", "reached t = 1 s", 1e-3, limit)
    assert status == "warning" and "reached t = 1 s" in message and "stability limit" in message
    assert judge_fixed_step("wheel-lift", "lift", 1e-3, limit)[0] == "wheel-lift"
