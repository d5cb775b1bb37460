"""Regression tests: the BEM's FFTs by scipy's transform functions called directly (influence._DIRECT, per-grid
buffers, the inverse in place) give the same bits as the public scipy.fft calls they replace."""

import numpy as np
import pytest
import scipy.fft

from rigid_dynamics.contact.bem import influence
from rigid_dynamics.contact.bem.influence import InfluenceGrid, period_irfft2, period_rfft2

pytestmark = pytest.mark.skipif(influence._DIRECT is None, reason="scipy without its duccfft/pocketfft module")

SHAPES = [(7, 5), (40, 33), (64, 48), (1, 50)]


def public_forward(grid: InfluenceGrid, values: np.ndarray) -> np.ndarray:
    ly, lx = grid.padded_shape
    spec = scipy.fft.rfft(values, n=lx, axis=-1)
    return spec if ly == 1 else scipy.fft.fft(spec, n=ly, axis=-2, overwrite_x=True)


def public_backward(grid: InfluenceGrid, spectrum: np.ndarray) -> np.ndarray:
    ly, lx = grid.padded_shape
    if ly > 1:
        spectrum = scipy.fft.ifft(spectrum, axis=-2)[..., : grid.ny, :]
    return scipy.fft.irfft(spectrum, n=lx, axis=-1)[..., : grid.nx]


@pytest.mark.parametrize(("ny", "nx"), SHAPES)
def test_forward_backward_bit_identical_to_scipy_fft(ny, nx):
    rng = np.random.default_rng(ny * 100 + nx)
    plane = ny == 1
    grid = InfluenceGrid(nx, ny, 0.2e-3, 0.3e-3, 82e9, 0.28, plane=plane)
    for lead in ((), (2,)):
        for _ in range(2):  # a second call reuses the buffers: no leftovers of the first
            values = rng.standard_normal((*lead, ny, nx))
            spec = grid._forward(values)
            expected = public_forward(grid, values)
            assert np.array_equal(spec, expected)
            product = spec * grid._kernel_fft("zz", False)
            want = public_backward(grid, product.copy())
            assert np.array_equal(grid._backward(product.copy()), want)
            assert np.array_equal(grid._backward(product.copy(), reuse=True), want)


@pytest.mark.parametrize(("ny", "nx"), SHAPES[:3])
def test_products_and_preconditioner_bit_identical(ny, nx):
    rng = np.random.default_rng(7)
    grid = InfluenceGrid(nx, ny, 0.2e-3, 0.2e-3, 82e9, 0.28)
    p = rng.random((ny, nx)) * 1e9
    kzz = grid._kernel_fft("zz", False)
    want = public_backward(grid, kzz * public_forward(grid, p))
    first = grid.normal(p, reuse=True).copy()
    assert np.array_equal(grid.normal(p), want)
    assert np.array_equal(first, want)
    res = rng.standard_normal((ny, nx)) * 1e-6
    grid.normal_preconditioner(res)  # fills the symbol
    spec = scipy.fft.rfft2(res) * grid._cache["prec"]
    want_z = scipy.fft.irfft2(spec, s=(ny, nx))
    assert np.array_equal(grid.normal_preconditioner(res), want_z)
    assert np.array_equal(grid.normal_preconditioner(res, reuse=True), want_z)
    pair = rng.standard_normal((2, ny, nx))
    out = np.empty((2, ny, nx // 2 + 1), complex)
    assert np.array_equal(period_rfft2(pair, out), scipy.fft.rfft2(pair))
    back = np.empty((2, ny, nx))
    assert np.array_equal(period_irfft2(out, nx, back), scipy.fft.irfft2(out, s=(ny, nx)))


def test_a_changed_private_layer_falls_back_to_the_public_functions():
    """Regression: scipy's private transform functions are used only after a check against the public ones at import;
    a layer whose signature changed (an exception) or whose result differs is not used."""
    from rigid_dynamics.contact.bem import influence

    class Moved:
        @staticmethod
        def r2c(a, axes, forward, inorm, out, nthreads, extra):  # one more argument: the call raises
            return a

    class Wrong:
        @staticmethod
        def r2c(a, axes, forward, inorm, out, nthreads):
            return np.zeros((a.shape[0], a.shape[1] // 2 + 1), complex)

        c2c = r2c

        @staticmethod
        def c2r(a, axes, n, forward, inorm, out, nthreads):
            return np.zeros((a.shape[0], n))

    assert not influence._direct_agrees(Moved)
    assert not influence._direct_agrees(Wrong)
    if influence._DIRECT is not None:
        assert influence._direct_agrees(influence._DIRECT)
