"""wheelrail: railway wheelset dynamics and wheel-rail contact with a verified ladder of contact models.

The public API in one place (``import wheelrail as wr``; names are imported lazily on first use, so
``import wheelrail`` stays light). Frames and units: SI everywhere, units in the names; track frame x along
the track, y to the right, z down; contact forces act on the wheel in the patch's contact frame.

Profiles and materials
    load_profile, builtin_profiles, Material, STEEL, combined_from_pair
Contact: one patch, a batch, a case
    ContactGeometry, Creepage, ContactResult, ContactFields, models, get_model, solve_batch,
    ContactCase, load_case, embedded_cases, solve_case, CaseSolution, WheelsetCase, solve_wheelset_case,
    OperatingPoint, creep_sensitivities
Dynamics
    DynamicsScene, load_scene, embedded_scenes, Irregularities, simulate, SimulationResult,
    linear_model_for_scene, critical_speed, equivalent_conicity_from_names
Outputs and plots
    write_patch_files, timeseries_table, write_timeseries_table, plot_contact_fields, plot_patch,
    plot_dynamics, plot_simulation

``wheelrail.api()`` returns ``{name: one-line description}`` of all of them.

Example::

    import wheelrail as wr
    solution = wr.solve_case("hertz-quadric", "fastsim")   # a case, or its name or file
    solution.to_dataframe()                      # one row per patch
    run = wr.simulate("hunting-conical")         # a scene, or its name or file
    run.to_dataframe()                           # one row per output time, units in the column names
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_API: dict[str, tuple[str, str, str]] = {
    # profiles and materials
    "load_profile": ("rigid_dynamics.geometry", "load_profile", "a wheel or rail profile by built-in name or file"),
    "builtin_profiles": ("rigid_dynamics.geometry.readers", "builtin_profiles", "built-in profile names"),
    "Material": ("rigid_dynamics.materials", "Material", "elastic constants and friction of the pair"),
    "STEEL": ("rigid_dynamics.materials", "STEEL", "wheel and rail steel (G 82 GPa, nu 0.28, mu 0.3)"),
    "combined_from_pair": ("rigid_dynamics.materials", "combined_from_pair", "combined constants of two materials"),
    # contact
    "ContactGeometry": ("rigid_dynamics.contact.types", "ContactGeometry", "one patch's geometry (quadric or sampled)"),
    "Creepage": ("rigid_dynamics.contact.types", "Creepage", "longitudinal, lateral, spin creepage and speed"),
    "ContactResult": ("rigid_dynamics.contact.types", "ContactResult", "one patch solved by one model"),
    "ContactFields": ("rigid_dynamics.contact.types", "ContactFields", "pressure/traction/slip fields on a grid"),
    "models": ("rigid_dynamics.contact.registry", "model_names", "names of the registered contact models"),
    "get_model": ("rigid_dynamics.contact.registry", "get_model", "a contact model by name"),
    "solve_batch": ("rigid_dynamics.contact.models", "solve_batch", "Hertz + a creep law for arrays of patches"),
    "OperatingPoint": ("rigid_dynamics.contact.sensitivities", "OperatingPoint", "a patch and its operating point"),
    "creep_sensitivities": (
        "rigid_dynamics.contact.sensitivities",
        "creep_sensitivities",
        "d(Fx, Fy, Mz)/d(xi, eta, phi, N) of a rung at an operating point",
    ),
    "ContactCase": ("wheelrail.cases", "ContactCase", "a validated contact case (quadric or wheelset)"),
    "load_case": ("wheelrail.cases", "load_case", "read a case TOML file or embedded case"),
    "embedded_cases": ("wheelrail.cases", "embedded_cases", "embedded contact cases: name -> path"),
    "solve_case": ("wheelrail.cases", "solve_case", "solve a contact case with a model"),
    "CaseSolution": ("wheelrail.cases", "CaseSolution", "patches of a solved case"),
    "WheelsetCase": ("rigid_dynamics.contact.wheelset_case", "WheelsetCase", "wheelset on track, prescribed load"),
    "solve_wheelset_case": ("rigid_dynamics.contact.wheelset_case", "solve_wheelset_case", "solve a WheelsetCase"),
    # dynamics
    "DynamicsScene": ("rigid_dynamics.wheelset", "DynamicsScene", "everything a dynamics run needs"),
    "load_scene": ("wheelrail.scenes", "load_scene", "read a scene TOML file or embedded scene"),
    "embedded_scenes": ("wheelrail.scenes", "embedded_scenes", "embedded dynamics scenes: name -> path"),
    "Irregularities": ("rigid_dynamics.wheelset", "Irregularities", "wheel and rail irregularities of a scene"),
    "simulate": ("wheelrail.scenes", "simulate", "run a dynamics scene (a scene, or its name or file)"),
    "SimulationResult": ("rigid_dynamics.wheelset", "SimulationResult", "time series and status of a run"),
    "linear_model_for_scene": ("rigid_dynamics.wheelset", "linear_model_for_scene", "linearised wheelset"),
    "critical_speed": ("rigid_dynamics.wheelset", "critical_speed", "linear critical speed (eigenvalues)"),
    "equivalent_conicity_from_names": (
        "rigid_dynamics.contact.conicity",
        "equivalent_conicity_from_names",
        "EN 15302 equivalent conicity of a profile pair",
    ),
    # outputs and plots
    "write_patch_files": ("wheelrail.contact_files", "write_patch_files", "NPZ + VTU field files of a patch"),
    "timeseries_table": ("rigid_dynamics.wheelset.table", "to_dataframe", "tidy DataFrame of a run"),
    "write_timeseries_table": ("rigid_dynamics.wheelset.table", "write_table", "tidy CSV/Parquet of a run"),
    "plot_contact_fields": ("comparisons.contact_plots", "plot_contact_fields", "PNG maps of a patch's fields"),
    "plot_patch": ("wheelrail.contact_files", "plot_patch", "PNG of a patch (fields, or Hertz ellipse)"),
    "plot_dynamics": ("comparisons.dynamics_plots", "plot_dynamics", "PNG of a run's main time series"),
    "plot_simulation": ("comparisons.dynamics_plots", "plot_simulation", "all PNG plots of a run"),
}

__all__ = sorted(_API) + ["api", "__version__"]


def api() -> dict[str, str]:
    """The public names and a one-line description of each."""
    return {name: description for name, (_, _, description) in _API.items()}


def __getattr__(name: str):
    if name in _API:
        module, attribute, _ = _API[name]
        value = getattr(importlib.import_module(module), attribute)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'wheelrail' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
