"""JSON files of the comparisons, written through the one atomic writer (:mod:`rigid_dynamics.files`)."""

from __future__ import annotations

import json
import math
from pathlib import Path

from rigid_dynamics.files import write_text


def _clean(value):
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if hasattr(value, "item") and getattr(value, "ndim", 1) == 0:
        return _clean(value.item())
    if hasattr(value, "tolist"):
        return _clean(value.tolist())
    if isinstance(value, Path):
        return str(value)
    return value


def write_json_atomic(path: str | Path, data) -> Path:
    """JSON (non-finite numbers as null) written atomically."""
    return write_text(path, json.dumps(_clean(data), indent=2) + "\n")
