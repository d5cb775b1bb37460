"""Equilibrium of the wheelset case: the model's own forces carry the total vertical load, creep forces included.

References:

* a Hertzian wheelset (circular wheel profile R 100 mm on a circular rail head R 300 mm): one elliptic patch per
  wheel, so the bem equilibrium must differ from Hertz's only by the BEM's discretisation error, predicted
  independently from one BEM solve at the Hertz approach: F_bem(q_H) = F_H (1 + e_F) and F ~ q^1.5 give
  q_bem / q_H - 1 = -(2/3) e_F + O(e_F^2);
* the balance itself, summed here from each patch's forces in its contact frame (not the solver's bookkeeping):
  -e_z . sum (F_x e_x + F_y e_y + N n) = W per wheel;
* flange contact (A-2.2, 6.5 mm): the creep forces carry 2-4 kN of the 10 kN (CONTACT's published FN = 15.44 kN
  at delta = 1.159 rad: N cos(delta) alone is 6.2 kN);
* free rolling: at the zero-axle-moment pitch rate the moments of all contact forces about the axle cancel.
"""

import math

import numpy as np
import pytest

from comparisons.manchester import MATERIAL, a22_case
from rigid_dynamics.contact.hertz import hertz_force_from_approach
from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.types import Creepage
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
from rigid_dynamics.materials import STEEL

LOAD_N = 10e3


def circular_case(**kwargs):
    args = dict(
        wheel_profile="circ_r100", rail_profile="circ_r300", lateral_shift_m=0.002, wheel_load_N=LOAD_N,
        rolling_speed_m_per_s=2.0,
    )  # fmt: skip
    args.update(kwargs)
    return WheelsetCase(**args)


def vertical_loads(solution):
    out = {}
    for p in solution.patches:
        r = p.result
        f = p.geometry.frame @ np.array([r.creep_force_long_N, r.creep_force_lat_N, r.normal_force_N])
        out[p.side] = out.get(p.side, 0.0) - f[2]
    return out


@pytest.fixture(scope="module")
def circular_track():
    return build_track(circular_case())


def test_hertzian_wheelset_bem_equilibrium_differs_from_hertz_by_the_bem_error(circular_track):
    options = {"spin_rate": "nominal"}
    hertz = solve_wheelset_case(circular_case(), STEEL, "hertz", options, track=circular_track)
    bem = solve_wheelset_case(circular_case(), STEEL, "bem", options, track=circular_track)
    assert hertz.success and bem.success, (hertz.message, bem.message)
    for sol in (hertz, bem):
        for side, load in vertical_loads(sol).items():
            assert load == pytest.approx(LOAD_N, rel=1e-5), side
    model = get_model("bem")
    for ph, pb in zip(hertz.patches, bem.patches, strict=True):
        g = ph.geometry
        assert ph.side == pb.side and g.is_elliptic and ph.combination == "single"
        f_hertz = float(
            hertz_force_from_approach(
                g.curvature_long_1_per_m, g.curvature_lat_1_per_m, g.approach_m,
                shear_modulus_Pa=STEEL.shear_modulus_Pa, poisson_ratio=STEEL.poisson_ratio,
            )
        )  # fmt: skip
        assert ph.result.normal_force_N == pytest.approx(f_hertz, rel=1e-12)
        e_force = model.solve(g, Creepage(), STEEL).normal_force_N / f_hertz - 1.0
        assert 0 < abs(e_force) < 5e-3  # the 40 x 40 BEM's error on a Hertz ellipse
        observed = pb.geometry.approach_m / g.approach_m - 1.0
        # the bem's creep forces (spin of the tilted patch) carry V_t of the load, Hertz has none:
        # F_bem(q_b) (-n_z) = W - V_t and F_H(q_H) (-n_z) = W give q_b / q_H = ((1 - V_t/W) / (1 + e_F))^(2/3)
        r = pb.result
        v_t = -(pb.geometry.frame @ np.array([r.creep_force_long_N, r.creep_force_lat_N, 0.0]))[2]
        predicted = ((1.0 - v_t / LOAD_N) / (1.0 + e_force)) ** (2.0 / 3.0) - 1.0
        assert observed == pytest.approx(predicted, abs=2e-4), (observed, predicted, e_force, v_t)


def test_creep_forces_carry_part_of_the_load_in_flange_contact():
    case = a22_case(13, "deck")
    sol = solve_wheelset_case(case, MATERIAL, "fastsim", {"sides": ("right",)})
    assert sol.success, sol.message
    (patch,) = sol.patches
    g, r = patch.geometry, patch.result
    assert g.contact_angle_rad > 1.1  # flange
    assert vertical_loads(sol)["right"] == pytest.approx(LOAD_N, rel=1e-5)
    normal_share = r.normal_force_N * -g.frame[2, 2]
    assert 0.5 * LOAD_N < normal_share < 0.8 * LOAD_N  # the creep forces carry the rest (2-5 kN)
    assert r.normal_force_N == pytest.approx(15.44e3, rel=0.05)  # CONTACT's FN (bem: see the reference test)
    # Hertz has no creep forces: its normal force alone carries W, N cos(delta) = W
    hertz = solve_wheelset_case(case, MATERIAL, "hertz", {"sides": ("right",)})
    (ph,) = hertz.patches
    assert ph.result.normal_force_N * -ph.geometry.frame[2, 2] == pytest.approx(LOAD_N, rel=1e-5)


def test_close_regions_form_one_patch_as_contact_does():
    """5 mm shift: tread and flange root interpenetrate 4-8 mm apart; CONTACT (D_SEP 8 mm) solves one patch, as
    the "contact" patches do (blended), while the search gives one patch per minimum."""
    case = a22_case(10, "deck")
    options = {"sides": ("right",), "model": {"nx": 24, "ny": 24}}
    joined = solve_wheelset_case(case, MATERIAL, "bem", options)
    assert joined.success, joined.message
    assert [p.combination for p in joined.patches] == ["blended"]
    assert not joined.patches[0].geometry.is_elliptic
    search = solve_wheelset_case(case, MATERIAL, "bem", dict(options, patches="search"))
    assert search.success and len(search.patches) == 2
    separate = solve_wheelset_case(case, MATERIAL, "bem", dict(options, patch={"distance_separation_m": 1e-3}))
    assert separate.success and len(separate.patches) == 2
    # the analytic rungs take each region as its own patch (a joined patch is no ellipse)
    hertz = solve_wheelset_case(case, MATERIAL, "hertz", {"sides": ("right",)})
    assert hertz.success and [p.combination for p in hertz.patches] == ["single", "single"]


def test_zero_axle_moment_is_free_rolling():
    case = a22_case(6)  # whole-wheelset equilibrium, 3 mm shift: unequal rolling radii
    sol = solve_wheelset_case(case, MATERIAL, "linear")
    assert sol.success and sol.spin_rate_mode == "zero-axle-moment"
    moment = 0.0
    axle = sol.pose.rotation[:, 1]
    for p in sol.patches:
        r = p.result
        f = p.geometry.frame @ np.array([r.creep_force_long_N, r.creep_force_lat_N, r.normal_force_N])
        moment += float(np.cross(p.geometry.point_m - sol.pose.centre_m, f) @ axle)
    assert abs(moment) < 1e-5 * LOAD_N * 0.46
    fx = {p.side: p.result.creep_force_long_N for p in sol.patches}
    assert fx["left"] * fx["right"] < 0  # opposite longitudinal forces (the normal forces' moments differ with yaw)
    nominal = solve_wheelset_case(case, MATERIAL, "linear", {"spin_rate": "nominal"})
    assert abs(nominal.axle_moment_Nm) > 100 * abs(sol.axle_moment_Nm)


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"patches": "all"}, "patches = 'all'"),
        ({"sides": ("middle",)}, "sides = "),
        ({"rolling_speed": "fast"}, "rolling_speed = 'fast'"),
        ({"patch": {"d_sep": 1}}, "patch option 'd_sep'"),
        ({"force_tolerance": -1.0}, "force_tolerance = -1.0"),
    ],
)
def test_bad_options_raise(options, match):
    with pytest.raises(ValueError, match=match):
        solve_wheelset_case(a22_case(0, "deck"), MATERIAL, "hertz", options)


def test_whole_wheelset_needs_both_sides():
    with pytest.raises(ValueError, match="needs both wheels"):
        solve_wheelset_case(a22_case(0), MATERIAL, "hertz", {"sides": ("right",)})


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"roll_rad": 0.5}, "roll_rad = 0.5"), ({"pitch_rate_rad_per_s": 4.3}, "pitch_rate_rad_per_s = 4.3"),
     ({"pitch_rate_rad_per_s": math.nan}, "pitch_rate_rad_per_s = nan")],
)  # fmt: skip
def test_bad_kinematics_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        circular_case(**kwargs)
