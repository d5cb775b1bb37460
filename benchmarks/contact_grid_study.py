"""CONTACT's own solution of Manchester A-2.2 steps 6, 11 and 17 (right wheel) on refined grids.

The published solution (examples/mbench_a22_right of CONTACT, comparisons/data/contact_reference) is CONTACT's
at the deck's 0.2 mm x 0.2 mm elements. Its max pressure and contact area depend on the element size: the area
is NCON dx ds (whole elements in contact) and PMAX an element's mean pressure. On the flange (step 17) the patch
is 3-4 elements wide at 0.2 mm. This script runs the same deck (the step's pose, roll, pitch rate, 10 kN,
A_SEP 90 deg, D_SEP 8 mm, D_COMB 4 mm; only DX and DS changed) at finer elements and records FN, FX, FS, PMAX,
NCON, the area and the patch count, so that the named cases a22-* can be compared with a grid-converged CONTACT
solution (comparisons/cases/a22-*/contact_grid.csv).

Needs a built CONTACT executable (E.A.H. Vollebregt, J.J. Kalker, Vtech CMCC, open source under Apache-2.0;
not part of this repository) and its A-2.2 decks: environment variables CONTACT_EXE and CONTACT_DECKS (a folder
with mbench_a22_right.inp and the profiles MBench_S1002_v3.prw, MBench_UIC60_v3.prr).

Writes benchmarks/results/contact_grid.json and .md, and with ``--write-cases`` the cases' contact_grid.csv.
Run: CONTACT_EXE=... CONTACT_DECKS=... .venv/bin/python benchmarks/contact_grid_study.py [--write-cases]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

STEPS = {6: "a22-tread", 11: "a22-flange-root", 17: "a22-flange"}
GRIDS_MM = ((0.2, 0.2), (0.1, 0.1), (0.05, 0.05), (0.1, 0.025), (0.05, 0.025))
"""(DX, DS) in mm; the first is the deck's own."""
NPOT_MAX = 400_000
"""CONTACT's limit on the elements of a potential contact area (its default 20000 enlarges fine grids)."""
COLUMNS = (
    "case", "dx_mm", "ds_mm", "n_patches", "fn_N", "fx_N", "fs_N", "pmax_N_per_mm2", "ncon", "contact_area_mm2",
    "wall_time_s",
)  # fmt: skip


def step_deck(deck_text: str, step: int, dx_mm: float, ds_mm: float) -> str:
    """The deck's first case (all settings) with the pose and velocities of ``step`` and elements DX x DS."""
    blocks = re.split(r"\n(?=%\s*\d+:)", deck_text)
    header, first = blocks[0], blocks[1]
    target = next(b for b in blocks[1:] if re.match(rf"%\s*{step}:", b))
    pose = next(line for line in target.splitlines() if "S, Y, FZ" in line)
    speed = next(line for line in target.splitlines() if "VS,VY" in line)
    out = []
    for line in first.splitlines():
        if "MAXGS" in line:  # NPOT_MAX (6th value): CONTACT otherwise doubles DX, DS above 20000 elements
            line = "  " + "  ".join(line.split()[:5]) + f"  {NPOT_MAX}   MAXGS, MAXIN, MAXNR, MAXOUT, EPS, NPOT_MAX"
        elif "DX, DS, DQREL" in line:
            rest = line.split()[2:]
            line = f"  {dx_mm:.4f}  {ds_mm:.4f}  " + "  ".join(rest[:4]) + "      DX, DS, DQREL, A_SEP, D_SEP, D_COMB"
        elif "S, Y, FZ" in line:
            line = pose
        elif "VS,VY" in line:
            line = speed
        out.append(line)
    return header + "\n" + "\n".join(out) + "\n\n 0 MODULE\n"


def parse_out(text: str, dx_mm: float, ds_mm: float) -> dict:
    """FN, FX, FS summed over the right wheel's patches, the largest PMAX, NCON summed, area = NCON dx ds."""
    lines = text.splitlines()
    enlarged = [line for line in lines if "enlarged dx,dy" in line]
    if enlarged:
        raise RuntimeError(f"CONTACT enlarged the elements ({enlarged[-1].strip()}): raise NPOT_MAX")
    fn = fx = fs = 0.0
    pmax, ncon, patches = 0.0, 0, 0
    for i, line in enumerate(lines):
        if line.split()[:3] == ["FN", "FX", "FS"]:
            values = [float(v) for v in lines[i + 1].split()[:3]]
            fn, fx, fs = fn + values[0], fx + values[1], fs + values[2]
            pmax = max(pmax, float(lines[i + 3].split()[4]))
            patches += 1
        elif line.split()[:2] == ["NPOT", "NCON"]:
            ncon += int(lines[i + 1].split()[1])
    return {
        "n_patches": patches, "fn_N": fn, "fx_N": fx, "fs_N": fs, "pmax_N_per_mm2": pmax, "ncon": ncon,
        "contact_area_mm2": ncon * dx_mm * ds_mm,
    }  # fmt: skip


def run_case(exe: str, decks: Path, step: int, dx_mm: float, ds_mm: float) -> dict:
    deck = (decks / "mbench_a22_right.inp").read_text()
    with tempfile.TemporaryDirectory() as tmp:
        for profile in decks.glob("*.pr?"):
            shutil.copy(profile, tmp)
        (Path(tmp) / "grid.inp").write_text(step_deck(deck, step, dx_mm, ds_mm))
        t0 = time.perf_counter()
        done = subprocess.run([exe, "2", "grid"], cwd=tmp, check=False, capture_output=True, text=True)
        elapsed = time.perf_counter() - t0
        out = Path(tmp) / "grid.out"
        text = out.read_text() if out.exists() else ""
    if done.returncode != 0 or "ended succesfully" not in done.stdout:
        raise RuntimeError(f"CONTACT step {step} at {dx_mm} x {ds_mm} mm failed: {done.stdout[-300:]}")
    return {"case": step, "dx_mm": dx_mm, "ds_mm": ds_mm, **parse_out(text, dx_mm, ds_mm), "wall_time_s": elapsed}


def bem_rows(grids) -> list[dict]:
    """Our ``bem`` rung on the same decks (kinematics "deck", right wheel) with square elements of the same sizes."""
    from comparisons.manchester import MATERIAL, a22_case
    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case

    track = build_track(a22_case(0, "deck"))  # the deck's profiles (SMOOTH = 0)
    rows = []
    for step in STEPS:
        for dx, ds in grids:
            if dx != ds:
                continue
            t0 = time.perf_counter()
            options = {"model": {"element_size_m": dx * 1e-3}, "sides": ("right",)}
            sol = solve_wheelset_case(a22_case(step - 1, "deck"), MATERIAL, "bem", options, track=track)
            res = [p.result for p in sol.patches if p.side == "right"]
            rows.append({
                "case": step, "dx_mm": dx, "ds_mm": ds, "n_patches": len(res),
                "fn_N": sum(r.normal_force_N for r in res), "fx_N": -sum(r.creep_force_long_N for r in res),
                "fs_N": sum(r.creep_force_lat_N for r in res),
                "pmax_N_per_mm2": max(r.max_pressure_Pa for r in res) * 1e-6,
                "contact_area_mm2": sum(r.contact_area_m2 for r in res) * 1e6,
                "wall_time_s": time.perf_counter() - t0,
            })  # fmt: skip
            print(json.dumps(rows[-1]), flush=True)
    return rows


def markdown(result: dict) -> str:
    lines = [
        "# CONTACT's A-2.2 solution against its element size (benchmarks/contact_grid_study.py)",
        "",
        f"CONTACT {result['contact']} (E.A.H. Vollebregt, J.J. Kalker; Apache-2.0), run here on "
        f"{result['machine']} ({result['date']}). Right wheel, the deck's kinematics (roll, pitch rate, 10 kN, "
        "A_SEP 90 deg, D_SEP 8 mm, D_COMB 4 mm); only DX and DS changed. Area = NCON dx ds. Forces on the rail.",
        "",
        "| step | case | DX x DS [mm] | patches | FN [N] | FX [N] | FS [N] | PMAX [MPa] | NCON | area [mm2] | time |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in result["rows"]:
        lines.append(
            f"| {r['case']} | {STEPS[r['case']]} | {r['dx_mm']:g} x {r['ds_mm']:g} | {r['n_patches']} | "
            f"{r['fn_N']:.5g} | {r['fx_N']:.5g} | {r['fs_N']:.5g} | {r['pmax_N_per_mm2']:.5g} | {r['ncon']} | "
            f"{r['contact_area_mm2']:.4g} | {r['wall_time_s']:.1f} s |"
        )
    if result.get("bem"):
        contact = {(r["case"], r["dx_mm"], r["ds_mm"]): r for r in result["rows"]}
        lines += [
            "",
            "## Our BEM at the same element size (`--with-bem`)",
            "",
            'The `bem` rung on the same deck (comparisons.manchester, kinematics "deck", right wheel) with square '
            "elements of CONTACT's size aligned with the reference point (option element_size_m); forces on the rail "
            "as above; differences to CONTACT at the same size (FX, FS in % of mu FN).",
            "",
            "| step | DX [mm] | patches | FN | FX | FS | PMAX [MPa] | area [mm2] | d FN | d FX | d FS | d PMAX "
            "| d area |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for b in result["bem"]:
            c = contact.get((b["case"], b["dx_mm"], b["ds_mm"]))
            if c is None:
                continue
            mu_fn = 0.3 * c["fn_N"]
            d = [
                b["fn_N"] / c["fn_N"] - 1, (b["fx_N"] - c["fx_N"]) / mu_fn, (b["fs_N"] - c["fs_N"]) / mu_fn,
                b["pmax_N_per_mm2"] / c["pmax_N_per_mm2"] - 1, b["contact_area_mm2"] / c["contact_area_mm2"] - 1,
            ]  # fmt: skip
            lines.append(
                f"| {b['case']} | {b['dx_mm']:g} | {b['n_patches']} | {b['fn_N']:.5g} | {b['fx_N']:.5g} | "
                f"{b['fs_N']:.5g} | {b['pmax_N_per_mm2']:.5g} | {b['contact_area_mm2']:.4g} | "
                + " | ".join(f"{100 * v:+.2f} %" for v in d)
                + " |"
            )
    return "\n".join(lines) + "\n"


def write_case_grids(result: dict) -> list[Path]:
    """comparisons/cases/<name>/contact_grid.csv for each step of ``result`` (rows sorted by element size)."""
    written = []
    for step, name in STEPS.items():
        rows = sorted((r for r in result["rows"] if r["case"] == step), key=lambda r: -r["dx_mm"] * r["ds_mm"])
        if not rows:
            continue
        head = (
            f"# CONTACT {result['contact']} (E.A.H. Vollebregt, J.J. Kalker, Vtech CMCC; open source, Apache-2.0), "
            f"run here ({result['date']}; {result['machine']}) by benchmarks/contact_grid_study.py on its example deck "
            f"examples/mbench_a22_right.inp, case {step} alone with DX and DS changed (NPOT_MAX {NPOT_MAX}); the "
            "0.2 mm row is the published solution. Units mm, N, N/mm^2; forces on the rail; area = NCON dx ds.\n"
        )
        lines = [",".join(COLUMNS)]
        for r in rows:
            lines.append(",".join(f"{r[c]:.6g}" if isinstance(r[c], float) else str(r[c]) for c in COLUMNS))
        path = ROOT / "comparisons" / "cases" / name / "contact_grid.csv"
        tmp = path.with_suffix(".csv.tmp")
        tmp.write_text(head + "\n".join(lines) + "\n")
        tmp.replace(path)
        written.append(path)
    return written


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, nargs="*", default=list(STEPS))
    parser.add_argument("--grids", nargs="*", default=[f"{dx}x{ds}" for dx, ds in GRIDS_MM], help="DXxDS in mm")
    parser.add_argument("--contact-version", default="revision 2707 of 2025-07-23")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "contact_grid"))
    parser.add_argument("--from-json", nargs="*", default=None, help="merge earlier outputs instead of running")
    parser.add_argument("--write-cases", action="store_true", help="write comparisons/cases/a22-*/contact_grid.csv")
    parser.add_argument("--with-bem", action="store_true", help="also run our bem rung at the same element sizes")
    args = parser.parse_args(argv)
    if args.from_json:
        parts = [json.loads(Path(p).read_text()) for p in args.from_json]
        result = {**parts[0], "rows": [r for p in parts for r in p["rows"]]}
        result["machine"] = "; ".join(dict.fromkeys(p["machine"] for p in parts))
        result["date"] = ", ".join(dict.fromkeys(p["date"] for p in parts))
        if args.with_bem:
            sizes = sorted({(r["dx_mm"], r["ds_mm"]) for r in result["rows"]}, reverse=True)
            result["bem"] = bem_rows(sizes)
        _write(result, Path(args.out))
        if args.write_cases:
            print("\n".join(str(p) for p in write_case_grids(result)))
        return 0
    exe, decks = os.environ.get("CONTACT_EXE"), os.environ.get("CONTACT_DECKS")
    if not exe or not decks:
        print("contact_grid_study: error: set CONTACT_EXE and CONTACT_DECKS", file=sys.stderr)
        return 2
    grids = [tuple(float(v) for v in g.split("x")) for g in args.grids]
    rows = []
    for step in args.steps:
        for dx, ds in grids:
            rows.append(run_case(exe, Path(decks), step, dx, ds))
            print(json.dumps(rows[-1]), flush=True)
    result = {
        "contact": args.contact_version,
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, load {tuple(round(v, 2) for v in os.getloadavg())}",
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "rows": rows,
    }
    if args.with_bem:
        result["bem"] = bem_rows(grids)
    _write(result, Path(args.out))
    if args.write_cases:
        print("\n".join(str(p) for p in write_case_grids(result)))
    return 0


def _write(result: dict, out: Path) -> None:
    assert all(math.isfinite(r["fn_N"]) for r in result["rows"])
    out.parent.mkdir(parents=True, exist_ok=True)
    for suffix, text in ((".json", json.dumps(result, indent=1)), (".md", markdown(result))):
        tmp = out.with_suffix(suffix + ".tmp")
        tmp.write_text(text)
        tmp.replace(out.with_suffix(suffix))


if __name__ == "__main__":
    raise SystemExit(main())
