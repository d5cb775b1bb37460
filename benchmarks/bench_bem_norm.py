"""NORM scaling on CONTACT's performance grids: iterations and time of NormCG (preconditioned) and Polonsky-Keer.

Case: CONTACT's ``perfc_test/norm_problm_{1,2,4}{p,f}`` decks (benchmarks/data/SOURCE.md): a right wheel on its
rail at 6.2 mm lateral shift, h(x, y) = p(y) + x^2/(2 * 483.931 mm) - PEN with the deck's lateral profile p,
G = 82 GPa, nu = 0.28, EPS = 1e-7; approach control (``p``, PEN = 0.02084 mm) and force control (``f``, 10 kN)
on 71 x 81, 143 x 163 and 287 x 323 elements (5751 / 23309 / 92701). CONTACT's iterations and elements in
contact are its recorded ones (get_times.ref_out, version 1274); CONTACT itself was not built or timed here.

Times: in-process, influence coefficients + solve, wall and CPU of this process, best of ``repeats`` after a
warm-up run (numba compiled); one thread. Differences: NormCG against Polonsky-Keer solved to 1e-10.

Run: ``.venv/bin/python benchmarks/bench_bem_norm.py`` -> benchmarks/results/bem_norm_scaling.json and .md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from rigid_dynamics.contact.bem.influence import InfluenceGrid  # noqa: E402
from rigid_dynamics.contact.bem.norm import solve_norm  # noqa: E402

PROFILE = ROOT / "benchmarks" / "data" / "contact_perfc_norm_profile.csv"
GRIDS = {"1": (71, 81, 0.1e-3), "2": (143, 163, 0.05e-3), "4": (287, 323, 0.025e-3)}
CONTACT = {  # deck -> (elements in contact, NormCG iterations), get_times.ref_out
    "1p": (3148, 19),
    "2p": (12902, 22),
    "4p": (50796, 27),
    "1f": (3148, 16),
    "2f": (12912, 18),
    "4f": (50830, 23),
}
PEN_M, FN_N, RM_M, EPS = 0.02084e-3, 1.0e4, 0.483931, 1e-7


def problem(level: str, force_control: bool):
    """(make_influence, h, normal_force_N) of deck ``level`` + (f or p)."""
    mx, my, d = GRIDS[level]
    prof = np.loadtxt(PROFILE, delimiter=",")
    x = -3.55e-3 + d * (np.arange(mx) + 0.5)
    y = -6.15e-3 + d * (np.arange(my) + 0.5)
    h = np.interp(y, prof[:, 0] * 1e-3, prof[:, 1] * 1e-3)[:, None] + x[None, :] ** 2 / (2 * RM_M)
    if force_control:
        return (lambda: InfluenceGrid(mx, my, d, d, 82e9, 0.28)), h, FN_N
    return (lambda: InfluenceGrid(mx, my, d, d, 82e9, 0.28)), h - PEN_M, None


def timed(func, repeats):
    """(best wall, best CPU of this process, result) after one warm-up call."""
    out = func()
    walls, cpus = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = func()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return min(walls), min(cpus), out


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main():
    rows = []
    repeats = int(os.environ.get("BEM_NORM_REPEATS", "5"))
    for level in GRIDS:
        for kind in ("p", "f"):
            make, h, force = problem(level, kind == "f")
            row = {"deck": f"norm_problm_{level}{kind}", "elements": h.size}
            row["contact_elements_contact"], row["contact_iterations"] = CONTACT[level + kind]
            sols = {}
            for method in ("normcg", "polonsky-keer"):

                def run(method=method, make=make, h=h, force=force):
                    return solve_norm(make(), h, normal_force_N=force, tolerance=EPS, method=method)

                wall, cpu, sol = timed(run, repeats if method == "normcg" else max(1, repeats // 2))
                sols[method] = sol
                row[method] = {
                    "iterations": sol.iterations,
                    "converged": bool(sol.converged),
                    "contact_elements": int((sol.pressure_Pa > 0).sum()),
                    "normal_force_N": sol.normal_force_N,
                    "approach_shift_m": sol.approach_shift_m,
                    "residual": sol.residual,
                    "wall_s": wall,
                    "cpu_s": cpu,
                }
            ref = solve_norm(make(), h, normal_force_N=force, tolerance=1e-10, method="polonsky-keer")
            p = sols["normcg"].pressure_Pa
            row["normcg_max_pressure_difference_rel"] = float(np.abs(p - ref.pressure_Pa).max() / ref.pressure_Pa.max())
            row["normcg_force_difference_rel"] = float(sols["normcg"].normal_force_N / ref.normal_force_N - 1)
            rows.append(row)
            print(json.dumps(row), flush=True)
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "threads": "1",
        "load_average_at_end": os.getloadavg(),
        "note": "machine shared with other jobs while running; CPU times are the more robust measure",
    }
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    summary = {"case": __doc__.split("\n\n")[1], "machine": machine, "repeats": repeats, "rows": rows}
    write_atomic(out / "bem_norm_scaling.json", json.dumps(summary, indent=2) + "\n")
    lines = [
        "# NORM scaling on CONTACT's perfc grids (benchmarks/bench_bem_norm.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Machine: {machine['platform']}, {machine['processor']}, {machine['cpu_count']} CPUs (one thread used), "
        f"Python {machine['python']}; load average at end {machine['load_average_at_end']} (shared machine).",
        f"Times: influence coefficients + solve, ms, wall (CPU), best of {repeats} (Polonsky-Keer: "
        f"{max(1, repeats // 2)}).",
        "",
        "| deck | elements | in contact (CONTACT) | NormCG its (CONTACT) | NormCG ms | P-K its | P-K ms | "
        "max dp/p0 vs P-K 1e-10 | dF/F |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        n, k = r["normcg"], r["polonsky-keer"]
        lines.append(
            f"| {r['deck']} | {r['elements']} | {n['contact_elements']} ({r['contact_elements_contact']}) | "
            f"{n['iterations']} ({r['contact_iterations']}) | {1e3 * n['wall_s']:.0f} ({1e3 * n['cpu_s']:.0f}) | "
            f"{k['iterations']} | {1e3 * k['wall_s']:.0f} ({1e3 * k['cpu_s']:.0f}) | "
            f"{r['normcg_max_pressure_difference_rel']:.1e} | {r['normcg_force_difference_rel']:+.1e} |"
        )
    write_atomic(out / "bem_norm_scaling.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
