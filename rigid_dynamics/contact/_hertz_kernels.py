"""numba-compiled versions of the Hertz loops in rigid_dynamics/contact/hertz.py (one source, two paths).

hertz.py holds the loops as plain Python so that a command solving one patch need not import numba. This module
compiles the same functions' code with numba (lazy_kernels.compiled_copies); scipy's ``ellipkm1``/``ellipe`` are
called from compiled code through ``scipy.special.cython_special`` (registered as named external symbols so that the
kernels can be cached on disk). Imported by hertz.py for batches above ``lazy_kernels.PYTHON_BATCH_LIMIT`` or once
numba is loaded, and by kpec.py.
"""

from __future__ import annotations

import llvmlite.binding as llvm
from numba import types
from numba.extending import get_cython_function_address

from rigid_dynamics.contact import hertz as _source
from rigid_dynamics.contact.lazy_kernels import compiled_copies

for _name in ("ellipkm1", "ellipe"):
    llvm.add_symbol(f"wheelrail_scipy_{_name}", get_cython_function_address("scipy.special.cython_special", _name))

_COPIES = compiled_copies(
    _source,
    ("_kdbc", "_shape", "_kdbc_many", "_shape_many", "_hertz_many"),
    replacements={
        "_ellipkm1": types.ExternalFunction("wheelrail_scipy_ellipkm1", types.float64(types.float64)),
        "_ellipe": types.ExternalFunction("wheelrail_scipy_ellipe", types.float64(types.float64)),
    },
)
_kdbc = _COPIES["_kdbc"]
_shape = _COPIES["_shape"]
_kdbc_many = _COPIES["_kdbc_many"]
_shape_many = _COPIES["_shape_many"]
_hertz_many = _COPIES["_hertz_many"]
