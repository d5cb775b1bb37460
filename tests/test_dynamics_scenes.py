"""The embedded dynamics scenes: every TOML file maps field by field onto DynamicsScene and runs.

Regression/smoke tests (they check that the scenes are complete and runnable, not physics): each scene is
built with the front end's generic TOML -> dataclass mapping and run for 10 ms, the irregular ones on
contact-geometry tables (the 3-D search is exercised by the benchmark and tests/test_dynamics_search.py).
"""

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.simulate import simulate
from wheelrail.config import build_dataclass

SCENES = Path(__file__).resolve().parents[1] / "wheelrail" / "scenes"
NAMES = ("hunting-conical", "polygonal-wheel", "wheel-flat", "corrugation")


def load(name):
    with open(SCENES / f"{name}.toml", "rb") as handle:
        return build_dataclass(DynamicsScene, tomllib.load(handle))


def test_scene_contents():
    hunting = load("hunting-conical")
    assert hunting.track.conicity == 0.05 and hunting.wheelset.nominal_radius_m == 0.46
    assert hunting.wheelset.contact_half_distance_m == 0.75 and hunting.speed_m_per_s == 20.0
    assert hunting.initial.lateral_displacement_m == 0.003 and hunting.suspension == type(hunting.suspension)()
    polygon = load("polygonal-wheel")
    assert (polygon.irregularities.polygon_order, polygon.irregularities.polygon_amplitude_m) == (3, 3e-4)
    assert polygon.speed_m_per_s == pytest.approx(100 / 3.6, rel=1e-5) and polygon.duration_s == 2.0
    assert polygon.track.rail_inclination_rad == 0.025 and polygon.track.wheel_profile == "S1002"
    flat = load("wheel-flat")
    assert flat.irregularities.flat_length_m == 0.05 and flat.speed_m_per_s == pytest.approx(60 / 3.6, rel=1e-5)
    corrugation = load("corrugation")
    assert corrugation.irregularities.corrugation_wavelength_m == 0.05
    assert corrugation.irregularities.corrugation_amplitude_m == 3e-5
    assert corrugation.speed_m_per_s == pytest.approx(80 / 3.6, rel=1e-5)


@pytest.mark.parametrize("name", NAMES)
def test_scene_runs(name):
    scene = load(name)
    provider = "conical" if scene.track.is_conical else "tables"
    result = simulate(replace(scene, duration_s=0.01, contact_provider=provider))
    assert result.success, result.message
    peaks = result.summary()["peak_normal_force_N"]
    assert peaks["left"] > 0.5 * scene.static_wheel_load_N and peaks["right"] > 0.5 * scene.static_wheel_load_N
    assert np.all(np.isfinite(result.states))
