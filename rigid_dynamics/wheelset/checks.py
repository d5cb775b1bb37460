"""Checks of a whole scene that join several of its tables (each dataclass checks its own fields).

A scene can be valid table by table and still describe no physical wheelset: a flat longer than the
wheel's diameter, a polygon deeper than the radius, the analytic conical provider asked to serve real
profiles, a contact model that is not registered. :func:`check_scene` finds these before any work and
raises :class:`SceneError` naming the key (dotted, as in a scene file), its value and what was expected.
"""

from __future__ import annotations

from rigid_dynamics.wheelset.parameters import DynamicsScene


class SceneError(ValueError):
    """A scene that cannot be run. Attributes: ``key`` (dotted), ``value``, ``expected`` (words)."""

    def __init__(self, key: str, value, expected: str):
        self.key, self.value, self.expected = key, value, expected
        super().__init__(f"{key} = {value!r}: expected {expected}")


def check_scene(scene: DynamicsScene) -> None:
    """Raise SceneError for the first inconsistency between the scene's tables (module docstring).

    Checks:
        contact_model: a registered model name (rigid_dynamics.contact.registry.MODELS); "table" (and creep_table)
            with Coulomb friction only (contact.creep_table: falling friction is not tabulated).
        creep_table: true only with contact_model "auto".
        contact_provider: "conical" only with wheel_profile "conical" and rail_profile "circular" (the analytic
            pair). ("search" serves both: on the analytic pair it searches the ideal cone and circular rail head.)
        irregularities.flat_length_m: L < 2 r0 (a flat is a chord of the wheel).
        irregularities.flat_depth_m: d < r0; the derived d = L^2/(16 r0) is then < r0/4.
        irregularities.polygon_amplitude_m: A < r0, and A n^2 < r0 (the radius of curvature of
            r0 + A cos(n alpha) at a trough, r0 - A n^2 roughly, stays > 0: the wheel stays convex).
    """
    from rigid_dynamics.contact.registry import MODELS

    _check_traction(scene)
    if isinstance(scene.contact_model, str) and scene.contact_model not in MODELS:
        raise SceneError("contact_model", scene.contact_model, "one of " + ", ".join(MODELS))
    _check_creep_table(scene)
    track, irr = scene.track, scene.irregularities
    r0 = scene.wheelset.nominal_radius_m
    if scene.contact_provider == "conical" and not track.is_conical:
        raise SceneError(
            "contact_provider",
            scene.contact_provider,
            "'auto', 'tables' or 'search' for the profiles "
            f"{track.wheel_profile!r} / {track.rail_profile!r} (the analytic 'conical' provider serves only "
            "track.wheel_profile = 'conical' with track.rail_profile = 'circular')",
        )
    if irr.flat_length_m >= 2.0 * r0:
        raise SceneError(
            "irregularities.flat_length_m",
            irr.flat_length_m,
            f"a length < 2 r0 = {2.0 * r0:g} m (a flat is a chord of the wheel, wheelset.nominal_radius_m = {r0:g})",
        )
    if irr.flat_depth_m >= r0:
        raise SceneError(
            "irregularities.flat_depth_m",
            irr.flat_depth_m,
            f"a depth < r0 = {r0:g} m (wheelset.nominal_radius_m; real flats are below a few mm)",
        )
    if irr.polygon_order > 0 and irr.polygon_amplitude_m > 0:
        n, amplitude = irr.polygon_order, irr.polygon_amplitude_m
        limit = r0 / max(n * n, 1)
        if amplitude >= limit:
            raise SceneError(
                "irregularities.polygon_amplitude_m",
                amplitude,
                f"an amplitude < r0 / n^2 = {limit:.4g} m for polygon_order n = {n} and r0 = {r0:g} m (beyond it "
                "the wheel is no longer convex, or no longer round at all)",
            )


TRACTION_METHODS = ("RK4", "DP54", "BS32")
"""Integrator methods that run the traction controller (the compiled loop's, stopped at each sample)."""


def _check_traction(scene: DynamicsScene) -> None:
    """A [traction] controller sets the torque: no constant torque beside it, a method of the compiled loop."""
    control = scene.traction
    if not control.active:
        return
    if scene.loads.traction_torque_N_m != 0.0:
        raise SceneError(
            "loads.traction_torque_N_m",
            scene.loads.traction_torque_N_m,
            f"0 with traction.mode = {control.mode!r} (the controller sets the torque; remove one of the two)",
        )
    if scene.integrator.method not in TRACTION_METHODS:
        raise SceneError(
            "integrator.method",
            scene.integrator.method,
            f"one of {', '.join(TRACTION_METHODS)} with traction.mode = {control.mode!r} (the controller runs in "
            "the compiled loop, sampled at the output times)",
        )


def _check_creep_table(scene: DynamicsScene) -> None:
    """The creep-force table's scene keys: ``creep_table`` with auto only; the table with Coulomb friction only."""
    if scene.creep_table and scene.contact_model != "auto":
        raise SceneError(
            "creep_table",
            scene.creep_table,
            f"false with contact_model {scene.contact_model!r} (it serves auto's FASTSIM rung; contact_model "
            "'table' is the table for every patch)",
        )
    if scene.contact_model == "table" or scene.creep_table:
        law = scene.material.friction
        if law is not None and not law.is_coulomb:
            key = "contact_model" if scene.contact_model == "table" else "creep_table"
            raise SceneError(
                key,
                getattr(scene, key),
                f"Coulomb friction ([friction] law = 'coulomb'; this scene's falls with the slip velocity, "
                f"{law.laws[0].law} form, which the creep-force table does not tabulate): use contact_model 'fastsim'",
            )
