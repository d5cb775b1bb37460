"""Friction laws in the dynamics (issue 26): falling friction and friction varying in place in the compiled laws,
the ``[friction]`` table of scenes, and a braking run to wheel slide.

References:
* Full slip of the Vermeulen-Johnson law: its cube saturates at exactly mu N, with mu the law at the patch's mean
  slip velocity V |xi| (compiled_laws.mean_slip_coefficient): |T| = mu(V |xi|) N.
* A varying law at a node: the patch sees the node's coefficient, for every compiled law that has a bound.
* Braking to slide (scene braking-slide): once the wheel slides, every element of the patch slides at the slip
  velocity V |xi| and the creep force is mu(V |xi|) N times FASTSIM's full-slip quadrature of the traction bound on
  its grid (fastsim_batch at mu = 1 and a large creepage, the same semi-axes), to the elastic slip's share (< 1e-3
  at |xi| > 0.5, tests/test_fastsim_falling.py).
* Coulomb in a ``[friction]`` table equals ``material.friction_coefficient`` to the bit (regression of the two
  input paths).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hardening_helpers import assert_bad_scene

from rigid_dynamics.contact import friction
from rigid_dynamics.materials import STEEL

G, NU = STEEL.shear_modulus_Pa, STEEL.poisson_ratio


def _tables(name, law):
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.wheelset.compiled_laws import hertz_kalker_tables, tables_for
    from rigid_dynamics.wheelset.compiled_records import law_code
    from rigid_dynamics.wheelset.layout import new_parameters

    tables = tables_for(G, NU)
    par = new_parameters()
    par["shear_modulus_Pa"], par["contact_modulus_Pa"] = G, tables.e_star
    par["friction_coefficient"] = law.max_static
    par["model_code"] = law_code(get_model(name))
    par["fastsim_nx"], par["fastsim_ny"] = 20, 20
    return par, hertz_kalker_tables(tables, law)


PATCH = (1.0e-4, 1.0, 5.0)  # approach (m), relative curvatures A, B (1/m)


@pytest.mark.parametrize("name", ["vermeulen-johnson", "fastsim"])
def test_varying_law_at_a_patch_equals_the_node_value(name):
    """Nodes of the surface inclination (mu 0.4 up to 0.2 rad, 0.1 from 0.4 rad): a patch at a node gets the node's
    Coulomb law; at 0.3 rad the interpolated 0.25."""
    from rigid_dynamics.wheelset.compiled_laws import patch_forces

    law = friction.varying("surface_inclination", [0.2, 0.4], [friction.coulomb(0.4), friction.coulomb(0.1)])
    par, tables = _tables(name, law)
    creep = (3e-3, 1e-3, 0.1)
    for place, mu in ((0.0, 0.4), (0.2, 0.4), (0.3, 0.25), (0.4, 0.1), (1.0, 0.1)):
        got = patch_forces(par, tables, *PATCH, *creep, (place, 20.0))
        ref_par, ref_tables = _tables(name, friction.uniform(mu))
        want = patch_forces(ref_par, ref_tables, *PATCH, *creep, (0.0, 20.0))
        np.testing.assert_allclose(got[:4], want[:4], rtol=1e-12, atol=1e-9)


def test_coulomb_record_is_todays_law():
    """Coulomb that varies nowhere: the parameter record's coefficient serves as before (bit-identical forces)."""
    from rigid_dynamics.wheelset.compiled_laws import hertz_kalker_tables, patch_forces, tables_for

    par, tables = _tables("fastsim", friction.uniform(0.3))
    old = hertz_kalker_tables(tables_for(G, NU))  # no law given: the record's friction_coefficient
    creep = (2e-3, -1e-3, 0.3)
    assert patch_forces(par, tables, *PATCH, *creep) == patch_forces(par, old, *PATCH, *creep)


def test_vermeulen_johnson_full_slip_is_mu_at_the_slip_velocity():
    """|T| = mu(V sqrt(xi^2 + eta^2)) N in full slip (the cube saturated), Polach's law, V = 20 m/s."""
    from rigid_dynamics.wheelset.compiled_laws import patch_forces

    law = friction.FrictionLaw((friction.polach(0.4, 0.4, 0.6),))
    par, tables = _tables("vermeulen-johnson", law)
    for xi, eta in ((0.05, 0.0), (0.2, 0.05), (0.5, -0.1)):
        normal, tx, ty, _, _, _, _ = patch_forces(par, tables, *PATCH, xi, eta, 0.0, (0.0, 20.0))
        mu = law.coefficient(20.0 * math.hypot(xi, eta))
        assert math.hypot(tx, ty) == pytest.approx(mu * normal, rel=1e-12)


@pytest.fixture(scope="module")
def braking():
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    return simulate(load_scene("braking-slide"))


def test_braking_run_to_wheel_slide(braking):
    """braking-slide (40 kN m against mu_0 Q r = 32.7 kN m, Polach's falling law): the adhesion limit, then the
    creep force falls beyond its maximum and the wheel slides; both events on both wheels, in that order."""
    result = braking
    assert result.status == "ok", result.message
    kinds = [(kind, side) for kind, side, _ in result.events]
    for side in ("left", "right"):
        assert kinds.index(("adhesion-limit", side)) < kinds.index(("wheel-slide", side))
    p = result.patches
    ratio = np.abs(p["creep_force_long_N"][:, 0, 0]) / p["normal_force_N"][:, 0, 0]
    peak = int(np.nanargmax(ratio))
    assert 0.35 < ratio[peak] < 0.4  # below mu_0 = 0.4 (the adhesion zone's share and the fall with slip)
    assert ratio[-1] < 0.5 * ratio[peak]  # falling towards A mu_0 = 0.16
    xi = np.abs(p["creepage_long"][:, 0, 0])
    assert np.all(np.diff(xi[peak:]) > 0)  # the slip grows: the wheel slides
    summary = result.summary()
    assert {e["kind"] for e in summary["events"]} >= {"adhesion-limit", "wheel-slide"}


def test_braking_slide_force_is_mu_at_the_slip_velocity(braking):
    """At the end of the run (|xi| = 0.71): |T_x| / N = mu(V |xi|) times FASTSIM's full-slip quadrature factor."""
    from rigid_dynamics.contact.fastsim import fastsim_batch

    p = braking.patches
    a, b = p["semi_axis_long_m"][-1, 0, 0], p["semi_axis_lat_m"][-1, 0, 0]
    normal, tx, xi = p["normal_force_N"][-1, 0, 0], p["creep_force_long_N"][-1, 0, 0], p["creepage_long"][-1, 0, 0]
    quadrature = -fastsim_batch(a, b, 1.0, 10.0, 0.0, 0.0, shear_modulus_Pa=G, poisson_ratio=NU,
                                friction_coefficient=1.0).creep_force_long_N  # fmt: skip
    law = braking.scene.material.friction_law()
    mu = law.coefficient(braking.scene.speed_m_per_s * abs(xi))
    assert abs(xi) > 0.5
    assert abs(tx) / normal == pytest.approx(mu * float(quadrature), rel=2e-3)


def test_friction_table_coulomb_equals_material_coefficient():
    """Regression of the two input paths: [friction] law = "coulomb" against material.friction_coefficient."""
    import tomllib

    from wheelrail.scenes import embedded_scenes, parse_scene

    doc = tomllib.loads(embedded_scenes()["hunting-conical"].read_text())
    table = dict(doc)
    material = {k: v for k, v in doc["material"].items() if k != "friction_coefficient"}
    table.update(material=material, friction={"law": "coulomb", "coefficient": doc["material"]["friction_coefficient"]})
    plain, with_table = parse_scene(doc), parse_scene(table)
    assert plain.material.friction_coefficient == with_table.material.friction_coefficient
    assert with_table.material.friction_law().record().kinetic[0] == plain.material.friction_coefficient
    assert replace(with_table, material=plain.material) == plain


@pytest.mark.parametrize(
    ("new", "pattern"),
    [
        ('friction_coefficient = 0.3\n\n[friction]\nlaw = "coulomb"\ncoefficient = 0.3',
         r"'material\.friction_coefficient' = 0\.3: not allowed with a \[friction\] table"),
        ('\n[friction]\nlaw = "coulomb"\nvaries_with = "rail_lateral"\nnodes_m = [0.0, 0.02]\ncoefficient = [0.4, 0.1]',
         r"'friction\.varies_with' = 'rail_lateral': not available in dynamics scenes"),
        ('\n[friction]\nlaw = "polach"\nstatic = 0.4\npolach_a = 1.5\npolach_b_s_per_m = 0.6',
         r"polach_a = 1\.5: expected a number in \[0, 1\]"),
        ('\n[friction]\nlaw = "sticky"', r"'friction\.law' = 'sticky': expected one of"),
    ],
)  # fmt: skip
def test_bad_friction_table_in_a_scene_exits_2(tmp_path, capsys, new, pattern):
    assert_bad_scene(tmp_path, capsys, "hunting-conical", "friction_coefficient = 0.3", new, pattern)


def test_adhesion_events_on_synthetic_creep_curves():
    """recorder.adhesion_events: a falling creep curve (maximum at xi = 0.01, then falling) gives the adhesion limit
    at the maximum and the slide where |xi| reaches WHEEL_SLIDE_CREEPAGE; a saturating (Coulomb) curve gives none."""
    from rigid_dynamics.wheelset.recorder import WHEEL_SLIDE_CREEPAGE, adhesion_events

    t = np.linspace(0.0, 0.1, 101)
    xi = t.copy()  # the creepage grows linearly, 0 to 0.1
    falling = 0.4 * (xi / 0.01) * np.exp(1.0 - xi / 0.01) * 0.5 + 0.2 * np.minimum(xi / 0.01, 1.0)
    saturating = 0.4 * np.minimum(xi / 0.01, 1.0)

    def patches(ratio):
        shape = (len(t), 2, 2)
        normal = np.full(shape, np.nan)
        normal[:, :, 0] = 1e5
        tx, creep = np.full(shape, np.nan), np.full(shape, np.nan)
        tx[:, :, 0] = -ratio[:, None] * 1e5
        creep[:, :, 0] = xi[:, None]
        return {"normal_force_N": normal, "creep_force_long_N": tx, "creepage_long": creep}

    events = adhesion_events(t, patches(falling))
    peak = float(t[int(np.argmax(falling))])
    slide = float(t[int(np.argmax(xi >= WHEEL_SLIDE_CREEPAGE))])
    assert ("adhesion-limit", "left", peak) in events and ("wheel-slide", "right", slide) in events
    assert adhesion_events(t, patches(saturating)) == []
