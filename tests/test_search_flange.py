"""The 3-D contact search in flange contact: S1002 wheels on UIC60 rails (1:40) in the tight curve of the
embedded scene ``curve-flange`` (R = 100 m, cant 150 mm, 50 km/h).

The S1002 flange root (EN 13715, section D: R13, standard_profiles) and the UIC60 gauge corner (EN 13674-1: R13)
are arcs of one radius: in flange-root contact the two profiles are conformal over a 0.45 rad arc, the distance h
along the wheel normal is nearly flat along it and the relative lateral curvature of the surfaces,
B = (K_w - K_r)/2, is zero to round-off (either sign). Three defects followed from that, all in the search
(contact._search_kernels.refine_point / search._refine, wheelset.compiled_search, providers.SearchProvider):

* where h was not convex the refinement stepped by 1e-3 times the gradient (~2e-5 m per iteration): on the
  flat arc it stopped after its 12 iterations 0.3 mm short of the minimum, not converged, at a point with B < 0;
* B was floored at 1e-6 1/m only, and Hertz's force at q = 0.13 mm is then 3.6e7 N (at B = 0.05: 0.4 MN):
  curve-flange on the search ended ``force-anomaly`` at t = 0.092 s (the Python search at the same time), and with
  the refinement fixed the compiled search still kicked the wheelset off the track at t = 0.135 s from a
  stage whose tracked contact point lay inside the arc (B = -0.18 1/m);
* the compiled search's starts (minima of the vertical gap along the axle) missed the deepest point of h inside
  the arc, where the vertical gap has no minimum: it reported the arc's end (q 7 um shallower, contact angle
  1.20 rad against 0.78) where the Python search (minima of h on an (alpha, y_d) grid) found the deepest point.

Now h convex along the rolling direction but not across it takes a descent step with a line search (concave along
it, between a wheel flat's edges, keeps the short step: the angle scan seeds both edges), the compiled scan also
starts from the minima of h where the vertical gap is negative, and the dynamics' search providers floor B at the
profile section's MIN_LATERAL_CURVATURE_1_PER_M (0.05 1/m: a conformal contact is not Hertzian; the floor keeps
the ellipse finite, as the tables do).

Verification of the run against two other methods of the same geometry: the default tables (TableProvider over
the profile section) and the profile section evaluated at every pose without tables (ProfileSectionProvider: the
2-D vertical gap of the lowest wheel points, no interpolation). Measured steady state (t 0.9-1.0 s; the tables at
t 1.5-2.0 s) of curve-flange:

=============  =========  =========  =========
quantity       search     section    tables
=============  =========  =========  =========
y, mm          -6.279     -6.235     -5.706
yaw, mrad      -4.55      -4.12      -3.55
N left, kN     96.80      96.53      96.89
N right, kN    84.79      84.78      84.61
Fy left, kN    26.37      27.03      26.19
Fy right, kN   23.21      22.89      22.22
Fx left, kN    -6.15      -5.54      -4.67
=============  =========  =========  =========

The search lies within 0.045 mm of the exact section; the default tables lie 0.53 mm from it: their roll grid
(2 mrad steps: 1.5 mm of vertical motion at a wheel) and their linear extrapolation in the centre height cannot
follow the approach across the conformal flange root (at the tables' own steady pose the section gives the left
wheel a gap of 9 um where the tables give an approach of 132 um). A table with a 0.1 mrad roll step
(lateral_range 0.01 m, step 0.1 mm) settles at -6.199 mm, yaw -4.78 mrad, Fx -6.32 kN. The longitudinal creep
forces and the yaw are ill-conditioned at the flange root: the rolling radius changes by R_y ~ 0.6 m per m of
contact-point shift, so a 0.1 mm shift of the contact point moves Fx by ~1 kN.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact import _search_kernels as kern
from rigid_dynamics.contact.hertz import hertz_force_from_approach
from rigid_dynamics.contact.search import WheelsetPose
from rigid_dynamics.kinematics import wheelset_rotation
from rigid_dynamics.wheelset import compiled_search as cs
from rigid_dynamics.wheelset.providers import MIN_LATERAL_CURVATURE_1_PER_M, ProfileSectionProvider
from rigid_dynamics.wheelset.simulate import build_provider, simulate
from wheelrail.scenes import load_scene

R13 = 0.013  # m, S1002 flange root (EN 13715 section D) and UIC60 gauge corner (EN 13674-1)
# The pose at which the old refinement stopped off the minimum: the state of the Python search's run of curve-flange
# at t = 0.091 s extrapolated one output step (the first step of that run that went to 2.5e7 N).
POSE = (1.277976414642136, -0.006342631482373633, -0.4602028328462104, -0.009009176923680725, 7.54273503739788e-4,
        2.7759919663658916)  # fmt: skip


def _scene(name, provider):
    scene = load_scene(name)
    return replace(scene, contact_provider=provider)


@pytest.fixture(scope="module")
def flange_search():
    return build_provider(_scene("curve-flange", "search"))


def _kernel_args(provider, pose):
    wheel, rail = provider.surfaces.fast["left"]
    rot = wheelset_rotation(pose[3], pose[4], pose[5])
    surf = kern.Surfaces(
        wheel.table_tuple, rail.table_tuple, wheel.irregularity_rows, rail.irregularity_rows, rail.lateral_map,
        np.array(wheel.y_range_m), np.array(rail.y_range_m),
    )  # fmt: skip
    return rot, np.array(pose[:3]), surf


def _compiled_patches(provider, pose):
    search = cs.search_args(provider, provider.options)
    cg = np.zeros((4, cs.N_GEO))
    state = np.zeros(14)
    state[:6] = pose
    failed = cs.search_geometry(state, search, True, cg)
    return cg, failed


def test_flange_root_and_gauge_corner_are_conformal_arcs(flange_search):
    """The cause: on the left (outer) side the wheel's flange root and the rail's gauge corner both have the
    curvature 1/13 mm (the published radii), so B of the surfaces vanishes along the arc."""
    wheel, rail = flange_search.surfaces.wheels["left"], flange_search.surfaces.rails["left"]
    y_d = np.linspace(-0.7150, -0.7125, 11)  # wheel lateral coordinate, contact angles 0.69-1.05 rad
    r, _, r_y, _, _, r_yy = wheel.evaluate(np.full_like(y_d, 0.5 * np.pi), y_d)
    np.testing.assert_allclose(r_yy / (1 + r_y**2) ** 1.5, 1 / R13, rtol=2e-3)
    y = np.linspace(-0.7230, -0.7180, 11)  # rail: the gauge corner arc at the same angles
    n, _, n_y, _, _, n_yy = rail.evaluate(np.zeros_like(y), y)
    np.testing.assert_allclose(n_yy / (1 + n_y**2) ** 1.5, 1 / R13, rtol=2e-3)
    assert np.ptp(np.arctan(np.abs(n_y))) > 0.4  # the arc spans 0.4 rad of contact angle there


def test_refinement_reaches_the_minimum_on_the_flat_flange_arc(flange_search):
    """At POSE h falls along the conformal arc to the flange flank: the search must converge to the minimum of h,
    which an exhaustive sampling finds independently (a 5 um x 5e-4 rad grid over the whole flange, then a
    0.1 um x 5e-6 rad grid around its best point). The old gradient fallback stopped at y_d = -0.71188 m
    (h = -1.3146e-4 m, not converged, B < 0), 0.3 mm and 5 um of approach short of the minimum."""
    pose = WheelsetPose(*POSE)
    result = flange_search.surfaces.search(pose, "left", {"field": False})
    assert result.status == "ok" and bool(np.all(result.candidates.converged))
    args = _kernel_args(flange_search, POSE)
    mid = 0.5 * np.pi - POSE[5]
    alphas, ys = mid + np.linspace(-0.05, 0.05, 201), np.arange(-0.74, -0.70, 5e-6)
    h = kern.distance_grid(alphas, ys, *args, 8)
    i, j = np.unravel_index(np.argmin(h), h.shape)
    alphas, ys = alphas[i] + np.linspace(-5e-4, 5e-4, 201), ys[j] + np.linspace(-1e-5, 1e-5, 201)
    h = kern.distance_grid(alphas, ys, *args, 8)
    i, j = np.unravel_index(np.argmin(h), h.shape)
    h_min, y_min = h[i, j], ys[j]
    assert h_min == pytest.approx(-1.3657e-4, abs=1e-8)  # the flank end of the arc (contact angle 1.21 rad)
    k = int(np.argmin(result.candidates.gap_m))
    # grid: h within A (5e-6)^2 + B (1e-7)^2 ~ 1e-11 m of its minimum; y_d within the fine spacing of the minimum
    assert result.candidates.gap_m[k] == pytest.approx(h_min, abs=1e-10)
    assert result.candidates.lateral_m[k] == pytest.approx(y_min, abs=5e-7)
    patch = result.patches[0]
    assert patch.curvature_lat_1_per_m > 10  # a genuine minimum: the wheel's flank against the R13 corner
    cg, failed = _compiled_patches(flange_search, POSE)
    assert failed == 0
    assert cg[0, 0] == pytest.approx(-h_min, abs=1e-10)
    assert cg[0, 10] == pytest.approx(y_min, abs=5e-7)


def test_contact_inside_the_conformal_arc_gets_the_section_floor(flange_search):
    """At this pose (POSE moved 0.2 mm out and 0.2 mrad in roll) the minimum of h lies inside the arc (y_d -0.7147,
    contact angle 0.78 rad): the surfaces' B is <= 0 there; the providers give the profile section's floor, and
    Hertz's force stays below the run's force limit (at the old floor 1e-6 1/m it exceeds it 40 times). The
    compiled search finds the same point (its vertical-gap scan alone gave the arc's flank end: y_d -0.7117,
    q 7 um shallower, B 6.3)."""
    pose = np.array(POSE)
    pose[1] -= 2e-4
    pose[4] -= 2e-4
    patches = flange_search.patches(pose[:3], pose[3], pose[4], pose[5])
    assert patches.side[0] == 0 and -0.7150 < patches.wheel_lateral_m[0] < -0.7125
    assert patches.geometries[0].curvature_lat_1_per_m <= 1e-6  # B of the surfaces: <= 0, clipped by the search
    assert patches.curvature_lat_1_per_m[0] == MIN_LATERAL_CURVATURE_1_PER_M
    cg, _ = _compiled_patches(flange_search, pose)
    assert cg[0, 8] == MIN_LATERAL_CURVATURE_1_PER_M
    assert cg[0, 0] == pytest.approx(patches.approach_m[0], abs=1e-11)
    assert cg[0, 10] == pytest.approx(patches.wheel_lateral_m[0], abs=1e-7)
    scene = _scene("curve-flange", "search")
    limit = scene.integrator.max_force_factor * scene.static_wheel_load_N
    material = {"shear_modulus_Pa": scene.material.shear_modulus_Pa, "poisson_ratio": scene.material.poisson_ratio}
    a, q = np.array([patches.curvature_long_1_per_m[0]]), np.array([patches.approach_m[0]])
    assert hertz_force_from_approach(a, np.array([MIN_LATERAL_CURVATURE_1_PER_M]), q, **material)[0] < limit
    assert hertz_force_from_approach(a, np.array([1e-6]), q, **material)[0] > 10 * limit


def _steady(result, start_s, end_s):
    """Means over [start_s, end_s] of y, yaw (m, rad), the per-wheel normal, longitudinal and lateral contact
    forces (N; (2,) each, left and right) and the left wheel's contact angle (rad)."""
    m = (result.t >= start_s) & (result.t <= end_s)
    out = {"y": result.states[m, 1].mean(), "yaw": result.states[m, 3].mean()}
    for key, name in (("normal_force_N", "N"), ("creep_force_long_N", "Fx"), ("creep_force_lat_N", "Fy")):
        out[name] = np.nan_to_num(result.patches[key][m]).sum(axis=2).mean(axis=0)
    loaded = np.nan_to_num(result.patches["normal_force_N"][m, 0, 0]) > 0  # the left wheel's first patch
    out["angle_left"] = result.patches["contact_angle_rad"][m, 0, 0][loaded].mean()
    return out


def test_curve_flange_on_the_search_agrees_with_the_section_and_the_tables():
    """curve-flange (2 s, compiled) on the search and on the default tables; the profile section without tables
    (Python loop, 0.5 s: y and the forces settle within 0.4 s, the yaw within ~1 s). Bounds from the measured
    differences (module docstring): search - section 0.045 mm, 0.3 kN (N), 0.7 kN (Fy, Fx), 3-D normal distance
    against the 2-D vertical gap on a conformal arc, where the two put the contact at different points of the
    arc; search - tables 0.57 mm, 0.19 kN (N), 1.0 kN (Fy), 1.5 kN (Fx), the tables' own error against the
    section being 0.53 mm, 0.36, 0.84 and 0.87 kN. Bounds: about 1.5 times the measured."""
    search = simulate(_scene("curve-flange", "search"))
    tables = simulate(_scene("curve-flange", "tables"))
    assert search.status == "ok", search.message
    # the tables run's one statement above force_tolerance may be its geometry companion (discretisation.
    # geometry_error: forces on the tables and on the search at the same recorded states): at the flange root the
    # same-state difference (about 0.3 of the static load) far overstates the two runs' difference checked below
    # (about 1 % of it), so the run ends "warning" naming it; every other statement must pass
    geometry_only = tables.status == "warning" and tables.message.count("exceeds") == 1
    assert tables.status == "ok" or (geometry_only and "geometry tables error estimate" in tables.message), (
        tables.message
    )
    assert search.summary()["compiled"] is True
    s, t = _steady(search, 1.5, 2.0), _steady(tables, 1.5, 2.0)
    assert abs(s["y"] - t["y"]) < 0.8e-3
    assert np.max(np.abs(s["N"] - t["N"])) < 400.0
    assert np.max(np.abs(s["Fy"] - t["Fy"])) < 1.5e3
    assert np.max(np.abs(s["Fx"] - t["Fx"])) < 2.2e3
    assert s["angle_left"] > search.scene.track.flange_contact_angle_rad  # on the flange root, as the tables
    assert abs(s["angle_left"] - t["angle_left"]) < 0.03
    scene = replace(_scene("curve-flange", "tables"), duration_s=0.5)
    section = simulate(scene, provider=ProfileSectionProvider(scene.wheelset, scene.track), compiled=False)
    assert section.status == "ok", section.message
    s, r = _steady(search, 0.4, 0.5), _steady(section, 0.4, 0.5)
    assert abs(s["y"] - r["y"]) < 0.08e-3
    assert np.max(np.abs(s["N"] - r["N"])) < 450.0
    assert np.max(np.abs(s["Fy"] - r["Fy"])) < 1.0e3
    assert np.max(np.abs(s["Fx"] - r["Fx"])) < 1.1e3


def test_curve_on_the_search_agrees_with_the_tables():
    """curve (600 m, tread contact, 6 s): the search and the tables settle 0.065 mm apart (y -3.926 / -3.861 mm),
    normal forces 28 N, lateral creep forces 92 N, longitudinal 11 N apart; the tables' approach of the outer wheel is
    1.6 um above the search's and the section's (which agree to 0.04 um) at the same pose, and the profile section
    without tables (Python loop, 3 s) settles between the two (-3.884 mm at 2.5-3 s). Bounds ~1.5 times those."""
    search = simulate(_scene("curve", "search"))
    tables = simulate(_scene("curve", "tables"))
    assert search.status == tables.status == "ok", (search.message, tables.message)
    s, t = _steady(search, 5.0, 6.0), _steady(tables, 5.0, 6.0)
    assert abs(s["y"] - t["y"]) < 0.1e-3
    assert np.max(np.abs(s["N"] - t["N"])) < 60.0
    assert np.max(np.abs(s["Fy"] - t["Fy"])) < 150.0
    assert np.max(np.abs(s["Fx"] - t["Fx"])) < 20.0
