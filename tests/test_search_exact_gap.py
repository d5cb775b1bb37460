"""The 3-D search's sampled gap is evaluated exactly at a solver's element centres (no bilinear interpolation).

Cause of the demo's grid stripes (issue: "BEM 1147 MPa" on a one-row line of peak pressure): the search sampled the
undeformed distance on a 31 x 31 grid and the BEM interpolated it bilinearly. A chord lies above a convex gap, so
the interpolated gap has dimples on the grid's node lines: the pressure peaked there, in stripes whose peak grew
with the BEM's refinement (1013 / 1117 / 1272 / 1335 MPa at 32 / 64 / 96 / 128 elements on the demo's patch). With
the gap evaluated from the surfaces at every element centre the max pressure converges (941 / 967 / 970 / 971 MPa).
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact.search import WheelsetPose


@pytest.fixture(scope="module")
def tread_patch():
    """S1002 on UIC60 1:40 at the A-2.2 centred pose: the right wheel's tread patch (non-elliptic: the S1002 tread
    spans several profile arcs), with the sampled undeformed distance."""
    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import WheelsetCase

    case = WheelsetCase("MBench_S1002_v3", "MBench_UIC60_v3", rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4)
    track = build_track(case)
    got = track.search(WheelsetPose(y_m=0.0, z_m=-0.45980), "right", {"field": True})
    return max(got.patches, key=lambda p: p.approach_m)


def _solve(geometry, n, creepage=None):
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import Creepage
    from rigid_dynamics.materials import Material

    creepage = creepage or Creepage(0.0, 0.0, 0.0, 30.0)
    return get_model("bem").solve(
        geometry, creepage, Material(8.0e10, 0.28, 0.3), normal_force_N=1.0e5, options={"nx": n, "ny": n}
    )


def test_exact_gap_agrees_with_the_sampled_grid_at_its_nodes_and_is_smooth_between(tread_patch):
    """Regression (two evaluations of the same surfaces): ``exact`` equals the sampled field at the grid's nodes, and
    between two nodes it lies below their chord where the gap is convex along x (what bilinear interpolation missed)."""
    f = tread_patch.undeformed
    assert f.exact is not None
    xx, yy = np.meshgrid(f.x_m, f.y_m)
    np.testing.assert_allclose(f.exact(xx, yy), f.distance_m, rtol=0, atol=1e-12)
    j = len(f.y_m) // 2
    mid = 0.5 * (f.x_m[:-1] + f.x_m[1:])
    between = f.exact(mid, np.full_like(mid, f.y_m[j]))
    chord = 0.5 * (f.distance_m[j, :-1] + f.distance_m[j, 1:])
    finite = np.isfinite(between) & np.isfinite(chord)
    assert np.all(between[finite] < chord[finite])


def test_bem_max_pressure_converges_without_stripes(tread_patch):
    """BEM on the search's patch: max pressure 64 -> 128 elements changes by < 1 % (grid-periodic stripes made it
    grow by 19 % from 64 to 128 before), and the row through the peak has one maximum (no node-line ridges)."""
    coarse, fine = _solve(tread_patch, 64), _solve(tread_patch, 128)
    assert coarse.success and fine.success
    assert abs(fine.max_pressure_Pa / coarse.max_pressure_Pa - 1) < 0.01
    p = fine.fields.pressure_Pa
    j, i = np.unravel_index(np.argmax(p), p.shape)
    row = p[j][p[j] > 0]
    peaks = np.flatnonzero((row[1:-1] > row[:-2]) & (row[1:-1] > row[2:]))
    assert len(peaks) <= 1, row


def test_report_explains_the_fastsim_bem_creep_force_difference_from_spin_and_the_patch_centroid(tread_patch):
    """The compare report's diagnosis: with spin, FASTSIM on the ellipse of the reference point misses the
    longitudinal force that the BEM's laterally offset pressure centroid gives; FASTSIM re-solved with the creepage
    taken at that centroid closes the difference (a second evaluation of the same physics, measured, not assumed)."""
    from comparisons.rung_differences import explain
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import Creepage
    from rigid_dynamics.materials import Material

    material = Material(8.0e10, 0.28, 0.3)
    creepage = Creepage(0.0, 0.0, 0.3, 30.0)
    bem = _solve(tread_patch, 64, creepage)
    fastsim = get_model("fastsim").solve(
        tread_patch, creepage, material, normal_force_N=bem.normal_force_N, options={"nx": 40, "ny": 40}
    )
    y_c = float((bem.fields.pressure_Pa.sum(axis=1) * bem.fields.y_m).sum() / bem.fields.pressure_Pa.sum())
    assert abs(y_c) > 5e-4  # the tread patch is laterally asymmetric about its deepest point
    solved = {
        "bem": {"status": "ok", "main": ("right", tread_patch, creepage, bem)},
        "fastsim": {"status": "ok", "main": ("right", tread_patch, creepage, fastsim)},
    }
    bullets = explain(solved, material, {"fastsim": {"nx": 40, "ny": 40}})
    assert len(bullets) == 1 and bullets[0].startswith("- **fastsim**")
    assert "Fx" in bullets[0] and "pressure centroid" in bullets[0]
    assert "within the tolerance: explained" in bullets[0]
    moved = replace(creepage, longitudinal=-0.3 * y_c)
    again = get_model("fastsim").solve(
        tread_patch, moved, material, normal_force_N=bem.normal_force_N, options={"nx": 40, "ny": 40}
    )
    bound = 0.3 * bem.normal_force_N
    assert abs(fastsim.creep_force_long_N - bem.creep_force_long_N) > 0.05 * bound
    assert abs(again.creep_force_long_N - bem.creep_force_long_N) < 0.05 * bound
