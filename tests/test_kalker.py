"""Kalker's creepage coefficients: published table, interpolation, slender-ellipse asymptotes.

References:
* Kalker (1990), Three-Dimensional Elastic Bodies in Rolling Contact, Table E.3 (entries typed in
  below from the published table, independently of the CSV file the module loads);
* Carter's 2-D rolling theory (Johnson 1985, Contact Mechanics, sec. 8.3): in full adhesion a
  cylinder of contact half-width a carries Q = pi a G xi / (2 (1 - nu)) per unit length for a
  creepage xi (the small-creepage limit of Carter's law). Integrated over the lateral strips of a
  very short ellipse (a << b) this gives the a/b -> 0 limits of C11 and C33 (strip theory).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from rigid_dynamics.contact.kalker import KALKER_TABLE, kalker_coefficients, slender_asymptotes

# (a/b, nu, coefficient, published value) from Kalker (1990) Table E.3
PUBLISHED = [
    (1.0, 0.0, "c11", 3.40),
    (1.0, 0.25, "c11", 4.12),
    (1.0, 0.5, "c22", 3.98),
    (0.1, 0.5, "c11", 4.85),
    (10.0, 0.5, "c22", 16.0),
    (0.5, 0.0, "c23", 0.827),
    (2.0, 0.25, "c23", 2.62),
    (0.1, 0.0, "c33", 6.42),
    (5.0, 0.25, "c33", 0.601),
    (1.0, 0.5, "c33", 1.16),
    (1 / 0.3, 0.5, "c33", 0.446),
]


@pytest.mark.parametrize(("a_over_b", "nu", "name", "value"), PUBLISHED)
def test_loaded_table_matches_published_values(a_over_b, nu, name, value):
    row = int(np.argmin(np.abs(KALKER_TABLE.a_over_b - a_over_b)))
    col = KALKER_TABLE.poisson_ratios.index(nu)
    assert KALKER_TABLE.coefficient(name.upper())[row, col] == value
    # and the interpolation returns the node value exactly
    assert getattr(kalker_coefficients(a_over_b, nu), name) == pytest.approx(value, rel=1e-12)


def test_table_shape_and_nodes():
    assert KALKER_TABLE.values.shape == (19, 4, 3)
    assert KALKER_TABLE.a_over_b[0] == pytest.approx(0.1) and KALKER_TABLE.a_over_b[-1] == pytest.approx(10.0)
    for j, nu in enumerate(KALKER_TABLE.poisson_ratios):
        c = kalker_coefficients(KALKER_TABLE.a_over_b, nu)
        got = np.stack([c.c11, c.c22, c.c23, c.c33], axis=1)
        np.testing.assert_allclose(got, KALKER_TABLE.values[:, :, j], rtol=1e-12)


def test_nu_zero_longitudinal_equals_lateral():
    """For nu = 0 the tangential influence functions are isotropic and uncoupled, so C11 = C22 exactly."""
    r = np.logspace(-3, 3, 61)
    c = kalker_coefficients(r, 0.0)
    np.testing.assert_allclose(c.c11, c.c22, rtol=1e-12)


@pytest.mark.parametrize("nu", [0.0, 0.1, 0.25, 0.28, 0.4, 0.5])
def test_continuity_and_consistency_at_table_edges(nu):
    for edge in (0.1, 10.0):
        lo = kalker_coefficients(edge * (1 - 1e-9), nu)
        hi = kalker_coefficients(edge * (1 + 1e-9), nu)
        for name in ("c11", "c22", "c23", "c33"):
            assert getattr(lo, name) == pytest.approx(getattr(hi, name), rel=1e-7), (edge, name)
        # Kalker's asymptotes agree with his own table at its edge within 7 % (independent check
        # that the typed formulas are right: a wrong factor would show up here)
        asym = slender_asymptotes(edge, nu)[0]
        tab = kalker_coefficients(edge, nu)
        names = ("c11", "c22", "c23", "c33") if edge < 1 else ("c11", "c22", "c23")
        for i, name in enumerate(names):
            assert abs(getattr(tab, name) / asym[i] - 1.0) < 0.07, (edge, name)


def test_asymptotes_are_approached_far_outside_the_table():
    for r in (1e-4, 1e4):
        c = kalker_coefficients(r, 0.28)
        asym = slender_asymptotes(r, 0.28)[0]
        assert c.c11 == pytest.approx(asym[0], rel=1e-4)
        assert c.c22 == pytest.approx(asym[1], rel=1e-4)
        assert c.c23 == pytest.approx(asym[2], rel=1e-4)


@pytest.mark.parametrize("nu", [0.0, 0.28, 0.5])
def test_short_ellipse_limit_from_carter_strips(nu):
    """a/b -> 0: integrate Carter's 2-D adhesion law over lateral strips (see module docstring)."""
    G, a, b = 1.0, 1.0, 1.0e4  # a/b = 1e-4
    xi, phi = 1.0e-6, 1.0e-8

    def half_length(y):
        return a * math.sqrt(max(0.0, 1.0 - (y / b) ** 2))

    def strip_force(y, creep):
        return math.pi * half_length(y) * G * creep / (2.0 * (1.0 - nu))

    fx = quad(lambda y: strip_force(y, xi), -b, b, epsrel=1e-12)[0]
    mz = quad(lambda y: y * strip_force(y, phi * y), -b, b, epsrel=1e-12)[0]
    c11_strip = fx / (G * a * b * xi)
    c33_strip = mz / (G * (a * b) ** 2 * phi)
    c = kalker_coefficients(a / b, nu)
    assert c.c11 == pytest.approx(c11_strip, rel=2e-3)
    assert c.c33 == pytest.approx(c33_strip, rel=2e-3)


def test_monotone_in_axis_ratio():
    r = np.logspace(-2, 2, 200)
    c = kalker_coefficients(r, 0.28)
    assert np.all(np.diff(c.c11) > 0) and np.all(np.diff(c.c22) > 0) and np.all(np.diff(c.c23) > 0)
    assert np.all(np.diff(c.c33) <= 0)


def test_bad_input_raises():
    with pytest.raises(ValueError, match="a_over_b"):
        kalker_coefficients(0.0, 0.28)
    with pytest.raises(ValueError, match="a_over_b"):
        kalker_coefficients(np.nan, 0.28)
    with pytest.raises(ValueError, match="poisson_ratio"):
        kalker_coefficients(1.0, 0.6)
    with pytest.raises(ValueError, match="coefficient name"):
        KALKER_TABLE.coefficient("C12")


def test_pchip_coefficients_are_scipys():
    """The numpy PCHIP of the creep-coefficient table (kalker.pchip_coefficients, kept so that importing the
    coefficients needs no scipy.interpolate) equals scipy's PchipInterpolator: on the table and on random data with
    flat and sign-changing stretches. On the table bit for bit: an adaptive wheel-flat run with wheel lift
    (tests/test_dynamics_adaptive.py) moved its force error estimate from 0.9 % to 2.5 % on a 3e-15 change."""
    import numpy as np
    from scipy.interpolate import PchipInterpolator

    from rigid_dynamics.contact import kalker

    x = np.log(kalker.KALKER_TABLE.a_over_b)
    y = np.log(kalker.KALKER_TABLE.values.reshape(len(x), 12))
    assert np.array_equal(kalker._PP_C, PchipInterpolator(x, y, axis=0).c)  # bit for bit: runs are chaotic
    rng = np.random.default_rng(7)
    for _ in range(100):
        n = int(rng.integers(3, 12))
        x = np.sort(rng.random(n)) + np.arange(n)
        y = np.cumsum(rng.standard_normal((n, 3)), axis=0)
        y[int(rng.integers(1, n))] = y[0]  # a repeated value: a zero or sign-changing slope
        np.testing.assert_allclose(
            kalker.pchip_coefficients(x, y), PchipInterpolator(x, y, axis=0).c, rtol=1e-11, atol=1e-11
        )
