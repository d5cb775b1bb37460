"""Contact-angle turning of neighbouring patches (rigid_dynamics.contact.wheelset_patches.turned_angles) against
CONTACT's own numbers.

Reference: CONTACT (E.A.H. Vollebregt, J.J. Kalker; Apache-2.0; revision 2707) run here by /work/contact-build on
case 5 of tests/data/contact_friction/force_control/force_control.inp (A-2.2 right wheel at 5 mm shift, 12 mrad yaw,
D_SEP 6 mm, D_COMB 3 mm) with its locate debug output on (X = 1, PSFLCIN 0003000). Its last iteration prints the
two interpenetration regions (y and z of their ends on the rail in track coordinates, mm; weighted angle;
"totgap", the weight int (int (c - a x^2)^2 dx) dy) and the turn:

    cp 1: y=[ 734.6910, 738.6495], zr=[ 1.4032, 0.8700], angl= -0.1326 (-0.132601), totgap= 0.000201
    cp 2: y=[ 725.5425, 727.9872], zr=[ 3.5167, 2.7735], angl= -0.2984 (-0.298433), totgap= 0.004483
    cp 1 and 2: dist= 6.8425, turning with 0.2808 * a1,a2 + 0.7192 * comb
    input a1= -0.1326, a2= -0.2984, comb= -0.2913 blended= -0.2467, -0.2933

and the solution's contact angles DELTCP -0.2467 and -0.2933 (its right-side sign; ours is positive towards the
track centre). The weights' unit does not matter (only their ratio does).
"""

import math

import numpy as np
import pytest

from rigid_dynamics.contact.wheelset_patches import (
    DEFAULT_PATCH_OPTIONS,
    InterpenetrationRegion,
    turned_angles,
    turning_distance_m,
)

DECK = {**DEFAULT_PATCH_OPTIONS, "distance_separation_m": 6e-3, "distance_combination_m": 3e-3}


def _region(y_mm, z_mm, angle_rad, weight) -> InterpenetrationRegion:
    ends = np.array([[y_mm[0], z_mm[0]], [y_mm[1], z_mm[1]]]) * 1e-3
    centre = (0.0, 0.5e-3 * (y_mm[0] + y_mm[1]))
    return InterpenetrationRegion(0, 1, weight, centre, angle_rad, ends, -1e-5, 0)


FLANGE_ROOT = _region((725.5425, 727.9872), (3.5167, 2.7735), 0.298433, 0.004483)
TREAD = _region((734.6910, 738.6495), (1.4032, 0.8700), 0.132601, 0.000201)


def test_turned_angles_are_contacts():
    (big, big_turn), (small, small_turn) = turned_angles([[FLANGE_ROOT], [TREAD]], DECK)
    assert big == pytest.approx(0.2933, abs=1e-4) and small == pytest.approx(0.2467, abs=1e-4)
    assert big - big_turn == pytest.approx(0.298433) and small - small_turn == pytest.approx(0.132601)


def test_default_turning_distance_is_contacts():
    """D_TURN = 2 D_SEP - D_COMB unless given (CONTACT user guide, D_TURN)."""
    assert turning_distance_m(DECK) == pytest.approx(9e-3)
    assert turning_distance_m({**DECK, "distance_turning_m": 7e-3}) == 7e-3


@pytest.mark.parametrize(
    "change",
    [
        {"distance_turning_m": 6.5e-3},  # D > D_TURN
        {"distance_separation_m": 7e-3, "distance_turning_m": 8e-3},  # D < D_SEP (such regions are joined)
        {"distance_turning_m": 5e-3},  # D_TURN <= D_SEP: no turning at all
        {"angle_separation_rad": 0.1},  # angles differ by more than A_SEP
    ],
)
def test_no_turn_outside_the_band(change):
    angles = turned_angles([[FLANGE_ROOT], [TREAD]], {**DECK, **change})
    assert [turn for _, turn in angles] == [0.0, 0.0]
    assert angles[0][0] == pytest.approx(0.298433) and angles[1][0] == pytest.approx(0.132601)


def test_turn_is_linear_in_the_distance_and_adds_from_both_neighbours():
    """A patch between two others is turned by both (each turn from the angles before turning); at D = D_SEP the
    turn is the whole way to the common weighted angle."""
    left = _region((0.0, 1.0), (0.0, 0.0), 0.1, 1.0)
    middle = _region((7.0, 8.0), (0.0, 0.0), 0.2, 1.0)  # 6 mm from left: D = D_SEP, fraction 1
    right = _region((15.5, 16.5), (0.0, 0.0), 0.4, 1.0)  # 7.5 mm from middle: fraction 0.5
    (a, _), (b, turn_b), (c, _) = turned_angles([[left], [middle], [right]], DECK)
    assert a == pytest.approx(0.15) and c == pytest.approx(0.4 + 0.5 * (0.3 - 0.4))
    assert turn_b == pytest.approx((0.15 - 0.2) + 0.5 * (0.3 - 0.2))
    assert b == pytest.approx(0.2 + turn_b) and math.isfinite(b)
