"""Plain-Python loops compiled by numba only when a batch is large or numba is already loaded (start-up).

A module whose loops are written once as plain Python (hertz.py, kalker.py, linear.py, vermeulen_johnson.py) runs
them as Python for a small batch in a process that has not imported numba -- a command solving one patch then never
pays numba's import and CPU target (0.6-0.8 s CPU, benchmarks/results/startup.md) -- and otherwise calls copies of
the same function code compiled by numba (cached on disk), made by :func:`compiled_copies` in the module's
``_*_kernels`` companion. Both paths give the same bits (tests/test_hertz.py, tests/test_import_hygiene.py).
"""

from __future__ import annotations

import sys
import types

PYTHON_BATCH_LIMIT = 8
"""Batches up to this size run as Python when numba is not imported yet."""


def run_as_python(n: int) -> bool:
    """True where a batch of ``n`` runs as Python: numba not imported, ``n <= PYTHON_BATCH_LIMIT``."""
    return n <= PYTHON_BATCH_LIMIT and "numba" not in sys.modules


def compiled_copies(source, names, *, replacements=None, options=None) -> dict:
    """numba-compiled copies (``cache=True``) of ``source``'s plain-Python functions ``names``.

    Each copy runs the function's code with ``source``'s globals, except that ``replacements`` (name -> object,
    e.g. numba external functions) and the copies made before it (list callees first) take their names' places.

    Args:
        source: the module holding the functions.
        names: function names, callees before callers.
        replacements: globals to replace in the compiled copies.
        options: name -> extra ``njit`` options (e.g. ``{"inline": "always"}``).

    Returns:
        name -> compiled dispatcher.
    """
    from numba import njit

    scope = dict(vars(source))
    scope.update(replacements or {})
    copies = {}
    for name in names:
        function = getattr(source, name)
        clone = types.FunctionType(function.__code__, scope, function.__name__, function.__defaults__)
        clone.__qualname__ = function.__qualname__
        clone.__doc__ = function.__doc__
        copies[name] = scope[name] = njit(cache=True, **(options or {}).get(name, {}))(clone)
    return copies
