"""``--set key=value`` overrides of scene, case and sweep files.

A key is a dotted path into the TOML document (``speed_m_per_s``, ``material.friction_coefficient``,
``irregularities.polygon_amplitude_m``); the value is read as a TOML value (``0.3``, ``true``, ``"S1002"``,
``[1, 2]``), and a value that is not valid TOML is taken as a string (``--set track.wheel_profile=S1002``).
Overrides change the document before validation, so a bad value fails with the same message as in the file.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from wheelrail.config import ConfigError, read_toml


def parse_set(item: str) -> tuple[str, object]:
    """``"key=value"`` -> (key, value) (module docstring). ConfigError for a missing ``=`` or an empty key."""
    key, sep, text = item.partition("=")
    key = key.strip()
    if not sep or not key or any(not part for part in key.split(".")):
        raise ConfigError(f"--set {item!r}: expected KEY=VALUE, e.g. material.friction_coefficient=0.4")
    text = text.strip()
    try:
        value = tomllib.loads(f"value = {text}")["value"]
    except tomllib.TOMLDecodeError:
        value = text
    return key, value


def parse_sets(items: list[str] | None) -> dict[str, object]:
    """Several ``--set`` items -> {dotted key: value} (a later item wins)."""
    return dict(parse_set(item) for item in items or [])


def apply_overrides(doc: dict, overrides: dict[str, object]) -> dict:
    """A copy of ``doc`` with each dotted key set to its value (tables created as needed).

    Raises:
        ConfigError: a key runs through a value that is not a table.
    """
    out = _copy(doc)
    for dotted, value in overrides.items():
        parts = dotted.split(".")
        table = out
        for depth, part in enumerate(parts[:-1]):
            nxt = table.setdefault(part, {})
            if not isinstance(nxt, dict):
                where = ".".join(parts[: depth + 1])
                raise ConfigError(f"--set {dotted}: key {where!r} = {nxt!r} is not a table")
            table = nxt
        table[parts[-1]] = value
    return out


def _copy(doc):
    if isinstance(doc, dict):
        return {k: _copy(v) for k, v in doc.items()}
    if isinstance(doc, list):
        return [_copy(v) for v in doc]
    return doc


def load_scene_with(scene: str | Path, sets: list[str] | None):
    """Read, override and validate a scene (embedded name or path); returns (DynamicsScene, path, overrides)."""
    from wheelrail.scenes import parse_scene, resolve_scene_path

    path = resolve_scene_path(scene)
    overrides = parse_sets(sets)
    doc = apply_overrides(read_toml(path, "scene file"), overrides)
    return parse_scene(doc, base_dir=path.parent), path, overrides


def load_case_with(case: str | Path, sets: list[str] | None, method: str | None = None):
    """Read, override and validate a contact case (embedded name or path); returns (ContactCase, path, overrides).

    The CLI's front to :func:`wheelrail.cases.load_case` (the one case loader: relative files in the case refer to
    its folder). With ``method`` the ``[solver]`` table is checked against that model's options.
    """
    from wheelrail.cases import load_case, resolve_case_path

    path = resolve_case_path(case)
    overrides = parse_sets(sets)
    return load_case(path, method=method, overrides=overrides), path, overrides
