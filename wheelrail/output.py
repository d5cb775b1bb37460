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
nothing was written. Every command (``run``, ``contact``, ``sweep``, ``critical-speed``, ``stress``, ``compare``,
``bench``, ``demo``, ``manchester``) takes its folder here, once, before any work.

Nothing is written outside the folder: a folder name made from an input file (a case's ``name``) is sanitised
(:func:`safe_name`: no separators, no ``..``), a folder whose run sub-folders hold a symbolic link (planted by
someone else: a run never makes one) is refused, sub-folders are made by :func:`subfolder` (which refuses a link in
their place), and a path that cannot be encoded (for the file system, for the UTF-8 of ``summary.json`` or for
the terminal) is refused before anything is written.
"""

from __future__ import annotations

import os
import shutil
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

from rigid_dynamics.files import WriteError, atomic_write, save_figure, to_json, write_json, write_npz, write_text
from wheelrail.config import ConfigError

__all__ = [
    "LOCK_NAME",
    "WriteError",
    "atomic_write",
    "copy_input",
    "new_output_dir",
    "output_folder",
    "safe_name",
    "save_figure",
    "subfolder",
    "to_json",
    "write_json",
    "write_npz",
    "write_text",
]

LOCK_NAME = ".wheelrail.lock"
"""The lock file a run holds in its output folder (pid and host of the run)."""


def safe_name(text: str) -> str:
    """A name from an input file made safe as one path component: separators, ``..``, control characters and
    leading dots replaced (``"../../x"`` -> ``"x"``), at most 80 characters, never empty.
    """
    import re

    cleaned = re.sub(r"[^A-Za-z0-9._+-]+", "_", str(text))
    cleaned = re.sub(r"_+", "_", re.sub(r"\.{2,}", "_", cleaned)).strip("._-")
    return cleaned[:80] or "case"


def check_encodable(text: str, what: str) -> None:
    """ConfigError unless ``text`` (a path) can be encoded for the file system, as UTF-8 (the JSON summaries) and
    for this process's standard output (the printed folder): found before anything is written.
    """
    import sys

    targets = [("the file system", None), ("UTF-8", "utf-8")]
    encoding = getattr(sys.stdout, "encoding", None)
    if encoding:
        targets.append((f"the terminal's encoding {encoding}", encoding))
    for name, codec in targets:
        try:
            os.fsencode(text) if codec is None else text.encode(codec)
        except (UnicodeEncodeError, LookupError):
            shown = text.encode("ascii", "backslashreplace").decode("ascii")
            raise ConfigError(f"{what} {shown!r}: cannot be encoded for {name} (choose a plain path)") from None


def _check_out(base: str | Path, option: str) -> Path:
    """The path of ``--out`` if it can be a folder (ConfigError naming the option and the value otherwise)."""
    text = str(base)
    if not text.strip():
        raise ConfigError(
            f"{option} {text!r}: expected a folder path (an empty path would write into the current folder)"
        )
    check_encodable(text, option)
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
    name = safe_name(name)
    if base is not None:
        out = _check_out(base, option)
        _create(out, option, str(base), exclusive=False)
        return out
    check_encodable(str(Path.cwd()), "the current folder")
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
    if base is not None:
        _check_out(base, option)  # an empty or unencodable path is refused before anything is created
    existed = base is not None and Path(base).is_dir()
    out = new_output_dir(base, name, option=option)
    text = str(base) if base is not None else str(out)
    try:
        _refuse_links(out, option, text)
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
        try:
            lock.unlink(missing_ok=True)
        except OSError as exc:  # the folder turned read-only (or went away) during the run
            import sys

            if sys.exc_info()[0] is None:
                raise WriteError(exc.errno, exc.strerror or str(exc), str(lock)) from None
        if not existed:
            _remove_if_empty(out)


RUN_SUBFOLDERS = ("points", "fea", "run", "compare")
"""The sub-folders commands write into (sweep points, FEA files, the demo's run and comparison)."""


def _refuse_links(out: Path, option: str, text: str) -> None:
    """ConfigError if a sub-folder a run writes into (:data:`RUN_SUBFOLDERS`), or anything below one, is a symbolic
    link: a run never makes one, and following it could write outside the folder. (Files in the folder itself are
    replaced by name, a link among them is replaced, not followed; the rest of a user's folder is not searched.)
    """
    for name in RUN_SUBFOLDERS:
        top = out / name
        if top.is_symlink():
            found = top
        elif top.is_dir():
            found = next(
                (
                    Path(root) / n
                    for root, dirs, files in os.walk(top)
                    for n in dirs + files
                    if (Path(root) / n).is_symlink()
                ),
                None,
            )
        else:
            found = None
        if found is not None:
            raise ConfigError(
                f"{option} {text!r}: holds the symbolic link {str(found)!r}; a run writes only inside its folder "
                "and does not follow links (remove it or choose another folder)"
            )


def subfolder(out: Path, name: str) -> Path:
    """The sub-folder ``name`` of an output folder, created if missing; never a symbolic link (WriteError if a link
    or a file is in its place, e.g. planted after the folder was checked).
    """
    path = Path(out) / name
    try:
        path.mkdir(exist_ok=True)
    except FileExistsError:
        pass
    except OSError as exc:
        raise WriteError(exc.errno, exc.strerror or str(exc), str(path)) from None
    if path.is_symlink() or not path.is_dir():
        import errno

        raise WriteError(errno.ENOTDIR, "a symbolic link or a file where the run makes its sub-folder", str(path))
    return path


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
