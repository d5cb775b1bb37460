"""The rungs that bound a patch with one friction coefficient (vermeulen-johnson, fastrip, kpec) given a falling law:
the law at the patch's mean rigid slip velocity V |xi|, said in the message (as the compiled loop's analytic laws).

Independent reference: in full slip every element slides at the rigid slip velocity, so the creep force is
mu(V |xi|) N exactly (the law's closed form, tested in test_friction_laws.py), and FASTSIM, which bounds each element
at its own slip velocity, gives the same within its grid error. Before this, these rungs took the law's static
coefficient (0.33 here, 16 % above mu(0.5 m/s) = 0.284) with status ok.
"""

from __future__ import annotations

import math

import pytest

from rigid_dynamics.contact.friction import FallingLaw, FrictionLaw
from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import Material

LAW = FrictionLaw((FallingLaw("exponential", 0.14, 0.19, 1.25),))
MATERIAL = Material(82e9, 0.28, LAW.max_static).with_friction(LAW)
NORMAL_N = 1e4
CREEP = Creepage(-0.05, 0.0, 0.0, 10.0)  # full slip: |xi| 50 x the creepage that saturates this patch


def _fx(method: str):
    result = get_model(method).solve(ContactGeometry.quadric(0.46, 0.3), CREEP, MATERIAL, normal_force_N=NORMAL_N)
    return result


@pytest.mark.parametrize("method", ["vermeulen-johnson", "fastrip", "kpec"])
def test_one_coefficient_rungs_take_the_law_at_the_rigid_slip_velocity(method):
    mu = 0.14 + 0.19 * math.exp(-math.log(2.0) * 0.5 / 1.25)  # CONTACT's exponential form at s = V |xi| = 0.5 m/s
    assert LAW.coefficient(0.5) == pytest.approx(mu, rel=1e-12)
    result = _fx(method)
    assert result.status == "ok"
    assert "falling friction" in result.message and "0.5 m/s" in result.message
    assert result.extra["friction_coefficient_used"] == pytest.approx(mu, rel=1e-12)  # recorded, not only in text
    assert result.creep_force_long_N == pytest.approx(mu * NORMAL_N, rel=5e-3)
    fastsim = _fx("fastsim")
    assert result.creep_force_long_N == pytest.approx(fastsim.creep_force_long_N, rel=1e-2)
