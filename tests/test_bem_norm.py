"""NORM (rigid_dynamics.contact.bem.norm): Hertz as the exact reference (Johnson 1985, eq 4.22-4.23).

Circular Hertz contact, relative radius R, combined modulus E* = G/(1 - nu) for equal bodies:
a^3 = 3 F R/(4 E*), p0 = 3 F/(2 pi a^2), approach = a^2/R.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from rigid_dynamics.contact.bem.influence import InfluenceGrid
from rigid_dynamics.contact.bem.norm import solve_norm

G, NU = 82e9, 0.28
E_STAR = G / (1 - NU)
R, F = 0.3, 1.0e4
A_HZ = (3 * F * R / (4 * E_STAR)) ** (1 / 3)
P0_HZ = 3 * F / (2 * math.pi * A_HZ**2)
Q_HZ = A_HZ**2 / R


def _grid(n, half_width):
    d = 2 * half_width / n
    x = -half_width + d * (np.arange(n) + 0.5)
    xx, yy = np.meshgrid(x, x)
    return InfluenceGrid(n, n, d, d, G, NU), (xx**2 + yy**2) / (2 * R), d


def _observed_order(ns, errors):
    return -np.polyfit(np.log(ns), np.log(errors), 1)[0]


def test_force_control_converges_to_hertz_with_order():
    """p0 and approach converge to Hertz; observed order of the p0 error fitted over 4 grids >= 1.5."""
    ns = np.array([16, 32, 64, 128])
    err_p0, err_q, iters, field_errors = [], [], [], []
    for n in ns:
        grid, h, d = _grid(int(n), 1.2 * A_HZ)
        sol = solve_norm(grid, h, normal_force_N=F)
        assert sol.converged
        assert sol.normal_force_N == pytest.approx(F, rel=1e-12)
        err_p0.append(abs(sol.pressure_Pa.max() / P0_HZ - 1))
        err_q.append(abs(sol.approach_shift_m / Q_HZ - 1))
        iters.append(sol.iterations)
        # pressure field inside 0.9 a against p0 sqrt(1 - r^2/a^2)
        x = -1.2 * A_HZ + d * (np.arange(n) + 0.5)
        xx, yy = np.meshgrid(x, x)
        r2 = (xx**2 + yy**2) / A_HZ**2
        inner = r2 < 0.81
        field_errors.append(np.abs(sol.pressure_Pa[inner] - P0_HZ * np.sqrt(1 - r2[inner])).max() / P0_HZ)
    order = _observed_order(ns, err_p0)
    assert order > 1.5, f"observed order of p0 {order:.2f}, errors {err_p0}"
    assert err_p0[-1] < 2e-4 and err_q[-1] < 1e-4, (err_p0, err_q)
    assert field_errors[-1] < 2e-3 and _observed_order(ns, field_errors) > 1.0, field_errors
    # iteration count grows mildly (P&K CG): 64x more unknowns, far less than 8x the iterations
    assert iters[-1] < 3 * iters[0], iters


def test_approach_control_converges_to_hertz_force():
    """Imposed Hertz approach: the force converges to the Hertz force (order >= 1)."""
    ns = np.array([16, 32, 64])
    errors = []
    for n in ns:
        grid, h, _ = _grid(int(n), 1.2 * A_HZ)
        sol = solve_norm(grid, h - Q_HZ)
        assert sol.converged and sol.approach_shift_m == 0.0
        errors.append(abs(sol.normal_force_N / F - 1))
    assert errors[-1] < 1e-3
    assert _observed_order(ns, errors) > 1.0, errors


def test_complementarity_and_no_contact():
    grid, h, _ = _grid(24, 1.2 * A_HZ)
    sol = solve_norm(grid, h, normal_force_N=F)
    p, e = sol.pressure_Pa, sol.deformed_distance_m
    assert (p >= 0).all()
    assert e.min() > -1e-6 * Q_HZ
    assert np.abs(e[p > 0]).max() < 1e-6 * Q_HZ
    free = solve_norm(grid, h + 1e-6)
    assert free.normal_force_N == 0.0 and not free.pressure_Pa.any()


def test_infinite_distance_elements_carry_no_pressure():
    grid, h, _ = _grid(20, 1.2 * A_HZ)
    h = h.copy()
    h[:, :3] = np.inf
    sol = solve_norm(grid, h, normal_force_N=F)
    assert sol.converged and not sol.pressure_Pa[:, :3].any()


def test_non_convergence_is_reported():
    grid, h, _ = _grid(24, 1.2 * A_HZ)
    sol = solve_norm(grid, h, normal_force_N=F, max_iterations=2)
    assert not sol.converged and sol.iterations == 2


def test_bad_inputs():
    grid, h, _ = _grid(8, A_HZ)
    with pytest.raises(ValueError, match="shape"):
        solve_norm(grid, h[:-1])
    with pytest.raises(ValueError, match="normal_force_N"):
        solve_norm(grid, h, normal_force_N=-1.0)
    with pytest.raises(ValueError, match="tolerance"):
        solve_norm(grid, h, tolerance=0.0)
    with pytest.raises(ValueError, match="max_iterations"):
        solve_norm(grid, h, max_iterations=0)
    with pytest.raises(ValueError, match="method = 'cg'"):
        solve_norm(grid, h, method="cg")
    bad = h.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        solve_norm(grid, bad)


# --- NormCG (preconditioned) ----------------------------------------------------------------------------------
PERFC_PROFILE = Path(__file__).resolve().parents[1] / "benchmarks" / "data" / "contact_perfc_norm_profile.csv"


def _perfc_problem(level=1):
    """CONTACT's perfc_test/norm_problm_{level}p deck (benchmarks/data/SOURCE.md): 71 x 81 elements of 0.1 mm
    (level 1) or 143 x 163 of 0.05 mm (level 2), h = p(y) + x^2/(2 RM) - PEN, G = 82 GPa, nu = 0.28."""
    profile = np.loadtxt(PERFC_PROFILE, delimiter=",")
    mx, my, d = {1: (71, 81, 0.1e-3), 2: (143, 163, 0.05e-3)}[level]
    x = -3.55e-3 + d * (np.arange(mx) + 0.5)
    y = -6.15e-3 + d * (np.arange(my) + 0.5)
    h = np.interp(y, profile[:, 0] * 1e-3, profile[:, 1] * 1e-3)[:, None] + x[None, :] ** 2 / (2 * 0.483931)
    return InfluenceGrid(mx, my, d, d, 82e9, 0.28), h - 0.02084e-3


@pytest.mark.parametrize("force_control", [False, True])
def test_normcg_on_contacts_perfc_grid(force_control):
    """CONTACT's published result of perfc_test/norm_problm_1p / _1f (get_times.ref_out): 3148 elements in
    contact, 19 / 16 NormCG iterations at EPS = 1e-7. Ours: the same contact set, no more iterations; the
    unpreconditioned Polonsky-Keer solver (our second method; regression) gives the same pressures."""
    grid, h = _perfc_problem()
    force = 1.0e4 if force_control else None
    h_in = h + 0.02084e-3 if force_control else h
    sol = solve_norm(grid, h_in, normal_force_N=force, tolerance=1e-7)
    ref = solve_norm(grid, h_in, normal_force_N=force, tolerance=1e-9, method="polonsky-keer")
    assert sol.converged and ref.converged
    assert int((sol.pressure_Pa > 0).sum()) == 3148
    assert sol.iterations <= (16 if force_control else 19), sol.iterations
    assert ref.iterations > 2 * sol.iterations
    p0 = ref.pressure_Pa.max()
    assert np.abs(sol.pressure_Pa - ref.pressure_Pa).max() < 1e-6 * p0
    assert sol.normal_force_N == pytest.approx(ref.normal_force_N, rel=1e-7)
    assert sol.approach_shift_m == pytest.approx(ref.approach_shift_m, rel=1e-6, abs=1e-15)
    assert sol.residual < 1e-6


@pytest.mark.parametrize(("force_control", "contact_elements", "iterations"), [(False, 12902, 22), (True, 12912, 18)])
def test_normcg_on_contacts_finer_perfc_grid(force_control, contact_elements, iterations):
    """perfc_test/norm_problm_2p / _2f (143 x 163 elements): CONTACT's published contact count and no more than its
    NormCG iterations (get_times.ref_out)."""
    grid, h = _perfc_problem(2)
    force = 1.0e4 if force_control else None
    sol = solve_norm(grid, h + 0.02084e-3 if force_control else h, normal_force_N=force, tolerance=1e-7)
    assert sol.converged and int((sol.pressure_Pa > 0).sum()) == contact_elements
    assert sol.iterations <= iterations, sol.iterations


def test_normcg_hertz_pressure_order_two():
    """NormCG on the circular Hertz case: p0 error of order 2 (fit over 4 grids) and the same pressures as the
    Polonsky-Keer solver (regression) to 1e-6 p0."""
    ns = np.array([16, 32, 64, 128])
    errors = []
    for n in ns:
        grid, h, _ = _grid(int(n), 1.2 * A_HZ)
        sol = solve_norm(grid, h, normal_force_N=F)
        assert sol.converged and sol.iterations <= 20, sol.iterations
        errors.append(abs(sol.pressure_Pa.max() / P0_HZ - 1))
        if n == 32:
            ref = solve_norm(grid, h, normal_force_N=F, tolerance=1e-10, method="polonsky-keer")
            assert np.abs(sol.pressure_Pa - ref.pressure_Pa).max() < 1e-6 * P0_HZ
    order = _observed_order(ns, errors)
    assert 1.9 < order < 2.2, f"observed order {order:.2f}, errors {errors}"
