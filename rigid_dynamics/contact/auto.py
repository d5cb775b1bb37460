"""``auto``'s patch features, its measured thresholds and the choice of rung.

Features of one patch (:func:`patch_features`, all dimensionless, 0 for a plain quadric patch without spin):

* ``saturation`` w' = T_lin / (3 mu N): the linear theory's creep force against the friction bound (seed eq 55);
  the linear theory has no slip, so its error grows with w' (1 - T_bar/T = w' - w'^2/3 for the cubic law);
* ``spin_share`` s = G (ab)^1.5 C23 |phi| / max(T_lin, mu N): the spin's linear lateral force against the force
  level of the patch (Vermeulen-Johnson treats spin only through that linear term);
* ``ellipticity_residual``: how far the sampled undeformed distance is from the quadric of the patch's curvatures,
  max |h - h_quadric| / q over the rigid overlap (:func:`rigid_dynamics.contact.search.ellipticity_error`), q the
  geometry's approach or, under force control (approach 0), Hertz's; 0 when the geometry has no sampled field;
* ``curvature_change``: how much the relative curvature changes across the patch: the local curvatures
  d2h/dx2 / 2 and d2h/dy2 / 2 of the sampled field (second differences) over the rigid overlap,
  (max - min) / A resp. B, the larger of the two; 0 without a sampled field;
* ``second_patch_nearness``: the lateral extent of the patch's rigid overlap divided by the clearance to another
  overlap region inside the patch's sampled box (the box reaches 30 % of the patch's extent beyond it, so only a
  near second patch is seen); 0 when the box holds one region or there is no sampled field.

Thresholds (:func:`derive_thresholds`): for each tolerance level (10, 5, 2, 1 %) and each rung (linear,
vermeulen-johnson, fastsim at each bench grid) the box {feature <= threshold} grown from the origin over the
measured cases where the rung met the tolerance, in increasing order of the rung's primary feature
(:data:`PRIMARY_FEATURE`), stopping before the box would hold a case where the rung missed it. The box holds only
measured successes; beyond them the rung is not used (the thresholds are the largest measured passing values,
not extrapolations). The stored thresholds (``data/auto_thresholds.json``) carry the identity of the bench runs
that produced them; ``benchmarks/derive_auto_thresholds.py`` regenerates them.

The choice (:func:`choose_rung`): the tolerance level is the largest stored level <= the tolerance (a tolerance
below the smallest level: no level, BEM); the first rung in cost order (linear, vermeulen-johnson, fastsim at the
run's grid) whose box holds the patch's features; BEM when none does. FASTSIM at a grid not on the bench uses the
thresholds of the finest bench grid with no more elements (none: FASTSIM is not a candidate).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np

FEATURES = ("saturation", "spin_share", "ellipticity_residual", "curvature_change", "second_patch_nearness")
"""Patch features, in the order of the dynamics' ``auto_deciding_feature`` codes."""
RUNG_MODELS = ("linear", "vermeulen-johnson", "fastsim")
"""The cheaper rungs auto may choose, in cost order (BEM is the fallback)."""
AUTO_RUNGS = ("linear", "vermeulen-johnson", "fastsim", "bem", "bem-corrected")
"""Codes of the dynamics' ``auto_rung`` field (index into this tuple); "bem-corrected": a patch auto gave to BEM
served in the loop by FASTSIM corrected by a stored BEM solution within its trust region
(rigid_dynamics/wheelset/auto_reuse.py)."""
PRIMARY_FEATURE = {"linear": "saturation", "vermeulen-johnson": "spin_share", "fastsim": "ellipticity_residual"}
"""The feature along which a rung's box is grown (the error mechanism the rung neglects)."""
LEVELS = (0.10, 0.05, 0.02, 0.01)
GEOMETRY_FLOOR = 1.0e-6
"""Ellipticity residuals and curvature changes below this are round-off of a sampled quadric: 0."""
THRESHOLDS_PATH = Path(__file__).parent / "data" / "auto_thresholds.json"


# ------------------------------------------------------------------------------------------------ features
def _local_curvature_change(field: np.ndarray, xs: np.ndarray, ys: np.ndarray, a: float, b: float) -> float:
    """(max - min) of d2h/dx2 / 2 over the overlap, / A; the same along y, / B; the larger (0 if undefined)."""
    over = np.isfinite(field) & (field < 0)
    out = 0.0
    for axis, spacing, ref in ((1, xs, a), (0, ys, b)):
        if len(spacing) < 3 or ref <= 0:
            continue
        d = float(spacing[1] - spacing[0])
        f = np.moveaxis(field, axis, 0)
        m = np.moveaxis(over, axis, 0)
        second = (f[2:] - 2.0 * f[1:-1] + f[:-2]) / (2.0 * d * d)
        inside = m[1:-1] & np.isfinite(second)
        if np.count_nonzero(inside) >= 2:
            vals = second[inside]
            out = max(out, float((vals.max() - vals.min()) / ref))
    return out


def _second_patch_nearness(field: np.ndarray, ys: np.ndarray) -> float:
    """Lateral overlap extent / clearance to another overlap region in the box (0 with one region)."""
    over = np.isfinite(field) & (field < 0)
    rows = np.flatnonzero(over.any(axis=1))  # overlap rows along y
    if len(rows) < 2:
        return 0.0
    breaks = np.flatnonzero(np.diff(rows) > 1)
    if len(breaks) == 0:
        return 0.0
    # runs of consecutive overlap rows: the widest is the patch, the nearest other run the neighbour
    starts = np.concatenate([[rows[0]], rows[breaks + 1]])
    stops = np.concatenate([rows[breaks], [rows[-1]]])
    widths = stops - starts
    main = int(np.argmax(widths))
    dy = float(ys[1] - ys[0])
    extent = (widths[main] + 1) * dy
    gaps = [
        (starts[k] - stops[main] - 1) * dy if k > main else (starts[main] - stops[k] - 1) * dy
        for k in range(len(starts))
        if k != main
    ]
    clearance = max(min(gaps), dy)
    return float(extent / clearance)


def patch_features(geometry, creepage, material, hertz) -> dict:
    """The features of one patch (module docstring) for its Hertz solution ``hertz`` (a HertzBatch of one patch).

    Returns:
        feature name -> float (inf for the saturation of a patch without friction bound).
    """
    from rigid_dynamics.contact.kalker import kalker_coefficients
    from rigid_dynamics.contact.linear import linear_creep_forces

    a, b = float(hertz.semi_axis_long_m), float(hertz.semi_axis_lat_m)
    coef = kalker_coefficients(a / b, material.poisson_ratio)
    tx, ty, _ = linear_creep_forces(
        a, b, creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m,
        shear_modulus_Pa=material.shear_modulus_Pa, poisson_ratio=material.poisson_ratio, coefficients=coef,
    )  # fmt: skip
    t_lin = math.hypot(float(tx), float(ty))
    mu_n = material.friction_coefficient * float(hertz.normal_force_N)
    saturation = t_lin / (3.0 * mu_n) if mu_n > 0 else math.inf
    spin_force = material.shear_modulus_Pa * (a * b) ** 1.5 * float(coef.c23) * abs(creepage.spin_1_per_m)
    level = max(t_lin, mu_n)
    features = {
        "saturation": saturation,
        "spin_share": spin_force / level if level > 0 else 0.0,
        "ellipticity_residual": 0.0,
        "curvature_change": 0.0,
        "second_patch_nearness": 0.0,
    }
    und = geometry.undeformed
    if und is not None:
        from rigid_dynamics.contact.search import ellipticity_error
        from rigid_dynamics.contact.types import UndeformedDistance

        # the sampled field is h - q at the geometry's approach; under force control (approach 0) use Hertz's q
        q = geometry.approach_m if geometry.approach_m > 0 else float(hertz.approach_m)
        field = np.asarray(und.distance_m, float) + (geometry.approach_m - q)
        xs, ys = np.asarray(und.x_m, float), np.asarray(und.y_m, float)
        features["ellipticity_residual"] = ellipticity_error(
            UndeformedDistance(xs, ys, field),
            geometry.curvature_long_1_per_m,
            geometry.curvature_lat_1_per_m,
            geometry.ellipse_angle_rad,
            q,
        )
        features["curvature_change"] = _local_curvature_change(
            field, xs, ys, geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m
        )
        features["second_patch_nearness"] = _second_patch_nearness(field, ys)
        for name in ("ellipticity_residual", "curvature_change"):
            if features[name] < GEOMETRY_FLOOR:
                features[name] = 0.0  # round-off of a sampled quadric
    return features


def batch_features(a, b, normal_N, xi, eta, phi, material, coefficients) -> dict:
    """Saturation and spin share of many quadric patches (arrays); the geometric features are 0 (no sampled field)."""
    from rigid_dynamics.contact.linear import linear_creep_forces

    tx, ty, _ = linear_creep_forces(
        a, b, xi, eta, phi, shear_modulus_Pa=material.shear_modulus_Pa, poisson_ratio=material.poisson_ratio,
        coefficients=coefficients,
    )  # fmt: skip
    t_lin = np.hypot(tx, ty)
    mu_n = material.friction_coefficient * np.asarray(normal_N, float)
    level = np.maximum(t_lin, mu_n)
    with np.errstate(divide="ignore", invalid="ignore"):
        sat = np.where(mu_n > 0, t_lin / (3.0 * mu_n), np.inf)
        share = material.shear_modulus_Pa * (a * b) ** 1.5 * coefficients.c23 * np.abs(phi) / level
    zero = np.zeros(np.shape(sat))
    return {
        "saturation": sat,
        "spin_share": np.where(level > 0, np.nan_to_num(share), 0.0),
        "ellipticity_residual": zero,
        "curvature_change": zero,
        "second_patch_nearness": zero,
    }


# ------------------------------------------------------------------------------------------------ derivation
def rung_label(model: str, resolution: str) -> str:
    """``linear``, ``vermeulen-johnson``, ``fastsim 20x20`` (the bench's model and resolution)."""
    return model if resolution in ("", "-") else f"{model} {resolution}"


def _box_of(points: list[dict]) -> dict:
    return {f: max(p[f] for p in points) for f in FEATURES}


ROUND_OFF = 1.0e-9
"""Relative slack of the derivation's conflict test: a missed case whose features equal a box corner to round-off
(e.g. a sweep point's spin share 0.3 and another's 0.29999999999999993) is inside the box."""


def _inside(point: dict, box: dict) -> bool:
    return all(point[f] <= box[f] * (1.0 + ROUND_OFF) + 1e-15 for f in FEATURES)


def derive_thresholds(rows: Iterable[Mapping], features: Mapping[str, Mapping], levels=LEVELS) -> dict:
    """Per tolerance level and rung the measured feature box where the rung met the tolerance (module docstring).

    Args:
        rows: bench rows (``comparisons.bench`` CSV columns: case, model, resolution, status, error); rows of other
            models (hertz, bem, fea) are ignored. A row with status other than "ok" or no error counts as a miss.
        features: case -> feature name -> value (cases without features are skipped).
        levels: tolerance levels.

    Returns:
        {"levels": {"0.05": {rung: {"thresholds": {feature: value} | None, "cases_met": [...],
        "cases_missed": [...], "limited_by": case or None}}}}.
    """
    measured: dict[str, list[tuple[str, float | None]]] = {}
    for row in rows:
        if row["model"] not in RUNG_MODELS or row["case"] not in features:
            continue
        err = row.get("error")
        err = None if err in (None, "") else float(err)
        if row.get("status") != "ok" or (err is not None and not math.isfinite(err)):
            err = None
        measured.setdefault(rung_label(row["model"], row["resolution"]), []).append((row["case"], err))
    out: dict = {"levels": {}}
    for level in levels:
        per_rung = {}
        for rung, results in sorted(measured.items()):
            model = rung.split(" ")[0]
            primary = PRIMARY_FEATURE[model]
            met = [c for c, e in results if e is not None and e <= level]
            missed = [c for c, e in results if c not in met]
            # grow along the primary feature; ties (e.g. the quadric cases' ellipticity 0) by the largest other
            # feature relative to its range over the cases
            span = {
                f: max([features[c][f] for c in features if math.isfinite(features[c][f])] + [0.0]) for f in FEATURES
            }
            met.sort(
                key=lambda c: (
                    features[c][primary],
                    max((features[c][f] / span[f] if span[f] > 0 else 0.0) for f in FEATURES if f != primary),
                    c,
                )
            )
            chosen: list[str] = []
            limited_by = None
            for case in met:
                box = _box_of([features[c] for c in (*chosen, case)])
                inside = [m for m in missed if _inside(features[m], box)]
                if inside:
                    limited_by = sorted(inside)[0]
                    break
                chosen.append(case)
            per_rung[rung] = {
                "thresholds": _box_of([features[c] for c in chosen]) if chosen else None,
                "cases_met": sorted(met),
                "cases_missed": sorted(missed),
                "cases_in_box": sorted(chosen),
                "limited_by": limited_by,
            }
        out["levels"][f"{level:g}"] = per_rung
    return out


# ------------------------------------------------------------------------------------------------ the choice
_CACHE: dict = {}


def load_thresholds(path: str | Path | None = None) -> dict:
    """The stored thresholds (``data/auto_thresholds.json`` unless ``path``), cached per path."""
    path = Path(path) if path is not None else THRESHOLDS_PATH
    key = str(path)
    if key not in _CACHE:
        with open(path, encoding="utf-8") as handle:
            _CACHE[key] = json.load(handle)
    return _CACHE[key]


def level_for(tolerance: float, data: Mapping) -> str | None:
    """The largest stored level <= tolerance (as its key), or None when the tolerance is below every level."""
    levels = sorted((float(k), k) for k in data["levels"])
    best = None
    for value, key in levels:
        if value <= tolerance * (1.0 + 1e-12):
            best = key
    return best


def fastsim_rung(nx: int, ny: int, level: Mapping) -> str | None:
    """The fastsim rung whose thresholds serve an nx x ny grid: the same grid, else the finest with fewer elements."""
    exact = f"fastsim {nx}x{ny}"
    if exact in level:
        return exact
    best, best_n = None, -1
    for rung in level:
        if not rung.startswith("fastsim "):
            continue
        gx, gy = (int(v) for v in rung.split(" ")[1].split("x"))
        if gx <= nx and gy <= ny and gx * gy > best_n:
            best, best_n = rung, gx * gy
    return best


def choose_rung(features: Mapping, tolerance: float, *, fastsim_grid=(20, 20), data: Mapping | None = None) -> dict:
    """The rung for a patch: {"model", "rung", "level", "reason", "deciding_feature", "deciding_threshold",
    "rejected": {rung: reason}} (module docstring).
    """
    data = data if data is not None else load_thresholds()
    key = level_for(tolerance, data)
    if key is None:
        lowest = min(float(k) for k in data["levels"])
        return {
            "model": "bem",
            "rung": "bem",
            "level": None,
            "reason": f"tolerance {tolerance:g} is below the smallest measured level {lowest:g}: bem",
            "deciding_feature": None,
            "deciding_threshold": None,
            "rejected": {},
        }
    level = data["levels"][key]
    candidates = [("linear", "linear"), ("vermeulen-johnson", "vermeulen-johnson")]
    fs = fastsim_rung(int(fastsim_grid[0]), int(fastsim_grid[1]), level)
    if fs is not None:
        candidates.append(("fastsim", fs))
    rejected: dict = {}
    last_reject = (None, None)
    for model, rung in candidates:
        entry = level.get(rung)
        box = None if entry is None else entry["thresholds"]
        if box is None:
            rejected[rung] = f"no measured case within {float(key):.0%}"
            continue
        over = [(f, features[f], box[f]) for f in FEATURES if not features[f] <= box[f]]
        if over:
            # the feature furthest beyond its threshold decided the rejection
            f, v, t = max(over, key=lambda o: o[1] / o[2] if o[2] > 0 else math.inf)
            rejected[rung] = f"{f} {v:.3g} > {t:.3g}"
            last_reject = (f, t)
            continue
        if last_reject[0] is None:
            # the cheapest candidate qualified: the binding feature is the one closest to its threshold
            f = max(FEATURES, key=lambda n: features[n] / box[n] if box[n] > 0 else (0.0 if features[n] <= 0 else 1.0))
            decided = (f, box[f])
        else:
            decided = last_reject
        why = ", ".join(f"{n} {features[n]:.3g} <= {box[n]:.3g}" for n in FEATURES if box[n] > 0 or features[n] > 0)
        prefix = "; ".join(f"{r} rejected: {w}" for r, w in rejected.items())
        return {
            "model": model,
            "rung": rung,
            "level": float(key),
            "reason": (prefix + "; " if prefix else "") + f"{rung} within {float(key):.0%} measured for {why}",
            "deciding_feature": decided[0],
            "deciding_threshold": decided[1],
            "rejected": rejected,
        }
    prefix = "; ".join(f"{r} rejected: {w}" for r, w in rejected.items())
    return {
        "model": "bem",
        "rung": "bem",
        "level": float(key),
        "reason": f"{prefix}; no cheaper rung measured within {float(key):.0%} for these features: bem",
        "deciding_feature": last_reject[0],
        "deciding_threshold": last_reject[1],
        "rejected": rejected,
    }
