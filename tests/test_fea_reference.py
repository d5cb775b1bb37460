"""Closed-form Hertz references (fea.hertz_reference) against independent numbers.

Independent checks: the circular closed form (Johnson 1985 eq 4.23), Johnson's published maximum
subsurface shear (0.31 p0 at 0.48 a for nu = 0.3), and the Boussinesq surface displacement of the
Hertz pressure integrated numerically (u_z(0) = delta, delta - u_z(x, 0) = A x^2).
"""

import math

import numpy as np
import pytest

from fea.hertz_reference import circular_axis_maximum, circular_axis_stresses, hertz_elliptic, hertz_force_from_approach

E_STAR = 115.4e9


def test_circular_limit_matches_johnson_closed_form():
    radius, force = 0.3, 1e5
    sol = hertz_elliptic(0.5 / radius, 0.5 / radius, force, E_STAR)
    a = (3 * force * radius / (4 * E_STAR)) ** (1 / 3)  # Johnson (1985) eq 4.22
    assert sol.semi_axis_long_m == pytest.approx(a, rel=1e-9)
    assert sol.semi_axis_lat_m == pytest.approx(a, rel=1e-9)
    assert sol.max_pressure_Pa == pytest.approx(3 * force / (2 * math.pi * a * a), rel=1e-9)
    assert sol.approach_m == pytest.approx(a * a / radius, rel=1e-9)


def _boussinesq_uz(sol, x0, y0, n=400):
    """Surface displacement (times E*) under the Hertz pressure, polar quadrature around (x0, y0)."""
    from scipy.integrate import quad

    a, b, p0 = sol.semi_axis_long_m, sol.semi_axis_lat_m, sol.max_pressure_Pa

    def radial(theta):
        c, s = math.cos(theta), math.sin(theta)
        # distance to the ellipse edge along the ray: (x0 + r c)^2/a^2 + (y0 + r s)^2/b^2 = 1
        qa = c * c / a**2 + s * s / b**2
        qb = 2 * (x0 * c / a**2 + y0 * s / b**2)
        qc = x0**2 / a**2 + y0**2 / b**2 - 1
        r_edge = (-qb + math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
        return quad(
            lambda r: p0 * math.sqrt(max(0.0, 1 - (x0 + r * c) ** 2 / a**2 - (y0 + r * s) ** 2 / b**2)),
            0,
            r_edge,
            limit=200,
        )[0]

    return quad(radial, 0, 2 * math.pi, limit=200)[0] / (math.pi * E_STAR)


def test_elliptic_solution_satisfies_boussinesq_displacements():
    curv_a, curv_b = 0.5 / 0.46, 0.5 / 0.15
    sol = hertz_elliptic(curv_a, curv_b, 1e5, E_STAR)
    assert sol.semi_axis_long_m > sol.semi_axis_lat_m  # smaller curvature -> longer axis
    uz0 = _boussinesq_uz(sol, 0.0, 0.0)
    assert uz0 == pytest.approx(sol.approach_m, rel=1e-6)
    x = 0.5 * sol.semi_axis_long_m
    assert uz0 - _boussinesq_uz(sol, x, 0.0) == pytest.approx(curv_a * x * x, rel=1e-5)
    y = 0.5 * sol.semi_axis_lat_m
    assert uz0 - _boussinesq_uz(sol, 0.0, y) == pytest.approx(curv_b * y * y, rel=1e-5)


def test_swapped_curvatures_swap_axes_and_force_from_approach_inverts():
    s1 = hertz_elliptic(3.0, 1.0, 2e4, E_STAR)
    s2 = hertz_elliptic(1.0, 3.0, 2e4, E_STAR)
    assert s1.semi_axis_long_m == pytest.approx(s2.semi_axis_lat_m, rel=1e-12)
    back = hertz_force_from_approach(3.0, 1.0, s1.approach_m, E_STAR)
    assert back.normal_force_N == pytest.approx(2e4, rel=1e-9)


def test_johnson_maximum_shear_for_nu_03():
    tau, depth = circular_axis_maximum(0.3)
    assert tau == pytest.approx(0.31, abs=0.005)  # Johnson (1985) sec. 3.4: 0.31 p0
    assert depth == pytest.approx(0.48, abs=0.01)  # at z = 0.48 a
    s = circular_axis_stresses(np.array([0.0]), 0.3)
    assert s["sigma_z"][0] == pytest.approx(-1.0)
    assert s["sigma_r"][0] == pytest.approx(-(1 + 2 * 0.3) / 2)  # Johnson eq 3.41 at the centre


@pytest.mark.parametrize(
    ("args", "match"),
    [((0.0, 1.0, 1.0, 1.0), "curvature_long_1_per_m"), ((1.0, 1.0, -5.0, 1.0), "normal_force_N")],
)
def test_bad_input_raises(args, match):
    with pytest.raises(ValueError, match=match):
        hertz_elliptic(*args)
    with pytest.raises(ValueError, match="approach_m"):
        hertz_force_from_approach(1.0, 1.0, -1.0, 1.0)
