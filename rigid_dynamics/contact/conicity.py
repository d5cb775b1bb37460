"""Equivalent conicity by the rolling-radius-difference method of EN 15302 (Klingel's kinematic oscillation).

1. Rolling-radius difference Delta r(y) = r_right(y) - r_left(y): for each lateral shift y of the wheelset
   (towards main +y, the right rail; no yaw) the vertical position and roll are found so that both wheels just
   touch their rails (rigid contact, ``wheelset_case.rigid_contact``), and r is the wheel radius at the
   contact point of each wheel (the smallest gap). For a conical wheelset of conicity lambda on rail heads of
   crown radius R_r, Delta r = 2 lambda y / (1 - lambda (r0 + R_r) / e0) to first order: the roll theta that
   follows Delta r swings the wheels' lowest points sideways by r0 theta and moves the contact points over the
   crowns by R_r theta (tests/test_conicity.py checks this against an independent tangency construction), so
   the equivalent conicity of a cone exceeds lambda by a few % at 1:20 and tends to lambda as lambda -> 0.
2. Klingel's equation of the free wheelset (kinematic, no creep forces), with the distance s rolled as the
   independent variable (J. Klingel 1883; A.H. Wickens, Fundamentals of Rail Vehicle Dynamics, 2003, ch. 1):

       d^2 y / ds^2 + Delta r(y) / (2 e0 r0) = 0,

   whose solutions for Delta r = 2 lambda y have the wavelength L = 2 pi sqrt(e0 r0 / lambda) (e0 half the
   distance of the contact points, r0 the nominal radius).
3. EN 15302 (principle of the reference procedure; Annex B "integration of the nonlinear differential
   equation"): the equation is integrated with the tabulated Delta r(y) from y = y_hat, y' = 0 for one full
   oscillation; its wavelength L defines the equivalent conicity

       tan(gamma_e) = 4 pi^2 e0 r0 / L^2

   (the conicity of the conical wheelset with the same wavelength at that amplitude). The result does not
   depend on e0 r0 (L scales with sqrt(e0 r0)); ``wavelength_m`` is reported with e0 from the contact points at
   y = 0 and r0 = nominal_radius_m.

Discretisation error: the Delta r table is spaced ``shift_step_m`` (default min(0.1 mm, amplitude / 30)) and
interpolated (PCHIP); both conicities are computed again from every second row of the same table (a table twice as
coarse, no new contact solves), and ``discretisation_error_estimate`` is the larger relative change. With the
default spacing the table is halved (new rows between the old) up to MAX_TABLE_REFINEMENTS times while the estimate
exceeds ``tolerance`` (1 %). Against tables five times finer (S1002 on UIC60 at 1:40 and 1:20, a 1.432 m gauge with
its jumps of the contact point, amplitudes 1, 3 and 6 mm): true error / estimate 0.1-0.72 at the automatic
spacing (true 1e-8 to 0.34 %; 6 mm needed one halving, 16 s); but at a fixed 0.2 mm one case (the 1.432 m gauge)
was 2.1 times its estimate, so the estimate is a measured indicator at the automatic spacing, not a bound
(tests/test_conicity.py). Above ``tolerance`` the result is a ``warning``.

Also reported: the harmonic (first-Fourier-coefficient) linearisation tan(gamma_h) = b1 / (2 y_hat),
b1 = (1/pi) int_0^{2 pi} Delta r(y_hat sin t) sin t dt, which equals the least-squares slope of Delta r(y) / 2 for
samples of a sinusoidal motion of amplitude y_hat (the idea of EN 15302's Annex C regression).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.contact.search import SIDES


@dataclass(frozen=True, eq=False)
class ConicityResult:
    """Equivalent conicity and the rolling-radius-difference function it came from.

    Attributes:
        success, status, message: status "ok", "warning" (the table's discretisation-error estimate exceeds the
            tolerance), "not-converged" (a rigid-contact solve failed; its shift is left out) or "no-oscillation"
            (Delta r does not restore the wheelset: no wavelength).
        equivalent_conicity: tan(gamma_e) by the wavelength of Klingel's nonlinear equation (EN 15302), -.
        harmonic_conicity: tan(gamma_h), first-harmonic linearisation, -.
        amplitude_m: y_hat, m.
        wavelength_m: L of the kinematic oscillation for e0 = half_contact_distance_m, r0 = nominal_radius_m, m.
        half_contact_distance_m: e0 at zero shift, m. nominal_radius_m: r0, m.
        lateral_shift_m: y of the table, m (shape (n,)).
        rolling_radius_difference_m: Delta r(y) = r_right - r_left, m (shape (n,)).
        rolling_radius_left_m, rolling_radius_right_m: m (shape (n,)).
        roll_rad: rigid-contact roll angle theta(y), rad (shape (n,)).
        discretisation_error_estimate: relative change of the conicities on the table of every second shift
            (module docstring), -; nan when that table gives none.
        tolerance: the accepted estimate, -. shift_step_m: the table's spacing, m.
    """

    success: bool
    status: str
    message: str
    equivalent_conicity: float
    harmonic_conicity: float
    amplitude_m: float
    wavelength_m: float
    half_contact_distance_m: float
    nominal_radius_m: float
    lateral_shift_m: np.ndarray
    rolling_radius_difference_m: np.ndarray
    rolling_radius_left_m: np.ndarray
    rolling_radius_right_m: np.ndarray
    roll_rad: np.ndarray
    discretisation_error_estimate: float
    tolerance: float
    shift_step_m: float

    def as_dict(self) -> dict:
        """JSON-ready dictionary (arrays as lists)."""
        out = {}
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            out[name] = value.tolist() if isinstance(value, np.ndarray) else value
        return out


def rolling_radius_difference(track, lateral_shifts_m, *, search_options=None):
    """Delta r(y) and the rigid-contact data for the given wheelset shifts (no yaw).

    Args:
        track: :class:`~rigid_dynamics.contact.track.WheelsetTrack`.
        lateral_shifts_m: y values, m (shape (n,)).
        search_options: options of the contact search (default: the profile-only fast path, valid without yaw).

    Returns:
        dict with arrays ``lateral_shift_m``, ``rolling_radius_left_m``, ``rolling_radius_right_m``, ``roll_rad``,
        ``contact_y_left_m``, ``contact_y_right_m`` (main-frame y of the contact points) and ``converged``.
    """
    from rigid_dynamics.contact.wheelset_case import rigid_contact

    options = {"field": False, "profile_only": True}
    options.update(search_options or {})
    ys = np.asarray(lateral_shifts_m, float)
    out = {k: np.full(ys.shape, math.nan) for k in ("left", "right", "roll", "y_left", "y_right")}
    converged = np.zeros(ys.shape, bool)
    for i, shift in enumerate(ys):
        contact = rigid_contact(track, float(shift), 0.0, search_options=options)
        converged[i] = contact.success
        out["roll"][i] = contact.pose.roll_rad
        for side in SIDES:
            out[side][i] = contact.rolling_radius_m[side]
            out["y_" + side][i] = contact.contact_point_m[side][1]
    return {
        "lateral_shift_m": ys,
        "rolling_radius_left_m": out["left"],
        "rolling_radius_right_m": out["right"],
        "roll_rad": out["roll"],
        "contact_y_left_m": out["y_left"],
        "contact_y_right_m": out["y_right"],
        "converged": converged,
    }


def klingel_wavelength(delta_r, amplitude_m: float, e0_r0_m2: float) -> float:
    """Wavelength L (m) of d2y/ds2 + Delta r(y)/(2 e0 r0) = 0 started at y = amplitude, y' = 0; nan if none.

    Args:
        delta_r: callable Delta r(y) (m -> m).
        amplitude_m: y_hat, m.
        e0_r0_m2: e0 r0, m^2.
    """
    from scipy.integrate import solve_ivp

    def rhs(_s, state):
        return [state[1], -float(delta_r(state[0])) / (2.0 * e0_r0_m2)]

    def turning(_s, state):
        return state[1]

    turning.direction = 1.0  # y' crosses 0 upwards: the lowest point of the oscillation
    turning.terminal = True
    guess = 2 * math.pi * math.sqrt(e0_r0_m2 / 0.01)  # wavelength of a conicity of 0.01
    back = solve_ivp(rhs, (0.0, 20 * guess), [amplitude_m, 0.0], events=turning, rtol=1e-10, atol=1e-14)
    if not back.t_events[0].size:
        return math.nan
    half = back.t_events[0][0]
    y_low = back.y_events[0][0][0]
    turning.direction = -1.0

    forth = solve_ivp(rhs, (0.0, 20 * guess), [y_low, 0.0], events=turning, rtol=1e-10, atol=1e-14)
    if not forth.t_events[0].size:
        return math.nan
    return float(half + forth.t_events[0][0])


MAX_TABLE_REFINEMENTS = 3
"""Halvings of the Delta r table's automatic spacing while its estimate exceeds the tolerance (each doubles the
contact solves)."""


def _conicities(shifts, delta, amplitude_m, e0_r0):
    """(wavelength m, equivalent conicity, harmonic conicity) of the Delta r table (module docstring)."""
    from scipy.interpolate import PchipInterpolator

    interp = PchipInterpolator(shifts, delta, extrapolate=True)
    wavelength = klingel_wavelength(interp, amplitude_m, e0_r0)
    conicity = 4 * math.pi**2 * e0_r0 / wavelength**2 if math.isfinite(wavelength) else math.nan
    t = np.linspace(0.0, 2 * math.pi, 721)[:-1]
    b1 = 2.0 * np.mean(interp(amplitude_m * np.sin(t)) * np.sin(t))
    return wavelength, conicity, float(b1 / (2.0 * amplitude_m))


def _relative_change(coarse: float, fine: float) -> float:
    """|coarse / fine - 1| (nan when either is not finite; 0 when both are 0, inf when only ``fine`` is)."""
    if not (math.isfinite(coarse) and math.isfinite(fine)):
        return math.nan
    if fine == 0.0:
        return 0.0 if coarse == 0.0 else math.inf
    return abs(coarse / fine - 1.0)


def _interleave(rows, middle):
    """rows[0], middle[0], rows[1], ... (length 2 n - 1 from n rows and n - 1 middles)."""
    out = np.empty(rows.size + middle.size, dtype=np.result_type(rows, middle))
    out[0::2] = rows
    out[1::2] = middle
    return out


def equivalent_conicity(
    wheel_profile,
    rail_profile,
    *,
    gauge_m: float = 1.435,
    gauge_height_m: float = 0.014,
    flange_back_distance_m: float = 1.360,
    nominal_radius_m: float = 0.46,
    rail_inclination_rad: float = math.atan(1.0 / 40.0),
    amplitude_m: float = 0.003,
    shift_step_m: float | None = None,
    tolerance: float = 0.01,
    search_options=None,
) -> ConicityResult:
    """Equivalent conicity of a wheel/rail profile pair at an amplitude (EN 15302 method, module docstring).

    Args:
        wheel_profile, rail_profile: built-in names, file paths, Profile objects or profile curves.
        gauge_m, gauge_height_m, flange_back_distance_m, nominal_radius_m: track and wheelset, m.
        rail_inclination_rad: rail inclination in the track (a pre-canted file is not canted twice, track.py).
        amplitude_m: y_hat, m (EN 15302 quotes 3 mm).
        shift_step_m: spacing of the Delta r table, m; None (default): min(0.1 mm, amplitude / 30), halved up to
            MAX_TABLE_REFINEMENTS times while the estimate exceeds ``tolerance``.
        tolerance: accepted relative discretisation-error estimate of the conicities (module docstring), -.

    Raises:
        ValueError: bad amplitude or step, or the errors of the profile readers and placement.
    """
    from rigid_dynamics.contact.track import build_track

    checked = (("amplitude_m", amplitude_m), ("tolerance", tolerance))
    for name, value in checked + ((("shift_step_m", shift_step_m),) if shift_step_m is not None else ()):
        if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    if amplitude_m > 0.012:
        raise ValueError(f"amplitude_m = {amplitude_m!r}: expected at most 0.012 m (beyond the flangeway clearance)")

    class _Case:
        pass

    case = _Case()
    case.wheel_profile, case.rail_profile = wheel_profile, rail_profile
    case.gauge_m, case.gauge_height_m = gauge_m, gauge_height_m
    case.flange_back_distance_m, case.nominal_radius_m = flange_back_distance_m, nominal_radius_m
    case.rail_inclination_rad = rail_inclination_rad
    track = build_track(case)
    automatic = shift_step_m is None
    step = min(1.0e-4, amplitude_m / 30.0) if automatic else shift_step_m
    reach = amplitude_m * 1.3 + 2 * step
    n = int(math.ceil(reach / step))
    table = rolling_radius_difference(track, step * np.arange(-n, n + 1), search_options=search_options)
    for refinement in range(MAX_TABLE_REFINEMENTS + 1):
        shifts = table["lateral_shift_m"]
        ok = table["converged"] & np.isfinite(table["rolling_radius_left_m"])
        ok &= np.isfinite(table["rolling_radius_right_m"])
        delta = table["rolling_radius_right_m"] - table["rolling_radius_left_m"]
        centre = int(np.argmin(np.abs(shifts)))
        e0 = 0.5 * (table["contact_y_right_m"][centre] - table["contact_y_left_m"][centre])
        e0_r0 = e0 * nominal_radius_m
        wavelength, conicity, harmonic = _conicities(shifts[ok], delta[ok], amplitude_m, e0_r0)
        coarse = ok & (np.abs(np.arange(shifts.size) - centre) % 2 == 0)  # every second row, the centre kept
        _, conicity_2, harmonic_2 = _conicities(shifts[coarse], delta[coarse], amplitude_m, e0_r0)
        estimate = max(_relative_change(conicity_2, conicity), _relative_change(harmonic_2, harmonic))
        stop = not automatic or estimate <= tolerance or not np.all(ok) or not math.isfinite(conicity)
        if stop or refinement == MAX_TABLE_REFINEMENTS:
            break
        # halve the spacing: the new rows between the old ones, the old rows kept
        step *= 0.5
        middle = rolling_radius_difference(track, 0.5 * (shifts[1:] + shifts[:-1]), search_options=search_options)
        table = {k: _interleave(table[k], middle[k]) for k in table}
    status, message = "ok", f"Delta r tabulated at {int(ok.sum())} shifts ({1e3 * step:.3g} mm apart)"
    if not np.all(ok):
        status, message = "not-converged", f"rigid contact failed at {int((~ok).sum())} shift(s); left out"
    if not math.isfinite(conicity):
        status, message = "no-oscillation", "Delta r(y) does not restore the wheelset: no kinematic oscillation"
    elif status == "ok" and math.isnan(estimate):
        status = "warning"
        message += "; the table of every second shift gives no conicity: the table's error is not estimated"
    elif status == "ok" and not estimate <= tolerance:
        status = "warning"
        message += (
            f"; the conicities change by {100 * estimate:.3g} % on the table of every second shift, above the "
            f"tolerance {100 * tolerance:g} %: "
            + ("refine shift_step_m" if not automatic else f"still after {MAX_TABLE_REFINEMENTS} halvings")
        )
    return ConicityResult(
        success=status == "ok",
        status=status,
        message=message,
        equivalent_conicity=float(conicity),
        harmonic_conicity=harmonic,
        amplitude_m=float(amplitude_m),
        wavelength_m=float(wavelength),
        half_contact_distance_m=float(e0),
        nominal_radius_m=float(nominal_radius_m),
        lateral_shift_m=shifts,
        rolling_radius_difference_m=delta,
        rolling_radius_left_m=table["rolling_radius_left_m"],
        rolling_radius_right_m=table["rolling_radius_right_m"],
        roll_rad=table["roll_rad"],
        discretisation_error_estimate=float(estimate),
        tolerance=float(tolerance),
        shift_step_m=float(step),
    )


def equivalent_conicity_from_names(
    wheel_profile,
    rail_profile,
    *,
    gauge_m: float = 1.435,
    gauge_height_m: float = 0.014,
    flange_back_distance_m: float = 1.360,
    nominal_radius_m: float = 0.46,
    rail_inclination_rad: float | None = None,
    amplitude_m: float = 0.003,
    shift_step_m: float | None = None,
    tolerance: float = 0.01,
) -> dict:
    """:func:`equivalent_conicity` as a JSON-ready dict (for the CLI); rail_inclination_rad None means 1:40."""
    if rail_inclination_rad is None:
        rail_inclination_rad = math.atan(1.0 / 40.0)
    return equivalent_conicity(
        wheel_profile,
        rail_profile,
        gauge_m=gauge_m,
        gauge_height_m=gauge_height_m,
        flange_back_distance_m=flange_back_distance_m,
        nominal_radius_m=nominal_radius_m,
        rail_inclination_rad=rail_inclination_rad,
        amplitude_m=amplitude_m,
        shift_step_m=shift_step_m,
        tolerance=tolerance,
    ).as_dict()
