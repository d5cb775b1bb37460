"""The FEA's peak box (fea.model, "Peak box") on the demo's peak patch against the block size: a property of the patch?

The demo's peak patch (polygonal-wheel, auto at contact_tolerance 0.1, Hertz's ellipse per patch in the run, the
largest normal force after 0.3 s, re-searched with its sampled gap) is located with blocks of D semi-axes. For each
D the script records both passes of ``FeaModel._locate_peak`` (the coarse solve without a box and the solve with that
box meshed ``peak_refinement`` times finer) and, as the independent reference, the region where the half-space
solution (the BEM at its default options on the same gap and force) is at least ``PEAK_LEVEL`` of its top.

Usage::

    .venv/bin/python benchmarks/bench_fea_peak_box.py [D ...]   # default 19 20 21 25 40; writes fea_peak_box.json/md
"""

from __future__ import annotations

import dataclasses
import json
import os
import platform
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def main(factors: list[float]) -> dict:
    from comparisons.demo import peak_patch_case
    from fea.model import PEAK_LEVEL, FeaModel, FeaOptions
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.wheelset import simulate
    from wheelrail.comparison_commands import DEMO_PATCH_GEOMETRY, DEMO_TOLERANCE
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = dataclasses.replace(
        load_scene(resolve_scene_path("polygonal-wheel")), contact_model="auto", contact_tolerance=DEMO_TOLERANCE,
        patch_geometry=DEMO_PATCH_GEOMETRY,
    )  # fmt: skip
    patch = peak_patch_case(simulate(scene))
    bem = get_model("bem").solve(patch.geometry, patch.creepage, patch.material, normal_force_N=patch.normal_force_N)
    gx, gy = np.meshgrid(bem.fields.x_m, bem.fields.y_m)
    top = bem.fields.pressure_Pa >= PEAK_LEVEL * bem.fields.pressure_Pa.max()
    out = {
        "normal_force_N": patch.normal_force_N,
        "time_s": patch.time_s,
        "bem": {
            "max_pressure_Pa": bem.max_pressure_Pa,
            "top_x_m": [float(gx[top].min()), float(gx[top].max())],
            "top_y_m": [float(gy[top].min()), float(gy[top].max())],
        },  # fmt: skip
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, load {os.getloadavg()}",
        "rows": [],
    }
    model = FeaModel()
    for factor in factors:
        opts = FeaOptions.from_mapping({"stresses": False, "domain_factor": factor})
        solve_level, peak = model.level_solver((patch.geometry, patch.creepage, patch.material, patch.normal_force_N))
        box, record = model._locate_peak(solve_level, opts, peak)
        out["rows"].append({"domain_factor": factor, **record})
        print(factor, record, flush=True)
    return out


def _markdown(out: dict) -> str:
    bem = out["bem"]
    lines = [
        "# FEA peak box against the block size (demo's peak patch)",
        "",
        f"Machine: {out['machine']}. Patch: N = {out['normal_force_N'] / 1e3:.2f} kN at t = {out['time_s']:.3f} s.",
        f"Half-space reference (BEM, default options): max pressure {bem['max_pressure_Pa'] / 1e6:.1f} MPa, >= 0.85 "
        f"of it for x in [{bem['top_x_m'][0] * 1e3:.2f}, {bem['top_x_m'][1] * 1e3:.2f}] mm, y in "
        f"[{bem['top_y_m'][0] * 1e3:.2f}, {bem['top_y_m'][1] * 1e3:.2f}] mm.",
        "",
        "Box: centre (x, y) and full size (2a x 2b), mm; filtered max: the pass's largest patch-averaged pressure.",
        "",
        "| D | coarse box | coarse filtered max [MPa] | resolved box | unknowns (coarse / resolved) | time / s |",
        "|---|---|---|---|---|---|",
    ]

    def box(b):
        return f"({b[0] * 1e3:.2f}, {b[1] * 1e3:.2f}) {2 * b[2] * 1e3:.2f} x {2 * b[3] * 1e3:.2f}"

    for row in out["rows"]:
        p = row["passes"]
        lines.append(
            f"| {row['domain_factor']:g} | {box(p[0]['box_m'])} | {p[0]['max_pressure_filtered_Pa'] / 1e6:.0f} | "
            f"{box(p[1]['box_m'])} | {p[0]['dofs']} / {p[1]['dofs']} | {row['wall_time_s']:.1f} |"
        )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    factors = [float(a) for a in sys.argv[1:]] or [19.0, 20.0, 21.0, 25.0, 40.0]
    result = main(factors)
    (OUT / "fea_peak_box.json").write_text(json.dumps(result, indent=1, default=float))
    (OUT / "fea_peak_box.md").write_text(_markdown(result))
