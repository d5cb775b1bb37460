"""Dynamics scenes: embedded TOML files, validation into ``DynamicsScene``, run outputs.

A scene file mirrors the fields of :class:`rigid_dynamics.wheelset.DynamicsScene`: nested tables
for nested dataclasses, SI units in the key names. Any key whose name ends in ``_profile`` names a
built-in profile or a profile file and is read before any work, so an unreadable profile fails
with the key named.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from wheelrail.config import ConfigError, build_dataclass, read_toml, resolve_embedded

SCENES_DIR = Path(__file__).parent / "scenes"
DEFAULT_SCENE = "hunting-conical"
DEFAULT_STRESS_SCENE = "hunting-conical"
REQUIRED_SCENE_KEYS = ("speed_m_per_s", "duration_s")
"""Keys a scene must state although the dataclass has defaults for them (a run's speed and length)."""
ANALYTIC_TRACK_NAMES = {"conical", "circular"}
"""Profile names a scene's track may use for the analytic conical-wheel / circular-rail pair (no file)."""


def embedded_scenes() -> dict[str, Path]:
    """Embedded scenes: name -> path."""
    return {p.stem: p for p in sorted(SCENES_DIR.glob("*.toml"))}


def scene_description(path: Path) -> str:
    """The ``description`` of a scene file ('' if it has none or cannot be read)."""
    try:
        return str(read_toml(path).get("description", ""))
    except ConfigError:
        return ""


def resolve_scene_path(scene: str | Path) -> Path:
    """A file path, or the path of the embedded scene of that name."""
    return resolve_embedded(scene, embedded_scenes(), "scene")


def _check_profiles(table: dict, prefix: str = "") -> None:
    from rigid_dynamics.geometry import load_profile

    for key, value in table.items():
        dotted = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict):
            _check_profiles(value, dotted)
        elif key.endswith("_profile") and isinstance(value, str) and value.lower() not in ANALYTIC_TRACK_NAMES:
            kind = "rail" if "rail" in key else "wheel"
            try:
                load_profile(value, kind)
            except ValueError as exc:
                raise ConfigError(f"key {dotted!r} = {value!r}: {exc}") from None


def parse_scene(doc: dict):
    """Validate a parsed scene document into a DynamicsScene (ConfigError on any problem)."""
    from rigid_dynamics.wheelset import DynamicsScene

    field_names = {f.name for f in dataclasses.fields(DynamicsScene)}
    doc = dict(doc)
    for informative in ("description", "name"):
        if informative in doc and informative not in field_names:
            value = doc.pop(informative)
            if not isinstance(value, str):
                raise ConfigError(f"key {informative!r} = {value!r}: expected a string")
    for key in REQUIRED_SCENE_KEYS:
        if key not in doc:
            raise ConfigError(f"missing key {key!r}: expected a finite number (every scene states it)")
    _check_profiles(doc)
    scene = build_dataclass(DynamicsScene, doc)
    from rigid_dynamics.wheelset.checks import SceneError, check_scene

    try:
        check_scene(scene)
    except SceneError as exc:
        raise ConfigError(f"key {exc.key!r} = {exc.value!r}: expected {exc.expected}") from None
    return scene


def load_scene(path: str | Path):
    """Read and validate a scene file or embedded scene name."""
    path = resolve_scene_path(path)
    return parse_scene(read_toml(path, "scene file"))


def write_run_outputs(result, scene_path: Path, out_dir: Path, plots: bool = True) -> dict:
    """Write scene.toml, summary.json, timeseries.npz (atomic) and plots; return the summary."""
    from rigid_dynamics.wheelset import timeseries_arrays
    from wheelrail.output import copy_input, write_json, write_npz

    copy_input(scene_path, out_dir, "scene.toml")
    summary = dict(result.summary())
    files = ["scene.toml", "summary.json"]
    arrays = timeseries_arrays(result)
    if arrays:
        write_npz(out_dir / "timeseries.npz", **arrays)
        files.append("timeseries.npz")
    if plots and len(result.t) > 1:
        from comparisons.dynamics_plots import plot_simulation

        files.extend(Path(p).name for p in plot_simulation(result, out_dir))
    summary["files"] = files
    write_json(out_dir / "summary.json", summary)
    return summary
