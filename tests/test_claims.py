"""Research claims as numbers, measured on the named cases against their stored references.

Runs the cheap rungs (Hertz, linear, Vermeulen-Johnson, FASTSIM) on the quadric cases; the references are the
closed forms and BEM Richardson limits stored with the cases (comparisons/cases/*/reference.toml).
"""

import pytest

from comparisons import bench
from comparisons.claims import evaluate_claims
from wheelrail.named_cases import load_named_cases

CASES = (
    "creep-long-small", "creep-long-mid", "creep-long-saturated", "creep-lat-spin", "creep-spin-only", "large-spin",
    "wheel-flat", "corrugation",
)  # fmt: skip


@pytest.fixture(scope="module")
def claims():
    runs = bench.run_bench(load_named_cases(CASES), ("hertz", "linear", "vermeulen-johnson", "fastsim"), quick=True)
    # a run may fail as a status (FASTSIM 10x10 at full slip: |F| above mu N by 1.1 %); claims use ok runs only
    assert all(r.status in ("ok", "failed") for r in runs)
    return {c["claim"]: c for c in evaluate_claims(runs)}


def test_linear_theory_has_no_slip(claims):
    c = claims["linear theory has no slip"]
    assert c["holds"] == "yes"
    n = c["numbers"]
    assert n["creep-long-small"] < 0.01 and n["creep-long-mid"] > 0.1 and n["creep-long-saturated"] > 1.0


def test_vermeulen_johnson_without_spin_only_in_part(claims):
    c = claims["Vermeulen-Johnson is accurate only without spin"]
    assert c["numbers"]["without"]["creep-long-mid"] < 0.03
    assert c["numbers"]["with"]["large-spin"] > 0.1 and c["numbers"]["with"]["creep-lat-spin"] > 0.1
    # does NOT hold as stated for pure spin: VJ within 5 % there (the report says so)
    assert c["numbers"]["with"]["creep-spin-only"] < 0.05 and c["holds"] == "partly"
    assert "creep-spin-only" in c["text"]


def test_fastsim_with_spin_beats_vj_on_the_large_spin_case(claims):
    c = claims["FASTSIM is needed with spin"]
    fastsim, vj = c["numbers"]["large-spin"]
    assert fastsim < 0.07 and vj > 2 * fastsim
    assert c["numbers"]["creep-lat-spin"][0] < c["numbers"]["creep-lat-spin"][1]


def test_rigid_body_contact_with_irregularities(claims):
    c = claims["rigid-body contact is insufficient with irregularities"]
    flat, corrugation = c["numbers"]["wheel-flat"], c["numbers"]["corrugation"]
    assert flat["err_max_pressure"] > 0.2 and flat["err_area"] > 0.2  # two shoulders, Hertz sees one
    assert corrugation["err_max_pressure"] < 0.05  # mild corrugation: the claim does not hold there
    assert c["holds"] == "partly"


def test_flange_claim_needs_the_bem_runs(claims):
    assert claims["non-Hertzian methods are needed at the flange"]["holds"] == "not measured"
