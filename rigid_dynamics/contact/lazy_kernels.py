"""Plain-Python loops compiled by numba only when a batch is large or the module's loops are called often (start-up).

A module whose loops are written once as plain Python (hertz.py, kalker.py, linear.py, vermeulen_johnson.py,
friction.py) runs them as Python for a small batch in a process that has not imported numba -- a command solving one
patch then never pays numba's import and CPU target (0.6-0.8 s CPU, benchmarks/results/startup.md) -- and, where
numba is loaded already (the BEM's kernels), for its first :data:`PYTHON_CALLS_LIMIT` small batches: loading a
module's compiled copies from the disk cache costs 5-20 ms (2-4 ms a kernel), a small batch as Python 0.01-0.3 ms,
so a command solving one patch (``wheelrail contact``, whose ``auto`` runs Hertz and Kalker's table before it runs
the BEM) loads none of them. Otherwise it calls copies of the same function code compiled by numba (cached on disk),
made once per module by :func:`compiled_copies` (the module's ``compiled_kernels()``). Both paths give the same bits
(tests/test_hertz.py, tests/test_lazy_kernels.py).
"""

from __future__ import annotations

import sys
import types
from collections.abc import Callable, Mapping

PYTHON_BATCH_LIMIT = 8
"""Batches up to this size run as Python when numba is not imported yet (or the module's copies are not loaded and
it has run fewer than :data:`PYTHON_CALLS_LIMIT` small batches)."""

PYTHON_CALLS_LIMIT = 32
"""Small batches a module runs as Python in a process that has imported numba before it loads its compiled copies
(about the number at which loading them, 5-20 ms, costs what the Python batches cost)."""

_COPIES: dict[str, dict] = {}
_PYTHON_CALLS: dict[str, int] = {}


def run_as_python(n: int, source: str) -> bool:
    """True where a batch of ``n`` of module ``source``'s loops runs as Python: ``n <= PYTHON_BATCH_LIMIT`` and
    either numba is not imported, or the module's compiled copies are not made yet and this is one of its first
    :data:`PYTHON_CALLS_LIMIT` small batches (counted here).
    """
    if n > PYTHON_BATCH_LIMIT:
        return False
    if "numba" not in sys.modules:
        return True
    if source in _COPIES:
        return False
    calls = _PYTHON_CALLS.get(source, 0) + 1
    _PYTHON_CALLS[source] = calls
    return calls <= PYTHON_CALLS_LIMIT


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
