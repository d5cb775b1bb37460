"""The vertical track under each wheel: its models, data, states' physics and parameters, in one module.

Everything the elastic track adds to a wheelset run lives here, apart from the state layout
(:mod:`rigid_dynamics.wheelset.state`: where its states sit, :data:`state.TRACK`, and their names) and the one
right-hand side (:mod:`rigid_dynamics.wheelset.compiled`, which calls :func:`track_rates` and lowers each rail by
its deflection in the contact geometry):

* the scene's table :class:`TrackDynamics` and its default data (:data:`UIC60_RAIL_SEAT`,
  :func:`lumped_track_equivalent`);
* the fields the track adds to the compiled parameter record (:data:`PARAMETER_FIELDS`) and how a scene fills them
  (:func:`pack_parameters`);
* the track's equations of motion (:func:`track_rates`, compiled), its energy (:func:`energy_J`), its state at
  rest under given rail forces (:func:`rest_state`) and the rail forces that hold a resting track
  (:func:`rail_forces_at_rest`).

The lumped model: under each wheel a rail mass on a pad (spring and damper) on a sleeper mass on the ballast
(spring and damper), moving with the wheelset (the seed's rail deflection N_d,t of eq 6). States, z down from the
unloaded track: rail and sleeper deflection per side (left, right), then their rates (state.TRACK_STATE_NAMES).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from rigid_dynamics.wheelset.state import RAIL, RAIL_VELOCITY, SLEEPER, SLEEPER_VELOCITY

TRACK_MODELS = ("rigid", "lumped")
"""Vertical track models under each wheel (:class:`TrackDynamics`)."""


def lumped_track_equivalent(
    rail_mass_per_length_kg_per_m: float,
    rail_bending_stiffness_N_m2: float,
    sleeper_spacing_m: float,
    pad_stiffness_N_per_m: float,
    pad_damping_N_s_per_m: float,
    half_sleeper_mass_kg: float,
    ballast_stiffness_N_per_m: float,
    ballast_damping_N_s_per_m: float,
) -> dict:
    """Per-wheel two-layer lumped track from per-rail-seat data (the reduction behind TrackDynamics' defaults).

    The rail on its supports in series (pad and ballast per rail seat, k_s = 1/(1/k_p + 1/k_b), smeared over the
    sleeper spacing a: foundation modulus k_f = k_s / a) is a Winkler beam with beta = (k_f / (4 EI))^(1/4), whose
    static point stiffness is 2 k_f / beta (Timoshenko's closed form, w0 = P beta / (2 k_f)). The lumped model
    lets n = 2 / (beta a) rail seats carry the wheel: pad, ballast, their dampers and the sleeper mass are n times
    the per-seat values, the rail mass is the rail over n spacings. The static stiffness of the lumped model then
    equals the beam's exactly; the masses are an approximation (a beam's participating mass depends on frequency).
    """
    k_series = 1.0 / (1.0 / pad_stiffness_N_per_m + 1.0 / ballast_stiffness_N_per_m)
    k_f = k_series / sleeper_spacing_m
    beta = (k_f / (4.0 * rail_bending_stiffness_N_m2)) ** 0.25
    n = 2.0 / (beta * sleeper_spacing_m)
    return {
        "rail_mass_kg": rail_mass_per_length_kg_per_m * n * sleeper_spacing_m,
        "pad_stiffness_N_per_m": n * pad_stiffness_N_per_m,
        "pad_damping_N_s_per_m": n * pad_damping_N_s_per_m,
        "sleeper_mass_kg": n * half_sleeper_mass_kg,
        "ballast_stiffness_N_per_m": n * ballast_stiffness_N_per_m,
        "ballast_damping_N_s_per_m": n * ballast_damping_N_s_per_m,
    }


UIC60_RAIL_SEAT = {
    "rail_mass_per_length_kg_per_m": 60.21,
    "rail_bending_stiffness_N_m2": 210.0e9 * 3038.3e-8,
    "sleeper_spacing_m": 0.6,
    "pad_stiffness_N_per_m": 120.0e6,
    "pad_damping_N_s_per_m": 30.0e3,
    "half_sleeper_mass_kg": 125.0,
    "ballast_stiffness_N_per_m": 140.0e6,
    "ballast_damping_N_s_per_m": 80.0e3,
}
"""Per-rail-seat data of a UIC60 (60E1) rail on concrete monoblock sleepers from which TrackDynamics' defaults
are reduced (:func:`lumped_track_equivalent`): rail mass 60.21 kg/m and I_y = 3038.3 cm^4 (EN 13674-1, 60E1),
E = 210 GPa; sleeper spacing 0.6 m; pad 120 MN/m and 30 kN s/m, half sleeper 125 kg, ballast 140 MN/m and
80 kN s/m: values inside the ranges Knothe & Grassie (1993, Vehicle System Dynamics 22, 209-262) give for
ballasted track with concrete sleepers and studded pads (pads ~100-500 MN/m, ballast ~50-200 MN/m per seat),
chosen here, not one table of that paper. The result (150 MN/m static stiffness per wheel) matches the
equivalent track stiffness 150 MN/m of Jenkins et al. (1974) for concrete-sleepered continuously welded track.
"""


@dataclass(frozen=True)
class TrackDynamics:
    """Vertical track model under each wheel (seed eq 6: the rail deflection N_d,t shifts the rail surface).

    ``model`` = "rigid": the rails do not move (the default). "lumped": under each wheel a rail mass on a pad
    (spring and damper) on a sleeper mass on the ballast (spring and damper), moving with the wheelset; the
    rail mass's displacement (z down) lowers that rail's surface in the contact geometry, and the vertical
    component of the wheel's contact forces acts on it. Lateral track: rigid.

    The defaults are the per-wheel equivalent of a UIC60 track on concrete sleepers
    (:data:`UIC60_RAIL_SEAT` reduced by :func:`lumped_track_equivalent`): static stiffness 150 MN/m per wheel,
    track resonances 143 and 341 Hz without a wheel, 60 Hz (P2) with an unsprung mass of 907 kg per wheel.

    Attributes:
        model: "rigid" or "lumped".
        rail_mass_kg, sleeper_mass_kg: m_r, m_s per wheel, kg.
        pad_stiffness_N_per_m, pad_damping_N_s_per_m: k_p, c_p between rail and sleeper.
        ballast_stiffness_N_per_m, ballast_damping_N_s_per_m: k_b, c_b between sleeper and ground.
    """

    model: str = "rigid"
    rail_mass_kg: float = 84.0
    pad_stiffness_N_per_m: float = 2.79e8
    pad_damping_N_s_per_m: float = 6.98e4
    sleeper_mass_kg: float = 291.0
    ballast_stiffness_N_per_m: float = 3.26e8
    ballast_damping_N_s_per_m: float = 1.86e5

    def __post_init__(self) -> None:
        from rigid_dynamics.wheelset.parameters import _check_finite  # parameters imports this module

        _check_finite(
            self,
            positive=["rail_mass_kg", "pad_stiffness_N_per_m", "sleeper_mass_kg", "ballast_stiffness_N_per_m"],
            nonnegative=["pad_damping_N_s_per_m", "ballast_damping_N_s_per_m"],
        )
        if self.model not in TRACK_MODELS:
            raise ValueError(f"model = {self.model!r}: expected one of {', '.join(TRACK_MODELS)}")

    @property
    def elastic(self) -> bool:
        """True for a track with states (not rigid)."""
        return self.model != "rigid"

    @property
    def static_stiffness_N_per_m(self) -> float:
        """Pad and ballast in series, N/m."""
        return 1.0 / (1.0 / self.pad_stiffness_N_per_m + 1.0 / self.ballast_stiffness_N_per_m)


PARAMETER_FIELDS = (
    ("elastic_track", "1: elastic track"),
    ("rail_mass_kg", "rail mass per wheel"),
    ("pad_stiffness_N_per_m", "pad stiffness"),
    ("pad_damping_N_s_per_m", "pad damping"),
    ("sleeper_mass_kg", "sleeper mass per wheel"),
    ("ballast_stiffness_N_per_m", "ballast stiffness"),
    ("ballast_damping_N_s_per_m", "ballast damping"),
)
"""The track's fields of the compiled parameter record (compiled.PARAMETER_FIELDS): (field, meaning), SI units."""


def pack_parameters(par, track: TrackDynamics) -> None:
    """Fill the track's fields of the parameter record ``par`` (compiled.PARAMETERS) from the scene's table."""
    if not track.elastic:
        par["elastic_track"] = 0.0
        return
    par["elastic_track"] = 1.0
    for name, _ in PARAMETER_FIELDS[1:]:
        par[name] = getattr(track, name)


@njit(cache=True, _nrt=False)
def track_rates(par, y, rail_f0, rail_f1, out, p_ext):
    """The lumped track's equations of motion under the vertical contact forces on the rails (left, right), N
    (z down, acting on the rail): its rates into ``out`` (state.TRACK). Returns ``p_ext`` less the power of the
    pad and ballast dampers.
    """
    for sd in range(2):
        zr, zs_, vr, vs = y[RAIL + sd], y[SLEEPER + sd], y[RAIL_VELOCITY + sd], y[SLEEPER_VELOCITY + sd]
        pad = par.pad_stiffness_N_per_m * (zr - zs_) + par.pad_damping_N_s_per_m * (vr - vs)
        ballast = par.ballast_stiffness_N_per_m * zs_ + par.ballast_damping_N_s_per_m * vs
        out[RAIL + sd], out[SLEEPER + sd] = vr, vs
        out[RAIL_VELOCITY + sd] = ((rail_f0 if sd == 0 else rail_f1) - pad) / par.rail_mass_kg
        out[SLEEPER_VELOCITY + sd] = (pad - ballast) / par.sleeper_mass_kg
        p_ext -= par.pad_damping_N_s_per_m * (vr - vs) ** 2 + par.ballast_damping_N_s_per_m * vs * vs
    return p_ext


def energy_J(track: TrackDynamics, states) -> tuple:
    """(kinetic, potential) energy of the track's states (n, 8) or (8,) (state.TRACK order), J: the masses' kinetic
    energy and the pad's and ballast's strain energy (0, 0 for the rigid track).
    """
    if not track.elastic:
        return 0.0, 0.0
    t = np.asarray(states, float)
    z_r, z_s, v_r, v_s = t[..., 0:2], t[..., 2:4], t[..., 4:6], t[..., 6:8]
    kinetic = 0.5 * np.sum(track.rail_mass_kg * v_r**2 + track.sleeper_mass_kg * v_s**2, axis=-1)
    potential = 0.5 * np.sum(
        track.pad_stiffness_N_per_m * (z_r - z_s) ** 2 + track.ballast_stiffness_N_per_m * z_s**2, axis=-1
    )
    return kinetic, potential


def rest_state(track: TrackDynamics, rail_force_N) -> np.ndarray:
    """The track's states at rest under the vertical rail forces (left, right), N: z_s = F / k_b,
    z_r = z_s + F / k_p, rates 0 (state.TRACK order).
    """
    force = np.asarray(rail_force_N, float)
    out = np.zeros(8)
    out[2:4] = force / track.ballast_stiffness_N_per_m
    out[0:2] = out[2:4] + force / track.pad_stiffness_N_per_m
    return out


def rail_forces_at_rest(track: TrackDynamics, rest, rates) -> np.ndarray:
    """The vertical contact force on each rail (left, right), N, of a track at rest in ``rest`` (state.TRACK order)
    whose rates the right-hand side gives as ``rates`` (state.TRACK order): m_r z_r'' = F_r - k_p (z_r - z_s).
    """
    return track.rail_mass_kg * np.asarray(rates)[4:6] + track.pad_stiffness_N_per_m * (rest[0:2] - rest[2:4])
