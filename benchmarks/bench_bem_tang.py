"""TANG solver speed: the current solve_tang against the one of a baseline commit, on the problems the models pose.

Problems: (1) every TANG call of the wheelset case on Manchester A-2.2 (``solve_wheelset_case(..., "bem")`` with
CONTACT's 0.2 mm grid, ``comparisons.manchester.default_model_options``), steps as chosen; the vertical equilibrium
solves each patch many times with slowly changing pressure; (2) the large-spin case of benchmarks/bench_bem.py
(a = 8 mm, b = 4 mm, F_N = 82 kN, eta = -6.25e-4, phi = 0.625 1/m, mu = 0.3) at 40 x 40 and 100 x 100. The inputs
(grid, pressure, rigid slip, options) are recorded from the models and each is solved by the baseline's
``solve_tang`` (its tang.py from git, with the current influence module) and by the current one: cold (as the
models call it) and warm (``initial_traction`` and ``initial_slip`` from the solution of the same patch's
previous call in the equilibrium iteration, where the grid is the same). CPU time of this process per solve,
best of 3 after a warm-up; Newton and GMRES iterations; the difference of the creep forces to the baseline's in
units of mu F_N (the solver's tolerance is 1e-6 on the slip residual). Single thread.

Run: ``.venv/bin/python benchmarks/bench_bem_tang.py [A-2.2 steps, default 0,4,12] [baseline commit]``
-> benchmarks/results/bem_tang.json and .md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import importlib.util  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

import rigid_dynamics.contact.bem.influence as influence_module  # noqa: E402
import rigid_dynamics.contact.bem.model as bem_model  # noqa: E402
from comparisons.manchester import MATERIAL, a22_case, default_model_options  # noqa: E402
from rigid_dynamics.contact.bem.influence import _SHARED_CACHES, InfluenceGrid  # noqa: E402
from rigid_dynamics.contact.bem.tang import solve_tang  # noqa: E402
from rigid_dynamics.contact.types import ContactGeometry, Creepage  # noqa: E402
from rigid_dynamics.contact.wheelset_case import solve_wheelset_case  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

BASELINE = "eb74c17"  # main after the merge of bemrung (TANG as before this benchmark)


def load_baseline(commit: str):
    """solve_tang of tang.py at ``commit`` (imported from a temporary file; it uses the current influence module)."""
    text = subprocess.run(
        ["git", "-C", str(ROOT), "show", f"{commit}:rigid_dynamics/contact/bem/tang.py"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    path = Path(tempfile.mkdtemp()) / "tang_baseline.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location("tang_baseline", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["tang_baseline"] = module
    spec.loader.exec_module(module)
    return module.solve_tang


def record(run, timing: dict | None = None) -> list[dict]:
    """The TANG calls made while ``run()`` executes: grid, inputs and keyword options of each.

    ``timing``: filled with the CPU time of ``run()`` and of the TANG calls in it (s).
    """
    calls = []
    original = bem_model.solve_tang
    spent = [0.0]

    def recorder(influence, pressure, mu, wx, wy, **kw):
        c0 = time.process_time()
        out = original(influence, pressure, mu, wx, wy, **kw)
        spent[0] += time.process_time() - c0
        calls.append(
            {
                "grid": (influence.nx, influence.ny, influence.dx_m, influence.dy_m),
                "elastic": (influence.shear_modulus_Pa, influence.poisson_ratio, influence.difference_parameter),
                "args": (np.array(pressure), mu, np.array(wx), np.array(wy)),
                "kw": dict(kw),
            }
        )
        return out

    bem_model.solve_tang = recorder
    c0 = time.process_time()
    try:
        run()
    finally:
        bem_model.solve_tang = original
    if timing is not None:
        timing.update(case_cpu_s=time.process_time() - c0, tang_cpu_s=spent[0])
    return calls


def timed(func, repeats=3):
    """(best CPU time of this process, result) after one warm-up call."""
    out = func()
    best = float("inf")
    for _ in range(repeats):
        c0 = time.process_time()
        out = func()
        best = min(best, time.process_time() - c0)
    return best, out


def solve_group(name: str, calls: list[dict], baseline) -> dict:
    """Baseline, current cold and current warm on each call; per-group sums and worst differences."""
    previous = {}  # same patch's previous solution: calls alternate between the patches of a step
    rows = []
    for k, call in enumerate(calls):
        nx, ny, dx, dy = call["grid"]
        pressure, mu, wx, wy = call["args"]

        def grid(call=call):
            return InfluenceGrid(*call["grid"], *call["elastic"])

        def run(solver, extra=None, pressure=pressure, mu=mu, wx=wx, wy=wy, call=call):
            return solver(grid(), pressure, mu, wx, wy, **call["kw"], **(extra or {}))

        t_base, base = timed(lambda run=run: run(baseline))
        t_new, new = timed(lambda run=run: run(solve_tang))
        mu_fn = mu * float(pressure.sum())

        def force_diff(a, b, mu_fn=mu_fn):
            return max(
                abs(float(a.traction_x_Pa.sum() - b.traction_x_Pa.sum())),
                abs(float(a.traction_y_Pa.sum() - b.traction_y_Pa.sum())),
            ) / max(mu_fn, 1e-300)

        row = {
            "call": k,
            "grid": [nx, ny],
            "contact_elements": int((pressure > 0).sum()),
            "fy_over_mu_fn": float(new.traction_y_Pa.sum()) / max(mu_fn, 1e-300),
            "baseline": {"cpu_s": t_base, "newton": base.iterations, "gmres": base.linear_iterations},
            "cold": {"cpu_s": t_new, "newton": new.iterations, "gmres": new.linear_iterations},
            "cold_df_over_mu_fn": force_diff(new, base),
            "converged": bool(new.converged and base.converged),
        }
        key = (k % 2, nx, ny)  # the patches of a step alternate (two wheels)
        if key in previous and name.startswith("A-2.2"):
            prev = previous[key]
            warm_kw = {"initial_traction": (prev.traction_x_Pa, prev.traction_y_Pa), "initial_slip": prev.in_slip}
            t_warm, warm = timed(lambda run=run, warm_kw=warm_kw: run(solve_tang, warm_kw))
            row["warm"] = {"cpu_s": t_warm, "newton": warm.iterations, "gmres": warm.linear_iterations}
            row["warm_df_over_mu_fn"] = force_diff(warm, base)
            row["converged"] = row["converged"] and bool(warm.converged)
        previous[key] = new
        rows.append(row)
    return {"name": name, "rows": rows, "coefficients_cpu_s_per_grid": coefficient_cost(calls)}


def coefficient_cost(calls: list[dict]) -> float:
    """Mean CPU time (s) to compute a new grid's tangential coefficients and spectra (cache cleared), per grid."""
    times = []
    for grid_args, elastic in {(c["grid"], c["elastic"]) for c in calls}:
        best = float("inf")
        for _ in range(3):
            _SHARED_CACHES.clear()
            c0 = time.process_time()
            grid = InfluenceGrid(*grid_args, *elastic)
            grid.tangential_spectra(True)
            grid.tangential_spectra(False)
            grid.inverse_static_period_spectra()
            best = min(best, time.process_time() - c0)
        times.append(best)
    return float(np.mean(times))


def summarise(group: dict) -> dict:
    rows = group["rows"]
    out = {"name": group["name"], "calls": len(rows), "grids": sorted({tuple(r["grid"]) for r in rows})}
    for kind in ("baseline", "cold", "warm"):
        sel = [r[kind] for r in rows if kind in r]
        if sel:
            out[kind] = {
                "calls": len(sel),
                "cpu_ms_per_call": 1e3 * float(np.mean([s["cpu_s"] for s in sel])),
                "newton_per_call": float(np.mean([s["newton"] for s in sel])),
                "gmres_per_call": float(np.mean([s["gmres"] for s in sel])),
            }
    warm_rows = [r for r in rows if "warm" in r]
    if warm_rows:  # the baseline on the same calls as the warm starts (speed-up on like calls)
        out["baseline_on_warm_calls_ms"] = 1e3 * float(np.mean([r["baseline"]["cpu_s"] for r in warm_rows]))
    out["max_cold_df_over_mu_fn"] = max(r["cold_df_over_mu_fn"] for r in rows)
    if warm_rows:
        out["max_warm_df_over_mu_fn"] = max(r["warm_df_over_mu_fn"] for r in warm_rows)
    out["all_converged"] = all(r["converged"] for r in rows)
    out["coefficients_ms_per_grid"] = 1e3 * group["coefficients_cpu_s_per_grid"]
    if "case_timing" in group:
        out["case_cpu_ms"] = 1e3 * group["case_timing"]["case_cpu_s"]
        out["tang_cpu_ms_in_case"] = 1e3 * group["case_timing"]["tang_cpu_s"]
        out["baseline_case_cpu_ms"] = 1e3 * group["case_timing"]["baseline_case_cpu_s"]
        out["baseline_tang_cpu_ms_in_case"] = 1e3 * group["case_timing"]["baseline_tang_cpu_s"]
    return out


def large_spin_calls(n: int) -> list[dict]:
    from benchmarks.bench_bem import A, B, F, curvatures

    a_c, b_c = curvatures()
    material = Material(82e9, 0.28, 0.3)
    model = bem_model.BemModel()
    geometry, creepage = ContactGeometry(a_c, b_c, 0.0), Creepage(0.0, -6.25e-4, 0.625)
    assert (A, B) == (8e-3, 4e-3)
    return record(
        lambda: model.solve(geometry, creepage, material, normal_force_N=F, options={"nx": n, "ny": n, "margin": 1.0})
    )


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main(steps, baseline_commit):
    baseline = load_baseline(baseline_commit)
    groups = []
    for step in steps:

        def case(step=step):
            return solve_wheelset_case(a22_case(step), MATERIAL, "bem", {"model": default_model_options("bem")})

        case()  # warm-up (JIT, caches)
        _SHARED_CACHES.clear()
        timing = {}
        calls = record(case, timing)
        groups.append(solve_group(f"A-2.2 step {step}", calls, baseline))
        # the same case as before: the baseline's TANG and no coefficients shared between grids
        before = {}
        bem_model.solve_tang, keep = baseline, influence_module.SHARED_CACHE_GRIDS
        influence_module.SHARED_CACHE_GRIDS = 0
        try:
            _SHARED_CACHES.clear()
            record(case, before)
        finally:
            bem_model.solve_tang = solve_tang
            influence_module.SHARED_CACHE_GRIDS = keep
        timing.update(baseline_case_cpu_s=before["case_cpu_s"], baseline_tang_cpu_s=before["tang_cpu_s"])
        groups[-1]["case_timing"] = timing
        print(json.dumps(summarise(groups[-1])), flush=True)
    for n in (40, 100):
        groups.append(solve_group(f"large spin {n}x{n}", large_spin_calls(n), baseline))
        print(json.dumps(summarise(groups[-1])), flush=True)
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "threads": "1 (OPENBLAS/OMP/NUMBA_NUM_THREADS=1)",
        "load_average_at_end": os.getloadavg(),
    }
    summaries = [summarise(g) for g in groups]
    result = {
        "case": __doc__.split("\n\n")[1],
        "commit": commit.stdout.strip(),
        "baseline_commit": baseline_commit,
        "machine": machine,
        "summaries": summaries,
        "groups": groups,
    }
    out = ROOT / "benchmarks" / "results"
    write_atomic(out / "bem_tang.json", json.dumps(result, indent=2) + "\n")
    lines = [
        "# TANG solver speed (benchmarks/bench_bem_tang.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Commit {result['commit']} against baseline {baseline_commit}; machine {machine['platform']}, "
        f"{machine['cpu_count']} CPUs shared with other jobs (one thread used), Python {machine['python']}; "
        f"load average at end {tuple(round(v, 2) for v in machine['load_average_at_end'])}.",
        "",
        "Per call means: CPU ms, Newton / GMRES iterations. dF: max over the calls of the creep-force difference to "
        "the baseline, units of mu F_N. Warm: calls with a previous solution of the same patch on the same grid "
        "(the baseline's mean on those calls in brackets). Times with the grid's coefficients already computed "
        "(both solvers): the influence module now shares them between grids of equal parameters, so a repeated "
        "solve on a patch grid no longer pays the last column (tangential coefficients and spectra of a new grid, "
        "which every TANG call of the wheelset case paid before, the model building a new grid per solve).",
        "",
        "| problems | calls | grids | baseline ms (Newton/GMRES) | cold ms (Newton/GMRES) | cold dF | "
        "warm calls | warm ms (Newton/GMRES) [baseline ms] | warm dF | converged | coefficients ms/grid |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]

    def cell(s):
        return f"{s['cpu_ms_per_call']:.1f} ({s['newton_per_call']:.1f}/{s['gmres_per_call']:.1f})"

    for s in summaries:
        grids = ", ".join(f"{a}x{b}" for a, b in s["grids"])
        if "warm" in s:
            warm = [str(s["warm"]["calls"]), f"{cell(s['warm'])} [{s['baseline_on_warm_calls_ms']:.1f}]"]
            warm.append(f"{s['max_warm_df_over_mu_fn']:.1e}")
        else:
            warm = ["-", "-", "-"]
        cells = [s["name"], str(s["calls"]), grids, cell(s["baseline"]), cell(s["cold"])]
        cells += [f"{s['max_cold_df_over_mu_fn']:.1e}", *warm, "yes" if s["all_converged"] else "NO"]
        cells.append(f"{s['coefficients_ms_per_grid']:.1f}")
        lines.append("| " + " | ".join(cells) + " |")
    lines += [
        "",
        "Whole wheelset case (after a warm-up run; coefficient caches emptied before each): CPU ms of "
        "solve_wheelset_case and of its TANG calls, with the current code (cold TANG, as the case calls it today) "
        "and with the baseline's TANG and no coefficients shared between grids (as before).",
        "",
        "| A-2.2 | TANG calls | case ms: baseline -> current | TANG ms in it: baseline -> current |",
        "|---|---|---|---|",
    ]
    for s in summaries:
        if "case_cpu_ms" in s:
            lines.append(
                f"| {s['name']} | {s['calls']} | {s['baseline_case_cpu_ms']:.0f} -> {s['case_cpu_ms']:.0f} | "
                f"{s['baseline_tang_cpu_ms_in_case']:.0f} -> {s['tang_cpu_ms_in_case']:.0f} |"
            )
    write_atomic(out / "bem_tang.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    chosen = [int(s) for s in sys.argv[1].split(",")] if len(sys.argv) > 1 else [0, 4, 12]
    main(chosen, sys.argv[2] if len(sys.argv) > 2 else BASELINE)
