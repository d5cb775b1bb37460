"""Conformal real-profile contact: the FEA of the two profiles against the half-space rungs, with stated errors.

Case (as comparisons/fea_report.py): Manchester benchmark profiles MBench_S1002_v3 on MBench_UIC60_v3 (1:40), the
wheelset shifted 6 mm towards the right rail, 50 kN per wheel, G 82 GPa, nu 0.28; the right wheel's patch at its
flange root (the search's patch: plane at the deepest point). Solved at the search's normal force (load control),
frictionless:

* ``hertz``: the quadric of the search's curvatures (half-space, quadric);
* ``bem``: the half-space BEM on the sampled gap, default grid refinement with its grid estimate (``grid_tolerance``
  0.02);
* ``fea`` rigid: a clamped elastic block under a rigid indenter with the sampled gap (a planar contact surface: the
  half-space's geometry, finite body), default refinement series (``mesh_tolerance`` 0.02);
* ``fea`` profiles: the rail and wheel sections meshed from the real profiles, two elastic bodies, no contact plane
  (the conformal geometry), default refinement series.

The FEA profiles row is the one without the half-space assumption: its difference from the BEM, judged against the
sum of the two stated errors, is the claim. Also recorded: the BEM patch's lateral extent in the contact plane.

Usage::

    .venv/bin/python benchmarks/bench_fea_conformal.py   # writes fea_conformal.json/md
"""

from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
WHEEL, RAIL = "MBench_S1002_v3", "MBench_UIC60_v3"


def _row(result, wall) -> dict:
    from comparisons.stated_errors import stated_errors

    return {
        "status": result.status,
        "message": result.message,
        "normal_force_N": result.normal_force_N,
        "max_pressure_Pa": result.max_pressure_Pa,
        "contact_area_m2": result.contact_area_m2,
        "stated_errors": stated_errors(result),
        "dofs": (result.extra or {}).get("dofs"),
        "wall_time_s": wall,
    }


def run() -> dict:
    import dolfinx_solver  # noqa: F401

    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
    from rigid_dynamics.materials import STEEL

    case = WheelsetCase(wheel_profile=WHEEL, rail_profile=RAIL, lateral_shift_m=6e-3, wheel_load_N=5e4)
    sol = solve_wheelset_case(
        case, STEEL, "hertz", options={"patches": "search", "search": {"field": True}, "spin_rate": "nominal"}
    )
    patch = next(p for p in sol.patches if p.side == "right")
    force = float(patch.result.normal_force_N)
    rows = {"hertz": _row(patch.result, 0.0)}
    runs = (
        ("bem", {}),
        ("fea rigid", {"stresses": False}),
        ("fea profiles", {"stresses": False, "formulation": "profiles", "wheel_profile": WHEEL, "rail_profile": RAIL}),
    )
    for label, options in runs:
        model = get_model(label.split()[0])
        start = time.perf_counter()
        result = model.solve(patch.geometry, patch.creepage, STEEL, normal_force_N=force, options=options)
        rows[label] = _row(result, time.perf_counter() - start)
        if result.fields is not None and label == "bem":
            mask = result.fields.in_contact
            ys = result.fields.y_m[mask.any(axis=1)]
            rows[label]["lateral_extent_m"] = [float(ys.min()), float(ys.max())]
        print(label, rows[label]["status"], rows[label]["max_pressure_Pa"], rows[label]["contact_area_m2"],
              rows[label]["stated_errors"], f"{rows[label]['wall_time_s']:.0f} s", flush=True)  # fmt: skip
    return {
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}",
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "case": {"wheel_profile": WHEEL, "rail_profile": RAIL, "lateral_shift_m": 6e-3, "wheel_load_N": 5e4,
                 "side": "right", "contact_angle_rad": float(patch.geometry.contact_angle_rad),
                 "curvatures_1_per_m": [patch.geometry.curvature_long_1_per_m,
                                        patch.geometry.curvature_lat_1_per_m],
                 "normal_force_N": force},
        "rows": rows,
    }  # fmt: skip


def _agreement(a: dict, b: dict, key: str, name: str) -> str:
    from comparisons.stated_errors import agreement

    ea = (a["stated_errors"] or {}).get(name)
    eb = (b["stated_errors"] or {}).get(name)
    if a[key] is None or b[key] is None:
        return "-"
    judged = agreement(a[key], b[key], ea, eb)
    verdict = {True: "agree", False: "differ", None: "undecided: an error not stated"}[judged["agree"]]
    allowed = "" if judged["allowed"] is None else f", allowed {judged['allowed']:.1%}"
    return f"{a[key] / b[key] - 1:+.1%} ({verdict}{allowed})"


def markdown(data: dict) -> str:
    c = data["case"]
    lines = [
        "# Conformal real-profile contact: FEA of the two profiles against the half-space rungs (issue 22)",
        "",
        f"Run {data['date']} on {data['machine']} by benchmarks/bench_fea_conformal.py (its docstring gives the case "
        f"and what each row solves). Right wheel, contact angle {c['contact_angle_rad']:.3f} rad, curvatures "
        f"{c['curvatures_1_per_m'][0]:.3g} / {c['curvatures_1_per_m'][1]:.3g} 1/m, normal force "
        f"{c['normal_force_N'] / 1e3:.2f} kN (load control, frictionless).",
        "",
        "| rung | status | p max [MPa] | stated | area [mm2] | stated | DOFs | time / s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for label, r in data["rows"].items():
        e = r["stated_errors"] or {}

        def pct(name, e=e):
            return "-" if e.get(name) is None else f"{e[name]:.1%}"

        lines.append(
            f"| {label} | {r['status']} | {r['max_pressure_Pa'] / 1e6:.0f} | {pct('max_pressure')} | "
            f"{r['contact_area_m2'] * 1e6:.1f} | {pct('contact_area')} | {r['dofs'] or '-'} | "
            f"{r['wall_time_s']:.0f} |"
        )
    rows = data["rows"]
    lines += ["", "| FEA profiles against | max pressure | area |", "|---|---|---|"]
    for other in ("bem", "fea rigid", "hertz"):
        if other in rows and "fea profiles" in rows:
            a, b = rows["fea profiles"], rows[other]
            lines.append(
                f"| {other} | {_agreement(a, b, 'max_pressure_Pa', 'max_pressure')} | "
                f"{_agreement(a, b, 'contact_area_m2', 'contact_area')} |"
            )
    return "\n".join(lines) + "\n"


def main() -> None:
    from rigid_dynamics.files import write_text

    data = run()
    write_text(OUT / "fea_conformal.json", json.dumps(data, indent=1, default=float))
    write_text(OUT / "fea_conformal.md", markdown(data))
    print(markdown(data))


if __name__ == "__main__":
    main()
