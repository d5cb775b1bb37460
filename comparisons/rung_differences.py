"""Why the rungs differ on one patch: each difference from the BEM above the tolerance, with a measured diagnosis.

The ellipse-based rungs (hertz, linear, vermeulen-johnson, fastsim, fastrip) solve the quadric of the contact
reference point, h = A x^2 + B y^2 - q, while the BEM solves the sampled undeformed distance of the same patch.
Two measurable causes explain most of their differences on a non-Hertzian patch:

* **Shape.** The sampled gap departs from the quadric; :func:`rigid_dynamics.contact.search.ellipticity_error`
  gives the largest departure over the overlap as a fraction of the approach. Max pressure and area follow it.
* **Where the creepages act.** The creepages are the rigid slip at the reference point (the deepest point); the
  rigid slip of spin varies across the patch, w = (xi - phi y, eta + phi x). When the BEM's pressure centroid
  (x_c, y_c) lies off that point, the patch as a whole sees the longitudinal creepage xi - phi y_c and the lateral
  eta + phi x_c: a longitudinal creep force from spin that an ellipse centred on the reference point cannot give.
  The rung is re-solved with the creepages taken at the centroid; how much of the difference that closes is
  reported, not assumed.

What neither cause closes is reported as not explained.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

ELLIPSE_RUNGS = ("hertz", "linear", "vermeulen-johnson", "fastsim", "fastrip")
TOLERANCE = 0.05  # relative (N, p max, area) and as a fraction of mu N (creep forces), as the report's headline


def _centroid(fields):
    """The pressure centroid (x_c, y_c) of a BEM field, m, or None."""
    if fields is None or fields.pressure_Pa is None:
        return None
    p = np.clip(np.nan_to_num(np.asarray(fields.pressure_Pa, float)), 0.0, None)
    total = p.sum()
    if total <= 0:
        return None
    xx, yy = np.meshgrid(np.asarray(fields.x_m, float), np.asarray(fields.y_m, float))
    return float((p * xx).sum() / total), float((p * yy).sum() / total)


def _differences(result, bem, mu: float) -> dict:
    """Relative differences from the BEM: N, p max, area (relative), Fx, Fy (fractions of mu N_BEM)."""
    out = {}
    for key in ("normal_force_N", "max_pressure_Pa", "contact_area_m2"):
        value, ref = getattr(result, key, None), getattr(bem, key, None)
        if value is not None and ref:
            out[key] = (value - ref) / abs(ref)
    bound = mu * (bem.normal_force_N or 0.0)
    for key in ("creep_force_long_N", "creep_force_lat_N"):
        value, ref = getattr(result, key, None), getattr(bem, key, None)
        if value is not None and ref is not None and bound > 0:
            out[key] = (value - ref) / bound
    return out


_LABELS = {
    "normal_force_N": "N",
    "max_pressure_Pa": "p max",
    "contact_area_m2": "area",
    "creep_force_long_N": "Fx",
    "creep_force_lat_N": "Fy",
}


def explain(solved: dict, material, options: dict | None = None, tolerance: float = TOLERANCE) -> list[str]:
    """One Markdown bullet per rung whose main patch differs from the BEM's by more than ``tolerance``.

    Args:
        solved: model -> entry with ``status`` and ``main`` = (side, geometry, creepage, ContactResult), as
            :func:`comparisons.compare.run_compare` holds them.
        material: the case's Material (its friction coefficient scales the creep-force differences).
        options: model -> solver options used (the re-solve at the centroid uses the same).
        tolerance: relative for N, p max and area; a fraction of mu N for the creep forces.

    Returns:
        Bullets (empty when the BEM has no patch or every rung is within the tolerance).
    """
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.search import ellipticity_error

    bem_entry = solved.get("bem", {})
    if bem_entry.get("status") != "ok" or bem_entry.get("main") is None or material is None:
        return []
    _, geometry, creepage, bem = bem_entry["main"]
    mu = float(material.friction_coefficient)
    centroid = _centroid(bem.fields)
    shape = None
    if geometry is not None and geometry.undeformed is not None:
        shape = ellipticity_error(
            geometry.undeformed, geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m,
            getattr(geometry, "ellipse_angle_rad", 0.0) or 0.0, geometry.approach_m,
        )  # fmt: skip
    bullets = []
    for model, entry in solved.items():
        if model in ("bem", "fea") or entry.get("status") != "ok" or entry.get("main") is None:
            continue
        result = entry["main"][3]
        diff = _differences(result, bem, mu)
        if model == "hertz":  # a normal-contact rung: its creep forces are not stated, not zero
            diff = {k: v for k, v in diff.items() if not k.startswith("creep")}
        above = {k: v for k, v in diff.items() if math.isfinite(v) and abs(v) > tolerance}
        if not above:
            continue
        listed = ", ".join(
            f"{_LABELS[k]} {100 * v:+.1f} %" + (" of mu N" if k.startswith("creep") else "") for k, v in above.items()
        )
        causes = []
        if model in ELLIPSE_RUNGS and shape is not None and math.isfinite(shape) and shape > 0:
            causes.append(
                f"the patch is not an ellipse (the sampled gap departs from the quadric at the reference point by "
                f"{100 * shape:.0f} % of the approach; {'elliptic' if geometry.is_elliptic else 'non-elliptic'} "
                "by the search's test), so the ellipse's max pressure and area are not the patch's"
            )
        creep_keys = [k for k in above if k.startswith("creep")]
        if creep_keys and model in ELLIPSE_RUNGS and centroid is not None and creepage is not None:
            x_c, y_c = centroid
            moved = replace(
                creepage,
                longitudinal=creepage.longitudinal - creepage.spin_1_per_m * y_c,
                lateral=creepage.lateral + creepage.spin_1_per_m * x_c,
            )
            try:
                again = get_model(model).solve(
                    geometry, moved, material, normal_force_N=result.normal_force_N,
                    options=(options or {}).get(model, {}),
                )  # fmt: skip
            except Exception as exc:  # the diagnosis must not break the report
                again = None
                causes.append(f"re-solve at the pressure centroid failed ({type(exc).__name__}: {exc})")
            if again is not None:
                after = _differences(again, bem, mu)
                left = {k: after.get(k, math.nan) for k in creep_keys}
                closed = all(math.isfinite(v) and abs(v) <= tolerance for v in left.values())
                causes.append(
                    f"the BEM's pressure centroid lies at x = {x_c * 1e3:.2f} mm, y = {y_c * 1e3:.2f} mm from the "
                    f"reference point, where spin {creepage.spin_1_per_m:.3g} 1/m gives the creepages "
                    f"xi - phi y_c = {moved.longitudinal:.3g}, eta + phi x_c = {moved.lateral:.3g} (at the point: "
                    f"{creepage.longitudinal:.3g}, {creepage.lateral:.3g}); {model} with those gives Fx "
                    f"{again.creep_force_long_N:.0f} N, Fy {again.creep_force_lat_N:.0f} N (BEM "
                    f"{bem.creep_force_long_N:.0f}, {bem.creep_force_lat_N:.0f} N): "
                    + ", ".join(f"{_LABELS[k]} {100 * v:+.1f} % of mu N" for k, v in left.items())
                    + (" left, within the tolerance: explained" if closed else " left: explained only in part")
                )
        if not causes:
            causes.append("not explained by the patch shape or by where the creepages act (no diagnosis measured)")
        bullets.append(f"- **{model}** differs from the BEM by {listed}: " + "; ".join(causes) + ".")
    return bullets
