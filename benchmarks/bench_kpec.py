"""The compiled KPEC and ANALYN rungs against CONTACT's and against the full half-space solution (ours, CONTACT's).

For the three poses of CONTACT's example ``mbench_a22_kpec`` (Manchester A-2.2, right wheel, y_ws = 0, 0.5, 5 mm,
the deck's roll and pitch rate, 10 kN total vertical force, 0.2 mm elements; tests/data/contact_kpec/SOURCE.md)
the wheelset case is solved with the ``kpec``, ``analyn`` and ``bem`` rungs (kinematics "deck", CONTACT's grid,
the deck's unsmoothed profiles, creepages at CONTACT's wheel point: case option creepage_point = "approach").
Per case: the differences of our KPEC and ANALYN to CONTACT's (cases 1-3 and 4-6 of the deck), of ours and
CONTACT's to the full solutions (CONTACT's, cases 7-9, and our BEM), and the KPEC patch solved again by the BEM
on the same gap, creepages and normal force (the method's own error at one geometry). Times in process, warm
(numba cache loaded): the whole wheelset case; one patch through the rung (median of repeats: grid, gap evaluated
exactly at the element centres, kernels); the compiled KPEC kernels alone on a sampled gap (what the dynamics loop
will call); the BEM on the same patch.

Run: ``.venv/bin/python benchmarks/bench_kpec.py`` -> benchmarks/results/kpec.json and kpec.md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import csv  # noqa: E402
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
from rigid_dynamics.contact.kpec import fastsim_strips, kpec_pressure, simplified_flexibilities  # noqa: E402
from rigid_dynamics.contact.registry import get_model  # noqa: E402
from rigid_dynamics.contact.track import build_track  # noqa: E402
from rigid_dynamics.contact.wheelset_case import solve_wheelset_case  # noqa: E402
from rigid_dynamics.files import write_text  # noqa: E402

REFERENCE = ROOT / "tests" / "data" / "contact_kpec" / "mbench_a22_kpec.csv"
STEP_OF_CASE = {1: 0, 2: 1, 3: 10}  # KPEC case of the deck -> A-2.2 step; CONTACT's full solution is case + 6
ELEMENT_M = 0.2e-3
REPEATS = 20
KEYS = ("fn", "fx", "fs", "pmax", "area", "ycp")


def contact_rows() -> dict[int, dict]:
    """CONTACT's printed values per case, in wheelrail's units and conventions (forces on the wheel, SI)."""
    with REFERENCE.open(encoding="utf-8") as fh:
        rows = {int(r["case"]): r for r in csv.DictReader(fh)}
    return {
        c: {
            "fn": float(r["fn_N"]),
            "fx": -float(r["fx_N"]),
            "fs": float(r["fs_N"]),
            "pmax": float(r["pmax_N_per_mm2"]) * 1e6,
            "area": float(r["contact_area_mm2"]) * 1e-6,
            "ycp": float(r["ycp_rail_mm"]) * 1e-3,
        }
        for c, r in rows.items()
    }


def ours(result, geometry) -> dict:
    return {
        "fn": result.normal_force_N,
        "fx": result.creep_force_long_N,
        "fs": result.creep_force_lat_N,
        "pmax": result.max_pressure_Pa,
        "area": result.contact_area_m2,
        "ycp": geometry.contact_point_rail_m[0],
    }


def differences(mine: dict, ref: dict) -> dict:
    """F_N, p_max, area relative; F_x, F_s in mu F_N (of the reference); reference point in mm."""
    mu_fn = MATERIAL.friction_coefficient * ref["fn"]
    return {
        "fn": mine["fn"] / ref["fn"] - 1,
        "fx": (mine["fx"] - ref["fx"]) / mu_fn,
        "fs": (mine["fs"] - ref["fs"]) / mu_fn,
        "pmax": mine["pmax"] / ref["pmax"] - 1,
        "area": mine["area"] / ref["area"] - 1,
        "ycp": (mine["ycp"] - ref["ycp"]) * 1e3,
    }


def median_time(fn, repeats=REPEATS) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def kernel_time(result, geometry, creepage) -> float:
    """The compiled kernels alone on the patch's grid (gap sampled once), s."""
    f = result.fields
    xx, yy = np.meshgrid(f.x_m, f.y_m)
    h = np.ascontiguousarray(geometry.gap_m(xx, yy), dtype=float)
    p, contact = np.zeros(h.shape), np.zeros(h.shape, dtype=np.bool_)
    tx, ty, slip = np.zeros(h.shape), np.zeros(h.shape), np.zeros(h.shape, dtype=np.bool_)
    g, nu, mu = MATERIAL.shear_modulus_Pa, MATERIAL.poisson_ratio, MATERIAL.friction_coefficient
    dx, dy = f.x_m[1] - f.x_m[0], f.y_m[1] - f.y_m[0]
    xi, eta, phi = creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m

    def run():
        out = kpec_pressure(h, f.x_m, f.y_m, g, nu, p, contact)
        l1, l2, l3, _, _ = simplified_flexibilities(contact, dx, dy, out[0], g, nu, mu, xi, eta, phi)
        fastsim_strips((p, contact), (f.x_m, f.y_m), (mu, xi, eta, phi), (l1, l2, l3), (tx, ty, slip))

    run()
    return median_time(run, 200)


COLD_SCRIPT = """
import time
t0 = time.perf_counter()
import numpy as np
from rigid_dynamics.contact import kpec
x = -3e-3 + 0.1e-3 * (np.arange(60) + 0.5)
h = np.ascontiguousarray(0.5 * x[None, :] ** 2 + 0.4 * x[:, None] ** 2 - 1e-6)
p, c = np.zeros(h.shape), np.zeros(h.shape, dtype=np.bool_)
tx, ty, s = np.zeros(h.shape), np.zeros(h.shape), np.zeros(h.shape, dtype=np.bool_)
out = kpec.kpec_pressure(h, x, x, 82e9, 0.28, p, c)
l1, l2, l3, a, b = kpec.simplified_flexibilities(c, 1e-4, 1e-4, out[0], 82e9, 0.28, 0.3, 1e-3, 1e-3, 0.5)
kpec.fastsim_strips((p, c), (x, x), (0.3, 1e-3, 1e-3, 0.5), (l1, l2, l3), (tx, ty, s))
kpec.analyn_pressure(h, x, x, 82e9, 0.28, p, c)
from rigid_dynamics.contact.fastrip import StripTheory
strip = StripTheory(a, 1e9, 0.28, -1.0, -1.0, 0.1)
kpec.fastrip_strips((p, c), (x, x), (0.3, 1e-3, 1e-3, 0.5), (l1, l2, l3), (tx, ty, s), strip)
print(time.perf_counter() - t0)
"""


def cold_start_s() -> tuple[float, float]:
    """Import and first call of every kernel in a new process: with an empty numba cache, then with it filled, s."""
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
        times = []
        for _ in range(2):
            run = subprocess.run([sys.executable, "-c", COLD_SCRIPT], env=env, capture_output=True, text=True)
            times.append(float(run.stdout.strip().splitlines()[-1]))
    return times[0], times[1]


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main():
    reference = contact_rows()
    # the deck's profiles (SMOOTH = 0) and CONTACT's creepage point (kpec_case3_diagnosis.md)
    track = build_track(a22_case(0, "deck"))
    options = {"model": {"element_size_m": ELEMENT_M}, "sides": ("right",), "creepage_point": "approach"}
    kpec, bem, analyn = get_model("kpec"), get_model("bem"), get_model("analyn")
    opts = options["model"]
    strip_opts = dict(opts, tangential="fastrip")
    for method in ("kpec", "bem", "analyn"):  # warm-up (numba cache, FFT plans)
        solve_wheelset_case(a22_case(0, "deck"), MATERIAL, method, options, track=track)
    rows = []
    for case, step in STEP_OF_CASE.items():
        t0 = time.perf_counter()
        sol_k = solve_wheelset_case(a22_case(step, "deck"), MATERIAL, "kpec", options, track=track)
        t_case_k = time.perf_counter() - t0
        t0 = time.perf_counter()
        sol_b = solve_wheelset_case(a22_case(step, "deck"), MATERIAL, "bem", options, track=track)
        t_case_b = time.perf_counter() - t0
        t0 = time.perf_counter()
        sol_a = solve_wheelset_case(a22_case(step, "deck"), MATERIAL, "analyn", options, track=track)
        t_case_a = time.perf_counter() - t0
        pa = [p for p in sol_a.patches if p.side == "right"]
        pk = [p for p in sol_k.patches if p.side == "right"]
        pb = [p for p in sol_b.patches if p.side == "right"]
        patch = pk[0]
        t_patch = median_time(lambda p=patch: kpec.solve(p.geometry, p.creepage, MATERIAL, options=opts))
        t_kernel = kernel_time(patch.result, patch.geometry, patch.creepage)
        t_patch_f = median_time(lambda p=patch: kpec.solve(p.geometry, p.creepage, MATERIAL, options=strip_opts))
        fastrip_res = kpec.solve(patch.geometry, patch.creepage, MATERIAL, options=strip_opts)
        t_patch_a = median_time(lambda p=pa[0]: analyn.solve(p.geometry, p.creepage, MATERIAL, options=opts))
        analyn_mine = ours(pa[0].result, pa[0].geometry)
        t0 = time.perf_counter()
        force = patch.result.normal_force_N
        same_gap = bem.solve(patch.geometry, patch.creepage, MATERIAL, normal_force_N=force, options=opts)
        t_bem_patch = time.perf_counter() - t0
        mine = ours(patch.result, patch.geometry)
        row = {
            "case": case,
            "step": step,
            "lateral_shift_mm": 0.5 * step,
            "patches": {"kpec": len(pk), "analyn": len(pa), "bem": len(pb), "contact": 1},
            "status": {"kpec": sol_k.status, "analyn": sol_a.status, "bem": sol_b.status},
            "analyn_vertical_load_N": sol_a.wheel_vertical_load_N["right"],
            "combination": patch.combination,
            "grid": [int(patch.result.extra["nx"]), int(patch.result.extra["ny"])],
            "kpec": mine,
            "kpec_vs_contact_kpec": differences(mine, reference[case]),
            "kpec_vs_contact_full": differences(mine, reference[case + 6]),
            "contact_kpec_vs_contact_full": differences(reference[case], reference[case + 6]),
            "analyn_vs_contact_analyn": differences(analyn_mine, reference[case + 3]),
            "analyn_vs_contact_full": differences(analyn_mine, reference[case + 6]),
            "contact_analyn_vs_contact_full": differences(reference[case + 3], reference[case + 6]),
            "bem_vs_contact_full": differences(ours(pb[0].result, pb[0].geometry), reference[case + 6]),
            "kpec_vs_bem_case": differences(mine, ours(pb[0].result, pb[0].geometry)),
            "kpec_vs_bem_same_gap": differences(mine, ours(same_gap, patch.geometry)),
            "kpec_fastrip_vs_bem_same_gap": differences(
                ours(fastrip_res, patch.geometry), ours(same_gap, patch.geometry)
            ),
            "time_s": {
                "kpec_case": t_case_k,
                "bem_case": t_case_b,
                "analyn_case": t_case_a,
                "kpec_patch": t_patch,
                "analyn_patch": t_patch_a,
                "kpec_fastrip_patch": t_patch_f,
                "kpec_kernels": t_kernel,
                "bem_patch": t_bem_patch,
            },
            "iterations": {"kpec_case": sol_k.iterations, "bem_case": sol_b.iterations},
        }
        rows.append(row)
        print(json.dumps(row), flush=True)
    write(rows, cold_start_s())


def write(rows, cold):
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    machine = {
        "cpu": cpu_model(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "load_1min": os.getloadavg()[0],
        "threads": 1,
    }
    out = ROOT / "benchmarks" / "results"
    summary = {
        "case": __doc__.split("\n\n")[1],
        "commit": commit.stdout.strip(),
        "machine": machine,
        "cold_start_s": {"empty_cache": cold[0], "filled_cache": cold[1]},
        "rows": rows,
    }
    write_text(out / "kpec.json", json.dumps(summary, indent=2) + "\n")

    def cells(d):
        return (
            f"{100 * d['fn']:+.2f} | {100 * d['fx']:+.2f} | {100 * d['fs']:+.2f} | {100 * d['pmax']:+.1f} | "
            f"{100 * d['area']:+.1f} | {d['ycp']:+.3f}"
        )

    head = "| case | y_ws mm | F_N % | F_x % muFN | F_s % muFN | p_max % | area % | y_cp mm |"
    rule = "|---|---|---|---|---|---|---|---|"
    lines = [
        "# KPEC: CONTACT's method compiled, against CONTACT's KPEC and the full solution (benchmarks/bench_kpec.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Commit {summary['commit']}; machine: {machine['cpu']}, {machine['cpu_count']} cores shared with other work "
        f"(load {machine['load_1min']:.1f}), {machine['platform']}, one thread.",
        "Differences: F_N, p_max, area relative; F_x, F_s in % of mu F_N of the reference; y_cp (reference point on "
        "the rail) in mm.",
    ]
    for key, title in (
        ("kpec_vs_contact_kpec", "Our KPEC against CONTACT's KPEC (cases 1-3): the method equal?"),
        ("kpec_vs_contact_full", "Our KPEC against CONTACT's full solution (cases 7-9)"),
        ("contact_kpec_vs_contact_full", "CONTACT's KPEC against CONTACT's full solution (the method's own error)"),
        ("analyn_vs_contact_analyn", "Our ANALYN against CONTACT's ANALYN (cases 4-6)"),
        ("analyn_vs_contact_full", "Our ANALYN against CONTACT's full solution (cases 7-9)"),
        ("contact_analyn_vs_contact_full", "CONTACT's ANALYN against CONTACT's full solution"),
        ("bem_vs_contact_full", "Our BEM (wheelset case, same grid) against CONTACT's full solution"),
        ("kpec_vs_bem_same_gap", "Our KPEC against our BEM on the same patch (same gap, creepages, F_N)"),
        ("kpec_fastrip_vs_bem_same_gap", "Our KPEC with FaStrip per strip against our BEM on the same patch"),
    ):
        lines += ["", f"## {title}", "", head, rule]
        for r in rows:
            note = ""
            if key.startswith("analyn") and r["status"]["analyn"] != "ok":
                note = f" ({r['status']['analyn']}: vertical load {r['analyn_vertical_load_N']:.0f} N)"
            lines.append(f"| {r['case']} | {r['lateral_shift_mm']:g}{note} | {cells(r[key])} |")
    lines += [
        "",
        "## Time (in process, warm; median of repeats for the patch and kernels)",
        "",
        "| case | y_ws mm | grid | kpec wheelset case s | analyn wheelset case s | bem wheelset case s | "
        "kpec patch ms | kpec+fastrip patch ms | analyn patch ms | kpec kernels ms | bem same patch ms | "
        "bem/kpec per patch |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        t = r["time_s"]
        lines.append(
            f"| {r['case']} | {r['lateral_shift_mm']:g} | {r['grid'][0]} x {r['grid'][1]} | {t['kpec_case']:.2f} | "
            f"{t['analyn_case']:.2f} | {t['bem_case']:.2f} | {1e3 * t['kpec_patch']:.2f} | "
            f"{1e3 * t['kpec_fastrip_patch']:.2f} | {1e3 * t['analyn_patch']:.2f} | {1e3 * t['kpec_kernels']:.3f} | "
            f"{1e3 * t['bem_patch']:.1f} | {t['bem_patch'] / t['kpec_patch']:.0f} |"
        )
    lines += [
        "",
        f"Cold start (new process: import and first call of every kpec kernel, with their Hertz and Kalker "
        f"helpers): {cold[0]:.1f} s with an empty numba cache (compilation), {cold[1]:.2f} s with the cache filled.",
    ]
    write_text(out / "kpec.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
