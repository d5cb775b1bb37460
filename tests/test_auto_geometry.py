"""``auto`` in the loop decides on the patches' real geometry: with the 3-D search and ``patch_geometry =
"sampled"`` the compiled right-hand side samples each candidate's gap (compiled_patch.sample_candidates) and auto's
geometric features (ellipticity residual, curvature change, second-patch nearness: contact.auto's definitions) enter
its choice, so a patch whose real gap lies beyond a rung's measured box is not served on Hertz's ellipse by that rung.
polygonal-wheel's S1002/UIC60 treads are not elliptic (search.ellipticity_error: about 2 for the S1002 tread on UIC60
at zero shift), beyond every ellipse rung's measured box (0.55 at 10 %, 0 for linear theory), so they go to the BEM.
``discretisation.auto_geometry`` stays as the run's check that no served patch lies outside its box.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact import _gap_kernels as gk
from rigid_dynamics.contact.auto import FEATURES, _local_curvature_change, _second_patch_nearness
from rigid_dynamics.wheelset import simulate
from rigid_dynamics.wheelset.compiled_laws import auto_boxes
from rigid_dynamics.wheelset.discretisation import auto_geometry_check
from rigid_dynamics.wheelset.layout import AUTO_BEM
from wheelrail.scenes import load_scene, resolve_scene_path


def _run(geometry: str):
    scene = load_scene(resolve_scene_path("polygonal-wheel"))
    scene = replace(scene, contact_model="auto", contact_tolerance=0.1, duration_s=0.004, settling_distance_m=0.0,
                    patch_geometry=geometry)  # fmt: skip
    return simulate(scene)


@pytest.fixture(scope="module")
def runs():
    return {geometry: _run(geometry) for geometry in ("sampled", "ellipse")}


def test_sampled_run_decides_on_the_gap_and_serves_no_patch_beyond_its_box(runs):
    result = runs["sampled"]
    assert result.status in ("ok", "warning"), result.message
    assert "beyond the rung's measured box" not in result.message
    p = result.patches
    rung = p["auto_rung"]
    touching = np.isfinite(rung) & (np.nan_to_num(p["normal_force_N"]) > 0)
    assert touching.any()
    # the decision saw the sampled gap: its ellipticity residual is a feature, finite and beyond the quadric's 0
    decided = p["auto_ellipticity_residual"][touching]
    assert np.all(np.isfinite(decided)) and np.all(decided > 0)
    # each rung's box at the run's level, from the thresholds file (an independent reading of it): a patch served on
    # the ellipse has every feature inside its rung's box; the others went up the ladder (BEM or its reuse)
    _, boxes = auto_boxes(0.1, (result.scene.fastsim_elements_per_strip, result.scene.fastsim_strips))
    for k in np.argwhere(touching):
        r = int(rung[tuple(k)])
        if r >= AUTO_BEM:
            continue
        box = boxes[r][1]
        for name in FEATURES:
            assert p[f"auto_{name}"][tuple(k)] <= box[name], (name, r)
    bem_box = max(box["ellipticity_residual"] for _, box in boxes if box is not None)
    beyond = touching & (p["auto_ellipticity_residual"] > bem_box)
    assert beyond.any() and np.all(rung[beyond] >= AUTO_BEM)
    geometry = result.summary()["auto"]["geometry"]
    assert geometry["outside_box"] == 0


def test_the_ellipse_choice_samples_nothing_and_says_so(runs):
    """patch_geometry "ellipse" (multi-Hertzian, a named choice): nothing sampled, the geometric features are 0 and the
    summary says the geometry was not seen; with the treads' real gap seen, the sampled run sends more patches up the
    ladder than the ellipse run does."""
    result = runs["ellipse"]
    assert result.status == "ok", result.message
    geometry = result.summary()["auto"]["geometry"]
    assert not geometry["seen"] and geometry["checked"] == 0 and geometry["outside_box"] == 0
    assert np.all(np.isnan(result.patches["ellipticity_residual"]))
    p = result.patches
    touching = np.isfinite(p["auto_rung"]) & (np.nan_to_num(p["normal_force_N"]) > 0)
    for name in ("ellipticity_residual", "curvature_change", "second_patch_nearness"):
        assert np.all(p[f"auto_{name}"][touching] == 0.0)

    def share_up(r):
        q = r.patches
        t = np.isfinite(q["auto_rung"]) & (np.nan_to_num(q["normal_force_N"]) > 0)
        return float(np.mean(q["auto_rung"][t] >= AUTO_BEM))

    assert share_up(runs["sampled"]) > share_up(result)


def test_compiled_geometric_features_equal_autos_definitions():
    """Regression test (two implementations of one definition): the loop's curvature change and second-patch
    nearness (_gap_kernels, on the sampled grid) equal contact.auto's on random gaps with several overlap regions,
    missing points (inf) and NaN."""
    rng = np.random.default_rng(1)
    several = 0
    for trial in range(200):
        nx, ny = rng.integers(3, 30, 2)
        xs, ys = np.linspace(-0.01, 0.01, nx), np.linspace(-0.008, 0.012, ny)
        x, y = np.meshgrid(xs, ys)
        gap = 2.0 * x**2 + rng.uniform(0.5, 20.0) * y**2 - 1e-5 + 1e-4 * np.sin(rng.uniform(100.0, 900.0) * y)
        gap += rng.normal(0.0, 3e-6, x.shape)
        if trial % 3 == 0:
            gap[rng.random(gap.shape) < 0.05] = np.inf
        if trial % 5 == 0:
            gap[rng.random(gap.shape) < 0.05] = np.nan
        with np.errstate(invalid="ignore"):
            change = _local_curvature_change(gap, xs, ys, 2.0, 5.0)
        assert gk.curvature_change(xs, ys, gap, 2.0, 5.0) == pytest.approx(change, rel=1e-12, abs=0.0)
        near = _second_patch_nearness(gap, ys)
        assert gk.second_patch_nearness(ys, gap) == pytest.approx(near, rel=1e-12, abs=0.0)
        several += near > 0
    assert several > 10


def test_the_check_leaves_other_statuses_and_clean_runs_alone():
    clean = {"served_on_ellipse": 4, "seen": True, "checked": 4, "outside_box": 0, "largest_residual": 0.1}
    assert auto_geometry_check("ok", "reached t = 1 s", clean) == ("ok", "reached t = 1 s")
    assert auto_geometry_check("ok", "reached t = 1 s", None) == ("ok", "reached t = 1 s")
    outside = {**clean, "outside_box": 3, "largest_outside": 1.5, "largest_outside_t_s": 0.25}
    assert auto_geometry_check("step-unstable", "m", outside) == ("step-unstable", "m")
    status, message = auto_geometry_check("ok", "reached t = 1 s", outside)
    assert status == "warning" and "3 of 4 recorded patches" in message and "1.5 at t = 0.25 s" in message
    # a run already warned (e.g. for its BEM grid) names this too: one warning does not hide another
    status, message = auto_geometry_check("warning", "reached t = 1 s; BEM grid-error estimate ...", outside)
    assert status == "warning" and "BEM grid-error estimate" in message and "3 of 4 recorded patches" in message


def test_the_demo_offers_the_scene_keys_patch_geometries():
    from rigid_dynamics.wheelset.parameters import PATCH_GEOMETRIES
    from wheelrail import comparison_commands

    assert comparison_commands.PATCH_GEOMETRIES == PATCH_GEOMETRIES
    assert comparison_commands.DEMO_PATCH_GEOMETRY in PATCH_GEOMETRIES
