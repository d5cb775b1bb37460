"""The FEA's stated discretisation error against its true error, with the cost of each refinement level.

Cases:

* Hertz (issue 6): R_long 0.46 m, R_lat 0.15 m, P = 100 kN, E 210 GPa, nu 0.3 (reference: Johnson 1985 eq 3.64,
  fea.hertz_reference): the default series (P1, 6 elements per semi-axis, block 20 semi-axes, mesh_tolerance 2 %)
  and the P2 series of tests/test_fea_refinement.py (3 per semi-axis, block 80, 1 %). True error against the
  closed form; the stated one from fea.refinement.
* The two patches of ``wheelrail contact manchester-a22`` (S1002 / UIC60 1:40, 10 kN, shift 5 mm, yaw 12 mrad),
  each at the BEM equilibrium's approach (approach control, as in the wheelset equilibrium): the series at the
  default tolerance, its levels and stated errors beside the BEM (40 x 40 default grid, not a converged
  reference: no true error there).

Usage::

    .venv/bin/python benchmarks/bench_fea_error.py     # writes benchmarks/results/fea_error.json and fea_error.md
"""

from __future__ import annotations

import json
import math
import os
import platform
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def _levels(result) -> list[dict]:
    return result.extra["discretisation_error"].get("levels", [])


def hertz_series(options: dict) -> dict:
    from fea.hertz_reference import hertz_elliptic
    from fea.model import FeaModel
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    steel = Material.from_young(210e9, 0.3, 0.3)
    geo = ContactGeometry.quadric(0.46, 0.15)
    ref = hertz_elliptic(geo.curvature_long_1_per_m, geo.curvature_lat_1_per_m, 1e5, steel.combined_modulus_Pa)
    exact = {
        "max_pressure": ref.max_pressure_Pa,
        "contact_area": math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m,
        "approach": ref.approach_m,
    }
    start = time.perf_counter()
    r = FeaModel().solve(geo, Creepage(), steel, normal_force_N=1e5, options={"stresses": False, **options})
    info = r.extra["discretisation_error"]
    return {
        "options": options,
        "status": r.status,
        "message": r.message,
        "wall_time_s": time.perf_counter() - start,
        "levels": [
            {
                **{k: lv[k] for k in ("elements_per_semi_axis", "dofs", "wall_time_s")},
                **{f"true_{k}": lv[k] / v - 1.0 for k, v in exact.items()},
            }
            for lv in _levels(r)
        ],  # fmt: skip
        "stated": {k: info["relative_error"].get(k) for k in exact},
        "true": {k: abs(getattr_value(r, k) / v - 1.0) for k, v in exact.items()},
    }


def getattr_value(result, name):
    return {"max_pressure": result.max_pressure_Pa, "contact_area": result.contact_area_m2,
            "approach": result.approach_m}[name]  # fmt: skip


def manchester_patches() -> list[dict]:
    from fea.model import FeaModel
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case
    from wheelrail.cases import load_case

    case = load_case("manchester-a22")
    bem = solve_wheelset_case(case.wheelset, case.material, "bem", options={})
    out = []
    for p in bem.patches:
        start = time.perf_counter()
        r = FeaModel().solve(p.geometry, p.creepage, case.material, options={"stresses": False})
        info = r.extra["discretisation_error"]
        out.append({
            "side": p.side,
            "contact_angle_rad": p.geometry.contact_angle_rad,
            "bem": {"normal_force_N": p.result.normal_force_N, "max_pressure_Pa": p.result.max_pressure_Pa,
                    "contact_area_m2": p.result.contact_area_m2},
            "fea": {"status": r.status, "normal_force_N": r.normal_force_N, "max_pressure_Pa": r.max_pressure_Pa,
                    "contact_area_m2": r.contact_area_m2},
            "stated": info.get("relative_error"),
            "block_size": info.get("block_size_relative_error"),
            "levels": [{k: lv[k] for k in ("elements_per_semi_axis", "dofs", "wall_time_s", "normal_force",
                                           "max_pressure", "contact_area")} for lv in _levels(r)],
            "wall_time_s": time.perf_counter() - start,
        })  # fmt: skip
    return out


def _pct(v):
    return "-" if v is None else f"{100 * v:.2f} %"


def markdown(data: dict) -> str:
    lines = ["# FEA: stated against true discretisation error, and the cost per level", "",
             f"Machine: {data['machine']}. Times are wall times on a shared machine (load average at the start "
             f"{data['load']}).", ""]  # fmt: skip
    for h in data["hertz"]:
        lines += [f"## Hertz, options {json.dumps(h['options'])}: {h['status']} in {h['wall_time_s']:.1f} s", "",
                  "| elements per semi-axis | DOFs | time / s | p0 err | area err | approach err |",
                  "|---|---|---|---|---|---|"]  # fmt: skip
        for lv in h["levels"]:
            lines.append(
                f"| {lv['elements_per_semi_axis']:.3g} | {lv['dofs']} | {lv['wall_time_s']:.1f} | "
                f"{_pct(lv['true_max_pressure'])} | {_pct(lv['true_contact_area'])} | {_pct(lv['true_approach'])} |"
            )
        lines += ["", "| quantity | stated | true |", "|---|---|---|"]
        lines += [f"| {k} | {_pct(h['stated'][k])} | {_pct(h['true'][k])} |" for k in h["true"]]
        lines.append("")
    for p in data["manchester"]:
        lines += [f"## manchester-a22, {p['side']} patch (contact angle {p['contact_angle_rad']:.3f} rad): "
                  f"{p['fea']['status']} in {p['wall_time_s']:.1f} s", "",
                  "| elements per semi-axis | DOFs | time / s | N [N] | p max [MPa] | area [mm2] |",
                  "|---|---|---|---|---|---|"]  # fmt: skip
        for lv in p["levels"]:
            lines.append(
                f"| {lv['elements_per_semi_axis']:.3g} | {lv['dofs']} | {lv['wall_time_s']:.1f} | "
                f"{lv['normal_force']:.0f} | {lv['max_pressure'] / 1e6:.0f} | {lv['contact_area'] * 1e6:.2f} |"
            )
        b = p["bem"]
        lines += [
            "",
            f"BEM (40 x 40, the equilibrium's): N {b['normal_force_N']:.0f} N, p max "
            f"{b['max_pressure_Pa'] / 1e6:.0f} MPa, area {b['contact_area_m2'] * 1e6:.2f} mm2. Stated FEA "
            "errors: "
            + ", ".join(f"{k} {_pct(v)}" for k, v in (p["stated"] or {}).items() if v is not None)
            + "; of which block size: "
            + ", ".join(f"{k} {_pct(v)}" for k, v in (p["block_size"] or {}).items() if v is not None),
            "",
        ]
    return "\n".join(lines) + "\n"


def main() -> None:
    import dolfinx_solver  # noqa: F401

    from rigid_dynamics.files import write_text

    data = {
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}",
        "load": [round(v, 2) for v in os.getloadavg()],
        "hertz": [
            hertz_series({}),
            hertz_series({"degree": 2, "elements_per_semi_axis": 3, "domain_factor": 80, "mesh_tolerance": 0.01}),
        ],
        "manchester": manchester_patches(),
    }
    write_text(OUT / "fea_error.json", json.dumps(data, indent=1, default=float) + "\n")
    write_text(OUT / "fea_error.md", markdown(data))
    print(markdown(data))


if __name__ == "__main__":
    main()
