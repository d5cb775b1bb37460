"""Reading the named benchmark cases of ``comparisons/cases/<name>/`` (layout: :mod:`comparisons.named_cases`).

Bad names or files raise :class:`~wheelrail.config.ConfigError` naming the case, the key and the value.
"""

from __future__ import annotations

import csv
import math
import tomllib
from pathlib import Path

from comparisons.named_cases import CASES_ROOT, SOURCES, NamedCase, contact_grid_reference, contact_row_reference
from wheelrail.config import ConfigError


def named_case_names() -> list[str]:
    """Names of the named cases (folders with a reference.toml), sorted."""
    return sorted(p.parent.name for p in CASES_ROOT.glob("*/reference.toml"))


def _csv_rows(path: Path) -> list[dict]:
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(line for line in handle if not line.startswith("#")))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        reason = getattr(exc, "strerror", None) or exc
        raise ConfigError(f"{str(path)!r}: cannot be read as a CSV table ({reason})") from None
    if not rows:
        raise ConfigError(f"{path}: no data row")
    return rows


def _contact_grid_reference(folder: Path) -> tuple[dict, dict]:
    """Reference and uncertainty from CONTACT's runs at refined elements (``contact_grid.csv``)."""
    path = folder / "contact_grid.csv"
    try:
        return contact_grid_reference(_csv_rows(path))
    except ConfigError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise ConfigError(f"{path}: {exc}") from None


def _contact_reference(folder: Path) -> dict:
    """Sum of the published CONTACT rows of ``contact_reference.csv`` (N, Fx, Fy summed; max p; summed area)."""
    path = folder / "contact_reference.csv"
    rows = _csv_rows(path)
    try:
        parts = [contact_row_reference(r) for r in rows]
    except (KeyError, TypeError, ValueError) as exc:
        raise ConfigError(
            f"{str(path)!r}: expected CONTACT's columns with numbers ({type(exc).__name__}: {exc})"
        ) from None
    out = {k: sum(p[k] for p in parts) for k in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")}
    out["max_pressure_Pa"] = max(p["max_pressure_Pa"] for p in parts)
    out["contact_area_m2"] = sum(p["contact_area_m2"] for p in parts)
    return out


def load_named_case(name_or_folder: str | Path) -> NamedCase:
    """Read a named case: a name under ``comparisons/cases`` or a folder path holding case.toml + reference.toml."""
    from wheelrail.cases import embedded_cases, load_case

    folder = Path(name_or_folder)
    if not (folder / "reference.toml").is_file():
        folder = CASES_ROOT / str(name_or_folder)
    if not (folder / "reference.toml").is_file():
        cases = embedded_cases()
        if str(name_or_folder) in cases:  # a case without a reference: compared rung against rung, no error columns
            return _unreferenced_case(str(name_or_folder), cases[str(name_or_folder)])
        raise ConfigError(f"case {str(name_or_folder)!r}: expected one of {', '.join(cases)}")
    path = folder / "reference.toml"
    try:
        with open(path, "rb") as handle:
            doc = tomllib.load(handle)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    source = doc.get("source")
    if source not in SOURCES:
        raise ConfigError(f"key 'source' = {source!r} in {path}: expected one of {', '.join(SOURCES)}")
    if not (folder / "case.toml").is_file():
        raise ConfigError(f"case {str(name_or_folder)!r}: {str(folder / 'case.toml')!r} not found (expected the case)")
    for key, kind, what in (("reference", dict, "a table"), ("uncertainty", dict, "a table"), ("tags", list, "a list"),
                            ("side", str, "a string"), ("note", str, "a string")):  # fmt: skip
        if key in doc and not isinstance(doc[key], kind):
            raise ConfigError(f"key {key!r} = {doc[key]!r} in {path}: expected {what}")
    for table in ("reference", "uncertainty"):
        for key, value in doc.get(table, {}).items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ConfigError(f"key '{table}.{key}' = {value!r} in {path}: expected a finite number")
    reference = {k: float(v) for k, v in doc.get("reference", {}).items()}
    uncertainty = {k: float(v) for k, v in doc.get("uncertainty", {}).items()}
    if source == "contact-published":
        reference = {**_contact_reference(folder), **reference}
    elif source == "contact-converged":
        grid, grid_uncertainty = _contact_grid_reference(folder)
        reference, uncertainty = {**grid, **reference}, {**grid_uncertainty, **uncertainty}
    _check_reference_field(folder / "reference_field.npz")
    return NamedCase(
        name=folder.name,
        folder=folder,
        source=source,
        side=str(doc.get("side", "single")),
        reference=reference,
        uncertainty=uncertainty,
        note=str(doc.get("note", "")),
        tags=tuple(doc.get("tags", ())),
        case=load_case(folder / "case.toml"),
    )


def _check_reference_field(path: Path) -> None:
    """A stored reference field (x_m, y_m, pressure_Pa on its grid) must load: checked before any work."""
    if not path.exists():
        return
    import numpy as np

    try:
        with np.load(path) as data:
            x, y, p = (np.asarray(data[k], float) for k in ("x_m", "y_m", "pressure_Pa"))
    except Exception as exc:  # a zip that is not one, a missing array, an object array: all a bad input file
        raise ConfigError(
            f"{str(path)!r}: expected an NPZ file with the arrays x_m, y_m and pressure_Pa ({type(exc).__name__})"
        ) from None
    if x.ndim != 1 or y.ndim != 1 or p.shape != (len(y), len(x)):
        raise ConfigError(
            f"{str(path)!r}: pressure_Pa of shape {p.shape}: expected (len(y_m), len(x_m)) = ({len(y)}, {len(x)})"
        )


def _unreferenced_case(name: str, path: Path) -> NamedCase:
    """A named case without a reference (``wheelrail/cases``): source "none", the right wheel for a wheelset case
    (the side of CONTACT's published A-2.2 solution).
    """
    from wheelrail.cases import load_case
    from wheelrail.config import read_toml

    case = load_case(path)
    return NamedCase(
        name=name,
        folder=path.parent,
        source="none",
        side="single" if case.kind == "quadric" else "right",
        reference={},
        note=str(read_toml(path).get("description", name)),
        case=case,
        case_file=path,
    )


def load_named_cases(names=None) -> list[NamedCase]:
    """The named cases ``names`` (all when None or empty), in the given order."""
    return [load_named_case(n) for n in (names or named_case_names())]
