"""comparisons/manchester.py: the A-2.2 sweep writes its table, summary and plots (two steps only, to stay fast).

Reference: CONTACT's published right-wheel solution (comparisons/data/contact_reference): the roll angles of its
deck, the flange contact from 6.5 mm on, and the difference columns against its forces (the full comparison over
all 21 steps with the bem rung is tests/test_wheelset_case_contact_reference.py).
"""

import csv
import json
import math

import pytest

from comparisons.manchester import COLUMNS, a22_case, contact_reference, run_manchester_a22


def test_two_steps_write_table_summary_and_plots(tmp_path):
    summary = run_manchester_a22(tmp_path, method="fastsim", steps=(4, 14), kinematics="equilibrium")
    for name in ("manchester_a22.csv", "manchester_a22_summary.json", "contact_position.png", "contact_angle.png",
                 "rolling_radius_difference.png", "forces.png", "pressure_area.png"):  # fmt: skip
        assert (tmp_path / name).stat().st_size > 0
    assert not list(tmp_path.glob("*.tmp*"))
    rows = list(csv.DictReader((tmp_path / "manchester_a22.csv").open()))
    assert tuple(rows[0]) == COLUMNS
    assert {int(r["step"]) for r in rows} == {4, 14}
    reference = contact_reference()
    for r in rows:  # the whole-wheelset equilibrium finds CONTACT's roll (the deck's, from its own equilibrium)
        assert float(r["roll_rad"]) == pytest.approx(reference[int(r["step"])]["roll_rad"], rel=0.03)
    flange = [r for r in rows if r["step"] == "14" and r["side"] == "right"]
    assert max(float(r["contact_angle_rad"]) for r in flange) > 0.7
    assert summary["first_flange_contact_shift_m"] == pytest.approx(7.0e-3)
    assert summary["all_converged"]
    # FASTSIM against CONTACT in flange contact (full slip): the normal force within a few %, the difference
    # columns filled on the right wheel only
    right = [r for r in rows if r["side"] == "right"]
    assert all(r["diff_normal_force"] != "" for r in right)
    assert all(r["diff_normal_force"] == "" for r in rows if r["side"] == "left")
    on_disk = json.loads((tmp_path / "manchester_a22_summary.json").read_text())
    assert on_disk["method"] == "fastsim" and math.isfinite(on_disk["max_roll_difference_to_contact_rad"])
    assert set(on_disk["contact_comparison"]["largest_difference"]) == {
        "normal_force", "creep_force_long", "creep_force_lat", "max_pressure", "contact_area", "contact_y_rail"
    }  # fmt: skip


def test_deck_kinematics_prescribe_contacts_roll_and_pitch_rate():
    case = a22_case(13, "deck")
    ref = contact_reference()[13]
    assert case.roll_rad == ref["roll_rad"] == pytest.approx(-0.004376)
    assert case.pitch_rate_rad_per_s == pytest.approx(-4.2748834)
    with pytest.raises(ValueError, match="kinematics = 'free'"):
        a22_case(0, "free")
