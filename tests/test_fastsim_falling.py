"""FASTSIM with falling friction and friction varying in place (rigid_dynamics.contact.fastsim, issue 26).

References:
* Full slip: every element slides at the rigid slip velocity V |xi| (the elastic part of the slip vanishes against
  it as xi grows), so the force tends to mu(V |xi|) N: the Coulomb result at that coefficient on the same grid
  (whose own full-slip force mu N is tested in tests/test_fastsim.py), to a difference that falls with xi.
* One element (closed form): with CONTACT's linear law inside its linear range, mu(s) = mu_s - f1 s / (2 s1), the
  element equation g = p mu(V k (|t| - g)) is linear in g: g = p (mu_s - c |t|) / (1 - p c), c = f1 V k / (2 s1).
* A law of one value (f1 = f2 = 0) in the falling path equals Coulomb's fast kernel (regression of the two paths).
* Varying in place: at a node the patch sees the node's law (mu at the node).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact import friction
from rigid_dynamics.contact.fastsim import FrictionAt, PatchFriction, _falling_bound, fastsim_batch, fastsim_fields

G, NU = 82.0e9, 0.28
A, B, FN = 6.0e-3, 4.0e-3, 80.0e3
SPEED = 20.0
EXPONENTIAL = friction.FrictionLaw((friction.falling("exponential", 0.2, 0.2, 5.0),))


def _fx(xi, law, **kw):
    kw.setdefault("nx", 40)
    kw.setdefault("ny", 40)
    r = fastsim_batch(A, B, FN, xi, 0.0, 0.0, shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=law, **kw)
    return float(r.creep_force_long_N), float(r.slip_fraction)


def test_full_slip_force_tends_to_mu_at_the_slip_velocity_times_n():
    """|Fx| / (mu(V xi) N_grid) - 1 (N_grid: Coulomb's full-slip force per mu on the same grid) falls with xi:
    5.6e-4, 1.6e-4, 4e-5, 2.5e-6 at xi = 0.05, 0.5, 1, 2 (V = 20 m/s, slip velocities 1-40 m/s)."""
    deviations = []
    for xi in (0.05, 0.5, 1.0, 2.0):
        fx, slip = _fx(xi, EXPONENTIAL, rolling_speed_m_per_s=SPEED)
        coulomb, _ = _fx(xi, EXPONENTIAL.coefficient(SPEED * xi))
        assert slip == 1.0
        deviations.append(abs(fx / coulomb - 1.0))
    assert deviations[-1] < 1e-5, deviations
    assert all(d1 < d0 for d0, d1 in zip(deviations, deviations[1:], strict=False)), deviations
    assert deviations[0] < 1e-3, deviations


def test_creep_curve_falls_beyond_its_maximum():
    """The falling law's creep curve peaks near mu_s N and falls towards mu_k N; Coulomb's saturates (monotone)."""
    xis = np.array([1e-3, 4e-3, 1e-2, 2e-2, 5e-2, 0.2, 1.0])
    falling = np.array([-_fx(x, EXPONENTIAL, rolling_speed_m_per_s=SPEED)[0] for x in xis]) / FN
    coulomb = np.array([-_fx(x, 0.4)[0] for x in xis]) / FN
    peak = int(np.argmax(falling))
    assert 0 < peak < len(xis) - 1
    assert falling[peak] < 0.4 and falling[-1] < 0.25 and falling[-1] > 0.2
    assert np.all(np.diff(coulomb) > -1e-12)


def test_element_bound_equals_the_linear_law_closed_form():
    """_falling_bound against g = p (mu_s - c |t|) / (1 - p c), c = f1 V k / (2 s1), inside the linear range."""
    law = friction.FrictionLaw((friction.falling("linear", 0.2, 0.2, 10.0),))
    pressure, trial, k = 1.0e9, 5.0e8, 1.0e-11
    c = 0.2 * SPEED * k / (2.0 * 10.0)
    expected = pressure * (0.4 - c * trial) / (1.0 - pressure * c)
    got = _falling_bound(PatchFriction(law.record(), 0.0, 0.4, SPEED), pressure, trial, k)
    assert SPEED * k * (trial - expected) < 2.0 * 10.0  # inside the linear range of the law
    assert got == pytest.approx(expected, rel=1e-12)


def test_constant_law_in_the_falling_path_equals_coulomb_regression():
    """Regression of the two paths: the exponential form with f1 = 0 (mu = mu_k at every slip velocity) runs the
    plain loop with the element solve; it must give Coulomb's fast kernel to round-off."""
    flat = friction.FrictionLaw((friction.falling("exponential", 0.3, 0.0, 1.0),))
    for creep in ((1e-3, 0.0, 0.0), (2e-3, -1e-3, 0.5), (0.05, 0.01, 0.0)):
        r = fastsim_batch(A, B, FN, *creep, shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=flat)
        c = fastsim_batch(A, B, FN, *creep, shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=0.3)
        np.testing.assert_allclose(
            [r.creep_force_long_N, r.creep_force_lat_N], [c.creep_force_long_N, c.creep_force_lat_N],
            rtol=1e-12, atol=1e-12 * 0.3 * FN,
        )  # fmt: skip


def test_varying_law_at_a_node_is_the_node_law():
    """A Coulomb law at nodes of the surface inclination: a patch at a node equals Coulomb with the node's mu; half
    way between two nodes, the interpolated mu."""
    law = friction.varying("surface_inclination", [0.3, 0.5], [friction.coulomb(0.4), friction.coulomb(0.1)])
    for place, mu in ((0.3, 0.4), (0.5, 0.1), (0.0, 0.4), (1.2, 0.1), (0.4, 0.25)):
        got = _fx(0.01, FrictionAt(law, place))[0]
        assert got == pytest.approx(_fx(0.01, mu)[0], rel=1e-12, abs=1e-9)


def test_fields_of_a_falling_law_report_slip_velocity():
    """fastsim_fields with a falling law: slip velocities in the slip zone equal V |s|, and the force equals the
    batch's (one kernel)."""
    (fx, _, _, _), fields = fastsim_fields(
        A, B, FN, 0.01, 0.0, 0.0, shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=EXPONENTIAL,
        rolling_speed_m_per_s=SPEED,
    )  # fmt: skip
    batch = fastsim_batch(
        A, B, FN, 0.01, 0.0, 0.0, shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=EXPONENTIAL,
        rolling_speed_m_per_s=SPEED,
    )  # fmt: skip
    assert fx == pytest.approx(float(batch.creep_force_long_N), rel=1e-13)
    assert fields.slip_m_per_s.max() > 0.0 and math.isfinite(fields.slip_m_per_s.max())


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"rolling_speed_m_per_s": -1.0}, "rolling_speed_m_per_s"),
        ({"nz": 3}, "nz = 3: unknown option"),
    ],
)
def test_bad_inputs_name_the_argument(kwargs, match):
    """Bad keywords raise ValueError naming the argument (and a place that is not finite, below)."""
    with pytest.raises(ValueError, match=match):
        fastsim_batch(A, B, FN, 0.0, 0.0, 0.0, shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=EXPONENTIAL,
                      **kwargs)  # fmt: skip


def test_static_fastsim_model_takes_the_material_law_at_the_patch_place():
    """The registry's fastsim model with a material carrying a varying law: a patch whose contact angle sits at a
    node gives the node's Coulomb result; a falling law gives fastsim_fields' result with that law."""
    from dataclasses import replace

    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    model = get_model("fastsim")
    base = Material(G, NU, 0.3)
    geometry = replace(ContactGeometry(1.0, 5.0, 1e-4), contact_angle_rad=0.4)
    creep = Creepage(2e-3, 0.0, 0.0, SPEED)
    law = friction.varying("surface_inclination", [0.2, 0.4], [friction.coulomb(0.4), friction.coulomb(0.1)])
    got = model.solve(geometry, creep, base.with_friction(law))
    want = model.solve(geometry, creep, Material(G, NU, 0.1))
    assert got.creep_force_long_N == pytest.approx(want.creep_force_long_N, rel=1e-12)
    falling = model.solve(geometry, creep, base.with_friction(EXPONENTIAL))
    (fx, _, _, _), _ = fastsim_fields(
        falling.semi_axis_long_m, falling.semi_axis_lat_m, falling.normal_force_N, 2e-3, 0.0, 0.0,
        shear_modulus_Pa=G, poisson_ratio=NU, friction_coefficient=EXPONENTIAL, rolling_speed_m_per_s=SPEED,
    )  # fmt: skip
    assert falling.creep_force_long_N == pytest.approx(fx, rel=1e-12)


def test_a_place_that_is_not_finite_is_refused():
    with pytest.raises(ValueError, match="place = nan: expected finite values"):
        _fx(0.01, FrictionAt(EXPONENTIAL, math.nan))
