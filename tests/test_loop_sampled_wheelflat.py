"""The dynamics loop's contact on CONTACT's scanned wheel flat (examples/wheelflat.inp) in the quasi-static limit,
against CONTACT's published solution at the flat (comparisons/data/contact_wheelflat, SOURCE.md).

As tests/test_loop_sampled_a22.py: the wheelset held at the deck's pose (lateral shift, yaw and roll 0, the wheel
turned to phi = -PITCH, 2 m/s, CONTACT's pitch rate), only its height solved here for 125 kN vertical force on the
right wheel; each contact the loop's own (WheelsetModel.contact: the provider's patches of the measured wheel, the
sampled patch formed as the static case forms it, ``bem`` on CONTACT's 0.4 mm elements). The wheel and rail read as
tests/test_wheelflat_contact_reference.py reads them (CONTACT's SMOOTH 5 as ISMOOTH 0, the rail unsmoothed, TH_INTPOL
2, the base slice's file offset). Forces on the wheel (main frame) expressed in the plane the loop solved the patch
in, compared with CONTACT's (on the rail, FX sign turned) with issue 28's tolerances: normal force 0.5 %, creep
forces 1 % of mu N, max pressure 3 %, area 5 %. The creepages are the loop's (eq 41), not CONTACT's: they differ by
2 / (2 - xi), 1.0008 here. One angle, -37 deg (the flat under the wheel, the contact 16 mm towards the field side),
for the suite's time; the bench (benchmarks/results/wheelflat_contact.md) has all 26 angles of the static case.
Recorded at -37 deg: normal force +0.02 %, FX +0.18 % and FS +0.15 % of mu N, max pressure +0.05 %, area 0.0 %
(the static case's numbers, as the patch is the same). Cost: the test about 15 s for its height iteration, about
1-3 s per loop evaluation at this pose on the shared machine (a measured wheel takes the provider's numpy search,
layout.GEOMETRY_GIVEN, not the compiled 3-D search).
"""

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from loop_helpers import height_at_load

from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase
from rigid_dynamics.geometry.slices import contact_smoothing_wavelength_m, read_wheel_slices
from rigid_dynamics.materials import Material
from rigid_dynamics.wheelset.layout import PATCH_SAMPLED
from rigid_dynamics.wheelset.parameters import DynamicsScene, TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers import SearchProvider
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

DATA = Path(__file__).resolve().parents[1] / "comparisons/data/contact_wheelflat"
EXAMPLES = DATA / "examples"
BASE = EXAMPLES / "S1002_flat/Wheel_section_208.txt"
RAIL = EXAMPLES / "r300_wide.prr"
MATERIAL = Material(82e9, 0.28, 0.3)
SPEED_M_PER_S = 2.0
PITCH_RATE_RAD_PER_S = -4.08190679  # CONTACT's sign (forward rolling negative)
LOAD_N = 125.0e3
TOLERANCES = {"normal_force": 0.005, "creep_force_long": 0.01, "creep_force_lat": 0.01, "max_pressure": 0.03,
              "contact_area": 0.05}  # fmt: skip


@pytest.fixture(scope="module")
def model():
    smoothing = contact_smoothing_wavelength_m(5.0, BASE)
    slices = read_wheel_slices(EXAMPLES / "S1002_flat.slcw", smoothing_wavelength_m=smoothing)
    case = WheelsetCase(
        wheel_profile=str(BASE), rail_profile=str(RAIL), gauge_m=1.435, gauge_height_m=0.014,
        flange_back_distance_m=1.360, nominal_radius_m=0.49, rail_inclination_rad=0.02, wheel_load_N=LOAD_N,
        rolling_speed_m_per_s=SPEED_M_PER_S, wheel_irregularities_right=(slices.irregularity,),
        profile_smoothing_m=smoothing, rail_profile_smoothing_m=0.0,
    )  # fmt: skip
    scene = DynamicsScene(
        track=TrackGeometry(
            wheel_profile=str(BASE), rail_profile=str(RAIL), rail_inclination_rad=0.02, gauge_m=1.435,
            gauge_height_m=0.014, flange_back_distance_m=1.360,
        ),
        wheelset=WheelsetParameters(nominal_radius_m=0.49), material=MATERIAL, speed_m_per_s=SPEED_M_PER_S,
        contact_model="bem", contact_provider="search",
    )  # fmt: skip
    surfaces = build_track(case, wheel_irregularities=case.wheel_irregularities)
    provider = SearchProvider(scene.wheelset, scene.track, surfaces=surfaces)
    return WheelsetModel(scene, provider, get_model("bem"), {"element_size_m": 4e-4})


def _right_wheel(model, pitch_deg, z):
    state = np.array([0.0, 0.0, z, 0.0, 0.0, -math.radians(pitch_deg), SPEED_M_PER_S, 0.0, 0.0, 0.0, 0.0,
                      -PITCH_RATE_RAD_PER_S])  # fmt: skip
    contact = model.contact(state, record=True)
    right = contact.side == 1
    return contact, right, -float(contact.force_N[right, 2].sum())


def _held_at_load(model, pitch_deg, z_lo, z_hi, tolerance=1e-4):
    """The right wheel's contact at the height of LOAD_N between z_lo (out of contact) and z_hi (deeper)
    (loop_helpers.height_at_load: the Illinois method on load^(2/3))."""
    _, contact, right = height_at_load(
        lambda z: _right_wheel(model, pitch_deg, z), LOAD_N, z_lo, z_hi, tolerance, 40, f"pitch {pitch_deg} deg"
    )
    return contact, right


@pytest.mark.parametrize("pitch_deg", [-37.0])
def test_loop_contact_on_the_flat_equals_contacts_solution(model, pitch_deg):
    with open(DATA / "wheelflat_ref_out.csv") as f:
        ref = next(
            {k: float(v) for k, v in row.items()} for row in csv.DictReader(f) if float(row["pitch_deg"]) == pitch_deg
        )
    contact, right = _held_at_load(model, pitch_deg, -0.4905, -0.487)
    values = contact.values
    serving = np.flatnonzero(right & (np.nan_to_num(values["normal_force_N"]) > 0))
    assert len(serving) == 1, f"pitch {pitch_deg} deg: {len(serving)} loop patches carry force"
    k = int(serving[0])
    assert values["patch_geometry_code"][k] == PATCH_SAMPLED
    (formed,) = model.callback.former.last("right")
    e_x, e_y, normal = formed.geometry.frame.T
    force = contact.force_N[right].sum(axis=0)  # on the wheel, main frame
    mu_n = MATERIAL.friction_coefficient * ref["fn_N"]
    diffs = {
        "normal_force": float(force @ normal) / ref["fn_N"] - 1.0,
        "creep_force_long": (-float(force @ e_x) - ref["fx_N"]) / mu_n,  # CONTACT's FX on the rail
        "creep_force_lat": (float(force @ e_y) - ref["fs_N"]) / mu_n,
        "max_pressure": values["max_pressure_Pa"][k] / (1e6 * ref["pmax_MPa"]) - 1.0,
        "contact_area": values["contact_area_m2"][k] / (1e-6 * ref["area_mm2"]) - 1.0,
    }
    worst = {key: f"{value:+.4f}" for key, value in diffs.items() if abs(value) > TOLERANCES[key]}
    assert not worst, f"pitch {pitch_deg} deg: {diffs}"
