"""Rigid wheelset dynamics on two rails (seed section 3.3, eq 59-71).

Public API::

    from rigid_dynamics.wheelset import DynamicsScene, simulate, save_timeseries
    result = simulate(scene, progress=None)        # -> SimulationResult (never raises for numerical trouble)
    result.summary()                               # JSON-ready dict (status, forces, wavelength, ...)
    save_timeseries(result, "out/series.npz")      # atomic NPZ

Parameters are frozen dataclasses with SI units in the field names (parameters.py); contact geometry comes
from a provider (the providers package: conical analytic, tables, profile section, 3-D search); the contact model is any
registered one (rigid_dynamics.contact.registry).
"""

from rigid_dynamics.wheelset.linear import CriticalSpeed, LinearWheelset, critical_speed, linear_model_for_scene
from rigid_dynamics.wheelset.parameters import (
    CONTACT_PROVIDERS,
    INTEGRATORS,
    DynamicsScene,
    InitialConditions,
    IntegratorSettings,
    Irregularities,
    LoadParameters,
    SuspensionParameters,
    TrackDynamics,
    TrackGeometry,
    WheelsetParameters,
)
from rigid_dynamics.wheelset.simulate import (
    STATUSES,
    SimulationResult,
    build_provider,
    dominant_wavelength_m,
    save_timeseries,
    simulate,
    timeseries_arrays,
)

__all__ = [
    "CONTACT_PROVIDERS",
    "INTEGRATORS",
    "STATUSES",
    "CriticalSpeed",
    "DynamicsScene",
    "InitialConditions",
    "IntegratorSettings",
    "Irregularities",
    "LinearWheelset",
    "LoadParameters",
    "SimulationResult",
    "SuspensionParameters",
    "TrackDynamics",
    "TrackGeometry",
    "WheelsetParameters",
    "build_provider",
    "critical_speed",
    "dominant_wavelength_m",
    "linear_model_for_scene",
    "save_timeseries",
    "simulate",
    "timeseries_arrays",
]
