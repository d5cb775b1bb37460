"""What a wheelset run states about each discretisation it depends on (summary.json ``discretisation_errors``):
the step (the run's force error estimate, drivers.force_error_check), the beam's modal cut-off (a measured rule,
:func:`modal_cutoff_error`), the contact grid and the geometry tables ("not estimated" where no estimate exists).

The modal cut-off rule. The beam keeps its flexural modes up to ``cutoff_frequency_Hz`` (track.py); a modal
truncation is invisible to the step's error estimate (it compares two integrators of the same truncated system).
Its error was measured on the ``wheel-flat`` scene (60 km/h, 50 mm rounded flat, RK4) at cut-offs 5/10/15/20 kHz
against the 20 kHz run (benchmarks/results/wheelflat_cutoff.md, bench_wheelflat_cutoff.py): the settled peaks of
the lateral creep force move 11.93 / 1.48 / 0.37 %, the longitudinal 3.04 / 2.52 / 0.70 %, the normal force
0.81 / 0.21 / 0.09 %. The lateral peak converges as f^-3.0 (5-10 kHz) to f^-3.4 (10-15 kHz); the longitudinal one
is not yet in its asymptotic range below 10 kHz (order 0.3 there, 3.2 above), so no single power law brackets the
table (f^-3 from 5 kHz gives 1.49 % lateral and 0.38 % longitudinal at 10 kHz against 1.48 % and 2.52 %
measured). The rule is therefore the measured table itself: per force component the measured difference plus the
reference's own error (the 15 kHz difference carried to 20 kHz with order 3), interpolated log-log between the
measured cut-offs and continued with order 3 outside them. The cut-off enters as a multiple of the impact's
frequency content, speed / flat length (333 Hz on the measured scene): a faster passage or a shorter flat excites
higher modes. That scaling is assumed, not measured (one speed and one flat length were measured): the rule is
calibrated on one scene and the statement says so. It applies to runs whose wheel flat reaches the rail; other
beam runs say "not estimated".
"""

from __future__ import annotations

import math

import numpy as np

MODAL_RULE_CUTOFFS_HZ = (5000.0, 10000.0, 15000.0)
"""The measured cut-offs of the rule (benchmarks/results/wheelflat_cutoff.md), Hz, at the measured impact frequency
:data:`MODAL_RULE_IMPACT_HZ`."""
MODAL_RULE_IMPACT_HZ = 16.6667 / 0.05
"""speed / flat length of the measured scene (60 km/h, 50 mm flat), Hz."""
MODAL_RULE_REFERENCE_HZ = 20000.0
MODAL_RULE_MEASURED = {
    "lateral_creep_force": (0.1193, 0.0148, 0.0037),
    "longitudinal_creep_force": (0.0304, 0.0252, 0.0070),
    "normal_force": (0.0081, 0.0021, 0.0009),
}
"""Per force component: the settled peak's relative difference to the 20 kHz run at MODAL_RULE_CUTOFFS_HZ (the
larger of the two wheels; they agree on the symmetric scene)."""
MODAL_RULE_ORDER = 3.0
"""The convergence order in the cut-off used outside the measured range and for the reference's own error: the
lateral peak's observed 3.0 (5-10 kHz); 3.4 between 10 and 15 kHz."""


def _rule_table() -> dict:
    """Per component the estimated error at each measured cut-off: the measured difference plus the reference's own
    error (the last measured difference carried to the reference cut-off with order MODAL_RULE_ORDER).
    """
    ratio = (MODAL_RULE_CUTOFFS_HZ[-1] / MODAL_RULE_REFERENCE_HZ) ** MODAL_RULE_ORDER
    return {k: tuple(v + ratio * m[-1] for v in m) for k, m in MODAL_RULE_MEASURED.items()}


def modal_rule_estimate(cutoff_Hz: float, impact_Hz: float = MODAL_RULE_IMPACT_HZ) -> dict:
    """The rule's relative error of each settled force peak at cut-off ``cutoff_Hz`` for an impact with frequency
    content ``impact_Hz`` (speed / flat length): {component: relative error}.
    """
    scaled = cutoff_Hz * MODAL_RULE_IMPACT_HZ / impact_Hz  # the cut-off as the measured scene would see it
    f = np.log(np.asarray(MODAL_RULE_CUTOFFS_HZ))
    out = {}
    for key, values in _rule_table().items():
        e = np.log(np.asarray(values))
        if scaled <= MODAL_RULE_CUTOFFS_HZ[0]:
            value = values[0] * (MODAL_RULE_CUTOFFS_HZ[0] / scaled) ** MODAL_RULE_ORDER
        elif scaled >= MODAL_RULE_CUTOFFS_HZ[-1]:
            value = values[-1] * (MODAL_RULE_CUTOFFS_HZ[-1] / scaled) ** MODAL_RULE_ORDER
        else:
            value = float(np.exp(np.interp(math.log(scaled), f, e)))
        out[key] = float(value)
    return out


def cutoff_meeting(tolerance: float, impact_Hz: float) -> float:
    """The smallest cut-off (Hz, to 100 Hz) at which the rule's largest component meets ``tolerance``."""
    lo, hi = 100.0, 1.0e6
    if max(modal_rule_estimate(hi, impact_Hz).values()) > tolerance:
        return math.inf
    while hi - lo > 100.0:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if max(modal_rule_estimate(mid, impact_Hz).values()) <= tolerance else (mid, hi)
    return math.ceil(hi / 100.0) * 100.0


def _first_flat_contact_m(scene) -> float:
    """Travel at which the flat's leading edge first reaches the rail, m (parameters.Irregularities.flat_angle_rad:
    the flat centre reaches it after r0 (pi/2 - alpha_d) of travel, modulo the circumference).
    """
    r0 = scene.wheelset.nominal_radius_m
    irr = scene.irregularities
    return (r0 * (0.5 * math.pi - irr.flat_angle_rad) - 0.5 * irr.flat_length_m) % (2.0 * math.pi * r0)


def modal_cutoff_error(scene) -> dict:
    """The statement of the beam's modal cut-off error for ``scene``: {"estimate": largest relative error of a
    settled force peak or None, "component", "per_component", "cutoff_frequency_Hz", "method"}.
    """
    track = scene.track_dynamics
    if track.model != "beam":
        return {"estimate": 0.0, "method": f"none: track model {track.model!r} has no modal truncation"}
    cutoff = float(track.cutoff_frequency_Hz)
    irr = scene.irregularities
    travel = float(scene.speed_m_per_s * scene.duration_s)
    base = {"cutoff_frequency_Hz": cutoff}
    if irr.flat_length_m <= 0:
        return {**base, "estimate": None, "method": "not estimated (the measured rule covers wheel-flat impacts)"}
    if travel < _first_flat_contact_m(scene):
        return {**base, "estimate": 0.0, "method": "none: the wheel flat does not reach the rail in this run"}
    impact = scene.speed_m_per_s / irr.flat_length_m
    per = modal_rule_estimate(cutoff, impact)
    worst = max(per, key=per.get)
    return {
        **base,
        "estimate": per[worst],
        "component": worst,
        "per_component": per,
        "impact_frequency_Hz": impact,
        "method": (
            "measured rule (rigid_dynamics/wheelset/discretisation.py): relative error of the settled force peaks "
            "against the cut-off, measured on wheel-flat at 5-20 kHz (benchmarks/results/wheelflat_cutoff.md), the "
            "cut-off scaled by speed / flat length; calibrated on one speed and flat length"
        ),
    }


def modal_cutoff_check(status: str, message: str, scene, tolerance: float) -> tuple[str, str]:
    """(status, message) with the modal cut-off judged: an "ok" run ends "warning" when the rule's estimate exceeds
    ``tolerance`` (force_tolerance), the message naming the cut-off and the cut-off that meets it.
    """
    stated = modal_cutoff_error(scene)
    estimate = stated["estimate"]
    if status != "ok" or estimate is None or estimate <= tolerance:
        return status, message
    need = cutoff_meeting(tolerance, stated["impact_frequency_Hz"])
    return "warning", (
        f"{message}; modal cut-off error estimate {estimate:.3g} of the settled {stated['component'].replace('_', ' ')}"
        f" peak at [track_dynamics] cutoff_frequency_Hz = {stated['cutoff_frequency_Hz']:g} exceeds force_tolerance "
        f"= {tolerance:g} (measured rule): a cut-off of {need:g} Hz meets it"
    )


def contact_grid_check(status: str, message: str, callback_stats) -> tuple[str, str]:
    """(status, message) with the BEM's grid judged: an "ok" run whose BEM patches were solved coarser than their
    ``grid_tolerance`` asks (the largest force estimate of a solve above it) ends "warning", naming the estimate.
    """
    grid = (callback_stats or {}).get("bem_grid_error")
    if status != "ok" or not grid or not grid["estimated"] or grid["largest_force"] <= grid["tolerance"]:
        return status, message
    return "warning", (
        f"{message}; BEM grid-error estimate of the patch forces {grid['largest_force']:.3g} (t = {grid['t_s']:.6g} s) "
        f"exceeds the BEM's grid_tolerance = {grid['tolerance']:g} (the loop solves a sampled patch on about "
        "BEM_ELEMENTS = 40 elements across its sampled box, rigid_dynamics/wheelset/callback.py, unrefined; an "
        "ellipse patch on the BEM's default grid refined at most max_refinements times)"
    )


def _contact_grid_error(result) -> dict:
    """The contact grid's statement: the BEM's own estimate of every solve in the loop (callback.PatchCallback
    keeps the largest), or "not estimated" for the other models.
    """
    grid = (result.callback_stats or {}).get("bem_grid_error")
    if not grid or not grid["estimated"]:
        return {"estimate": None, "method": f"not estimated ({result.contact_model})"}
    return {
        "estimate": grid["largest_force"],
        "relative_to": "each BEM patch's own normal and creep force (the creep force at least 0.01 mu F_N)",
        "method": (
            "the BEM's companion grids with elements 2x and 4x as large on every solve (rigid_dynamics.contact.bem."
            "model.grid_error_estimate), the largest over the run"
        ),
        "largest_all_quantities": grid["largest"],
        "at_t_s": grid["t_s"],
        "grid_tolerance": grid["tolerance"],
        "solves_estimated": grid["estimated"],
        "solves_above_grid_tolerance": grid["above_tolerance"],
        "solves_not_estimated": grid["not_estimated"],
    }


def discretisation_errors(result) -> dict:
    """Each discretisation the run depends on with its error estimate or "not estimated" (summary.json)."""
    scene = result.scene
    est = result.force_error_estimate
    if est is not None:
        settled = np.where(result.settled, est, np.nan) if len(est) else est
        value = float(np.nanmax(settled)) if len(est) and np.any(np.isfinite(settled)) else None
        step = {
            "estimate": value,
            "relative_to": "static wheel load",
            "method": "force_error_estimate: one step's contact forces against the embedded lower-order solution",
        }
    else:
        step = {"estimate": None, "method": "not estimated (scipy's step control; energy balance judged instead)"}
    out = {"step": step}
    if scene is None:
        return out
    modal = modal_cutoff_error(scene)
    if modal.get("per_component"):
        modal = {**modal, "relative_to": "the settled peak of each force"}
    out["modal_cutoff"] = modal
    out["contact_grid"] = _contact_grid_error(result)
    provider = result.provider
    out["geometry_tables"] = (
        {"estimate": None, "method": "not estimated (contact tables against the 3-D search)"}
        if "table" in str(provider)
        else {"estimate": None, "method": f"not estimated (provider {provider})"}
    )
    return out
