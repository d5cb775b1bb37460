"""Scoped use of gmsh: no global gmsh state is left behind.

:func:`gmsh_model` initialises gmsh if nobody else did (and finalises it on exit in that case),
adds a fresh named model, makes it current, silences the terminal and removes the model on exit,
restoring the previous options it changed.
"""

from __future__ import annotations

import contextlib
import itertools

_counter = itertools.count()

_SIZE_OPTIONS = {
    "Mesh.MeshSizeExtendFromBoundary": 0.0,
    "Mesh.MeshSizeFromPoints": 0.0,
    "Mesh.MeshSizeFromCurvature": 0.0,
}


@contextlib.contextmanager
def gmsh_model(name: str = "wheelrail"):
    """Context manager yielding ``gmsh.model`` with a fresh current model called ``name``-N."""
    try:
        import gmsh
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError("meshing needs the gmsh Python API (pip install gmsh)") from error

    owner = not gmsh.isInitialized()
    if owner:
        ignored = _sigpipe_ignored()
        gmsh.initialize(interruptible=False)
        if ignored:
            _ignore_sigpipe()
    saved = {key: gmsh.option.getNumber(key) for key in ("General.Terminal", *_SIZE_OPTIONS)}
    gmsh.option.setNumber("General.Terminal", 0)
    for key, value in _SIZE_OPTIONS.items():
        gmsh.option.setNumber(key, value)
    model_name = f"{name}-{next(_counter)}"
    previous = gmsh.model.getCurrent() if gmsh.model.list() else None
    gmsh.model.add(model_name)
    try:
        yield gmsh.model
    finally:
        gmsh.model.setCurrent(model_name)
        gmsh.model.remove()
        if previous is not None and previous in gmsh.model.list():
            gmsh.model.setCurrent(previous)
        for key, value in saved.items():
            gmsh.option.setNumber(key, value)
        if owner:
            gmsh.finalize()


def _sigpipe_ignored() -> bool:
    """Whether SIGPIPE is ignored in this process (Python's setting at start-up), read from /proc (Linux)."""
    try:
        with open("/proc/self/status", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("SigIgn:"):
                    return bool(int(line.split()[1], 16) >> 12 & 1)  # bit SIGPIPE - 1 = 12
    except (OSError, ValueError, IndexError):
        pass
    return False


def _ignore_sigpipe() -> None:
    """Ignore SIGPIPE again: gmsh.initialize resets it to its default, after which a write to a closed socket or pipe
    (a dask TLS connection closing, a reader that went away) kills the process instead of raising BrokenPipeError.
    Process-wide, from any thread (a dask worker runs its task outside the main thread).
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


def generate(model, dim: int = 3, optimize: bool = True) -> None:
    """Generate the mesh of the current model (and optimise the tetrahedra with gmsh's default pass)."""
    model.mesh.generate(dim)
    if optimize and dim == 3:
        model.mesh.optimize("")
