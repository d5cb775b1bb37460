"""Kalker's linear theory (eq 50-52) and the Vermeulen-Johnson law (eq 53-58, with the cube).

References: the linear-theory formulas with Kalker's Table E.3 values typed in (a/b = 1,
nu = 0.25: C11 = 4.12, C22 = 3.67, C23 = 1.47, C33 = 1.19); signs as in REFERENCES.md (forces on
the wheel oppose the creepage, C32 = -C23); Vermeulen & Johnson (1964) closed form
T_bar = mu N [1 - (1 - w')^3], w' = T/(3 mu N) (eq 56 corrected, REFERENCES.md).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.linear import linear_creep_forces
from rigid_dynamics.contact.vermeulen_johnson import vermeulen_johnson_saturation

G = 82.0e9


def test_linear_theory_against_table_values_and_signs():
    a = b = 6.0e-3
    xi, eta, phi = 1e-4, 2e-4, 0.3
    fx, fy, mz = linear_creep_forces(a, b, xi, eta, phi, shear_modulus_Pa=G, poisson_ratio=0.25)
    ab = a * b
    assert fx == pytest.approx(-G * ab * 4.12 * xi, rel=1e-12)
    assert fy == pytest.approx(-G * ab * 3.67 * eta - G * ab**1.5 * 1.47 * phi, rel=1e-12)
    assert mz == pytest.approx(G * ab**1.5 * 1.47 * eta - G * ab**2 * 1.19 * phi, rel=1e-12)
    # positive lateral creepage and positive spin both push the wheel laterally negative
    assert linear_creep_forces(a, b, 0, 1e-4, 0, shear_modulus_Pa=G, poisson_ratio=0.25)[1] < 0
    assert linear_creep_forces(a, b, 0, 0, 0.1, shear_modulus_Pa=G, poisson_ratio=0.25)[1] < 0
    assert linear_creep_forces(a, b, 1e-4, 0, 0, shear_modulus_Pa=G, poisson_ratio=0.25)[0] < 0


def test_linear_theory_is_vectorised():
    a = np.array([4e-3, 6e-3, 8e-3])
    fx, fy, mz = linear_creep_forces(a, 4e-3, 1e-4, 0.0, 0.0, shear_modulus_Pa=G, poisson_ratio=0.28)
    assert fx.shape == (3,) and np.all(np.diff(fx) < 0)


def test_vermeulen_johnson_cubic_closed_form():
    mu_n = 0.3 * 80e3
    for w in (0.1, 0.5, 0.9, 1.0):
        t = 3.0 * mu_n * w
        fx, fy = vermeulen_johnson_saturation(-t, 0.0, 80e3, 0.3)
        assert -fx == pytest.approx(mu_n * (1 - (1 - w) ** 3), rel=1e-12)
        assert fy == 0


def test_vermeulen_johnson_limits():
    mu_n = 0.3 * 80e3
    # small creepage: equals the linear theory (only with the cube: 1 - (1-w)^3 ~ 3 w)
    t = 1e-6 * mu_n
    fx, fy = vermeulen_johnson_saturation(0.6 * t, -0.8 * t, 80e3, 0.3)
    assert math.hypot(fx, fy) == pytest.approx(t, rel=1e-6)
    square = mu_n * (1 - (1 - t / (3 * mu_n)) ** 2)  # the misprinted eq 56 would give 2/3 of it
    assert square / t == pytest.approx(2.0 / 3.0, rel=1e-5)
    # large creepage: mu N, direction kept
    fx, fy = vermeulen_johnson_saturation(3e6, -4e6, 80e3, 0.3)
    assert math.hypot(fx, fy) == pytest.approx(mu_n, rel=1e-12)
    assert fy / fx == pytest.approx(-4.0 / 3.0, rel=1e-12)
    # monotone and bounded
    ts = np.linspace(0, 10 * mu_n, 200)
    out, _ = vermeulen_johnson_saturation(ts, 0.0, 80e3, 0.3)
    assert np.all(np.diff(out) >= -1e-12 * mu_n) and out.max() <= mu_n * (1 + 1e-12)
    # zero force stays zero, zero friction gives zero
    assert vermeulen_johnson_saturation(0.0, 0.0, 80e3, 0.3) == (0.0, 0.0)
    assert vermeulen_johnson_saturation(5.0, 0.0, 80e3, 0.0)[0] == 0.0


def test_bad_input_raises():
    with pytest.raises(ValueError, match="semi-axes"):
        linear_creep_forces(0.0, 1e-3, 0, 0, 0, shear_modulus_Pa=G, poisson_ratio=0.28)
    with pytest.raises(ValueError, match="normal_force_N and friction_coefficient"):
        vermeulen_johnson_saturation(1.0, 0.0, -1.0, 0.3)
