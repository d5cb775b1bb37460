"""Linearised lateral dynamics of a single suspended wheelset with conical wheels, and its critical speed.

The classic two-degree-of-freedom model (lateral displacement y, yaw psi) of A.H. Wickens,
*Fundamentals of Rail Vehicle Dynamics* (Swets & Zeitlinger, 2003), ch. 2, and S. Iwnicki (ed.),
*Handbook of Railway Vehicle Dynamics* (2006), ch. "Rail vehicle dynamics" — written here in this
project's frames (x forward, y right, z down; yaw psi about z) and derived from the same creepages
as the nonlinear model (rigid_dynamics.contact.creepage, eq 39-49), linearised about centred rolling
at speed V with spin rate V/r0::

    lateral creepage (both wheels)   eta   = y'/V - psi          (contact frame y points left: the
                                                                  sign flips on both sides alike)
    longitudinal creepage, right     xi_R  = -e0 psi'/V - lambda y/r0,   left xi_L = -xi_R

    m y''    = [-2 f22 ((1 + kappa) y'/V - psi) - k_g y] / (1 - kappa) - k_y y - c_y y'
    J_z psi'' = -2 f11 e0 (e0 psi'/V + lambda y / r0) - k_psi psi - c_psi psi'

Symbols: m mass (kg), J_z yaw inertia (kg m^2), f11 = G a b C11 and f22 = G a b C22 Kalker's
longitudinal and lateral creep coefficients per wheel (N), lambda conicity, e0 half distance of the
contact points (m), r0 rolling radius (m), k_y = 2 k_lat (N/m), c_y = 2 c_lat (N s/m),
k_psi = 2 (k_long b^2 + k_yaw) (N m/rad), c_psi = 2 (c_long b^2 + c_yaw) (N m s/rad), b the suspension
half spacing (m), and k_g = W lambda / e0 the gravitational stiffness of coned wheels (W the total
vertical load, N): a lateral shift y rolls the axle by -lambda y / e0, which tilts both contact normals
so that their lateral components add to -W lambda y / e0 (derived for a cone touching a rail at a
fixed point; Wickens 2003 sec. 2.3 discusses the gravitational stiffness). With kappa = 0 this is the
classic model. kappa = lambda r0 / e0 adds the two first-order effects of the quasi-static roll
theta = -lambda y / e0 that the contact points below the centre bring (derived here): (i) the roll rate
moves the contact point laterally by -r0 theta', so eta = (1 + kappa) y'/V - psi; (ii) the lateral contact
force F acting r0 below the centre transfers load N_R - N_L = -r0 F / e0, whose normal forces, tilted by
+-lambda, add lambda r0 F / e0 to F, so the total is (F_creep + F_grav) / (1 - kappa). Spin-creep coupling
(f23 terms) and the gyroscopic couple are left out, as in the classic model; for the small conicity
and the spin levels of a conical tread they change the critical speed by far less than 1 %.

The kinematic limit (f11, f22 -> infinity, no suspension) gives Klingel's wavelength
2 pi sqrt(r0 e0 / lambda).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rigid_dynamics.materials import STANDARD_GRAVITY_M_PER_S2
from rigid_dynamics.wheelset.parameters import DynamicsScene


@dataclass(frozen=True)
class LinearWheelset:
    """Parameters of the linear 4-state model (module docstring), SI units.

    Attributes:
        mass_kg, yaw_inertia_kg_m2: m, J_z.
        conicity: lambda (the effective one when the rail head is not a point).
        nominal_radius_m, contact_half_distance_m: r0, e0.
        creep_long_N, creep_lat_N: f11, f22 per wheel, N.
        lateral_stiffness_N_per_m, lateral_damping_N_s_per_m: k_y, c_y for the whole wheelset.
        yaw_stiffness_N_m_per_rad, yaw_damping_N_m_s_per_rad: k_psi, c_psi for the whole wheelset.
        gravitational_stiffness_N_per_m: k_g.
        roll_coupling: kappa (0 for the classic model).
    """

    mass_kg: float
    yaw_inertia_kg_m2: float
    conicity: float
    nominal_radius_m: float
    contact_half_distance_m: float
    creep_long_N: float
    creep_lat_N: float
    lateral_stiffness_N_per_m: float = 0.0
    lateral_damping_N_s_per_m: float = 0.0
    yaw_stiffness_N_m_per_rad: float = 0.0
    yaw_damping_N_m_s_per_rad: float = 0.0
    gravitational_stiffness_N_per_m: float = 0.0
    roll_coupling: float = 0.0

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")
        for name in ("mass_kg", "yaw_inertia_kg_m2", "nominal_radius_m", "contact_half_distance_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected > 0")
        if not 0 <= self.roll_coupling < 1:
            raise ValueError(f"roll_coupling = {self.roll_coupling!r}: expected a value in [0, 1)")
        for name in ("creep_long_N", "creep_lat_N", "conicity"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} = {getattr(self, name)!r}: expected >= 0")

    def state_matrix(self, speed_m_per_s: float) -> np.ndarray:
        """A(V) of x' = A x, x = [y, psi, y', psi'] (module docstring)."""
        if not speed_m_per_s > 0:
            raise ValueError(f"speed_m_per_s = {speed_m_per_s!r}: expected > 0")
        v = speed_m_per_s
        m, jz = self.mass_kg, self.yaw_inertia_kg_m2
        lam, r0, e0 = self.conicity, self.nominal_radius_m, self.contact_half_distance_m
        f11, f22 = self.creep_long_N, self.creep_lat_N
        kappa = self.roll_coupling
        amplify = 1.0 / (1.0 - kappa)
        a = np.zeros((4, 4))
        a[0, 2] = a[1, 3] = 1.0
        a[2, 0] = -(self.gravitational_stiffness_N_per_m * amplify + self.lateral_stiffness_N_per_m) / m
        a[2, 1] = 2 * f22 * amplify / m
        a[2, 2] = -(2 * f22 * (1 + kappa) * amplify / v + self.lateral_damping_N_s_per_m) / m
        a[3, 0] = -2 * f11 * e0 * lam / (r0 * jz)
        a[3, 1] = -self.yaw_stiffness_N_m_per_rad / jz
        a[3, 3] = -(2 * f11 * e0 * e0 / v + self.yaw_damping_N_m_s_per_rad) / jz
        return a

    def eigenvalues(self, speed_m_per_s: float) -> np.ndarray:
        """Eigenvalues of A(V), 1/s."""
        return np.linalg.eigvals(self.state_matrix(speed_m_per_s))

    def max_real_part(self, speed_m_per_s: float) -> float:
        """Largest real part of the eigenvalues (> 0: unstable), 1/s."""
        return float(np.max(self.eigenvalues(speed_m_per_s).real))

    def kinematic_wavelength_m(self) -> float:
        """Klingel's wavelength 2 pi sqrt(r0 e0 / lambda), m."""
        return 2 * math.pi * math.sqrt(self.nominal_radius_m * self.contact_half_distance_m / self.conicity)


@dataclass(frozen=True)
class CriticalSpeed:
    """Result of :func:`critical_speed`: success/status/message and the speed, m/s (nan if none)."""

    success: bool
    status: str
    message: str
    speed_m_per_s: float
    frequency_Hz: float


def critical_speed(
    model: LinearWheelset, min_speed_m_per_s: float = 1.0, max_speed_m_per_s: float = 200.0, points: int = 400
) -> CriticalSpeed:
    """Lowest speed at which the largest real eigenvalue part crosses zero (scan, then Brent's method)."""
    from scipy.optimize import brentq

    speeds = np.linspace(min_speed_m_per_s, max_speed_m_per_s, points)
    growth = np.array([model.max_real_part(v) for v in speeds])
    if growth[0] > 0:
        return CriticalSpeed(
            False, "unstable-at-min", f"unstable already at {min_speed_m_per_s} m/s", math.nan, math.nan
        )
    crossing = np.flatnonzero((growth[:-1] <= 0) & (growth[1:] > 0))
    if len(crossing) == 0:
        return CriticalSpeed(False, "stable", f"stable up to {max_speed_m_per_s} m/s", math.nan, math.nan)
    i = int(crossing[0])
    speed = brentq(model.max_real_part, speeds[i], speeds[i + 1], xtol=1e-10)
    eig = model.eigenvalues(speed)
    freq = float(np.max(np.abs(eig[np.argmax(eig.real)].imag))) / (2 * math.pi)
    return CriticalSpeed(True, "ok", "zero crossing of the largest real part", float(speed), freq)


def linear_model_for_scene(
    scene: DynamicsScene, creep_long_N: float, creep_lat_N: float, *, classic: bool = False
) -> LinearWheelset:
    """The linear model of a conical scene, given the creep coefficients f11, f22 per wheel (N).

    The conicity is the effective one of the analytic conical provider,
    lambda / (1 - lambda R_r / e0) (providers/conical.py), and W = m g + axle load. ``classic`` drops the
    roll coupling (kappa = 0). The suspension's ``frame_yaw_rad`` is a constant forcing: it moves the equilibrium,
    not the eigenvalues of this linear model, so it does not enter it.
    """
    ws, susp, track = scene.wheelset, scene.suspension, scene.track
    lam, e0 = track.conicity, ws.contact_half_distance_m
    lam_eff = lam / (1.0 - lam * track.rail_head_radius_m / e0)
    weight = ws.mass_kg * STANDARD_GRAVITY_M_PER_S2 + scene.loads.axle_load_N
    b = ws.suspension_half_spacing_m
    return LinearWheelset(
        mass_kg=ws.mass_kg,
        yaw_inertia_kg_m2=ws.transverse_inertia_kg_m2,
        conicity=lam_eff,
        nominal_radius_m=ws.nominal_radius_m,
        contact_half_distance_m=e0,
        creep_long_N=creep_long_N,
        creep_lat_N=creep_lat_N,
        lateral_stiffness_N_per_m=2 * susp.lateral_stiffness_N_per_m,
        lateral_damping_N_s_per_m=2 * susp.lateral_damping_N_s_per_m,
        yaw_stiffness_N_m_per_rad=2 * (susp.longitudinal_stiffness_N_per_m * b * b + susp.yaw_stiffness_N_m_per_rad),
        yaw_damping_N_m_s_per_rad=2 * (susp.longitudinal_damping_N_s_per_m * b * b + susp.yaw_damping_N_m_s_per_rad),
        gravitational_stiffness_N_per_m=weight * lam_eff / e0,
        roll_coupling=0.0 if classic else lam_eff * ws.nominal_radius_m / e0,
    )


def creep_sensitivities_at_rest(scene: DynamicsScene, contact_model=None, provider=None) -> list:
    """The creep-force sensitivities (rigid_dynamics.contact.sensitivities) of every wheel in contact of the centred
    wheelset at rest on its static load, at zero creepage: one CreepSensitivities per patch (left wheel first).

    The rung is ``contact_model`` (default the scene's) with the options a run gives it (simulate.model_options:
    the scene's FASTSIM grid, auto's tolerance); the patch is the static equilibrium's (approach, curvatures), the
    derivatives under force control at its normal force. Analytic for the linear and Vermeulen-Johnson rungs (there
    the slopes are Kalker's G a b C11, G a b C22), central differences for the others (FASTSIM, KPEC, BEM: their
    grid's slope at zero creepage, with its difference error).

    Raises:
        ValueError: no static equilibrium, no wheel in contact, or a rung whose sensitivities failed (its message).
    """
    from dataclasses import replace

    from rigid_dynamics.contact.sensitivities import OperatingPoint, creep_sensitivities
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.wheelset.parameters import InitialConditions
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, initial_state, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    centred = replace(scene, initial=InitialConditions())
    provider = provider if provider is not None else build_provider(centred)
    model_obj = get_contact_model(contact_model if contact_model is not None else scene.contact_model)
    options = model_options(getattr(model_obj, "name", ""), scene)
    model = WheelsetModel(centred, provider, model_obj, options)
    state, ok, why = model.static_state(initial_state(centred))
    if not ok:
        raise ValueError(f"no static equilibrium for the creep coefficients: {why}")
    patches = provider.patches(state[:3], state[3], state[4], state[5])
    out = []
    for k in np.argsort(patches.side, kind="stable"):
        if patches.approach_m[k] <= 0:
            continue
        geometry = ContactGeometry(
            float(patches.curvature_long_1_per_m[k]),
            float(patches.curvature_lat_1_per_m[k]),
            float(patches.approach_m[k]),
        )
        point = OperatingPoint(geometry, Creepage(0.0, 0.0, 0.0, scene.speed_m_per_s), scene.material, None, options)
        sens = creep_sensitivities(model_obj, point)
        if not sens.success:
            raise ValueError(f"creep sensitivities of {sens.method!r} at rest: {sens.status}: {sens.message}")
        out.append(sens)
    if not out:
        raise ValueError("no wheel in contact at rest: cannot linearise the creep forces")
    return out


def creep_coefficients(scene: DynamicsScene, contact_model=None, provider=None) -> tuple[float, float]:
    """Creep coefficients f11, f22 (N) of the centred wheelset at rest on its static load: the slopes at zero
    creepage of the rung's creep forces, f11 = -dFx/dxi, f22 = -dFy/deta (:func:`creep_sensitivities_at_rest`; for
    the linear rung Kalker's G a b C11, G a b C22), averaged over both wheels.
    """
    coef = [s.coefficients() for s in creep_sensitivities_at_rest(scene, contact_model, provider)]
    return float(np.mean([c.f11_N for c in coef])), float(np.mean([c.f22_N for c in coef]))
