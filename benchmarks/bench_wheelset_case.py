"""Run time and error of the wheelset contact case against CONTACT's published Manchester A-2.2 solution.

For each rung (hertz, fastsim, bem on CONTACT's 0.2 mm grid) and each of the 21 A-2.2 steps with CONTACT's deck
kinematics (roll and pitch rate prescribed, the right wheel's vertical position solved for 10 kN), the in-process
wall time of ``solve_wheelset_case`` (right wheel, numba kernels loaded beforehand) and the differences to
CONTACT's published values (comparisons/data/contact_reference): FN, Fx and Fs in % of mu FN, PMAX, area,
reference point. The analytic rungs' differences are the model error (Hertz has no creep forces); the bem's are
the implementation's.

Geometry cost, per side at the equilibrium poses of 0, 5 and 7 mm shift: the 3-D search with its sampled field
(31 x 31 points, fitted to the overlap: what the BEM rung interpolated bilinearly before), against the CONTACT-style
patches (contact locus, joined regions, exact plane gap, compiled); and the cost of evaluating the undeformed
distance at the centres of a 40 x 40 BEM grid: bilinear interpolation of the sampled field against the exact
evaluation.

Whole process: ``wheelrail manchester --method bem`` (21 steps, both wheels, plots) and ``wheelrail contact
manchester-a22 --method fastsim --json``, each the second of two runs (warm caches). CONTACT's own time is
measured when the environment variable CONTACT_EXE names a built CONTACT executable and CONTACT_DECKS a folder with
its mbench_a22_right.inp / mbench_a22_left.inp (not part of this repository), and CONTACT_BUILD_NOTE how it was
built; otherwise the table says so.

Writes benchmarks/results/wheelset_case.json and wheelset_case.md. Run: .venv/bin/python
benchmarks/bench_wheelset_case.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from comparisons.manchester import (  # noqa: E402
    MATERIAL,
    STEPS,
    TOLERANCES,
    a22_case,
    compare_summary,
    default_model_options,
    sweep,
)
from rigid_dynamics.contact.search import SIDES  # noqa: E402
from rigid_dynamics.contact.track import build_track  # noqa: E402
from rigid_dynamics.contact.wheelset_case import solve_wheelset_case  # noqa: E402
from rigid_dynamics.contact.wheelset_patches import wheel_patches  # noqa: E402
from rigid_dynamics.files import write_text  # noqa: E402  (atomic)

METHODS = ("hertz", "fastsim", "bem")


def best_time(func, repeats=5):
    func()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        func()
        best = min(best, time.perf_counter() - t0)
    return best


def per_case():
    track = build_track(a22_case(0, "deck"))
    out = {}
    for method in METHODS:
        options = {"model": default_model_options(method), "sides": ("right",)}
        solve_wheelset_case(a22_case(5, "deck"), MATERIAL, method, options, track=track)  # load kernels
        times = []
        for step in STEPS:
            case = a22_case(step, "deck")
            t0 = time.perf_counter()
            solve_wheelset_case(case, MATERIAL, method, options, track=track)
            times.append(time.perf_counter() - t0)
        rows = sweep(method, STEPS, kinematics="deck", sides=("right",))
        summary = compare_summary(rows)
        out[method] = {
            "time_per_case_s": {"median": float(np.median(times)), "max": float(np.max(times)), "total": sum(times)},
            "largest_difference": summary["largest_difference"],
            "patch_count_mismatch_steps": summary["patch_count_mismatch_steps"],
            "within_tolerance": summary["within_tolerance"],
        }
        print(method, out[method]["time_per_case_s"], flush=True)
    return out


def geometry_cost():
    track = build_track(a22_case(0))
    out = []
    for step in (0, 10, 14):
        sol = solve_wheelset_case(a22_case(step), MATERIAL, "hertz", {"spin_rate": "nominal"}, track=track)
        pose = sol.pose

        def old(pose=pose):
            return [track.search(pose, side, {"field": True}) for side in SIDES]

        def new(pose=pose):
            result = []
            for side in SIDES:
                wheel, rail = track.fast[side]
                result.append(
                    wheel_patches(
                        wheel, rail, pose, side, wheel_lateral_range_m=wheel.y_range_m,
                        rail_lateral_range_m=rail.y_range_m, nominal_radius_m=0.46,
                    )
                )  # fmt: skip
            return result

        t_old, t_new = best_time(old), best_time(new)
        patches = [p for side_patches, _ in new() for p in side_patches]
        field_old = old()[1].patches[0].undeformed
        field_new = patches[-1].geometry.undeformed
        x = np.linspace(field_old.x_m[2], field_old.x_m[-3], 40)
        y = np.linspace(field_old.y_m[2], field_old.y_m[-3], 40)
        xx, yy = np.meshgrid(x, y)
        t_interp = best_time(lambda f=field_old, xx=xx, yy=yy: f.evaluate(xx, yy))
        x = np.linspace(field_new.x_m[2], field_new.x_m[-3], 40)
        y = np.linspace(field_new.y_m[2], field_new.y_m[-3], 40)
        xx2, yy2 = np.meshgrid(x, y)
        t_exact = best_time(lambda f=field_new, xx=xx2, yy=yy2: f.evaluate(xx, yy))
        out.append({
            "step": step, "lateral_shift_m": step * 0.5e-3,
            "search_with_sampled_field_s": t_old, "contact_patches_s": t_new,
            "gap_40x40_bilinear_s": t_interp, "gap_40x40_exact_s": t_exact,
        })  # fmt: skip
        print(out[-1], flush=True)
    return out


def whole_process():
    exe = ROOT / ".venv" / "bin" / "wheelrail"
    if not exe.exists():
        exe = Path(shutil.which("wheelrail") or "wheelrail")
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, args in (
            ("manchester_bem", ["manchester", "--method", "bem", "--out", str(Path(tmp) / "m")]),
            ("contact_fastsim", ["contact", "manchester-a22", "--method", "fastsim", "--json"]),
        ):
            times = []
            for k in range(2):
                if name == "manchester_bem":
                    args[-1] = str(Path(tmp) / f"m{k}")
                t0 = time.perf_counter()
                done = subprocess.run([str(exe), *args], check=False, capture_output=True, text=True)
                times.append(time.perf_counter() - t0)
                if done.returncode != 0:
                    raise RuntimeError(f"wheelrail {' '.join(args)} ended with {done.returncode}: {done.stderr[-500:]}")
            out[name] = {"cold_s": times[0], "warm_s": times[1]}
            print(name, out[name], flush=True)
    exe_contact, decks = os.environ.get("CONTACT_EXE"), os.environ.get("CONTACT_DECKS")
    if exe_contact and decks:
        out["contact_program_s"] = contact_program(exe_contact, Path(decks))
    else:
        out["contact_program_s"] = None
    return out


def contact_program(exe: str, decks: Path) -> dict:
    """Whole-process time of the CONTACT program (IMODE 2) on its A-2.2 decks, and its right-wheel numbers.

    Each deck runs twice in a fresh folder (the second run is kept: warm file cache). The right deck's FN, FX and
    PMAX per case are read back from its .out file and compared with the published values of
    comparisons/data/contact_reference, so the timing is of a build that reproduces the published solution.
    """
    times = {}
    for deck in ("mbench_a22_right", "mbench_a22_left"):
        for _ in range(2):
            with tempfile.TemporaryDirectory() as tmp:
                shutil.copy(decks / f"{deck}.inp", tmp)
                for profile in decks.glob("*.pr?"):
                    shutil.copy(profile, tmp)
                t0 = time.perf_counter()
                done = subprocess.run([exe, "2", deck], cwd=tmp, check=False, capture_output=True, text=True)
                elapsed = time.perf_counter() - t0
                text = (Path(tmp) / f"{deck}.out").read_text() if (Path(tmp) / f"{deck}.out").exists() else ""
            if done.returncode != 0 or "ended succesfully" not in done.stdout:
                raise RuntimeError(f"CONTACT on {deck} failed ({done.returncode}): {done.stdout[-300:]}")
        times[deck] = {"whole_process_s": elapsed, "cases": text.count(" Case ")}
        if deck == "mbench_a22_right":
            times[deck]["largest_difference_to_published"] = _contact_out_vs_published(text)
    return times


def _contact_out_vs_published(text: str) -> dict:
    """Largest relative differences of FN and PMAX, and of FX in % of mu FN, of a CONTACT .out to the published rows."""
    import csv

    rows = list(csv.DictReader((ROOT / "comparisons/data/contact_reference/mbench_a22_right.csv").open()))
    lines = text.splitlines()
    found = []
    for i, line in enumerate(lines):
        if line.split()[:2] == ["FN", "FX"] and i + 3 < len(lines):
            fn, fx = (float(v) for v in lines[i + 1].split()[:2])
            pmax = float(lines[i + 3].split()[4])
            found.append((fn, fx, pmax))
    if len(found) != len(rows):
        return {"patches_read": len(found), "patches_published": len(rows)}
    d_fn = max(abs(f[0] / float(r["fn_N"]) - 1) for f, r in zip(found, rows, strict=True))
    d_fx = max(abs(f[1] - float(r["fx_N"])) / (0.3 * float(r["fn_N"])) for f, r in zip(found, rows, strict=True))
    d_p = max(abs(f[2] / float(r["pmax_N_per_mm2"]) - 1) for f, r in zip(found, rows, strict=True))
    return {"patches": len(found), "fn": d_fn, "fx_over_mu_fn": d_fx, "pmax": d_p}


def markdown(result) -> str:
    lines = [
        "# Wheelset contact case against CONTACT's Manchester A-2.2 (benchmarks/bench_wheelset_case.py)",
        "",
        f"Machine: {result['machine']['platform']}, {result['machine']['cpu_count']} cores (shared, noisy); "
        f"python {result['machine']['python']}; load average at the start "
        f"{result['machine'].get('load_average_1min', float('nan')):.1f}. Times of one run are comparable with each "
        "other, not across runs.",
        "",
        "## Per case (right wheel, CONTACT's deck kinematics), in-process",
        "",
        "| rung | median / max time per case | FN | Fx / muFN | Fs / muFN | PMAX | area | ref. point | within tol. |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for method, r in result["per_case"].items():
        d = r["largest_difference"]

        def cell(key, d=d):
            if key not in d:
                return "-"
            v = d[key]["value"]
            return f"{1e3 * v:.3f} mm" if key == "contact_y_rail" else f"{100 * v:.2f} % (step {d[key]['step']})"

        t = r["time_per_case_s"]
        mismatch = (
            f" (patch count differs at {r['patch_count_mismatch_steps']})" if r["patch_count_mismatch_steps"] else ""
        )
        lines.append(
            f"| {method} | {1e3 * t['median']:.0f} / {1e3 * t['max']:.0f} ms | "
            + " | ".join(cell(k) for k in TOLERANCES)
            + f" | {'yes' if r['within_tolerance'] else 'no'}{mismatch} |"
        )
    lines += [
        "",
        "Largest differences over the 21 steps. Tolerances: FN 1 %, Fx and Fs 2 % of mu FN, PMAX 3 %, area 5 %, "
        "reference point 0.5 mm. The analytic rungs' numbers are their model error against the exact theory.",
        "",
        "## Geometry per wheelset pose (both sides)",
        "",
        "| shift | 3-D search + sampled field 31x31 | CONTACT-style patches (exact gap) | gap at 40x40: bilinear "
        "| exact |",
        "|---|---|---|---|---|",
    ]
    for g in result["geometry"]:
        lines.append(
            f"| {1e3 * g['lateral_shift_m']:.1f} mm | {1e3 * g['search_with_sampled_field_s']:.1f} ms | "
            f"{1e3 * g['contact_patches_s']:.1f} ms | {1e3 * g['gap_40x40_bilinear_s']:.2f} ms | "
            f"{1e3 * g['gap_40x40_exact_s']:.2f} ms |"
        )
    w = result["whole_process"]
    lines += ["", "## Whole process (cold / warm)", ""]
    for key in ("manchester_bem", "contact_fastsim"):
        lines.append(f"- `{key}`: {w[key]['cold_s']:.1f} s / {w[key]['warm_s']:.1f} s")
    if w["contact_program_s"]:
        for deck, c in w["contact_program_s"].items():
            lines.append(
                f"- CONTACT program, `{deck}.inp` ({c['cases']} cases, whole process): {c['whole_process_s']:.2f} s, "
                f"{1e3 * c['whole_process_s'] / max(c['cases'], 1):.0f} ms per case"
            )
            if "largest_difference_to_published" in c:
                d = c["largest_difference_to_published"]
                lines.append(
                    f"  - its right-wheel numbers against the published solution ({d.get('patches')} patches): "
                    f"FN {100 * d.get('fn', math.nan):.2g} %, FX {100 * d.get('fx_over_mu_fn', math.nan):.2g} % of "
                    f"mu FN, PMAX {100 * d.get('pmax', math.nan):.2g} %"
                )
        build = os.environ.get("CONTACT_BUILD_NOTE", "its build options not recorded (set CONTACT_BUILD_NOTE)")
        lines.append(
            f"  - CONTACT built locally (outside this repository): {build}; the build and the decks are not part of "
            "this repository."
        )
    else:
        lines.append("- CONTACT itself was not timed on this run (CONTACT_EXE / CONTACT_DECKS not set).")
    return "\n".join(lines) + "\n"


def main():
    result = {
        "machine": {
            "platform": platform.platform(),
            "cpu_count": os.cpu_count(),
            "python": platform.python_version(),
            "load_average_1min": os.getloadavg()[0],
        },
        "per_case": per_case(),
        "geometry": geometry_cost(),
        "whole_process": whole_process(),
    }
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    for name, text in (("wheelset_case.json", json.dumps(result, indent=2)), ("wheelset_case.md", markdown(result))):
        write_text(out / name, text)
    print(markdown(result))


if __name__ == "__main__":
    main()
