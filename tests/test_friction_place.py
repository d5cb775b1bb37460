"""Friction varying in place within a wheelset patch (the case option ``friction_place = "element"``): each BEM
element's traction bound is mu at the rail's inclination under it. Checked on the A-2.2 flange-root patch (step 10,
right wheel, CONTACT's D_SEP 6 / D_COMB 3 mm so that it is a patch of its own), where the rail's inclination runs
from 0.26 to 0.34 rad across the contact. D_TURN = D_SEP: each patch in the plane of its own weighted angle (the
deck's default D_TURN of 9 mm would turn the two patches, 6.8 mm apart, towards each other:
tests/test_patch_turning.py), which the place function is checked against."""

import math

import numpy as np
import pytest

from comparisons.manchester import MATERIAL, a22_case, build_track
from rigid_dynamics.contact.bem.model import BemModel
from rigid_dynamics.contact.friction import FrictionLaw, coulomb, falling, varying
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.contact.wheelset_case import friction_place_of, solve_wheelset_case

LUBRICATED_FLANGE = varying("surface_inclination", [0.28, 0.32], [coulomb(0.3), coulomb(0.1)])
"""mu 0.3 on the rail head, 0.1 towards the gauge face (0.28 to 0.32 rad, linear between)."""


@pytest.fixture(scope="module")
def solved():
    case = a22_case(10, "deck")
    track = build_track(case)
    out = {}
    for place in ("patch", "element"):
        options = {"model": {"element_size_m": 2e-4}, "sides": ("right",), "friction_place": place,
                   "patch": {"distance_separation_m": 6e-3, "distance_combination_m": 3e-3,
                             "distance_turning_m": 6e-3}}  # fmt: skip
        out[place] = solve_wheelset_case(case, MATERIAL.with_friction(LUBRICATED_FLANGE), "bem", options, track=track)
    return track, out


def test_place_function_at_the_reference_point(solved):
    """At the patch's reference point the rail-profile coordinate is the patch's own and the inclination is within
    0.005 rad of its (weighted) contact angle."""
    track, out = solved
    for p in out["patch"].patches:
        place = friction_place_of(p.geometry, track.fast["right"][1], "right")
        assert float(place("rail_lateral", 0.0, 0.0)) == pytest.approx(p.geometry.contact_point_rail_m[0], abs=1e-7)
        assert float(place("surface_inclination", 0.0, 0.0)) == pytest.approx(p.geometry.contact_angle_rad, abs=5e-3)


def test_slip_elements_carry_mu_at_their_own_place(solved):
    """Element-wise: every slip element's |t| is mu(inclination under it) p (to the solver's tolerance), and mu
    spans 0.1-0.3 over the flange-root patch; patch-wise one mu (at the patch's contact angle, 0.298 rad: 0.21)
    bounds every element. The patch's lateral creep force differs by 1.3 % between the two (recorded: -1582 N
    element-wise, -1603 N patch-wise, FN 8.1 kN)."""
    track, out = solved
    big = {k: max(v.patches, key=lambda p: p.result.normal_force_N) for k, v in out.items()}
    assert all(v.success for v in out.values())
    for kind, p in big.items():
        f = p.result.fields
        xx, yy = np.meshgrid(f.x_m, f.y_m)
        if kind == "element":
            inclination = friction_place_of(p.geometry, track.fast["right"][1], "right")("surface_inclination", xx, yy)
        else:
            inclination = np.full(xx.shape, p.geometry.contact_angle_rad)
        mu = np.vectorize(LUBRICATED_FLANGE.static_coefficient)(inclination)
        slip = f.in_slip & f.in_contact
        bound = mu * f.pressure_Pa
        t = np.hypot(f.traction_long_Pa, f.traction_lat_Pa)
        assert slip.sum() > 100
        assert np.allclose(t[slip], bound[slip], rtol=1e-6, atol=1e-9 * bound.max())
        assert np.all(t[f.in_contact] <= bound[f.in_contact] * (1 + 1e-6) + 1e-9 * bound.max())
        if kind == "element":
            assert mu[f.in_contact].min() == pytest.approx(0.1) and mu[f.in_contact].max() == pytest.approx(0.3)
    fs = {k: p.result.creep_force_lat_N for k, p in big.items()}
    assert 0.005 * abs(fs["patch"]) < abs(fs["element"] - fs["patch"]) < 0.03 * abs(fs["patch"]), fs


def test_falling_law_needs_steady_rolling():
    law = FrictionLaw((falling("exponential", 0.2, 0.1, 1.0),))
    with pytest.raises(ValueError, match="problem = 'shift': a falling friction law is solved for steady rolling"):
        BemModel().solve(ContactGeometry.quadric(0.46, 0.3), Creepage(), MATERIAL.with_friction(law),
                         normal_force_N=1e4, options={"nx": 8, "ny": 8, "problem": "shift"})  # fmt: skip


def test_place_needs_a_reference():
    """A quadric patch has no rail-profile coordinate: a law varying with it is refused with one line."""
    law = varying("rail_lateral", [-0.01, 0.01], [coulomb(0.3), coulomb(0.2)])
    with pytest.raises(ValueError, match="friction varies_with = 'rail_lateral': the patch has no such place"):
        BemModel().solve(ContactGeometry.quadric(0.46, 0.3), Creepage(1e-3), MATERIAL.with_friction(law),
                         normal_force_N=1e4, options={"nx": 8, "ny": 8})  # fmt: skip
    assert math.isnan(ContactGeometry.quadric(0.46, 0.3).contact_point_rail_m[0])
