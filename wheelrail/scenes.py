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
        elif (
            key.endswith("_profile") and isinstance(value, str) and value and value.lower() not in ANALYTIC_TRACK_NAMES
        ):
            # (an empty per-side key, e.g. left_wheel_profile = "", means the two-sided profile)
            kind = "rail" if "rail" in key else "wheel"
            try:
                load_profile(value, kind)
            except ValueError as exc:
                raise ConfigError(f"key {dotted!r} = {value!r}: {exc}") from None


IRREGULARITY_FILE_KEYS = {"wheel_grid_file": "wheel", "corrugation_file": "rail"}
"""Keys of [irregularities] that name measured grids (CSV, rigid_dynamics.geometry.measured)."""


def _resolve_irregularity_files(doc: dict, base_dir: Path | None) -> dict:
    """Make the measured-grid paths of [irregularities] absolute (relative to the scene file) and read them once,
    so that a bad file fails before any work with the key named.
    """
    table = doc.get("irregularities")
    if not isinstance(table, dict) or not any(key in table for key in IRREGULARITY_FILE_KEYS):
        return doc
    from rigid_dynamics.geometry.measured import read_rail_grid_csv, read_wheel_grid_csv

    table = dict(table)
    for key, kind in IRREGULARITY_FILE_KEYS.items():
        value = table.get(key)
        if value is None or value == "":
            continue
        if not isinstance(value, str):
            raise ConfigError(f"key 'irregularities.{key}' = {value!r}: expected the path of a CSV grid file")
        path = Path(value).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        try:
            (read_wheel_grid_csv if kind == "wheel" else read_rail_grid_csv)(path)
        except ValueError as exc:
            raise ConfigError(f"key 'irregularities.{key}' = {value!r}: {exc}") from None
        table[key] = str(path.resolve())
    return {**doc, "irregularities": table}


def _friction_table(doc: dict):
    """(the document without ``[friction]``, its FrictionLaw or None): the table of docs/files.md (the case files'
    shape, rigid_dynamics.contact.friction.friction_law_from_table), which replaces
    ``material.friction_coefficient`` (giving both is an error). The dynamics place a patch by its contact angle
    (surface_inclination) or its track distance; rail_lateral is refused here.
    """
    from rigid_dynamics.contact.friction import friction_law_from_table

    if "friction" not in doc:
        return doc, None
    table = doc["friction"]
    material = doc.get("material", {})
    if isinstance(material, dict) and "friction_coefficient" in material:
        raise ConfigError(
            f"key 'material.friction_coefficient' = {material['friction_coefficient']!r}: not allowed with a "
            "[friction] table (it gives the friction law; remove one of the two)"
        )
    try:
        law = friction_law_from_table(table)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    if law.varies_with == "rail_lateral":
        raise ConfigError(
            "key 'friction.varies_with' = 'rail_lateral': not available in dynamics scenes (a patch is placed by its "
            "contact angle or its track distance): expected 'none', 'surface_inclination' or 'track_distance'"
        )
    rest = {k: v for k, v in doc.items() if k != "friction"}
    if isinstance(material, dict):
        rest["material"] = {**material, "friction_coefficient": law.max_static}
    return rest, law


def parse_scene(doc: dict, base_dir: Path | None = None):
    """Validate a parsed scene document into a DynamicsScene (ConfigError on any problem).

    ``base_dir``: folder that relative file names in the scene (measured irregularity grids) refer to.
    """
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
    doc = _resolve_irregularity_files(doc, base_dir)
    doc, law = _friction_table(doc)
    scene = build_dataclass(DynamicsScene, doc)
    if law is not None:
        scene = dataclasses.replace(scene, material=scene.material.with_friction(law))
    from rigid_dynamics.wheelset.checks import SceneError, check_scene

    try:
        check_scene(scene)
    except SceneError as exc:
        raise ConfigError(f"key {exc.key!r} = {exc.value!r}: expected {exc.expected}") from None
    return scene


def load_scene(path: str | Path):
    """Read and validate a scene file or embedded scene name."""
    path = resolve_scene_path(path)
    return parse_scene(read_toml(path, "scene file"), base_dir=Path(path).parent)


def simulate(scene, progress=None, **options):
    """Run a dynamics scene: a :class:`~rigid_dynamics.wheelset.DynamicsScene`, or a scene's name or TOML file
    (read by :func:`load_scene`); the keyword arguments of :func:`rigid_dynamics.wheelset.simulate` pass through.
    """
    from rigid_dynamics.wheelset import simulate as run

    if isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    return run(scene, progress, **options)


def write_run_outputs(result, scene_path: Path, out_dir: Path, plots: bool = True, extra: dict | None = None) -> dict:
    """Write scene.toml, summary.json, timeseries.npz/.csv/.parquet (atomic) and plots; return the summary.

    ``timeseries.csv`` and ``timeseries.parquet`` hold the tidy table of :mod:`rigid_dynamics.wheelset.table`
    (one row per output time, one column per named quantity, units in the names).
    """
    from rigid_dynamics.wheelset import timeseries_arrays
    from wheelrail.output import copy_input, write_json, write_npz

    copy_input(scene_path, out_dir, "scene.toml")
    summary = dict(result.summary())
    summary.update({k: v for k, v in (extra or {}).items() if v})  # e.g. the --set overrides of the scene
    files = ["scene.toml", "summary.json"]
    irregularities = getattr(result.scene, "irregularities", None)
    for key in IRREGULARITY_FILE_KEYS:
        source = getattr(irregularities, key, "")
        if source:  # the measured grids the scene read, so that the folder reproduces the run
            files.append(copy_input(source, out_dir, f"{key.removesuffix('_file')}-{Path(source).name}").name)
    arrays = timeseries_arrays(result)
    if arrays:
        from rigid_dynamics.wheelset.table import write_table

        write_npz(out_dir / "timeseries.npz", **arrays)
        files.append("timeseries.npz")
        for name in ("timeseries.csv", "timeseries.parquet"):
            write_table(result, out_dir / name)
            files.append(name)
    if plots and len(result.t) > 1:
        from comparisons.dynamics_plots import plot_simulation

        files.extend(Path(p).name for p in plot_simulation(result, out_dir))
    summary["files"] = files
    write_json(out_dir / "summary.json", summary)
    return summary
