"""Checks of a frozen dataclass's own fields (the scene's tables and the track's parameters call them from their
``__post_init__``); the checks that join several tables are in checks.py.
"""

from __future__ import annotations

import math
from dataclasses import fields


def check_finite(obj, *, positive=(), nonnegative=()) -> None:
    """Check that all float/int fields are finite, and the named ones > 0 or >= 0."""
    for f in fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            continue
        if not math.isfinite(value):
            raise ValueError(f"{f.name} = {value!r}: expected a finite number")
    for name in positive:
        value = getattr(obj, name)
        if not value > 0:
            raise ValueError(f"{name} = {value!r}: expected a number > 0")
    for name in nonnegative:
        value = getattr(obj, name)
        if not value >= 0:
            raise ValueError(f"{name} = {value!r}: expected a number >= 0")
