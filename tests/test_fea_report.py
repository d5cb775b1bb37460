"""FEA vs BEM on a non-Hertzian Manchester-profile patch (comparisons.fea_report).

Second-method check: the FE block with the combined modulus and Kalker-type boundary elements
solve the same half-space problem on the same sampled gap, so on coarse grids their pressures must
agree to a coarse-grid tolerance (measured at this resolution: D_p ~ 0.1, D_A ~ 0.03). One coarse mesh
(``mesh_tolerance`` None: no refinement series, so no stated error) keeps the test short.
"""

import json

import pytest

from comparisons.fea_report import run_fea_report

pytestmark = pytest.mark.fea


def test_fea_and_bem_agree_on_a_manchester_patch(tmp_path):
    summary = run_fea_report(
        tmp_path,
        sides=("right",),
        fea_options={"quick": True, "stresses": False, "mesh_tolerance": None},
        bem_options={"nx": 24, "ny": 24},
    )
    assert summary["equilibrium"]["status"] == "ok"
    (patch,) = summary["patches"]
    assert patch["fea"]["success"] and patch["bem"]["success"]
    assert patch["fea"]["status"] == "error-not-estimated" and patch["fea"]["stated_errors"] is None
    assert patch["fea"]["normal_force_N"] == pytest.approx(patch["bem"]["normal_force_N"], rel=1e-6)
    assert patch["pressure_difference_force_weighted"] < 0.25
    assert abs(patch["contact_area_difference"]) < 0.15
    # two elastic bodies meshed from the real profiles: same problem up to finite-body effects
    assert patch["fea_profiles"]["success"]
    assert patch["profiles_pressure_difference_force_weighted"] < 0.25
    assert abs(patch["profiles_contact_area_difference"]) < 0.15
    assert json.loads((tmp_path / "fea_report.json").read_text())["patches"][0]["side"] == "right"
    assert (tmp_path / "fea_vs_bem_right_0.png").is_file()
