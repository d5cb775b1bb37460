"""The wheelset case with the total longitudinal force prescribed against CONTACT's F = 1 (module 1).

Reference: CONTACT run here on the A-2.2 right-wheel deck's case 1 with FX_WS = -1500 and -2700 N on the rail
prescribed and the pitch velocity solved (tests/data/contact_force, SOURCE.md there). Ours: the same deck
(``kinematics = "deck"`` roll, the pitch rate left free), the right wheel, the ``bem`` rung on CONTACT's 0.2 mm
grid, ``longitudinal_force_N`` = +1500 / +2700 N on the wheel (wheelrail.cases.solve_wheelset_to_force).

Tolerances (issue 26): the patch's Fs within 1 % of mu FN (Fx is the prescribed force), PMAX 3 %; the solved pitch
rate within 1e-5 relative and the patch's xi within 0.5 % of CONTACT's. Recorded on this commit: Fs 0.24 % and
0.16 % of mu FN, PMAX 0.02 %, pitch rate 1.6e-6 and 1.4e-6, xi 0.04 %.
"""

import csv
import dataclasses
from pathlib import Path

import pytest

from comparisons.manchester import MATERIAL, a22_case
from wheelrail.cases import ContactCase, solve_wheelset_to_force

DATA = Path(__file__).parent / "data" / "contact_force" / "mbench_a22_right_force.csv"


def _reference() -> list[dict]:
    with DATA.open(encoding="utf-8") as fh:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(fh)]


@pytest.mark.parametrize("ref", _reference(), ids=lambda r: f"{-r['fx_ws_rail_N']:.0f}N")
def test_prescribed_force_against_contact(ref):
    wheelset = dataclasses.replace(a22_case(0, "deck"), pitch_rate_rad_per_s=None)
    options = {"model": {"element_size_m": 2e-4}, "sides": ("right",)}
    case = ContactCase("wheelset", MATERIAL, wheelset=wheelset, solver_options=options,
                       longitudinal_force_N=-ref["fx_ws_rail_N"])  # fmt: skip
    solution, control = solve_wheelset_to_force(case, "bem")
    assert control["status"] == "ok" and abs(control["residual_N"]) <= control["force_tolerance_N"], control
    assert control["pitch_rate_rad_per_s"] == pytest.approx(ref["vpitch_ws_rad_per_s"], rel=1e-5)
    (patch,) = solution.patches
    r = patch.result
    mu_fn = 0.3 * ref["fn_N"]
    assert r.normal_force_N == pytest.approx(ref["fn_N"], rel=0.01)
    assert r.creep_force_long_N == pytest.approx(-ref["fx_N"], abs=0.01 * mu_fn)
    assert abs(r.creep_force_lat_N - ref["fs_N"]) <= 0.01 * mu_fn
    assert r.max_pressure_Pa / 1e6 == pytest.approx(ref["pmax_N_per_mm2"], rel=0.03)
    assert patch.creepage.longitudinal == pytest.approx(-ref["cksi"], rel=0.005)
