"""wheelrail against CONTACT side by side: whole-process and in-process time, with each side's difference.

Work (issue 27's table):
* Manchester A-2.2, 21 cases x 2 wheels. CONTACT: its example decks ``mbench_a22_left`` + ``mbench_a22_right``
  (0.2 mm elements, FZ = 10 kN per wheel). wheelrail: ``wheelrail manchester --method bem`` (writes table, summary
  and plots) and the Python API without plots (``comparisons.manchester.run_manchester_a22(..., plots=False)``);
  in process: ``comparisons.manchester.sweep("bem")`` after a warm-up, per wheel-case.
* CONTACT's perfc NORM decks ``norm_problm_{1,2,4}p`` (approach control, 71 x 81 / 143 x 163 / 287 x 323
  elements; benchmarks/data/SOURCE.md). wheelrail has no command for them: its whole process is a Python process
  that imports the BEM and solves the deck (``--perfc-once``), in process the influence numbers + NormCG
  (``rigid_dynamics.contact.bem``) after a warm-up, as benchmarks/bench_bem_norm.py.

Differences (the error column): A-2.2, wheelrail's largest relative difference to CONTACT's published right-wheel
solution over the 21 cases (normal force, creep forces, max pressure, area; ``compare_summary``). perfc, wheelrail's
total force, max pressure and elements in contact against CONTACT's run in the same script (same grid, same
approach), relative.

CONTACT is the open-source program of E.A.H. Vollebregt and J.J. Kalker (Vtech CMCC; Apache-2.0; revision 2707,
snapshot d431cdb), built outside this repository (its code never enters it) in ``$CONTACT_DIR`` (default
``/work/contact-build``: the snapshot's ``src``, ``examples`` and ``perfc_test``, the executable
``bin/contact_linux64``) with its makefile (PROD=exe_l64: -O3, OpenMP) and gfortran 12 in place of ifort, and
with oneMKL's FFT (the ``WITH_MKLFFT`` NORM preconditioner and FFT products; pip's ``mkl-static`` 2026.2,
sequential, linked statically). gfortran needed small source patches (Intel extensions: logical comparisons,
``(i)`` formats, ``ifport``), and oneMKL 2026 the explicit real-domain strides of CONTACT's descriptors (the
lines CONTACT has commented out: without them the back transform is wrong and NORM ends in NaN). The build
reproduces CONTACT's ``mbench_a22_{left,right}.ref_out`` force lines exactly. When the build is missing the
script reads CONTACT's times recorded in ``benchmarks/results/vs_contact.json`` and times only wheelrail (said so
in the output).

Timing: interleaved pairs (CONTACT, then wheelrail, ``PAIRS`` times), one thread each (OMP/MKL/NUMBA/OPENBLAS = 1),
wall and CPU (user + system of the child process); the machine is shared and noisy, so the ratios come from the
same run and the medians over the pairs are reported. CONTACT's in-process time is its whole-process CPU: a Fortran
executable starts in milliseconds (its own ``Total`` timer, 0.1 s resolution, is recorded too).

Run: ``.venv/bin/python benchmarks/bench_vs_contact.py`` -> benchmarks/results/vs_contact.json and .md
(``VS_CONTACT_PAIRS`` sets the number of pairs, default 3).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import json  # noqa: E402
import platform  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

CONTACT_BUILD = Path(os.environ.get("CONTACT_DIR", "/work/contact-build"))
CONTACT_EXE = CONTACT_BUILD / "bin" / "contact_linux64"
CONTACT_SRC = CONTACT_BUILD  # decks: CONTACT_SRC/examples, CONTACT_SRC/perfc_test
RESULTS = ROOT / "benchmarks" / "results"
PERFC = {"1p": (71, 81, 0.1e-3), "2p": (143, 163, 0.05e-3), "4p": (287, 323, 0.025e-3)}
PEN_M, RM_M, EPS = 0.02084e-3, 0.483931, 1e-7
A22_DECKS = ("mbench_a22_left", "mbench_a22_right")
PROFILES = ("MBench_S1002_v3.prw", "MBench_UIC60_v3.prr")
CASE = (
    "Work: Manchester A-2.2, 21 cases x 2 wheels (CONTACT: its example decks mbench_a22_left + mbench_a22_right, "
    "0.2 mm elements; wheelrail: `wheelrail manchester --method bem` with its plots, the Python API "
    "`run_manchester_a22(..., plots=False)`, and in process `sweep('bem')` after a warm-up) and CONTACT's perfc "
    "NORM decks norm_problm_{1,2,4}p (approach control; wheelrail: a Python process that imports the BEM and "
    "solves the deck, and in process influence numbers + NormCG after a warm-up). Errors: A-2.2, wheelrail's "
    "largest difference to CONTACT's published right-wheel solution; perfc, wheelrail against CONTACT's run here "
    "(CONTACT prints 4 significant digits, so differences below about 1e-4 are at its print precision)."
)


# ------------------------------------------------------------------------------------------------ process timing


def run_timed(cmd: list[str], cwd: Path, env: dict | None = None) -> dict:
    """Run ``cmd``; its wall time and CPU (user + system of the child), exit code."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    err = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
    if proc.returncode != 0:
        raise RuntimeError(f"{cmd} exited {proc.returncode}: {err[-2000:]}")
    return {"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime}


def env_one_thread() -> dict:
    env = dict(os.environ)
    env.update({k: "1" for k in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS")})
    env["PYTHONPATH"] = str(ROOT)
    return env


# ------------------------------------------------------------------------------------------------ CONTACT side


def contact_workdir() -> Path:
    work = Path(tempfile.mkdtemp(prefix="vs-contact-"))
    for deck in A22_DECKS:
        shutil.copy(CONTACT_SRC / "examples" / f"{deck}.inp", work)
    for prof in PROFILES:
        shutil.copy(CONTACT_SRC / "examples" / prof, work)
    for level in PERFC:
        shutil.copy(CONTACT_SRC / "perfc_test" / f"norm_problm_{level}.inp", work)
    return work


def contact_run(work: Path, deck: str) -> dict:
    t = run_timed([str(CONTACT_EXE), "2", deck], work, env_one_thread())
    text = (work / f"{deck}.out").read_text(errors="replace")
    m = re.search(r"^\|Total +\| +\d+ \| +([\d.]+) \|", text, flags=re.M)
    t["own_total_cpu_s"] = float(m.group(1)) if m else None
    return t


def contact_perfc_result(work: Path, level: str) -> dict:
    from contact_out import read_out

    p = read_out(work / f"norm_problm_{level}.out")[0]["patches"][0]
    return {"normal_force_N": p["FN"], "max_pressure_Pa": p["PMAX"] * 1e6, "contact_elements": int(p["NCON"])}


# ------------------------------------------------------------------------------------------------ wheelrail side


def perfc_problem(level: str):
    import numpy as np

    from rigid_dynamics.contact.bem.influence import InfluenceGrid

    mx, my, d = PERFC[level]
    prof = np.loadtxt(ROOT / "benchmarks" / "data" / "contact_perfc_norm_profile.csv", delimiter=",")
    x = -3.55e-3 + d * (np.arange(mx) + 0.5)
    y = -6.15e-3 + d * (np.arange(my) + 0.5)
    h = np.interp(y, prof[:, 0] * 1e-3, prof[:, 1] * 1e-3)[:, None] + x[None, :] ** 2 / (2 * RM_M)
    return (lambda: InfluenceGrid(mx, my, d, d, 82e9, 0.28)), h - PEN_M


def perfc_solve(level: str) -> dict:
    from rigid_dynamics.contact.bem.norm import solve_norm

    make, h = perfc_problem(level)
    sol = solve_norm(make(), h, normal_force_N=None, tolerance=EPS, method="normcg")
    return {
        "normal_force_N": float(sol.normal_force_N),
        "max_pressure_Pa": float(sol.pressure_Pa.max()),
        "contact_elements": int((sol.pressure_Pa > 0).sum()),
        "iterations": int(sol.iterations),
        "converged": bool(sol.converged),
    }


def wheelrail_manchester_cli(out: Path) -> dict:
    cmd = [sys.executable, "-c", "import sys; from wheelrail.cli import main; sys.exit(main(sys.argv[1:]))"]
    return run_timed([*cmd, "manchester", "--method", "bem", "--out", str(out)], ROOT, env_one_thread())


def wheelrail_manchester_api(out: Path) -> dict:
    code = (
        "import sys; from comparisons.manchester import run_manchester_a22; "
        f"run_manchester_a22({str(out)!r}, 'bem', plots=False)"
    )
    return run_timed([sys.executable, "-c", code], ROOT, env_one_thread())


def wheelrail_perfc_process(level: str) -> dict:
    return run_timed([sys.executable, __file__, "--perfc-once", level], ROOT, env_one_thread())


def in_process_a22() -> dict:
    """wheelrail's A-2.2 sweep in this process (after a warm-up run): total and per wheel-case CPU/wall."""
    from comparisons.manchester import compare_summary, sweep

    sweep("bem", steps=[0, 10])  # warm-up: numba kernels loaded/compiled, profiles read
    t0, c0 = time.perf_counter(), time.process_time()
    rows = sweep("bem")
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    cases = len({(r["step"], r["side"]) for r in rows})
    return {"wall_s": wall, "cpu_s": cpu, "wheel_cases": cases, "comparison": compare_summary(rows)}


def in_process_perfc(level: str) -> dict:
    perfc_solve(level)  # warm-up
    t0, c0 = time.perf_counter(), time.process_time()
    res = perfc_solve(level)
    res.update({"wall_s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0})
    return res


# ------------------------------------------------------------------------------------------------ main


def median(rows: list[dict], key: str) -> float:
    return statistics.median(r[key] for r in rows)


def machine_info() -> dict:
    import numpy as np

    return {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_model": next(
            (
                ln.split(":", 1)[1].strip()
                for ln in Path("/proc/cpuinfo").read_text().splitlines()
                if "model name" in ln
            ),
            "",
        )
        if Path("/proc/cpuinfo").exists()
        else "",
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "threads": "1 (OMP/MKL/NUMBA/OPENBLAS_NUM_THREADS=1)",
        "load_average_at_start": os.getloadavg(),
    }


def main() -> None:
    pairs = int(os.environ.get("VS_CONTACT_PAIRS", "3"))
    have_contact = CONTACT_EXE.exists() and CONTACT_SRC.exists()
    recorded = json.loads((RESULTS / "vs_contact.json").read_text()) if (RESULTS / "vs_contact.json").exists() else None
    if not have_contact and recorded is None:
        raise SystemExit("bench_vs_contact: error: no CONTACT build at /work/contact-build and no recorded times")
    machine = machine_info()
    work = contact_workdir() if have_contact else None
    tmp = Path(tempfile.mkdtemp(prefix="vs-wheelrail-"))
    # warm the numba cache once (not timed): a cold compile is issue 27's separate item
    wheelrail_manchester_api(tmp / "warm")
    wheelrail_perfc_process("1p")

    whole = {"a22": [], "perfc": {lv: [] for lv in PERFC}}
    for i in range(pairs):
        row = {}
        if have_contact:
            left, right = (contact_run(work, d) for d in A22_DECKS)
            row["contact"] = {k: left[k] + right[k] for k in ("wall_s", "cpu_s")}
            row["contact"]["own_total_cpu_s"] = (left["own_total_cpu_s"] or 0) + (right["own_total_cpu_s"] or 0)
        row["wheelrail_cli"] = wheelrail_manchester_cli(tmp / f"cli{i}")
        row["wheelrail_api"] = wheelrail_manchester_api(tmp / f"api{i}")
        whole["a22"].append(row)
        print("a22", json.dumps(row), flush=True)
        for level in PERFC:
            prow = {}
            if have_contact:
                prow["contact"] = contact_run(work, f"norm_problm_{level}")
            prow["wheelrail"] = wheelrail_perfc_process(level)
            whole["perfc"][level].append(prow)
            print(level, json.dumps(prow), flush=True)

    inproc = {"a22": in_process_a22(), "perfc": {lv: in_process_perfc(lv) for lv in PERFC}}
    contact_perfc = {lv: contact_perfc_result(work, lv) for lv in PERFC} if have_contact else None
    machine["load_average_at_end"] = os.getloadavg()

    def contact_whole(key: str, level: str | None = None):
        if have_contact:
            rows = whole["a22"] if level is None else whole["perfc"][level]
            return {k: median([r["contact"] for r in rows], k) for k in ("wall_s", "cpu_s")}
        rec = recorded["a22"] if level is None else recorded["perfc"][level]
        return rec["contact_whole"]

    summary = {
        "case": CASE,
        "machine": machine,
        "pairs": pairs,
        "contact": f"run in this script ({CONTACT_EXE})"
        if have_contact
        else "recorded times read from the previous vs_contact.json",
        "wheelrail_commit": subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        ).stdout.strip(),
        "a22": {
            "contact_whole": contact_whole("a22"),
            "wheelrail_cli_whole": {
                k: median([r["wheelrail_cli"] for r in whole["a22"]], k) for k in ("wall_s", "cpu_s")
            },
            "wheelrail_api_whole": {
                k: median([r["wheelrail_api"] for r in whole["a22"]], k) for k in ("wall_s", "cpu_s")
            },
            "wheelrail_in_process": inproc["a22"],
            "pairs": whole["a22"],
        },
        "perfc": {},
    }
    for level in PERFC:
        wr = inproc["perfc"][level]
        entry = {
            "contact_whole": contact_whole("perfc", level),
            "wheelrail_whole": {
                k: median([r["wheelrail"] for r in whole["perfc"][level]], k) for k in ("wall_s", "cpu_s")
            },
            "wheelrail_in_process": wr,
            "pairs": whole["perfc"][level],
        }
        ref = contact_perfc[level] if contact_perfc else (recorded["perfc"][level].get("contact_result"))
        if ref:
            entry["contact_result"] = ref
            entry["difference"] = {
                "normal_force_rel": wr["normal_force_N"] / ref["normal_force_N"] - 1,
                "max_pressure_rel": wr["max_pressure_Pa"] / ref["max_pressure_Pa"] - 1,
                "contact_elements": wr["contact_elements"] - ref["contact_elements"],
            }
        summary["perfc"][level] = entry
    RESULTS.mkdir(parents=True, exist_ok=True)
    tmp_json = RESULTS / "vs_contact.json.tmp"
    tmp_json.write_text(json.dumps(summary, indent=2) + "\n")
    tmp_json.replace(RESULTS / "vs_contact.json")
    write_markdown(summary)


NUMBA_FLOOR_CPU_S = 0.87
"""CPU of a process that imports numba and loads one cached kernel (0.85-0.89 s, benchmarks/results/startup.md,
benchmarks/numba_floor_kernel.py): the floor of any wheelrail command that runs a compiled kernel."""


def goals(s: dict) -> list[str]:
    """Issue 27's speed goals against this run: met, or the gap and where it is."""
    a = s["a22"]
    cw, api, ip = a["contact_whole"], a["wheelrail_api_whole"], a["wheelrail_in_process"]
    whole = api["cpu_s"] / cw["cpu_s"]
    inproc = ip["cpu_s"] / cw["cpu_s"]
    rest = api["cpu_s"] - ip["cpu_s"]
    perfc = s["perfc"]
    first = next(iter(perfc.values()))
    small = first["wheelrail_whole"]["cpu_s"] / first["contact_whole"]["cpu_s"]
    ratios = {lv: e["wheelrail_in_process"]["cpu_s"] / e["contact_whole"]["cpu_s"] for lv, e in perfc.items()}

    def verdict(ok: bool) -> str:
        return "met" if ok else "not met"

    return [
        "",
        "## Issue 27's goals against this run",
        "",
        "| goal | measured (CPU ratio) | verdict |",
        "|---|---|---|",
        f"| A-2.2 whole process <= 1.0x CONTACT (stretch 0.5x) | {whole:.2f}x (Python API) | {verdict(whole <= 1.0)} |",
        f"| perfc NORM whole process <= 2x on the smallest deck | {small:.1f}x | {verdict(small <= 2.0)} |",
        "| perfc NORM in process <= 0.5x on all three | "
        + ", ".join(f"{r:.2f}x" for r in ratios.values())
        + f" | {verdict(all(r <= 0.5 for r in ratios.values()))} |",
        "",
        f"Where the A-2.2 gap is: in process wheelrail needs {ip['cpu_s']:.2f} s CPU for the 42 wheel-cases against "
        f"CONTACT's {cw['cpu_s']:.2f} s for its whole two runs ({inproc:.2f}x); the whole process adds "
        f"{rest:.2f} s, of which about {NUMBA_FLOOR_CPU_S} s is the floor of importing numba and loading one cached "
        "kernel (startup.md) and the rest the imports of the contact package and the case set-up. Reaching 1.0x "
        "needs both the per-case BEM below CONTACT's and start-up without numba's import (ahead-of-time compiled "
        "kernels, not done). In process (cProfile of the sweep after the direct FFT calls, session 17): the FFT "
        "arithmetic itself (scipy's duccfft r2c/c2c/c2r, about a third), TANG's Newton-loop numpy work and GMRES "
        "in Python, the undeformed distance on the deck's spline surfaces (plane_gap, contact_locus, about an "
        "eighth), and the final patches' grid-error estimate (solves on a grid twice as coarse, about a fifth, "
        "which CONTACT does not do). The perfc smallest deck is start-up bound the same way (CONTACT's whole run "
        "is about 0.05 s CPU, below wheelrail's numba floor "
        "alone); where an in-process perfc ratio is above 0.5x, its cause was not analysed.",
    ]


def write_markdown(s: dict) -> None:
    m, a = s["machine"], s["a22"]
    cw, cli, api, ip = a["contact_whole"], a["wheelrail_cli_whole"], a["wheelrail_api_whole"], a["wheelrail_in_process"]
    largest = ip["comparison"]["largest_difference"]
    diff_a22 = ", ".join(
        f"{k} {1e3 * v['value']:.3f} mm (step {v['step']})"
        if k == "contact_y_rail"
        else f"{k} {100 * v['value']:.2f} % (step {v['step']})"
        for k, v in largest.items()
    )
    per_case_contact = cw["cpu_s"] / ip["wheel_cases"]
    lines = [
        "# wheelrail against CONTACT, side by side (benchmarks/bench_vs_contact.py)",
        "",
        s["case"].replace("\n", " "),
        "",
        f"Machine: {m['cpu_model'] or m['processor']}, {m['cpu_count']} cores shared with other jobs "
        f"(load average {m['load_average_at_start'][0]:.1f} at start, {m['load_average_at_end'][0]:.1f} at end), "
        f"{m['platform']}, Python {m['python']}, numpy {m['numpy']}; {m['threads']}. CONTACT: {s['contact']}. "
        f"Medians over {s['pairs']} interleaved pairs; times in s, wall / CPU; ratio = wheelrail / CONTACT "
        "(CPU ratio first: wall times carry the other jobs' load).",
        "",
        "## Manchester A-2.2, 21 cases x 2 wheels",
        "",
        "| run | wall s | CPU s | ratio CPU | ratio wall |",
        "|---|---|---|---|---|",
        f"| CONTACT, both decks (whole process) | {cw['wall_s']:.2f} | {cw['cpu_s']:.2f} | 1 | 1 |",
        f"| `wheelrail manchester --method bem` (whole process, plots) | {cli['wall_s']:.2f} | {cli['cpu_s']:.2f} | "
        f"{cli['cpu_s'] / cw['cpu_s']:.2f}x | {cli['wall_s'] / cw['wall_s']:.2f}x |",
        f"| Python API, no plots (whole process) | {api['wall_s']:.2f} | {api['cpu_s']:.2f} | "
        f"{api['cpu_s'] / cw['cpu_s']:.2f}x | {api['wall_s'] / cw['wall_s']:.2f}x |",
        f"| wheelrail in process, `sweep('bem')` warm ({ip['wheel_cases']} wheel-cases) | {ip['wall_s']:.2f} | "
        f"{ip['cpu_s']:.2f} | {ip['cpu_s'] / cw['cpu_s']:.2f}x | {ip['wall_s'] / cw['wall_s']:.2f}x |",
        "",
        f"Per wheel-case in process: wheelrail {1e3 * ip['cpu_s'] / ip['wheel_cases']:.0f} ms CPU, CONTACT "
        f"{1e3 * per_case_contact:.0f} ms CPU (its whole-process CPU / {ip['wheel_cases']}). Error (wheelrail's "
        f"largest relative difference to CONTACT's published right-wheel solution): {diff_a22}; within the "
        f"comparison's tolerances: {ip['comparison']['within_tolerance']}.",
        "",
        "## CONTACT's perfc NORM decks (approach control)",
        "",
        "| deck | elements | CONTACT whole wall / CPU | wheelrail whole wall / CPU | ratio whole CPU (wall) | "
        "wheelrail in process wall / CPU | ratio in process CPU | wheelrail - CONTACT: FN, pmax, elements in contact |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for level, e in s["perfc"].items():
        mx, my, _ = PERFC[level]
        c, w, i = e["contact_whole"], e["wheelrail_whole"], e["wheelrail_in_process"]
        d = e.get("difference")
        dtxt = (
            f"{d['normal_force_rel']:+.1e}, {d['max_pressure_rel']:+.1e}, {d['contact_elements']:+d}"
            if d
            else "not compared"
        )
        lines.append(
            f"| norm_problm_{level} | {mx} x {my} | {c['wall_s']:.2f} / {c['cpu_s']:.2f} | {w['wall_s']:.2f} / "
            f"{w['cpu_s']:.2f} | {w['cpu_s'] / c['cpu_s']:.1f}x ({w['wall_s'] / c['wall_s']:.1f}x) | "
            f"{i['wall_s']:.3f} / {i['cpu_s']:.3f} | {i['cpu_s'] / c['cpu_s']:.2f}x | {dtxt} |"
        )
    lines += [
        "",
        "CONTACT's in-process time is taken as its whole-process CPU (a Fortran executable starts in milliseconds; "
        "its own `Total` timer has 0.1 s resolution). CONTACT's CPU for the small deck is at the resolution of the "
        "process accounting (10 ms), so that ratio is coarse.",
    ]
    lines += goals(s)
    tmp = RESULTS / "vs_contact.md.tmp"
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(RESULTS / "vs_contact.md")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--perfc-once":
        print(json.dumps(perfc_solve(sys.argv[2])))
    elif len(sys.argv) == 2 and sys.argv[1] == "--markdown":  # rewrite the .md from the recorded .json
        write_markdown(json.loads((RESULTS / "vs_contact.json").read_text()))
    else:
        main()
