"""Output folders and atomic writes.

Every file is written through :func:`atomic_write` (from :mod:`rigid_dynamics.files`): a temporary name in
the same folder, flushed, renamed into place (``os.replace`` is atomic on POSIX), with the permissions of a
normally created file. A crash, a kill or a full disk never leaves a half file under a final name; a failed
write raises :class:`~rigid_dynamics.files.WriteError` (an OSError naming the file), which the CLI reports in
one line (exit status 3).

:func:`output_folder` is where a run gets its folder: it checks before any work that the folder can be
written (``--out ""``, a path that is a file or lies under a file, a read-only place, a full disk: one
ConfigError naming ``--out`` and the value), takes a lock file so that two runs never write into the same
folder, removes a summary left by an earlier run (a folder's ``summary.json`` is always the last run's, and
is written last), and on leaving releases the lock and removes the folder again if it created it and
nothing was written.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from rigid_dynamics.files import WriteError, atomic_write, save_figure
from wheelrail.config import ConfigError

__all__ = [
    "LOCK_NAME",
    "WriteError",
    "atomic_write",
    "copy_input",
    "new_output_dir",
    "output_folder",
    "save_figure",
    "to_json",
    "write_json",
    "write_npz",
    "write_text",
]

LOCK_NAME = ".wheelrail.lock"
"""The lock file a run holds in its output folder (pid and host of the run)."""


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


def _check_out(base: str | Path, option: str) -> Path:
    """The path of ``--out`` if it can be a folder (ConfigError naming the option and the value otherwise)."""
    text = str(base)
    if not text.strip():
        raise ConfigError(
            f"{option} {text!r}: expected a folder path (an empty path would write into the current folder)"
        )
    out = Path(base)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"{option} {text!r}: expected a folder, found a file")
    for parent in out.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ConfigError(f"{option} {text!r}: expected a folder path, but {str(parent)!r} is a file")
            break
    return out


def _create(out: Path, option: str, text: str, *, exclusive: bool) -> None:
    try:
        out.mkdir(parents=True, exist_ok=not exclusive)
    except FileExistsError:
        raise
    except OSError as exc:
        raise ConfigError(f"{option} {text!r}: the folder cannot be created ({exc.strerror or exc})") from None


def new_output_dir(base: str | Path | None, name: str, *, option: str = "--out") -> Path:
    """The folder a run writes into: ``base`` (checked, created) or a new ``wheelrail-out/<name>-<UTC time>``.

    Prefer :func:`output_folder`, which also locks the folder and checks that it can be written.

    Raises:
        ConfigError: ``base`` is empty, a file, under a file, or cannot be created.
    """
    if base is not None:
        out = _check_out(base, option)
        _create(out, option, str(base), exclusive=False)
        return out
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S")
    for attempt in range(1, 1000):
        out = Path("wheelrail-out") / (f"{name}-{stamp}" if attempt == 1 else f"{name}-{stamp}-{attempt}")
        _check_out(out, "output folder")
        try:
            _create(out, "output folder", str(out), exclusive=True)
        except FileExistsError:
            continue  # another run started in the same second: take the next name
        return out
    raise ConfigError(f"output folder {str(out)!r}: no free name")  # pragma: no cover


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _lock(out: Path, option: str, text: str) -> Path:
    """Create the lock file (also the check that the folder can be written); ConfigError if another run holds it."""
    lock = out / LOCK_NAME
    content = f"{os.getpid()} {socket.gethostname()} {datetime.now(UTC).isoformat()}\n".encode()
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666)
        except FileExistsError:
            try:
                pid_text, host = lock.read_text(encoding="utf-8").split()[:2]
                pid = int(pid_text)
            except (OSError, ValueError):
                pid, host = -1, ""
            if host == socket.gethostname() and not _pid_alive(pid):
                lock.unlink(missing_ok=True)  # left by a run that was killed
                continue
            raise ConfigError(
                f"{option} {text!r}: another wheelrail run (pid {pid} on {host or 'unknown host'}) is writing into "
                f"this folder (lock file {LOCK_NAME}); choose another folder or wait for it to finish"
            ) from None
        except OSError as exc:
            raise ConfigError(f"{option} {text!r}: the folder cannot be written ({exc.strerror or exc})") from None
        try:
            os.write(fd, content)
            os.fsync(fd)
        except OSError as exc:
            os.close(fd)
            lock.unlink(missing_ok=True)
            raise ConfigError(f"{option} {text!r}: the folder cannot be written ({exc.strerror or exc})") from None
        os.close(fd)
        return lock
    raise ConfigError(f"{option} {text!r}: the lock file {LOCK_NAME} cannot be taken")  # pragma: no cover


@contextmanager
def output_folder(
    base: str | Path | None, name: str, *, option: str = "--out", summaries: tuple[str, ...] = ("summary.json",)
) -> Iterator[Path]:
    """The output folder of one run, checked, locked and cleaned up (module docstring). Use it before the work.

    ``summaries`` are the names of the run's summary files: one left by an earlier run is removed first, so that
    a summary in the folder always belongs to the files beside it (write it last).

    Raises:
        ConfigError: the folder is not usable (empty path, a file, under a file, cannot be created or written,
            held by another run).
    """
    existed = base is not None and Path(base).is_dir()
    out = new_output_dir(base, name, option=option)
    text = str(base) if base is not None else str(out)
    try:
        lock = _lock(out, option, text)
    except ConfigError:
        if not existed:
            _remove_if_empty(out)
        raise
    for summary in summaries:
        try:
            (out / summary).unlink(missing_ok=True)
        except OSError as exc:
            lock.unlink(missing_ok=True)
            raise ConfigError(
                f"{option} {text!r}: the old {summary} cannot be removed ({exc.strerror or exc})"
            ) from None
    try:
        yield out
    finally:
        lock.unlink(missing_ok=True)
        if not existed:
            _remove_if_empty(out)


def _remove_if_empty(out: Path) -> None:
    """Remove a folder this run created if nothing was written into it (an unknown model leaves no folder)."""
    try:
        out.rmdir()
    except OSError:
        pass  # not empty (the run wrote files), or already gone


def copy_input(source: str | Path, out_dir: Path, name: str | None = None) -> Path:
    """Copy the scene or case file a run used into its output folder (atomically)."""
    source = Path(source)
    target = out_dir / (name or source.name)
    return atomic_write(target, lambda tmp: shutil.copyfile(source, tmp))
