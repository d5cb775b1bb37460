"""The contact area's stated error against its true error: the BEM's element count and the FEA's nodal area.

Part 1, BEM on sampled Hertz gaps (h = A x^2 + B y^2 given as samples, so the area is the element count, not the
fitted ellipse): named grids 20 ... 160 elements a side, each with its companions (grid_error_estimate; the area's
estimate from where the edge lies within its cells, rigid_dynamics.contact.edge_area), against Hertz's closed-form
area pi a b (Johnson 1985, sec. 4.2; fea.hertz_reference).

Part 2, BEM on the demo's peak patch (polygonal-wheel, auto at contact_tolerance 0.1, 99 kN; sampled gap): named
grids 32 ... 256 against the 512 x 512 count (itself stated with its error).

Part 3, FEA nodal area on the sampled Hertz circle (full block, D = 40 semi-axes, levels 4, 6, 9 elements per
semi-axis): the stated error of each level from the levels up to it (fea.refinement.nodal_area_error) against the
closed form.

Part 4 (optional, ``--demo-compare PATH``): the FEA levels of a demo's compare.json against Part 2's reference.

Run: ``PYTHONPATH=. .venv/bin/python benchmarks/bench_area_edge_error.py [--demo-compare DIR/compare/compare.json]``
-> benchmarks/results/area_edge_error.json and .md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"
HERTZ = ((0.5, 0.5, 1e5), (0.46, 0.15, 1e5), (2.0, 0.2, 5e4))
"""(A, B, P): circle, ellipse a/b 0.48, narrow ellipse a/b 0.22."""


def _sampled(a_curv, b_curv):
    from rigid_dynamics.contact.types import ContactGeometry, UndeformedDistance

    x = np.linspace(-0.03, 0.03, 601)
    gx, gy = np.meshgrid(x, x)
    exact = lambda xx, yy: a_curv * xx**2 + b_curv * yy**2  # noqa: E731
    gap = UndeformedDistance(x, x, exact(gx, gy), exact=exact)
    return ContactGeometry(a_curv, b_curv, approach_m=0.0, undeformed=gap)


def _bem_row(label, geometry, creepage, material, force, n, reference):
    from rigid_dynamics.contact.registry import get_model

    r = get_model("bem").solve(geometry, creepage, material, normal_force_N=force, options={"nx": n, "ny": n})
    stated = r.extra["grid_error"]["contact_area_m2"]
    true = r.contact_area_m2 - reference
    return {"case": label, "grid": n, "area_mm2": r.contact_area_m2 * 1e6, "edge_mm2":
            r.extra["contact_area_edge_m2"] * 1e6, "stated_mm2": stated * 1e6, "true_mm2": true * 1e6,
            "stated_rel": stated / r.contact_area_m2, "true_rel": true / reference,
            "ratio": stated / abs(true) if true else math.inf}  # fmt: skip


def part1():
    from fea.hertz_reference import hertz_elliptic
    from rigid_dynamics.contact.types import Creepage
    from rigid_dynamics.materials import Material

    steel = Material.from_young(210e9, 0.3, 0.3)
    rows = []
    for a_curv, b_curv, force in HERTZ:
        ref = hertz_elliptic(a_curv, b_curv, force, steel.combined_modulus_Pa)
        exact = math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m
        for n in (20, 40, 80, 160):
            label = f"Hertz samples A {a_curv:g} B {b_curv:g} ({force / 1e3:g} kN)"
            rows.append(_bem_row(label, _sampled(a_curv, b_curv), Creepage(), steel, force, n, exact))
    return rows


def demo_patch():
    from comparisons.demo import peak_patch_case
    from rigid_dynamics.wheelset import simulate
    from wheelrail.comparison_commands import DEMO_PATCH_GEOMETRY, DEMO_TOLERANCE
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = dataclasses.replace(
        load_scene(resolve_scene_path("polygonal-wheel")), contact_model="auto", contact_tolerance=DEMO_TOLERANCE,
        patch_geometry=DEMO_PATCH_GEOMETRY,
    )  # fmt: skip
    return peak_patch_case(simulate(scene))


def part2(patch):
    from rigid_dynamics.contact.registry import get_model

    ref = get_model("bem").solve(patch.geometry, patch.creepage, patch.material, normal_force_N=patch.normal_force_N,
                                 options={"nx": 512, "ny": 512})  # fmt: skip
    reference = ref.contact_area_m2
    rows = [_bem_row("demo peak patch", patch.geometry, patch.creepage, patch.material, patch.normal_force_N, n,
                     reference) for n in (32, 64, 128, 256)]  # fmt: skip
    return rows, {"area_mm2": reference * 1e6, "stated_mm2": ref.extra["grid_error"]["contact_area_m2"] * 1e6,
                  "edge_mm2": ref.extra["contact_area_edge_m2"] * 1e6}  # fmt: skip


def part3():
    from fea.hertz_reference import hertz_elliptic
    from fea.model import FeaModel
    from fea.refinement import nodal_area_error
    from rigid_dynamics.contact.types import Creepage
    from rigid_dynamics.materials import Material

    steel = Material.from_young(210e9, 0.3, 0.3)
    ref = hertz_elliptic(0.5, 0.5, 1e5, steel.combined_modulus_Pa)
    exact = math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m
    areas, rows = [], []
    for n in (4.0, 6.0, 9.0):
        options = {"domain_factor": 40.0, "mesh_tolerance": None, "elements_per_semi_axis": n, "stresses": False}
        r = FeaModel().solve(_sampled(0.5, 0.5), Creepage(), steel, normal_force_N=1e5, options=options)
        areas.append(r.contact_area_m2)
        stated = nodal_area_error(areas) if len(areas) >= 2 else None
        true = r.contact_area_m2 - exact
        rows.append({"case": "FEA, Hertz samples A 0.5 B 0.5 (100 kN)", "grid": n, "area_mm2": r.contact_area_m2 * 1e6,
                     "stated_mm2": None if stated is None else stated * 1e6, "true_mm2": true * 1e6,
                     "stated_rel": None if stated is None else stated / r.contact_area_m2, "true_rel": true / exact,
                     "ratio": None if stated is None else stated / abs(true)})  # fmt: skip
    return rows


def part4(path, reference_mm2):
    from fea.refinement import nodal_area_error

    levels = json.loads(Path(path).read_text())["models"]["fea"]["error_parts"]["levels"]
    areas, rows = [], []
    for level in levels:
        areas.append(level["contact_area"] * 1e6)
        stated = nodal_area_error(areas) if len(areas) >= 2 else None
        true = areas[-1] - reference_mm2
        rows.append({"case": "FEA, demo peak patch", "grid": level["elements_per_semi_axis"], "area_mm2": areas[-1],
                     "stated_mm2": stated, "true_mm2": true, "true_rel": true / reference_mm2,
                     "stated_rel": None if stated is None else stated / areas[-1],
                     "ratio": None if stated is None else stated / abs(true)})  # fmt: skip
    return rows


def _fmt(v, pct=False):
    if v is None:
        return "-"
    return f"{100 * v:+.2f} %" if pct else f"{v:.2f}"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--demo-compare", help="a demo's compare/compare.json (its FEA levels)")
    args = parser.parse_args()
    t0 = time.perf_counter()
    rows = part1()
    patch = demo_patch()
    demo_rows, reference = part2(patch)
    rows += demo_rows
    rows += part3()
    if args.demo_compare:
        rows += part4(args.demo_compare, reference["area_mm2"])
    out = {"rows": rows, "demo_reference": reference, "wall_time_s": time.perf_counter() - t0,
           "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}"}  # fmt: skip
    RESULTS.joinpath("area_edge_error.json").write_text(json.dumps(out, indent=1) + "\n")
    lines = [
        "# The contact area's stated error against its true error (benchmarks/bench_area_edge_error.py)",
        "",
        f"Machine: {out['machine']}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; "
        f"{out['wall_time_s']:.0f} s in all.",
        "",
        "BEM rows: the element count of a sampled gap, stated error from where its edge lies within its cells "
        "(rigid_dynamics.contact.edge_area, companions twice as coarse). FEA rows: the nodal area, stated error "
        "from the levels up to that one (fea.refinement.nodal_area_error). True error against Hertz's closed form, "
        f"or for the demo's peak patch against the BEM's 512 x 512 count {reference['area_mm2']:.2f} mm2 (its own "
        f"stated error {reference['stated_mm2']:.2f} mm2; reconstructed edge {reference['edge_mm2']:.2f} mm2).",
        "",
        "| case | grid / elements per semi-axis | area mm2 | stated mm2 | true mm2 | stated | true | stated / true |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['grid']:g} | {r['area_mm2']:.2f} | {_fmt(r['stated_mm2'])} | {r['true_mm2']:+.2f} | "
            f"{_fmt(r['stated_rel'], True).lstrip('+')} | {_fmt(r['true_rel'], True)} | {_fmt(r['ratio'])} |"
        )
    RESULTS.joinpath("area_edge_error.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
