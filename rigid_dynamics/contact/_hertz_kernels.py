"""numba-compiled versions of the Hertz loops in rigid_dynamics/contact/hertz.py (one source, two paths).

hertz.py holds the loops as plain Python so that a command solving one patch need not import numba. This module
compiles the same function objects' code with numba: each is re-bound to a namespace where its callees are the
compiled ones and scipy's ``ellipkm1``/``ellipe`` are called from compiled code through
``scipy.special.cython_special`` (registered as named external symbols so that the kernels can be cached on disk).
Imported by hertz.py for batches above ``hertz.PYTHON_BATCH_LIMIT`` or once numba is loaded, and by kpec.py.
"""

from __future__ import annotations

import types as _pytypes

import llvmlite.binding as llvm
from numba import njit, types
from numba.extending import get_cython_function_address

from rigid_dynamics.contact import hertz as _source

for _name in ("ellipkm1", "ellipe"):
    llvm.add_symbol(f"wheelrail_scipy_{_name}", get_cython_function_address("scipy.special.cython_special", _name))

_SCOPE = dict(vars(_source))
_SCOPE["_ellipkm1"] = types.ExternalFunction("wheelrail_scipy_ellipkm1", types.float64(types.float64))
_SCOPE["_ellipe"] = types.ExternalFunction("wheelrail_scipy_ellipe", types.float64(types.float64))


def _compiled(function):
    """``function``'s code compiled (cached on disk) with its globals taken from ``_SCOPE``; enters ``_SCOPE``."""
    clone = _pytypes.FunctionType(function.__code__, _SCOPE, function.__name__, function.__defaults__)
    clone.__qualname__ = function.__qualname__
    clone.__doc__ = function.__doc__
    kernel = njit(cache=True)(clone)
    _SCOPE[function.__name__] = kernel
    return kernel


_kdbc = _compiled(_source._kdbc)
_shape = _compiled(_source._shape)
_kdbc_many = _compiled(_source._kdbc_many)
_shape_many = _compiled(_source._shape_many)
_hertz_many = _compiled(_source._hertz_many)
