"""TANG (rigid_dynamics.contact.bem.tang) against closed forms and Kalker's table.

* Cattaneo (1938) / Mindlin shift of a circular Hertz contact, exact for nu = 0 (no normal-tangential
  coupling of the Cerruti field): traction mu p0 [sqrt(1 - r^2/a^2) - (c/a) sqrt(1 - r^2/c^2)],
  shift |W| = mu p0 pi (a^2 - c^2)/(2 G a) (both bodies), force mu F_N (1 - (c/a)^3)
  (Johnson 1985, sec. 7.1, eq 7.37-7.41 with the pair's compliance).
* Carter (1926) 2-D rolling (plane strain, long cylinder; here the BEM's 2-D mode with line
  elements): adhesion zone of width 2c at the leading edge, c = a - |xi| R/mu, force
  mu F_N (1 - (c/a)^2), traction -sign(xi) mu p0 [sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - (x - a + c)^2/c^2)]
  (Johnson 1985, sec. 8.4, eq 8.36-8.42).
* Kalker's linear theory, Table E.3 of Kalker (1990), a/b = 1, nu = 0.25:
  C11 = 4.12, C22 = 3.67, C23 = 1.47 (F_x = -G a b C11 xi, F_y = -G a b C22 eta - G (ab)^1.5 C23 phi).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.bem.influence import _SHARED_CACHES, InfluenceGrid
from rigid_dynamics.contact.bem.norm import solve_norm
from rigid_dynamics.contact.bem.tang import rigid_slip, solve_tang


def _hertz_grid(n, margin, g_mod, nu, radius, force):
    e_star = g_mod / (1 - nu)
    a = (3 * force * radius / (4 * e_star)) ** (1 / 3)
    d = 2 * margin * a / n
    x = -margin * a + d * (np.arange(n) + 0.5)
    xx, yy = np.meshgrid(x, x)
    grid = InfluenceGrid(n, n, d, d, g_mod, nu)
    norm = solve_norm(grid, (xx**2 + yy**2) / (2 * radius), normal_force_N=force)
    assert norm.converged
    return grid, norm.pressure_Pa, x, a, d


def test_cattaneo_shift_nu0():
    """Shift problem with nu = 0: force and adhesion radius of Cattaneo's closed form."""
    g_mod, nu, mu, radius, force = 80e9, 0.0, 0.3, 0.2, 1e4
    grid, p, x, a, d = _hertz_grid(48, 1.1, g_mod, nu, radius, force)
    p0 = 3 * force / (2 * math.pi * a * a)
    c_over_a = 0.6
    shift = mu * p0 * math.pi * a * (1 - c_over_a**2) / (2 * g_mod)
    sol = solve_tang(grid, p, mu, np.full(p.shape, shift), np.zeros(p.shape), problem="shift")
    assert sol.converged
    fx = sol.traction_x_Pa.sum() * d * d
    assert fx / (mu * force) == pytest.approx(-(1 - c_over_a**3), rel=0.01)
    assert abs(sol.traction_y_Pa.sum() * d * d) < 1e-9 * force
    xx, yy = np.meshgrid(x, x)
    stick = (p > 0) & ~sol.in_slip
    stick_radius = math.sqrt(stick.sum() * d * d / math.pi)
    assert stick_radius / a == pytest.approx(c_over_a, abs=0.03)
    r = np.hypot(xx, yy) / a
    exact = (
        -mu * p0 * (np.sqrt(np.clip(1 - r**2, 0, None)) - c_over_a * np.sqrt(np.clip(1 - (r / c_over_a) ** 2, 0, None)))
    )
    inner = r < 0.9
    assert np.abs(sol.traction_x_Pa[inner] - exact[inner]).max() < 0.04 * mu * p0


@pytest.mark.parametrize("xi", [2e-4, -5e-4])
def test_carter_2d_rolling(xi):
    """2-D mode (line elements): Carter's force and traction distribution (leading edge at +x)."""
    g_mod, nu, mu, radius, force = 82e9, 0.28, 0.3, 0.46, 1e6  # force per unit length, N/m
    e_star = g_mod / (1 - nu)
    a = math.sqrt(4 * force * radius / (math.pi * e_star))
    p0 = 2 * force / (math.pi * a)
    n = 400
    d = 2.2 * a / n
    x = -1.1 * a + d * (np.arange(n) + 0.5)
    grid = InfluenceGrid(n, 1, d, 1.0, g_mod, nu, plane=True)
    norm = solve_norm(grid, (x**2 / (2 * radius))[None, :], normal_force_N=force)
    assert norm.converged
    np.testing.assert_allclose(norm.pressure_Pa[0], p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None)), atol=0.01 * p0)
    wx, wy = rigid_slip(x, [0.0], xi, 0.0, 0.0)
    sol = solve_tang(grid, norm.pressure_Pa, mu, wx, wy)
    assert sol.converged
    c = a - abs(xi) * radius / mu
    fx = sol.traction_x_Pa.sum() * d
    assert fx / (mu * force) == pytest.approx(-math.copysign(1 - (c / a) ** 2, xi), abs=0.01)
    stick_zone = np.clip(1 - ((x - (a - c)) / c) ** 2, 0, None)
    exact = -math.copysign(mu * p0, xi) * (np.sqrt(np.clip(1 - (x / a) ** 2, 0, None)) - (c / a) * np.sqrt(stick_zone))
    assert np.abs(sol.traction_x_Pa[0] - exact).max() < 0.03 * mu * p0
    # adhesion at the leading edge (+x), slip at the trailing edge
    contact = norm.pressure_Pa[0] > 0
    adhesion = contact & ~sol.in_slip[0]
    assert x[adhesion].min() == pytest.approx(a - 2 * c, abs=3 * d)


def test_creep_coefficients_converge_to_kalker_table():
    """Full adhesion (mu large): C11, C22, C23 from the BEM approach Kalker's Table E.3 (a/b = 1, nu = 0.25).

    Observed errors (margin 1, grid inside the contact): C11 5.0 %, 1.6 %, 1.4 %, 0.3 % and
    C22 5.4 %, 1.9 %, 1.6 %, 0.5 % on 16, 32, 64, 128 elements per side; C23 within 1 % on all.
    """
    g_mod, nu, radius, force = 82e9, 0.25, 0.2, 1e4
    table = {"C11": 4.12, "C22": 3.67, "C23": 1.47}
    errors = {k: [] for k in table}
    for n in (16, 128):
        grid, p, x, a, d = _hertz_grid(n, 1.0, g_mod, nu, radius, force)
        got = {}
        for key, creep in (("C11", (1e-4, 0, 0)), ("C22", (0, 1e-4, 0)), ("C23", (0, 0, 1e-2))):
            sol = solve_tang(grid, p, 1e3, *rigid_slip(x, x, *creep))
            assert sol.converged and not sol.in_slip.any()
            fx, fy = sol.traction_x_Pa.sum() * d * d, sol.traction_y_Pa.sum() * d * d
            if key == "C11":
                got[key] = -fx / (g_mod * a * a * creep[0])
            elif key == "C22":
                got[key] = -fy / (g_mod * a * a * creep[1])
            else:
                got[key] = -fy / (g_mod * a**3 * creep[2])
        for key in table:
            errors[key].append(abs(got[key] / table[key] - 1))
    assert errors["C11"][-1] < 0.005 and errors["C11"][-1] < errors["C11"][0] / 5, errors
    assert errors["C22"][-1] < 0.007 and errors["C22"][-1] < errors["C22"][0] / 5, errors
    assert max(errors["C23"]) < 0.01, errors


def test_zero_creepage_full_stick_and_saturation_full_slip():
    grid, p, x, a, d = _hertz_grid(24, 1.1, 82e9, 0.28, 0.3, 2e4)
    zero = solve_tang(grid, p, 0.3, *rigid_slip(x, x, 0.0, 0.0, 0.0))
    assert zero.converged and not zero.traction_x_Pa.any() and not zero.in_slip.any()
    sat = solve_tang(grid, p, 0.3, *rigid_slip(x, x, 0.05, 0.0, 0.0))
    assert sat.converged
    assert (sat.in_slip == (p > 0)).all()
    # all elements at the bound; directions deviate from -x only by the small elastic part of the slip
    assert sat.traction_x_Pa.sum() * d * d == pytest.approx(-0.3 * 2e4, rel=1e-4)
    np.testing.assert_allclose(np.hypot(sat.traction_x_Pa, sat.traction_y_Pa), 0.3 * p, rtol=1e-9, atol=1e-6)


def test_non_convergence_reported():
    grid, p, x, a, d = _hertz_grid(24, 1.1, 82e9, 0.28, 0.3, 2e4)
    sol = solve_tang(grid, p, 0.3, *rigid_slip(x, x, 0.0, -6e-4, 0.6), max_iterations=1)
    assert not sol.converged and sol.iterations == 1


def test_bad_inputs():
    grid, p, x, a, d = _hertz_grid(8, 1.1, 82e9, 0.28, 0.3, 2e4)
    w = np.zeros(p.shape)
    with pytest.raises(ValueError, match="problem"):
        solve_tang(grid, p, 0.3, w, w, problem="transient")
    with pytest.raises(ValueError, match="rigid_slip_x"):
        solve_tang(grid, p, 0.3, w[:-1], w)
    with pytest.raises(ValueError, match="friction_coefficient"):
        solve_tang(grid, p, -0.1, w, w)
    with pytest.raises(ValueError, match="tolerance"):
        solve_tang(grid, p, 0.3, w, w, tolerance=-1.0)
    with pytest.raises(ValueError, match="max_iterations"):
        solve_tang(grid, p, 0.3, w, w, max_iterations=0)
    with pytest.raises(ValueError, match="initial_traction"):
        solve_tang(grid, p, 0.3, w, w, initial_traction=(w[:-1], w[:-1]))
    with pytest.raises(ValueError, match="initial_slip"):
        solve_tang(grid, p, 0.3, w, w, initial_slip=p > 0)


@pytest.mark.parametrize("with_slip_area", [True, False])
def test_warm_start_same_solution(with_slip_area):
    """Regression: a warm start (initial_traction, initial_slip) from a nearby problem's solution gives the cold
    solution to the tolerance, in fewer Newton steps; started from the solution itself it stops at once."""
    grid, p, x, a, d = _hertz_grid(40, 1.1, 82e9, 0.28, 0.3, 2e4)
    w = rigid_slip(x, x, 2e-4, -6e-4, 0.6)
    cold = solve_tang(grid, p, 0.3, *w)
    near = solve_tang(grid, 1.02 * p, 0.3, *rigid_slip(x, x, 2.1e-4, -5.8e-4, 0.6))
    assert cold.converged and near.converged
    slip = near.in_slip if with_slip_area else None
    warm = solve_tang(grid, p, 0.3, *w, initial_traction=(near.traction_x_Pa, near.traction_y_Pa), initial_slip=slip)
    assert warm.converged
    mu_fn = 0.3 * p.sum()
    for got, ref in ((warm.traction_x_Pa, cold.traction_x_Pa), (warm.traction_y_Pa, cold.traction_y_Pa)):
        assert abs(got.sum() - ref.sum()) < 1e-6 * mu_fn
        assert np.abs(got - ref).max() < 1e-4 * 0.3 * p.max()
    assert (warm.in_slip == cold.in_slip).all()
    if with_slip_area:
        assert warm.iterations < cold.iterations
    same = solve_tang(
        grid, p, 0.3, *w, initial_traction=(cold.traction_x_Pa, cold.traction_y_Pa), initial_slip=cold.in_slip
    )
    assert same.converged and same.iterations == 1 and same.linear_iterations == 0


def test_grids_of_equal_parameters_share_coefficients():
    """Regression: a new grid of equal parameters reuses the coefficients (same arrays); others do not."""
    a = InfluenceGrid(12, 10, 1e-4, 1e-4, 82e9, 0.28)
    kxx = a.kernel("xx", True)
    b = InfluenceGrid(12, 10, 1e-4, 1e-4, 82e9, 0.28)
    assert b.kernel("xx", True) is kxx
    c = InfluenceGrid(12, 10, 1e-4, 1e-4, 82e9, 0.3)
    assert c.kernel("xx", True) is not kxx
    _SHARED_CACHES.clear()
    fresh = InfluenceGrid(12, 10, 1e-4, 1e-4, 82e9, 0.3)
    assert fresh.kernel("xx", True) is not c.kernel("xx", True)
    np.testing.assert_array_equal(fresh.kernel("xx", True), c.kernel("xx", True))
    for n in range(20):  # bounded: at most 16 grids, at most 100 000 elements in all (the newest always kept)
        InfluenceGrid(4 + n, 4, 1e-4, 1e-4, 82e9, 0.28)
    assert len(_SHARED_CACHES) == 16
    InfluenceGrid(320, 320, 1e-4, 1e-4, 82e9, 0.28)
    assert list(_SHARED_CACHES) == [(320, 320, 1e-4, 1e-4, 82e9, 0.28, 0.0, False)]


def test_period_preconditioner_inverts_the_folded_circulant():
    """The tangential preconditioner's spectra invert the block circulant on the (ny, nx) period whose coefficients
    are the rectangle influences (Love/Cerruti closed forms, influence.rectangle_influence) summed over the offsets
    congruent modulo the period: checked against that dense matrix built independently of the FFT."""
    from rigid_dynamics.contact.bem.influence import rectangle_influence

    nx, ny, dx, dy, g_mod, nu = 6, 5, 1e-3, 0.7e-3, 82e9, 0.28
    grid = InfluenceGrid(nx, ny, dx, dy, g_mod, nu)
    ixx, ixy, iyy = grid.inverse_static_period_spectra()
    di = np.arange(-(nx - 1), nx + 1)
    dj = np.arange(-(ny - 1), ny + 1)
    ddi, ddj = np.meshgrid(di, dj)
    kern = rectangle_influence(ddi * dx, ddj * dy, dx, dy, g_mod, nu)
    n = nx * ny
    dense = np.zeros((2 * n, 2 * n))
    for row in range(n):
        jr, ir = divmod(row, nx)
        for col in range(n):
            jc, ic = divmod(col, nx)
            sel = ((ddj - (jr - jc)) % ny == 0) & ((ddi - (ir - ic)) % nx == 0)
            for a, b, name in ((0, 0, "xx"), (0, 1, "xy"), (1, 0, "xy"), (1, 1, "yy")):
                dense[a * n + row, b * n + col] = kern[name][sel].sum()
    rng = np.random.default_rng(3)
    u = rng.normal(size=(2, ny, nx))
    spec = np.fft.rfft2(u)
    t = np.fft.irfft2(np.stack((ixx * spec[0] + ixy * spec[1], ixy * spec[0] + iyy * spec[1])), s=(ny, nx))
    back = dense @ t.reshape(-1)
    # the symbol's real part is inverted: exact for the symmetric part of the (slightly non-symmetric) folded xy
    sym = 0.5 * (dense + dense.T) @ t.reshape(-1)
    assert np.abs(sym - u.reshape(-1)).max() < 1e-9 * np.abs(u).max()
    assert np.abs(back - u.reshape(-1)).max() < 0.05 * np.abs(u).max()


def test_coarse_start_on_odd_grid_same_solution():
    """Regression: the nested-iteration start on an odd grid (33 x 35, padded for merging) gives the solution of the
    plain start to the tolerance."""
    g_mod, nu, radius, force = 82e9, 0.28, 0.3, 2e4
    e_star = g_mod / (1 - nu)
    a = (3 * force * radius / (4 * e_star)) ** (1 / 3)
    d = 2.2 * a / 34
    x = -1.1 * a + d * (np.arange(33) + 0.5)
    y = -1.1 * a + d * (np.arange(35) + 0.5)
    xx, yy = np.meshgrid(x, y)
    grid = InfluenceGrid(33, 35, d, d, g_mod, nu)
    p = solve_norm(grid, (xx**2 + yy**2) / (2 * radius), normal_force_N=force).pressure_Pa
    w = rigid_slip(x, y, 2e-4, -6e-4, 0.6)
    plain = solve_tang(grid, p, 0.3, *w, coarse_start=False)
    nested = solve_tang(grid, p, 0.3, *w)
    assert plain.converged and nested.converged
    mu_fn = 0.3 * p.sum()
    assert abs(nested.traction_x_Pa.sum() - plain.traction_x_Pa.sum()) < 1e-6 * mu_fn
    assert abs(nested.traction_y_Pa.sum() - plain.traction_y_Pa.sum()) < 1e-6 * mu_fn
    assert (nested.in_slip == plain.in_slip).all()
    assert nested.iterations <= plain.iterations
