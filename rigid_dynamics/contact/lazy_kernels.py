"""Plain-Python loops compiled by numba only when a batch is large or numba is already loaded (start-up).

A module whose loops are written once as plain Python (hertz.py, kalker.py, linear.py, vermeulen_johnson.py) runs
them as Python for a small batch in a process that has not imported numba -- a command solving one patch then never
pays numba's import and CPU target (0.6-0.8 s CPU, benchmarks/results/startup.md) -- and otherwise calls copies of
the same function code compiled by numba (cached on disk), made once per module by :func:`compiled_copies` (the
module's ``compiled_kernels()``). Both paths give the same bits (tests/test_hertz.py, tests/test_lazy_kernels.py).
"""

from __future__ import annotations

import sys
import types
from collections.abc import Callable, Mapping

PYTHON_BATCH_LIMIT = 8
"""Batches up to this size run as Python when numba is not imported yet."""


def run_as_python(n: int) -> bool:
    """True where a batch of ``n`` runs as Python: numba not imported, ``n <= PYTHON_BATCH_LIMIT``."""
    return n <= PYTHON_BATCH_LIMIT and "numba" not in sys.modules


_COPIES: dict[str, dict] = {}


def compiled_copies(
    source: str,
    names: tuple[str, ...],
    *,
    replacements: Callable[[], Mapping] | None = None,
    options: Mapping[str, Mapping] | None = None,
) -> dict:
    """numba-compiled copies (``cache=True``) of the plain-Python functions ``names`` of module ``source``, made
    once per process and module (imports numba).

    Each copy runs the function's code with the module's globals, except that ``replacements()`` (name -> object,
    e.g. numba external functions) and the copies made before it (list callees first) take their names' places.

    Args:
        source: the module's name (``__name__``; the module is imported already).
        names: function names, callees before callers.
        replacements: called once, returns the globals to replace in the compiled copies.
        options: name -> extra ``njit`` options (e.g. ``{"inline": "always"}``).

    Returns:
        name -> compiled dispatcher.
    """
    if source in _COPIES:
        return _COPIES[source]
    from numba import njit

    module = sys.modules[source]
    scope = dict(vars(module))
    scope.update(replacements() if replacements is not None else {})
    copies = {}
    for name in names:
        function = getattr(module, name)
        clone = types.FunctionType(function.__code__, scope, function.__name__, function.__defaults__)
        clone.__qualname__ = function.__qualname__
        clone.__doc__ = function.__doc__
        copies[name] = scope[name] = njit(cache=True, **(options or {}).get(name, {}))(clone)
    _COPIES[source] = copies
    return copies
