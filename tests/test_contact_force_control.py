"""The wheelset case with the total longitudinal force prescribed against CONTACT's F = 1 (module 1).

Reference: tests/data/contact_friction/force_control (SOURCE.md there; CONTACT rev 2707 run here by h5c): the
A-2.2 right wheel with FX_WS (on the rail, along the wheelset's x) = +-1500 N and +2700 N at zero shift, and
+1500 N at 5 mm shift and 12 mrad yaw with one patch (D_SEP 8 mm) and two (D_SEP 6, D_COMB 3 mm); the pitch
velocity solved. Ours: the same wheelset (roll prescribed as the deck, the pitch rate left free), the right wheel,
the ``bem`` rung on CONTACT's 0.2 mm grid, ``longitudinal_force_N`` = -FX_WS on the wheel
(wheelrail.cases.solve_wheelset_to_force).

Tolerances (issue 26): per patch Fx and Fs within 1 % of mu FN, PMAX 3 %; the solved pitch rate within 1e-4
relative. Recorded on this commit (pytest -s prints them): cases 1-3 pitch rate
1.4-1.6e-6, Fx 0.00 %, Fs 0.18-0.23 % of mu FN, PMAX 0.01 %; case 4 (yawed, flange root, :data:`BLENDED`) pitch
rate 3.0e-5, Fx 0.01 %, Fs 0.00 %, PMAX 0.43 %; case 5 (two patches) pitch rate 1.7e-5, the small patch FN
+0.77 %, Fx 0.53 %, Fs 0.54 % of mu FN, PMAX 0.44 %, the large one FN -0.14 %, Fx 0.08 %, Fs 0.11 %, PMAX 0.08 %.

Case 5 has two patches D = 6.8 mm apart, between D_SEP (6 mm) and CONTACT's D_TURN (2 D_SEP - D_COMB = 9 mm):
CONTACT keeps them apart but turns both contact planes towards their weighted angle by (D_TURN - D) / (D_TURN -
D_SEP) = 0.72 of the difference, so the small tread patch is solved in a plane at 0.247 rad where its own surface
slope is 0.133 (rigid_dynamics.contact.wheelset_patches.turned_angles); the deck's profiles are interpolated
(SMOOTH = 0, comparisons.manchester.DECK_PROFILE_SMOOTHING_M) and the rail placed by CONTACT's gauge point (the
chord-length spline through the profile points, rigid_dynamics.geometry.placement; 0.31 um from the z(y) spline's,
which moves 1 % of the small patch's FN). Before these (planes untilted, profiles smoothed over 2 mm) the small patch
carried 9.1 % more FN than CONTACT's, its Fx and Fs 5.9 % and 6.9 % of mu FN off.
"""

import csv
import dataclasses
from pathlib import Path

import pytest

from comparisons.manchester import MATERIAL, a22_case
from wheelrail.cases import ContactCase, solve_wheelset_to_force

BLENDED = 4
"""CONTACT's case 4 joins the two regions (6.8 mm apart, D_COMB 4 < D <= D_SEP 8 mm) into one patch of two
sub-patches whose normal interaction is scaled by ((D_SEP - D) / (D_SEP - D_COMB))^0.8, and so does our ``bem``
(option ``subpatch_interaction``, default "contact"): pitch rate 3.0e-5 from CONTACT's, PMAX 0.43 %. Joined fully
(before) its reference point lay 0.13 mm from CONTACT's, the pitch rate 1.04e-4 off and PMAX 1.4 %."""
DATA = Path(__file__).parent / "data" / "contact_friction" / "force_control" / "force_control.csv"


def _reference() -> dict[int, list[dict]]:
    out: dict = {}
    with DATA.open(encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            out.setdefault(int(row["case"]), []).append({k: float(v) for k, v in row.items() if v != ""})
    return out


@pytest.mark.parametrize("number", sorted(_reference()))
def test_prescribed_force_against_contact(number):
    reference = _reference()[number]
    first = reference[0]
    step = round(first["y_ws_mm"] / 0.5)
    wheelset = dataclasses.replace(a22_case(step, "deck"), roll_rad=first["roll_ws_rad"],
                                   pitch_rate_rad_per_s=None)  # fmt: skip
    assert wheelset.yaw_rad == pytest.approx(first["yaw_ws_rad"])
    options = {
        "model": {"element_size_m": 2e-4},
        "sides": ("right",),
        "patch": {"distance_separation_m": first["d_sep_mm"] * 1e-3,
                  "distance_combination_m": first["d_comb_mm"] * 1e-3},
    }  # fmt: skip
    case = ContactCase("wheelset", MATERIAL, wheelset=wheelset, solver_options=options,
                       longitudinal_force_N=-first["fx_ws_prescribed_N"])  # fmt: skip
    solution, control = solve_wheelset_to_force(case, "bem")
    assert control["status"] == "ok" and abs(control["residual_N"]) <= control["force_tolerance_N"], control
    pitch_error = control["pitch_rate_rad_per_s"] / first["vpitch_ws_rad_per_s"] - 1.0
    assert abs(pitch_error) <= 1e-4, control
    assert len(solution.patches) == len(reference)
    for ref in reference:
        patch = min(solution.patches, key=lambda p: abs(p.geometry.contact_point_rail_m[0] - ref["ycp_rail_mm"] * 1e-3))
        r = patch.result
        mu_fn = 0.3 * ref["fn_N"]
        errors = {
            "fn": r.normal_force_N / ref["fn_N"] - 1.0,
            "fx": (r.creep_force_long_N + ref["fx_N"]) / mu_fn,
            "fs": (r.creep_force_lat_N - ref["fs_N"]) / mu_fn,
            "pmax": r.max_pressure_Pa / (ref["pmax_N_per_mm2"] * 1e6) - 1.0,
            "xi": patch.creepage.longitudinal + ref["cksi"],
        }
        print(number, int(ref["patch"]), f"pitch {pitch_error:.2e}", {k: f"{v:.4f}" for k, v in errors.items()})
        assert abs(errors["fx"]) <= 0.01 and abs(errors["fs"]) <= 0.01, errors
        assert abs(errors["pmax"]) <= 0.03, errors
