"""The vertical track under the wheels: its models, data, states' physics and parameters, in one module.

Everything the elastic track adds to a wheelset run lives here, apart from the state layout
(:mod:`rigid_dynamics.wheelset.state`: where its states sit, :data:`state.TRACK`, and their names) and the one
right-hand side (:mod:`rigid_dynamics.wheelset.compiled_rhs`, which calls :func:`track_rates` through
compiled_motion and lowers each rail by its deflection in the contact geometry):

* the scene's table :class:`TrackDynamics` and its default data (:data:`UIC60_RAIL_SEAT`,
  :func:`lumped_track_equivalent`);
* the fields the track adds to the compiled parameter record (:data:`PARAMETER_FIELDS`) and how a scene fills them
  (:func:`pack_parameters`);
* the track's equations of motion (:func:`track_rates`, compiled) and the rail under each wheel
  (:func:`rail_under_wheel`, compiled);
* the same equations as matrices, M a + C v + K q = b(x) F per rail (track_matrices.TrackSystem): the state at rest
  under given rail forces, the rail forces that hold a resting track, the energy, the receptance and the
  eigenfrequencies. The compiled rates equal M^-1 (b F - C v - K q) (a regression test); the physics tests check
  the matrices against closed forms.

Two elastic models (``model``):

* "lumped": under each wheel a rail mass on a pad (spring and damper) on a sleeper mass on the ballast (spring
  and damper), moving with the wheelset (the seed's rail deflection N_d,t of eq 6). States, z down from the
  unloaded track: rail and sleeper deflection per side (left, right), then their rates (state.TRACK_STATE_NAMES).
* "beam": each rail a beam (Timoshenko, or Euler-Bernoulli) on discrete rail seats (pad, half sleeper mass,
  ballast) at the sleeper spacing, fixed in space, the wheel rolling along it: sleeper-passing and the
  pinned-pinned resonance are in it. The beam is simply supported over a length that holds the run with a margin
  at each end and is written as a sum of its sine modes up to a cut-off frequency (modal superposition; the
  sleepers are discrete masses). States per rail: the modes' amplitudes W_n (and, Timoshenko, the section
  rotations Psi_n), the sleepers' deflections; then their rates (:class:`BeamLayout`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from rigid_dynamics.wheelset.fields import check_finite
from rigid_dynamics.wheelset.state import N_RIGID, RAIL, SLEEPER

TRACK_MODELS = ("rigid", "lumped", "beam")
"""Vertical track models (:class:`TrackDynamics`)."""

LATERAL_MODELS = ("rigid", "lumped")
"""Lateral track models of an elastic track (:class:`TrackDynamics` ``lateral_model``)."""

MAX_BEAM_STATES = 8000
"""The largest beam a scene may ask for (states of both rails, positions and rates): about 80 m of track with
modes to 5 kHz; each right-hand side costs ~ modes x seats per rail."""

RAIL_THEORIES = ("timoshenko", "euler-bernoulli")
"""Beam theories of the rail in the discretely supported model."""


def _seats_carrying_the_wheel(seat_stiffness_N_per_m, sleeper_spacing_m, bending_stiffness_N_m2) -> float:
    """N = 2 / (beta a) of the Winkler beam (k_f = k_seat / a, beta = (k_f / (4 EI))^(1/4)): the number of rail seats
    whose springs, n k_seat, give the beam's static point stiffness 2 k_f / beta.
    """
    k_f = seat_stiffness_N_per_m / sleeper_spacing_m
    beta = (k_f / (4.0 * bending_stiffness_N_m2)) ** 0.25
    return 2.0 / (beta * sleeper_spacing_m)


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
    n = _seats_carrying_the_wheel(k_series, sleeper_spacing_m, rail_bending_stiffness_N_m2)
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


def lumped_lateral_equivalent(
    rail_mass_per_length_kg_per_m: float,
    rail_lateral_bending_stiffness_N_m2: float,
    sleeper_spacing_m: float,
    fastening_lateral_stiffness_N_per_m: float,
    fastening_lateral_damping_N_s_per_m: float,
) -> dict:
    """Per-wheel lumped lateral rail from per-rail-seat data (the reduction behind TrackDynamics' lateral defaults).

    The reduction of :func:`lumped_track_equivalent` in the lateral plane: the rail, bending about its vertical axis
    (E I_z), on the fastenings' lateral springs smeared over the sleeper spacing (k_f = k_y / a) is a Winkler beam
    with beta = (k_f / (4 E I_z))^(1/4) and the static point stiffness 2 k_f / beta; n = 2 / (beta a) rail seats
    carry the wheel, the lumped rail has the rail mass of n spacings. The sleepers are held laterally (the
    ballast's lateral stiffness per sleeper is not in the model).
    """
    n = _seats_carrying_the_wheel(
        fastening_lateral_stiffness_N_per_m, sleeper_spacing_m, rail_lateral_bending_stiffness_N_m2
    )
    return {
        "lateral_rail_mass_kg": rail_mass_per_length_kg_per_m * n * sleeper_spacing_m,
        "lateral_rail_stiffness_N_per_m": n * fastening_lateral_stiffness_N_per_m,
        "lateral_rail_damping_N_s_per_m": n * fastening_lateral_damping_N_s_per_m,
    }


UIC60_LATERAL_SEAT = {
    "rail_mass_per_length_kg_per_m": 60.21,
    "rail_lateral_bending_stiffness_N_m2": 210.0e9 * 5.24e-6,
    "sleeper_spacing_m": 0.6,
    "fastening_lateral_stiffness_N_per_m": 1.5e7,
    "fastening_lateral_damping_N_s_per_m": 5.0e4,
}
"""Per-rail-seat lateral data of a 60 kg/m rail from which TrackDynamics' lateral defaults are reduced
(:func:`lumped_lateral_equivalent`): the rail's second moment of area about its vertical axis I_z = 5.24e-6 m^4,
the fastening's lateral stiffness 1.5e7 N/m and lateral damping 5.0e4 N s/m per rail seat, as tabulated for a
60 kg/m rail in vehicle-track coupled models (Advances in Civil Engineering 2021, article 8847633, Table 2;
the same fastening values in Shock and Vibration 2019, article 2015465, Table 2), with E = 210 GPa, the rail mass
and sleeper spacing of :data:`UIC60_RAIL_SEAT`. Result: 32.4 MN/m and 78 kg per wheel, a free lateral rail
frequency of 103 Hz, critically damped (damping ratio 1.07).
"""


UIC60_BEAM = {
    "rail_shear_stiffness_N": 0.4 * 80.77e9 * 76.70e-4,
    "rail_rotary_inertia_kg_m": 7850.0 * 3038.3e-8,
}
"""The Timoshenko terms of the UIC60 (60E1) rail in vertical bending: kappa G A with the shear coefficient
kappa = 0.4 (the value used for a 60 kg rail in vertical bending in the railway-noise literature, e.g.
D.J. Thompson, Railway Noise and Vibration, Elsevier 2009, ch. 3), G = E / (2 (1 + 0.3)) = 80.77 GPa and
A = 76.70 cm^2 (EN 13674-1, 60E1); the rotary inertia rho I with rho = 7850 kg/m^3 and I_y = 3038.3 cm^4.
"""


@dataclass(frozen=True)
class TrackDynamics:
    """Vertical track model under the wheels (seed eq 6: the rail deflection N_d,t shifts the rail surface).

    ``model`` = "rigid": the rails do not move (the default). "lumped": under each wheel a rail mass on a pad
    (spring and damper) on a sleeper mass on the ballast (spring and damper), moving with the wheelset; the
    rail mass's displacement (z down) lowers that rail's surface in the contact geometry, and the vertical
    component of the wheel's contact forces acts on it. "beam": each rail a Timoshenko (``rail_theory``, or
    Euler-Bernoulli) beam on discrete rail seats (pad, half sleeper, ballast) every ``sleeper_spacing_m``, fixed
    in space; the rail's deflection under the wheel lowers its surface and the vertical contact force acts on the
    beam where the wheel is.

    ``lateral_model`` = "lumped" (an elastic ``model`` only): under each wheel the rail's lateral mass on the
    fastenings' lateral spring and damper (the sleeper held laterally), moving with the wheelset, added to either
    vertical model; the rail's lateral displacement (y, the track's lateral axis) shifts that rail's profile in the
    contact geometry, and the lateral component of the wheel's contact forces acts on it. "rigid" (the default):
    the rails do not move laterally. Defaults: :data:`UIC60_LATERAL_SEAT` reduced by
    :func:`lumped_lateral_equivalent` (32.4 MN/m, 78 kg, 1.08e5 N s/m per wheel). A lateral beam is not built.

    The lumped defaults are the per-wheel equivalent of a UIC60 track on concrete sleepers
    (:data:`UIC60_RAIL_SEAT` reduced by :func:`lumped_track_equivalent`): static stiffness 150 MN/m per wheel,
    track resonances 143 and 341 Hz without a wheel, 60 Hz (P2) with an unsprung mass of 907 kg per wheel. The
    beam's defaults are that UIC60 track itself (:data:`UIC60_RAIL_SEAT`, :data:`UIC60_BEAM`).

    Attributes:
        model: "rigid", "lumped" or "beam".
        rail_mass_kg, sleeper_mass_kg: m_r, m_s per wheel, kg (lumped).
        pad_stiffness_N_per_m, pad_damping_N_s_per_m: k_p, c_p between rail and sleeper (lumped, per wheel).
        ballast_stiffness_N_per_m, ballast_damping_N_s_per_m: k_b, c_b between sleeper and ground (lumped).
        rail_theory: "timoshenko" or "euler-bernoulli" (beam).
        rail_mass_per_length_kg_per_m, rail_bending_stiffness_N_m2: rho A and E I of the rail (beam).
        rail_shear_stiffness_N, rail_rotary_inertia_kg_m: kappa G A and rho I (beam, Timoshenko).
        sleeper_spacing_m: distance between rail seats (beam).
        seat_pad_stiffness_N_per_m, seat_pad_damping_N_s_per_m: one rail seat's pad (beam).
        seat_sleeper_mass_kg: the sleeper mass under one rail (half a sleeper) (beam).
        seat_ballast_stiffness_N_per_m, seat_ballast_damping_N_s_per_m: the ballast under one rail seat (beam).
        rail_loss_factor: the rail's own damping, eta (beam): each mode's amplitude W_n has the viscous damping
            eta omega_n (rho A L / 2), omega_n its flexural frequency (the loss factor at that frequency). 0.02 is
            the order used for a rail's own vertical damping in the railway-noise literature (Thompson 2009,
            ch. 3); without it the pinned-pinned mode, which the pads do not touch, would ring undamped.
        cutoff_frequency_Hz: the beam's modes up to this frequency are kept (the flexural branch; beam).
        end_margin_m: the beam reaches this far beyond the run at each end (beam).
        lateral_model: "rigid" or "lumped" (the lateral track of an elastic track).
        lateral_rail_mass_kg, lateral_rail_stiffness_N_per_m, lateral_rail_damping_N_s_per_m: the lumped lateral
            rail per wheel, its spring and damper to the sleeper.
    """

    model: str = "rigid"
    rail_mass_kg: float = 84.0
    pad_stiffness_N_per_m: float = 2.79e8
    pad_damping_N_s_per_m: float = 6.98e4
    sleeper_mass_kg: float = 291.0
    ballast_stiffness_N_per_m: float = 3.26e8
    ballast_damping_N_s_per_m: float = 1.86e5
    rail_theory: str = "timoshenko"
    rail_mass_per_length_kg_per_m: float = UIC60_RAIL_SEAT["rail_mass_per_length_kg_per_m"]
    rail_bending_stiffness_N_m2: float = UIC60_RAIL_SEAT["rail_bending_stiffness_N_m2"]
    rail_shear_stiffness_N: float = UIC60_BEAM["rail_shear_stiffness_N"]
    rail_rotary_inertia_kg_m: float = UIC60_BEAM["rail_rotary_inertia_kg_m"]
    sleeper_spacing_m: float = UIC60_RAIL_SEAT["sleeper_spacing_m"]
    seat_pad_stiffness_N_per_m: float = UIC60_RAIL_SEAT["pad_stiffness_N_per_m"]
    seat_pad_damping_N_s_per_m: float = UIC60_RAIL_SEAT["pad_damping_N_s_per_m"]
    seat_sleeper_mass_kg: float = UIC60_RAIL_SEAT["half_sleeper_mass_kg"]
    seat_ballast_stiffness_N_per_m: float = UIC60_RAIL_SEAT["ballast_stiffness_N_per_m"]
    seat_ballast_damping_N_s_per_m: float = UIC60_RAIL_SEAT["ballast_damping_N_s_per_m"]
    rail_loss_factor: float = 0.02
    cutoff_frequency_Hz: float = 5000.0
    end_margin_m: float = 6.0
    lateral_model: str = "rigid"
    lateral_rail_mass_kg: float = 78.0
    lateral_rail_stiffness_N_per_m: float = 3.24e7
    lateral_rail_damping_N_s_per_m: float = 1.08e5

    def __post_init__(self) -> None:
        check_finite(
            self,
            positive=[
                "rail_mass_kg", "pad_stiffness_N_per_m", "sleeper_mass_kg", "ballast_stiffness_N_per_m",
                "rail_mass_per_length_kg_per_m", "rail_bending_stiffness_N_m2", "rail_shear_stiffness_N",
                "rail_rotary_inertia_kg_m", "sleeper_spacing_m", "seat_pad_stiffness_N_per_m", "seat_sleeper_mass_kg",
                "seat_ballast_stiffness_N_per_m", "cutoff_frequency_Hz", "end_margin_m", "lateral_rail_mass_kg",
                "lateral_rail_stiffness_N_per_m",
            ],
            nonnegative=[
                "pad_damping_N_s_per_m", "ballast_damping_N_s_per_m", "seat_pad_damping_N_s_per_m",
                "seat_ballast_damping_N_s_per_m", "rail_loss_factor", "lateral_rail_damping_N_s_per_m",
            ],
        )  # fmt: skip
        if self.model not in TRACK_MODELS:
            raise ValueError(f"model = {self.model!r}: expected one of {', '.join(TRACK_MODELS)}")
        if self.rail_theory not in RAIL_THEORIES:
            raise ValueError(f"rail_theory = {self.rail_theory!r}: expected one of {', '.join(RAIL_THEORIES)}")
        if self.lateral_model not in LATERAL_MODELS:
            raise ValueError(f"lateral_model = {self.lateral_model!r}: expected one of {', '.join(LATERAL_MODELS)}")
        if self.lateral_model != "rigid" and self.model == "rigid":
            raise ValueError(
                f"lateral_model = {self.lateral_model!r}: expected 'rigid' with model = 'rigid' (the lateral track "
                "joins an elastic vertical track: model = 'lumped' or 'beam')"
            )

    @property
    def elastic(self) -> bool:
        """True for a track with states (not rigid)."""
        return self.model != "rigid"

    @property
    def lateral(self) -> bool:
        """True for a track with lateral states (lateral_model "lumped" on an elastic track)."""
        return self.elastic and self.lateral_model == "lumped"

    @property
    def static_stiffness_N_per_m(self) -> float:
        """The lumped model's pad and ballast in series, N/m."""
        return 1.0 / (1.0 / self.pad_stiffness_N_per_m + 1.0 / self.ballast_stiffness_N_per_m)

    @property
    def seat_stiffness_N_per_m(self) -> float:
        """One rail seat's pad and ballast in series, N/m (beam)."""
        return 1.0 / (1.0 / self.seat_pad_stiffness_N_per_m + 1.0 / self.seat_ballast_stiffness_N_per_m)

    @property
    def timoshenko(self) -> bool:
        return self.rail_theory == "timoshenko"


def flexural_frequency_rad_per_s(track: TrackDynamics, wavenumber_1_per_m):
    """Free rail's lower (flexural) natural frequency at the wavenumber k, rad/s: Euler-Bernoulli
    k^2 sqrt(EI / rho A); Timoshenko the lower root of
    (kGA k^2 - rho A w^2)(EI k^2 + kGA - rho I w^2) = (kGA k)^2 (the compiled :func:`_flexural_omega` per
    wavenumber, the one the rail damping of the compiled rates uses).
    """
    k = np.asarray(wavenumber_1_per_m, float)
    rail = (track.rail_bending_stiffness_N_m2, track.rail_mass_per_length_kg_per_m, track.rail_shear_stiffness_N,
            track.rail_rotary_inertia_kg_m, track.timoshenko)  # fmt: skip
    return np.array([_flexural_omega(float(x), *rail) for x in k.ravel()]).reshape(k.shape)


@dataclass(frozen=True)
class BeamLayout:
    """Size of the discretely supported beam of a run and where its states sit.

    The beam of length L = (n_sleepers + 1) a (a the sleeper spacing) is simply supported at its ends; rail seat j
    is at (j + 1) a from its start (j = 0 .. n_sleepers - 1), so that the pinned-pinned mode sin(pi x / a), with
    its nodes at the seats, is one of the beam's modes. The wheelset is at xi = x - x0 + margin along it (x0 its
    x at t = 0). Per rail the positions are [W_1..W_N, (Psi_1..Psi_N for Timoshenko), z_1..z_S],
    w(x) = sum W_n sin(n pi x / L) (z down), the section rotation psi(x) = sum Psi_n cos(n pi x / L); left rail
    first, then the right rail, then every rate in the same order.
    """

    n_modes: int
    n_sleepers: int
    length_m: float
    margin_m: float
    timoshenko: bool

    @property
    def per_rail(self) -> int:
        return self.n_modes * (2 if self.timoshenko else 1) + self.n_sleepers

    @property
    def n_positions(self) -> int:
        return 2 * self.per_rail


def beam_layout(track: TrackDynamics, travel_m: float) -> BeamLayout:
    """The beam for a run of ``travel_m``: it holds the travel (with 10 % and one sleeper spacing to spare) and
    ``end_margin_m`` at each end, in whole sleeper spacings; its modes are those whose flexural frequency
    (:func:`flexural_frequency_rad_per_s`) is at most ``cutoff_frequency_Hz`` (counted up to one past the size
    that :data:`MAX_BEAM_STATES` allows).
    """
    a = track.sleeper_spacing_m
    n_sleepers = int(math.ceil((1.1 * max(travel_m, 0.0) + a + 2.0 * track.end_margin_m) / a)) - 1
    length = (n_sleepers + 1) * a
    cutoff = 2.0 * math.pi * track.cutoff_frequency_Hz
    # counted up to one mode past MAX_BEAM_STATES (the scene's check refuses such a beam; an enormous travel would
    # otherwise count millions of modes one by one first)
    most = max(0, (MAX_BEAM_STATES // 4 - n_sleepers) // (2 if track.timoshenko else 1)) + 1
    n = 0
    while n < most and float(flexural_frequency_rad_per_s(track, (n + 1) * math.pi / length)) <= cutoff:
        n += 1
    return BeamLayout(max(n, 1), n_sleepers, length, track.end_margin_m, track.timoshenko)


PARAMETER_FIELDS = (
    ("elastic_track", "1: lumped track, 2: discretely supported beam, 0: rigid"),
    ("track_positions", "number of the track's position states (0, 4 lumped, BeamLayout.n_positions)"),
    ("rail_mass_kg", "rail mass per wheel"),
    ("pad_stiffness_N_per_m", "pad stiffness"),
    ("pad_damping_N_s_per_m", "pad damping"),
    ("sleeper_mass_kg", "sleeper mass per wheel"),
    ("ballast_stiffness_N_per_m", "ballast stiffness"),
    ("ballast_damping_N_s_per_m", "ballast damping"),
    ("beam_modes", "beam: modes per rail"),
    ("beam_sleepers", "beam: rail seats per rail"),
    ("beam_timoshenko", "beam: 1 Timoshenko, 0 Euler-Bernoulli"),
    ("beam_length_m", "beam: length"),
    ("beam_margin_m", "beam: where the wheelset starts along it"),
    ("rail_mass_per_length_kg_per_m", "beam: rho A"),
    ("rail_bending_stiffness_N_m2", "beam: E I"),
    ("rail_shear_stiffness_N", "beam: kappa G A"),
    ("rail_rotary_inertia_kg_m", "beam: rho I"),
    ("sleeper_spacing_m", "beam: rail seat spacing"),
    ("seat_pad_stiffness_N_per_m", "beam: pad per seat"),
    ("seat_pad_damping_N_s_per_m", "beam: pad damping per seat"),
    ("seat_sleeper_mass_kg", "beam: sleeper mass per seat"),
    ("seat_ballast_stiffness_N_per_m", "beam: ballast per seat"),
    ("seat_ballast_damping_N_s_per_m", "beam: ballast damping per seat"),
    ("rail_loss_factor", "beam: the rail's loss factor"),
    ("lateral_track", "1: lumped lateral rail per wheel (the last 2 positions and the last 2 rates), 0: none"),
    ("lateral_rail_mass_kg", "lateral rail mass per wheel"),
    ("lateral_rail_stiffness_N_per_m", "lateral fastening stiffness per wheel"),
    ("lateral_rail_damping_N_s_per_m", "lateral fastening damping per wheel"),
)
"""The track's fields of the compiled parameter record (compiled.PARAMETER_FIELDS): (field, meaning), SI units."""

_LUMPED_FIELDS = (
    "rail_mass_kg", "pad_stiffness_N_per_m", "pad_damping_N_s_per_m", "sleeper_mass_kg",
    "ballast_stiffness_N_per_m", "ballast_damping_N_s_per_m",
)  # fmt: skip
_BEAM_FIELDS = (
    "rail_mass_per_length_kg_per_m", "rail_bending_stiffness_N_m2", "rail_shear_stiffness_N",
    "rail_rotary_inertia_kg_m", "sleeper_spacing_m", "seat_pad_stiffness_N_per_m", "seat_pad_damping_N_s_per_m",
    "seat_sleeper_mass_kg", "seat_ballast_stiffness_N_per_m", "seat_ballast_damping_N_s_per_m", "rail_loss_factor",
)  # fmt: skip


def travel_m(scene) -> float:
    """How far a scene's wheelset runs: speed x duration, m (the beam is sized for it)."""
    return float(scene.speed_m_per_s * scene.duration_s)


def n_positions(track: TrackDynamics, travel: float) -> int:
    """Number of the track's position states (as many rates follow): 0 rigid, 4 lumped, the beam's layout; 2 more
    with the lateral track (its rails' lateral displacements, left and right, last).
    """
    if track.model == "rigid":
        return 0
    lateral = 2 if track.lateral else 0
    if track.model == "lumped":
        return 4 + lateral
    return beam_layout(track, travel).n_positions + lateral


def pack_parameters(par, track: TrackDynamics, travel: float) -> None:
    """Fill the track's fields of the parameter record ``par`` (compiled.PARAMETERS) from the scene's table and the
    run's travel (m, :func:`travel_m`; it sizes the beam).
    """
    par["elastic_track"] = {"rigid": 0.0, "lumped": 1.0, "beam": 2.0}[track.model]
    par["track_positions"] = float(n_positions(track, travel))
    if track.model == "lumped":
        for name in _LUMPED_FIELDS:
            par[name] = getattr(track, name)
    elif track.model == "beam":
        layout = beam_layout(track, travel)
        for name in _BEAM_FIELDS:
            par[name] = getattr(track, name)
        par["beam_modes"], par["beam_sleepers"] = float(layout.n_modes), float(layout.n_sleepers)
        par["beam_timoshenko"] = 1.0 if layout.timoshenko else 0.0
        par["beam_length_m"], par["beam_margin_m"] = layout.length_m, layout.margin_m
    par["lateral_track"] = 1.0 if track.lateral else 0.0
    if track.lateral:
        for name in ("lateral_rail_mass_kg", "lateral_rail_stiffness_N_per_m", "lateral_rail_damping_N_s_per_m"):
            par[name] = getattr(track, name)


@njit(cache=True, _nrt=False)
def beam_position_m(par, y):
    """Where the wheelset is along the beam, m: xi = x - x0 + margin (BeamLayout)."""
    return y[0] - par.frame_x0_m + par.beam_margin_m


@njit(cache=True, _nrt=False)
def rail_under_wheel(par, y, side):
    """(deflection m, vertical velocity m/s) of the rail of ``side`` (0 left, 1 right) under the wheel, z down, at
    the full state ``y``: the lumped rail mass, or the beam's modal sum at the wheelset's position (the material
    velocity of the rail there). (0, 0) on the rigid track.
    """
    if par.elastic_track < 0.5:
        return 0.0, 0.0
    if par.elastic_track < 1.5:
        return y[RAIL + side], y[N_RIGID + int(par.track_positions) + side]
    n_modes = int(par.beam_modes)
    per_rail = n_modes * (2 if par.beam_timoshenko > 0 else 1) + int(par.beam_sleepers)
    base = N_RIGID + side * per_rail
    rates = base + int(par.track_positions)
    theta = math.pi * beam_position_m(par, y) / par.beam_length_m
    s_prev, s, c2 = 0.0, math.sin(theta), 2.0 * math.cos(theta)
    w, v = 0.0, 0.0
    for n in range(n_modes):  # sin((n+1) theta) by the recurrence s_{n+1} = 2 cos(theta) s_n - s_{n-1}
        w += y[base + n] * s
        v += y[rates + n] * s
        s_prev, s = s, c2 * s - s_prev
    return w, v


@njit(cache=True, _nrt=False)
def rail_lateral_under_wheel(par, y, side):
    """(lateral displacement m, lateral velocity m/s) of the rail of ``side`` (0 left, 1 right) under the wheel, y
    along the track's lateral axis, at the full state ``y``: the lumped lateral rail (the last two positions and the
    last two rates of the track). (0, 0) without the lateral track.
    """
    if par.lateral_track < 0.5:
        return 0.0, 0.0
    n_pos = int(par.track_positions)
    return y[N_RIGID + n_pos - 2 + side], y[N_RIGID + 2 * n_pos - 2 + side]


@njit(cache=True, _nrt=False)
def track_rates(par, y, rail_f0, rail_f1, rail_fy0, rail_fy1, out, p_ext):
    """The elastic track's equations of motion under the vertical contact forces on the rails (left, right), N (z
    down, acting on the rail under the wheel), and the lateral ones (rail_fy0, rail_fy1, N, along y; the lateral
    track): its rates into ``out`` (the full state's track part). Returns ``p_ext`` less the power of the pad,
    ballast and lateral fastening dampers.
    """
    n_pos = int(par.track_positions)
    if par.lateral_track > 0.5:
        m_y, k_y, c_y = par.lateral_rail_mass_kg, par.lateral_rail_stiffness_N_per_m, par.lateral_rail_damping_N_s_per_m
        for sd in range(2):
            u, v = y[N_RIGID + n_pos - 2 + sd], y[N_RIGID + 2 * n_pos - 2 + sd]
            out[N_RIGID + n_pos - 2 + sd] = v
            out[N_RIGID + 2 * n_pos - 2 + sd] = ((rail_fy0 if sd == 0 else rail_fy1) - k_y * u - c_y * v) / m_y
            p_ext -= c_y * v * v
    if par.elastic_track < 1.5:
        rv = N_RIGID + n_pos  # the rates: rail left, right, sleeper left, right
        for sd in range(2):
            zr, zs_, vr, vs = y[RAIL + sd], y[SLEEPER + sd], y[rv + sd], y[rv + 2 + sd]
            pad = par.pad_stiffness_N_per_m * (zr - zs_) + par.pad_damping_N_s_per_m * (vr - vs)
            ballast = par.ballast_stiffness_N_per_m * zs_ + par.ballast_damping_N_s_per_m * vs
            out[RAIL + sd], out[SLEEPER + sd] = vr, vs
            out[rv + sd] = ((rail_f0 if sd == 0 else rail_f1) - pad) / par.rail_mass_kg
            out[rv + 2 + sd] = (pad - ballast) / par.sleeper_mass_kg
            p_ext -= par.pad_damping_N_s_per_m * (vr - vs) ** 2 + par.ballast_damping_N_s_per_m * vs * vs
        return p_ext
    return _beam_rates(par, y, rail_f0, rail_f1, out, p_ext)


@njit(cache=True, _nrt=False)
def _beam_rates(par, y, rail_f0, rail_f1, out, p_ext):
    """track_rates of the discretely supported beam (BeamLayout), per rail:
    (rho A L/2) W_n'' = F sin(k_n xi) - sum_s P_s sin(k_n x_s) - (L/2) [E I k_n^4 W_n] (Euler-Bernoulli) or
    - (L/2) kGA (k_n^2 W_n - k_n Psi_n) (Timoshenko, with (rho I L/2) Psi_n'' = -(L/2) [E I k_n^2 Psi_n +
    kGA (Psi_n - k_n W_n)]); m_s z_s'' = P_s - k_b z_s - c_b z_s', the pad force P_s = k_p (w(x_s) - z_s) +
    c_p (w'(x_s) - z_s'), k_n = n pi / L.
    """
    n_modes, n_seats = int(par.beam_modes), int(par.beam_sleepers)
    timo = par.beam_timoshenko > 0
    n_w = n_modes * (2 if timo else 1)
    per_rail = n_w + n_seats
    n_pos = int(par.track_positions)
    length, spacing = par.beam_length_m, par.sleeper_spacing_m
    kp, cp = par.seat_pad_stiffness_N_per_m, par.seat_pad_damping_N_s_per_m
    kb, cb, ms = par.seat_ballast_stiffness_N_per_m, par.seat_ballast_damping_N_s_per_m, par.seat_sleeper_mass_kg
    ei, ga = par.rail_bending_stiffness_N_m2, par.rail_shear_stiffness_N
    modal_mass, rotary = 0.5 * par.rail_mass_per_length_kg_per_m * length, par.rail_rotary_inertia_kg_m
    theta_w = math.pi * beam_position_m(par, y) / length
    ra = par.rail_mass_per_length_kg_per_m
    for sd in range(2):
        base = N_RIGID + sd * per_rail
        rates = base + n_pos
        force = rail_f0 if sd == 0 else rail_f1
        s_prev, s, c2 = 0.0, math.sin(theta_w), 2.0 * math.cos(theta_w)
        for n in range(n_modes):  # the generalised forces collect in the modes' acceleration slots
            out[rates + n] = force * s
            s_prev, s = s, c2 * s - s_prev
        for j in range(n_seats):
            theta = math.pi * (j + 1) * spacing / length
            c2 = 2.0 * math.cos(theta)
            s_prev, s = 0.0, math.sin(theta)
            w, v = 0.0, 0.0
            for n in range(n_modes):
                w += y[base + n] * s
                v += y[rates + n] * s
                s_prev, s = s, c2 * s - s_prev
            z, vz = y[base + n_w + j], y[rates + n_w + j]
            pad = kp * (w - z) + cp * (v - vz)
            out[base + n_w + j] = vz
            out[rates + n_w + j] = (pad - kb * z - cb * vz) / ms
            p_ext -= cp * (v - vz) ** 2 + cb * vz * vz
            s_prev, s = 0.0, math.sin(theta)
            for n in range(n_modes):
                out[rates + n] -= pad * s
                s_prev, s = s, c2 * s - s_prev
        for n in range(n_modes):
            k = (n + 1) * math.pi / length
            w_n = y[base + n]
            out[base + n] = y[rates + n]
            damping = par.rail_loss_factor * _flexural_omega(k, ei, ra, ga, rotary, timo) * modal_mass
            out[rates + n] -= damping * y[rates + n]
            p_ext -= damping * y[rates + n] ** 2
            if timo:
                psi = y[base + n_modes + n]
                out[base + n_modes + n] = y[rates + n_modes + n]
                out[rates + n] = (out[rates + n] - 0.5 * length * ga * (k * k * w_n - k * psi)) / modal_mass
                out[rates + n_modes + n] = -(ei * k * k * psi + ga * (psi - k * w_n)) / rotary
            else:
                out[rates + n] = (out[rates + n] - 0.5 * length * ei * k**4 * w_n) / modal_mass
    return p_ext


@njit(cache=True, _nrt=False)
def _flexural_omega(k, ei, ra, ga, ri, timo):
    """Free rail's flexural frequency at one wavenumber k, rad/s (:func:`flexural_frequency_rad_per_s`)."""
    if not timo:
        return k * k * math.sqrt(ei / ra)
    a = ra * ri
    b = ga * k * k * ri + ra * (ei * k * k + ga)
    c = ga * k * k * (ei * k * k + ga) - (ga * k) ** 2
    return math.sqrt((b - math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a))
