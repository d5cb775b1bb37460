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


# --- the three-dimensional creep force with a stated error: rolling block series (fea.rolling_series) -------------


def test_richardson_estimate_on_known_series():
    """F = F_inf + C n^-p on three meshes at ratio 1.5: the order and the limit come back; the stated error uses
    q = min(p, 1) (Carter's first order), so it bounds the true error of the finest mesh when p >= 1."""
    from fea.rolling_series import richardson_estimate

    n = (4.0, 6.0, 9.0)
    for p in (1.0, 1.7):
        values = [100.0 + 40.0 * k**-p for k in n]
        est = richardson_estimate(n, values)
        assert est.status == "ok"
        assert est.observed_order == pytest.approx(p, rel=1e-9)
        assert est.extrapolated == pytest.approx(100.0, rel=1e-12)
        assert est.stated_error >= values[-1] - 100.0 - 1e-9
        assert est.stated_error == pytest.approx(abs(values[2] - values[1]) / 0.5, rel=1e-12)
    assert richardson_estimate(n, [3.0, 1.0, 2.0]).status == "irregular"  # not monotone
    assert richardson_estimate(n, [10.0, 9.0, 8.9]).status == "irregular"  # p = 5.7: outside [0.5, 4]
    assert math.isnan(richardson_estimate(n, [3.0, 1.0, 2.0]).stated_error)  # a status, never a number
    with pytest.raises(ValueError, match="constant ratio"):
        richardson_estimate((4.0, 6.0, 8.0), [1.0, 2.0, 3.0])


def test_series_statuses_from_levels():
    """fea.rolling_series.series_from_levels: the slip zone must be resolved on every level (no error stated in the
    no-slip regime, a status), a fully sliding patch states the levels' spread, a regular series its first-order
    error, and an insignificant cross component is not extrapolated."""
    from fea.rolling_series import series_from_levels

    n = (4.0, 6.0, 9.0)

    def levels(forces, slip, contact=(49, 107, 247), rows=(9, 13, 19)):
        return [
            {"n": k, "creep_force_N": f, "slip_nodes": s, "contact_nodes": c, "rows": r}
            for k, f, s, c, r in zip(n, forces, slip, contact, rows, strict=True)
        ]

    regular = [(-1241.7, 0.9), (-1180.3, 0.0), (-1146.1, -0.4)]  # the circle at xi = 5e-4 (bench)
    out = series_from_levels(levels(regular, (17, 32, 65)), n)
    assert out.status == "ok", out.message
    assert out.observed_order[0] == pytest.approx(1.45, abs=0.01)
    assert out.stated_error_N[0] == pytest.approx(2 * (1180.3 - 1146.1), rel=1e-9)
    assert out.stated_error_N[1] == pytest.approx(0.9)  # F_y below 5e-3 |F|: its largest magnitude, no order
    linear = [(-152.3, 0.0), (-139.2, 0.0), (-133.8, 0.0)]  # xi = 5e-5: all nodes stick at n = 4 and 6
    out = series_from_levels(levels(linear, (0, 0, 4)), n)
    assert out.status == "unresolved" and math.isnan(out.stated_error_N[0])
    sliding = [(-3000.0, 0.0), (-3000.0 + 1e-9, 0.0), (-3000.0, 0.0)]
    out = series_from_levels(levels(sliding, (49, 107, 247)), n)
    assert out.status == "ok" and out.stated_error_N[0] <= 1e-8
    wobbly = [(-1241.7, 0.0), (-1180.3, 0.0), (-1190.0, 0.0)]
    assert series_from_levels(levels(wobbly, (17, 32, 65)), n).status == "irregular"


def test_rolling_block_face_is_a_mirror_symmetric_edge_fitted_grid():
    """The rolling block's mesh (meshing.rolling_block): conforming (every interior triangle shared by two
    tetrahedra), symmetric about y = 0, the contact face's box nodes on rows y = j h, each row's contact nodes ending
    on the expected edge x_e = a sqrt(1 - y^2/a^2) (regression test of the construction)."""
    import dolfinx_solver  # noqa: F401
    from dolfinx.cpp.mesh import entities_to_geometry
    from dolfinx.mesh import exterior_facet_indices

    from fea.domain import rolling_block_domain
    from meshing.rolling_block import RollingBlockSpec

    spec = RollingBlockSpec(A_M, A_M, 4.0)
    domain = rolling_block_domain(spec)
    msh = domain.mesh
    msh.topology.create_connectivity(2, 3)
    outside = msh.geometry.x[entities_to_geometry(msh._cpp_object, 2, exterior_facet_indices(msh.topology), False)]
    big = spec.half_width_m
    on_boundary = (
        np.all(np.isclose(np.abs(outside[:, :, 0]), big), axis=1)
        | np.all(np.isclose(np.abs(outside[:, :, 1]), big), axis=1)
        | np.all(np.isclose(outside[:, :, 2], -big), axis=1)
        | np.all(np.abs(outside[:, :, 2]) <= 1e-12 * big, axis=1)
    )
    assert on_boundary.all()  # no crack: the transfinite box conforms to the unstructured rest
    h = spec.contact_size_m
    x = msh.geometry.x
    face = x[(np.abs(x[:, 2]) <= 1e-12 * big) & (np.abs(x[:, 0]) <= A_M + h) & (np.abs(x[:, 1]) <= A_M + h)]
    key = np.round(face[:, :2] / (1e-6 * h)).astype(np.int64)
    mirrored = key * np.array([1, -1])
    assert {tuple(k) for k in key} == {tuple(k) for k in mirrored}
    rows = face[:, 1] / h
    assert np.allclose(rows, np.round(rows), atol=1e-9)
    for j in range(-3, 4):
        xs = face[np.round(rows) == j, 0]
        edge = A_M * math.sqrt(1.0 - (j * h / A_M) ** 2)
        assert np.min(np.abs(xs - edge)) <= 1e-9 * A_M and np.min(np.abs(xs + edge)) <= 1e-9 * A_M


@pytest.mark.slow
def test_circle_creep_force_series_states_its_error_against_the_bem():
    """Steady rolling of the Hertz circle (R = 0.3 m both ways, P = 10 kN, mu = 0.3, xi = 5e-4, F about 0.37 mu P) on
    the rolling block at 4, 6, 9 elements per semi-axis (about 25 s CPU): the series is regular and the stated error
    of the n = 9 force (first-order Richardson from n = 6 and 9) covers its distance to the BEM (a second method,
    its stated grid error 1.2 %) within the BEM's error.

    Measured (benchmarks/results/fea_friction.md): +11.3/+5.8/+2.7 % against the BEM at n = 4/6/9, observed
    order 1.45, stated error 6.0 % of the force (the first order overstates it by about 2 when p > 1; 3.2 % stated
    against 1.1 % on 6/9/13.5).
    """
    from fea.hertz_reference import hertz_elliptic
    from fea.rolling_series import solve_rolling_series
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    radius, force, xi = 0.3, 1e4, 5e-4
    hertz = hertz_elliptic(0.5 / radius, 0.5 / radius, force, E_STAR)
    a = hertz.semi_axis_long_m
    series = solve_rolling_series(
        a, a, lambda x, y: (x * x + y * y) / (2 * radius), E_BLOCK, NU, MU, force, (xi, 0.0, 0.0),
        elements=(4.0, 6.0, 9.0), initial_approach_m=hertz.approach_m,
    )  # fmt: skip
    assert series.status == "ok", series.message
    bem = get_model("bem").solve(
        ContactGeometry.quadric(radius, radius), Creepage(longitudinal=xi), Material.from_young(E_PA, NU, MU),
        normal_force_N=force,
    )  # fmt: skip
    assert bem.status == "ok"
    band = bem.extra["grid_error"]["relative"]["creep_force_N"] * abs(bem.creep_force_long_N)
    fx, error_x = series.creep_force_N[0], series.stated_error_N[0]
    assert 1.0 <= series.observed_order[0] <= 2.5
    assert abs(fx - bem.creep_force_long_N) <= error_x + band
    assert error_x <= 0.08 * abs(fx)  # and the statement is not vacuous
    assert abs(series.extrapolated_N[0] - bem.creep_force_long_N) <= error_x + band
    assert abs(series.creep_force_N[1]) <= 1e-3 * abs(fx)  # F_y = 0 by the mesh's symmetry
    assert [lv["n"] for lv in series.levels] == [4.0, 6.0, 9.0]
