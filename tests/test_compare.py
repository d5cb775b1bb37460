"""wheelrail compare on the Hertz circle (coarse settings): report, maps, and the subsurface check.

Verification: on the Hertz circle the maximum shear below the patch from the half-space solution of the BEM
pressure and from FEA must both be Johnson's 0.31 p0 at 0.48 a (nu = 0.3; Johnson 1985 fig. 3.9), here with
nu = 0.28 of the case: the closed-form axis stresses (Johnson eq 3.45) give the target for that nu.
"""

import json

import numpy as np
import pytest

from comparisons import compare
from rigid_dynamics.contact.subsurface import hertz_axis_stresses
from wheelrail.cli import main
from wheelrail.named_cases import load_named_case


def _johnson_max_shear(nu):
    t = np.linspace(0.3, 0.7, 4001)
    s_r, s_z = hertz_axis_stresses(t, nu)
    tau = 0.5 * (s_r - s_z)
    return float(tau.max()), float(t[np.argmax(tau)])


@pytest.mark.fea
def test_compare_hertz_circle_report_and_subsurface_check(tmp_path, monkeypatch):
    monkeypatch.setattr(compare, "CUT_POINTS", (21, 25))
    monkeypatch.setitem(compare.DEFAULT_OPTIONS, "bem", {"nx": 40, "ny": 40})
    out = tmp_path / "cmp"
    code = main(["compare", "hertz-ab-1", "--models", "hertz", "bem", "fea", "--out", str(out)])
    assert code == 0
    for name in ("report.md", "report.html", "pressure.png", "pressure_difference.png", "subsurface.png"):
        assert (out / name).stat().st_size > 500, name
    summary = json.loads((out / "compare.json").read_text())
    named = load_named_case("hertz-ab-1")
    p0, a = named.reference["max_pressure_Pa"], named.reference["semi_axis_long_m"]
    target, depth = _johnson_max_shear(named.case.material.poisson_ratio)
    assert target == pytest.approx(0.31, abs=0.01) and depth == pytest.approx(0.48, abs=0.03)
    by_source = {s["source"]: s for s in summary["subsurface"]}
    bem = by_source["BEM pressure, half-space"]
    fea = by_source["FEA (frictionless)"]
    # cut grid: 25 depths down to ~2.5 a, so the depth is resolved to ~0.1 a
    assert bem["max_shear_Pa"] / p0 == pytest.approx(target, rel=0.03)
    assert bem["max_shear_depth_m"] / a == pytest.approx(depth, abs=0.1)
    assert fea["max_shear_Pa"] / p0 == pytest.approx(target, rel=0.06)  # FEA default mesh, nodal recovery
    assert fea["max_shear_depth_m"] / a == pytest.approx(depth, abs=0.1)
    html = (out / "report.html").read_text()
    assert "<table>" in html and 'src="subsurface.png"' in html
