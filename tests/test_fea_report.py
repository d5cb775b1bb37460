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


def test_fea_bem_verdicts_and_why_on_synthetic_numbers():
    """The report's judgement of FEA against BEM (comparisons.compare): agree within the stated errors, differ by X
    beyond them, undecided without a stated error; the normal force (force control) is equal by construction; the
    why names the FEA's mesh and a tolerance it did not meet. Synthetic numbers, no solve."""
    from comparisons.compare import _agreement_lines, _fea_bem_why, agreement_sentence, verdict
    from comparisons.stated_errors import agreement

    def case(fea, bem, e_fea, e_bem):
        return {"fea": fea, "bem": bem, "fea_stated": e_fea, "bem_stated": e_bem, **agreement(fea, bem, e_fea, e_bem)}

    agree = case(912e6, 967e6, 0.063, 0.005)  # 5.7 % apart, 6.8 % allowed (the demo's peak patch)
    differ = case(899e6, 1147e6, 0.02, 0.005)
    assert verdict(agree).startswith("agree within the stated errors (5.7 % apart")
    assert verdict(differ).startswith("differ by 22 % (beyond the stated 2.5 %")
    assert verdict(case(1.0, 1.1, None, 0.01)) == "undecided (FEA error not stated)"
    text = agreement_sentence("max_pressure", agree)
    assert "FEA 912 MPa +- 6.3 %" in text and "BEM 967 MPa +- 0.5 %" in text
    assert "equal by construction" in agreement_sentence("normal_force", case(1e5, 1e5, 0.0, 1e-12))
    entry = {
        "status": "mesh-tolerance-not-met",
        "message": "discretisation error above mesh_tolerance = 0.02 (max_pressure 6.29%)",
        "resolution": "element size 0.474 mm at the patch",
        "agreement_with_bem": {"max_pressure": agree},
    }
    why = _fea_bem_why(entry, {"resolution": "64 x 64"})
    assert "Why they agree" in why and "0.474 mm" in why and "averaged over 1.5 elements" in why
    assert "only at its larger stated error" in why
    entry.update(status="ok", agreement_with_bem={"max_pressure": differ})
    assert "Why they differ" in _fea_bem_why(entry, {"resolution": "64 x 64"})
    lines = _agreement_lines(entry["agreement_with_bem"], "why")
    assert any("differ by 22 %" in line for line in lines) and "why" in lines
