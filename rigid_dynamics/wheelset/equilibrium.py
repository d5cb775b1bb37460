"""The start of a run: the initial 12-state, the static equilibrium of z and roll with free rolling
(:func:`consistent_start`), the elastic track at rest under the wheels (:func:`elastic_start`), and their
compiled right-hand-side versions.
"""

from __future__ import annotations

import numpy as np

from rigid_dynamics.wheelset.layout import MAX_SLOTS
from rigid_dynamics.wheelset.parameters import DynamicsScene
from rigid_dynamics.wheelset.state import TRACK
from rigid_dynamics.wheelset.wheelset_model import ContactFailure, WheelsetModel


def initial_state(scene: DynamicsScene) -> np.ndarray:
    """The 12-state at t = 0 before the static equilibrium of z and theta (see InitialConditions)."""
    ic = scene.initial
    r0 = scene.wheelset.nominal_radius_m
    v = scene.speed_m_per_s
    state = np.zeros(12)
    state[1] = ic.lateral_displacement_m
    state[2] = -r0 + 1e-4
    state[3] = ic.yaw_rad
    state[6] = v
    state[7] = ic.lateral_velocity_m_per_s
    state[8] = ic.vertical_velocity_m_per_s
    state[9] = ic.yaw_rate_rad_per_s
    state[11] = (1.0 - ic.longitudinal_creepage) * v / r0
    return state


def side_force_sums(table: dict) -> np.ndarray:
    """Per wheel (left, right) the normal, longitudinal and lateral creep forces summed over the patches in contact,
    (2, 3), N, from a patch table (PATCH_FIELDS -> (2, MAX_SLOTS)).
    """
    names = ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")
    touching = np.nan_to_num(table["normal_force_N"], nan=0.0) > 0
    return np.stack([np.where(touching, np.nan_to_num(table[n], nan=0.0), 0.0).sum(axis=1) for n in names], axis=1)


def contact_force_sums(model: WheelsetModel, state: np.ndarray) -> np.ndarray:
    """:func:`side_force_sums` of the contact at a 12-state (the Python path's force error estimate)."""
    contact = model.contact(state[:12], record=True, track=state[TRACK] if model.elastic else None)
    table = {
        name: np.full((2, MAX_SLOTS), np.nan) for name in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")
    }
    for k in range(len(contact.side)):
        side, slot = int(contact.side[k]), int(contact.slot[k])
        if slot < MAX_SLOTS:
            for name in table:
                table[name][side, slot] = contact.values[name][k]
    return side_force_sums(table)


def rolling_radii(sides, normal_N, radius_m) -> np.ndarray:
    """Rolling radius of each wheel (left, right), m: the radii of its patches in contact weighted by their normal
    forces; NaN for a wheel without contact.
    """
    sides = np.asarray(sides)
    normal = np.nan_to_num(np.asarray(normal_N, float), nan=0.0)
    radius = np.nan_to_num(np.asarray(radius_m, float), nan=0.0)
    out = np.full(2, np.nan)
    for i in (0, 1):
        w = np.where((sides == i) & (normal > 0), normal, 0.0)
        if w.sum() > 0:
            out[i] = float(np.sum(w * radius) / w.sum())
    return out


MAX_STATIC_APPROACH_SHARE = 0.01
"""The largest static approach accepted, as a share of the nominal wheel radius (4.6 mm at 0.46 m; steel wheels on
steel rails: about 0.1 mm). Beyond it the patch is no small region of two half-spaces; the start is refused
(a material with G = 1 Pa put the cone's tabulated wheel 2.3 km into the rail and the run said ok)."""


def elastic_start(model: WheelsetModel, state: np.ndarray, derivative=None, deepest=None, rolling=None):
    """:func:`consistent_start` with the elastic track at rest under the wheels (the rigid track: that alone).

    The track starts deflected by the static wheel load (``model.track_rest``), then wheelset equilibrium and
    track deflection under the contact forces found (vertical, and lateral with the lateral track) are alternated
    until the rail forces change by < 1e-6 of the static wheel load (at most 8 rounds; each round solves the
    wheelset's equilibrium on a fixed track).
    """
    if not model.elastic:
        return consistent_start(model, state, derivative, deepest, rolling)
    load = model.scene.static_wheel_load_N
    model.track_rest = model.static_track([load, load])
    derivative_ = model.derivative if derivative is None else derivative
    out = (state, False, "no rounds")
    before = np.array([load, load] + ([0.0, 0.0] if model.track.lateral else []), float)
    for _ in range(8):
        out = consistent_start(model, state, derivative, deepest, rolling)
        if not out[1]:
            return out
        force = _rail_forces(model, out[0], derivative_)
        model.track_rest = model.static_track(force)
        state = out[0]
        if np.max(np.abs(force - before)) < 1e-6 * load:
            break
        before = force
    return consistent_start(model, state, derivative, deepest, rolling)


def _rail_forces(model: WheelsetModel, state: np.ndarray, derivative) -> np.ndarray:
    """Vertical contact force on each rail (left, right; then the lateral ones with the lateral track) at a 12-state
    on ``track_rest``, N, from the track acceleration the right-hand side gives (at rest b F = M q'' + K q:
    track_matrices.TrackSystem.rail_forces_at_rest).
    """
    d = derivative(0.0, model.full_state(state))
    return model.track_system.rail_forces_at_rest(model.track_rest, d[TRACK])


def consistent_start(model: WheelsetModel, state: np.ndarray, derivative=None, deepest=None, rolling=None):
    """A consistent rolling start from the 12-state of :func:`initial_state`: (state, success, message).

    1. Static equilibrium of z and roll at the initial lateral offset and yaw (WheelsetModel.static_state).
    2. Free rolling: the spin rate phi' (and, with ``initial.free_rolling``, the yaw rate psi') at which the
       spin and yaw accelerations vanish, by Newton steps from V / r_roll (r_roll the mean of the two wheels'
       rolling radii, each the normal-force-weighted mean over its patches) and the given yaw rate; phi' is then
       scaled by (1 - xi0) with xi0 the scene's ``initial.longitudinal_creepage``. With V / r0 (r0 the nominal
       radius) a profiled wheel off its tape circle starts with a common longitudinal creepage (r_roll - r0)/r0;
       with psi' = 0 an offset wheelset starts with the creepages +-(r_right - r_left)/(2 r_roll): both a
       creep-force spike at t = 0. With the solved psi' the wheelset starts on its kinematic (Klingel) path,
       psi' = -V (r_right - r_left)/(2 e0 r_roll) to first order, at the extreme of the offset.
    3. The static equilibrium again at that spin rate.

    ``derivative``, ``deepest``, ``rolling``: replacements; None: the model's own (the compiled right-hand side).
    """
    state, ok, why = model.static_state(state, derivative, deepest)
    if not ok:
        return state, ok, why
    contact = model.contact(state[:12], record=True)  # on model.track_rest
    approach = float(np.nanmax(contact.values["approach_m"], initial=0.0))
    r0 = model.scene.wheelset.nominal_radius_m
    if approach > MAX_STATIC_APPROACH_SHARE * r0:
        return (
            state,
            False,
            (
                f"the static approach {approach:.3g} m is {approach / r0:.3g} of the wheel radius (more than "
                f"{MAX_STATIC_APPROACH_SHARE:g}): the contact laws' elastic half-space does not hold there (is the "
                f"shear modulus {model.scene.material.shear_modulus_Pa:.3g} Pa meant?)"
            ),
        )
    if rolling is None:
        radii = rolling_radii(contact.side, contact.values["normal_force_N"], contact.values["rolling_radius_m"])
    else:
        radii = rolling(state)
    if not np.all(np.isfinite(radii)):
        return state, False, f"a wheel has no contact at the static equilibrium (rolling radii {radii} m)"
    derivative = model.derivative if derivative is None else derivative
    state = state.copy()
    ic = model.scene.initial
    # in a curve the yaw rate (relative to the track) is kept: a free-rolling yaw rate there would be about -V/R,
    # the wheelset leaving the curve
    solve_yaw = ic.free_rolling and not model.scene.track.curved
    rolling_rate = model.scene.speed_m_per_s / float(np.mean(radii))

    def residual(rates):
        trial = model.full_state(state)
        trial[11] = rates[0]
        if solve_yaw:
            trial[9] = rates[1]
        try:
            d = derivative(0.0, trial)
        except ContactFailure:
            return np.full(2, np.nan)
        return np.array([d[11], d[9] if solve_yaw else 0.0])

    # Newton with a forward-difference Jacobian on (spin rate, yaw rate): the creep forces are about linear in them
    rates = np.array([rolling_rate, state[9]])
    steps = np.array([1e-6 * rolling_rate, 1e-6 * rolling_rate * model.scene.wheelset.nominal_radius_m])
    r = residual(rates)
    for _ in range(8):
        if not np.all(np.isfinite(r)):
            break
        jac = np.eye(2)
        for k in range(2 if solve_yaw else 1):
            trial = rates.copy()
            trial[k] += steps[k]
            jac[:, k] = (residual(trial) - r) / steps[k]
        try:
            delta = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            break
        if not np.all(np.isfinite(delta)):
            break
        rates = rates + delta
        r = residual(rates)
        if abs(delta[0]) < 1e-12 * rolling_rate and abs(delta[1]) < 1e-12 * rolling_rate:
            break
    if not np.all(np.isfinite(rates)) or abs(rates[0] / rolling_rate - 1.0) > 0.01:
        rates = np.array([rolling_rate, state[9]])  # no free-rolling solution nearby: the rolling radii alone
    state[11] = (1.0 - ic.longitudinal_creepage) * rates[0]
    state[9] = rates[1]
    return model.static_state(state, derivative, deepest)
