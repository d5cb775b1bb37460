"""Turn TOML tables into the frozen dataclasses of rigid_dynamics, with messages that name the key.

The mapping is generic: a TOML table fills a dataclass field by field. Accepted field types are
float, int, str, bool, tuples of those, ``X | None`` and nested frozen dataclasses (a sub-table).
Every problem becomes one :class:`ConfigError` naming the dotted key, the value and what was
expected; validation errors raised by a dataclass's ``__post_init__`` are re-raised with the
key path of the table they came from.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import types
import typing
from pathlib import Path
from typing import Any


class ConfigError(ValueError):
    """A scene or case file is invalid. The message names the key, the value and what was expected."""


PHYSICAL_RANGES: dict[str, tuple[float, float, str]] = {
    "creepage_long": (-1.0, 1.0, "a creepage is a slip velocity over the rolling speed"),
    "creepage_lat": (-1.0, 1.0, "a creepage is a slip velocity over the rolling speed"),
    "spin_creepage_1_per_m": (-20.0, 20.0, "1/m: sin(contact angle) / rolling radius"),
    "rolling_speed_m_per_s": (0.0, 200.0, "m/s: the rail speed record is 160 m/s"),
    "speed_m_per_s": (0.0, 200.0, "m/s: the rail speed record is 160 m/s"),
    "normal_force_N": (0.0, 5.0e6, "N: a wheel load is at most a few hundred kN"),
    "wheel_load_N": (0.0, 5.0e6, "N: a wheel load is at most a few hundred kN"),
    "axle_load_N": (0.0, 1.0e7, "N: axle loads are at most a few hundred kN"),
    "shear_modulus_Pa": (1.0e6, 1.0e12, "Pa: steel 8e10, rubber 1e6"),
    "young_modulus_Pa": (3.0e6, 3.0e12, "Pa: steel 2.1e11, rubber 3e6"),
    "friction_coefficient": (0.0, 2.0, "dry steel on steel about 0.3-0.6"),
    "approach_m": (-1.0, 0.01, "m: Hertz approaches of wheels on rails are below 0.1 mm"),
    "radius_long_m": (1.0e-4, 1.0e6, "m"),
    "radius_lat_m": (1.0e-4, 1.0e6, "m"),
    "mass_kg": (1.0, 1.0e5, "kg: a wheelset is 1-2 t"),
    "transverse_inertia_kg_m2": (1.0e-3, 1.0e5, "kg m^2"),
    "axle_inertia_kg_m2": (1.0e-3, 1.0e5, "kg m^2"),
    "nominal_radius_m": (0.05, 2.0, "m: wheel radii are 0.3-0.63 m (scaled rigs smaller)"),
    "contact_half_distance_m": (0.05, 2.0, "m: half the distance of the contact points, about half the gauge"),
    "suspension_half_spacing_m": (0.0, 10.0, "m"),
    "gauge_m": (0.1, 3.0, "m: track gauges are 0.6-1.7 m"),
    "gauge_height_m": (0.0, 0.05, "m: gauge is measured 14 mm below the rail top"),
    "flange_back_distance_m": (0.1, 3.0, "m"),
    "lateral_shift_m": (-0.1, 0.1, "m: the flangeway clearance is about +-10 mm"),
    "lateral_displacement_m": (-0.1, 0.1, "m: the flangeway clearance is about +-10 mm"),
    "longitudinal_stiffness_N_per_m": (0.0, 1.0e12, "N/m"),
    "lateral_stiffness_N_per_m": (0.0, 1.0e12, "N/m"),
    "vertical_stiffness_N_per_m": (0.0, 1.0e12, "N/m"),
    "lateral_damping_N_s_per_m": (0.0, 1.0e10, "N s/m"),
    "vertical_damping_N_s_per_m": (0.0, 1.0e10, "N s/m"),
    "duration_s": (0.0, 86400.0, "s: one day of simulated time at most"),
    "fixed_step_s": (1.0e-8, 1.0, "s"),
    "max_step_s": (1.0e-8, 10.0, "s"),
    "output_step_s": (1.0e-7, 100.0, "s: the output holds duration / output_step samples"),
    "relative_tolerance": (1.0e-14, 1.0, "relative error per step"),
    "absolute_tolerance": (1.0e-16, 1.0, "absolute error per step"),
    "contact_tolerance": (0.0, 10.0, "relative creep-force error accepted by auto"),
    "traction_torque_N_m": (-1.0e6, 1.0e6, "N m: mu N r is about 25 kN m for a 100 kN wheel load"),
    "rail_head_radius_m": (1.0e-3, 10.0, "m"),
    "amplitude_m": (1.0e-5, 0.02, "m: EN 15302 uses 3 mm; the flangeway clearance is about 10 mm"),
    "rail_inclination_rad": (-0.2, 0.2, "rad: 1:40 is 0.025, 1:20 is 0.05"),
    "left_rail_inclination_rad": (-0.2, 0.2, "rad: 1:40 is 0.025, 1:20 is 0.05"),
    "right_rail_inclination_rad": (-0.2, 0.2, "rad: 1:40 is 0.025, 1:20 is 0.05"),
    "cant_m": (0.0, 0.2, "m: the outer rail's height above the inner one; EN 13803 allows up to 0.18 m"),
    "cant_reference_width_m": (0.5, 2.5, "m: 1.5 m (the distance between the rail centres) for standard gauge"),
    "rail_mass_kg": (1.0, 1.0e4, "kg per wheel: the UIC60 default is 84 kg"),
    "sleeper_mass_kg": (1.0, 1.0e5, "kg per wheel: the default is 291 kg"),
    "pad_stiffness_N_per_m": (1.0e5, 1.0e12, "N/m per wheel: the default is 2.79e8"),
    "ballast_stiffness_N_per_m": (1.0e5, 1.0e12, "N/m per wheel: the default is 3.26e8"),
    "pad_damping_N_s_per_m": (0.0, 1.0e9, "N s/m per wheel: the default is 6.98e4"),
    "ballast_damping_N_s_per_m": (0.0, 1.0e9, "N s/m per wheel: the default is 1.86e5"),
    "rail_mass_per_length_kg_per_m": (10.0, 200.0, "kg/m: UIC60 is 60.21"),
    "rail_bending_stiffness_N_m2": (1.0e5, 1.0e8, "N m^2: UIC60 is 6.38e6"),
    "rail_shear_stiffness_N": (1.0e6, 1.0e10, "kappa G A in N: UIC60 is 2.48e8"),
    "rail_rotary_inertia_kg_m": (1.0e-3, 10.0, "rho I in kg m: UIC60 is 0.2385"),
    "sleeper_spacing_m": (0.3, 1.5, "m: 0.6 for concrete sleepers"),
    "seat_pad_stiffness_N_per_m": (1.0e5, 1.0e11, "N/m per rail seat: the default is 1.2e8"),
    "seat_pad_damping_N_s_per_m": (0.0, 1.0e8, "N s/m per rail seat: the default is 3e4"),
    "seat_sleeper_mass_kg": (1.0, 1.0e4, "kg per rail seat (half a sleeper): the default is 125 kg"),
    "seat_ballast_stiffness_N_per_m": (1.0e5, 1.0e11, "N/m per rail seat: the default is 1.4e8"),
    "seat_ballast_damping_N_s_per_m": (0.0, 1.0e8, "N s/m per rail seat: the default is 8e4"),
    "rail_loss_factor": (0.0, 1.0, "the rail's loss factor: the default is 0.02"),
    "cutoff_frequency_Hz": (500.0, 5.0e4, "Hz: the beam's modes up to it; 5 kHz resolves a wheel-flat impact"),
    "end_margin_m": (1.0, 100.0, "m of beam beyond the run at each end: the default is 6 m"),
    "lateral_rail_mass_kg": (1.0, 1.0e4, "kg per wheel: the default is 78 kg"),
    "lateral_rail_stiffness_N_per_m": (1.0e5, 1.0e11, "N/m per wheel: the default is 3.24e7"),
    "lateral_rail_damping_N_s_per_m": (0.0, 1.0e8, "N s/m per wheel: the default is 1.08e5"),
}
"""Key name -> (lowest, highest, why): numbers outside are bad input however well typed (the range and
the reason are in the message). Applied to every key of that name in scene and case files."""


def check_physical_range(key: str, value: float, name: str | None = None) -> float:
    """``value`` if it lies in the physical range of ``name`` (default: the last part of the dotted ``key``) or
    there is none; else ConfigError naming ``key`` (a file's key or a command-line option).
    """
    limits = PHYSICAL_RANGES.get(name or key.rsplit(".", 1)[-1])
    if limits is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
        low, high, why = limits
        if not low <= value <= high:
            what = key if key.startswith("-") else f"key {key!r} ="
            raise ConfigError(f"{what} {value!r}: expected a number from {low:g} to {high:g} ({why})")
    return value


def read_toml(path: str | Path, what: str = "file") -> dict:
    """Read a TOML file, turning I/O and syntax errors into ConfigError."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{what} {str(path)!r}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{what} {str(path)!r}: cannot be read ({exc})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{what} {str(path)!r}: not valid TOML ({exc})") from None


def resolve_embedded(name: str | Path, embedded: dict[str, Path], what: str) -> Path:
    """A file path, or the path of the embedded ``what`` (scene, case) called ``name``."""
    candidate = Path(name)
    if candidate.exists() or candidate.suffix:
        return candidate
    if str(name) in embedded:
        return embedded[str(name)]
    raise ConfigError(
        f"{what} {str(name)!r}: no such file and no embedded {what} of that name (embedded: {', '.join(embedded)})"
    )


def _key(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _type_name(tp: Any) -> str:
    if tp is float:
        return "a finite number"
    if tp is int:
        return "an integer"
    if tp is str:
        return "a string"
    if tp is bool:
        return "true or false"
    if dataclasses.is_dataclass(tp):
        return f"a table ({tp.__name__})"
    origin = typing.get_origin(tp)
    if origin is tuple:
        args = typing.get_args(tp)
        inner = args[0] if args else Any
        return f"a list of {_type_name(inner).removeprefix('a ').removeprefix('an ')}s"
    if origin in (typing.Union, types.UnionType):
        return " or ".join("nothing (omit the key)" if a is type(None) else _type_name(a) for a in typing.get_args(tp))
    if origin is typing.Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(tp))
    return str(tp)


def convert_value(value: Any, tp: Any, key: str) -> Any:
    """Check and convert one TOML value to the annotated type ``tp``; ConfigError names ``key``."""
    origin = typing.get_origin(tp)
    if tp is Any:
        return value
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        errors = []
        for arg in args:
            if arg is type(None):
                continue
            try:
                return convert_value(value, arg, key)
            except ConfigError as exc:
                errors.append(exc)
        if len(errors) == 1:
            raise errors[0]
        raise ConfigError(f"key {key!r} = {value!r}: expected {_type_name(tp)}")
    if origin is typing.Literal:
        if value not in typing.get_args(tp):
            raise ConfigError(f"key {key!r} = {value!r}: expected {_type_name(tp)}")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"key {key!r} = {value!r}: expected a finite number")
        if not math.isfinite(value):
            raise ConfigError(f"key {key!r} = {value!r}: expected a finite number")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"key {key!r} = {value!r}: expected an integer")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"key {key!r} = {value!r}: expected a string")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"key {key!r} = {value!r}: expected true or false")
        return value
    if origin is tuple:
        if not isinstance(value, list):
            raise ConfigError(f"key {key!r} = {value!r}: expected {_type_name(tp)}")
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(convert_value(v, args[0], f"{key}[{i}]") for i, v in enumerate(value))
        if len(args) != len(value):
            raise ConfigError(f"key {key!r} = {value!r}: expected a list of {len(args)} values")
        return tuple(convert_value(v, a, f"{key}[{i}]") for i, (v, a) in enumerate(zip(value, args, strict=True)))
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise ConfigError(f"key {key!r} = {value!r}: expected {_type_name(tp)}")
        return build_dataclass(tp, value, key)
    raise ConfigError(f"key {key!r}: unsupported field type {tp!r} (a wheelrail bug)")


def build_dataclass(cls: type, table: dict, prefix: str = "") -> Any:
    """Build the frozen dataclass ``cls`` from a TOML table, checking every key.

    Raises:
        ConfigError: unknown key, missing key, wrong type, non-finite number, or a validation
            error of the dataclass itself (re-raised with the key path).
    """
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(table) - set(fields))
    if unknown:
        where = f"in table [{prefix}]" if prefix else "at the top level"
        raise ConfigError(
            f"unknown key {_key(prefix, unknown[0])!r} {where}: expected one of {', '.join(sorted(fields))}"
        )
    kwargs = {}
    for name, f in fields.items():
        key = _key(prefix, name)
        if name not in table:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise ConfigError(f"missing key {key!r}: expected {_type_name(hints[name])}")
            continue
        kwargs[name] = check_physical_range(key, convert_value(table[name], hints[name], key))
    try:
        return cls(**kwargs)
    except ConfigError:
        raise
    except (ValueError, TypeError) as exc:
        where = f"[{prefix}] " if prefix else ""
        raise ConfigError(f"{where}{exc}") from None


def check_keys(table: dict, allowed: set[str] | dict, prefix: str) -> None:
    """Raise ConfigError for a key of ``table`` not in ``allowed``."""
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        where = f"in table [{prefix}]" if prefix else "at the top level"
        raise ConfigError(
            f"unknown key {_key(prefix, unknown[0])!r} {where}: expected one of {', '.join(sorted(allowed))}"
        )


def get_table(doc: dict, name: str, required: bool = True) -> dict:
    """Sub-table ``name`` of ``doc`` ({} if absent and not required)."""
    if name not in doc:
        if required:
            raise ConfigError(f"missing table [{name}]")
        return {}
    value = doc[name]
    if not isinstance(value, dict):
        raise ConfigError(f"key {name!r} = {value!r}: expected a table [{name}]")
    return value


def get_number(table: dict, name: str, prefix: str, *, positive: bool = False, default: float | None = None) -> float:
    """A finite number from ``table`` (ConfigError naming ``prefix.name`` otherwise)."""
    key = _key(prefix, name)
    if name not in table:
        if default is not None:
            return default
        raise ConfigError(f"missing key {key!r}: expected a finite number")
    value = convert_value(table[name], float, key)
    if positive and value <= 0:
        raise ConfigError(f"key {key!r} = {value!r}: expected a number > 0")
    return check_physical_range(key, value)
