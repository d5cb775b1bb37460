"""The compiled gap sampler (contact/_gap_kernels.py), the one sampling code of the static wheelset case and the
dynamics loop.

Regression tests (two code paths of ours): the compiled kernel against search._gap_at_python (numpy, the surfaces'
own ``evaluate``) on the same tabulated surfaces, at the flange patch of ``curve-flange`` (S1002 on UIC60 in the
R = 100 m curve: flange-root contact on the conformal R13 arcs) and at a tread patch of a polygonal wheel; and the
compiled fitted box and ellipticity residual against search._fitted_field and search.ellipticity_error.
"""

from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact import _gap_kernels as gk
from rigid_dynamics.contact import search as se
from rigid_dynamics.contact.search import WheelsetPose
from rigid_dynamics.wheelset.simulate import build_provider
from wheelrail.scenes import load_scene

# the flange-contact pose of tests/test_search_flange.py (curve-flange, left wheel on its flange root)
POSE = (1.277976414642136, -0.006342631482373633, -0.4602028328462104, -0.009009176923680725, 7.54273503739788e-4,
        2.7759919663658916)  # fmt: skip


def _side(scene_name, pose, side):
    provider = build_provider(replace(load_scene(scene_name), contact_provider="search"))
    wheel, rail = provider.surfaces.fast[side]
    assert isinstance(wheel, se.TabulatedWheel) and isinstance(rail, se.TabulatedRail)
    p = WheelsetPose(*pose)
    result = se.search_side(
        wheel, rail, p, side, wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m
    )
    geo = se._SideGeometry(wheel, rail, p, side, tuple(wheel.y_range_m), tuple(rail.y_range_m))
    return result, geo


@pytest.fixture(scope="module")
def flange():
    return _side("curve-flange", POSE, "left")


def _deepest_flange(result):
    angles = [pt.contact_angle_rad for pt in result.patches]
    k = int(np.argmax(angles))
    return k, result.patches[k]


def test_regression_compiled_gap_equals_python_on_the_flange_patch(flange):
    """Regression: on the flange patch (contact angle > 0.5 rad), over a grid twice the sampled field's box, the
    compiled gap equals the numpy path to 1e-12 m (both solve the same equations; round-off and Newton's last
    step differ), and +inf where the numpy path gives +inf. The numpy path runs 40 Newton iterations: with 8 (from
    the patch's parameters) its wheel root at the doubled box's far corners is 3e-8 m short of convergence, which
    the compiled sampler (chained from neighbours, iterated to a 1e-9 m step) reaches.
    """
    result, geo = flange
    k, patch = _deepest_flange(result)
    assert patch.contact_angle_rad > 0.5
    alpha0, y0 = result.wheel_parameters[k]
    u = patch.undeformed
    xs = np.linspace(2 * u.x_m[0], 2 * u.x_m[-1], 41)
    ys = np.linspace(2 * u.y_m[0], 2 * u.y_m[-1], 37)
    gx, gy = np.meshgrid(xs, ys)
    compiled = se._gap_at(geo, alpha0, y0, patch.point_m, patch.frame, gx, gy, 8)
    python = se._gap_at_python(geo, alpha0, y0, patch.point_m, patch.frame, gx, gy, 40)
    finite = np.isfinite(python)
    assert finite.mean() > 0.5  # off the flange tip the normal leaves the wheel profile
    np.testing.assert_array_equal(np.isfinite(compiled), finite)
    assert np.max(np.abs(compiled[finite] - python[finite])) < 1e-12
    assert np.min(python) < 0 < np.max(python[finite])


def test_regression_compiled_gap_on_a_polygonal_wheel():
    """Regression: the compiled gap with a closed-form wheel irregularity (the polygonal-wheel scene's harmonic
    out-of-roundness) equals the numpy path to 1e-12 m at its tread patch.
    """
    scene = load_scene("polygonal-wheel")
    provider = build_provider(replace(scene, contact_provider="search"))
    z = -provider.r0 + 5e-4  # 0.1 mm into the rails
    result, geo = _side("polygonal-wheel", (0.0, 0.0, z, 0.0, 0.0, 0.3), "right")
    assert result.patches and geo.wheel.irregularity_rows.shape[0] > 0
    patch = result.patches[0]
    alpha0, y0 = result.wheel_parameters[0]
    gx, gy = np.meshgrid(np.linspace(-0.012, 0.012, 31), np.linspace(-0.01, 0.01, 29))
    compiled = se._gap_at(geo, alpha0, y0, patch.point_m, patch.frame, gx, gy, 8)
    python = se._gap_at_python(geo, alpha0, y0, patch.point_m, patch.frame, gx, gy, 8)
    finite = np.isfinite(python)
    np.testing.assert_array_equal(np.isfinite(compiled), finite)
    assert np.max(np.abs(compiled[finite] - python[finite])) < 1e-12


def test_regression_fitted_box_and_residual_equal_the_search(flange):
    """Regression: the compiled fitted box (_gap_kernels.fitted_grid) at search._patch's start sizes and
    31 points samples the same field as search._fitted_field (the static case's undeformed distance) to 1e-12 m,
    and the compiled residual equals search.ellipticity_error to 1e-12 relative.
    """
    result, geo = flange
    k, patch = _deepest_flange(result)
    alpha0, y0 = result.wheel_parameters[k]
    u = patch.undeformed
    surf, rec = se._gap_records(geo, alpha0, y0, patch.point_m, patch.frame, 8)
    q, a, b = patch.approach_m, patch.curvature_long_1_per_m, patch.curvature_lat_1_per_m
    fit = gk.GridFit(1.6 * np.sqrt(q / a), 1.6 * np.sqrt(q / b), 0.25, 1e-3)
    xs, ys, gap = np.empty(31), np.empty(31), np.empty((31, 31))
    gk.fitted_grid(surf, rec, fit, xs, ys, gap, np.empty((31, gk.COLUMN_SCRATCH)))
    np.testing.assert_allclose(xs, u.x_m, rtol=0, atol=1e-15)
    np.testing.assert_allclose(ys, u.y_m, rtol=0, atol=1e-15)
    finite = np.isfinite(u.distance_m)
    assert np.max(np.abs(gap[finite] - u.distance_m[finite])) < 1e-12
    expected = se.ellipticity_error(u, a, b, patch.ellipse_angle_rad, q)
    got = gk.ellipticity_residual(xs, ys, gap, (a, b, patch.ellipse_angle_rad), q)
    assert got == pytest.approx(expected, rel=1e-9)


def _exact_reference(surf, rec, box, n):
    """The exact sampling: every point solved from the patch's parameters alone (the rail's Newton from t = 0, the
    wheel's on (alpha, y_d, s)), with 40 Newton iterations (8, the loop's, leave the wheel's far corners of a
    doubled box unconverged: 6e-8 m on the flange patch).
    """
    xs, ys, gap = np.empty(n), np.empty(n), np.empty((n, n))
    gk.exact_grid(surf, rec._replace(iterations=40), box, xs, ys, gap)
    return gap


SAMPLER_CASES = (
    ("curve-flange", POSE, "left"),  # flange flank, conformal R13 arcs
    ("curve-flange", POSE, "right"),  # tread
    ("polygonal-wheel", (0.0, 0.002, None, 0.004, 0.001, 1.0), "right"),  # harmonic rows: the column series
    ("wheel-flat", (0.0, 0.001, None, 0.003, 0.0, 0.4351), "right"),  # rounded flat: rows at each iterate
    ("corrugation", (0.0, 0.001, None, 0.003, 0.0, 0.3), "right"),  # rail rows: Newton's method per point
)


@pytest.mark.parametrize("scene_name, pose, side", SAMPLER_CASES)
@pytest.mark.parametrize("scale", [1.0, 2.0])
def test_row_sampler_equals_the_exact_newton_sampling(scene_name, pose, side, scale):
    """The sampler (sample_grid: per lateral strip three anchors chained from the strip before, the other points'
    wheel roots by Newton's method from the quadratic through the anchors, the rail's moved along the strip)
    against the exact Newton sampling (every point solved from the patch's parameters) on the patch's fitted box
    and on the box doubled (far from the overlap, where the starts are poorest), 24 x 24 points: the same points
    are off the surfaces (+-inf) and the finite gaps agree to 1e-12 m (the sampler's roots are Newton's to a
    step of 1e-9 m; measured: < 1e-13 m). Its error is round-off: it is the exact sampling, faster.
    """
    if pose[2] is None:
        provider = build_provider(replace(load_scene(scene_name), contact_provider="search"))
        pose = (pose[0], pose[1], -provider.r0 + 5e-4, *pose[3:])
    result, geo = _side(scene_name, pose, side)
    assert result.patches
    patch = result.patches[0]
    alpha0, y0 = result.wheel_parameters[0]
    surf, rec = se._gap_records(geo, alpha0, y0, patch.point_m, patch.frame, 8)
    u = patch.undeformed
    box = (scale * u.x_m[0], scale * u.x_m[-1], scale * u.y_m[0], scale * u.y_m[-1])
    n = 24
    xs, ys, gap = np.empty(n), np.empty(n), np.empty((n, n))
    gk.sample_grid(surf, rec, box, xs, ys, gap, np.empty((n, gk.COLUMN_SCRATCH)))
    exact = _exact_reference(surf, rec, box, n)
    np.testing.assert_array_equal(gap[~np.isfinite(exact)], exact[~np.isfinite(exact)])
    finite = np.isfinite(exact)
    assert finite.mean() > 0.5 and np.min(exact[finite]) < 0.0
    assert np.max(np.abs(gap[finite] - exact[finite])) < 1e-12
    points = np.empty(n * n)
    gx, gy = np.meshgrid(xs, ys)
    gk.gap_points(gx.ravel(), gy.ravel(), surf, rec, points)  # the static case's point sampler: the same roots
    assert np.max(np.abs(points.reshape(n, n)[finite] - exact[finite])) < 1e-12
