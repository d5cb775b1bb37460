"""The compiled run's records: what a run hands the compiled right-hand side and loops, packed once.

:func:`pack` turns a WheelsetModel, its provider, the Hertz/Kalker tables and the contact model into a
:class:`PackedRun`: the parameter record (layout.PARAMETERS: numba compiles ``par.mass_kg`` to a load at a fixed
offset; a structured numpy record keeps numba's on-disk cache working, where a jitclass or structref argument made
every new process recompile, measured with numba 0.68), the tables of compiled_laws.HertzKalkerTables, the
candidates' sides and slots, where the geometry comes from (the provider answers: ``compiled_geometry()``) and its
record (compiled_tables.TableGeometry, compiled_search.SearchArgs). The contact model declares the law the loop
runs in its place (``compiled_law``, compiled_laws.LAW_CODES; None or absent: the callback).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from rigid_dynamics.wheelset import track
from rigid_dynamics.wheelset.compiled_laws import (
    LAW_AUTO,
    LAW_CALLBACK,
    LAW_CODES,
    LAW_TABLE,
    HertzKalkerTables,
    auto_parameters,
    hertz_kalker_tables,
)
from rigid_dynamics.wheelset.compiled_search import SearchArgs, no_search_args, search_args
from rigid_dynamics.wheelset.compiled_tables import (
    TableGeometry,
    irregularity_parameters,
    no_table_geometry,
    table_geometry,
)
from rigid_dynamics.wheelset.layout import (
    GEOMETRY_GIVEN,
    GEOMETRY_SEARCH,
    GEOMETRY_TABLES,
    N_FIELDS,
    new_parameters,
)
from rigid_dynamics.wheelset.state import n_states


class PackedRun(NamedTuple):
    """A run as the compiled code takes it: the parameter record, the Hertz/Kalker tables, the candidates' sides
    (0 left, 1 right) and slots, the geometry mode (layout.GEOMETRY_TABLES, GEOMETRY_SEARCH, GEOMETRY_GIVEN) and
    the records of the tables and the search modes (the mode's own is read; the other is of the right types).
    """

    par: np.void
    tables: HertzKalkerTables
    sides: np.ndarray
    slots: np.ndarray
    mode: int
    geometry: TableGeometry
    search: SearchArgs


def geometry_mode(provider) -> int:
    """Where the right-hand side gets the contact geometry of ``provider``: what its ``compiled_geometry()`` answers
    (providers.TableProvider: the compiled tables; providers.SearchProvider on tabulated surfaces: the compiled 3-D
    search), else layout.GEOMETRY_GIVEN (the conical provider, the search on measured grids or harmonics, user
    providers: wheelset_model.WheelsetModel fills the candidates).
    """
    answer = getattr(provider, "compiled_geometry", None)
    return int(answer()) if callable(answer) else GEOMETRY_GIVEN


def law_code(model, patch_geometry: str = "sampled") -> int:
    """The compiled law of a contact model instance (compiled_laws.LAW_CODES of its ``compiled_law``; None or absent:
    LAW_CALLBACK, every patch through the callback). With ``patch_geometry`` "formed" (DynamicsScene.patch_geometry)
    a model that solves a gap (callback._solves_gap: kpec) goes through the callback too, on the formed patches.
    """
    code = LAW_CODES.get(getattr(model, "compiled_law", None), LAW_CALLBACK)
    if patch_geometry == "formed" and code not in (LAW_CALLBACK, LAW_AUTO):
        from rigid_dynamics.wheelset.callback import _solves_gap

        if _solves_gap(model):
            return LAW_CALLBACK
    return code


def supported(scene, provider) -> bool:
    """Whether the compiled loop can run this scene: method RK4, DP54 or BS32 and a provider whose geometry is
    compiled (tables or search). Any contact model: the compiled laws inline, ``auto``'s choice inline, the others
    (bem, fea, user models) through the callback.
    """
    from rigid_dynamics.wheelset.tableaux import TABLEAUX

    return scene.integrator.method in TABLEAUX and geometry_mode(provider) != GEOMETRY_GIVEN


def model_parameters(model_wheelset):
    """The parameter record's fields of the equations of motion, the suspension, the run's limits and the elastic
    track, from a WheelsetModel (the contact fields stay zero: :func:`pack` adds them for the compiled loop).
    """
    m = model_wheelset
    scene = m.scene
    par = new_parameters()
    par["mass_kg"], par["inertia_transverse_kg_m2"], par["inertia_axial_kg_m2"] = m.mass, m.j_body[0, 0], m.j_body[1, 1]
    par["gravity_m_per_s2"] = m.gravity
    par["suspension_kx_N_per_m"], par["suspension_ky_N_per_m"], par["suspension_kz_N_per_m"] = m.k
    par["suspension_cx_N_s_per_m"], par["suspension_cy_N_s_per_m"], par["suspension_cz_N_s_per_m"] = m.c
    par["yaw_stiffness_N_m_per_rad"], par["yaw_damping_N_m_s_per_rad"] = m.k_yaw, m.c_yaw
    par["frame_yaw_rad"] = m.frame_yaw
    par["suspension_half_spacing_m"], par["frame_z_m"], par["frame_x0_m"], par["speed_m_per_s"] = (
        m.half_spacing,
        m.z_frame,
        m.frame_x0,
        m.speed,
    )
    par["axle_load_N"], par["torque_N_m"] = m.axle_load, m.torque
    par["max_force_N"] = scene.integrator.max_force_factor * scene.static_wheel_load_N
    par["max_lateral_m"] = scene.integrator.max_lateral_displacement_m
    geometry = scene.track
    if geometry.curved:
        par["track_frame"] = 1.0
        par["curvature_1_per_m"] = geometry.curvature_1_per_m
        par["cant_sin"], par["cant_cos"] = math.sin(geometry.cant_rad), math.cos(geometry.cant_rad)
        par["carried_mass_kg"] = m.axle_load / m.gravity
    track.pack_parameters(par, scene.track_dynamics, track.travel_m(scene))
    return par


def friction_law_of(material):
    """The friction law of a material: ``material.friction_law()`` where the material carries one (a
    contact.friction.FrictionLaw), else Coulomb with its ``friction_coefficient``. The compiled loop takes the
    static inclination and the track distance as places; a law on the rail's lateral coordinate raises ValueError.
    """
    from rigid_dynamics.contact.friction import uniform

    getter = getattr(material, "friction_law", None)
    law = getter() if callable(getter) else uniform(material.friction_coefficient)
    if law.varies_with == "rail_lateral":
        raise ValueError(
            "friction.varies_with = 'rail_lateral': not available in dynamics (the loop has the contact angle and "
            "the track distance of a patch); expected 'surface_inclination' or 'track_distance'"
        )
    return law


def _creep_table(scene, law, opts):
    """FASTSIM's creep-force table at the run's grid, traction bound and flexibility for the scene's material
    (contact.creep_table: from memory, the disk cache, or built); ValueError (contact.creep_table.TableUnavailable)
    for a falling friction law.
    """
    from rigid_dynamics.contact.creep_table import SourceOptions, check_friction, creep_table

    check_friction(law)
    options = SourceOptions("fastsim", int(opts["nx"]), int(opts["ny"]), opts["traction_bound"], opts["flexibility"])
    return creep_table(scene.material.poisson_ratio, options).table


def pack(model_wheelset, provider, tables, model, options=None, tolerance=0.05, python_geometry=False) -> PackedRun:
    """The :class:`PackedRun` of a WheelsetModel, its provider, the Hertz / Kalker tables and the contact model
    instance. ``options``: FASTSIM's (nx, ny, traction_bound, flexibility) for ``fastsim``, ``table`` (its source)
    and ``auto``;
    ``tolerance``: auto's; ``python_geometry``: the geometry given by Python for any provider.
    """
    from rigid_dynamics.contact.fastsim import FLEXIBILITY_CODES
    from rigid_dynamics.contact.search import DEFAULT_OPTIONS as SEARCH_OPTIONS
    from rigid_dynamics.wheelset.auto_reuse import reuse_store

    mode = GEOMETRY_GIVEN if python_geometry else geometry_mode(provider)
    m = model_wheelset
    scene = m.scene
    par = model_parameters(m)
    par["shear_modulus_Pa"] = scene.material.shear_modulus_Pa
    par["contact_modulus_Pa"] = tables.e_star
    law = friction_law_of(scene.material)
    par["friction_coefficient"] = law.max_static  # the coefficient of Coulomb's uniform law; else mu_s at most
    code = law_code(model, scene.patch_geometry)
    par["model_code"] = code
    par["z_ref_m"] = provider.z_ref if mode == GEOMETRY_TABLES else 0.0
    opts = {"nx": 20, "ny": 20, "traction_bound": "elliptic", "flexibility": "three"}
    opts.update({k: v for k, v in (options or {}).items() if k in opts})
    par["fastsim_nx"], par["fastsim_ny"] = int(opts["nx"]), int(opts["ny"])
    par["fastsim_parabolic"] = 1.0 if opts["traction_bound"] == "parabolic" else 0.0
    par["flexibility_code"] = FLEXIBILITY_CODES[opts["flexibility"]]
    par["kpec_nx"] = par["kpec_ny"] = scene.kpec_points
    par["kpec_margin"] = SEARCH_OPTIONS["field_margin"]
    par["patch_sampled"] = 1.0 if scene.patch_geometry in ("sampled", "formed") else 0.0
    if code == LAW_AUTO:
        auto_parameters(par, tolerance, (opts["nx"], opts["ny"]))
        par["auto_fastsim_table"] = 1.0 if getattr(scene, "creep_table", False) else 0.0
        par["auto_reuse"] = 1.0 if getattr(scene, "auto_reuse", True) else 0.0
    hk = hertz_kalker_tables(
        tables,
        law,
        _creep_table(scene, law, opts) if code == LAW_TABLE or par["auto_fastsim_table"] else None,
        reuse_store(_candidates(provider, mode)),
    )
    if mode == GEOMETRY_TABLES:
        par["nominal_radius_m"] = provider.r0
        if provider.irregularities is not None:
            irregularity_parameters(par, provider.irregularities, provider._irr_sides, provider.r0)
        sides = np.asarray(provider.side, np.int64)
        geometry = table_geometry(provider)
        return PackedRun(par, hk, sides, geometry.slots, mode, geometry, no_search_args())
    sides = np.array([0, 0, 1, 1], np.int64)
    slots = np.array([0, 1, 0, 1], np.int64)
    if mode == GEOMETRY_SEARCH:
        par["nominal_radius_m"] = provider.r0
        return PackedRun(par, hk, sides, slots, mode, no_table_geometry(slots), search_args(provider, provider.options))
    par["nominal_radius_m"] = getattr(provider, "r0", scene.wheelset.nominal_radius_m)
    return PackedRun(par, hk, sides, slots, mode, no_table_geometry(slots), no_search_args())


def _candidates(provider, mode) -> int:
    """The run's number of candidates (:func:`pack`'s sides): the table provider's, else 4 (two per side)."""
    return len(provider.side) if mode == GEOMETRY_TABLES else 4


def load(run: PackedRun) -> None:
    """Load (from numba's cache, or compile) the compiled loop and rhs_once for the types of ``run``: zero steps
    (one compilation serves every tableau and controller of tableaux.TABLEAUX: the same argument types), and
    one right-hand side at the zero state (no wheel near a rail there: no candidate enters the search memory, whose
    warm starts are its only state).
    """
    from rigid_dynamics.wheelset.compiled_loop import (
        PI_CONTROL,
        Carried,
        EventLog,
        Outputs,
        StepControl,
        embedded_run,
    )
    from rigid_dynamics.wheelset.compiled_rhs import rhs_once
    from rigid_dynamics.wheelset.tableaux import TABLEAUX

    y = np.zeros(n_states(int(run.par["track_positions"])))
    ncand = len(run.sides)
    outputs = Outputs(np.zeros(0), np.zeros((0, len(y))), np.zeros((0, ncand + 2, N_FIELDS)), np.zeros(0))
    tableau = TABLEAUX["RK4"][0]
    control = StepControl(1e-6, np.ones(len(y)), np.ones(len(y)), 1e-10, 1e-3, 1e-6, 0, PI_CONTROL, 0)
    carried = Carried(np.array([1e-4, 1.0]), np.zeros((len(tableau.a), len(y))), np.zeros(ncand, np.int64),
                      np.zeros(ncand))  # fmt: skip
    events = EventLog(np.zeros(0), np.zeros((0, ncand), np.int64), np.zeros(1, np.int64))
    embedded_run(y, 0.0, 0.0, 1e-3, tableau, control, run, outputs, 0, carried, events)
    rhs_once(0.0, y, run, np.zeros(len(y)), np.zeros((ncand + 2, N_FIELDS)))
