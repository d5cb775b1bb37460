"""Atomic file writes: the one helper every file of a run goes through (data, summaries, plots).

:func:`atomic_write` calls a writer on a temporary name in the target's folder (a hidden name ending in
``.part`` plus the target's suffix, so matplotlib and numpy still see the format), flushes it to disk and
renames it onto the final name (``os.replace``, atomic on POSIX). A run that is killed, or a writer that
fails (full disk, file-size limit, read-only folder), therefore never leaves a file under its final name
that is not whole. The file gets the permissions of a normally created file (0666 minus the umask), not
the 0600 of a temporary file.

:func:`ignore_sigpipe` restores Python's start-up setting (SIGPIPE ignored) that gmsh and dolfinx reset: with it at
its default, a write to a closed pipe or socket kills the process mid-write instead of raising BrokenPipeError.

:func:`json_ready` is the one JSON sanitiser (NaN/inf -> null, numpy values -> numbers and lists) behind
:func:`to_json` and :func:`write_json`.

It lives in the lowest layer (stdlib only; numpy imported by :func:`write_npz` alone) so that every package can use
it: ``wheelrail.output`` re-exports it, ``comparisons`` and ``fea`` write and save their plots through it.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path, PurePath


class WriteError(OSError):
    """Writing a file failed; ``filename`` is the final path, ``strerror`` the reason (no partial file is left)."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write(path: str | Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer(tmp_path)``, then rename the temporary file to ``path`` only if it succeeded.

    Args:
        path: final path; its folder is created if missing.
        writer: writes the whole file at the path it is given.

    Returns:
        ``path`` as a Path.

    Raises:
        WriteError: an OSError while writing or renaming (the temporary file is removed).
        Any other exception of ``writer`` (the temporary file is removed too).
    """
    path = Path(path)
    tmp_path = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".part{path.suffix}", dir=path.parent)
        os.close(fd)
        tmp_path = Path(tmp)
        writer(tmp_path)
        with open(tmp_path, "rb+") as handle:
            os.fsync(handle.fileno())
        os.chmod(tmp_path, 0o666 & ~_umask())
        os.replace(tmp_path, path)
    except OSError as exc:
        _remove(tmp_path)
        if isinstance(exc, WriteError):
            raise
        raise WriteError(exc.errno, exc.strerror or str(exc), str(path)) from exc
    except BaseException:
        _remove(tmp_path)
        raise
    return path


def _remove(tmp_path: Path | None) -> None:
    if tmp_path is not None:
        try:
            tmp_path.unlink(missing_ok=True)
        except OSError:
            pass


def write_text(path: str | Path, text: str) -> Path:
    """Write text (UTF-8) atomically."""
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def json_ready(value):
    """``value`` as data JSON can hold, recursively: NaN and inf -> None (JSON has no NaN), numpy scalars and arrays
    -> numbers and lists, paths -> strings, tuples -> lists, dict keys that JSON cannot take -> strings. Other
    objects are left for ``json.dumps`` to refuse (TypeError). The one JSON sanitiser of every written file.
    """
    if isinstance(value, float):  # numpy.float64 too
        return float(value) if math.isfinite(value) else None
    if isinstance(value, dict):
        return {_json_key(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, PurePath):
        return str(value)
    if hasattr(value, "item") and getattr(value, "ndim", None) == 0:  # numpy scalar or 0-d array
        return json_ready(value.item())
    if hasattr(value, "tolist") and hasattr(value, "ndim"):  # numpy array
        return json_ready(value.tolist())
    return value


def _json_key(key):
    return key if key is None or isinstance(key, (str, int, float, bool)) else str(key)


def to_json(data) -> str:
    """JSON text (indent 2) of :func:`json_ready` ``(data)``: NaN/inf written as null."""
    return json.dumps(json_ready(data), indent=2)


def write_json(path: str | Path, data) -> Path:
    """Write ``data`` as JSON (:func:`to_json`, a closing newline) atomically."""
    return write_text(path, to_json(data) + "\n")


def write_npz(path: str | Path, **arrays) -> Path:
    """Write arrays to a compressed NPZ file atomically (numpy imported here: this module stays stdlib-only)."""
    import numpy as np

    def writer(tmp: Path) -> None:
        with open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)

    return atomic_write(path, writer)


def save_figure(fig, path: str | Path, **savefig_kwargs) -> Path:
    """Save a matplotlib figure atomically; the format comes from the suffix of ``path`` (PNG if none)."""
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower() or "png"
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt, **savefig_kwargs))


def sigpipe_ignored() -> bool:
    """Whether SIGPIPE is ignored in this process (Python's setting at start-up), read from /proc (Linux)."""
    try:
        with open("/proc/self/status", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("SigIgn:"):
                    return bool(int(line.split()[1], 16) >> 12 & 1)  # bit SIGPIPE - 1 = 12
    except (OSError, ValueError, IndexError):
        pass
    return False


def ignore_sigpipe() -> None:
    """Ignore SIGPIPE again, as Python does at start-up: gmsh.initialize and importing dolfinx (PETSc) reset it to its
    default, after which a write to a closed socket or pipe (a dask TLS connection closing, a reader that went away)
    kills the process instead of raising BrokenPipeError. Process-wide, from any thread (a dask worker runs its task
    outside the main thread).
    """
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)
        return
    import ctypes

    try:
        ctypes.CDLL(None).signal(int(signal.SIGPIPE), ctypes.c_void_p(1))  # SIG_IGN
    except (OSError, AttributeError):  # pragma: no cover - no libc signal(): nothing to restore with
        pass
