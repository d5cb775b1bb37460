"""The FEA's contact area from the edge reconstructed out of the free nodes' deformed separation (issue 22).

On Hertz's closed forms (quadric rigid indenter, quarter block, one mesh per level, ``mesh_tolerance`` None, load
control at 1e5 N, E 210 GPa, nu 0.3): per level, the nodal area (sum of the active nodes' lumped weights,
``extra["contact_area_nodal_m2"]``) and the edge-reconstructed area (fea.postprocess.edge_reconstructed_area,
``extra["contact_area_edge_m2"]``) against Hertz's pi a b (fea.hertz_reference.hertz_elliptic).

Usage::

    nice .venv/bin/python benchmarks/bench_fea_edge_area.py run CASE DEGREE N [N ...]   # appends to the raw jsonl
    nice .venv/bin/python benchmarks/bench_fea_edge_area.py --report     # fea_edge_area_runs.md / .json
    nice .venv/bin/python benchmarks/bench_fea_edge_area.py flange-root 2 1.778 2.667   # A-2.2 flange root

CASE: circle (R 0.3 / 0.3 m) or ellipse (R 0.46 / 0.15 m, the tests' quadric).
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
RAW = OUT / "fea_edge_area_levels.jsonl"
CASES = {"circle": (0.3, 0.3), "ellipse": (0.46, 0.15)}
FORCE_N = 1e5


def run(case: str, degree: int, levels: list[float]) -> None:
    import dolfinx_solver  # noqa: F401

    from fea.hertz_reference import hertz_elliptic
    from fea.model import FeaModel
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    steel = Material.from_young(210e9, 0.3, 0.3)
    geo = ContactGeometry.quadric(*CASES[case])
    ref = hertz_elliptic(geo.curvature_long_1_per_m, geo.curvature_lat_1_per_m, FORCE_N, steel.combined_modulus_Pa)
    exact = math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m
    for n in levels:
        opts = {
            "degree": degree,
            "elements_per_semi_axis": n,
            "mesh_tolerance": None,
            "stresses": False,
            "edge_area": True,
        }
        t0, c0 = time.perf_counter(), time.process_time()
        r = FeaModel().solve(geo, Creepage(), steel, normal_force_N=FORCE_N, options=opts)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        ex = r.extra
        # load control: the area scales as F^(2/3); compare at the solved force
        exact_here = exact * (r.normal_force_N / FORCE_N) ** (2.0 / 3.0)
        rec = {
            "case": case,
            "degree": degree,
            "n_per_semi_axis": n,
            "status": r.status,
            "dofs": ex.get("dofs"),
            "normal_force_N": r.normal_force_N,
            "hertz_area_m2": exact_here,
            "nodal_area_m2": ex.get("contact_area_nodal_m2"),
            "edge_area_m2": ex.get("contact_area_edge_m2"),
            "edge": ex.get("contact_area_edge"),
            "element_size_m": ex.get("element_size_m"),
            "wall_s": wall,
            "cpu_s": cpu,
            "load_avg": os.getloadavg()[0],
        }
        for k in ("nodal", "edge"):
            v = rec[f"{k}_area_m2"]
            rec[f"{k}_rel_error"] = None if v is None else v / exact_here - 1.0
        print(json.dumps(rec), flush=True)
        with RAW.open("a") as fh:
            fh.write(json.dumps(rec) + "\n")


FLANGE_RAW = OUT / "fea_edge_area_flange_root.jsonl"
BEM_EDGE_M2 = 15.05e-6
"""The BEM's converged edge area on the same gap at 9619 N (benchmarks/results/fea_flange_root_p2_findings.md)."""


def flange_root(degree: int, levels: list[float]) -> None:
    """The A-2.2 flange-root levels of benchmarks/bench_fea_flange_root_p2.py (full block, peak box, load control at
    9619 N, grading 0.4 / 1.5^k capped at 0.9): nodal against edge-reconstructed area, against the BEM's 15.05 mm2."""
    import dolfinx_solver  # noqa: F401

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_fea_flange_root_p2 import CONTACT, G0, N0, _patch

    from fea.model import FeaModel, FeaOptions
    from fea.refinement import REFINEMENT_RATIO, _level_options

    case, patch = _patch()
    base = {"stresses": False, "mesh_tolerance": 0.02, "load_balanced": True, "edge_area": True}
    model = FeaModel()
    solve_level, peak = model.level_solver((patch.geometry, patch.creepage, case.material, None))
    box, _ = model._locate_peak(solve_level, FeaOptions.from_mapping(base), peak)
    peak["box"] = box
    for n in levels:
        k = math.log(n / N0) / math.log(REFINEMENT_RATIO)
        level = _level_options(FeaOptions.from_mapping({**base, "degree": degree}), n, min(G0 / 1.5**k, 0.9))
        t0, c0 = time.perf_counter(), time.process_time()
        r, _ = solve_level(level, force_N=CONTACT["normal_force_N"])
        rec = {
            "degree": degree,
            "n_per_semi_axis": n,
            "status": r.status,
            "dofs": r.extra.get("dofs"),
            "normal_force_N": r.normal_force_N,
            "max_pressure_Pa": r.max_pressure_Pa,
            "nodal_area_m2": r.extra.get("contact_area_nodal_m2"),
            "edge_area_m2": r.extra.get("contact_area_edge_m2"),
            "edge": r.extra.get("contact_area_edge"),
            "wall_s": time.perf_counter() - t0,
            "cpu_s": time.process_time() - c0,
            "load_avg": os.getloadavg()[0],
        }
        for key in ("nodal", "edge"):
            v = rec[f"{key}_area_m2"]
            rec[f"{key}_rel_error"] = None if v is None else v / BEM_EDGE_M2 - 1.0
        print(json.dumps(rec, default=float), flush=True)
        with FLANGE_RAW.open("a") as fh:
            fh.write(json.dumps(rec, default=float) + "\n")


def _order(errors, ratio):
    out = []
    for e0, e1 in zip(errors, errors[1:], strict=False):
        out.append(math.log(abs(e0) / abs(e1)) / math.log(ratio) if e0 and e1 else None)
    return out


def report() -> None:
    recs = [json.loads(line) for line in RAW.read_text().splitlines() if line.strip()]
    lines = [
        "# FEA contact area: nodal sum against the edge reconstructed from the free nodes' separation (issue 22)",
        "",
        f"Generated by benchmarks/bench_fea_edge_area.py on {platform.node()} ({platform.processor() or 'cpu'}, "
        f"{os.cpu_count()} cores, shared; load average at each run in the table), {time.strftime('%Y-%m-%d')}.",
        "",
        "Hertz quadric, rigid indenter, quarter block, load control at 1e5 N, E 210 GPa, nu 0.3, one mesh per level "
        "(`mesh_tolerance` None, `stresses` False). Errors relative to pi a b at the solved force (Hertz, "
        "fea.hertz_reference). `edge`: fea.postprocess.edge_reconstructed_area (720 rays, f = d^(2/3) linear "
        "over the face Delaunay triangles, zero of the line through the first all-free point and one element "
        "further). Order: log(e_k / e_k+1) / log(n_k+1 / n_k) between successive levels.",
        "",
    ]
    groups = {}
    for r in recs:
        groups.setdefault((r["case"], r["degree"]), {})[r["n_per_semi_axis"]] = r  # last run of a level wins
    summary = {}
    for (case, degree), by_n in sorted(groups.items()):
        rows = [by_n[n] for n in sorted(by_n)]
        ns = [r["n_per_semi_axis"] for r in rows]
        lines += [
            f"## {case}, P{degree}",
            "",
            "| n / semi-axis | dofs | nodal err | edge err | order nodal | order edge | rays clamped | "
            "rays fallback | wall s | cpu s | load |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for i, r in enumerate(rows):
            on = oe = ""
            if i:
                ratio = ns[i] / ns[i - 1]
                on = _order([rows[i - 1]["nodal_rel_error"], r["nodal_rel_error"]], ratio)[0]
                oe = _order([rows[i - 1]["edge_rel_error"], r["edge_rel_error"]], ratio)[0]
                on = "" if on is None else f"{on:.2f}"
                oe = "" if oe is None else f"{oe:.2f}"
            e = r.get("edge") or {}
            lines.append(
                f"| {r['n_per_semi_axis']:g} | {r['dofs']} | {r['nodal_rel_error']:+.3%} | "
                f"{r['edge_rel_error']:+.3%} | {on} | {oe} | {e.get('rays_clamped', float('nan')):.3f} | "
                f"{e.get('rays_fallback', float('nan')):.3f} | {r['wall_s']:.1f} | {r['cpu_s']:.1f} | "
                f"{r['load_avg']:.1f} |"
            )
        lines.append("")
        summary[f"{case}-P{degree}"] = rows
    (OUT / "fea_edge_area_runs.json").write_text(json.dumps(summary, indent=1) + "\n")
    md = OUT / "fea_edge_area_runs.md"
    notes = (
        md.read_text().split("<!-- findings -->", 1)[1] if md.exists() and "<!-- findings -->" in md.read_text() else ""
    )
    md.write_text("\n".join(lines) + "\n<!-- findings -->" + notes)


if __name__ == "__main__":
    if sys.argv[1] == "--report":
        report()
    elif sys.argv[1] == "flange-root":
        flange_root(int(sys.argv[2]), [float(v) for v in sys.argv[3:]])
    elif sys.argv[1] == "run":
        run(sys.argv[2], int(sys.argv[3]), [float(v) for v in sys.argv[4:]])
    else:
        raise SystemExit("wheelrail: error: usage: bench_fea_edge_area.py run CASE DEGREE N [N ...] | --report")
