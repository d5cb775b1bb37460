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
        from rigid_dynamics.files import ignore_sigpipe, sigpipe_ignored

        ignored = sigpipe_ignored()
        gmsh.initialize(interruptible=False)
        if ignored:
            ignore_sigpipe()  # gmsh.initialize resets it to its default (the process dies on a closed pipe)
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


def generate(model, dim: int = 3, optimize: bool = True) -> None:
    """Generate the mesh of the current model (and optimise the tetrahedra with gmsh's default pass)."""
    model.mesh.generate(dim)
    if optimize and dim == 3:
        model.mesh.optimize("")


def gmsh_number(value) -> str:
    """A number as gmsh's MathEval expressions read it back exactly (17 significant digits)."""
    return f"{float(value):.17g}"


def set_size_field(model, expression: str) -> int:
    """A MathEval size field ``expression`` (of x, y, z; numbers written by :func:`gmsh_number`) set as the background
    mesh size of ``model``; returns the field's tag.
    """
    field = model.mesh.field.add("MathEval")
    model.mesh.field.setString(field, "F", expression)
    model.mesh.field.setAsBackgroundMesh(field)
    return field
