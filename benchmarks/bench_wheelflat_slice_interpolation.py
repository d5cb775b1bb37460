"""Why the wheelset case is off CONTACT on its wheel-flat example: the slices' spline along the wheel's angle.

Usage: ``python benchmarks/bench_wheelflat_slice_interpolation.py CONTACT_EXAMPLES_DIR [PITCH_DEG ...]`` (default
-37 -40, the positions with the flat at the contact). CONTACT_EXAMPLES_DIR is the ``examples`` folder of a CONTACT
checkout (eve70a/CONTACT, Apache-2.0; read from there, not copied). The reference numbers are
``comparisons/data/contact_wheelflat/wheelflat_ref_out.csv`` (SOURCE.md there). Writes
``benchmarks/results/wheelflat_slice_interpolation.md`` and ``.json``.

The example's slices file says TH_INTPOL = 2: CONTACT takes the slices as the control points of a cubic B-spline
along the angle (rigid_dynamics.geometry.slices, module docstring), which smooths the flat's edges over about one
slice (1 mm here). Each position is solved twice with the set-up of bench_wheelflat_contact.py (BEM, 0.4 mm
elements, right wheel, 125 kN, CONTACT's pitch rate): the slices read as the file says ("approximating", the
reader's behaviour) and read as interpolating (the reader's behaviour before it honoured TH_INTPOL: the same file
with TH_INTPOL 1). Time per position beside the differences; the machine is stated in the output.
"""

from __future__ import annotations

import csv
import json
import math
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case  # noqa: E402
from rigid_dynamics.files import write_text  # noqa: E402
from rigid_dynamics.geometry.slices import read_wheel_slices  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

SMOOTHING_M = 0.005
KEYS = ("fx_N", "fs_N", "pmax_MPa", "area_mm2")


def _interpolating_copy(slcw: Path, folder: Path) -> Path:
    """The slices file with TH_INTPOL 1 and absolute slice paths, written into ``folder``."""
    out, seen = [], 0
    for line in slcw.read_text().splitlines():
        text = line.split("%")[0].strip()
        if text and "'" not in text:
            seen += 1
            if seen == 4:  # TH_OFFSET TH_SCALE / NSLC / NFEAT NKINK NACCEL / TH_INTPOL
                line = "1"
        elif "'" in text:
            angle, name = text.split("'")[0], text.split("'")[1]
            line = f"{angle} '{(slcw.parent / name).resolve()}'"
        out.append(line)
    path = folder / slcw.name
    path.write_text("\n".join(out) + "\n")
    return path


def _solve(examples: Path, slices, pitch: float):
    first = next(line for line in (examples / "S1002_flat.slcw").read_text().splitlines() if "'" in line)
    base = examples / first.split("'")[1]
    case = WheelsetCase(
        wheel_profile=str(base), rail_profile=str(examples / "r300_wide.prr"), gauge_m=1.435,
        gauge_height_m=0.014, flange_back_distance_m=1.360, nominal_radius_m=0.49, rail_inclination_rad=0.02,
        wheel_load_N=125e3, rolling_speed_m_per_s=2.0, roll_rad=0.0, pitch_rate_rad_per_s=-4.08190679,
        wheel_rotation_rad=-math.radians(pitch), wheel_irregularities_right=(slices.irregularity,),
        profile_smoothing_m=SMOOTHING_M,
    )  # fmt: skip
    started = time.perf_counter()
    sol = solve_wheelset_case(
        case, Material(82e9, 0.28, 0.3), "bem", options={"sides": ("right",), "model": {"element_size_m": 4e-4}}
    )
    seconds = time.perf_counter() - started
    (patch,) = sol.patches
    r = patch.result
    values = {
        "fx_N": -r.creep_force_long_N,  # on the rail, as CONTACT prints it
        "fs_N": r.creep_force_lat_N,
        "pmax_MPa": r.max_pressure_Pa / 1e6,
        "area_mm2": 1e6 * r.contact_area_m2,
    }
    return values, seconds, sol.status


def main(argv):
    examples = Path(argv[0])
    pitches = [float(v) for v in argv[1:]] or [-37.0, -40.0]
    reference = {}
    with open(ROOT / "comparisons/data/contact_wheelflat/wheelflat_ref_out.csv") as f:
        for row in csv.DictReader(f):
            reference[float(row["pitch_deg"])] = {k: float(v) for k, v in row.items()}
    slcw = examples / "S1002_flat.slcw"
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        variants = {
            "approximating (TH_INTPOL 2, the file's)": read_wheel_slices(slcw, smoothing_wavelength_m=SMOOTHING_M),
            "interpolating (TH_INTPOL 1)": read_wheel_slices(
                _interpolating_copy(slcw, Path(tmp)), smoothing_wavelength_m=SMOOTHING_M
            ),
        }
        for pitch in pitches:
            ref = reference[pitch]
            for name, slices in variants.items():
                values, seconds, status = _solve(examples, slices, pitch)
                diff = {k: values[k] / ref[k] - 1.0 for k in ("pmax_MPa", "area_mm2")}
                mu_fn = 0.3 * ref["fn_N"]
                diff.update({k: (values[k] - ref[k]) / mu_fn for k in ("fx_N", "fs_N")})
                rows.append({"pitch_deg": pitch, "slices": name, "status": status, "seconds": seconds,
                             "ours": values, "contact": {k: ref[k] for k in KEYS}, "difference": diff})  # fmt: skip
                print(rows[-1], flush=True)
    machine = f"{platform.platform()}, {os.cpu_count()} CPUs shared with other jobs, Python "
    machine += f"{platform.python_version()}; load average at the end {tuple(round(v, 2) for v in os.getloadavg())}"
    lines = [
        "# CONTACT's wheelflat example: the slices' spline along the angle (approximating vs interpolating)",
        "",
        f"`python benchmarks/bench_wheelflat_slice_interpolation.py CONTACT/examples`; machine: {machine}. "
        "BEM 0.4 mm elements, right wheel, 125 kN (as bench_wheelflat_contact.py). Differences to CONTACT: PMAX and "
        "area relative, FX and FS as a fraction of mu FN (FX, FS on the rail as CONTACT prints them).",
        "",
        "| PITCH deg | slices along the angle | PMAX MPa ours / CONTACT (diff) | area mm2 (diff) "
        "| FX N (diff of mu FN) | FS N (diff of mu FN) | time s |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        o, c, d = r["ours"], r["contact"], r["difference"]
        lines.append(
            f"| {r['pitch_deg']:g} | {r['slices']} | {o['pmax_MPa']:.0f} / {c['pmax_MPa']:.0f} "
            f"({100 * d['pmax_MPa']:+.1f} %) | {o['area_mm2']:.1f} / {c['area_mm2']:.1f} "
            f"({100 * d['area_mm2']:+.1f} %) "
            f"| {o['fx_N']:.0f} / {c['fx_N']:.0f} ({100 * d['fx_N']:+.1f} %) | {o['fs_N']:.0f} / {c['fs_N']:.0f} "
            f"({100 * d['fs_N']:+.1f} %) | {r['seconds']:.0f} |"
        )
    write_text(ROOT / "benchmarks/results/wheelflat_slice_interpolation.md", "\n".join(lines) + "\n")
    write_text(
        ROOT / "benchmarks/results/wheelflat_slice_interpolation.json",
        json.dumps({"machine": machine, "rows": rows}, indent=1) + "\n",
    )
    print("\n".join(lines))


if __name__ == "__main__":
    main(sys.argv[1:])
