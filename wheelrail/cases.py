"""Contact-case files (``wheelrail contact CASE.toml``): reading, validation, solving, JSON.

A case file has the tables

* ``[material]``: ``shear_modulus_Pa`` or ``young_modulus_Pa``, ``poisson_ratio``, ``friction_coefficient``;
* ``[friction]`` (optional, instead of ``material.friction_coefficient``): the friction law (Coulomb, CONTACT's
  falling laws, Polach's law) and its variation in place, docs/files.md;
* ``[geometry]``: ``kind = "quadric"`` with ``radius_long_m``, ``radius_lat_m`` (relative radii of
  curvature, h = x^2/(2 R_long) + y^2/(2 R_lat)); or ``kind = "wheelset"`` with ``wheel_profile``,
  ``rail_profile``, ``lateral_shift_m``, ``yaw_rad``, ``gauge_m``, ``gauge_height_m``,
  ``flange_back_distance_m``, ``nominal_radius_m``, ``rail_inclination_rad``;
* ``[loading]``: ``normal_force_N`` (quadric) or ``wheel_load_N`` (wheelset), or ``approach_m``; a quadric case may
  add ``longitudinal_force_N`` (the creep force on the wheel along x, N; CONTACT's F = 1): its longitudinal creepage
  is then solved (``kinematics.creepage_long`` not given) and ``case.force_control`` in the JSON states the solved
  creepage and the force residual; a wheelset case may add it too (the contact forces on its wheels summed along
  the wheelset's longitudinal axis, CONTACT's FX_WS): its pitch rate is then solved
  (``kinematics.pitch_rate_rad_per_s`` not given);
* ``[kinematics]``: ``creepage_long``, ``creepage_lat``, ``spin_creepage_1_per_m``,
  ``rolling_speed_m_per_s`` (quadric); a wheelset case takes ``rolling_speed_m_per_s``, ``roll_rad``,
  ``pitch_rate_rad_per_s`` and ``wheel_rotation_rad`` (phi, the wheels' rotation angle: an irregularity centred
  at the wheel angle alpha_0 is at the contact when phi = pi/2 - alpha_0) and derives the creepages from its yaw
  and geometry;
* ``[irregularities]`` (wheelset only): wheel out-of-roundness with the dynamics scenes' keys ``polygon_order``,
  ``polygon_amplitude_m``, ``polygon_phase_rad`` (R_irr = A cos(n alpha + phase)), ``flat_length_m``,
  ``flat_depth_m`` (0: L^2/(16 r0) for a rounded flat; a new flat has its chord depth), ``flat_angle_rad`` (alpha_0
  of the flat's centre), ``flat_shape`` ("rounded", default, or "new"; rigid_dynamics.geometry.WheelFlat),
  ``wheel_slices_file`` (a CONTACT wheel slices file, .slcw, relative to the case file: a measured out-of-round
  wheel relative to its first slice, rigid_dynamics.geometry.slices, smoothed along y with the case's
  ``profile_smoothing_m``, a wavelength L_filt: CONTACT's SMOOTH under its default ISMOOTH 0 is a smoothing
  parameter, converted by slices.contact_smoothing_wavelength_m; the case's wheel_profile should be that slice's
  file) and ``side`` ("both", default, "left" or "right");
* ``[solver]``: for a quadric case the options of the contact model; for a wheelset case the case's options
  (``rigid_dynamics.contact.wheelset_case.DEFAULT_CASE_OPTIONS``) with the model's options in ``[solver.model]``.
  Both are checked against their declarations before any work (:func:`check_solver_options`;
  ``wheelrail models`` lists each model's options).

Numbers are checked against physical ranges as well as types (:data:`PHYSICAL_RANGES`): a creepage of 1e9
or a rolling speed of 1e6 m/s is bad input, not a case.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rigid_dynamics.contact.friction import friction_law_from_table
from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material
from wheelrail.config import ConfigError, check_keys, get_number, get_table, read_toml, resolve_embedded

TOP_LEVEL_TABLES = {
    "name", "description", "material", "friction", "geometry", "loading", "kinematics", "solver", "irregularities"
}  # fmt: skip
QUADRIC_GEOMETRY_KEYS = {"kind", "radius_long_m", "radius_lat_m"}
IRREGULARITY_KEYS = {
    "wheel_flat_length_m",
    "wheel_flat_depth_m",
    "wheel_flat_shape",
    "wheel_flat_offset_m",
    "corrugation_wavelength_m",
    "corrugation_amplitude_m",
    "corrugation_phase_rad",
}
WHEELSET_GEOMETRY_KEYS = {
    "kind",
    "wheel_profile",
    "rail_profile",
    "lateral_shift_m",
    "yaw_rad",
    "gauge_m",
    "gauge_height_m",
    "flange_back_distance_m",
    "nominal_radius_m",
    "rail_inclination_rad",
    "wheel_profile_left",
    "rail_profile_left",
    "rail_profile_cant_rad",
    "profile_smoothing_m",
    "rail_profile_smoothing_m",
    "wheel_profile_mirror_y",
    "wheel_profile_mirror_z",
    "rail_profile_mirror_y",
    "rail_profile_mirror_z",
    "track_distance_m",
}
QUADRIC_KINEMATICS_KEYS = {"creepage_long", "creepage_lat", "spin_creepage_1_per_m", "rolling_speed_m_per_s"}
WHEELSET_KINEMATICS_KEYS = {"rolling_speed_m_per_s", "roll_rad", "pitch_rate_rad_per_s", "wheel_rotation_rad"}
WHEEL_IRREGULARITY_KEYS = {
    "side",
    "polygon_order",
    "polygon_amplitude_m",
    "polygon_phase_rad",
    "flat_length_m",
    "flat_depth_m",
    "flat_angle_rad",
    "flat_shape",
    "wheel_slices_file",
}
"""Keys of a wheelset case's ``[irregularities]``: the dynamics scenes' wheel keys (rigid_dynamics.wheelset.parameters
.Irregularities: same names, same meaning, same checks) and ``flat_shape`` ("rounded" as the scenes, or "new")."""
FLAT_SHAPES = ("rounded", "new")


@dataclass(frozen=True, eq=False)
class ContactCase:
    """A validated contact case.

    Attributes:
        kind: "quadric" or "wheelset".
        material: elastic constants and friction.
        geometry: the single patch of a quadric case (None for a wheelset case).
        creepage: creepages of a quadric case (None for a wheelset case).
        normal_force_N: imposed normal force (quadric), or None for approach control.
        wheelset: the ``WheelsetCase`` of a wheelset case (None for a quadric case).
        solver_options: options passed to the contact model.
        name: case name (file stem unless given).
        longitudinal_force_N: a quadric case's prescribed creep force on the wheel along x (N; CONTACT's F = 1):
            its longitudinal creepage is solved (:func:`rigid_dynamics.contact.force_control.solve_for_force`);
            None: the creepage as given.
    """

    kind: str
    material: Material
    geometry: ContactGeometry | None = None
    creepage: Creepage | None = None
    normal_force_N: float | None = None
    wheelset: Any = None
    solver_options: dict = field(default_factory=dict)
    name: str = ""
    longitudinal_force_N: float | None = None


def read_material(table: dict, prefix: str = "material", friction: dict | None = None) -> Material:
    """[material] -> Material. Exactly one of shear_modulus_Pa and young_modulus_Pa.

    ``friction``: the ``[friction]`` table (rigid_dynamics.contact.friction.friction_law_from_table), which then
    replaces ``friction_coefficient`` (giving both is an error).
    """
    if friction is not None:
        if "friction_coefficient" in table:
            raise ConfigError(
                f"key '{prefix}.friction_coefficient' = {table['friction_coefficient']!r}: not allowed with a "
                "[friction] table (it gives the friction law; remove one of the two)"
            )
        try:
            law = friction_law_from_table(friction)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
        return read_material({**table, "friction_coefficient": law.max_static}, prefix).with_friction(law)
    check_keys(table, {"shear_modulus_Pa", "young_modulus_Pa", "poisson_ratio", "friction_coefficient"}, prefix)
    has_g, has_e = "shear_modulus_Pa" in table, "young_modulus_Pa" in table
    if has_g == has_e:
        raise ConfigError(
            f"table [{prefix}]: expected exactly one of 'shear_modulus_Pa' and 'young_modulus_Pa'"
            f" (found {'both' if has_g else 'neither'})"
        )
    nu = get_number(table, "poisson_ratio", prefix)
    if not -1.0 < nu < 0.5:
        raise ConfigError(f"key '{prefix}.poisson_ratio' = {nu!r}: expected a value in (-1, 0.5)")
    mu = get_number(table, "friction_coefficient", prefix)
    if mu < 0:
        raise ConfigError(f"key '{prefix}.friction_coefficient' = {mu!r}: expected a number >= 0")
    if has_g:
        return Material(get_number(table, "shear_modulus_Pa", prefix, positive=True), nu, mu)
    return Material.from_young(get_number(table, "young_modulus_Pa", prefix, positive=True), nu, mu)


def _read_loading(table: dict, force_key: str) -> tuple[float | None, float | None]:
    check_keys(table, {force_key, "approach_m"}, "loading")
    if (force_key in table) == ("approach_m" in table):
        raise ConfigError(f"table [loading]: expected exactly one of {force_key!r} and 'approach_m'")
    if force_key in table:
        return get_number(table, force_key, "loading", positive=True), None
    return None, get_number(table, "approach_m", "loading")


def _read_solver(table: dict) -> dict:
    for key, value in table.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(f"key 'solver.{key}' = {value!r}: expected a finite number")
    model = table.get("model")
    for key, value in (("output_dir", table.get("output_dir")), ("model.output_dir", (model or {}).get("output_dir")
                       if isinstance(model, dict) else None)):  # fmt: skip
        if value is not None:
            raise ConfigError(
                f"key 'solver.{key}' = {value!r}: not allowed in a case file (a command writes only under its output "
                "folder: give --out DIR, the FEA files go to DIR/fea)"
            )
    return dict(table)


def parse_case(doc: dict, name: str = "", base_dir: Path | None = None) -> ContactCase:
    """Validate a parsed case document into a ContactCase (ConfigError on any problem).

    ``base_dir``: folder that relative file names in the case (``irregularities.wheel_slices_file``) refer to.
    """
    check_keys(doc, TOP_LEVEL_TABLES, "")
    friction = get_table(doc, "friction") if "friction" in doc else None
    material = read_material(get_table(doc, "material"), friction=friction)
    geometry_table = get_table(doc, "geometry")
    kinematics = get_table(doc, "kinematics", required=False)
    solver = _read_solver(get_table(doc, "solver", required=False))
    for key in ("name", "description"):
        if key in doc and not isinstance(doc[key], str):
            raise ConfigError(f"key {key!r} = {doc[key]!r}: expected a string")
    name = str(doc.get("name", name))
    kind = geometry_table.get("kind")
    if kind == "quadric":
        check_keys(geometry_table, QUADRIC_GEOMETRY_KEYS | IRREGULARITY_KEYS, "geometry")
        radius_long = get_number(geometry_table, "radius_long_m", "geometry", positive=True)
        radius_lat = get_number(geometry_table, "radius_lat_m", "geometry", positive=True)
        loading = dict(get_table(doc, "loading"))
        longitudinal_force = _longitudinal_force(loading, kinematics, "creepage_long", "the longitudinal creepage")
        force, approach = _read_loading(loading, "normal_force_N")
        check_keys(kinematics, QUADRIC_KINEMATICS_KEYS, "kinematics")
        creepage = Creepage(
            get_number(kinematics, "creepage_long", "kinematics", default=0.0),
            get_number(kinematics, "creepage_lat", "kinematics", default=0.0),
            get_number(kinematics, "spin_creepage_1_per_m", "kinematics", default=0.0),
            get_number(kinematics, "rolling_speed_m_per_s", "kinematics", positive=True, default=1.0),
        )
        if "irregularities" in doc:
            raise ConfigError(
                "table [irregularities]: expected only in a wheelset case (geometry.kind = 'wheelset'); a quadric "
                "takes wheel_flat_* / corrugation_* keys in [geometry]"
            )
        if IRREGULARITY_KEYS & set(geometry_table):
            if approach is not None:
                raise ConfigError(
                    "table [loading]: a quadric with a wheel flat or corrugation expects 'normal_force_N' "
                    "(its sampled gap has no approach to prescribe)"
                )
            geometry = _irregular_geometry(geometry_table, radius_long, radius_lat)
        else:
            geometry = ContactGeometry.quadric(radius_long, radius_lat, approach if approach is not None else 0.0)
        return ContactCase("quadric", material, geometry, creepage, force, None, solver, name, longitudinal_force)
    if kind == "wheelset":
        check_keys(geometry_table, WHEELSET_GEOMETRY_KEYS, "geometry")
        check_keys(kinematics, WHEELSET_KINEMATICS_KEYS, "kinematics")
        loading = dict(get_table(doc, "loading"))
        longitudinal_force = _longitudinal_force(loading, kinematics, "pitch_rate_rad_per_s", "the pitch rate")
        force, approach = _read_loading(loading, "wheel_load_N")
        irregularities = dict(get_table(doc, "irregularities", required=False))
        if "wheel_slices_file" in irregularities:
            irregularities["wheel_slices_file"] = _slices_path(irregularities["wheel_slices_file"], base_dir)
        wheelset = _build_wheelset_case(geometry_table, force, approach, kinematics, irregularities)
        return ContactCase("wheelset", material, None, None, None, wheelset, solver, name, longitudinal_force)
    raise ConfigError(f"key 'geometry.kind' = {kind!r}: expected 'quadric' or 'wheelset'")


def _longitudinal_force(loading: dict, kinematics: dict, solved_key: str, solved: str) -> float | None:
    """``loading.longitudinal_force_N`` taken out of ``loading`` (None when absent); the kinematics key it solves
    (``solved_key``, described as ``solved``) may not be given with it.
    """
    if "longitudinal_force_N" not in loading:
        return None
    force = get_number(loading, "longitudinal_force_N", "loading")
    del loading["longitudinal_force_N"]
    if solved_key in kinematics:
        raise ConfigError(
            f"key 'kinematics.{solved_key}' = {kinematics[solved_key]!r}: not allowed with "
            f"'loading.longitudinal_force_N' ({solved} is solved for that force)"
        )
    return force


def _slices_path(value, base_dir: Path | None) -> str:
    if not isinstance(value, str) or not value:
        raise ConfigError(f"key 'irregularities.wheel_slices_file' = {value!r}: expected the path of a .slcw file")
    path = Path(value).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    return str(path)


def read_wheel_irregularities(table: dict, nominal_radius_m: float, smoothing_wavelength_m: float = 0.002) -> dict:
    """``[irregularities]`` of a wheelset case -> {"wheel_irregularities_right": (...), "..._left": (...)}.

    The checks are the dynamics scenes' (rigid_dynamics.wheelset.checks.check_scene): a flat shorter than the
    wheel's diameter and shallower than its radius, a polygon with A n^2 < r0 (the wheel stays convex).

    Raises:
        ConfigError: one line naming the key, its value and what was expected.
    """
    from rigid_dynamics.geometry import HarmonicOutOfRoundness, WheelFlat

    check_keys(table, WHEEL_IRREGULARITY_KEYS, "irregularities")
    r0 = nominal_radius_m
    side = table.get("side", "both")
    if side not in ("both", "left", "right"):
        raise ConfigError(f"key 'irregularities.side' = {side!r}: expected 'both', 'left' or 'right'")
    shape = table.get("flat_shape", "rounded")
    if shape not in FLAT_SHAPES:
        raise ConfigError(f"key 'irregularities.flat_shape' = {shape!r}: expected 'rounded' or 'new'")
    order = table.get("polygon_order", 0)
    if isinstance(order, bool) or not isinstance(order, int) or order < 0:
        raise ConfigError(f"key 'irregularities.polygon_order' = {order!r}: expected an integer >= 0 (0: no polygon)")
    values = {}
    for name in ("polygon_amplitude_m", "polygon_phase_rad", "flat_length_m", "flat_depth_m", "flat_angle_rad"):
        values[name] = get_number(table, name, "irregularities", default=0.0)
        if name not in ("polygon_phase_rad", "flat_angle_rad") and values[name] < 0:
            raise ConfigError(f"key 'irregularities.{name}' = {values[name]!r}: expected a number >= 0")
    amplitude, length, depth = values["polygon_amplitude_m"], values["flat_length_m"], values["flat_depth_m"]
    if amplitude > 0 and order == 0:
        raise ConfigError(
            f"key 'irregularities.polygon_order' = {order!r}: expected an integer >= 1 with polygon_amplitude_m > 0"
        )
    if order > 0 and amplitude >= r0 / order**2:
        raise ConfigError(
            f"key 'irregularities.polygon_amplitude_m' = {amplitude!r}: expected an amplitude < r0 / n^2 = "
            f"{r0 / order**2:.4g} m for polygon_order n = {order} and r0 = {r0:g} m (beyond it the wheel is no "
            "longer convex)"
        )
    if length >= 2.0 * r0:
        raise ConfigError(
            f"key 'irregularities.flat_length_m' = {length!r}: expected a length < 2 r0 = {2.0 * r0:g} m (a flat is "
            "a chord of the wheel)"
        )
    if depth > 0 and length == 0:
        raise ConfigError(f"key 'irregularities.flat_length_m' = {length!r}: expected a length > 0 with flat_depth_m")
    if depth >= r0:
        raise ConfigError(f"key 'irregularities.flat_depth_m' = {depth!r}: expected a depth < r0 = {r0:g} m")
    if shape == "new" and depth > 0:
        raise ConfigError(
            f"key 'irregularities.flat_depth_m' = {depth!r}: expected 0 with flat_shape 'new' (a new flat's depth is "
            "the chord depth of its length, r0 - sqrt(r0^2 - L^2/4))"
        )
    wheel = []
    if order > 0 and amplitude > 0:
        wheel.append(HarmonicOutOfRoundness(order, amplitude, values["polygon_phase_rad"]))
    if length > 0:
        wheel.append(WheelFlat(length, r0, depth if depth > 0 else None, values["flat_angle_rad"], shape))
    if "wheel_slices_file" in table:
        from rigid_dynamics.geometry.slices import read_wheel_slices

        try:
            slices = read_wheel_slices(table["wheel_slices_file"], smoothing_wavelength_m=smoothing_wavelength_m)
            wheel.append(slices.irregularity)
        except ValueError as exc:
            raise ConfigError(
                f"key 'irregularities.wheel_slices_file' = {table['wheel_slices_file']!r}: {exc}"
            ) from None
    sides = ("right", "left") if side == "both" else (side,)
    return {f"wheel_irregularities_{s}": tuple(wheel) for s in sides}


def _irregular_geometry(table: dict, radius_long: float, radius_lat: float) -> ContactGeometry:
    """The sampled gap of a quadric with a wheel flat and/or rail corrugation (ConfigError naming the key)."""
    from rigid_dynamics.contact.irregular_patch import irregular_quadric_geometry
    from rigid_dynamics.geometry.irregularities import RailCorrugation, WheelFlat

    flat = corrugation = None
    offset = get_number(table, "wheel_flat_offset_m", "geometry", default=0.0)
    if "wheel_flat_length_m" in table:
        length = get_number(table, "wheel_flat_length_m", "geometry", positive=True)
        depth = None
        if "wheel_flat_depth_m" in table:
            depth = get_number(table, "wheel_flat_depth_m", "geometry", positive=True)
        shape = table.get("wheel_flat_shape", "rounded")
        if shape not in ("rounded", "new"):
            raise ConfigError(f"key 'geometry.wheel_flat_shape' = {shape!r}: expected 'rounded' or 'new'")
        try:
            flat = WheelFlat(length, radius_long, depth, shape=shape)
        except ValueError as exc:
            raise ConfigError(f"key 'geometry.wheel_flat_length_m' = {length!r}: {exc}") from None
    elif {"wheel_flat_depth_m", "wheel_flat_shape", "wheel_flat_offset_m"} & set(table):
        raise ConfigError("table [geometry]: wheel-flat keys given without 'wheel_flat_length_m'")
    if "corrugation_wavelength_m" in table or "corrugation_amplitude_m" in table:
        wavelength = get_number(table, "corrugation_wavelength_m", "geometry", positive=True)
        amplitude = get_number(table, "corrugation_amplitude_m", "geometry", positive=True)
        phase = get_number(table, "corrugation_phase_rad", "geometry", default=0.0)
        corrugation = RailCorrugation(wavelength, amplitude, phase, half_width_m=1.0)
    elif "corrugation_phase_rad" in table:
        raise ConfigError("table [geometry]: 'corrugation_phase_rad' given without the corrugation's wavelength")
    try:
        return irregular_quadric_geometry(
            radius_long, radius_lat, flat=flat, flat_offset_m=offset, corrugation=corrugation
        )
    except ValueError as exc:
        raise ConfigError(f"table [geometry]: {exc}") from None


def _build_wheelset_case(geometry: dict, wheel_load_N, approach_m, kinematics: dict, irregularities=None):
    from rigid_dynamics.contact.wheelset_case import WheelsetCase
    from rigid_dynamics.geometry import load_profile
    from wheelrail.config import build_dataclass

    table = {k: v for k, v in geometry.items() if k != "kind"}
    if wheel_load_N is not None:
        table["wheel_load_N"] = wheel_load_N
    if approach_m is not None:
        table["approach_m"] = approach_m
    for key in ("rolling_speed_m_per_s", "roll_rad", "pitch_rate_rad_per_s", "wheel_rotation_rad"):
        if key in kinematics:
            if key == "wheel_rotation_rad":
                get_number(kinematics, key, "kinematics")  # a number, named under its own table
            table[key] = kinematics[key]
    if irregularities:
        from rigid_dynamics.contact.wheelset_case import WheelsetCase

        r0 = table.get("nominal_radius_m", WheelsetCase.__dataclass_fields__["nominal_radius_m"].default)
        r0 = get_number({"nominal_radius_m": r0}, "nominal_radius_m", "geometry", positive=True)
        smoothing = table.get("profile_smoothing_m", WheelsetCase.__dataclass_fields__["profile_smoothing_m"].default)
        smoothing = get_number({"profile_smoothing_m": smoothing}, "profile_smoothing_m", "geometry")
        built = read_wheel_irregularities(irregularities, r0, max(smoothing, 0.0))
    for key, kind in (("wheel_profile", "wheel"), ("rail_profile", "rail"), ("wheel_profile_left", "wheel"),
                      ("rail_profile_left", "rail")):  # fmt: skip
        if key not in table and key.endswith("_left"):
            continue
        if key not in table:
            raise ConfigError(f"missing key 'geometry.{key}': expected a built-in profile name or a file path")
        value = table[key]
        if not isinstance(value, str):
            raise ConfigError(f"key 'geometry.{key}' = {value!r}: expected a built-in profile name or a file path")
        try:
            load_profile(value, kind)
        except ValueError as exc:
            raise ConfigError(f"key 'geometry.{key}' = {value!r}: {exc}") from None
    case = build_dataclass(WheelsetCase, table, "geometry")
    if irregularities:
        case = dataclasses.replace(case, **built)
    return case


def load_case(path: str | Path, method: str | None = None, overrides: dict | None = None) -> ContactCase:
    """Read and validate a case file (an embedded case name is accepted too): the one case loader.

    Relative file names in the case (``irregularities.wheel_slices_file``) refer to the case file's folder,
    whatever the working directory. ``overrides``: {dotted key: value} applied to the document before
    validation (the CLI's ``--set``, :mod:`wheelrail.overrides`). With ``method`` (a registered model name) the
    ``[solver]`` table is checked against that model's declared options too (:func:`check_solver_options`).
    """
    from wheelrail.overrides import apply_overrides

    path = resolve_case_path(path)
    doc = apply_overrides(read_toml(path, "case file"), overrides or {})
    case = parse_case(doc, name=Path(path).stem, base_dir=Path(path).parent)
    if method is not None:
        check_solver_options(case, method)
    return case


def _wheelset_case_options(method: str) -> dict:
    """Declaration of a wheelset case's ``[solver]`` options (rigid_dynamics.contact.wheelset_case.case_options)."""
    from rigid_dynamics.contact.options import validate_options
    from rigid_dynamics.contact.registry import model_options
    from rigid_dynamics.contact.wheelset_case import case_options

    def check_model(value, key):
        validate_options(model_options(method), value, method, prefix=f"{key}.")
        _check_joint_rules(method, value, f"solver.{key}")

    return case_options(method, check_model)


def _check_joint_rules(method: str, options: dict, key: str) -> None:
    """Rules joining two options (a model's ``check_options``, e.g. FEA's degree 2 only with 'rigid')."""
    from rigid_dynamics.contact.options import OptionError
    from rigid_dynamics.contact.registry import model_class

    check = getattr(model_class(method), "check_options", None)
    if check is None:
        return
    try:
        check(options)
    except OptionError:
        raise
    except ValueError as exc:
        raise ConfigError(f"table [{key}]: {exc}") from None


def check_solver_options(case: ContactCase, method: str) -> None:
    """Check a case's ``[solver]`` table against the declared options of the model ``method``.

    Raises:
        ConfigError: one line naming the key (``solver.nx``), the value and what was expected.
    """
    from rigid_dynamics.contact.options import OptionError, validate_options
    from rigid_dynamics.contact.registry import MODELS, model_options

    if method not in MODELS:
        raise ConfigError(f"--method {method!r}: expected one of {', '.join(MODELS)}")
    try:
        if case.kind == "quadric":
            validate_options(model_options(method), case.solver_options, method)
            _check_joint_rules(method, case.solver_options, "solver")
        else:
            validate_options(_wheelset_case_options(method), case.solver_options, "wheelset case")
    except OptionError as exc:
        raise ConfigError(option_message(exc, "solver", method)) from None


def option_message(exc, table: str, method: str) -> str:
    """The one-line message for an OptionError met in the table ``table`` of a file."""
    from rigid_dynamics.contact.registry import MODELS

    key = f"{table}.{exc.key}"
    owner = f"the contact model {exc.model!r}" if exc.model in MODELS else f"the {exc.model}"
    if exc.model == "wheelset case" and exc.unknown:
        owner += f" (options of {method!r} go in [{table}.model])"
    if exc.unknown and exc.expected == "none":
        return f"unknown key {key!r} = {exc.value!r}: {owner} takes no options"
    if exc.unknown:
        return f"unknown key {key!r} = {exc.value!r}: not an option of {owner}; expected one of {exc.expected}"
    return f"key {key!r} = {exc.value!r}: expected {exc.expected} (option of {owner})"


CASES_DIR = Path(__file__).parent / "cases"


def embedded_cases() -> dict[str, Path]:
    """Every named contact case, one namespace for every command: name -> case file.

    The cases of ``wheelrail/cases/*.toml`` (no reference) and the benchmark cases of
    ``comparisons/cases/<name>/case.toml`` (with a reference for ``bench`` and ``compare``), sorted by name.
    """
    from comparisons.named_cases import CASES_ROOT

    found = {p.stem: p for p in CASES_DIR.glob("*.toml")}
    found.update({p.parent.name: p for p in CASES_ROOT.glob("*/case.toml")})
    return dict(sorted(found.items()))


def resolve_case_path(path: str | Path) -> Path:
    """A file path, or the path of an embedded case of that name."""
    return resolve_embedded(path, embedded_cases(), "case")


@dataclass(frozen=True, eq=False)
class CaseSolution:
    """What one contact-case run produced: per patch (side, geometry, creepage, result).

    ``wall_time_s`` is the solve itself; ``setup_s`` the model's import and the compilation (or loading from
    numba's cache) of its kernels, done on a small quadric patch before the clock starts (see :func:`solve_case`).
    """

    method: str
    success: bool
    message: str
    wall_time_s: float
    patches: list = field(default_factory=list)
    extra: dict = field(default_factory=dict)
    setup_s: float = 0.0

    def to_dict(self) -> dict:
        """The JSON record of ``wheelrail contact --json`` (:func:`solution_record`)."""
        return solution_record(self)

    def _repr_markdown_(self) -> str:
        """A table for notebooks: one row per patch, forces on the wheel in the contact frame."""

        def cell(value, scale=1.0):
            return "-" if value is None else f"{value * scale:.5g}"

        lines = [
            f"**{self.method}**: {solution_status(self)} in {self.wall_time_s:.3g} s"
            + (f" ({self.message})" if self.message else ""),
            "",
            "| side | status | N [N] | Fx [N] | Fy [N] | p max [MPa] | area [mm^2] |",
            "|---|---|---:|---:|---:|---:|---:|",
        ]
        for side, _, _, r in self.patches:
            lines.append(
                f"| {side} | {r.status} | {cell(r.normal_force_N)} | {cell(r.creep_force_long_N)} | "
                f"{cell(r.creep_force_lat_N)} | {cell(r.max_pressure_Pa, 1e-6)} | {cell(r.contact_area_m2, 1e6)} |"
            )
        return "\n".join(lines) + "\n"

    def to_dataframe(self):
        """One row per patch: side, model, forces, pressure, semi-axes, creepages (units in the names)."""
        import pandas as pd

        rows = [
            {k: v for k, v in patch.items() if not isinstance(v, (dict, list))} for patch in self.to_dict()["patches"]
        ]
        return pd.DataFrame(rows)

    def __repr__(self) -> str:
        patches = ", ".join(
            f"{side}: N={result.normal_force_N:.5g} N" for side, _geometry, _creepage, result in self.patches
        )
        return (
            f"CaseSolution(method={self.method!r}, success={self.success}, wall_time_s={self.wall_time_s:.3g}, "
            f"patches=[{patches}], message={self.message!r})"
        )


WARM_UP_OPTIONS = {"hertz": None, "linear": None, "vermeulen-johnson": None, "fastsim": None, "bem": {"nx": 8, "ny": 8}}
"""Models whose numba kernels :func:`solve_case` compiles (or loads from the cache) on a small patch before its
clock starts, with the options of that small solve. ``auto`` warms up Hertz and the model it chooses on a quadric
case, and every rung it may choose (bem, its fallback, included) on a wheelset case; ``fea`` has no numba kernels
(DOLFINx caches its compiled forms itself)."""


def warm_up(method: str, material: Material, models: tuple[str, ...] | None = None) -> float:
    """Solve a small quadric patch with ``method`` so that its compiled kernels are loaded; returns the time, s.

    ``models``: the models to warm up instead of ``method`` (``auto`` on a quadric patch: the one it chooses).
    """
    from rigid_dynamics.contact.registry import get_model

    start = time.perf_counter()
    names = ("hertz", "linear", "vermeulen-johnson", "fastsim", "bem") if method == "auto" else (method,)
    names = names if models is None else models
    geometry = ContactGeometry.quadric(0.46, 0.3)
    for name in names:
        if name in WARM_UP_OPTIONS:
            with contextlib.suppress(Exception):  # a warm-up never decides the run: the real solve reports
                get_model(name).solve(
                    geometry, Creepage(1e-3, 1e-3, 0.1), material, normal_force_N=1e4, options=WARM_UP_OPTIONS[name]
                )
    return time.perf_counter() - start


def _auto_choice(model, case: ContactCase) -> tuple[str, ...] | None:
    """("hertz", the model ``auto`` chooses) for a quadric case, so that only its kernels are warmed up (a case that
    ``auto`` serves by an analytic model then loads no numba); None (warm up every rung) for a wheelset case or
    when the choice fails (the solve reports why).
    """
    if case.kind != "quadric":
        return None
    try:
        chosen = model.chosen_model(
            case.geometry, case.creepage, case.material, normal_force_N=case.normal_force_N, options=case.solver_options
        )
    except Exception:  # the solve itself reports bad options or input
        return None
    return ("hertz", chosen)


def solve_case(case: ContactCase | str | Path, method: str, progress=None) -> CaseSolution:
    """Solve a validated case (or a case's name or file, read by :func:`load_case`) with the model ``method``.

    ``progress``: optional callable taking one line per wheel evaluation of a wheelset case (see
    ``solve_wheelset_case``).

    The model is imported and its compiled kernels loaded (:func:`warm_up`) before the clock starts, so
    ``wall_time_s`` measures the solve; that preparation is ``setup_s``. For a wheelset case the clock
    includes the contact search.
    """
    from rigid_dynamics.contact.registry import get_model

    if isinstance(case, (str, Path)):
        case = load_case(case)
    prepare = time.perf_counter()
    model = get_model(method)
    warm_up(method, case.material, _auto_choice(model, case) if method == "auto" else None)
    setup_s = time.perf_counter() - prepare
    start = time.perf_counter()
    if case.kind == "quadric":

        def solve_at(creepage: Creepage) -> ContactResult:
            try:  # a model raises ValueError only for bad input (STYLE 12), e.g. a [solver] option
                return model.solve(
                    case.geometry, creepage, case.material, normal_force_N=case.normal_force_N,
                    options=case.solver_options,
                )  # fmt: skip
            except ValueError as exc:
                raise ConfigError(f"[solver]: {exc}") from None

        creepage, extra = case.creepage, {}
        if case.longitudinal_force_N is not None:
            creepage, extra = _force_controlled(case, solve_at)
        result = solve_at(creepage)
        success, message = result.success, result.message
        if extra and extra["force_control"]["status"] != "ok":
            success, message = False, f"force control: {extra['force_control']['message']}; {message}"
        return CaseSolution(
            method,
            success,
            message,
            time.perf_counter() - start,
            [("single", case.geometry, creepage, result)],
            extra,
            setup_s=setup_s,
        )
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case  # only a wheelset case needs the search

    control = None
    if case.longitudinal_force_N is not None:
        solution, control = solve_wheelset_to_force(case, method, progress)
    else:
        solution = solve_wheelset_case(
            case.wheelset, case.material, method, options=case.solver_options, progress=progress
        )
    patches = [(p.side, p.geometry, p.creepage, p.result) for p in solution.patches]
    extra = {
        k: v
        for k, v in ((f.name, getattr(solution, f.name)) for f in dataclasses.fields(solution))
        if isinstance(v, (int, float, str, bool)) and k not in ("success", "message", "status", "wall_time_s")
    }
    extra["wheel_vertical_load_N"] = {k: float(v) for k, v in solution.wheel_vertical_load_N.items()}
    # how each patch was formed: CONTACT's weighted reference point (the patch's contact_point_rail_m) and the
    # deepest point of its interpenetration, both in rail-profile coordinates
    extra["patch_formation"] = [
        {
            "side": p.side,
            "combination": p.combination,
            "reference_point_rail_m": [_number(v) for v in p.geometry.contact_point_rail_m],
            "deepest_point_rail_m": [_number(v) for v in p.deepest_point_rail_m],
        }
        for p in solution.patches
    ]
    wall = time.perf_counter() - start
    success, message = solution.success, solution.message
    if control is not None:
        extra["force_control"] = control
        if control["status"] != "ok":
            success, message = False, f"force control: {control['message']}; {message}"
    return CaseSolution(method, success, message, wall, patches, extra, setup_s=setup_s)


def _force_controlled(case: ContactCase, solve_at) -> tuple[Creepage, dict]:
    """The creepage of a quadric case with ``longitudinal_force_N`` (CONTACT's F = 1) and the record of the solve:
    Brent's method on the longitudinal creepage to a force residual of 1e-4 mu_s F_N (F_N of the zero-creepage
    solve), the other creepages as given.
    """
    from rigid_dynamics.contact.force_control import solve_for_force

    base = case.creepage
    results: dict = {}

    def force_of(xi: float) -> float:
        result = solve_at(dataclasses.replace(base, longitudinal=xi))
        results[xi] = result
        return result.creep_force_long_N if result.success else math.nan

    first = solve_at(dataclasses.replace(base, longitudinal=0.0))
    mu_n = case.material.friction_coefficient * first.normal_force_N
    if not (first.success and math.isfinite(mu_n) and mu_n > 0):
        outcome = None
    else:
        outcome = solve_for_force(force_of, case.longitudinal_force_N, force_tolerance_N=1e-4 * mu_n)
    record = {
        "target_longitudinal_force_N": case.longitudinal_force_N,
        "status": "not-converged" if outcome is None else outcome.status,
        "solved_creepage_long": None if outcome is None else _number(outcome.creepage),
        "longitudinal_force_N": None if outcome is None else _number(outcome.force_N),
        "residual_N": None if outcome is None else _number(outcome.residual_N),
        "force_tolerance_N": _number(1e-4 * mu_n),
        "evaluations": 0 if outcome is None else outcome.evaluations,
        "message": (f"the zero-creepage solve failed: {first.message}" if outcome is None else outcome.message),
    }
    xi = 0.0 if outcome is None or not math.isfinite(outcome.creepage) else outcome.creepage
    return dataclasses.replace(base, longitudinal=xi), {"force_control": record}


def solve_wheelset_to_force(case: ContactCase, method: str, progress=None):
    """A wheelset case with ``longitudinal_force_N`` (CONTACT's F = 1 of its wheel-rail module): the pitch rate
    solved so that the contact forces on the solved wheels sum to that force along the wheelset's longitudinal
    axis (N, on the wheels; CONTACT's FX_WS is the same on the rail, of opposite sign).

    The unknown is the wheelset's longitudinal creepage xi_ws = 1 - omega / omega_0, omega the wheels' spin rate and
    omega_0 the free-rolling one (the zero-axle-moment spin rate of the case solved without the force): the pitch
    rate is -omega_0 (1 - xi_ws). Brent's method to a residual of 1e-4 mu times the vertical load.
    """
    from rigid_dynamics.contact.force_control import solve_for_force
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case

    options = dict(case.solver_options)
    free = solve_wheelset_case(case.wheelset, case.material, method, options=options, progress=progress)
    omega_0 = free.spin_rate_rad_per_s
    cos_yaw, sin_yaw = math.cos(case.wheelset.yaw_rad), math.sin(case.wheelset.yaw_rad)
    solutions: dict = {}

    def force_of(xi: float):
        wheelset = dataclasses.replace(case.wheelset, pitch_rate_rad_per_s=-omega_0 * (1.0 - xi))
        solution = solve_wheelset_case(wheelset, case.material, method, options=options, progress=progress)
        solutions[xi] = solution
        if not solution.success:
            return math.nan
        # along the wheelset's longitudinal axis, as CONTACT's FX_WS: F_x cos(psi) + F_y sin(psi) in track axes
        forces = [p.force_main_N for p in solution.patches if math.isfinite(p.result.normal_force_N)]
        return float(sum(f[0] * cos_yaw + f[1] * sin_yaw for f in forces))

    load = sum(free.wheel_vertical_load_N.values()) or float(case.wheelset.wheel_load_N or 0.0)
    tolerance = 1e-4 * case.material.friction_coefficient * load
    outcome = None
    if free.success and math.isfinite(omega_0) and tolerance > 0:
        # F_x on the wheels rises with xi_ws (traction): solve on -xi_ws, along which it falls
        outcome = solve_for_force(lambda u: -force_of(-u), -case.longitudinal_force_N, force_tolerance_N=tolerance)
    ok = outcome is not None and math.isfinite(outcome.creepage)
    xi = -outcome.creepage if ok else 0.0
    if xi not in solutions:
        force_of(xi)
    record = {
        "target_longitudinal_force_N": case.longitudinal_force_N,
        "status": "not-converged" if outcome is None else outcome.status,
        "solved_creepage_long": _number(xi) if ok else None,
        "free_rolling_spin_rate_rad_per_s": _number(omega_0),
        "pitch_rate_rad_per_s": _number(-omega_0 * (1.0 - xi)) if ok else None,
        "longitudinal_force_N": None if outcome is None else _number(-outcome.force_N),
        "residual_N": None if outcome is None else _number(-outcome.residual_N),
        "force_tolerance_N": _number(tolerance),
        "evaluations": 1 + (0 if outcome is None else outcome.evaluations),
        "message": f"the free-rolling solve failed: {free.message}" if outcome is None else outcome.message,
    }
    return solutions[xi], record


def _number(value) -> float | None:
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def patch_record(side: str, geometry: ContactGeometry, creepage: Creepage | None, result: ContactResult) -> dict:
    """The JSON record of one patch (the contract of ``wheelrail contact --json``)."""
    rail_point = geometry.contact_point_rail_m
    rail_point = [float(v) for v in rail_point] if all(math.isfinite(v) for v in rail_point) else None
    creepage = creepage or result.creepage
    return {
        "side": side,
        "model": str(result.extra.get("selected_model", result.method)),
        "success": bool(result.success),
        "status": result.status,
        "normal_force_N": _number(result.normal_force_N),
        "creep_force_long_N": _number(result.creep_force_long_N),
        "creep_force_lat_N": _number(result.creep_force_lat_N),
        "spin_moment_Nm": _number(result.spin_moment_Nm),
        "max_pressure_Pa": _number(result.max_pressure_Pa),
        "semi_axis_long_m": _number(result.semi_axis_long_m),
        "semi_axis_lat_m": _number(result.semi_axis_lat_m),
        "contact_area_m2": _number(result.contact_area_m2),
        "approach_m": _number(result.approach_m),
        "contact_angle_rad": _number(geometry.contact_angle_rad),
        "contact_point_rail_m": rail_point,
        "creepage_long": _number(creepage.longitudinal) if creepage else None,
        "creepage_lat": _number(creepage.lateral) if creepage else None,
        "spin_creepage_1_per_m": _number(creepage.spin_1_per_m) if creepage else None,
        "iterations": int(result.iterations),
        "wall_time_s": _number(result.wall_time_s),
        "message": result.message,
        "diagnostics": _json_safe(result.extra),
    }


def _json_safe(value):
    """``value`` with only JSON-representable parts (numbers, strings, lists, dicts); arrays as lists.

    ``ContactResult.extra`` holds every number a model computed beyond the common fields: ``auto``'s
    ``selected_model`` and ``selection_reason``, FEA's subsurface maxima with their points and depths
    (``max_von_mises_Pa``, ``max_von_mises_depth_m``, ...), mesh and solver counters, BEM's grid.
    """
    import numpy as np

    if isinstance(value, dict):
        items = ((str(k), _json_safe(v)) for k, v in value.items())
        return {k: v for k, v in items if v is not _SKIP}
    if isinstance(value, (list, tuple)):
        return [v for v in map(_json_safe, value) if v is not _SKIP]
    if isinstance(value, np.ndarray):
        return value.tolist() if value.size <= 1000 else _SKIP
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (bool, int, str)) or value is None:
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return str(value)


_SKIP = object()


OK_PATCH_STATUSES = ("ok", "no-contact")
"""Patch statuses of a case that ends ``ok`` (exit 0)."""


def solution_status(solution: CaseSolution) -> str:
    """The case's one status, as printed, in the JSON and by the exit code: "ok" when the solver succeeded and every
    patch is ok or out of contact; else the first patch status that is not (e.g. "beyond-friction-limit": the
    linear theory's number, outside its range), or "failed".
    """
    for patch in solution.patches:
        if patch[3].status not in OK_PATCH_STATUSES:
            return patch[3].status
    control = solution.extra.get("force_control", {}).get("status", "ok")
    if control != "ok":
        return control  # the prescribed force was not reached: "not-attainable" or "not-converged"
    return "ok" if solution.success else "failed"


def solution_record(solution: CaseSolution) -> dict:
    """The JSON object printed by ``wheelrail contact --json``: ``status`` and ``success`` (status == "ok") agree
    with the exit code; ``solver_converged`` is the solver's own flag.
    """
    status = solution_status(solution)
    return {
        "method": solution.method,
        "status": status,
        "success": status == "ok",
        "solver_converged": bool(solution.success),
        "message": solution.message,
        "wall_time_s": solution.wall_time_s,
        "setup_s": solution.setup_s,
        "patches": [patch_record(*p) for p in solution.patches],
        **({"case": solution.extra} if solution.extra else {}),
    }
