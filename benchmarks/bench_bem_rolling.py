"""Steady rolling on coarse grids: the large-spin case's F_y against its converged value, with and without
Richardson extrapolation (option ``extrapolate``) and for both rigid-slip points (option ``rolling_slip_point``).

Case: the large-spin case (Hertz ellipse a = 8 mm along x, b = 4 mm, F_N = 82 kN, G = 82 GPa, nu = 0.28,
mu = 0.3, xi = 0, eta = -6.25e-4, phi = 0.625 1/m), the model ``bem`` with its default margin 1.15, n x n
elements. Converged value: the Richardson limit (observed order) of each slip point's sequence at
n = 80, 160, 320; the two limits must agree. CONTACT's own coarse-grid error quoted in issue 10: |F_y| at
44 x 44 is 2.3 % from its 220 x 220 value (ours with the centre point: 4.2 %).

Run: ``.venv/bin/python benchmarks/bench_bem_rolling.py`` -> benchmarks/results/bem_rolling_coarse.json and .md.
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

from scipy.special import ellipe, ellipk  # noqa: E402

from rigid_dynamics.contact.bem.model import BemModel  # noqa: E402
from rigid_dynamics.contact.types import ContactGeometry, Creepage  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

A, B, F = 8e-3, 4e-3, 82e3
MAT = Material(82e9, 0.28, 0.3)
E_STAR = MAT.shear_modulus_Pa / (1 - MAT.poisson_ratio)
COARSE = (20, 24, 30, 40, 44, 50, 60, 80)
REFERENCE = (80, 160, 320)


def geometry() -> ContactGeometry:
    """Curvatures of the Hertz ellipse a x b under F (Johnson 1985, eq 4.26-4.27)."""
    e2 = 1 - (B / A) ** 2
    k, e = ellipk(e2), ellipe(e2)
    p0 = 3 * F / (2 * math.pi * A * B)
    a_c = p0 * B * (k - e) / (E_STAR * A * A * e2)
    b_c = p0 * B * ((A / B) ** 2 * e - k) / (E_STAR * A * A * e2)
    return ContactGeometry(a_c, b_c, 0.0)


def fy(n: int, point: str, extrapolate: bool) -> tuple[float, float, float]:
    """(F_y/(mu F_N), wall time s, estimated fine-grid error or nan)."""
    t0 = time.perf_counter()
    res = BemModel().solve(
        geometry(),
        Creepage(0.0, -6.25e-4, 0.625),
        MAT,
        normal_force_N=F,
        options={"nx": n, "ny": n, "rolling_slip_point": point, "extrapolate": extrapolate},
    )
    wall = time.perf_counter() - t0
    if not res.success:
        raise RuntimeError(f"n = {n}, {point}: {res.message}")
    scale = MAT.friction_coefficient * F
    est = res.extra["richardson"]["fine_error_estimate"]["creep_force_lat_N"] / scale if extrapolate else math.nan
    return res.creep_force_lat_N / scale, wall, est


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main():
    limits = {}
    for point in ("centre", "midpoint"):
        f1, f2, f3 = (fy(n, point, False)[0] for n in REFERENCE)
        order = math.log2((f1 - f2) / (f2 - f3))
        limits[point] = {"values": [f1, f2, f3], "observed_order": order, "limit": f3 - (f2 - f3) / (2**order - 1)}
        print(point, limits[point], flush=True)
    reference = 0.5 * (limits["centre"]["limit"] + limits["midpoint"]["limit"])
    rows = []
    for n in COARSE:
        row = {"n": n}
        for point in ("centre", "midpoint"):
            for extrapolate in (False, True):
                value, wall, est = fy(n, point, extrapolate)
                key = f"{point}{'_extrapolated' if extrapolate else ''}"
                row[key] = {"fy_over_mu_fn": value, "error": value / reference - 1, "wall_s": wall}
                if extrapolate:
                    row[key]["fine_error_estimate"] = est
        rows.append(row)
        print(json.dumps(row), flush=True)
    machine = {
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_at_end": os.getloadavg(),
    }
    out = ROOT / "benchmarks" / "results"
    summary = {"case": __doc__.split("\n\n")[1], "machine": machine, "limits": limits, "reference": reference}
    summary["rows"] = rows
    write_atomic(out / "bem_rolling_coarse.json", json.dumps(summary, indent=2) + "\n")
    lines = [
        "# Steady rolling on coarse grids (benchmarks/bench_bem_rolling.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Converged F_y/(mu F_N): centre {limits['centre']['limit']:.4f} (order "
        f"{limits['centre']['observed_order']:.2f} over n = 80, 160, 320), midpoint {limits['midpoint']['limit']:.4f} "
        f"(order {limits['midpoint']['observed_order']:.2f}); reference = their mean {reference:.4f}.",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs, one thread; load average at end "
        f"{machine['load_average_at_end']} (shared). Wall ms per solve (NORM + TANG, both grids when extrapolated).",
        "",
        "| n x n | centre | error | centre + Richardson | error (est. fine error) | midpoint | error | "
        "midpoint + Richardson | error (est. fine error) | ms (midpoint + R.) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        cells = [f"{r['n']}x{r['n']}"]
        for key in ("centre", "centre_extrapolated", "midpoint", "midpoint_extrapolated"):
            v = r[key]
            cells.append(f"{v['fy_over_mu_fn']:.4f}")
            err = f"{100 * v['error']:+.2f} %"
            if "fine_error_estimate" in v:
                err += f" ({100 * v['fine_error_estimate'] / abs(reference):+.1f} %)"
            cells.append(err)
        cells.append(f"{1e3 * r['midpoint_extrapolated']['wall_s']:.0f}")
        lines.append("| " + " | ".join(cells) + " |")
    write_atomic(out / "bem_rolling_coarse.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
