"""The dynamics loop's KPEC on the formed patch (``patch_geometry = "formed"``) against CONTACT's own KPEC output on
its example ``mbench_a22_kpec`` (Manchester A-2.2, right wheel; tests/data/contact_kpec, SOURCE.md there).

With ``patch_geometry = "formed"`` a gap-solving model whose law is compiled (``kpec``: with "sampled" its compiled
law samples each candidate on its own plane at its deepest point) goes through the callback on the patches formed as
the static wheelset case forms them (CONTACT's module 1: regions joined or split, each patch in the plane of its
weighted contact angle), as CONTACT applies KPEC. Independent reference: the numbers CONTACT prints for KPEC (B = 5)
with FASTSIM (M = 3) at y_ws = 0, 0.5 and 5 mm (its cases 1-3, the A-2.2 steps 0, 1 and 10), on 0.2 mm elements.

The wheelset is held at the deck's pose of each case (lateral shift, yaw, CONTACT's roll and pitch rate, 2 m/s on
the deck's profiles as CONTACT reads them); its height is solved by the loop itself for 10 kN on the right wheel
(CONTACT's case 1 stopped its own iteration at 9982 N: that case is compared at CONTACT's 9982 N). The forces the loop
applies to the wheel (main frame, summed over the right wheel's candidates) are expressed in the formed patch's plane
and compared with CONTACT's in its plane, with the issue's loop tolerances (tests/test_loop_sampled_a22.py): normal
force 0.5 %, creep forces 1 % of mu N, max pressure 3 %, area 5 %. The loop's creepages are relative to the wheelset
centre's speed, carried from the candidate's point to the formed patch's, not CONTACT's (at its point Q, relative to
the bodies' mean rolling speed); the static rung with CONTACT's point Q is within 0.3 % (tests/test_kpec_contact.py).

Recorded on this commit (loop against CONTACT; F_x, F_s in mu F_N):

| case | F_N | p_max | area | F_x | F_s |
|---|---|---|---|---|---|
| 1 (0 mm) | -0.005 % | -0.012 % | -0.000 % | -0.085 % | -0.002 % |
| 2 (0.5 mm) | -0.015 % | +0.003 % | -0.106 % | -0.844 % | -0.208 % |
| 3 (5 mm) | -0.024 % | +0.231 % | -0.444 % | -0.277 % | -0.060 % |

(F_x in case 2 is the creepages' definition: the static rung at CONTACT's point Q gives 0.005 %.) About 4 s.
"""

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from loop_helpers import height_at_load

from comparisons.manchester import CONTACT_ELEMENT_SIZE_M, MATERIAL, a22_case
from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.wheelset.compiled_laws import LAW_CALLBACK, LAW_KPEC
from rigid_dynamics.wheelset.compiled_records import law_code
from rigid_dynamics.wheelset.layout import PATCH_SAMPLED
from rigid_dynamics.wheelset.parameters import DynamicsScene, TrackGeometry
from rigid_dynamics.wheelset.providers import SearchProvider
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

REFERENCE = Path(__file__).parent / "data" / "contact_kpec" / "mbench_a22_kpec.csv"
SPEED_M_PER_S = 2.0
STEP_OF_CASE = {1: 0, 2: 1, 3: 10}
TOLERANCES = {"normal_force": 0.005, "creep_force_long": 0.01, "creep_force_lat": 0.01, "max_pressure": 0.03,
              "contact_area": 0.05}  # fmt: skip


def _reference() -> dict[int, dict]:
    with REFERENCE.open(encoding="utf-8") as fh:
        return {int(r["case"]): {k: (float(v) if k != "method" and v != "" else v) for k, v in r.items()}
                for r in csv.DictReader(fh)}  # fmt: skip


def _model(name, geometry, options=None):
    scene = DynamicsScene(
        track=TrackGeometry(
            wheel_profile="MBench_S1002_v3", rail_profile="MBench_UIC60_v3", rail_inclination_rad=math.atan(1 / 40),
            gauge_m=1.435, gauge_height_m=0.014, flange_back_distance_m=1.360,
        ),
        material=MATERIAL, speed_m_per_s=SPEED_M_PER_S, contact_model=name, contact_provider="search",
        patch_geometry=geometry,
    )  # fmt: skip
    provider = SearchProvider(scene.wheelset, scene.track, surfaces=build_track(a22_case(0, "deck")))
    return WheelsetModel(scene, provider, get_model(name), options)


@pytest.fixture(scope="module")
def model():
    return _model("kpec", "formed", {"element_size_m": CONTACT_ELEMENT_SIZE_M})


@pytest.fixture(scope="module")
def probe():
    """The loop with Hertz's compiled law: the height's start without a KPEC solve."""
    return _model("hertz", "sampled")


def _right_wheel(model, ref, z):
    state = np.array([0.0, ref["y_ws_mm"] * 1e-3, z, ref["yaw_ws_rad"], ref["roll_ws_rad"], 0.0,
                      SPEED_M_PER_S, 0.0, 0.0, 0.0, 0.0, -ref["vpitch_ws_rad_per_s"]])  # fmt: skip
    contact = model.contact(state, record=True)
    right = contact.side == 1
    return contact, right, -float(contact.force_N[right, 2].sum())


def test_formed_routes_kpec_through_the_callback():
    """With "formed" the compiled KPEC law gives way to the callback (on the formed patches); "sampled" keeps it."""
    kpec = get_model("kpec")
    assert law_code(kpec, "sampled") == LAW_KPEC and law_code(kpec, "ellipse") == LAW_KPEC
    assert law_code(kpec, "formed") == LAW_CALLBACK
    assert law_code(get_model("fastsim"), "formed") == law_code(get_model("fastsim"))  # a Hertzian law: unchanged


@pytest.mark.parametrize("case", list(STEP_OF_CASE))
def test_loop_kpec_on_the_formed_patch_equals_contacts_kpec(model, probe, case):
    ref = _reference()[case]
    load = ref["fz_tr_N"]  # the vertical force CONTACT's own iteration reached (9982 N in case 1, else 10 kN)
    z0 = -0.46
    z_hertz, _, _ = height_at_load(
        lambda z: _right_wheel(probe, ref, z), load, z0 - 0.01, z0 + 0.002, 1e-3, 60, f"case {case} (Hertz)"
    )
    _, contact, right = height_at_load(
        lambda z: _right_wheel(model, ref, z), load, z_hertz - 2e-5, z_hertz + 2e-5, 1e-6, 60, f"case {case}"
    )
    values = contact.values
    serving = np.flatnonzero(right & (np.nan_to_num(values["normal_force_N"]) > 0))
    assert len(serving) == int(ref["n_patches"]) == 1, f"case {case}: {len(serving)} loop patches carry force"
    k = int(serving[0])
    assert values["patch_geometry_code"][k] == PATCH_SAMPLED
    assert values["contact_law_code"][k] == LAW_CALLBACK
    (formed,) = model.callback.former.last("right")
    # CONTACT prints the right wheel's contact angle with the opposite sign (wheelset_patches' module docstring)
    assert formed.geometry.contact_angle_rad == pytest.approx(-ref["deltcp_tr_rad"], abs=0.02)
    e_x, e_y, normal = formed.geometry.frame.T
    force = contact.force_N[right].sum(axis=0)  # on the wheel, main frame
    mu_n = MATERIAL.friction_coefficient * ref["fn_N"]
    diffs = {
        "normal_force": float(force @ normal) / ref["fn_N"] - 1.0,
        "creep_force_long": (float(force @ e_x) + ref["fx_N"]) / mu_n,
        "creep_force_lat": (float(force @ e_y) - ref["fs_N"]) / mu_n,
        "max_pressure": values["max_pressure_Pa"][k] / (ref["pmax_N_per_mm2"] * 1e6) - 1.0,
        "contact_area": values["contact_area_m2"][k] / (ref["contact_area_mm2"] * 1e-6) - 1.0,
    }
    worst = {key: value for key, value in diffs.items() if abs(value) > TOLERANCES[key]}
    assert not worst, f"case {case}: {diffs}"
    print(f"case {case}: " + ", ".join(f"{key} {value:+.3%}" for key, value in diffs.items()))


def test_kpec_grid_error_recorded_and_judged(model, probe):
    """A callback model other than the BEM that states its grid error per solve (KPEC: companion grids 2x and 4x as
    coarse) has it recorded over the run (callback stats ``grid_error``) and judged against its grid_tolerance
    (discretisation.contact_grid_check: "ok" becomes "warning", naming the model), as the BEM's is."""
    from rigid_dynamics.wheelset.discretisation import contact_grid_check

    ref = _reference()[2]
    _right_wheel(model, ref, -0.4598)  # any height in contact: one solve per patch through the callback
    stats = model.callback.stats()
    assert "bem_grid_error" not in stats and stats["grid_error"]["estimated"] > 0
    grid = stats["grid_error"]
    assert 0 < grid["largest_force"] < 1 and grid["tolerance"] == 0.05
    above = {**stats, "grid_error": {**grid, "largest_force": 0.08, "t_s": 0.5}}
    status, message = contact_grid_check("ok", "reached t = 1 s", above)
    assert status == "warning" and "kpec's grid-error estimate of the patch forces 0.08" in message
    assert (
        contact_grid_check("ok", "reached t = 1 s", {**stats, "grid_error": {**grid, "largest_force": 0.01}})[0] == "ok"
    )


def test_a_grid_error_in_another_form_counts_as_not_estimated(model):
    """A user model's ``extra["grid_error"]`` without the BEM's form (estimated, relative forces, tolerance, largest)
    is counted as not estimated, not read (no KeyError inside the run)."""
    from types import SimpleNamespace

    callback = model.callback
    before = dict(callback.grid_error)
    for grid in ({"estimated": True, "relative": "2 %"}, {"estimated": True, "relative": {"normal_force_N": 0.01}}):
        callback._record_grid_error(SimpleNamespace(extra={"grid_error": grid}, status="ok"), 0.0)
    assert callback.grid_error["not_estimated"] == before["not_estimated"] + 2
    assert callback.grid_error["estimated"] == before["estimated"]
