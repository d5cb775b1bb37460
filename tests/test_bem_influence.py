"""Half-space influence coefficients of the BEM (rigid_dynamics.contact.bem.influence).

References: Boussinesq/Cerruti point-load surface displacements (Johnson 1985, eq 3.19, 3.77; two
bodies combined as in Kalker 1990, sec. 1.6); Love (1929) uniform pressure on a rectangle; uniform
pressure on a circle of radius c: centre deflection of one body 2 (1 - nu^2) p c / E (Johnson 1985,
eq 3.39), i.e. 2 (1 - nu) p c / G for the pair of equal bodies.
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.bem.influence import (
    KERNELS,
    InfluenceGrid,
    combined_elastic_constants,
    point_load_kernels,
    rectangle_influence,
    strip_influence,
)

G, NU = 82e9, 0.28


def test_far_field_equals_point_load():
    """Far from the element the rectangle coefficient tends to area * point-load kernel (all 8 kernels)."""
    dx, dy = 1e-3, 2e-3
    x = np.array([0.05, 0.03, -0.02, -0.04])
    y = np.array([0.01, -0.04, 0.035, -0.03])
    rect = rectangle_influence(x, y, dx, dy, G, NU, 0.1)
    point = point_load_kernels(x, y, G, NU, 0.1)
    for name in KERNELS:
        np.testing.assert_allclose(rect[name], point[name] * dx * dy, rtol=2e-3, err_msg=name)


def test_square_centre_closed_form():
    """Love: the integral of 1/r over a square of side s at its centre is 4 s asinh(1)."""
    s = 2e-3
    c = rectangle_influence(0.0, 0.0, s, s, G, NU)["zz"]
    assert c == pytest.approx((1 - NU) / (math.pi * G) * 4 * s * math.asinh(1.0), rel=1e-13)


def test_uniform_pressure_on_disc_converges_to_closed_form():
    """Uniform pressure on a disc (staircase of elements): centre deflection -> 2 (1 - nu) p c / G (both bodies)."""
    p, c = 1e8, 5e-3
    errors = []
    for n in (21, 41, 81):
        d = 2 * c / n
        x = -c + d * (np.arange(n) + 0.5)
        xx, yy = np.meshgrid(x, x)
        load = np.where(xx**2 + yy**2 <= c * c, p, 0.0)
        grid = InfluenceGrid(n, n, d, d, G, NU)
        u = grid.normal(load)[n // 2, n // 2]
        errors.append(abs(u / (2 * (1 - NU) * p * c / G) - 1))
    assert errors[-1] < 5e-3, errors
    assert errors[0] > errors[-1]


def test_influence_matrix_symmetric_reciprocity():
    """Betti: the full 3N x 3N influence matrix (with Kalker's K != 0) is symmetric; zz is positive definite."""
    grid = InfluenceGrid(5, 4, 1e-3, 1.5e-3, G, NU, difference_parameter=0.08)
    name = {"yx": "xy"}
    blocks = [[grid.dense(name.get(i + j, i + j)) for j in "xyz"] for i in "xyz"]
    full = np.block(blocks)
    np.testing.assert_allclose(full, full.T, atol=1e-12 * np.abs(full).max())
    assert np.linalg.eigvalsh(grid.dense("zz")).min() > 0


@pytest.mark.parametrize("rolling", [False, True])
def test_fft_convolution_equals_dense(rolling):
    """The zero-padded FFT convolution reproduces the dense matrix product for every kernel."""
    grid = InfluenceGrid(7, 5, 1e-3, 0.7e-3, G, NU, difference_parameter=0.05)
    rng = np.random.default_rng(1)
    t = rng.standard_normal((5, 7))
    for name in KERNELS:
        dense = grid.dense(name, rolling) @ t.ravel()
        np.testing.assert_allclose(grid.apply(name, t, rolling).ravel(), dense, atol=1e-13 * np.abs(dense).max())


def test_rolling_kernel_is_upwind_difference():
    """Rolling operator = (C(I-K) - C(I-K+e_x))/dx, i.e. (u(x_I) - u(x_I + dx))/dx of the static field."""
    grid = InfluenceGrid(6, 3, 1e-3, 1e-3, G, NU)
    big = InfluenceGrid(7, 3, 1e-3, 1e-3, G, NU)
    t = np.zeros((3, 7))
    t[:, :6] = np.random.default_rng(2).standard_normal((3, 6))
    u = big.apply("xx", t)
    np.testing.assert_allclose(grid.apply("xx", t[:, :6], rolling=True), (u[:, :6] - u[:, 1:7]) / 1e-3, rtol=1e-10)


def test_strip_kernel_matches_long_rectangle_differences():
    """2-D line-load kernel: differences equal those of a very long 3-D strip (constant dropped)."""
    dx, length = 1e-3, 400.0
    x = np.array([0.0, 2e-3, 7e-3])
    line = strip_influence(x, dx, G, NU)
    rect = rectangle_influence(x, 0.0, dx, length, G, NU)
    for name in ("zz", "xx"):
        np.testing.assert_allclose(np.diff(line[name]), np.diff(rect[name]), rtol=1e-4)


def test_combined_constants():
    """Equal bodies: G, nu unchanged and K = 0; steel on a softer body gives K != 0 with Kalker's sign."""
    assert combined_elastic_constants(G, NU, G, NU) == pytest.approx((G, NU, 0.0))
    g, nu, k = combined_elastic_constants(80e9, 0.3, 40e9, 0.3)
    assert g == pytest.approx(2 / (1 / 80e9 + 1 / 40e9))
    assert k == pytest.approx(0.25 * g * (0.4 / 80e9 - 0.4 / 40e9))


def test_bad_inputs():
    with pytest.raises(ValueError, match="shear_modulus_1_Pa"):
        combined_elastic_constants(-1.0, 0.3, G, NU)
    with pytest.raises(ValueError, match="poisson_ratio_2"):
        combined_elastic_constants(G, 0.3, G, 0.6)
    with pytest.raises(ValueError, match="nx"):
        InfluenceGrid(0, 3, 1e-3, 1e-3, G, NU)
    with pytest.raises(ValueError, match="dx_m"):
        InfluenceGrid(3, 3, -1e-3, 1e-3, G, NU)
    with pytest.raises(ValueError, match="poisson_ratio"):
        InfluenceGrid(3, 3, 1e-3, 1e-3, G, 0.5)
    with pytest.raises(ValueError, match="difference_parameter"):
        InfluenceGrid(3, 3, 1e-3, 1e-3, G, NU, difference_parameter=0.7)
    with pytest.raises(ValueError, match="ny"):
        InfluenceGrid(3, 2, 1e-3, 1e-3, G, NU, plane=True)
    with pytest.raises(ValueError, match="64 x 64"):
        InfluenceGrid(65, 64, 1e-3, 1e-3, G, NU).dense("zz")
    with pytest.raises(ValueError, match="kernel"):
        InfluenceGrid(3, 3, 1e-3, 1e-3, G, NU).kernel("zq")
