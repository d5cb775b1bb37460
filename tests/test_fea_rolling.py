"""Steady rolling in the FEA (fea/friction.py, solve_rolling) against Carter's two-dimensional closed form.

Reference (independent): Carter (1926), Johnson (1985) sec. 8.4 -- two equal cylinders rolling with longitudinal
creepage xi stick in a zone of half-length c = a (1 - xi R/(mu a)) at the leading edge, F = mu P (1 - (c/a)^2), and
the traction is the difference of two Hertz ellipses (fea.friction.carter_rolling). The FEA model is the
plane-strain slab (meshing.slab: one extruded layer with u_y = 0 on every node, 20 a wide and deep, clamped base)
under a rigid cylinder, the steady state solved directly.

Errors stated by the test, from the convergence study benchmarks/bench_fea_friction.py
(benchmarks/results/fea_friction.md): the creep force is too large by a first-order error, the nodal collocation of
Coulomb's law putting the stick/slip boundary on a node (the boundary node's whole cell slides: about h/(pi a) mu P);
measured at xi R/(mu a) = 0.5 and 0.05: +4.7/+6.4 % at n = 8, +2.0/+2.9 % at n = 16, +1.2/+1.3 % at n = 32 elements
per semi-axis. The test runs n = 16 with the tolerance 4 % (the n = 16 error plus a third) and checks that n = 8 is
worse (the error falls with h).
"""

import math

import numpy as np
import pytest

from fea.friction import carter_rolling

pytestmark = pytest.mark.fea

E_PA, NU, RADIUS_M, MU, A_M = 210e9, 0.3, 0.5, 0.3, 2e-3
E_STAR = E_PA / (2 * (1 - NU**2))
E_BLOCK = E_STAR * (1 - NU**2)
FORCE_PER_LENGTH = math.pi * A_M * A_M * E_STAR / (4 * RADIUS_M)  # Hertz: a^2 = 4 P' R/(pi E*)
TOLERANCE = 0.04


def _slab(n):
    import dolfinx_solver  # noqa: F401

    from fea.domain import plane_strain_slab_domain
    from fea.solver import solve_rigid_indenter
    from meshing.slab import SlabSpec

    spec = SlabSpec(A_M, n)
    domain = plane_strain_slab_domain(spec)
    normal = solve_rigid_indenter(
        domain,
        lambda x, y: x * x / (2 * RADIUS_M),
        E_BLOCK,
        NU,
        normal_force_N=FORCE_PER_LENGTH * spec.contact_size_m,
        initial_approach_m=A_M * A_M / (2 * RADIUS_M),
        length_scale_m=A_M,
    )
    assert normal.success, normal.message
    return domain, normal, spec


@pytest.fixture(scope="module")
def slabs():
    return {n: _slab(n) for n in (8.0, 16.0)}


def _roll(slab, xi):
    from fea.friction import solve_rolling

    domain, normal, spec = slab
    sol = solve_rolling(
        domain, normal, E_BLOCK, NU, MU, (xi, 0.0, 0.0), step_m=spec.contact_size_m / 2, length_scale_m=A_M
    )
    assert sol.success and sol.status == "ok", sol.message
    return sol, FORCE_PER_LENGTH * spec.contact_size_m


@pytest.mark.parametrize("slip_ratio", [0.5, 0.05])
def test_carter_creep_force_stick_zone_and_traction(slabs, slip_ratio):
    xi = slip_ratio * MU * A_M / RADIUS_M
    ref = carter_rolling(xi, MU, A_M, RADIUS_M)
    errors = {}
    for n, slab in slabs.items():
        sol, force = _roll(slab, xi)
        fx = sol.creep_force_N[0]
        assert fx < 0  # on the wheel, against the creepage
        errors[n] = -fx / (MU * force) / ref["force_ratio"] - 1.0
        assert abs(sol.creep_force_N[1]) <= 1e-9 * force  # plane strain: no lateral force
    assert 0 < errors[16.0] <= TOLERANCE  # stiffer than Carter by the stick/slip boundary's half cell
    assert errors[16.0] < 0.7 * errors[8.0]  # and the error falls with h (first order)
    # stick zone at the leading edge, its ends within 1.5 elements of Carter's (the stick/slip boundary on a node;
    # the leading-edge node itself, N_i ~ 0, slides)
    h = A_M / 16.0
    x_stick = sol.node_xy_m[sol.stick, 0]
    lo, hi = ref["stick_zone_m"]
    assert abs(x_stick.min() - lo) <= 1.5 * h and abs(x_stick.max() - hi) <= 1.5 * h
    # traction per x (the forces of the two faces' nodes at one x over their weights: the tetrahedra split the
    # extruded prisms unevenly, so the two faces share a station's force unevenly): Carter's shape within 4 % of
    # mu p0, except within 1.5 elements of the patch's edges (lumped pressure) and of the stick/slip boundary
    # (where Carter's traction has a square-root kink)
    p0 = 2 * FORCE_PER_LENGTH / (math.pi * A_M)
    stations, which = np.unique(np.round(sol.node_xy_m[:, 0] / h, 6), return_inverse=True)
    x = stations * h
    force_x = np.bincount(which, -sol.node_traction_Pa[:, 0] * sol.node_weight_m2)
    q = force_x / np.bincount(which, sol.node_weight_m2) / (MU * p0)
    inner = (np.abs(x) < A_M - 1.5 * h) & (np.abs(x - lo) > 1.5 * h)
    assert np.max(np.abs(q[inner] - ref["traction_ratio"](x[inner]))) <= 0.04
    # Coulomb's law on the slip nodes: |q| = mu N_i/w_i
    slipping = ~sol.stick
    bound = MU * sol.node_normal_force_N[slipping] / sol.node_weight_m2[slipping]
    assert np.allclose(np.abs(sol.node_traction_Pa[slipping, 0]), bound, rtol=1e-6)


def test_carter_beyond_saturation_slides_at_mu_p(slabs):
    sol, force = _roll(slabs[8.0], 2.0 * MU * A_M / RADIUS_M)
    assert sol.creep_force_N[0] == pytest.approx(-MU * force, rel=1e-9)
    assert not sol.stick.any()


def test_carter_closed_form_limits():
    """The closed form itself: F/(mu P) ~ 2 xi R/(mu a) at small creepage (Johnson eq 8.11's linear limit)."""
    ref = carter_rolling(1e-9, MU, A_M, RADIUS_M)
    assert ref["force_ratio"] == pytest.approx(2e-9 * RADIUS_M / (MU * A_M), rel=1e-6)
    assert carter_rolling(1.0, MU, A_M, RADIUS_M)["force_ratio"] == 1.0
    assert float(ref["traction_ratio"](0.5 * A_M)) == pytest.approx(0.0, abs=1e-5)
