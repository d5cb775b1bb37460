"""Research claims of the wheel-rail contact literature, measured on the named cases of the bench.

Each claim is evaluated from bench runs (:class:`comparisons.bench.BenchRun`) against the cases' references
and returns whether it holds as stated, the numbers, and a paragraph for the report. A claim that does not
hold (or holds only in part) says so; one whose cases were not run is "not measured".

1. Rigid-body (Hertzian) contact is insufficient with shape irregularities (the seed paper's conclusion):
   Hertz's max-pressure / area error on the wheel-flat and corrugation cases.
2. Linear theory has no slip: its creep-force error grows with the creepage (small / mid / saturated cases).
3. Vermeulen-Johnson is accurate only without spin: its error without spin vs with spin.
4. FASTSIM is needed with spin: FASTSIM's error vs Vermeulen-Johnson's on the spin cases.
5. Non-Hertzian methods are needed at the flange: Hertz/FASTSIM against BEM on the A-2.2 flange-root (two
   patches) and flange cases (reference: CONTACT's solution on its finest element run here, contact_grid.csv).

Every error is judged with its own uncertainty (:func:`measured`): the rung's discretisation error, estimated
from its resolution series (the two finest runs; with three, Richardson's estimate at the observed order), plus
the reference's own error estimate (``reference_uncertainty``). A comparison whose intervals overlap is
"undecided at this resolution", never a verdict: a claim's verdict must not flip with the bench's resolution.
"""

from __future__ import annotations

import math

CREEP_SERIES = ("creep-long-small", "creep-long-mid", "creep-long-saturated")
NO_SPIN = ("creep-long-mid",)
SPIN = ("creep-lat-spin", "creep-spin-only", "large-spin")
IRREGULAR = ("wheel-flat", "corrugation")
FLANGE = ("a22-flange-root", "a22-flange")


UNDECIDED = "undecided at this resolution"


def _value(run, key):
    return run.error if key == "error" else run.errors.get(key)


def measured(runs, case, model, key="error", reference_uncertainty=None) -> tuple[float, float] | None:
    """(error, its uncertainty) of the most resolved successful run of (case, model), or None.

    The most resolved run is the last (the bench runs each rung's resolutions from coarse to fine; wall times are
    too noisy to order them). Uncertainty: the reference's own estimate for the case
    (``reference_uncertainty[case]``, 0 if not given) plus the rung's discretisation error: 0 for a closed form
    (one resolution), else from the two finest runs e1 (coarser), e2 (finest), |e2 - e1|; with a third, e0, and an
    observed order p = log2(|e1 - e0| / |e2 - e1|) between 0.5 and 4 (refinement by 2), Richardson's
    |e2 - e1| / (2^p - 1).
    """
    chosen = [
        r for r in runs if r.case == case and r.model == model and r.status == "ok" and _value(r, key) is not None
    ]
    if not chosen:
        return None
    values = [float(_value(r, key)) for r in chosen]
    own = float((reference_uncertainty or {}).get(case, 0.0))
    if len(values) < 2:
        return values[-1], own
    step = abs(values[-1] - values[-2])
    if len(values) >= 3 and step > 0:
        before = abs(values[-2] - values[-3])
        order = math.log2(before / step) if before > 0 else math.nan
        if 0.5 <= order <= 4:
            step /= 2**order - 1
    return values[-1], own + step


def _best(runs, case, model, key="error"):
    """The error of the most resolved successful run of (case, model) (:func:`measured`'s value), or None."""
    got = measured(runs, case, model, key)
    return None if got is None else got[0]


def less(a, b) -> str:
    """Whether error ``a`` is below ``b``, each (value, uncertainty) or a bare number (exact): "yes", "no" or
    :data:`UNDECIDED` when the intervals overlap.
    """
    (va, ua), (vb, ub) = (x if isinstance(x, tuple) else (float(x), 0.0) for x in (a, b))
    if va + ua < vb - ub:
        return "yes"
    if va - ua > vb + ub:
        return "no"
    return UNDECIDED


def verdict(outcomes: dict) -> str:
    """A claim's verdict from its per-case outcomes ("yes"/"no"/UNDECIDED): "yes" or "no" when every case agrees,
    "partly" when decided cases disagree, else :data:`UNDECIDED`.
    """
    decided = {v for v in outcomes.values() if v != UNDECIDED}
    if decided == {"yes", "no"}:
        return "partly"
    if UNDECIDED in outcomes.values() or not decided:
        return UNDECIDED
    return decided.pop()


def _pm(pair) -> str:
    return "n/a" if pair is None else f"{100 * pair[0]:.3g} ± {100 * pair[1]:.2g} %"


def _pct(value) -> str:
    return "n/a" if value is None else f"{100 * value:.3g} %"


def claim_irregularities(runs, reference_uncertainty=None) -> dict:
    claim = "rigid-body contact is insufficient with irregularities"
    pairs = {
        case: {q: measured(runs, case, "hertz", q, reference_uncertainty) for q in ("err_max_pressure", "err_area")}
        for case in IRREGULAR
    }
    numbers = {c: {q: None if v is None else v[0] for q, v in row.items()} for c, row in pairs.items()}
    measured_cases = {c: v for c, v in pairs.items() if v["err_max_pressure"] is not None}
    if not measured_cases:
        return {"claim": claim, "holds": "not measured"}
    # Hertz is insufficient where its larger error is above 5 %, beyond the uncertainty
    outcomes = {
        c: less(0.05, max((p for p in v.values() if p is not None), key=lambda p: p[0]))
        for c, v in measured_cases.items()
    }
    holds = verdict(outcomes)
    text = (
        "Rigid-body (Hertzian) contact with shape irregularities: Hertz's theory on the local curvature at the "
        "deepest point, against the BEM on the sampled gap: "
        + "; ".join(
            f"{c}: max pressure {_pm(v['err_max_pressure'])}, area {_pm(v['err_area'])}"
            for c, v in measured_cases.items()
        )
        + ". "
        + (
            "The claim holds for "
            + ", ".join(c for c, o in outcomes.items() if o == "yes")
            + " but NOT for "
            + ", ".join(c for c, o in outcomes.items() if o == "no")
            + " (a wheel flat: two shoulders carry the load where Hertz sees one; a mild corrugation, 20 mm, "
            "10 um trough: the local curvature describes the patch to a few %)."
            if holds == "partly"
            else "The claim holds on every irregular case."
            if holds == "yes"
            else "Undecided at this resolution on "
            + ", ".join(c for c, o in outcomes.items() if o == UNDECIDED)
            + ": Hertz's error is within its uncertainty of 5 %."
            if holds == UNDECIDED
            else "The claim does not hold on these cases."
        )
    )
    return {"claim": claim, "holds": holds, "numbers": numbers, "outcomes": outcomes, "text": text}


def claim_linear_no_slip(runs, reference_uncertainty=None) -> dict:
    claim = "linear theory has no slip"
    pairs = {case: measured(runs, case, "linear", "err_creep_force", reference_uncertainty) for case in CREEP_SERIES}
    errors = {c: None if v is None else v[0] for c, v in pairs.items()}
    if any(v is None for v in pairs.values()):
        return {"claim": claim, "holds": "not measured", "numbers": errors}
    small, mid, saturated = (pairs[c] for c in CREEP_SERIES)
    outcomes = {
        "exact at small creepage": less(small, 0.02),
        "growing": less(small, mid),
        "unbounded": less(mid, saturated),
    }
    holds = verdict(outcomes)
    text = (
        "Linear theory (full adhesion, no slip) against the BEM limit as the longitudinal creepage grows: "
        f"xi = 1e-5: {_pm(small)}, 4e-4 (half saturated): {_pm(mid)}, 5e-3 (full slip): {_pm(saturated)}. "
        + (
            "The claim holds: exact in the limit of small creepage, the error grows without bound with it."
            if holds == "yes"
            else f"Undecided at this resolution ({', '.join(k for k, o in outcomes.items() if o == UNDECIDED)})."
            if holds == UNDECIDED
            else "The claim does not hold as measured."
        )
    )
    return {"claim": claim, "holds": holds, "numbers": errors, "outcomes": outcomes, "text": text}


def claim_vj_without_spin(runs, reference_uncertainty=None) -> dict:
    claim = "Vermeulen-Johnson is accurate only without spin"
    key = "err_creep_force"
    without = {c: measured(runs, c, "vermeulen-johnson", key, reference_uncertainty) for c in NO_SPIN}
    with_spin = {c: measured(runs, c, "vermeulen-johnson", key, reference_uncertainty) for c in SPIN}
    if any(v is None for v in (*without.values(), *with_spin.values())):
        return {"claim": claim, "holds": "not measured"}
    outcomes = {**{c: less(v, 0.05) for c, v in without.items()}, **{c: less(0.05, v) for c, v in with_spin.items()}}
    holds = verdict(outcomes)
    text = (
        "Vermeulen-Johnson's creep-force error without spin: "
        + ", ".join(f"{c} {_pm(v)}" for c, v in without.items())
        + "; with spin: "
        + ", ".join(f"{c} {_pm(v)}" for c, v in with_spin.items())
        + ". "
        + (
            "The claim holds on these cases."
            if holds == "yes"
            else "It holds only in part: with "
            + ", ".join(c for c in with_spin if outcomes[c] == "no")
            + " VJ stays within 5 % although spin is present."
            if holds == "partly"
            else "Undecided at this resolution on "
            + ", ".join(c for c, o in outcomes.items() if o == UNDECIDED)
            + " (the error is within its uncertainty of 5 %)."
            if holds == UNDECIDED
            else "The claim does not hold as measured."
        )
    )
    numbers = {
        "without": {c: v[0] for c, v in without.items()},
        "with": {c: v[0] for c, v in with_spin.items()},
    }
    return {"claim": claim, "holds": holds, "numbers": numbers, "outcomes": outcomes, "text": text}


def claim_fastsim_with_spin(runs, reference_uncertainty=None) -> dict:
    claim = "FASTSIM is needed with spin"
    key = "err_creep_force"
    pairs = {
        c: (
            measured(runs, c, "fastsim", key, reference_uncertainty),
            measured(runs, c, "vermeulen-johnson", key, reference_uncertainty),
        )
        for c in SPIN
    }
    if any(None in v for v in pairs.values()):
        return {"claim": claim, "holds": "not measured"}
    outcomes = {c: less(f, v) for c, (f, v) in pairs.items()}
    holds = verdict(outcomes)
    best_analytic = max(
        min(e for m in ("linear", "vermeulen-johnson", "fastsim") if (e := _best(runs, c, m, key)) is not None)
        for c in SPIN
    )
    text = (
        "With spin, FASTSIM (finest grid run) against Vermeulen-Johnson, creep-force error: "
        + "; ".join(f"{c}: FASTSIM {_pm(f)}, VJ {_pm(v)}" for c, (f, v) in pairs.items())
        + ". "
        + (
            "The claim holds: FASTSIM is the cheapest of the analytic rungs that follows spin."
            if holds == "yes"
            else "It holds only in part: FASTSIM is not better on "
            + ", ".join(c for c, o in outcomes.items() if o == "no")
            + "."
            if holds == "partly"
            else "Undecided at this resolution on "
            + ", ".join(c for c, o in outcomes.items() if o == UNDECIDED)
            + " (the two errors overlap within their uncertainties)."
            if holds == UNDECIDED
            else "The claim does not hold as measured."
        )
        + f" The best analytic rung on these cases still errs by {_pct(best_analytic)} (largest over the cases)."
    )
    numbers = {c: (f[0], v[0]) for c, (f, v) in pairs.items()}
    return {"claim": claim, "holds": holds, "numbers": numbers, "outcomes": outcomes, "text": text}


def claim_flange(runs, reference_uncertainty=None) -> dict:
    claim = "non-Hertzian methods are needed at the flange"
    pairs = {
        c: {m: measured(runs, c, m, reference_uncertainty=reference_uncertainty) for m in ("hertz", "fastsim", "bem")}
        for c in FLANGE
    }
    numbers = {c: {m: None if v is None else v[0] for m, v in row.items()} for c, row in pairs.items()}
    if any(v["fastsim"] is None or v["bem"] is None for v in pairs.values()):
        return {"claim": claim, "holds": "not measured", "numbers": numbers}
    outcomes = {c: less(v["bem"], v["fastsim"]) for c, v in pairs.items()}
    holds = verdict(outcomes)
    text = (
        "At the flange, error against CONTACT's solution on refined elements (largest of N, creep force, max "
        "pressure, area), each ± its uncertainty (the rung's resolution series and the reference's own estimate): "
        + "; ".join(
            f"{c}: Hertz {_pm(v['hertz'])}, FASTSIM {_pm(v['fastsim'])}, BEM {_pm(v['bem'])}" for c, v in pairs.items()
        )
        + ". "
        + (
            "The claim holds: the BEM on the sampled gap is closer to CONTACT than FASTSIM on both, beyond the errors."
            if holds == "yes"
            else "The claim holds only in part: the BEM is not closer to CONTACT than FASTSIM on "
            + ", ".join(c for c, b in outcomes.items() if b == "no")
            + "."
            if holds == "partly"
            else "Undecided at this resolution: on "
            + ", ".join(c for c, b in outcomes.items() if b == UNDECIDED)
            + " the BEM's and FASTSIM's errors overlap within their uncertainties (refine the BEM to decide)."
            if holds == UNDECIDED
            else "As measured the claim does NOT hold: FASTSIM on the search's patch is closer to CONTACT than the "
            "BEM, beyond the errors."
        )
        + " (Hertz gives no creep forces: 100 %.)"
    )
    uncertainties = {c: {m: None if v is None else v[1] for m, v in row.items()} for c, row in pairs.items()}
    return {
        "claim": claim, "holds": holds, "numbers": numbers, "uncertainties": uncertainties, "outcomes": outcomes,
        "text": text,
    }  # fmt: skip


CLAIMS = (claim_irregularities, claim_linear_no_slip, claim_vj_without_spin, claim_fastsim_with_spin, claim_flange)


def evaluate_claims(runs, reference_uncertainty=None) -> list[dict]:
    """Every claim of the module docstring on the bench runs ``runs``.

    ``reference_uncertainty``: case -> the reference's own relative error estimate (the largest over its
    quantities), added to every error's uncertainty (:func:`measured`).
    """
    return [claim(runs, reference_uncertainty) for claim in CLAIMS]


def claims_markdown(claims: list[dict]) -> str:
    """The report section: one paragraph per claim, with whether it holds."""
    lines = ["## Research claims, measured", ""]
    for c in claims:
        lines += [f"**{c['claim']}** — holds: {c['holds']}. {c.get('text', '')}", ""]
    return "\n".join(lines) + "\n"
