"""The FEA's max pressure on sampled patches: the peak box and the fixed-window fit against the shrinking-radius fit.

Two patches, load control, frictionless FEA (rigid formulation, P1), one solve per level of the default series
(6 x 1.5^k elements per semi-axis of the mesh box, grading 0.4 / 1.5^k) with ``mesh_tolerance`` None:

* ``hertz``: a Hertz gap h = 0.46 x^2 + 0.15 y^2 (1/m) given as samples (601 x 601 on +-30 mm), 100 kN, steel
  (E 210 GPa, nu 0.3): the sampled path (full block) with a closed-form p0 = 428.50 MPa (Johnson 1985, eq 3.64);
* ``demo``: the demo's peak patch (polygonal-wheel, contact_tolerance 0.1, the largest normal force after 0.3 s),
  against the BEM (default options) on the same patch and force.

For each level, without and with the peak box (fea.model, "Peak box": located by one solve a level coarser,
``peak_refinement`` 3), the script records the unknowns, the wall time and the candidate max-pressure estimates
computed from the same nodal forces: the reported one of fea.model, the quadric cap over a radius of k local element
sizes (k = 3 .. 6, a fixed count of nodes), and the area-weighted cap over a disc of fixed radius R (0.6 of the peak
box's smaller half-width) with its model error from R / 1.5 (fea.postprocess.window_peak).

Usage::

    .venv/bin/python benchmarks/bench_fea_peak_pressure.py [hertz=9] [demo=13.5]   # finest level per case; writes
                                                                                  # fea_peak_pressure.json/md
"""

from __future__ import annotations

import dataclasses
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
RATIO = 1.5


def _patch(name: str):
    from types import SimpleNamespace

    from rigid_dynamics.materials import Material

    if name == "hertz":
        from fea.hertz_reference import hertz_elliptic
        from rigid_dynamics.contact.types import ContactGeometry, Creepage, UndeformedDistance

        steel = Material.from_young(210e9, 0.3, 0.3)
        x = np.linspace(-0.03, 0.03, 601)
        gx, gy = np.meshgrid(x, x)
        gap = UndeformedDistance(x, x, 0.46 * gx**2 + 0.15 * gy**2)
        geo = ContactGeometry(0.46, 0.15, approach_m=0.0, undeformed=gap)
        p0 = hertz_elliptic(0.46, 0.15, 1e5, steel.combined_modulus_Pa).max_pressure_Pa
        return SimpleNamespace(geometry=geo, creepage=Creepage(), material=steel, normal_force_N=1e5), p0, "Hertz p0"
    from comparisons.demo import peak_patch_case
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.wheelset import simulate
    from wheelrail.comparison_commands import DEMO_TOLERANCE
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = dataclasses.replace(load_scene(resolve_scene_path("polygonal-wheel")), contact_tolerance=DEMO_TOLERANCE)
    patch = peak_patch_case(simulate(scene))
    bem = get_model("bem").solve(
        patch.geometry, patch.creepage, patch.material, normal_force_N=patch.normal_force_N, options={}
    )
    error = (bem.extra.get("discretisation_error") or {}).get("relative_error", {}).get("max_pressure")
    return patch, bem.max_pressure_Pa, f"BEM (default options, stated {error:.2%})"


def _candidates(capture: dict, h_local: float, window_radius: float | None) -> dict:
    from fea.postprocess import filtered_pressure, peak_pressure, window_peak

    xy, force, weight = capture["xy"], capture["force"], capture["weight"]
    ok = weight > 1e-9 * weight.max()
    xy, force, weight = xy[ok], force[ok], weight[ok]
    nodal, usable = force / weight, np.ones(len(xy), bool)
    average = filtered_pressure(xy, force, weight, xy, 1.5 * h_local)
    guess = xy[int(np.argmax(average))]
    out = {"largest_average_Pa": float(average.max())}
    for k in (3, 4, 5, 6):
        out[f"cap_{k}h_Pa"] = peak_pressure(xy, nodal, usable, guess, k * h_local)
    if window_radius is not None:
        big = window_peak(xy, force, weight, guess, window_radius)
        small = window_peak(xy, force, weight, big[1], window_radius / RATIO) if big else None
        out["window_Pa"] = big[0] if big else None
        out["window_small_Pa"] = small[0] if small else None
    return out


def series(name: str, max_n: float) -> dict:
    import fea.postprocess as post
    from fea.model import WINDOW_FRACTION, FeaModel, FeaOptions

    capture = {}
    original = post.filtered_pressure

    def spy(xy_all, force_all, weight_all, points, radius_m):
        capture.update(xy=xy_all.copy(), force=force_all.copy(), weight=weight_all.copy())
        return original(xy_all, force_all, weight_all, points, radius_m)

    post.filtered_pressure = spy
    patch, reference, label = _patch(name)
    model = FeaModel()
    out = {"case": name, "reference_Pa": reference, "reference": label, "normal_force_N": patch.normal_force_N}
    for refinement in (1.0, 3.0):
        opts = FeaOptions.from_mapping({"stresses": False, "peak_refinement": max(refinement, 1.0)})
        solve_level, peak = model.level_solver((patch.geometry, patch.creepage, patch.material, patch.normal_force_N))
        box = None
        if refinement > 1:
            box, record = model._locate_peak(solve_level, opts, peak)
            out["peak_box"] = record
        peak["box"] = box
        rows, n = [], 4.0
        while n <= max_n + 1e-9:
            level = dataclasses.replace(opts, elements_per_semi_axis=n, grading=0.4 * 6 / n, mesh_tolerance=None)
            start = time.perf_counter()
            result, _ = solve_level(level)
            h_local = result.extra["element_size_m"] / (refinement if box else 1.0)
            radius = WINDOW_FRACTION * min(box[2], box[3]) if box else None
            rows.append({
                "elements_per_semi_axis": n, "element_size_m": result.extra["element_size_m"], "h_local_m": h_local,
                "dofs": result.extra["dofs"], "wall_time_s": time.perf_counter() - start, "status": result.status,
                "reported_Pa": result.max_pressure_Pa, "contact_area_m2": result.contact_area_m2,
                **_candidates(capture, h_local, radius),
            })  # fmt: skip
            print(name, refinement, rows[-1], flush=True)
            n *= RATIO
        out["peak_box_off" if refinement == 1 else "peak_box_on"] = rows
    post.filtered_pressure = original
    return out


def markdown(data: list[dict], machine: str) -> str:
    lines = ["# FEA max pressure on sampled patches: peak box and fixed-window fit (issue 22)", "", machine, ""]
    keys = ("reported_Pa", "window_Pa", "largest_average_Pa", "cap_3h_Pa", "cap_5h_Pa")
    for case in data:
        ref = case["reference_Pa"]
        lines += [f"## {case['case']} ({case['reference']} {ref / 1e6:.1f} MPa)", ""]
        for part in ("peak_box_off", "peak_box_on"):
            lines += [f"### {part}", "", "| n | h local [mm] | DOFs | time / s | " + " | ".join(
                k.removesuffix("_Pa") + " [%]" for k in keys) + " | window model error [%] |",
                "|" + "---|" * (5 + len(keys))]  # fmt: skip
            for row in case.get(part, []):
                cells = [f"{(row[k] / ref - 1) * 100:+.2f}" if row.get(k) else "-" for k in keys]
                small, big = row.get("window_small_Pa"), row.get("window_Pa")
                model_error = f"{abs(big - small) / (1 - RATIO**-4) / big * 100:.2f}" if small and big else "-"
                lines.append(f"| {row['elements_per_semi_axis']:.3g} | {row['h_local_m'] * 1e3:.3f} | {row['dofs']} | "
                             f"{row['wall_time_s']:.1f} | " + " | ".join(cells) + f" | {model_error} |")  # fmt: skip
            lines.append("")
    return "\n".join(lines) + "\n"


def main() -> None:
    finest = dict(arg.split("=") for arg in sys.argv[1:]) or {"hertz": "9", "demo": "13.5"}
    machine = (f"Machine: {platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}; load "
               f"average at the start {[round(v, 2) for v in os.getloadavg()]}.")  # fmt: skip
    data = [series(name, float(n)) for name, n in finest.items()]
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "fea_peak_pressure.json").write_text(json.dumps(data, indent=1, default=float))
    (OUT / "fea_peak_pressure.md").write_text(markdown(data, machine))
    print(f"wrote {OUT / 'fea_peak_pressure.md'}")


if __name__ == "__main__":
    main()
