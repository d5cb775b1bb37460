"""comparisons/manchester.py: the A-2.2 sweep writes its table, summary and plots (two steps only, to stay fast).

Reference: CONTACT's roll angles for the same steps (module constant CONTACT_ROLL_RAD, from CONTACT's example
input, see tests/test_wheelset_case.py) and the flange contact that appears from 6.5 mm on.
"""

import csv
import json
import math

import pytest

from comparisons.manchester import COLUMNS, CONTACT_ROLL_RAD, run_manchester_a22


def test_two_steps_write_table_summary_and_plots(tmp_path):
    summary = run_manchester_a22(tmp_path, method="hertz", steps=(4, 14))
    for name in ("manchester_a22.csv", "manchester_a22_summary.json", "contact_position.png", "contact_angle.png",
                 "rolling_radius_difference.png", "forces.png"):  # fmt: skip
        assert (tmp_path / name).stat().st_size > 0
    assert not list(tmp_path.glob("*.tmp*"))
    rows = list(csv.DictReader((tmp_path / "manchester_a22.csv").open()))
    assert tuple(rows[0]) == COLUMNS
    assert {int(r["step"]) for r in rows} == {4, 14}
    for r in rows:
        assert float(r["roll_rad"]) == pytest.approx(CONTACT_ROLL_RAD[int(r["step"])], rel=0.03)
    flange = [r for r in rows if r["step"] == "14" and r["side"] == "right"]
    assert max(float(r["contact_angle_rad"]) for r in flange) > 0.7
    assert summary["first_flange_contact_shift_m"] == pytest.approx(7.0e-3)
    assert summary["all_converged"]
    on_disk = json.loads((tmp_path / "manchester_a22_summary.json").read_text())
    assert on_disk["method"] == "hertz" and math.isfinite(on_disk["max_roll_difference_to_contact_rad"])
