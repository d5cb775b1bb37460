"""The error a contact model states for its own result, read the same way for every rung.

A model that knows its discretisation error puts it in its :class:`ContactResult` as relative errors per quantity:
``extra["discretisation_error"]["relative_error"]`` (the FEA, fea.refinement: ``max_pressure``, ``contact_area``,
``normal_force``, ...), or an attribute ``discretisation_error`` of the result with the same layout (or the
relative errors themselves). A model that states none gives None: the reports then say that its error is not
stated, never 0.

Two models agree on a quantity when their difference is within the sum of their stated errors,
|v_a - v_b| <= (e_a + e_b) max(|v_a|, |v_b|) (:func:`agreement`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

QUANTITIES = ("normal_force", "max_pressure", "contact_area", "creep_force_long", "creep_force_lat")
"""The quantities the reports compare (keys of the relative errors)."""


def stated_errors(result) -> dict[str, float] | None:
    """{quantity: relative error} the model states for ``result`` (module docstring), or None."""
    info = getattr(result, "discretisation_error", None)
    if info is None:
        info = (getattr(result, "extra", None) or {}).get("discretisation_error")
    if not isinstance(info, Mapping):
        return None
    relative = info.get("relative_error", info)
    if not isinstance(relative, Mapping):
        return None
    out = {}
    for name in QUANTITIES:
        value = relative.get(name)
        if isinstance(value, (int, float)) and not isinstance(value, bool) and not math.isnan(value):
            out[name] = float(value)
    return out or None


def side_stated_errors(results) -> dict[str, float] | None:
    """Stated errors of the patches of one side, combined per quantity as the largest (None if any patch states
    none: a sum is only as known as its least known part).
    """
    per_patch = [stated_errors(r) for r in results]
    if not per_patch or any(e is None for e in per_patch):
        return None
    names = set.intersection(*(set(e) for e in per_patch))
    return {name: max(e[name] for e in per_patch) for name in QUANTITIES if name in names} or None


def largest(errors: Mapping | None, names=("normal_force", "max_pressure", "contact_area")) -> float | None:
    """The largest stated error over those of ``names`` that are stated (the headline), None when none is."""
    values = [errors[n] for n in names if errors and n in errors]
    return max(values) if values else None


def agreement(value_a: float, value_b: float, error_a: float | None, error_b: float | None) -> dict:
    """Whether two values agree within their stated errors (module docstring).

    Returns:
        {"difference": |a/b - 1| style relative difference (to the larger magnitude), "allowed": e_a + e_b or None,
        "agree": bool or None (None when an error is not stated)}.
    """
    scale = max(abs(value_a), abs(value_b))
    difference = abs(value_a - value_b) / scale if scale > 0 else 0.0
    if error_a is None or error_b is None:
        return {"difference": difference, "allowed": None, "agree": None}
    allowed = error_a + error_b
    return {"difference": difference, "allowed": allowed, "agree": difference <= allowed}
