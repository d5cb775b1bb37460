"""Validation of the wheelset-dynamics parameter dataclasses: every bad-input path raises a ValueError naming it."""

import dataclasses

import pytest

from rigid_dynamics.wheelset.linear import LinearWheelset
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    Irregularities,
    LoadParameters,
    SuspensionParameters,
    TrackGeometry,
    WheelsetParameters,
)
from rigid_dynamics.wheelset.providers import TableProvider


def test_defaults_are_valid_and_frozen():
    scene = DynamicsScene()
    assert scene.static_wheel_load_N == pytest.approx(0.5 * (1813.0 * 9.80665 + 160e3))
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.speed_m_per_s = 3.0


@pytest.mark.parametrize(
    ("cls", "kwargs", "match"),
    [
        (WheelsetParameters, {"mass_kg": -1.0}, "mass_kg = -1.0: expected a number > 0"),
        (WheelsetParameters, {"nominal_radius_m": float("nan")}, "nominal_radius_m = nan: expected a finite"),
        (SuspensionParameters, {"lateral_stiffness_N_per_m": -5.0}, "lateral_stiffness_N_per_m = -5.0"),
        (SuspensionParameters, {"yaw_damping_N_m_s_per_rad": float("inf")}, "yaw_damping_N_m_s_per_rad = inf"),
        (LoadParameters, {"axle_load_N": -1.0}, "axle_load_N = -1.0: expected a number >= 0"),
        (TrackGeometry, {"conicity": 1.5}, r"conicity = 1.5: expected a value in \[0, 1\)"),
        (TrackGeometry, {"rail_head_radius_m": 0.0}, "rail_head_radius_m = 0.0"),
        (TrackGeometry, {"wheel_profile": ""}, "wheel_profile = '': expected a profile name"),
        (TrackGeometry, {"rail_inclination_rad": 0.5}, "rail_inclination_rad = 0.5"),
        (Irregularities, {"polygon_order": 2.5}, "polygon_order = 2.5: expected an integer"),
        (Irregularities, {"flat_length_m": -0.01}, "flat_length_m = -0.01"),
        (Irregularities, {"side": "middle"}, "side = 'middle': expected one of both, left, right"),
        (Irregularities, {"corrugation_amplitude_m": 1e-5}, "corrugation_wavelength_m = 0.0: expected > 0"),
        (IntegratorSettings, {"method": "Euler"}, "method = 'Euler': expected one of RK45"),
        (IntegratorSettings, {"fixed_step_s": 0.0}, "fixed_step_s = 0.0: expected a number > 0"),
        (IntegratorSettings, {"max_rhs_evaluations": 0}, "max_rhs_evaluations = 0"),
        (InitialConditions, {"yaw_rad": 0.5}, r"yaw_rad = 0.5: expected \|value\| <= 0.2"),
        (InitialConditions, {"lateral_displacement_m": float("nan")}, "lateral_displacement_m = nan"),
        (DynamicsScene, {"speed_m_per_s": 0.0}, "speed_m_per_s = 0.0: expected a number > 0"),
        (DynamicsScene, {"duration_s": -1.0}, "duration_s = -1.0"),
        (DynamicsScene, {"contact_provider": "magic"}, "contact_provider = 'magic': expected one of auto"),
        (DynamicsScene, {"contact_model": ""}, "contact_model = '': expected a registered model name"),
        (DynamicsScene, {"fastsim_strips": 0}, "fastsim_strips = 0: expected an integer from 1 to 1000"),
        (DynamicsScene, {"fastsim_elements_per_strip": 12.0}, "fastsim_elements_per_strip = 12.0: expected an int"),
        (DynamicsScene, {"wheelset": {"mass_kg": 1.0}}, "wheelset = .*: expected a WheelsetParameters"),
    ],
)
def test_bad_input_names_the_field(cls, kwargs, match):
    with pytest.raises(ValueError, match=match):
        cls(**kwargs)


def test_linear_model_and_table_bad_input():
    with pytest.raises(ValueError, match="mass_kg = 0.0: expected > 0"):
        LinearWheelset(0.0, 1.0, 0.05, 0.46, 0.75, 1e6, 1e6)
    with pytest.raises(ValueError, match="creep_long_N = -1.0: expected >= 0"):
        LinearWheelset(1.0, 1.0, 0.05, 0.46, 0.75, -1.0, 1e6)
    with pytest.raises(ValueError, match="speed_m_per_s = 0.0: expected > 0"):
        LinearWheelset(1.0, 1.0, 0.05, 0.46, 0.75, 1.0, 1.0).state_matrix(0.0)
    with pytest.raises(ValueError, match="lateral_step_m = 0.0: expected a finite number > 0"):
        TableProvider(None, 0.46, lateral_step_m=0.0)
    with pytest.raises(ValueError, match="roll_points = 1: expected an integer >= 2"):
        TableProvider(None, 0.46, roll_points=1)
