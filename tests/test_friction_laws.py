"""The friction laws of rigid_dynamics.contact.friction against their closed forms (the formulas as published)."""

from __future__ import annotations

import math

import pytest

from rigid_dynamics.contact import friction


def test_polach_law_equals_polach_formula():
    """Polach (2005) eq 13: mu = mu_0 ((1 - A) exp(-B s) + A), at slip velocities 0 to 20 m/s."""
    law = friction.polach(0.55, 0.40, 0.60)
    for s in (0.0, 0.1, 1.0, 3.0, 20.0):
        assert law.coefficient(s) == pytest.approx(0.55 * ((1 - 0.40) * math.exp(-0.60 * s) + 0.40), rel=1e-12)
    assert law.static == pytest.approx(0.55, rel=1e-15)


@pytest.mark.parametrize(
    ("form", "expected"),
    [
        ("linear", lambda s: 0.2 + 0.1 * max(0.0, 1 - 0.5 * s / 2.0) + 0.05 * max(0.0, 1 - 0.5 * s / 5.0)),
        ("rational", lambda s: 0.2 + 0.1 / (1 + s / 2.0) + 0.05 / (1 + (s / 5.0) ** 2)),
        ("exponential", lambda s: 0.2 + 0.1 * 0.5 ** (s / 2.0) + 0.05 * 0.5 ** (s / 5.0)),
    ],
)
def test_falling_forms_equal_their_formulas(form, expected):
    """CONTACT's falling forms (L = 2, 3, 4) as written in the module text; each term halves at its velocity."""
    law = friction.falling(form, 0.2, 0.1, 2.0, 0.05, 5.0)
    for s in (0.0, 0.7, 2.0, 5.0, 11.0):
        assert law.coefficient(s) == pytest.approx(expected(s), rel=1e-12)
    assert law.static == pytest.approx(0.35)


def test_varying_law_interpolates_and_holds_beyond_the_ends():
    """Gauge-face lubrication as nodes in the surface inclination: 0.4 up to 0.3 rad, 0.1 from 0.5 rad."""
    law = friction.varying("surface_inclination", (0.3, 0.5), (friction.coulomb(0.4), friction.coulomb(0.1)))
    assert law.coefficient(place=-0.1) == pytest.approx(0.4)
    assert law.coefficient(place=0.4) == pytest.approx(0.25)
    assert law.coefficient(place=1.2) == pytest.approx(0.1)
    assert law.max_static == pytest.approx(0.4)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: friction.polach(0.5, 1.5, 0.6), "polach_a = 1.5"),
        (lambda: friction.polach(0.5, 0.4, 0.0), "polach_b_s_per_m = 0.0"),
        (lambda: friction.falling("parabolic", 0.2, 0.1, 1.0), "law = 'parabolic'"),
        (lambda: friction.falling("linear", 0.2, -0.1, 1.0), "term_1 = -0.1"),
        (lambda: friction.falling("linear", 0.2, 0.1, 0.0), "half_velocity_1_m_per_s = 0.0"),
        (lambda: friction.varying("track_distance", (10.0, 5.0), (friction.coulomb(0.3),) * 2), "ascending"),
        (lambda: friction.varying("track_distance", (10.0,), (friction.coulomb(0.3),) * 2), "one node per law"),
        (lambda: friction.varying("weather", (1.0,), (friction.coulomb(0.3),)), "varies_with = 'weather'"),
    ],
)
def test_bad_laws_name_key_and_value(build, message):
    """Each bad parameter is named with its value and what was expected."""
    with pytest.raises(ValueError, match=message):
        build()
