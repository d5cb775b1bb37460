"""On-disk cache of the contact-geometry tables (:class:`~rigid_dynamics.wheelset.providers.tables.TableProvider`).

Sampling the profile section on the (roll, lateral shift) grid is most of a profile scene's set-up (``curve``: 95 %
of its CPU before this cache), and it depends only on the profiles, their placement and the grid. The tables are
stored, as numba stores its kernels, in one file per key:

* the folder: ``$WHEELRAIL_CACHE_DIR/tables`` if that variable is set, else ``$XDG_CACHE_HOME/wheelrail/tables``,
  else ``~/.cache/wheelrail/tables``; deleting it is always safe (the next run rebuilds);
* the key: SHA-256 of the wheelset and track parameters (their exact ``repr``), the bytes of any profile file they
  name, the grid, the section provider's class, and the source of the code that computes the tables (every file
  of ``rigid_dynamics/geometry`` with its data, ``rigid_dynamics/wheelset/providers``, ``parameters.py``): an edit
  of any of them is a new key, never a stale table;
* the file: ``tables-<key>.npz`` (numpy, no pickles) holding the key itself and the arrays, written atomically
  (rigid_dynamics.files.atomic_write), so a killed run leaves the old file or none.

A file that cannot be read, holds another key or arrays of the wrong shape is rebuilt and rewritten, with a note
(:attr:`TableCacheResult.note`, which the run's summary carries). A folder that cannot be written costs only the
saving (noted too).
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

_PACKAGE = Path(__file__).resolve().parents[2]  # rigid_dynamics/
_SOURCE_DIRS = (_PACKAGE / "geometry", _PACKAGE / "wheelset" / "providers")
_SOURCE_FILES = (_PACKAGE / "wheelset" / "parameters.py",)
_FORMAT = "wheelrail-tables-1"


@dataclass(frozen=True)
class TableCacheResult:
    """How a run got its tables: ``status`` "hit" (loaded), "built" (no file yet) or "rebuilt" (a bad file
    replaced); ``path`` the cache file; ``note`` a sentence when something was wrong (else "").
    """

    status: str
    path: Path | None
    note: str = ""


def cache_dir() -> Path:
    """The folder of the table files (module docstring)."""
    explicit = os.environ.get("WHEELRAIL_CACHE_DIR")
    if explicit:
        return Path(explicit) / "tables"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "wheelrail" / "tables"


def _source_digest() -> bytes:
    digest = hashlib.sha256()
    files = [f for d in _SOURCE_DIRS for f in sorted(d.rglob("*")) if f.is_file() and "__pycache__" not in f.parts]
    for path in [*files, *_SOURCE_FILES]:
        digest.update(str(path.relative_to(_PACKAGE)).encode())
        digest.update(path.read_bytes())
    return digest.digest()


def table_key(wheelset, track, section_name: str, grid: tuple) -> str:
    """The cache key of the tables of ``section_name`` for these parameters and grid (module docstring)."""
    digest = hashlib.sha256()
    digest.update(_FORMAT.encode())
    digest.update(repr((wheelset, track, section_name, tuple(float(g) for g in grid))).encode())
    for name in (track.wheel_profile, track.rail_profile, track.left_wheel_profile, track.right_wheel_profile):
        _update_file(digest, name)
    for name in (track.left_rail_profile, track.right_rail_profile):
        _update_file(digest, name)
    digest.update(_source_digest())
    return digest.hexdigest()


def _update_file(digest, name: str) -> None:
    if name and os.path.isfile(name):
        digest.update(Path(name).read_bytes())


def load(key: str, shape: tuple) -> tuple[dict | None, str]:
    """(arrays, note): the cached arrays of ``key`` if its file is whole and matches ``shape`` (the table's), else
    None with a note saying what was wrong ("" when there is simply no file).
    """
    path = cache_dir() / f"tables-{key}.npz"
    if not path.exists():
        return None, ""
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: np.array(data[name]) for name in ("key", "table", "side", "slot")}
        if str(arrays["key"]) != key:
            raise ValueError("it holds another key")
        if arrays["table"].shape != shape or not np.all(np.isfinite(arrays["table"][[0, 1, 2, 3]])):
            raise ValueError(f"table shape {arrays['table'].shape} (expected {shape}) or non-finite values")
    except Exception as exc:  # noqa: BLE001 -- any unreadable file is rebuilt, never trusted
        return None, f"contact-table cache file {path} unreadable ({type(exc).__name__}: {exc}): rebuilt"
    return arrays, ""


def save(key: str, table: np.ndarray, side: np.ndarray, slot: np.ndarray) -> tuple[Path | None, str]:
    """Write the tables of ``key`` atomically; (path, note): note says why it could not be written (else "")."""
    from rigid_dynamics.files import atomic_write

    path = cache_dir() / f"tables-{key}.npz"

    def writer(tmp: Path) -> None:
        with open(tmp, "wb") as handle:
            np.savez(handle, key=np.array(key), table=table, side=side, slot=slot)

    try:
        atomic_write(path, writer)
    except OSError as exc:
        return None, f"contact tables not cached ({path}: {exc})"
    return path, ""
