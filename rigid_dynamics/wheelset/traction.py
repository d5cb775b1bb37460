"""A traction or braking controller: the axle torque that holds a longitudinal creep force or an adhesion demand.

A drive or brake does not prescribe its torque; it regulates it so that the wheelset transmits a demanded
longitudinal force, within the torque its motor or brake can give. The scene table ``[traction]``
(:class:`TractionControl`, docs/files.md) describes the controller; :class:`TractionController` runs it.

**The control law** (a sampled PI controller with feed-forward, zero-order hold). At the sample times t_k (the
run's output times, ``integrator.output_step_s``; the compiled loop stops there, drivers.run_compiled) the
controller measures the total longitudinal creep force F_k = sum T_x over every patch of both wheels (on the wheels,
contact frames, N; > 0 drives the wheelset forward) and the total normal force N_k (N), and sets the axle torque
held until the next sample::

    D_k = r(t_k) F_d                    (mode "force": force_demand_N = F_d)
    D_k = r(t_k) f_d N_k                (mode "adhesion": adhesion_demand = f_d, the demanded T_x / N)
    e_k = D_k - F_k
    u_k = r_0 D_k + K_p e_k + I_k,      T_k = min(max(u_k, -T_max), T_max)
    I_k = I_(k-1) + K_i (t_k - t_(k-1)) e_(k-1)   (not while T_(k-1) sat at the limit and e_(k-1) pushed beyond it)

with r(t) = min(1, t / ramp_time_s) the demand's ramp (1 without a ramp), r_0 the nominal rolling radius (the
feed-forward r_0 D_k is the steady torque of a wheelset that transmits D_k at that radius), K_p
(``proportional_gain_m``, N m of torque per N of force error), K_i (``integral_gain_m_per_s``, N m per N and s) and
T_max (``torque_limit_N_m``). The integral term removes the steady error the feed-forward leaves (rolling radii
other than r_0, the spin moments); the anti-windup (conditional integration) keeps the integral from growing while
the torque sits at its limit. Sign: a torque > 0 drives forward rolling (loads.traction_torque_N_m's convention),
and a braking demand is a negative force or adhesion demand.

Beyond the adhesion limit no torque holds the demand: on a falling creep curve the force falls as the slip grows,
the error grows, the torque runs to its limit and the wheel slides; the run's events (recorder.adhesion_events)
mark the adhesion limit and the wheel slide.

With slip protection (``slip_limit`` = xi_max > 0) the error is the smaller, in the demand's direction, of the
force error and a creepage error that vanishes at the slip limit::

    e_k = sgn(D_k) min(sgn(D_k) (D_k - F_k), |D_k| (1 - |xi_k| / xi_max))

(|xi_k| the largest longitudinal creepage of the patches in contact): below the limit and short of the demand the
controller raises the torque as before; a demand the adhesion cannot give no longer runs the wheel into a slide but
holds it at |xi| = xi_max (the creep controller of a wheel-slide protection or anti-slip system), on the falling
branch of the creep curve if xi_max lies beyond its maximum.

The plant seen by the controller is fast: the wheelset's spin against its creep stiffness settles in
J_a V / (k r_0^2) (0.5 ms for 112 kg m^2, 20 m/s, k = 2.2e7 N per unit creepage for the axle), so at a 1 ms sample
the measured force is close to T_(k-1) / r_0 and the proportional loop is stable for K_p < r_0; the integral's time
constant is about (r_0 + K_p) / K_i (28 ms for K_i = 20 m/s). On the creepage error of the slip protection the
torque changes by K_p |D| / xi_max per unit creepage, whose loop through the wheel's spin
(dxi/dt = r_0 (T - r_0 F) / (V J_a)) is stable at the sample dt while K_p |D| r_0 dt / (xi_max V J_a) < 2 (0.16 for
80 kN, xi_max = 0.01, dt = 1 ms).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TRACTION_MODES = ("none", "force", "adhesion")
"""``[traction] mode``: "none" (no controller: the torque is loads.traction_torque_N_m), "force" (hold
force_demand_N) or "adhesion" (hold adhesion_demand times the measured normal force)."""


@dataclass(frozen=True)
class TractionControl:
    """The scene's traction or braking controller (module docstring for the law).

    Attributes:
        mode: one of :data:`TRACTION_MODES`.
        force_demand_N: F_d, the demanded total longitudinal creep force on the wheelset's wheels (both wheels, in
            the contact frames, > 0 traction, < 0 braking), N (mode "force").
        adhesion_demand: f_d, the demanded ratio of that force to the total normal force (> 0 traction, < 0
            braking; mode "adhesion"), dimensionless, |f_d| <= 1.
        proportional_gain_m: K_p >= 0, N m of torque per N of force error (m).
        integral_gain_m_per_s: K_i >= 0, N m of torque per N of force error and second (m/s).
        torque_limit_N_m: T_max > 0, the largest axle torque of the drive or brake, N m.
        ramp_time_s: the demand rises linearly from zero over this time, s (0: a step at t = 0).
        slip_limit: xi_max, the longitudinal creepage the slip protection holds the wheels to, in (0, 1)
            (0: no slip protection).
    """

    mode: str = "none"
    force_demand_N: float = 0.0
    adhesion_demand: float = 0.0
    proportional_gain_m: float = 0.1
    integral_gain_m_per_s: float = 20.0
    torque_limit_N_m: float = 50.0e3
    ramp_time_s: float = 0.0
    slip_limit: float = 0.0

    def __post_init__(self) -> None:
        if self.mode not in TRACTION_MODES:
            raise ValueError(f"mode = {self.mode!r}: expected one of {', '.join(TRACTION_MODES)}")
        for name in ("force_demand_N", "adhesion_demand", "proportional_gain_m", "integral_gain_m_per_s",
                     "torque_limit_N_m", "ramp_time_s", "slip_limit"):  # fmt: skip
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")
        for name in ("proportional_gain_m", "integral_gain_m_per_s", "ramp_time_s"):
            if getattr(self, name) < 0.0:
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected a number >= 0")
        if not self.torque_limit_N_m > 0.0:
            raise ValueError(f"torque_limit_N_m = {self.torque_limit_N_m!r}: expected a number > 0 (N m)")
        if not 0.0 <= self.slip_limit < 1.0:
            raise ValueError(f"slip_limit = {self.slip_limit!r}: expected a creepage in (0, 1), or 0 for none")
        if abs(self.adhesion_demand) > 1.0:
            raise ValueError(f"adhesion_demand = {self.adhesion_demand!r}: expected a ratio T_x / N within [-1, 1]")
        if self.mode == "force" and self.force_demand_N == 0.0:
            raise ValueError("force_demand_N = 0.0: expected a nonzero demand (N) for mode = 'force'")
        if self.mode == "adhesion" and self.adhesion_demand == 0.0:
            raise ValueError("adhesion_demand = 0.0: expected a nonzero ratio for mode = 'adhesion'")

    @property
    def active(self) -> bool:
        """True when a controller sets the torque."""
        return self.mode != "none"


TRACTION_SERIES = ("traction_torque_N_m", "traction_demand_N", "traction_measured_force_N")
"""What the controller records per sample: the torque held from the sample on (N m), the demand D_k and the
measured total longitudinal creep force F_k (N)."""


class TractionController:
    """The sampled PI controller of :class:`TractionControl` (module docstring); one per run.

    :meth:`update` takes the measurement at a sample and returns the torque to hold until the next; ``log`` keeps
    one row per sample (time and :data:`TRACTION_SERIES`).
    """

    def __init__(self, control: TractionControl, nominal_radius_m: float):
        self.control = control
        self.radius = float(nominal_radius_m)
        self.integral = 0.0
        self.last = None  # (t, error, saturated direction) of the previous sample
        self.log: list[tuple[float, float, float, float]] = []

    def demand_N(self, t: float, normal_force_N: float) -> float:
        """D(t): the demanded total longitudinal creep force at time t and measured normal force, N."""
        c = self.control
        ramp = 1.0 if c.ramp_time_s == 0.0 else min(1.0, t / c.ramp_time_s)
        return ramp * (c.force_demand_N if c.mode == "force" else c.adhesion_demand * normal_force_N)

    def update(self, t: float, creep_force_N: float, normal_force_N: float, creepage: float = 0.0) -> float:
        """The torque (N m) from the sample at t: measured total longitudinal creep force and normal force (N), and
        the largest |xi| of the patches in contact (for the slip protection).
        """
        c = self.control
        if self.last is not None:
            t_last, e_last, saturated = self.last
            if saturated == 0 or saturated * e_last < 0.0:  # conditional integration (anti-windup)
                self.integral += c.integral_gain_m_per_s * (t - t_last) * e_last
        demand = self.demand_N(t, normal_force_N)
        error = demand - creep_force_N
        if c.slip_limit > 0.0 and demand != 0.0:
            sign = math.copysign(1.0, demand)
            error = sign * min(sign * error, abs(demand) * (1.0 - abs(creepage) / c.slip_limit))
        u = self.radius * demand + c.proportional_gain_m * error + self.integral
        torque = min(max(u, -c.torque_limit_N_m), c.torque_limit_N_m)
        saturated = 0 if torque == u else (1 if u > 0 else -1)
        self.last = (t, error, saturated)
        self.log.append((t, torque, demand, creep_force_N))
        return torque

    def series(self, t: np.ndarray) -> dict:
        """The log at the run's output times ``t`` (a sample for each; NaN where none was taken): the arrays of
        :data:`TRACTION_SERIES`.
        """
        out = {name: np.full(len(t), np.nan) for name in TRACTION_SERIES}
        if not self.log or len(t) == 0:
            return out
        rows = np.array(self.log)
        tol = 1e-9 * max(1.0, float(np.max(t)))
        k = np.minimum(np.searchsorted(rows[:, 0], t - tol), len(rows) - 1)
        found = np.abs(rows[k, 0] - t) <= tol
        for j, name in enumerate(TRACTION_SERIES):
            out[name][found] = rows[k[found], j + 1]
        return out
