"""Real-time factor of the wheelset simulation (simulated seconds per wall-clock second), with errors beside it.

Cases (scene polygonal-wheel: S1002/UIC60 1:40, 3rd-order polygon 0.3 mm, 100 km/h, Hertz + FASTSIM 20x20,
classical RK4 with a 0.5 ms step as in the scene file unless the case name gives another step):

* ``search``: 3-D contact search at every RHS evaluation (rigid_dynamics.contact.search), with the polygon, no
  reuse at all (the unmodified path, the reference of the search cases);
* ``search-reuse``: the same with SearchProvider(reuse_m=1e-5): an identical pose reuses the last search, a pose
  within 10 um (RK4's two stages at t + h/2, the last stage and the next step's first) reuses it with the
  first-order rigid-body correction (profiles.py);
* ``search-ideal``: the 3-D search without the polygon;
* ``tables-ideal``, ``tables-polygon``: contact-geometry tables over lateral shift and roll (ideal geometry; with
  the polygon by the running-direction section of providers.py), the Python right-hand side;
* ``*-compiled-*``: the same tables in the compiled RK4 loop (rigid_dynamics.wheelset.compiled; FASTSIM by the
  contact package's strip kernel, the polygon evaluated in the loop), 2 s simulated;
* ``hunting-conical``: the analytic conical provider, Kalker linear creep, RK45.

Error beside the time (largest difference of the wheel normal forces relative to the static wheel load, and of
the lateral displacement, over the common interval), against the case named in the ``reference`` column:
``search`` for search-reuse and for the table cases with the polygon (different geometry methods: see the notes),
``search-ideal`` for tables-ideal, and a fine-step run (``fine-*``: the compiled path with a 1/16 ms step, which
equals the Python path to ~1e-14, tests/test_dynamics_compiled.py) for the compiled cases (time-step error).
Targets (issue): >= 10x real time with the 3-D search, >= 100x with tables, on one core.

Run: ``.venv/bin/python benchmarks/bench_dynamics.py [--search-time 0.1] [--tables-time 0.5]``; writes
benchmarks/results/dynamics.json and dynamics.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.wheelset import DynamicsScene, Irregularities, simulate  # noqa: E402
from rigid_dynamics.wheelset.profiles import SearchProvider  # noqa: E402
from rigid_dynamics.wheelset.simulate import build_provider  # noqa: E402
from wheelrail.config import build_dataclass  # noqa: E402

NOTES = """\
Notes.

* What the search path spends its time on: before the compiled irregular search (cProfile, 0.01 s of the
  polygonal scene, 12 ms per RHS) the 3-D search was ~95 % (two sides, ~6 ms each, numpy on the exact irregular
  surfaces). The search now runs polygon, rounded flat and corrugation through its numba kernels (Hermite table of
  the ideal profile + closed-form irregularities; benchmarks/results/search.md: ~1.3 ms per side), and ~0.6 ms
  per side goes to evaluating each patch on the exact surfaces with scipy; RHS ~3.6 ms. The FASTSIM contact solve
  and the equations of motion are a small part. The gap field is off (``field=False``) for the dynamics.
* search-reuse halves the searches (RK4's two stages at t + h/2 differ by h^2/4 times the accelerations, and the
  last stage of a step and the first of the next by the same order; the output sample is the next step's first
  stage exactly). Its difference to the unmodified search is of the size of the unmodified search's own step-size
  sensitivity (search-0.25ms against search): the largest wheel-load differences of both come from the S1002/UIC60
  double gap minimum near the centred position, where the search's deepest point, and with it the Hertz patch,
  jumps between two places 10 mm apart, so that any small perturbation shifts the jump instants
  (tests/test_dynamics_search.py checks the reuse's approach against a fresh search: error 3e-10 m for a 2e-5 pose
  change, falling 4x per halving).
* The tables: the Python right-hand side costs 0.35-0.6 ms per call (numpy on 2-4 candidates); the compiled loop
  about 1.2 us (Vermeulen-Johnson), 6-8 us (FASTSIM 20 x 20, of which the strip kernel for the two patches is
  about 5 us) and 12-14 us (FASTSIM with the polygon: the running-direction section, an 81-angle grid and 3 Newton
  steps per candidate). The compiled path equals the Python path to ~1e-14 (tests/test_dynamics_compiled.py).
* Time-step error of the compiled cases against a 1/16 ms run: on ideal geometry 0.4 % (0.5 ms) and 4.5 % (1 ms)
  of the static wheel load at most. With the polygon the maximum stays large at every step size (a separate step-
  halving study of the compiled polygon case, 1 ms ... 1/16 ms against 1/32 ms, not run by this script: 0.77,
  0.58, 0.14, 0.30, 0.47) while the median converges (0.045, 0.013, 0.005, 0.0024, 0.0020): the table candidates
  switch between one and two patches per wheel near the centre (the same double minimum), and the switching
  instants move with the step.
* Targets. Tables >= 100x: reached on ideal geometry with Vermeulen-Johnson at a 1 ms step (4.5 % largest wheel-
  load error against the fine step; 90-100x at the scene's 0.5 ms, 0.4 %), not with FASTSIM (about 18x at 0.5 ms
  and 30x at 1 ms on ideal geometry, about 9x / 15x with the polygon; see the table): an RK4 step of 0.5 ms costs
  4.5 RHS calls (with the output sample), so 100x asks for ~1.1 us per call, below the cost of FASTSIM's 2 x 400
  strip elements alone. The 3-D search (about 0.01x, 0.02x with reuse) is three orders of magnitude short of 10x:
  that needs a compiled search on irregular surfaces (the contact search's owners) or the tables with the polygon
  by the running-direction section (tables-polygon-compiled, 9-15x, the geometry differing from the search as
  described above).
"""


def load_scene(name: str) -> DynamicsScene:
    with open(ROOT / "wheelrail" / "scenes" / f"{name}.toml", "rb") as handle:
        return build_dataclass(DynamicsScene, tomllib.load(handle))


def run_case(name, scene, provider_name, compiled=None, provider=None):
    started = time.perf_counter()
    if provider is None:
        provider = build_provider(replace(scene, contact_provider=provider_name))
    setup = time.perf_counter() - started
    result = simulate(scene, provider=provider, compiled=compiled)
    per_rhs = result.wall_time_s / max(result.rhs_evaluations, 1)
    record = {
        "case": name,
        "provider": result.provider,
        "contact_model": result.contact_model,
        "method": result.method,
        "step_ms": 1e3 * scene.integrator.fixed_step_s if result.method == "RK4" else float("nan"),
        "status": result.status,
        "simulated_time_s": result.simulated_time_s,
        "wall_time_s": result.wall_time_s,
        "setup_time_s": setup,
        "real_time_factor": result.real_time_factor,
        "rhs_evaluations": result.rhs_evaluations,
        "wall_time_per_rhs_ms": 1e3 * per_rhs,
        "peak_normal_force_N": result.summary()["peak_normal_force_N"],
    }
    return record, result


def compare(result, reference, static_load):
    n = min(len(result.t), len(reference.t))
    if n == 0:
        return {}
    diff = np.abs(result.wheel_normal_force_N[:n] - reference.wheel_normal_force_N[:n]) / static_load
    lateral = np.max(np.abs(result.states[:n, 1] - reference.states[:n, 1]))
    return {
        "max_normal_force_difference_rel": float(np.max(diff)),
        "median_normal_force_difference_rel": float(np.median(diff)),
        "max_lateral_difference_m": float(lateral),
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--search-time", type=float, default=0.1, help="simulated time of the search case, s")
    parser.add_argument("--tables-time", type=float, default=0.5, help="simulated time of the table cases, s")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = parser.parse_args(argv)

    polygon = load_scene("polygonal-wheel")
    hunting = load_scene("hunting-conical")
    static = polygon.static_wheel_load_N
    records = []

    def add(rec, result=None, reference=None, ref_name=None):
        if reference is not None:
            rec.update(compare(result, reference, static))
            rec["reference"] = ref_name
        records.append(rec)

    short = replace(polygon, duration_s=args.search_time)
    plain = SearchProvider(polygon.wheelset, polygon.track, polygon.irregularities)
    plain.patches = plain._search  # the unmodified path: a search at every call
    search_rec, search_res = run_case("search", short, "search", provider=plain)
    add(search_rec)
    reusing = SearchProvider(polygon.wheelset, polygon.track, surfaces=plain.surfaces, reuse_m=1e-5)
    rec, res = run_case("search-reuse", short, "search", provider=reusing)
    rec["searches_reused"] = reusing.reused
    add(rec, res, search_res, "search")
    half = replace(short, integrator=replace(short.integrator, fixed_step_s=2.5e-4))
    rec, res = run_case("search-0.25ms", half, "search", provider=plain)
    add(rec, res, search_res, "search")
    ideal = replace(polygon, irregularities=Irregularities(), duration_s=args.tables_time)
    rec_ideal_search, res_ideal_search = run_case("search-ideal", replace(ideal, duration_s=args.search_time), "search")
    add(rec_ideal_search)
    ideal_tables = build_provider(replace(ideal, contact_provider="tables"))
    polygon_tables = build_provider(replace(polygon, contact_provider="tables"))
    rec, res = run_case("tables-ideal", ideal, "tables", False, ideal_tables)
    add(rec, res, res_ideal_search, "search-ideal")
    rec, res = run_case(
        "tables-polygon", replace(polygon, duration_s=args.tables_time), "tables", False, polygon_tables
    )
    add(rec, res, search_res, "search")
    rec, _ = run_case("hunting-conical", replace(hunting, duration_s=1.0), "conical")
    add(rec)

    fine_step = 6.25e-5
    for label, base, provider in (
        ("tables-ideal", replace(ideal, duration_s=2.0), ideal_tables),
        ("tables-polygon", replace(polygon, duration_s=2.0), polygon_tables),
        ("tables-ideal-vj", replace(ideal, contact_model="vermeulen-johnson", duration_s=2.0), ideal_tables),
    ):
        simulate(replace(base, duration_s=0.01), provider=provider, compiled=True)  # load the compiled code
        fine = replace(base, integrator=replace(base.integrator, fixed_step_s=fine_step))
        _, reference = run_case(f"fine-{label}", fine, "tables", True, provider)
        for step in (5e-4, 1e-3):
            scene = replace(base, integrator=replace(base.integrator, fixed_step_s=step))
            rec, res = run_case(f"{label}-compiled-{step * 1e3:g}ms", scene, "tables", True, provider)
            add(rec, res, reference, f"fine-{label} ({fine_step * 1e3:g} ms)")

    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "note": "one process on a 2-core machine shared with other jobs; wall times include Python overhead",
    }
    payload = {"benchmark": "wheelset dynamics real-time factor", "machine": machine, "cases": records}
    args.out.mkdir(parents=True, exist_ok=True)
    lines = [
        "# Wheelset dynamics: real-time factor",
        "",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs, Python {machine['python']}, "
        f"numpy {machine['numpy']}. {machine['note']}.",
        "",
        "Targets (issue 5): >= 10x real time with the 3-D search, >= 100x with tables (one core).",
        "",
        "| case | provider | model | method, step ms | simulated s | wall s | real-time factor | RHS evals | us/RHS | "
        "reference | max dN/N0 | median dN/N0 | max dy (m) | status |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in records:
        lines.append(
            f"| {r['case']} | {r['provider']} | {r['contact_model']} | {r['method']} {r['step_ms']:g} | "
            f"{r['simulated_time_s']:.3g} | {r['wall_time_s']:.3g} | {r['real_time_factor']:.3g} | "
            f"{r['rhs_evaluations']} | {r['wall_time_per_rhs_ms'] * 1e3:.3g} | {r.get('reference', '-')} | "
            f"{r.get('max_normal_force_difference_rel', float('nan')):.3g} | "
            f"{r.get('median_normal_force_difference_rel', float('nan')):.3g} | "
            f"{r.get('max_lateral_difference_m', float('nan')):.3g} | {r['status']} |"
        )
    vs = next((r["vs_search"] for r in records if "vs_search" in r), None)
    lines += [
        "",
        NOTES.format(vs=vs, reused=next((r["searches_reused"] for r in records if "searches_reused" in r), 0)),
    ]
    for name, text in (("dynamics.json", json.dumps(payload, indent=2) + "\n"), ("dynamics.md", "\n".join(lines))):
        tmp = args.out / f".{name}.tmp"
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, args.out / name)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
