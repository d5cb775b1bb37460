"""The ``bem`` rung's reduced interaction of sub-patches (CONTACT's IPLAN = 4, bem.influence.SubPatchInfluence).

Verification: the product is the definition u_j = sum_i f_ij M_j A (M_i p) (m_solvpn's matrix-vector product of
NORM), and with f = 0 two sub-patches are independent: each one's pressure is that of the same sub-patch solved on
its own (approach control), whatever the other carries. The wheelset case against CONTACT:
tests/test_wheelset_case_contact_reference.py (case 11).
"""

import numpy as np
import pytest

from rigid_dynamics.contact.bem.influence import InfluenceGrid, SubPatchInfluence
from rigid_dynamics.contact.bem.norm import solve_norm

G_PA, NU = 82e9, 0.28


def _grid(nx=24, ny=40, d=2e-4):
    return InfluenceGrid(nx, ny, d, d, G_PA, NU, 0.0)


def _labels(ny, nx):
    labels = np.zeros((ny, nx), np.int64)
    labels[:16] = 1
    labels[22:] = 2
    return labels


def test_product_is_the_sub_patch_sum():
    grid = _grid()
    labels = _labels(grid.ny, grid.nx)
    factors = np.array([[1.0, 0.391], [0.391, 1.0]])
    p = np.random.default_rng(1).random((grid.ny, grid.nx)) * 1e9
    p[labels == 0] = 0.0
    masks = [labels == 1, labels == 2]
    expected = sum(factors[i, j] * masks[j] * grid.normal(masks[i] * p) for i in range(2) for j in range(2))
    expected = expected + (labels == 0) * grid.normal(p)
    assert np.allclose(SubPatchInfluence(grid, labels, factors).normal(p), expected, rtol=1e-12, atol=1e-20)
    assert np.allclose(SubPatchInfluence(grid, labels, np.ones((2, 2))).normal(p), grid.normal(p), rtol=1e-13)


def test_uncoupled_sub_patches_solve_independently():
    grid = _grid()
    labels = _labels(grid.ny, grid.nx)
    x = (np.arange(grid.nx) - grid.nx / 2 + 0.5) * grid.dx_m
    y = (np.arange(grid.ny) + 0.5) * grid.dy_m
    xx, yy = np.meshgrid(x, y)
    h = np.where(
        yy < 16 * grid.dy_m, (xx**2 + (yy - 1.6e-3) ** 2) / 0.6 - 2e-5, (xx**2 + (yy - 6.2e-3) ** 2) / 0.6 - 1e-5
    )
    h = np.where(labels > 0, h, np.inf)
    both = solve_norm(SubPatchInfluence(grid, labels, np.array([[1.0, 0.0], [0.0, 1.0]])), h, tolerance=1e-10)
    assert both.converged
    for k in (1, 2):
        alone = solve_norm(grid, np.where(labels == k, h, np.inf), tolerance=1e-10)
        assert np.allclose(
            both.pressure_Pa[labels == k],
            alone.pressure_Pa[labels == k],
            rtol=1e-6,
            atol=1e-6 * alone.pressure_Pa.max(),
        )
    full = solve_norm(grid, h, tolerance=1e-10)
    assert full.normal_force_N < both.normal_force_N  # the other patch's pressure lifts each one: less force
    assert full.normal_force_N == pytest.approx(both.normal_force_N, rel=0.2)
