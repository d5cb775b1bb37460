"""What a wheelset run states about each discretisation it depends on (summary.json ``discretisation_errors``):
the step (the run's force error estimate, drivers.force_error_check), the beam's modal cut-off (a measured rule,
:func:`modal_cutoff_error`), the contact grid (:func:`contact_grid_error`, a coarser companion evaluation) and the
geometry tables (:func:`geometry_error`, the 3-D search as companion); "not estimated" where no estimate exists.

The contact grid companion. FASTSIM's grid error is estimated on a sample of the run's recorded settled patches
(their semi-axes, normal force and creepages): FASTSIM at the run's grid and at half of it in each direction, the
difference extrapolated with the observed order GRID_ORDER (1.5: the lowest order measured along the strips at half
saturation, benchmarks/results/fastsim_grid.md; n^-2 in the linear range, so the estimate is on the safe side
there), relative to the static wheel load. Laws without a grid (linear, Vermeulen-Johnson, Hertz) say "no grid": their
model error is judged by auto, not here.

The geometry companion. A run on the contact tables is compared with the 3-D search at a sample of its recorded
settled states: the per-wheel contact forces (main frame) of the same contact law at the same state, the largest
difference relative to the static wheel load. It compares the forces at a given state; the run on the search would
settle to a slightly different state, so only the lateral force is judged: at a fixed state the vertical and the
longitudinal forces carry offsets that the run absorbs (a micrometre of height moves the normal force by about 1 %, a
rolling-radius difference the longitudinal creepage; the wheelset's height, spin and yaw settle them). Measured on
``curve`` (6 s, 40 settled states): same-state differences 2.6 % (vertical), 1.8 % (longitudinal), 0.06 % (lateral)
of the static wheel load, against 0.03 %, 0.01 % and 0.12 % between the settled peaks of a run on the tables and one
on the search (benchmarks/results/scene_defaults_error.md). The lateral statement is therefore of the right size but
not an upper bound (there 2x low); all three are stated (``per_component``).

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
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

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
    ``tolerance`` (force_tolerance), the message naming the cut-off and the cut-off that meets it; a run already
    warned names it too (as every check here: one warning does not hide another).
    """
    stated = modal_cutoff_error(scene)
    estimate = stated["estimate"]
    if status not in ("ok", "warning") or estimate is None or estimate <= tolerance:
        return status, message
    need = cutoff_meeting(tolerance, stated["impact_frequency_Hz"])
    return "warning", (
        f"{message}; modal cut-off error estimate {estimate:.3g} of the settled {stated['component'].replace('_', ' ')}"
        f" peak at [track_dynamics] cutoff_frequency_Hz = {stated['cutoff_frequency_Hz']:g} exceeds force_tolerance "
        f"= {tolerance:g} (measured rule): a cut-off of {need:g} Hz meets it"
    )


def callback_grid_error(callback_stats, default_model: str = "the contact model") -> tuple[dict | None, str]:
    """(the run's grid-error record, whose it is) from the callback's stats (callback.PatchCallback.stats): the
    BEM's ``bem_grid_error`` ("BEM"), another model's ``grid_error`` (its name), or (None, ``default_model``).
    """
    stats = callback_stats or {}
    if stats.get("bem_grid_error"):
        return stats["bem_grid_error"], "BEM"
    return stats.get("grid_error"), stats.get("model", default_model)


def contact_grid_check(status: str, message: str, callback_stats) -> tuple[str, str]:
    """(status, message) with the BEM's grid judged: an "ok" run whose BEM patches were solved coarser than their
    ``grid_tolerance`` asks (the largest force estimate of a solve above it) ends "warning", naming the estimate; a
    run already warned names it too.
    """
    grid, name = callback_grid_error(callback_stats)
    if (
        status not in ("ok", "warning")
        or not grid
        or not grid["estimated"]
        or grid["largest_force"] <= grid["tolerance"]
    ):
        return status, message
    if name != "BEM":
        return "warning", (
            f"{message}; {name}'s grid-error estimate of the patch forces "
            f"{grid['largest_force']:.3g} (t = {grid['t_s']:.6g} s) exceeds its grid_tolerance = {grid['tolerance']:g}"
        )
    return "warning", (
        f"{message}; BEM grid-error estimate of the patch forces {grid['largest_force']:.3g} (t = {grid['t_s']:.6g} s) "
        f"exceeds the BEM's grid_tolerance = {grid['tolerance']:g} (the loop solves a sampled patch on about "
        "BEM_ELEMENTS = 40 elements across its sampled box, rigid_dynamics/wheelset/callback.py, unrefined; an "
        "ellipse patch on the BEM's default grid refined at most max_refinements times; on the sampled patches of "
        "curve-flange, polygonal-wheel and wheel-flat this estimate was 2-15 times the difference from an 80 x 80 grid "
        "at the same states, benchmarks/results/patch_geometry.md)"
    )


def auto_reuse_check(status: str, message: str, callback_stats) -> tuple[str, str]:
    """(status, message) with ``auto``'s reuse of its BEM patches judged (wheelset/auto_reuse.py): an "ok" run ends
    "warning" when a correction measured at a re-solve departed from the fresh BEM solution by more than the
    tolerance (the patches served between re-solves are not measured; those near such a re-solve may be as far off);
    a run already warned names it too.
    """
    reuse = (callback_stats or {}).get("auto_reuse")
    if status not in ("ok", "warning") or not reuse or not reuse.get("errors_above_tolerance"):
        return status, message
    return "warning", (
        f"{message}; auto's reused BEM patches: {reuse['errors_above_tolerance']} of {reuse['errors_measured']} "
        f"measured corrections departed from the fresh BEM solution by more than contact_tolerance = "
        f"{reuse['tolerance']:g} (largest: creep force {reuse['max_creep_force_error']:.3g} at t = "
        f"{reuse['max_creep_force_error_t_s']:.6g} s, normal force {reuse['max_normal_force_error']:.3g}); "
        "auto_reuse = false solves every such patch"
    )


def auto_geometry(result, fastsim_grid) -> dict | None:
    """How far ``auto``'s patches served on Hertz's ellipse depart from it: None for other models. With the 3-D
    search and ``patch_geometry = "sampled"`` the compiled loop samples each patch's gap (compiled_patch.
    sample_candidates) and auto decides on its geometric features too, so this check finds no patch outside its
    rung's box unless the decision and the thresholds disagree (it stays as the run's guard); on the tables or with
    ``patch_geometry = "ellipse"`` the geometric features are 0 and nothing is seen. A recorded patch served by
    linear theory, Vermeulen-Johnson or FASTSIM whose
    residual exceeds that rung's measured box at the run's level (contact/data/auto_thresholds.json; the boxes come
    from the bench's cases, and a box of 0 means no measured case beyond the ellipse) is outside what the thresholds
    were measured on: its error against the BEM on the sampled gap is not known. Returns the counts, the largest
    residual and whether the geometry was seen (``seen`` False on the tables or with ``patch_geometry =
    "ellipse"``: nothing sampled).
    """
    from rigid_dynamics.wheelset.compiled_laws import auto_boxes
    from rigid_dynamics.wheelset.layout import AUTO_BEM

    p = result.patches
    if result.contact_model != "auto" or "auto_rung" not in p or not len(result.t):
        return None
    rung = np.asarray(p["auto_rung"], float)
    residual = np.asarray(p["ellipticity_residual"], float)
    served = np.isfinite(rung) & (np.nan_to_num(np.asarray(p["normal_force_N"], float)) > 0) & (rung < AUTO_BEM)
    seen = served & np.isfinite(residual)
    out = {"served_on_ellipse": int(served.sum()), "seen": bool(seen.any()), "checked": int(seen.sum()),
           "outside_box": 0, "largest_residual": None, "largest_outside_t_s": None}  # fmt: skip
    if not seen.any():
        return out
    out["largest_residual"] = float(residual[seen].max())
    key, boxes = auto_boxes(result.scene.contact_tolerance, fastsim_grid)
    limit = np.full(rung.shape, np.inf)
    for i, (_, box) in enumerate(boxes):
        if box is not None:
            limit[seen & (rung == i)] = box["ellipticity_residual"]
    outside = seen & (residual > limit)
    out["outside_box"] = int(outside.sum())
    out["level"] = None if key is None else float(key)
    if outside.any():
        k = np.argwhere(outside)
        worst = k[int(np.argmax(residual[outside]))]
        out["largest_outside"] = float(residual[tuple(worst)])
        out["largest_outside_t_s"] = float(result.t[worst[0]])
    return out


def auto_geometry_check(status: str, message: str, geometry: dict | None) -> tuple[str, str]:
    """(status, message) with :func:`auto_geometry` judged: an "ok" run of ``auto`` that served recorded patches on
    the ellipse outside their rung's measured ellipticity box ends "warning", naming how many and the largest; a run
    already warned names it too.
    """
    if status not in ("ok", "warning") or not geometry or not geometry["outside_box"]:
        return status, message
    return "warning", (
        f"{message}; auto served {geometry['outside_box']} of {geometry['checked']} recorded patches on Hertz's "
        f"ellipse whose sampled gap departs from it beyond the rung's measured box (ellipticity residual up to "
        f"{geometry['largest_outside']:.3g} at t = {geometry['largest_outside_t_s']:.6g} s; auto decides on the "
        'ellipse in the loop): their error against the BEM on the sampled gap is not known (contact_model "bem" '
        "solves the sampled patches)"
    )


def _contact_grid_error(result) -> dict:
    """The contact grid's statement: the BEM's own estimate of every solve in the loop (callback.PatchCallback
    keeps the largest), or "not estimated" for the other models.
    """
    grid, name = callback_grid_error(result.callback_stats, result.contact_model)
    if not grid or not grid["estimated"]:
        return {"estimate": None, "method": f"not estimated ({result.contact_model})"}
    return {
        "estimate": grid["largest_force"],
        "relative_to": f"each {name} patch's own normal and creep force (the creep force at least 0.01 mu F_N)",
        "method": (
            "the BEM's companion grids with elements 2x and 4x as large on every solve (rigid_dynamics.contact.bem."
            "model.grid_error_estimate), the largest over the run"
            if name == "BEM"
            else f"{name}'s own estimate of every solve (its result's grid_error: companion grids with elements 2x "
            "and 4x as large), the largest over the run"
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
        step = (result.companion_errors or {}).get("step") or {
            "estimate": None,
            "method": "not estimated (scipy's step control; energy balance judged instead)",
        }
    out = {"step": step}
    if scene is None:
        return out
    modal = modal_cutoff_error(scene)
    if modal.get("per_component"):
        modal = {**modal, "relative_to": "the settled peak of each force"}
    out["modal_cutoff"] = modal
    companions = result.companion_errors or {}
    bem = _contact_grid_error(result)  # the BEM's own estimate of its solves in the loop
    fastsim = companions.get("contact_grid")  # FASTSIM's coarser companion (auto may use both)
    if bem["estimate"] is None:
        out["contact_grid"] = fastsim or bem
    elif fastsim and fastsim.get("estimate") is not None and fastsim["estimate"] > bem["estimate"]:
        out["contact_grid"] = {**fastsim, "bem": bem}
    else:
        out["contact_grid"] = {**bem, **({"fastsim": fastsim} if fastsim else {})}
    out["geometry_tables"] = companions.get("geometry_tables") or {"estimate": None, "method": "not estimated"}
    return out


GRID_ORDER = 1.5
"""Observed convergence order of FASTSIM's creep forces in the element size (benchmarks/results/fastsim_grid.md:
1.5 along strips at half saturation, 2 across strips and in the linear range): the lower one, so the extrapolated
estimate errs high."""
GRID_SAMPLES = 400
"""At most this many recorded settled patches are re-evaluated by the grid companion (evenly spaced)."""
GEOMETRY_SAMPLES = 40
"""At most this many recorded settled states are re-evaluated by the geometry companion (evenly spaced)."""
NO_GRID_LAWS = ("linear", "vermeulen-johnson", "hertz")
_SEARCH_PROVIDERS: dict = {}


def _settled_indices(result, limit: int) -> np.ndarray:
    k = np.flatnonzero(result.settled) if len(result.t) else np.zeros(0, int)
    if len(k) > limit:
        k = k[np.linspace(0, len(k) - 1, limit).round().astype(int)]
    return k


def contact_grid_error(result) -> dict:
    """The statement of the contact law's grid error (module docstring): {"estimate", "method", ...}."""
    scene, law = result.scene, result.contact_model
    if law in NO_GRID_LAWS:
        return {"estimate": None, "method": f"no grid ({law}: its model error is the auto model's business)"}
    if law not in ("fastsim", "auto", "table"):
        return {"estimate": None, "method": f"not estimated ({law})"}
    from rigid_dynamics.contact.fastsim import fastsim_batch
    from rigid_dynamics.wheelset.compiled_laws import LAW_FASTSIM, LAW_TABLE

    nx, ny = int(scene.fastsim_elements_per_strip), int(scene.fastsim_strips)
    cx, cy = max(1, nx // 2), max(1, ny // 2)
    base = {"grid": [nx, ny], "companion_grid": [cx, cy], "relative_to": "static wheel load"}
    p = result.patches
    k = _settled_indices(result, len(result.t))
    normal = p["normal_force_N"][k]
    use = np.isfinite(normal) & (normal > 0)
    if law == "auto":
        use &= (p["contact_law_code"][k] == LAW_FASTSIM) | (p["contact_law_code"][k] == LAW_TABLE)
    names = ("semi_axis_long_m", "semi_axis_lat_m", "normal_force_N", "creepage_long", "creepage_lat")
    names += ("spin_creepage_1_per_m",)
    values = [p[n][k][use] for n in names]
    if not len(values[0]):
        return {**base, "estimate": 0.0, "method": "none: no settled patch was solved by FASTSIM"}
    take = np.linspace(0, len(values[0]) - 1, min(GRID_SAMPLES, len(values[0]))).round().astype(int)
    values = [v[take] for v in values]
    mat = scene.material
    kw = dict(shear_modulus_Pa=mat.shear_modulus_Pa, poisson_ratio=mat.poisson_ratio)
    kw["friction_coefficient"] = mat.friction_coefficient
    fine = fastsim_batch(*values, nx=nx, ny=ny, **kw)
    coarse = fastsim_batch(*values, nx=cx, ny=cy, **kw)
    load = scene.static_wheel_load_N
    ratio = math.sqrt(nx * ny / (cx * cy))
    if ratio <= 1.0:
        return {**base, "estimate": None, "method": "not estimated (a 1 x 1 grid has no coarser companion)"}
    factor = 1.0 / (ratio**GRID_ORDER - 1.0)
    per = {}
    for name, f, c in (
        ("creep_force_long", fine.creep_force_long_N, coarse.creep_force_long_N),
        ("creep_force_lat", fine.creep_force_lat_N, coarse.creep_force_lat_N),
    ):
        per[name] = float(np.max(np.abs(f - c)) * factor / load)
    recorded = max(
        float(np.max(np.abs(fine.creep_force_long_N - p["creep_force_long_N"][k][use][take]))),
        float(np.max(np.abs(fine.creep_force_lat_N - p["creep_force_lat_N"][k][use][take]))),
    )
    if law == "table" or np.any(p["contact_law_code"][k][use][take] == LAW_TABLE):
        # the recorded forces are the table's: FASTSIM at the run's grid on the same patches is its source
        # and the table's departure from it adds to FASTSIM's grid error
        base["table_departure"] = recorded / load
    return {
        **base,
        "estimate": max(per.values()) + base.get("table_departure", 0.0),
        "per_component": per,
        "samples": len(take),
        "companion_vs_run": recorded / load,
        "method": (
            f"coarser companion: FASTSIM at {cx} x {cy} against {nx} x {ny} on {len(take)} recorded settled patches, "
            f"extrapolated with order {GRID_ORDER:g} (benchmarks/results/fastsim_grid.md)"
            + (
                "; plus table_departure: the creep-force table's forces against FASTSIM at the run's grid on the same "
                "patches (contact.creep_table)"
                if "table_departure" in base
                else ""
            )
        ),
    }


class Companions(NamedTuple):
    """What the companions need from the run (simulate.py builds it; this module does not import simulate).

    Attributes:
        provider: the run's contact-geometry provider.
        model_for: provider -> a WheelsetModel of the run's scene and contact law on that provider (compiled
            geometry).
        rerun: scene -> the SimulationResult of that scene with the run's provider and law, without companions.
    """

    provider: object
    model_for: Callable
    rerun: Callable


def geometry_error(result, companions: Companions) -> dict:
    """The statement of the geometry tables' error against the 3-D search (module docstring)."""
    if "table" not in str(result.provider):
        return {"estimate": None, "method": f"none: provider {result.provider} (no tables)"}
    scene = result.scene
    k = _settled_indices(result, GEOMETRY_SAMPLES)
    if not len(k):
        return {"estimate": None, "method": "not estimated (no settled sample)"}
    from rigid_dynamics.wheelset.providers import SearchProvider
    from rigid_dynamics.wheelset.wheelset_model import ContactFailure

    try:
        if scene.irregularities.joint_dip_angle_rad > 0:
            return {"estimate": None, "method": "not estimated (the 3-D search does not serve this geometry)"}
        tables = companions.model_for(companions.provider)
        key = (scene.wheelset, scene.track, scene.irregularities)
        if key not in _SEARCH_PROVIDERS:  # its surfaces cost about 0.5 s: kept for further runs in the process
            _SEARCH_PROVIDERS.clear()
            _SEARCH_PROVIDERS[key] = SearchProvider(*key)
        search = companions.model_for(_SEARCH_PROVIDERS[key])
        diff = np.zeros(3)
        for i in k:
            track = result.track_full_states[i] if result.track_full_states is not None else None
            forces = []
            for model in (tables, search):
                c = model.contact(result.states[i], track=track)
                f = np.zeros((2, 3))
                np.add.at(f, c.side, c.force_N)
                forces.append(f)
            diff = np.maximum(diff, np.max(np.abs(forces[0] - forces[1]), axis=0))
    except (ValueError, ContactFailure) as exc:
        return {"estimate": None, "method": f"not estimated (the 3-D search companion failed: {exc})"}
    diff = diff / scene.static_wheel_load_N
    per = dict(zip(("longitudinal", "lateral", "vertical"), (float(v) for v in diff), strict=True))
    return {
        "estimate": per["lateral"],
        "judged": "lateral (the vertical and longitudinal differences at a fixed state are absorbed by the run)",
        "per_component": per,
        "samples": len(k),
        "relative_to": "static wheel load",
        "method": (
            f"companion: the per-wheel contact forces (main frame) on the tables against the 3-D search at {len(k)} "
            "recorded settled states, the largest lateral difference (forces at the same state, not two runs' peaks; "
            "measured 2x below the difference of the settled Y peaks on curve)"
        ),
    }


SCIPY_COMPANION_FACTOR = 10.0
"""The scipy methods' step companion runs at this multiple of both tolerances."""


def scipy_step_error(result, companions: Companions) -> dict:
    """The step error of a run by scipy's adaptive methods (no per-step force estimate): a companion run at
    SCIPY_COMPANION_FACTOR times both tolerances (about 0.6x the run's steps for RK45), the largest difference of the
    per-wheel contact forces at the settled output samples divided by (factor - 1) (the global error taken
    proportional to the tolerance), relative to the static wheel load.
    """
    scene = result.scene
    integ = scene.integrator
    f = SCIPY_COMPANION_FACTOR
    loose = replace(
        integ, relative_tolerance=integ.relative_tolerance * f, absolute_tolerance=integ.absolute_tolerance * f
    )
    companion = companions.rerun(replace(scene, integrator=loose))
    n = min(len(companion.t), len(result.t))
    if companion.status not in ("ok", "warning") or n == 0 or not np.allclose(companion.t[:n], result.t[:n]):
        return {
            "estimate": None,
            "method": f"not estimated (the companion at {f:g}x the tolerances: {companion.status})",
        }
    settled = result.settled[:n]
    diff = np.abs(companion.contact_force_N[:n] - result.contact_force_N[:n])[settled]
    value = float(np.max(diff)) / (f - 1.0) / scene.static_wheel_load_N if len(diff) else 0.0
    return {
        "estimate": value,
        "relative_to": "static wheel load",
        "method": (
            f"companion run at {f:g}x relative_tolerance and absolute_tolerance: the largest difference of the "
            f"per-wheel contact forces at the settled samples / {f - 1:g}"
        ),
    }


def companion_errors(result, companions: Companions) -> dict:
    """The companions' statements of a finished run: {"contact_grid": ..., "geometry_tables": ...} and, for scipy's
    methods, {"step": ...}.
    """
    if result.scene is None or not len(result.t):
        return {}
    out = {"contact_grid": contact_grid_error(result), "geometry_tables": geometry_error(result, companions)}
    if result.force_error_estimate is None and result.status in ("ok", "warning"):
        out["step"] = scipy_step_error(result, companions)
    return out


def companion_check(status: str, message: str, errors: dict, tolerance: float) -> tuple[str, str]:
    """(status, message): an "ok" run ends "warning" when a companion's estimate exceeds ``tolerance``; a run already
    warned names it too.
    """
    if status not in ("ok", "warning"):
        return status, message
    for key, label, fix in (
        ("step", "step companion", "tighter relative_tolerance / absolute_tolerance"),
        ("contact_grid", "contact grid", "a finer fastsim_elements_per_strip / fastsim_strips"),
        ("geometry_tables", "geometry tables", 'contact_provider = "search"'),
    ):
        estimate = (errors.get(key) or {}).get("estimate")
        if estimate is not None and estimate > tolerance:
            status = "warning"
            message = (
                f"{message}; {label} error estimate {estimate:.3g} of the static wheel load exceeds force_tolerance = "
                f"{tolerance:g} ({fix} reduces it)"
            )
    return status, message


def describe(errors: dict) -> str:
    """One line of the summary's ``discretisation_errors`` for the printed report: each estimate or why there is
    none.
    """
    parts = []
    for key, entry in errors.items():
        estimate = entry.get("estimate")
        if estimate is not None:
            parts.append(f"{key.replace('_', ' ')} {estimate:.2g}")
        else:
            parts.append(f"{key.replace('_', ' ')} {entry.get('method', 'not estimated').split(' (')[0]}")
    return "discretisation errors (relative): " + ", ".join(parts)
