"""numba-compiled copies of the loops of kalker.py, linear.py and vermeulen_johnson.py (see lazy_kernels.py).

Imported by those modules for batches above ``lazy_kernels.PYTHON_BATCH_LIMIT`` or once numba is loaded, by
``linear.linear_one`` / ``vermeulen_johnson.saturate_one`` (the compiled dynamics loop's laws) and by kpec.py.
"""

from __future__ import annotations

from rigid_dynamics.contact import kalker, linear, vermeulen_johnson
from rigid_dynamics.contact.lazy_kernels import compiled_copies

_INLINE = {"_nrt": False, "inline": "always"}

_kalker = compiled_copies(kalker, ("_table_one", "_asymptote_one", "_coefficients_many", "_asymptotes_many"))
_table_one = _kalker["_table_one"]
_asymptote_one = _kalker["_asymptote_one"]
_coefficients_many = _kalker["_coefficients_many"]
_asymptotes_many = _kalker["_asymptotes_many"]

_linear = compiled_copies(linear, ("_linear_one", "_linear_many"), options={"_linear_one": _INLINE})
linear_one = _linear["_linear_one"]
_linear_many = _linear["_linear_many"]

_saturation = compiled_copies(
    vermeulen_johnson, ("_saturate_one", "_saturate_many"), options={"_saturate_one": _INLINE}
)
saturate_one = _saturation["_saturate_one"]
_saturate_many = _saturation["_saturate_many"]
