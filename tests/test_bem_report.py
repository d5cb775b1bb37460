"""comparisons.bem_report on one Manchester A-2.2 step (flange-root contact): files written, equal loads.

Consistency checks between models on the same patches (no closed form): the bem carries the same normal
force as Hertz (force control), and for the non-elliptic flange-root patch the bem's creep forces stay
within 10 % of FASTSIM's (both near saturation there).
"""

import json

import pytest

from comparisons.bem_report import write_bem_report


def test_report_step12(tmp_path):
    report = write_bem_report(tmp_path, steps=(12,), bem_options={"nx": 24, "ny": 24})
    assert (tmp_path / "bem_report.md").exists()
    assert json.loads((tmp_path / "bem_report.json").read_text())["steps"][0]["step"] == 12
    patches = report["steps"][0]["patches"]
    assert any(not p["is_elliptic"] for p in patches)
    for p in patches:
        m = p["models"]
        assert m["bem"]["success"]
        # the BEM's own grid-error estimate is in the report (24 x 24 on the flange root: above 2 %, "warning")
        assert m["bem"]["grid_error_estimate"] > 0 and m["hertz"]["grid_error_estimate"] is None
        assert m["bem"]["status"] == ("ok" if m["bem"]["grid_error_estimate"] <= 0.02 else "warning")
        assert m["bem"]["normal_force_N"] == pytest.approx(m["hertz"]["normal_force_N"], rel=1e-9)
        assert (tmp_path / p["fields_png"]).stat().st_size > 1000
        if not p["is_elliptic"]:
            assert m["bem"]["semi_axis_long_m"] is None
            fs, bem = m["fastsim"], m["bem"]
            total_fs = (fs["creep_force_long_N"] ** 2 + fs["creep_force_lat_N"] ** 2) ** 0.5
            total_bem = (bem["creep_force_long_N"] ** 2 + bem["creep_force_lat_N"] ** 2) ** 0.5
            assert total_bem == pytest.approx(total_fs, rel=0.1)
