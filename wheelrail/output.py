"""Output folders and atomic writes.

Every data file is written to a temporary name in the same folder and renamed into place
(``os.replace`` is atomic on POSIX), so a crash never leaves a half file that looks whole.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path

import numpy as np


def atomic_write(path: str | Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer(tmp_path)`` and rename the temporary file to ``path`` only if it succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        writer(tmp_path)
        os.replace(tmp_path, path)
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        raise
    return path


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def _finite_or_none(value):
    """Replace NaN/inf by None (JSON has no NaN), recursively."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite_or_none(v) for v in value]
    return value


def to_json(data) -> str:
    """JSON text with NaN/inf written as null."""
    return json.dumps(_finite_or_none(data), indent=2, default=_json_default)


def write_json(path: str | Path, data) -> Path:
    """Write ``data`` as JSON atomically."""
    text = to_json(data)
    return atomic_write(path, lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"))


def write_text(path: str | Path, text: str) -> Path:
    """Write text atomically."""
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def write_npz(path: str | Path, **arrays) -> Path:
    """Write arrays to an NPZ file atomically."""

    def writer(tmp: Path) -> None:
        with open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)

    return atomic_write(path, writer)


def new_output_dir(base: str | Path | None, name: str) -> Path:
    """The folder a run writes into: ``base`` if given, else ``wheelrail-out/<name>-<UTC time>``."""
    if base is not None:
        out = Path(base)
    else:
        stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S")
        out = Path("wheelrail-out") / f"{name}-{stamp}"
    out.mkdir(parents=True, exist_ok=True)
    return out


def copy_input(source: str | Path, out_dir: Path, name: str | None = None) -> Path:
    """Copy the scene or case file a run used into its output folder (atomically)."""
    source = Path(source)
    target = out_dir / (name or source.name)
    return atomic_write(target, lambda tmp: shutil.copyfile(source, tmp))
