"""Benchmark of the BEM contact model: wall time and error vs grid size (NORM and NORM + TANG).

Case: the large-spin case of the analytic-pipeline issue (Hertz ellipse a = 8 mm along x, b = 4 mm,
F_N = 82 kN, G = 82 GPa, nu = 0.28, mu = 0.3, xi = 0, eta = -6.25e-4, phi = 0.625 1/m), grid of
n x n elements over the Hertz ellipse's bounding box (margin 1, "inside the contact").
Errors: NORM - max pressure against Hertz p0; NORM + TANG - F_y/(mu F_N) against -0.6074 (CONTACT at
40 x 40, value quoted in the issue) and against the Richardson extrapolation of this grid sequence
(n = 40, 80, 160; first order, about -0.624: see tests/test_bem_model.py, the grid-convergence study).
Single thread (BLAS/FFT), best of 3 after a warm-up run.

Run: ``.venv/bin/python benchmarks/bench_bem.py`` -> benchmarks/results/bem.json and bem.md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from rigid_dynamics.contact.bem.influence import InfluenceGrid  # noqa: E402
from rigid_dynamics.contact.bem.model import BemModel, hertz_ellipse  # noqa: E402
from rigid_dynamics.contact.bem.norm import solve_norm  # noqa: E402
from rigid_dynamics.contact.types import ContactGeometry, Creepage  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

A, B, F = 8e-3, 4e-3, 82e3
MAT = Material(82e9, 0.28, 0.3)
E_STAR = MAT.shear_modulus_Pa / (1 - MAT.poisson_ratio)
REFERENCE_FY = -0.6074
GRIDS = tuple(int(v) for v in os.environ.get("BEM_GRIDS", "20,40,60,80,100,160,200").split(","))


def curvatures():
    from scipy.optimize import brentq

    # find A, B of the ellipse a x b under F: invert hertz_ellipse by the known ratio of semi-axes
    def mismatch(log_ratio):
        a_c = 1.0
        b_c = math.exp(log_ratio)
        a, b, *_ = hertz_ellipse(a_c, b_c, E_STAR, normal_force_N=F)
        return a / b - A / B

    ratio = math.exp(brentq(mismatch, 1e-6, 5.0))
    a, *_ = hertz_ellipse(1.0, ratio, E_STAR, normal_force_N=F)
    scale = (a / A) ** 2  # a ~ curvature^(-1/3) at fixed ratio... solve exactly by a 1-D search
    a_c = brentq(lambda c: hertz_ellipse(c, c * ratio, E_STAR, normal_force_N=F)[0] - A, 1e-3 * scale, 1e3 * scale)
    return a_c, a_c * ratio


def best_time(func, repeats=3):
    """(best wall time, best CPU time of this process, result); CPU time is robust to a shared machine."""
    func()
    walls, cpus = [], []
    out = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = func()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return min(walls), min(cpus), out


def main():
    a_c, b_c = curvatures()
    _, _, p0, _, _ = hertz_ellipse(a_c, b_c, E_STAR, normal_force_N=F)
    geometry = ContactGeometry(a_c, b_c, 0.0)
    creepage = Creepage(0.0, -6.25e-4, 0.625)
    model = BemModel()
    rows = []
    for n in GRIDS:
        dx, dy = 2 * A / n, 2 * B / n
        x = -A + dx * (np.arange(n) + 0.5)
        y = -B + dy * (np.arange(n) + 0.5)
        xx, yy = np.meshgrid(x, y)
        h = geometry.gap_m(xx, yy)

        def norm_only(n=n, dx=dx, dy=dy, h=h):
            grid = InfluenceGrid(n, n, dx, dy, MAT.shear_modulus_Pa, MAT.poisson_ratio)
            return solve_norm(grid, h, normal_force_N=F)

        def full(n=n):
            return model.solve(geometry, creepage, MAT, normal_force_N=F, options={"nx": n, "ny": n, "margin": 1.0})

        repeats = 3 if n <= 100 else 1
        t_norm, c_norm, sol = best_time(norm_only, repeats)
        t_full, c_full, res = best_time(full, repeats)
        fy = res.creep_force_lat_N / (MAT.friction_coefficient * F)
        rows.append(
            {
                "n": n,
                "elements": n * n,
                "norm_time_s": t_norm,
                "norm_cpu_s": c_norm,
                "norm_iterations": sol.iterations,
                "norm_converged": bool(sol.converged),
                "norm_p0_rel_error": float(sol.pressure_Pa.max() / p0 - 1),
                "norm_tang_time_s": t_full,
                "norm_tang_cpu_s": c_full,
                "tang_newton_iterations": res.extra["tang_iterations"],
                "tang_gmres_iterations": res.extra["tang_linear_iterations"],
                "success": bool(res.success),
                "fy_over_mu_fn": fy,
                "fy_rel_error": fy / REFERENCE_FY - 1,
            }
        )
        print(rows[-1], flush=True)
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "threads": "1 (OPENBLAS/OMP/NUMBA_NUM_THREADS=1)",
        "load_average_at_end": os.getloadavg(),
        "note": "machine shared with other jobs while running; times are upper bounds",
    }
    if os.environ.get("BEM_GRIDS"):
        return rows  # partial run: do not overwrite the recorded results
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    summary = {"case": __doc__.split("\n\n")[1], "machine": machine, "rows": rows}
    by_n = {r["n"]: r["fy_over_mu_fn"] for r in rows}
    extrapolation = None
    if all(k in by_n for k in (40, 80, 160)):
        f1, f2, f3 = by_n[40], by_n[80], by_n[160]
        order = math.log2((f1 - f2) / (f2 - f3))
        limit = f3 - (f2 - f3) / (2**order - 1)
        extrapolation = {"grids": [40, 80, 160], "observed_order": order, "fy_over_mu_fn_limit": limit}
        for r in rows:
            r["fy_rel_error_vs_limit"] = r["fy_over_mu_fn"] / limit - 1
    summary["richardson"] = extrapolation
    (out / "bem.json").write_text(json.dumps(summary, indent=2))
    lines = [
        "# BEM benchmark (benchmarks/bench_bem.py)",
        "",
        "Large-spin case: a = 8 mm, b = 4 mm, F_N = 82 kN, G = 82 GPa, nu = 0.28, mu = 0.3, eta = -6.25e-4,",
        "phi = 0.625 1/m; n x n elements over the Hertz ellipse's bounding box. Targets: NORM+TANG 40x40 <= 20 ms,",
        "100x100 <= 200 ms on one core.",
        "",
        f"Machine: {machine['platform']}, {machine['processor']}, {machine['cpu_count']} CPUs (one thread used), "
        f"Python {machine['python']}; load average at end {machine['load_average_at_end']} (shared machine).",
        "",
        "Times: wall (CPU of this process) in ms, best of 3 (1 run above 100x100).",
        "",
    ]
    if extrapolation is not None:
        lines += [
            f"Grid convergence of F_y/(mu F_N): observed order {extrapolation['observed_order']:.2f} over n = 40, 80, "
            f"160; Richardson limit {extrapolation['fy_over_mu_fn_limit']:.4f}. The issue's -0.6074 is quoted for a "
            "40 x 40 grid, where a first-order discretisation error of a few % is expected (the rigid slip taken at "
            "the midpoint of the upwind difference instead of the element centre converges to the same limit from "
            "the other side and gives -0.634 at 40 x 40: tests/test_bem_model.py).",
            "",
        ]
    lines += [
        "| n x n | NORM ms | NORM its | p0 error | NORM+TANG ms | Newton | GMRES | Fy/(mu FN) | error vs -0.6074 "
        "| error vs limit |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['n']}x{r['n']} | {1e3 * r['norm_time_s']:.1f} ({1e3 * r['norm_cpu_s']:.1f}) | "
            f"{r['norm_iterations']} | "
            f"{r['norm_p0_rel_error']:+.2e} | "
            f"{1e3 * r['norm_tang_time_s']:.1f} ({1e3 * r['norm_tang_cpu_s']:.1f}) | {r['tang_newton_iterations']} | "
            f"{r['tang_gmres_iterations']} | "
            f"{r['fy_over_mu_fn']:.4f} | {100 * r['fy_rel_error']:+.2f} % | "
            + (f"{100 * r['fy_rel_error_vs_limit']:+.2f} % |" if "fy_rel_error_vs_limit" in r else "- |")
        )
    (out / "bem.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
