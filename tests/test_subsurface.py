"""Half-space subsurface stresses (rigid_dynamics/contact/subsurface.py) checked by what they must satisfy.

* equilibrium div(sigma) = 0 of both point-force kernels (central differences);
* a traction-free surface away from the load;
* the force balance of a depth plane (integral of s_dd = -P for Boussinesq, of s_xd = -Q for Cerruti);
* the Hertz circle: BEM pressure (NORM) -> stresses on the axis against Johnson's closed form (eq 3.45)
  and the maximum shear 0.31 p0 at 0.48 a (nu = 0.3; Johnson 1985 fig. 3.9).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.subsurface import (
    boussinesq_kernel,
    cerruti_kernel,
    halfspace_stress,
    hertz_axis_stresses,
    max_shear_Pa,
    von_mises_Pa,
)

NU = 0.3


def _tensor(s):
    t = np.empty((3, 3) + s.shape[1:])
    t[0, 0], t[1, 1], t[2, 2] = s[0], s[1], s[2]
    t[0, 1] = t[1, 0] = s[3]
    t[0, 2] = t[2, 0] = s[4]
    t[1, 2] = t[2, 1] = s[5]
    return t


@pytest.mark.parametrize("kernel", [boussinesq_kernel, cerruti_kernel])
def test_point_force_kernels_are_in_equilibrium(kernel):
    rng = np.random.default_rng(1)
    pts = rng.uniform([-2, -2, 0.3], [2, 2, 2], size=(20, 3))
    h = 1e-5
    for x, y, d in pts:
        div = np.zeros(3)
        for j, (ex, ey, ed) in enumerate(np.eye(3)):
            plus = _tensor(kernel(x + h * ex, y + h * ey, d + h * ed, NU))
            minus = _tensor(kernel(x - h * ex, y - h * ey, d - h * ed, NU))
            div += (plus[:, j] - minus[:, j]) / (2 * h)
        scale = np.abs(_tensor(kernel(x, y, d, NU))).max() / math.sqrt(x * x + y * y + d * d)
        assert np.abs(div).max() < 1e-5 * scale, (kernel.__name__, x, y, d, div)


@pytest.mark.parametrize("kernel", [boussinesq_kernel, cerruti_kernel])
def test_surface_is_traction_free_away_from_the_load(kernel):
    s = kernel(np.array([0.7, -1.3, 0.2]), np.array([0.4, 0.9, -1.1]), 1e-9, NU)
    assert np.abs(s[2:3]).max() < 1e-6 and np.abs(s[4:6]).max() < 1e-6


def test_depth_plane_carries_the_applied_forces():
    d = 1.0
    u = np.linspace(-60, 60, 1201)
    xx, yy = np.meshgrid(u, u)
    area = (u[1] - u[0]) ** 2
    b = boussinesq_kernel(xx, yy, d, NU)
    c = cerruti_kernel(xx, yy, d, NU)
    assert b[2].sum() * area == pytest.approx(-1.0, abs=2e-3)
    # s_xd decays as 1/rho^3: the plane beyond |x|, |y| <= R carries about 1.5 d / R (0.025 here) of Q
    assert c[4].sum() * area == pytest.approx(-1.0 + 1.5 * d / 60.0, abs=4e-3)
    assert abs(c[2].sum() * area) < 1e-6 and abs(b[4].sum() * area) < 1e-6


@pytest.fixture(scope="module")
def hertz_circle():
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    mat = Material(80e9, NU, 0.3)
    result = get_model("bem").solve(
        ContactGeometry.quadric(0.3, 0.3), Creepage(), mat, normal_force_N=1e4, options={"nx": 48, "ny": 48}
    )
    a = result.semi_axis_long_m
    f = result.fields
    p0 = 3 * 1e4 / (2 * math.pi * a * a)
    return f, a, p0


def test_hertz_axis_stresses_from_bem_pressure_match_johnson(hertz_circle):
    f, a, p0 = hertz_circle
    t = np.linspace(0.2, 2.0, 10)
    pts = np.column_stack([np.zeros_like(t), np.zeros_like(t), t * a])
    s = halfspace_stress(f.x_m, f.y_m, f.pressure_Pa, pts, NU)
    s_r, s_z = hertz_axis_stresses(t, NU)
    assert np.abs(s[:, 2, 2] / p0 - s_z).max() < 0.01
    assert np.abs(s[:, 0, 0] / p0 - s_r).max() < 0.01


def test_hertz_circle_max_shear_031_p0_at_048_a(hertz_circle):
    """Johnson 1985 (fig. 3.9, nu = 0.3): max (s1 - s3)/2 = 0.31 p0 at depth 0.48 a, on the axis."""
    f, a, p0 = hertz_circle
    t = np.linspace(0.3, 0.7, 41)
    pts = np.column_stack([np.zeros_like(t), np.zeros_like(t), t * a])
    tau = max_shear_Pa(halfspace_stress(f.x_m, f.y_m, f.pressure_Pa, pts, NU)) / p0
    k = int(np.argmax(tau))
    assert tau[k] == pytest.approx(0.31, abs=0.005)
    assert t[k] == pytest.approx(0.48, abs=0.02)
    # closed-form counterpart of the same numbers
    s_r, s_z = hertz_axis_stresses(t, NU)
    assert np.max(0.5 * (s_r - s_z)) == pytest.approx(0.31, abs=0.005)
    assert von_mises_Pa(np.diag([1.0, 1.0, 0.0])[None]) == pytest.approx(1.0)


def test_points_at_the_surface_are_refused(hertz_circle):
    f, a, _ = hertz_circle
    with pytest.raises(ValueError, match="depths > 0"):
        halfspace_stress(f.x_m, f.y_m, f.pressure_Pa, np.array([[0.0, 0.0, 0.0]]), NU)
