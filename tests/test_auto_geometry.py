"""``auto`` in the loop against the patches' real geometry (discretisation.auto_geometry): auto decides on Hertz's
ellipse, and with the 3-D search and ``patch_geometry = "sampled"`` its recorded evaluations sample the gap, so a
run states how many patches it served on the ellipse beyond the ellipticity its rungs were measured on, and ends
"warning" then. polygonal-wheel's S1002/UIC60 treads are not elliptic (search.ellipticity_error: about 2 for the
S1002 tread on UIC60 at zero shift), beyond every ellipse rung's measured box (0.56 at 10 %, 0 for linear theory).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

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


def test_sampled_run_records_the_gap_beside_the_ellipse_and_warns(runs):
    result = runs["sampled"]
    p = result.patches
    rung = p["auto_rung"]
    served = np.isfinite(rung) & (np.nan_to_num(p["normal_force_N"]) > 0) & (rung < AUTO_BEM)
    assert served.any()
    residual = p["ellipticity_residual"][served]
    assert np.all(np.isfinite(residual)) and np.all(residual > 0)
    geometry = result.summary()["auto"]["geometry"]
    assert geometry["seen"] and geometry["checked"] == int(served.sum())
    # each rung's box at the run's level, from the thresholds file (an independent reading of it)
    _, boxes = auto_boxes(0.1, (result.scene.fastsim_elements_per_strip, result.scene.fastsim_strips))
    limits = np.array([np.inf if box is None else box["ellipticity_residual"] for _, box in boxes])
    outside = residual > limits[rung[served].astype(int)]
    assert geometry["outside_box"] == int(outside.sum()) > 0
    assert geometry["largest_residual"] == pytest.approx(float(residual.max()))
    assert result.status == "warning"
    assert "beyond the rung's measured box" in result.message and "not known" in result.message


def test_the_ellipse_choice_samples_nothing_and_says_so(runs):
    """patch_geometry "ellipse" (multi-Hertzian, a named choice): nothing sampled, so nothing is judged, and the
    summary says the geometry was not seen; the compiled rungs' forces are the same as in the sampled run (sampling on
    the recorded evaluations does not change the trajectory: regression)."""
    result = runs["ellipse"]
    assert result.status == "ok", result.message
    geometry = result.summary()["auto"]["geometry"]
    assert not geometry["seen"] and geometry["checked"] == 0 and geometry["outside_box"] == 0
    assert np.all(np.isnan(result.patches["ellipticity_residual"]))
    np.testing.assert_array_equal(result.states, runs["sampled"].states)


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
