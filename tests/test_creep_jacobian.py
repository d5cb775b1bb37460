"""The wheelset Jacobian's velocity columns from the creep-force sensitivities (rigid_dynamics.wheelset.creep_jacobian).

References: the held-force assembly against the model's own right-hand side (a regression test of a second path
through compiled_motion._assemble), and the columns against central differences of the right-hand side (an
independent derivative of the same equations: the compiled law differenced, not the Python rung's sensitivities).
Numbers measured on hunting-conical at y = 2 mm, y' = 0.05 m/s, psi' = 0.02 rad/s (both wheels creeping):
linear 3e-8, FASTSIM 2e-8 (relative to each acceleration row's largest entry), the BEM 0.5 % against differences
with steps 1e-6..1e-4 (its differences at 1e-7 are noise: two of them differ by 5 %).
"""

import dataclasses

import numpy as np
import pytest

from rigid_dynamics.wheelset.creep_jacobian import (
    _Patches,
    creep_velocity_columns,
    difference_velocity_columns,
    held_rates,
    relative_difference,
)
from rigid_dynamics.wheelset.parameters import TrackDynamics
from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, initial_state, model_options
from rigid_dynamics.wheelset.wheelset_model import WheelsetModel
from wheelrail.scenes import load_scene


@pytest.fixture(scope="module")
def scene_and_provider():
    scene = load_scene("hunting-conical")
    return scene, build_provider(scene)


def _model_at_creeping_state(scene, provider, name):
    scene = dataclasses.replace(scene, contact_model=name)
    model = WheelsetModel(scene, provider, get_contact_model(name), model_options(name, scene))
    state, ok, why = model.static_state(initial_state(scene)[:12])
    assert ok, why
    full = model.full_state(state)
    full[1] += 0.002
    full[7] += 0.05
    full[9] += 0.02
    return model, full


@pytest.mark.parametrize("name", ["linear", "fastsim"])
def test_held_assembly_is_the_right_hand_side(scene_and_provider, name):
    model, full = _model_at_creeping_state(*scene_and_provider, name)
    patches = _Patches(model, full)
    assert len(patches) == 2
    np.testing.assert_allclose(held_rates(model, 0.0, full, patches, patches.forces), model.derivative(0.0, full),
                               rtol=1e-12, atol=1e-12)  # fmt: skip


@pytest.mark.parametrize(("name", "tolerance"), [("linear", 1e-6), ("vermeulen-johnson", 1e-6), ("fastsim", 1e-6)])
def test_velocity_columns_against_differences(scene_and_provider, name, tolerance):
    model, full = _model_at_creeping_state(*scene_and_provider, name)
    columns = creep_velocity_columns(model, 0.0, full)
    reference = difference_velocity_columns(model, 0.0, full)
    assert columns.patches == 2
    error = relative_difference(columns.columns, reference)
    assert error < tolerance, f"{name}: relative difference {error:.3g}"
    assert np.any(np.abs(reference[6:12]) > 0)


def test_bem_velocity_columns_against_differences_with_a_step_above_its_noise(scene_and_provider):
    """The BEM (callback rung): its right-hand side differenced with the step 1e-5 max(1, |v|) against the
    sensitivity columns: 0.5 % measured; asserted 2 %."""
    model, full = _model_at_creeping_state(*scene_and_provider, "bem")
    columns = creep_velocity_columns(model, 0.0, full)
    reference = difference_velocity_columns(model, 0.0, full, rel_step=1e-5)
    assert relative_difference(columns.columns, reference) < 0.02


def test_elastic_track_is_refused(scene_and_provider):
    scene, _ = scene_and_provider
    scene = dataclasses.replace(scene, track_dynamics=TrackDynamics(model="lumped"), contact_model="linear")
    provider = build_provider(scene)
    model = WheelsetModel(scene, provider, get_contact_model("linear"), None)
    with pytest.raises(ValueError, match="the elastic track"):
        creep_velocity_columns(model, 0.0, model.full_state(initial_state(scene)[:12]))


def test_implicit_methods_take_the_sensitivity_columns_for_a_called_back_rung_only(scene_and_provider):
    from rigid_dynamics.wheelset.drivers import sensitivity_velocity_columns

    scene, provider = scene_and_provider
    for name, expected in (("linear", False), ("fastsim", False), ("bem", True)):
        sc = dataclasses.replace(scene, contact_model=name)
        model = WheelsetModel(sc, provider, get_contact_model(name), model_options(name, sc))
        assert (sensitivity_velocity_columns(model) is not None) == expected, name


def test_state_jacobian_with_given_velocity_columns_and_its_fallback(scene_and_provider):
    """drivers.state_jacobian with the sensitivity columns (here of the linear rung, whose differences are exact to
    3e-8) agrees with its all-difference Jacobian; a velocity-column function that raises leaves the differences."""
    from rigid_dynamics.wheelset.drivers import state_jacobian

    model, full = _model_at_creeping_state(*scene_and_provider, "linear")
    plain = state_jacobian(model.derivative)(0.0, full)
    given = state_jacobian(model.derivative, lambda t, y: creep_velocity_columns(model, t, y).columns)(0.0, full)
    assert relative_difference(given[:, 6:12], plain[:, 6:12]) < 1e-5
    np.testing.assert_array_equal(given[:, :6], plain[:, :6])

    def refuse(t, y):
        raise ValueError("no sensitivities here")

    np.testing.assert_array_equal(state_jacobian(model.derivative, refuse)(0.0, full), plain)
