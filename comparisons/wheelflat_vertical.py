"""A second method for the wheel-flat impact: the classical vertical model, written apart from the wheelset code.

Half a wheelset (unsprung mass m_w = half the wheelset, carrying the static wheel load P0 = m_w g + F_axle / 2
as a constant force, plus the scene's primary vertical spring k_s and damper c_s to the frame) on a nonlinear
Hertz spring N = C_H delta^(3/2) on the lumped track of the scene (rail mass m_r on pad k_p, c_p on sleeper mass
m_s on ballast k_b, c_b), or on a rigid rail. Everything is vertical and one-dimensional; z is down, from the
unloaded track. The flat enters as the relative displacement of a rigid wheel rolling over a rigid flat rail,
the drop of the wheel centre

    e(x) = r0 - max_a r(a) cos(a - x / r0),        r(a) = r0 + R_irr(a),

with R_irr the rounded flat of rigid_dynamics.wheelset.irregular (-(d/2)(1 + cos(2 pi s / L)) over |s| < L/2,
s = r0 a, centred at x_c): the wheel-centre trajectory, not the profile deviation, as the input of a Hertz
spring (Wu & Thompson 2002, J. Sound Vib. 251: "a relative displacement excitation is introduced between the
wheel and rail that differs from the geometric form of the wheel flat due to the finite curvature of the wheel";
Pieringer, Kropp et al. 2014, "The influence of contact modelling on simulated wheel/rail interaction due to
wheel flats", abstract at research.chalmers.se/publication/197497: the Hertzian spring with the wheel-centre
trajectory as input gives results similar to a 3-D non-Hertzian contact model, with the profile deviation as input
it can give large errors).

What it leaves out against the wheelset model (rigid_dynamics.wheelset): the 3-D contact geometry of the flat
(the contact point's longitudinal shift and the curvature of the flattened tread, which change the Hertz
constant during the impact; here C_H is that of the round wheel), roll, lateral and yaw motion, creep forces.
What it can add: a pad that cannot pull the rail down (``pad_separation``), the rail-pad separation the lumped
track of the wheelset model does not have.

The equations are solved with scipy's DOP853 (explicit Runge-Kutta 8(5,3), error-controlled at rtol 1e-8, steps of
at most 20 us, well inside its stability region for the ~1.3 kHz contact mode; Radau gives the same peak to
1e-6 of it: 331.78 kN at 60 km/h), so this is also an independent integrator. :func:`simulate_passage` returns
the contact force history, :func:`first_impact` the peak of a passage.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

STANDARD_GRAVITY_M_PER_S2 = 9.80665


@dataclass(frozen=True)
class VerticalModel:
    """Parameters of the vertical half-wheelset model (SI units).

    Attributes:
        wheel_mass_kg: m_w, half the wheelset.
        static_load_N: P0, the constant downward force on it (its weight and half the axle load).
        suspension_stiffness_N_per_m, suspension_damping_N_s_per_m: k_s, c_s to the frame (zero force at rest).
        hertz_constant_N_per_m15: C_H in N = C_H delta^1.5.
        rail_mass_kg, pad_stiffness_N_per_m, pad_damping_N_s_per_m, sleeper_mass_kg, ballast_stiffness_N_per_m,
            ballast_damping_N_s_per_m: the lumped track under the wheel (ignored when ``rigid_track``).
        rigid_track: the rail does not move.
        pad_separation: the pad carries no tension (its force is max(k_p d + c_p d', 0) while compressed, 0 when
            the rail has lifted off it).
        nominal_radius_m: r0.
        flat_length_m, flat_depth_m: L and d of the rounded flat.
        flat_centre_m: x_c, the travel at which the flat's centre faces the rail.
    """

    wheel_mass_kg: float
    static_load_N: float
    suspension_stiffness_N_per_m: float
    suspension_damping_N_s_per_m: float
    hertz_constant_N_per_m15: float
    rail_mass_kg: float
    pad_stiffness_N_per_m: float
    pad_damping_N_s_per_m: float
    sleeper_mass_kg: float
    ballast_stiffness_N_per_m: float
    ballast_damping_N_s_per_m: float
    nominal_radius_m: float
    flat_length_m: float
    flat_depth_m: float
    flat_centre_m: float
    rigid_track: bool = False
    pad_separation: bool = False


def centre_drop_m(model: VerticalModel, x_m: np.ndarray, samples: int = 2001) -> np.ndarray:
    """e(x): the drop of a rigid wheel's centre over a rigid flat rail at travel x (module docstring), m."""
    r0, length, depth = model.nominal_radius_m, model.flat_length_m, model.flat_depth_m
    half = 0.5 * length / r0
    a = np.linspace(-1.5 * half, 1.5 * half, samples)  # material angle from the flat's centre
    s = r0 * a
    radius = r0 - np.where(np.abs(s) < 0.5 * length, 0.5 * depth * (1.0 + np.cos(2.0 * math.pi * s / length)), 0.0)
    x = np.atleast_1d(np.asarray(x_m, float))
    phi = (x - model.flat_centre_m) / r0  # the material angle facing down
    out = np.zeros_like(x)
    on = np.abs(phi) < half  # off the flat the round tread below the centre gives r0 (r <= r0 everywhere)
    if np.any(on):
        heights = np.max(radius[None, :] * np.cos(a[None, :] - phi[on, None]), axis=1)
        out[on] = np.maximum(r0 - heights, 0.0)
    return out


def _static(model: VerticalModel):
    """Static deflections (wheel centre, rail, sleeper) and Hertz approach under P0, m."""
    p0 = model.static_load_N
    delta0 = (p0 / model.hertz_constant_N_per_m15) ** (2.0 / 3.0)
    if model.rigid_track:
        return delta0, 0.0, 0.0, delta0
    sleeper = p0 / model.ballast_stiffness_N_per_m
    rail = sleeper + p0 / model.pad_stiffness_N_per_m
    return rail + delta0, rail, sleeper, delta0


def simulate_passage(
    model: VerticalModel, speed_m_per_s: float, distance_m: float, sample_s: float = 5e-6, method: str = "DOP853"
):
    """Contact force history of a run from static equilibrium over ``distance_m`` (the flat at flat_centre_m).

    Returns:
        (t, x, contact force N, rail-pad force N) sampled every ``sample_s``.
    """
    zw0, zr0, zs0, _ = _static(model)
    grid = np.arange(0.0, distance_m + 2e-5, 2e-5)
    drop = centre_drop_m(model, grid)

    def excitation(x):
        return np.interp(x, grid, drop)

    m = model

    def pad_force(y):
        d, dv = y[2] - y[4], y[3] - y[5]
        f = m.pad_stiffness_N_per_m * d + m.pad_damping_N_s_per_m * dv
        if m.pad_separation:
            return max(f, 0.0) if d > 0.0 else 0.0
        return f

    def contact(t, y):
        rail = 0.0 if m.rigid_track else y[2]
        delta = y[0] - rail - excitation(speed_m_per_s * t)
        return m.hertz_constant_N_per_m15 * delta**1.5 if delta > 0.0 else 0.0

    def rhs(t, y):
        n = contact(t, y)
        f_susp = m.suspension_stiffness_N_per_m * (y[0] - zw0) + m.suspension_damping_N_s_per_m * y[1]
        dy = np.zeros(len(y))
        dy[0] = y[1]
        dy[1] = (m.static_load_N - f_susp - n) / m.wheel_mass_kg
        if not m.rigid_track:
            pad = pad_force(y)
            ballast = m.ballast_stiffness_N_per_m * y[4] + m.ballast_damping_N_s_per_m * y[5]
            dy[2], dy[4] = y[3], y[5]
            dy[3] = (n - pad) / m.rail_mass_kg
            dy[5] = (pad - ballast) / m.sleeper_mass_kg
        return dy

    y0 = np.array([zw0, 0.0] if m.rigid_track else [zw0, 0.0, zr0, 0.0, zs0, 0.0])
    duration = distance_m / speed_m_per_s
    t_eval = np.arange(0.0, duration, sample_s)
    sol = solve_ivp(rhs, (0.0, duration), y0, method=method, t_eval=t_eval, rtol=1e-8, atol=1e-12, max_step=2e-5)
    if not sol.success:
        raise RuntimeError(f"vertical model: {sol.message}")
    force = np.array([contact(t, y) for t, y in zip(sol.t, sol.y.T, strict=True)])
    pad = np.zeros_like(force) if m.rigid_track else np.array([pad_force(y) for y in sol.y.T])
    return sol.t, speed_m_per_s * sol.t, force, pad


def first_impact(model: VerticalModel, speed_m_per_s: float, distance_m: float, method: str = "DOP853") -> dict:
    """Peak contact force of a passage over the flat, the smallest (0: the wheel lifted) after the flat's entry,
    and the smallest pad force (negative: the pad pulls the rail down), N.
    """
    t, x, force, pad = simulate_passage(model, speed_m_per_s, distance_m, method=method)
    after = x >= model.flat_centre_m - 0.5 * model.flat_length_m
    return {
        "peak_N": float(force.max()),
        "min_after_entry_N": float(force[after].min()),
        "min_pad_force_N": float(pad.min()),
    }


def from_scene(scene, hertz_constant_N_per_m15: float, flat_centre_m: float, **changes) -> VerticalModel:
    """The vertical model of a DynamicsScene (its wheelset, suspension, loads, track, flat) for one wheel."""
    from rigid_dynamics.wheelset.irregular import flat_depth_m

    ws, tr, irr = scene.wheelset, scene.track_dynamics, scene.irregularities
    fields = {
        "wheel_mass_kg": 0.5 * ws.mass_kg,
        "static_load_N": scene.static_wheel_load_N,
        "suspension_stiffness_N_per_m": scene.suspension.vertical_stiffness_N_per_m,
        "suspension_damping_N_s_per_m": scene.suspension.vertical_damping_N_s_per_m,
        "hertz_constant_N_per_m15": hertz_constant_N_per_m15,
        "rail_mass_kg": tr.rail_mass_kg,
        "pad_stiffness_N_per_m": tr.pad_stiffness_N_per_m,
        "pad_damping_N_s_per_m": tr.pad_damping_N_s_per_m,
        "sleeper_mass_kg": tr.sleeper_mass_kg,
        "ballast_stiffness_N_per_m": tr.ballast_stiffness_N_per_m,
        "ballast_damping_N_s_per_m": tr.ballast_damping_N_s_per_m,
        "nominal_radius_m": ws.nominal_radius_m,
        "flat_length_m": irr.flat_length_m,
        "flat_depth_m": flat_depth_m(irr, ws.nominal_radius_m),
        "flat_centre_m": flat_centre_m,
        "rigid_track": not tr.elastic,
    }
    fields.update(changes)
    return VerticalModel(**fields)
