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
"""

from __future__ import annotations

CREEP_SERIES = ("creep-long-small", "creep-long-mid", "creep-long-saturated")
NO_SPIN = ("creep-long-mid",)
SPIN = ("creep-lat-spin", "creep-spin-only", "large-spin")
IRREGULAR = ("wheel-flat", "corrugation")
FLANGE = ("a22-flange-root", "a22-flange")


def _best(runs, case, model, key="error"):
    """The most resolved successful run of (case, model): the one with the longest wall time, its ``key``."""
    chosen = [r for r in runs if r.case == case and r.model == model and r.status == "ok"]
    if not chosen:
        return None
    run = max(chosen, key=lambda r: r.wall_time_s)
    return run.error if key == "error" else run.errors.get(key)


def _pct(value) -> str:
    return "n/a" if value is None else f"{100 * value:.3g} %"


def claim_irregularities(runs) -> dict:
    numbers = {case: {q: _best(runs, case, "hertz", q) for q in ("err_max_pressure", "err_area")} for case in IRREGULAR}
    measured = {c: v for c, v in numbers.items() if v["err_max_pressure"] is not None}
    if not measured:
        return {"claim": "rigid-body contact is insufficient with irregularities", "holds": "not measured"}
    big = {c: max(v.values()) > 0.05 for c, v in measured.items()}
    holds = "yes" if all(big.values()) else "partly" if any(big.values()) else "no"
    text = (
        "Rigid-body (Hertzian) contact with shape irregularities: Hertz's theory on the local curvature at the "
        "deepest point, against the BEM on the sampled gap: "
        + "; ".join(
            f"{c}: max pressure {_pct(v['err_max_pressure'])}, area {_pct(v['err_area'])}" for c, v in measured.items()
        )
        + ". "
        + (
            "The claim holds for the wheel flat (two shoulders carry the load where Hertz sees one) but NOT for the "
            "mild corrugation (20 mm, 10 um trough): there the local curvature describes the patch to a few %."
            if holds == "partly"
            else "The claim holds on every irregular case."
            if holds == "yes"
            else "The claim does not hold on these cases."
        )
    )
    claim = "rigid-body contact is insufficient with irregularities"
    return {"claim": claim, "holds": holds, "numbers": numbers, "text": text}


def claim_linear_no_slip(runs) -> dict:
    errors = {case: _best(runs, case, "linear", "err_creep_force") for case in CREEP_SERIES}
    if any(v is None for v in errors.values()):
        return {"claim": "linear theory has no slip", "holds": "not measured", "numbers": errors}
    growing = errors["creep-long-small"] < errors["creep-long-mid"] < errors["creep-long-saturated"]
    holds = "yes" if growing and errors["creep-long-small"] < 0.02 else "no"
    text = (
        "Linear theory (full adhesion, no slip) against the BEM limit as the longitudinal creepage grows: "
        f"xi = 1e-5: {_pct(errors['creep-long-small'])}, 4e-4 (half saturated): {_pct(errors['creep-long-mid'])}, "
        f"5e-3 (full slip): {_pct(errors['creep-long-saturated'])}. "
        + (
            "The claim holds: exact in the limit of small creepage, the error grows without bound with it."
            if holds == "yes"
            else "The claim does not hold as measured."
        )
    )
    return {"claim": "linear theory has no slip", "holds": holds, "numbers": errors, "text": text}


def claim_vj_without_spin(runs) -> dict:
    without = {c: _best(runs, c, "vermeulen-johnson", "err_creep_force") for c in NO_SPIN}
    with_spin = {c: _best(runs, c, "vermeulen-johnson", "err_creep_force") for c in SPIN}
    if any(v is None for v in (*without.values(), *with_spin.values())):
        return {"claim": "Vermeulen-Johnson is accurate only without spin", "holds": "not measured"}
    good_without = max(without.values()) < 0.05
    bad_with = {c: v > 0.05 for c, v in with_spin.items()}
    holds = (
        "yes"
        if good_without and all(bad_with.values())
        else "partly"
        if good_without and any(bad_with.values())
        else "no"
    )  # noqa: E501
    text = (
        "Vermeulen-Johnson's creep-force error without spin: "
        + ", ".join(f"{c} {_pct(v)}" for c, v in without.items())
        + "; with spin: "
        + ", ".join(f"{c} {_pct(v)}" for c, v in with_spin.items())
        + ". "
        + (
            "The claim holds on these cases."
            if holds == "yes"
            else "It holds only in part: with "
            + ", ".join(c for c, bad in bad_with.items() if not bad)
            + " VJ stays within 5 % although spin is present."
            if holds == "partly"
            else "The claim does not hold as measured."
        )
    )
    numbers = {"without": without, "with": with_spin}
    return {
        "claim": "Vermeulen-Johnson is accurate only without spin",
        "holds": holds,
        "numbers": numbers,
        "text": text,
    }


def claim_fastsim_with_spin(runs) -> dict:
    pairs = {
        c: (_best(runs, c, "fastsim", "err_creep_force"), _best(runs, c, "vermeulen-johnson", "err_creep_force"))
        for c in SPIN
    }
    if any(None in v for v in pairs.values()):
        return {"claim": "FASTSIM is needed with spin", "holds": "not measured"}
    better = {c: f < v for c, (f, v) in pairs.items()}
    holds = "yes" if all(better.values()) else "partly" if any(better.values()) else "no"
    best_analytic = max(
        min(
            e
            for m in ("linear", "vermeulen-johnson", "fastsim")
            if (e := _best(runs, c, m, "err_creep_force")) is not None
        )
        for c in SPIN
    )
    text = (
        "With spin, FASTSIM (finest grid run) against Vermeulen-Johnson, creep-force error: "
        + "; ".join(f"{c}: FASTSIM {_pct(f)}, VJ {_pct(v)}" for c, (f, v) in pairs.items())
        + ". "
        + (
            "The claim holds: FASTSIM is the cheapest of the analytic rungs that follows spin."
            if holds == "yes"
            else "It holds only in part: FASTSIM is not better on "
            + ", ".join(c for c, b in better.items() if not b)
            + "."
            if holds == "partly"
            else "The claim does not hold as measured."
        )
        + f" The best analytic rung on these cases still errs by {_pct(best_analytic)} (largest over the cases)."
    )
    return {"claim": "FASTSIM is needed with spin", "holds": holds, "numbers": pairs, "text": text}


def claim_flange(runs) -> dict:
    numbers = {c: {m: _best(runs, c, m) for m in ("hertz", "fastsim", "bem")} for c in FLANGE}
    if any(v["fastsim"] is None or v["bem"] is None for v in numbers.values()):
        return {"claim": "non-Hertzian methods are needed at the flange", "holds": "not measured", "numbers": numbers}
    better = {c: v["bem"] < v["fastsim"] for c, v in numbers.items()}
    holds = "yes" if all(better.values()) else "partly" if any(better.values()) else "no"
    text = (
        "At the flange, error against CONTACT's solution on refined elements (largest of N, creep force, max "
        "pressure, area): "
        + "; ".join(
            f"{c}: Hertz {_pct(v['hertz'])}, FASTSIM {_pct(v['fastsim'])}, BEM {_pct(v['bem'])}"
            for c, v in numbers.items()
        )
        + ". "
        + (
            "The claim holds: the BEM on the sampled gap is closer to CONTACT than FASTSIM on both."
            if holds == "yes"
            else "The claim holds only in part: the BEM is not closer to CONTACT than FASTSIM on "
            + ", ".join(c for c, b in better.items() if not b)
            + "."
            if holds == "partly"
            else "As measured the claim does NOT hold: FASTSIM on the search's patch is as close to CONTACT as the "
            "BEM at these positions."
        )
        + " (Hertz gives no creep forces: 100 %.)"
    )
    return {"claim": "non-Hertzian methods are needed at the flange", "holds": holds, "numbers": numbers, "text": text}


CLAIMS = (claim_irregularities, claim_linear_no_slip, claim_vj_without_spin, claim_fastsim_with_spin, claim_flange)


def evaluate_claims(runs) -> list[dict]:
    """Every claim of the module docstring on the bench runs ``runs``."""
    return [claim(runs) for claim in CLAIMS]


def claims_markdown(claims: list[dict]) -> str:
    """The report section: one paragraph per claim, with whether it holds."""
    lines = ["## Research claims, measured", ""]
    for c in claims:
        lines += [f"**{c['claim']}** — holds: {c['holds']}. {c.get('text', '')}", ""]
    return "\n".join(lines) + "\n"
