"""The 3-D contact search (rigid_dynamics.contact.search) as the dynamics' contact provider.

Independent references: the exact line-circle contact of the analytic ConicalProvider (a second method for the
same cone on circular rail heads) and Klingel's wavelength 2 pi sqrt(r0 e0 / lambda) for a run whose every
contact patch comes from the search.
"""

import math

import numpy as np
import pytest

from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    Irregularities,
    TrackGeometry,
    WheelsetParameters,
)
from rigid_dynamics.wheelset.providers import ConicalProvider, SearchProvider
from rigid_dynamics.wheelset.simulate import simulate

TRACK = TrackGeometry(conicity=0.05, rail_head_radius_m=0.05)


@pytest.mark.parametrize(("shift", "yaw", "roll"), [(0.0, 0.0, 0.0), (0.002, 0.002, 2e-4), (-0.003, -0.001, -3e-4)])
def test_search_matches_analytic_cone(shift, yaw, roll):
    ws = WheelsetParameters()
    centre = np.array([0.3, shift, -ws.nominal_radius_m + 5e-4])
    exact = ConicalProvider(ws, TRACK).patches(centre, yaw, roll, 0.4)
    found = SearchProvider(ws, TRACK).patches(centre, yaw, roll, 0.4)
    np.testing.assert_array_equal(found.side, [0, 1])
    # the analytic provider neglects the O(psi lambda) shift of the cone's contact point off its lowest line
    np.testing.assert_allclose(found.approach_m, exact.approach_m, rtol=0, atol=1e-8)
    np.testing.assert_allclose(found.rolling_radius_m, exact.rolling_radius_m, rtol=0, atol=2e-6)
    np.testing.assert_allclose(found.normal, exact.normal, rtol=0, atol=1e-5)
    np.testing.assert_allclose(found.curvature_lat_1_per_m, exact.curvature_lat_1_per_m, rtol=1e-4)


def test_search_sees_the_polygon():
    """A 3rd-order polygon with its crest at the lowest point adds A cos(gamma) to the (normal) approach."""
    ws = WheelsetParameters()
    centre = np.array([0.0, 0.0, -ws.nominal_radius_m + 1e-4])
    ideal = SearchProvider(ws, TRACK).patches(centre, 0.0, 0.0, 0.5 * math.pi).approach_m
    polygon = Irregularities(polygon_order=3, polygon_amplitude_m=3e-4)
    rough = SearchProvider(ws, TRACK, polygon).patches(centre, 0.0, 0.0, 0.5 * math.pi).approach_m
    np.testing.assert_allclose(rough - ideal, 3e-4 / math.sqrt(1 + 0.05**2), atol=1e-9)


def _klingel_scene(duration_s):
    return DynamicsScene(
        track=TRACK,
        speed_m_per_s=30.0,
        duration_s=duration_s,
        contact_model="linear",
        contact_provider="search",
        initial=InitialConditions(lateral_displacement_m=0.003),
        integrator=IntegratorSettings(method="RK4", fixed_step_s=1.5e-3, output_step_s=3e-3),
    )


def test_klingel_through_the_search():
    """Klingel's wavelength 2 pi sqrt(r0 e / lambda) (closed form) through the 3-D search, which on the ideal cone
    runs compiled (its surfaces tabulated). The step, 1.5 ms, is 0.92 of RK4's stability limit here (1.63 ms; 2 ms
    derails at 0.05 s, the run says so). Measured: 16.5244 m, +0.12 %, in under a second (the Python search with its
    profile-only option, which keeps the contact on the wheel's lowest line, gave 16.5441 m, +0.24 %, in 46-155 s of
    the suite's runs)."""
    result = simulate(_klingel_scene(1.2))
    assert result.success, result.message
    assert result.provider == "search" and result.summary()["compiled"] is True
    klingel = 2 * math.pi * math.sqrt(0.46 * 0.75 / 0.05)
    measured = result.summary()["dominant_lateral_wavelength_m"]
    print(f"Klingel {klingel:.4f} m, through the 3-D search {measured:.4f} m ({measured / klingel - 1:+.3%})")
    assert measured == pytest.approx(klingel, rel=0.01)


def test_the_compiled_search_on_the_cone_equals_the_python_search():
    """Regression (our compiled path against our Python path, same geometry): the first 0.06 s of the Klingel run.
    The compiled search locates the contact on Hermite tables of the cone and the circular rail head; the Python
    search on the closed forms. Measured: 3e-9 m in the lateral displacement, 0.02 N of 9e4 N in the forces."""
    scene = _klingel_scene(0.06)
    fast, slow = simulate(scene, compiled=True), simulate(scene, compiled=False)
    assert fast.status == slow.status == "ok", (fast.message, slow.message)
    assert fast.summary()["compiled"] is True and slow.summary()["compiled"] is False
    np.testing.assert_allclose(fast.states[:, :6], slow.states[:, :6], rtol=0, atol=1e-7)
    np.testing.assert_allclose(fast.contact_force_N, slow.contact_force_N, rtol=0, atol=1.0)


def test_profile_section_agrees_with_search_on_s1002_uic60():
    """Second method on real profiles: the 2-D profile section (tables) against the 3-D search, S1002/UIC60 1:40.

    Same patches in contact per side (a connected overlap is one patch for both) and the same approach, rolling
    radius and contact angle of the deepest patch.
    """
    from rigid_dynamics.wheelset.providers import ProfileSectionProvider, build_surfaces

    ws = WheelsetParameters()
    track = TrackGeometry(wheel_profile="S1002", rail_profile="UIC60", rail_inclination_rad=0.025)
    surfaces = build_surfaces(ws, track)
    section = ProfileSectionProvider(ws, track, surfaces=surfaces)
    search = SearchProvider(ws, track, surfaces=surfaces)
    for shift, z in ((0.0, -0.4598), (0.0, -0.4597), (0.001, -0.4597), (0.003, -0.4597), (-0.002, -0.4597)):
        centre = np.array([0.0, shift, z])
        a, b = section.patches(centre), search.patches(centre, 0.0, 0.0, 0.0)
        for side in (0, 1):
            in_a = (a.side == side) & (a.approach_m > 0)
            in_b = (b.side == side) & (b.approach_m > 0)
            assert in_a.sum() == in_b.sum(), (shift, z, side)
            if in_a.any():
                ka = np.flatnonzero(in_a)[np.argmax(a.approach_m[in_a])]
                kb = np.flatnonzero(in_b)[np.argmax(b.approach_m[in_b])]
                assert a.approach_m[ka] == pytest.approx(b.approach_m[kb], rel=1e-3, abs=5e-8)
                assert a.rolling_radius_m[ka] == pytest.approx(b.rolling_radius_m[kb], abs=2e-5)
                assert a.contact_angle_rad[ka] == pytest.approx(b.contact_angle_rad[kb], abs=5e-4)


def test_search_reuse_first_order():
    """Reuse of the last search with the rigid-body correction (profiles module docstring) against a fresh search
    at the moved pose (the independent reference): a small pose change, including spin on a polygonal wheel, is
    captured to second order; an identical pose returns the last patches themselves."""
    ws = WheelsetParameters()
    polygon = Irregularities(polygon_order=3, polygon_amplitude_m=3e-4)
    fresh = SearchProvider(ws, TRACK, polygon)
    reusing = SearchProvider(ws, TRACK, surfaces=fresh.surfaces, reuse_m=1e-4)
    centre = np.array([0.1, 0.001, -ws.nominal_radius_m + 5e-4])
    pose = (0.001, 1e-4, 0.3)
    first = reusing.patches(centre, *pose)
    assert np.all(first.approach_m > 1e-5)
    assert reusing.patches(centre, *pose) is first
    errors = []
    for delta in (2e-5, 1e-5, 5e-6):
        moved = centre + np.array([delta, delta, delta])
        turned = (pose[0] + delta, pose[1] + 0.2 * delta, pose[2] + 2 * delta)
        reused = reusing.patches(moved, *turned)
        exact = fresh.patches(moved, *turned)
        change = np.max(np.abs(exact.approach_m - first.approach_m))
        error = np.max(np.abs(reused.approach_m - exact.approach_m))
        assert change > 0.5 * delta
        errors.append(error)
        np.testing.assert_allclose(reused.point_m, exact.point_m, rtol=0, atol=3 * delta)
    assert reusing.reused == 4 and reusing.searches == 2
    # second order: the error falls at least ~3.5x per halving (search tolerance 1e-9 m as the floor)
    assert errors[1] < max(errors[0] / 3.5, 3e-9) and errors[2] < max(errors[1] / 3.5, 3e-9)
    assert errors[0] < 1e-2 * 2e-5


def test_search_reuse_bad_input():
    with pytest.raises(ValueError, match="reuse_m = -1.0: expected a finite number >= 0"):
        SearchProvider(WheelsetParameters(), TRACK, reuse_m=-1.0)


def test_the_shipped_conical_scene_runs_on_the_search():
    """The analytic cone on the 3-D search from a scene file (`--set contact_provider="search"`; the scene check
    once refused it, from before the search served the cone). Reference: the same scene on the analytic conical
    provider (exact line-circle contact, scipy RK45), over the first 0.5 s. Measured: the search's lateral
    displacement within 4.5e-6 m of it (0.15 % of the 3 mm amplitude; the cone's own tables 6e-8 m), its normal
    forces within 8e-6 of their peak (the tables 2.4e-5)."""
    from wheelrail.overrides import load_scene_with

    runs = {}
    for provider, extra in (("search", []), ("conical", ['integrator.method="RK45"'])):
        scene, *_ = load_scene_with("hunting-conical", [f'contact_provider="{provider}"', "duration_s=0.5", *extra])
        runs[provider] = simulate(scene)
    search, exact = runs["search"], runs["conical"]
    assert search.status == exact.status == "ok", (search.message, exact.message)
    assert search.provider == "search" and search.summary()["compiled"] is True
    np.testing.assert_allclose(search.t, exact.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(search.states[:, 1], exact.states[:, 1], rtol=0, atol=1e-5)
    peak = exact.wheel_normal_force_N.max()
    assert np.abs(search.wheel_normal_force_N - exact.wheel_normal_force_N).max() < 1e-4 * peak
