"""P1 against P2 displacements on the A-2.2 flange-root patch: max pressure, area, unknowns and time per level.

The right patch of ``wheelrail contact manchester-a22`` at the BEM equilibrium's approach (as in
benchmarks/bench_fea_flange_root_order.py) is solved by fea.model's own level solver (rigid formulation, full block,
the peak box located once as the refinement series does, fea.model "Peak box") under load control at CONTACT's
force (9619 N; ``force_N`` of the level solver, the load-balanced series' finest-force solve), so that every level is
compared with CONTACT at one load, without Hertz scaling. Levels: n = n0 r^k elements per semi-axis with the
grading g0 / r^k of fea.refinement (n0 6, g0 0.4, r 1.5), P1 and P2.

Reported per level: unknowns, wall and CPU time of the solve, the max pressure (the peak box's fixed-window fit and
its window error, fea.model), the nodal contact area, and both against CONTACT (0.05 mm elements: 1572 MPa,
14.955 mm2). Per degree: the refinement series' estimate (fea.refinement.estimate, load-balanced: what the series
would state with these levels) for the last two / three levels.

Usage::

    nice .venv/bin/python benchmarks/bench_fea_flange_root_p2.py 1:2.667,4,6 2:1.778,2.667,4   # appends levels
    nice .venv/bin/python benchmarks/bench_fea_flange_root_p2.py --bem     # the BEM on the same gap, fine grids
    nice .venv/bin/python benchmarks/bench_fea_flange_root_p2.py --report                    # writes md / json
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
RAW = OUT / "fea_flange_root_p2_levels.jsonl"
BEM_RAW = OUT / "fea_flange_root_p2_bem.json"
BEM_SIZES_M = (0.1e-3, 0.05e-3, 0.035e-3, 0.025e-3)
CONTACT = {"normal_force_N": 9619.0, "max_pressure_Pa": 1572e6, "contact_area_m2": 14.955e-6}
N0, G0 = 6.0, 0.4
SERIES_TAGS = ("", "g0.9cap")
"""The runs of RAW that make the table's series (grading 0.4 / r^k, at most 0.9: at 1.78 elements per semi-axis
gmsh's mesh at 1.35 failed the quality limit, minSICN 1.2e-5)."""


def _patch():
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case
    from wheelrail.cases import load_case

    case = load_case("manchester-a22")
    bem = solve_wheelset_case(case.wheelset, case.material, "bem", options={})
    patch = next(p for p in bem.patches if p.side == "right")
    return case, patch


def run(specs: list[tuple[int, list[float]]], options: dict | None = None, tag: str = "", max_grading: float = 9.0):
    import dolfinx_solver  # noqa: F401

    from fea.model import FeaModel, FeaOptions
    from fea.refinement import REFINEMENT_RATIO, _level_options

    case, patch = _patch()
    base = {"stresses": False, "mesh_tolerance": 0.02, "load_balanced": True, **(options or {})}
    model = FeaModel()
    solve_level, peak = model.level_solver((patch.geometry, patch.creepage, case.material, None))
    opts = FeaOptions.from_mapping(base)
    box, record = model._locate_peak(solve_level, opts, peak)
    peak["box"] = box
    for degree, ns in specs:
        for n in ns:
            k = math.log(n / N0) / math.log(REFINEMENT_RATIO)
            grading = min(G0 / REFINEMENT_RATIO**k, max_grading)
            level = _level_options(FeaOptions.from_mapping({**base, "degree": degree}), n, grading)
            wall, cpu = time.perf_counter(), time.process_time()
            r, _ = solve_level(level, force_N=CONTACT["normal_force_N"])
            wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
            window = r.extra.get("max_pressure_window") or {}
            row = {
                "tag": tag, "options": options or {}, "degree": degree, "elements_per_semi_axis": n,
                "grading": level.grading, "status": r.status, "dofs": r.extra.get("dofs"),
                "element_size_m": r.extra.get("element_size_m"), "wall_time_s": wall, "cpu_time_s": cpu,
                "timings_s": r.extra.get("timings_s"), "iterations": r.extra.get("newton_iterations"),
                "linear_solver": r.extra.get("linear_solver"), "normal_force_N": r.normal_force_N,
                "max_pressure_Pa": r.max_pressure_Pa, "window_relative_error": window.get("relative_error"),
                "max_pressure_peak_fit_Pa": r.extra.get("max_pressure_peak_fit_Pa"),
                "contact_area_m2": r.contact_area_m2, "peak_box_m": list(box) if box else None,
                "load": os.getloadavg()[0], "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            }  # fmt: skip
            with RAW.open("a") as fh:
                fh.write(json.dumps(row, default=float) + "\n")
            print(json.dumps({k: row[k] for k in ("tag", "degree", "elements_per_semi_axis", "dofs", "wall_time_s",
                                                  "max_pressure_Pa", "window_relative_error", "contact_area_m2")},
                             default=float), flush=True)  # fmt: skip


def bem_reference() -> None:
    """Our BEM on the same gap at CONTACT's force (load control), square elements of BEM_SIZES_M: the half-space
    solution the FEA converges to (the FEA's block is the same half-space truncated); written to BEM_RAW."""
    from rigid_dynamics.contact.bem.model import BemModel

    case, patch = _patch()
    rows = []
    for size in BEM_SIZES_M:
        t = time.perf_counter()
        r = BemModel().solve(patch.geometry, patch.creepage, case.material, normal_force_N=CONTACT["normal_force_N"],
                             options={"element_size_m": size})  # fmt: skip
        rows.append({"element_size_m": size, "status": r.status, "max_pressure_Pa": r.max_pressure_Pa,
                     "contact_area_m2": r.contact_area_m2, "contact_area_edge_m2": r.extra.get("contact_area_edge_m2"),
                     "wall_time_s": time.perf_counter() - t})  # fmt: skip
        print(rows[-1], flush=True)
    BEM_RAW.write_text(json.dumps(rows, indent=1, default=float))


def _series_estimate(rows: list[dict]) -> dict:
    from fea.refinement import FORCE_KEY, NODAL_KEY, estimate

    levels = [{"max_pressure": r["max_pressure_Pa"], "contact_area": r["contact_area_m2"], NODAL_KEY: True,
               "normal_force": None, FORCE_KEY: r["normal_force_N"]} for r in rows]  # fmt: skip
    levels[-1]["normal_force"] = rows[-1]["normal_force_N"]
    e = estimate(levels, None, approach_control=True, load_balanced=True)
    window = rows[-1]["window_relative_error"] or 0.0
    return {
        "max_pressure": e["relative_error"]["max_pressure"] + window,
        "max_pressure_mesh": e["mesh_relative_error"]["max_pressure"],
        "window": window,
        "contact_area": e["relative_error"]["contact_area"],
        "observed_order": e["observed_order"]["max_pressure"],
    }


def report() -> dict:
    rows = [json.loads(line) for line in RAW.read_text().splitlines() if line.strip()]
    groups: dict[str, list[dict]] = {}
    for r in rows:
        if r["status"] == "ok" and r["tag"] in SERIES_TAGS:  # the same meshes' other runs (MUMPS) are in RAW
            groups.setdefault(f"P{r['degree']}", []).append(r)
    series = {}
    for name, rs in groups.items():
        rs.sort(key=lambda r: r["elements_per_semi_axis"])
        ests = []
        for j in range(1, len(rs)):
            ests.append({"finest_n": rs[j]["elements_per_semi_axis"], "two_levels": _series_estimate(rs[j - 1 : j + 1]),
                         "three_levels": _series_estimate(rs[j - 2 : j + 1]) if j >= 2 else None})  # fmt: skip
        series[name] = {"levels": rs, "estimates": ests}
    bem = json.loads(BEM_RAW.read_text()) if BEM_RAW.exists() else []
    return {"machine": f"{platform.platform()}, {os.cpu_count()} CPUs", "contact": CONTACT, "bem": bem,
            "series": series}  # fmt: skip


def markdown(data: dict) -> str:
    c = data["contact"]
    ref = data["bem"][-1]  # the finest BEM grid: the half-space solution on the same gap
    lines = [
        "# FEA on the A-2.2 flange-root patch: P1 against P2, unknowns, time and error per level (issue 22)",
        "",
        f"Machine: {data['machine']} (shared; load at each level in the table). By "
        "benchmarks/bench_fea_flange_root_p2.py (its docstring says what is computed). Every level solved under load "
        f"control at CONTACT's force {c['normal_force_N']:.0f} N on the BEM equilibrium's gap (right wheel).",
        f"CONTACT (0.05 mm elements): {c['max_pressure_Pa'] / 1e6:.0f} MPa, {c['contact_area_m2'] * 1e6:.3f} mm2.",
        "",
        "Our BEM on the same gap at the same force (half-space; area: element count and sub-element edge, "
        "rigid_dynamics.contact.edge_area):",
        "",
        "| element [mm] | p max [MPa] | area count [mm2] | area edge [mm2] | time / s |",
        "|---|---|---|---|---|",
        *[
            f"| {b['element_size_m'] * 1e3:.3g} | {b['max_pressure_Pa'] / 1e6:.1f} | "
            f"{b['contact_area_m2'] * 1e6:.3f} | {b['contact_area_edge_m2'] * 1e6:.3f} | {b['wall_time_s']:.1f} |"
            for b in data["bem"]
        ],
        "",
        "| series | n/semi-axis | grading | DOFs | wall / s | CPU / s | load | p max [MPa] | p vs BEM | window err "
        "| area [mm2] | area vs BEM edge | stated p err (2 / 3 levels) | stated area err (2 / 3 levels) | p order |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, s in data["series"].items():
        ests = {e["finest_n"]: e for e in s["estimates"]}
        for r in s["levels"]:
            e = ests.get(r["elements_per_semi_axis"])
            two = e["two_levels"] if e else None
            three = e["three_levels"] if e else None

            def pct(x, key):
                return "-" if x is None or x[key] is None else f"{x[key]:.2%}"

            order = "-" if three is None or three["observed_order"] is None else f"{three['observed_order']:.2f}"
            we = r["window_relative_error"]
            lines.append(
                f"| {name} | {r['elements_per_semi_axis']:.3g} | {r['grading']:.3g} | {r['dofs']} | "
                f"{r['wall_time_s']:.1f} | {r['cpu_time_s']:.1f} | {r['load']:.1f} | "
                f"{r['max_pressure_Pa'] / 1e6:.1f} | "
                f"{r['max_pressure_Pa'] / ref['max_pressure_Pa'] - 1:+.2%} | {'-' if we is None else f'{we:.2%}'} | "
                f"{r['contact_area_m2'] * 1e6:.3f} | {r['contact_area_m2'] / ref['contact_area_edge_m2'] - 1:+.2%} | "
                f"{pct(two, 'max_pressure')} / {pct(three, 'max_pressure')} | "
                f"{pct(two, 'contact_area')} / {pct(three, 'contact_area')} | {order} |"
            )
    lines += [
        "",
        "Times: before fea.postprocess.pressure_on_grid triangulated only the nodes near its grid (about 20 s less per "
        "P2 level, 1-5 s per P1 level now). Stated errors: fea.refinement.estimate over these levels as a "
        "load-balanced series (nodal area; window error added to p). Findings and the CLI runs: "
        "fea_flange_root_p2_findings.md.",
    ]
    return "\n".join(lines) + "\n"


def main() -> None:
    if sys.argv[1:] == ["--bem"]:
        bem_reference()
        return
    if sys.argv[1:] == ["--report"]:
        from rigid_dynamics.files import write_text

        data = report()
        write_text(OUT / "fea_flange_root_p2.json", json.dumps(data, indent=1, default=float))
        write_text(OUT / "fea_flange_root_p2.md", markdown(data))
        print(markdown(data))
        return
    options, tag, specs, max_grading = {}, "", [], 9.0
    for arg in sys.argv[1:]:
        if arg.startswith("--options="):
            options = json.loads(arg.split("=", 1)[1])
        elif arg.startswith("--max-grading="):
            max_grading = float(arg.split("=", 1)[1])
        elif arg.startswith("--tag="):
            tag = arg.split("=", 1)[1]
        else:
            degree, ns = arg.split(":")
            specs.append((int(degree), [float(n) for n in ns.split(",")]))
    run(specs, options, tag, max_grading)


if __name__ == "__main__":
    main()
