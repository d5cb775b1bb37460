"""The one right-hand side (rigid_dynamics.wheelset.compiled_rhs) in its compiled RK4 loop, against references.

Independent references: Klingel's kinematic wavelength 2 pi sqrt(r0 e0 / lambda) on the compiled tables; the
energy balance d(T + V_g)/dt = P_contact + P_exterior (the work integrals are integrated with the states, so the
residual is the integration error only) for every compiled law and running-direction irregularity; the registry's
contact models (exact Hertz solver and Kalker's coefficients, not the loop's tables) solving the patches through the
callback boundary against the compiled laws; ``auto``'s documented choice (contact.auto.choose_rung) on the recorded
features. Regression (labelled): the scene's FASTSIM grid reaches the loop.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from rigid_dynamics.contact.models import LinearModel
from rigid_dynamics.wheelset.parameters import (
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    Irregularities,
    SuspensionParameters,
    TrackGeometry,
)
from rigid_dynamics.wheelset.simulate import build_provider, simulate

SCENE = DynamicsScene(
    track=TrackGeometry(rail_head_radius_m=0.05),
    contact_provider="tables",
    speed_m_per_s=30.0,
    duration_s=0.1,
    suspension=SuspensionParameters(
        longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5, vertical_damping_N_s_per_m=1e5
    ),
    initial=InitialConditions(lateral_displacement_m=0.002, yaw_rate_rad_per_s=0.01, vertical_velocity_m_per_s=0.01),
    integrator=IntegratorSettings(method="RK4", fixed_step_s=5e-4, output_step_s=1e-3),
)


IRREGULARITIES = {
    "none": Irregularities(),
    "polygon": Irregularities(polygon_order=3, polygon_amplitude_m=3e-4),
    "flat": Irregularities(flat_length_m=0.05),
    "corrugation-right": Irregularities(corrugation_wavelength_m=0.05, corrugation_amplitude_m=3e-5, side="right"),
}


def test_klingel_wavelength_in_the_compiled_loop():
    """No suspension, Kalker linear creep, 20 m/s, 3 mm start, the conical section's tables in the compiled loop:
    wavelength within 1 % of Klingel's 2 pi sqrt(r0 e0 / lambda) (rail head 50 mm: roll correction 0.3 %)."""
    r0, e0, lam = 0.46, 0.75, 0.05
    scene = DynamicsScene(
        track=TrackGeometry(conicity=lam, rail_head_radius_m=0.05),
        contact_provider="tables",
        speed_m_per_s=20.0,
        duration_s=1.8,
        contact_model="linear",
        initial=InitialConditions(lateral_displacement_m=0.003),
        integrator=IntegratorSettings(method="RK4", fixed_step_s=5e-4, output_step_s=1e-3),
    )
    result = simulate(scene, compiled=True)
    assert result.success and result.compiled, result.message
    klingel = 2 * math.pi * math.sqrt(r0 * e0 / lam)
    measured = result.summary()["dominant_lateral_wavelength_m"]
    assert measured == pytest.approx(klingel, rel=0.01)


@pytest.mark.parametrize(
    ("model", "irregularity"),
    [
        ("hertz", "none"),
        ("linear", "none"),
        ("vermeulen-johnson", "none"),
        ("fastsim", "none"),
        ("fastsim", "polygon"),
        ("vermeulen-johnson", "flat"),
        ("linear", "corrugation-right"),
    ],
)
def test_energy_balance_in_the_compiled_loop(model, irregularity):
    """T + V_g changes by the work of the contact and exterior forces: the residual is RK4's error on the work
    integrals, which falls at least 4-fold with each halving of the step (a missing or wrong power term would not
    fall; 4: second order at least, as the flat's impact leaves), to below 1e-3 of the energy exchanged (the larger of
    the two works' ranges and the kinetic swing) at 0.125 ms."""
    scene = replace(SCENE, contact_model=model, irregularities=IRREGULARITIES[irregularity])
    residuals = []
    for step in (2.5e-4, 1.25e-4):
        result = simulate(replace(scene, integrator=replace(scene.integrator, fixed_step_s=step)), compiled=True)
        assert result.success and result.compiled, result.message
        residuals.append(np.max(np.abs(result.energy_residual_J)))
    exchanged = max(np.ptp(result.work_contact_J), np.ptp(result.work_exterior_J), np.ptp(result.kinetic_energy_J))
    assert exchanged > 1.0
    assert residuals[1] < residuals[0] / 4
    assert residuals[1] < 1e-3 * exchanged
    assert np.nanmax(result.patches["normal_force_N"]) > 0.5 * scene.static_wheel_load_N
    if model == "hertz":
        assert np.all(np.nan_to_num(result.patches["creep_force_lat_N"]) == 0.0)


class ExternalLinear(LinearModel):
    """The registry's linear model as a user model that declares no compiled law (``compiled_law = None``), so it
    runs through the callback boundary (a subclass that keeps its parent's law would run the compiled one)."""

    name = "external-linear"
    compiled_law = None


def test_callback_boundary_gives_the_registry_model_solution():
    """A user model (the registry's linear theory with the exact Hertz solver and Kalker's coefficients) solves every
    patch through the callback inside the compiled loop; the compiled linear law (tables) gives the same run to the
    tables' interpolation error (1e-7 of the forces), and the callback was called for every patch in contact."""
    provider = build_provider(SCENE)
    scene = replace(SCENE, duration_s=0.03)
    user = simulate(scene, provider=provider, contact_model=ExternalLinear(), compiled=True)
    inline = simulate(scene, provider=provider, contact_model="linear", compiled=True)
    assert user.success and inline.success and user.compiled
    load = scene.static_wheel_load_N
    for name in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N"):
        diff = np.nanmax(np.abs(user.patches[name] - inline.patches[name]))
        assert diff < 1e-5 * load, name
    np.testing.assert_allclose(user.states[:, 1], inline.states[:, 1], rtol=0, atol=1e-9)


class Failing(LinearModel):
    name = "failing"
    compiled_law = None  # its own solve: through the callback

    def solve(self, *args, **kwargs):
        raise RuntimeError("no answer")


class FailingLater(LinearModel):
    name = "failing-later"
    compiled_law = None  # its own solve: through the callback

    def solve(self, geometry, creepage, material, **kwargs):
        if FailingLater.armed:
            raise RuntimeError("no answer")
        return super().solve(geometry, creepage, material, **kwargs)


def _arm_failing_later_in_the_loop(monkeypatch):
    """FailingLater answers until the compiled loop starts (the equilibrium before it succeeds), then raises.
    Returns the unpatched run_compiled."""
    import importlib

    simulate_module = importlib.import_module("rigid_dynamics.wheelset.simulate")
    run = simulate_module.run_compiled

    def armed(*args, **kwargs):
        FailingLater.armed = True
        return run(*args, **kwargs)

    FailingLater.armed = False
    monkeypatch.setattr(simulate_module, "run_compiled", armed)
    return run


def test_callback_failure_is_a_status(monkeypatch):
    """A user model that raises: at the start the run has no equilibrium and says why; in the loop the run stops
    with "contact-failed" and the model's message."""
    result = simulate(replace(SCENE, duration_s=0.01), contact_model=Failing(), compiled=True)
    assert result.status == "invalid-initial-state" and not result.success
    assert "'failing' raised" in result.message and "no answer" in result.message
    _arm_failing_later_in_the_loop(monkeypatch)
    result = simulate(replace(SCENE, duration_s=0.01), contact_model=FailingLater(), compiled=True)
    assert result.status == "contact-failed" and not result.success
    assert "'failing-later' raised" in result.message and "no answer" in result.message


def test_auto_choice_in_the_loop_is_the_documented_rule():
    """``auto`` in the compiled loop records per patch the rung, the level and the deciding feature; on the recorded
    features contact.auto.choose_rung (the rule the contact JSON documents) chooses the same rung."""
    from rigid_dynamics.contact.auto import AUTO_RUNGS, FEATURES, choose_rung

    scene = replace(SCENE, contact_model="auto", contact_tolerance=0.1, duration_s=0.05)
    result = simulate(scene, compiled=True)
    assert result.success and result.compiled, result.message
    rung = result.patches["auto_rung"]
    touching = np.isfinite(rung)
    assert np.any(touching)
    assert np.all(result.patches["auto_level"][touching] == 0.1)
    for idx in zip(*np.nonzero(touching), strict=True):
        features = {f: float(result.patches[f"auto_{f}"][idx]) for f in FEATURES}
        choice = choose_rung(features, scene.contact_tolerance, fastsim_grid=(20, 20))
        # a BEM patch served by its stored solution's correction (wheelset/auto_reuse.py) is recorded as such
        served = AUTO_RUNGS[int(rung[idx])]
        assert (served if served != "bem-corrected" else "bem") == choice["model"]
        deciding = int(result.patches["auto_deciding_feature"][idx])
        assert FEATURES[deciding] == choice["deciding_feature"]


def test_auto_below_every_level_solves_by_bem_through_the_callback(monkeypatch):
    """A tolerance below the smallest measured level: every patch BEM (through the callback), level NaN. The
    choice is the subject here, not the BEM's grid: its default grid is not refined (``max_refinements`` 0; each
    patch then ends "warning" with its grid-error estimate, and so does the run), which keeps the test at seconds."""
    from rigid_dynamics.contact.bem import model as bem_model
    from rigid_dynamics.contact.options import Option

    monkeypatch.setitem(bem_model.OPTIONS, "max_refinements", Option("max_refinements", int, 0, "test", minimum=0))
    scene = replace(SCENE, contact_model="auto", contact_tolerance=0.001, duration_s=0.002)
    result = simulate(scene, compiled=True)
    # the unrefined 40 x 40 patches are coarser than the BEM's 2 % asks: the run says so (discretisation.py)
    assert result.status == "warning" and result.compiled, result.message
    assert "BEM grid-error estimate of the patch forces" in result.message
    rung = result.patches["auto_rung"]
    touching = np.isfinite(rung)
    assert np.any(touching) and np.all(rung[touching] == 3)
    assert np.all(np.isnan(result.patches["auto_level"][touching]))
    assert np.all(result.patches["normal_force_N"][touching] > 0)


def test_fastsim_grid_reaches_the_loop():
    """Regression: the scene's FASTSIM grid is the one the loop uses (10 x 6 moves the lateral creep forces by more
    than 1 N against 20 x 20)."""
    provider = build_provider(SCENE)
    scene = replace(SCENE, contact_model="fastsim", fastsim_elements_per_strip=10, fastsim_strips=6, duration_s=0.03)
    coarse = simulate(scene, provider=provider, compiled=True)
    fine = simulate(replace(scene, fastsim_elements_per_strip=20, fastsim_strips=20), provider=provider, compiled=True)
    assert np.nanmax(np.abs(fine.patches["creep_force_lat_N"] - coarse.patches["creep_force_lat_N"])) > 1.0


def test_compiled_stops_and_refuses():
    scene = replace(SCENE, contact_model="linear", integrator=replace(SCENE.integrator, fixed_step_s=0.02))
    result = simulate(scene, compiled=True)
    # a 20 ms step is far beyond RK4's stability limit: the failure is named as the integrator's (stability.py)
    assert result.status == "step-unstable" and not result.success
    assert "stability limit" in result.message
    assert result.failure_state is not None and np.all(np.isfinite(result.states))
    with pytest.raises(ValueError, match="compiled = True: the compiled loop needs method RK4"):
        simulate(replace(scene, integrator=IntegratorSettings(method="RK45")), compiled=True)


def test_embedded_pair_names_a_callback_failure_and_records_auto(monkeypatch):
    """The compiled DP54 loop: a model behind the callback that fails mid-run ends the run "contact-failed" with the
    model's message (a model's failure is not retried at smaller steps down to "step-size-underflow"); with ``auto``
    the per-patch choice is recorded as in the RK4 loop (both loops through drivers.patch_tables)."""
    dp54 = replace(SCENE, integrator=replace(SCENE.integrator, method="DP54"), duration_s=0.01)
    _arm_failing_later_in_the_loop(monkeypatch)
    result = simulate(dp54, contact_model=FailingLater(), compiled=True)
    assert result.status == "contact-failed" and not result.success, result.message
    assert "'failing-later' raised" in result.message and "no answer" in result.message
    monkeypatch.undo()  # run_compiled unpatched again
    auto = simulate(replace(dp54, contact_model="auto", contact_tolerance=0.1), compiled=True)
    assert auto.success and auto.compiled and auto.method == "DP54", auto.message
    assert np.any(np.isfinite(auto.patches["auto_rung"]))
