"""The fast rungs against the BEM on the Manchester A-2.2 contact patches: KPEC (+ FASTSIM), FaStrip, FASTSIM.

For each step of the Manchester benchmark A-2.2 (right and left wheel, shift k x 0.5 mm, yaw k x 1.2 mrad) the
wheelset case is solved with the BEM (``solve_wheelset_case(..., "bem")``); every BEM patch (its ContactGeometry,
creepages and BEM normal force) is then solved by ``kpec`` (CONTACT's KPEC on the sampled gap), ``fastrip`` and
``fastsim`` (Hertz on the patch's quadric) in force control with the BEM's normal force. Differences: creep forces
in units of mu F_N, maximum pressure and contact area relative to the BEM's; in-process time per patch.
The comparison depends on the wheelset case (load, creepages, gap sampling): rerun after changes to it.

Run: ``.venv/bin/python benchmarks/bench_bem_kpec.py [steps, e.g. 0,4,8,12]`` -> benchmarks/results/bem_kpec_a22.json
and .md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import json  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from comparisons.manchester import MATERIAL, a22_case  # noqa: E402
from rigid_dynamics.contact.registry import get_model  # noqa: E402
from rigid_dynamics.contact.wheelset_case import solve_wheelset_case  # noqa: E402
from rigid_dynamics.files import write_text as write_atomic  # noqa: E402

FAST = ("kpec", "fastrip", "fastsim")


def compare_patch(patch, material) -> dict:
    """The fast models on one BEM patch (force control with the BEM's normal force)."""
    ref = patch.result
    scale = material.friction_coefficient * ref.normal_force_N
    row = {
        "side": patch.side,
        "is_elliptic": bool(patch.geometry.is_elliptic),
        "bem": {
            "normal_force_N": ref.normal_force_N,
            "fx_over_mu_fn": ref.creep_force_long_N / scale,
            "fy_over_mu_fn": ref.creep_force_lat_N / scale,
            "max_pressure_Pa": ref.max_pressure_Pa,
            "contact_area_m2": ref.contact_area_m2,
        },
    }
    for name in FAST:
        t0 = time.perf_counter()
        res = get_model(name).solve(patch.geometry, patch.creepage, material, normal_force_N=ref.normal_force_N)
        wall = time.perf_counter() - t0
        row[name] = {
            "success": bool(res.success),
            "dfx_over_mu_fn": (res.creep_force_long_N - ref.creep_force_long_N) / scale,
            "dfy_over_mu_fn": (res.creep_force_lat_N - ref.creep_force_lat_N) / scale,
            "max_pressure_rel": res.max_pressure_Pa / ref.max_pressure_Pa - 1 if ref.max_pressure_Pa else None,
            "area_rel": res.contact_area_m2 / ref.contact_area_m2 - 1 if ref.contact_area_m2 else None,
            "wall_s": wall,
        }
    return row


def main(steps):
    rows = []
    for step in steps:
        solution = solve_wheelset_case(a22_case(step), MATERIAL, "bem")
        for patch in solution.patches:
            if patch.result.normal_force_N <= 0:
                continue
            row = {"step": step, **compare_patch(patch, MATERIAL)}
            rows.append(row)
            print(json.dumps(row), flush=True)
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    summary = {
        "case": __doc__.split("\n\n")[1],
        "commit": commit.stdout.strip(),
        "machine": {"platform": platform.platform(), "cpu_count": os.cpu_count(), "load": os.getloadavg()},
        "rows": rows,
    }
    out = ROOT / "benchmarks" / "results"
    write_atomic(out / "bem_kpec_a22.json", json.dumps(summary, indent=2) + "\n")
    lines = [
        "# Fast rungs against the BEM on the A-2.2 patches (benchmarks/bench_bem_kpec.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Commit {summary['commit']} (wheelset case as of that commit); machine {summary['machine']['platform']}.",
        "dFx, dFy: difference to the BEM in units of mu F_N; pmax, area: relative to the BEM.",
        "",
        "| step | side | elliptic | BEM Fy/muFN | " + " | ".join(f"{m} dFx, dFy, pmax, area, ms" for m in FAST) + " |",
        "|---|---|---|---|" + "---|" * len(FAST),
    ]

    def fmt(v):
        return "-" if v is None else f"{v:+.3f}"

    for r in rows:
        cells = [str(r["step"]), r["side"], "yes" if r["is_elliptic"] else "no", f"{r['bem']['fy_over_mu_fn']:+.3f}"]
        for m in FAST:
            v = r[m]
            cells.append(
                f"{fmt(v['dfx_over_mu_fn'])}, {fmt(v['dfy_over_mu_fn'])}, {fmt(v['max_pressure_rel'])}, "
                f"{fmt(v['area_rel'])}, {1e3 * v['wall_s']:.1f}"
            )
        lines.append("| " + " | ".join(cells) + " |")
    for m in FAST:
        dfx = np.array([abs(r[m]["dfx_over_mu_fn"]) for r in rows])
        dfy = np.array([abs(r[m]["dfy_over_mu_fn"]) for r in rows])
        if rows:
            lines.append("")
            lines.append(
                f"{m}: median |dFx| {np.median(dfx):.3f}, max {dfx.max():.3f}; median |dFy| {np.median(dfy):.3f}, "
                f"max {dfy.max():.3f} (mu F_N)"
            )
    write_atomic(out / "bem_kpec_a22.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    chosen = [int(s) for s in sys.argv[1].split(",")] if len(sys.argv) > 1 else list(range(21))
    main(chosen)
