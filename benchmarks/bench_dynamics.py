"""Real-time factor of the wheelset simulation (simulated seconds per wall-clock second), with errors beside it.

Cases (scene polygonal-wheel: S1002/UIC60 1:40, 3rd-order polygon 0.3 mm, 100 km/h, Hertz + FASTSIM 20x20,
classical RK4 with a 0.5 ms step as in the scene file unless the case name gives another step):

* ``search``: 3-D contact search at every RHS evaluation (rigid_dynamics.contact.search), with the polygon, no
  reuse at all (the unmodified path, the reference of the search cases);
* ``search-reuse``: the same with SearchProvider(reuse_m=1e-5): an identical pose reuses the last search, a pose
  within 10 um (RK4's two stages at t + h/2, the last stage and the next step's first) reuses it with the
  first-order rigid-body correction (providers/search.py);
* ``search-ideal``: the 3-D search without the polygon;
* ``tables-ideal``, ``tables-polygon``: contact-geometry tables over lateral shift and roll (ideal geometry; with
  the polygon by the running-direction section of compiled_tables._irregularity), the Python right-hand side;
* ``*-compiled-*``: the same tables in the compiled RK4 loop (rigid_dynamics.wheelset.compiled_loop; FASTSIM by the
  contact package's strip kernel, the polygon evaluated in the loop), 2 s simulated; ``-vj``: Vermeulen-Johnson,
  ``-fastsim15x10``: FASTSIM on 15 x 10 elements (creep forces within 1 % of a 200 x 200 grid,
  benchmarks/results/fastsim_grid.md) instead of 20 x 20 (0.5 %);
* ``search-compiled-*``: the 3-D search compiled into the RK4 loop (rigid_dynamics.wheelset.compiled_search:
  lateral scan at each step's first stage, tracking at the others), with the polygon, 2 s; ``-short`` is the same
  over the search case's interval against the Python search (``search``);
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

from rigid_dynamics.files import write_text  # noqa: E402  (atomic)
from rigid_dynamics.wheelset import DynamicsScene, Irregularities, simulate  # noqa: E402
from rigid_dynamics.wheelset.providers import SearchProvider  # noqa: E402
from rigid_dynamics.wheelset.simulate import build_provider  # noqa: E402
from wheelrail.config import build_dataclass  # noqa: E402

NOTES = """\
Notes.

* Targets. With the 3-D search (search-compiled, Hertz + FASTSIM 20 x 20, 2 s of the polygonal-wheel scene):
  about 13x real time at the scene's 0.5 ms step and 23x at 1 ms. With tables on ideal geometry: FASTSIM 20 x 20
  about 56x (0.5 ms) and 99x (1 ms); FASTSIM 15 x 10 (creep forces within 1 % of a 200 x 200 grid,
  benchmarks/results/fastsim_grid.md) about 90x and 160x; Vermeulen-Johnson about 150x and 270x. So >= 100x with
  tables and FASTSIM needs the 1 ms step with the 15 x 10 grid; at 1 ms the largest wheel-load error against the
  1/16 ms run is 4.6 % of the static load (a short transient; median 2e-5), at 0.5 ms 0.4 %. Real-time factors
  include the run's fixed cost (static equilibrium by the compiled RHS, packing, recording: a few ms).
  Machines here are shared: repeated runs of this script scatter by ~10-20 %.
* The compiled search (rigid_dynamics.wheelset.compiled_search) runs inside the compiled RK4 loop: at each
  step's first stage a lateral scan of the vertical gap (1 mm) seeds Newton refinements (warm-started and, near
  a last candidate, a single quasi-Newton step), and the other three stages track the last candidates; patch
  geometry (curvature tensors, principal relative curvatures) is evaluated on the tabulated surfaces. About
  9.5 us per RHS on average (2 x 0.8 us of it FASTSIM). It reproduces the Python search loop: 2e-4 N0 and 1e-8 m
  over 0.03 s (tests/test_dynamics_compiled_search.py); patches at random poses within 1e-11 m in approach.
* Largest errors are switching instants. S1002/UIC60 1:40 has two near-equal gap minima on each wheel near the
  centred position (10 mm apart); whether they form one patch or two, and which is deeper, flips with tiny
  changes of the pose, so any perturbation (the step size, the search method) moves the flip instants and the
  largest wheel-load difference at such an instant is O(1) of the static load while the median converges
  (search-compiled against its 1/16 ms run: median 2e-4 at 0.5 ms, 3e-3 at 1 ms; the Python search against
  itself at 0.25 ms: max 1.07, median 0.016; search-compiled-0.5ms-short against the Python search: max 1.28 at
  one flip, median 0.004). A genuinely non-Hertzian (conformal, two-point) contact: the BEM or FEA rungs are the
  tools to judge it, not a Hertz dynamics run.
* The Python paths, for reference: the search at every RHS (search) costs ~3.5 ms per call (search-reuse halves
  the searches by the first-order rigid-body update between close stages), the Python table RHS 0.35-0.6 ms.
  tables-polygon-compiled treats the polygon by a running-direction section of the table candidates
  (compiled_tables._irregularity) instead of the 3-D search (22x / 38x).
* Compiled table path: ~1 us per RHS with Vermeulen-Johnson, ~2.5 us with FASTSIM 20 x 20 (the strip kernel
  ~0.8 us per patch), ~1.6 us with 15 x 10. It equals the Python path to ~1e-14 (tests/test_dynamics_compiled.py).
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
    simulate(replace(short, duration_s=0.002), provider=plain, compiled=False)  # load the numba kernels
    # the Python RK4 loop (compiled=False: SearchProvider scenes run the compiled search by default)
    search_rec, search_res = run_case("search", short, "search", False, provider=plain)
    add(search_rec)
    reusing = SearchProvider(polygon.wheelset, polygon.track, surfaces=plain.surfaces, reuse_m=1e-5)
    rec, res = run_case("search-reuse", short, "search", False, provider=reusing)
    rec["searches_reused"] = reusing.reused
    add(rec, res, search_res, "search")
    half = replace(short, integrator=replace(short.integrator, fixed_step_s=2.5e-4))
    rec, res = run_case("search-0.25ms", half, "search", False, provider=plain)
    add(rec, res, search_res, "search")
    ideal = replace(polygon, irregularities=Irregularities(), duration_s=args.tables_time)
    rec_ideal_search, res_ideal_search = run_case(
        "search-ideal", replace(ideal, duration_s=args.search_time), "search", False
    )
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
        (
            "tables-ideal-fastsim15x10",
            replace(ideal, duration_s=2.0, fastsim_elements_per_strip=15, fastsim_strips=10),
            ideal_tables,
        ),
    ):
        simulate(replace(base, duration_s=0.01), provider=provider, compiled=True)  # load the compiled code
        fine = replace(base, integrator=replace(base.integrator, fixed_step_s=fine_step))
        _, reference = run_case(f"fine-{label}", fine, "tables", True, provider)
        for step in (5e-4, 1e-3):
            scene = replace(base, integrator=replace(base.integrator, fixed_step_s=step))
            rec, res = run_case(f"{label}-compiled-{step * 1e3:g}ms", scene, "tables", True, provider)
            add(rec, res, reference, f"fine-{label} ({fine_step * 1e3:g} ms)")

    # the compiled 3-D search (rigid_dynamics.wheelset.compiled_search) on the polygonal-wheel scene, 2 s
    search_provider = build_provider(polygon)
    simulate(replace(polygon, duration_s=0.01), provider=search_provider, compiled=True)  # load the compiled code
    rec, res = run_case("search-compiled-0.5ms-short", short, "search", True, search_provider)
    add(rec, res, search_res, "search")
    base = replace(polygon, duration_s=2.0)
    fine = replace(base, integrator=replace(base.integrator, fixed_step_s=fine_step))
    _, reference = run_case("fine-search-compiled", fine, "search", True, search_provider)
    for step in (5e-4, 1e-3):
        scene = replace(base, integrator=replace(base.integrator, fixed_step_s=step))
        rec, res = run_case(f"search-compiled-{step * 1e3:g}ms", scene, "search", True, search_provider)
        add(rec, res, reference, f"fine-search-compiled ({fine_step * 1e3:g} ms)")

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
        write_text(args.out / name, text)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
