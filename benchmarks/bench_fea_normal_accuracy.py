"""The FEA's normal contact at its defaults on the two cases of issue 22: convergence tables with time and error.

Cases (frictionless FEA, rigid formulation, P1, the default refinement series of fea.refinement):

* the two patches of ``wheelrail contact manchester-a22`` at the BEM equilibrium's approach (approach control,
  as in the wheelset equilibrium), against the BEM (40 x 40, with its grid error) and CONTACT's published
  Manchester A-2.2 case 11 (y 5 mm, yaw 12 mrad; comparisons/data/contact_reference/mbench_a22_right.csv, right
  wheel only; element 0.2 mm, no stated error);
* the demo's peak patch (polygonal-wheel, contact_tolerance 0.1, the largest normal force after 0.3 s) under
  load control, against the demo's BEM (64 x 64) with its grid error.

Each level records the element size at the patch, the unknowns, the wall time and the three max-pressure
definitions of fea.model (peak fit = the reported one, the largest patch average, the largest nodal value) with
the area and the force; the observed order of each between successive levels is printed in the md.

Usage::

    .venv/bin/python benchmarks/bench_fea_normal_accuracy.py [max_levels]   # writes fea_normal_accuracy.json/md
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
RATIO = 1.5


def _series(geometry, creepage, material, normal_force_N, levels: int) -> list[dict]:
    from fea.model import FeaModel

    rows = []
    for k in range(levels):
        opts = {"stresses": False, "mesh_tolerance": None, "elements_per_semi_axis": 6 * RATIO**k,
                "grading": 0.4 / RATIO**k}  # fmt: skip
        start = time.perf_counter()
        r = FeaModel().solve(geometry, creepage, material, normal_force_N=normal_force_N, options=opts)
        e = r.extra
        rows.append({
            "elements_per_semi_axis": opts["elements_per_semi_axis"],
            "element_size_m": e.get("element_size_m"),
            "dofs": e.get("dofs"),
            "wall_time_s": time.perf_counter() - start,
            "status": r.status,
            "normal_force_N": r.normal_force_N,
            "max_pressure_Pa": r.max_pressure_Pa,
            "max_pressure_filtered_Pa": e.get("max_pressure_filtered_Pa"),
            "max_nodal_pressure_Pa": e.get("max_nodal_pressure_Pa"),
            "contact_area_m2": r.contact_area_m2,
        })  # fmt: skip
    return rows


def manchester(levels: int) -> list[dict]:
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case
    from wheelrail.cases import load_case

    case = load_case("manchester-a22")
    bem = solve_wheelset_case(case.wheelset, case.material, "bem", options={})
    out = []
    for p in bem.patches:
        out.append({
            "case": f"manchester-a22 {p.side}",
            "contact_angle_rad": p.geometry.contact_angle_rad,
            "bem": {"normal_force_N": p.result.normal_force_N, "max_pressure_Pa": p.result.max_pressure_Pa,
                    "contact_area_m2": p.result.contact_area_m2},
            "levels": _series(p.geometry, p.creepage, case.material, None, levels),
        })  # fmt: skip
    return out


def demo_peak(levels: int) -> dict:
    from comparisons.demo import peak_patch_case
    from rigid_dynamics.wheelset import simulate
    from wheelrail.comparison_commands import DEMO_TOLERANCE
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = replace(load_scene(resolve_scene_path("polygonal-wheel")), contact_tolerance=DEMO_TOLERANCE)
    patch = peak_patch_case(simulate(scene))
    rows = _series(patch.geometry, patch.creepage, patch.material, patch.normal_force_N, levels)
    return {"case": "demo peak", "normal_force_N": patch.normal_force_N, "levels": rows}


def _order(values: list[float]) -> list[str]:
    out = ["", ""]
    for a, b, c in zip(values, values[1:], values[2:], strict=False):
        d1, d2 = abs(b - a), abs(c - b)
        out.append(f"{math.log(d1 / d2) / math.log(RATIO):.2f}" if d1 > 0 and d2 > 0 else "-")
    return out[: len(values)]


def markdown(data: dict) -> str:
    lines = ["# FEA normal contact at its defaults: convergence, time and error (issue 22)", "",
             f"Machine: {data['machine']}; load average at the start {data['load']}.", ""]  # fmt: skip
    for case in data["cases"]:
        lv = case["levels"]
        lines += [f"## {case['case']}", "",
                  "| n/semi-axis | h [mm] | DOFs | time / s | N [N] | p fit [MPa] | order | p filtered | p nodal | "
                  "area [mm2] | order |", "|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
        po = _order([r["max_pressure_Pa"] for r in lv])
        ao = _order([r["contact_area_m2"] for r in lv])
        for r, a, b in zip(lv, po, ao, strict=True):
            lines.append(
                f"| {r['elements_per_semi_axis']:.3g} | {r['element_size_m'] * 1e3:.3f} | {r['dofs']} | "
                f"{r['wall_time_s']:.1f} | {r['normal_force_N']:.0f} | {r['max_pressure_Pa'] / 1e6:.1f} | {a} | "
                f"{r['max_pressure_filtered_Pa'] / 1e6:.1f} | {r['max_nodal_pressure_Pa'] / 1e6:.1f} | "
                f"{r['contact_area_m2'] * 1e6:.2f} | {b} |"
            )
        lines.append("")
    return "\n".join(lines) + "\n"


def main() -> None:
    import dolfinx_solver  # noqa: F401  (before dolfinx)

    from rigid_dynamics.files import write_text

    levels = int(sys.argv[1]) if len(sys.argv) > 1 else 4
    data = {
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}",
        "load": [round(x, 2) for x in os.getloadavg()],
        "cases": [demo_peak(levels), *manchester(levels)],
    }
    write_text(OUT / "fea_normal_accuracy.json", json.dumps(data, indent=1))
    write_text(OUT / "fea_normal_accuracy.md", markdown(data))


if __name__ == "__main__":
    main()
