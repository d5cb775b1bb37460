"""Compare the wheelset case on CONTACT's wheel-flat example (examples/wheelflat.inp) with CONTACT's published solution.

Usage: ``python benchmarks/bench_wheelflat_contact.py CONTACT_EXAMPLES_DIR [PITCH_DEG ...]`` (default -25 -37 -40).
CONTACT_EXAMPLES_DIR is the ``examples`` folder of a CONTACT checkout (eve70a/CONTACT, Apache-2.0): the slices file
``S1002_flat.slcw`` with its slice folder and the rail ``r300_wide.prr`` are read from there (not copied into this
repository). The reference numbers are ``comparisons/data/contact_wheelflat/wheelflat_ref_out.csv`` (SOURCE.md).
Writes ``benchmarks/results/wheelflat_contact.md``; the time per position is the whole solve (search, patches,
BEM) after a first position that compiles.

Set-up as the deck: right wheel, roll 0 (per-wheel kinematics), total vertical force 125 kN, pitch rate
-4.08190679 rad/s, V = 2 m/s, r0 = 0.49 m, cant 0.020 rad, BEM with 0.4 mm elements; the wheel profile is the first
slice, the out-of-roundness the slices' deviation from it (with the base's offset at the tape circle: the files'
wheel), both smoothed as CONTACT's wheel SMOOTH 5 with its default ISMOOTH 0 (L_filt 9.1 mm,
slices.contact_smoothing_wavelength_m), the rail not smoothed (its SMOOTH 0).
wheel_rotation_rad = -PITCH.
"""

from __future__ import annotations

import csv
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case  # noqa: E402
from rigid_dynamics.files import write_text  # noqa: E402
from rigid_dynamics.geometry.slices import contact_smoothing_wavelength_m, read_wheel_slices  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

CONTACT_WHEEL_SMOOTH = 5.0  # the deck's wheel SMOOTH (ISMOOTH 0: a smoothing parameter, not a wavelength)


def main(argv):
    examples = Path(argv[0])
    pitches = [float(v) for v in argv[1:]]
    reference = {}
    with open(ROOT / "comparisons/data/contact_wheelflat/wheelflat_ref_out.csv") as f:
        for row in csv.DictReader(f):
            reference[float(row["pitch_deg"])] = {k: float(v) for k, v in row.items()}
    pitches = pitches or sorted(reference, reverse=True)
    first = next(line for line in (examples / "S1002_flat.slcw").read_text().splitlines() if "'" in line)
    base = examples / first.split("'")[1]
    smoothing_m = contact_smoothing_wavelength_m(CONTACT_WHEEL_SMOOTH, base)
    slices = read_wheel_slices(examples / "S1002_flat.slcw", smoothing_wavelength_m=smoothing_m)
    material = Material(82e9, 0.28, 0.3)
    lines = [
        "# CONTACT's wheelflat.inp: wheelset case (BEM, 0.4 mm) against CONTACT's published solution",
        "",
        "Forces on the rail as CONTACT prints them (ours on the wheel, sign turned for FX). `python "
        "benchmarks/bench_wheelflat_contact.py CONTACT/examples`.",
        "",
        "| PITCH deg | FX ours / CONTACT N | FS ours / CONTACT N | approach mm | PMAX MPa | area mm2 | YCP(R) mm | "
        "XCP mm | CKSI (ours, CONTACT) | diff FN, FX, FS (of mu FN), PMAX, area % | time s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for pitch in pitches:
        case = WheelsetCase(
            wheel_profile=str(base), rail_profile=str(examples / "r300_wide.prr"), gauge_m=1.435,
            gauge_height_m=0.014, flange_back_distance_m=1.360, nominal_radius_m=0.49, rail_inclination_rad=0.02,
            wheel_load_N=125e3, rolling_speed_m_per_s=2.0, roll_rad=0.0, pitch_rate_rad_per_s=-4.08190679,
            wheel_rotation_rad=-math.radians(pitch), wheel_irregularities_right=(slices.irregularity,),
            profile_smoothing_m=smoothing_m, rail_profile_smoothing_m=0.0,
        )  # fmt: skip
        started = time.perf_counter()
        sol = solve_wheelset_case(
            case, material, "bem", options={"sides": ("right",), "model": {"element_size_m": 4e-4}}
        )
        seconds = time.perf_counter() - started
        ref = reference[pitch]
        fn = sum(p.result.normal_force_N for p in sol.patches)
        mu_fn = 0.3 * ref["fn_N"]
        for p in sol.patches:
            r = p.result
            diffs = (
                100 * (fn / ref["fn_N"] - 1), 100 * (-r.creep_force_long_N - ref["fx_N"]) / mu_fn,
                100 * (r.creep_force_lat_N - ref["fs_N"]) / mu_fn,
                100 * (r.max_pressure_Pa / 1e6 / ref["pmax_MPa"] - 1),
                100 * (1e6 * r.contact_area_m2 / ref["area_mm2"] - 1),
            )  # fmt: skip
            lines.append(
                f"| {pitch:g} | {-r.creep_force_long_N:.0f} / {ref['fx_N']:.0f} | {r.creep_force_lat_N:.0f} / "
                f"{ref['fs_N']:.0f} | {1e3 * r.approach_m:.4f} / {ref['approach_mm']:.4f} | "
                f"{r.max_pressure_Pa / 1e6:.0f} / {ref['pmax_MPa']:.0f} | {1e6 * r.contact_area_m2:.1f} / "
                f"{ref['area_mm2']:.1f} | {1e3 * p.geometry.contact_point_rail_m[0]:.2f} / {ref['ycp_rail_mm']:.2f} | "
                f"{1e3 * p.geometry.point_m[0]:.2f} / {ref['xcp_tr_mm']:.2f} | {p.creepage.longitudinal:.3e}, "
                f"{ref['cksi']:.3e} | {', '.join(f'{d:+.1f}' for d in diffs)} | {seconds:.1f} |"
            )
    write_text(ROOT / "benchmarks/results/wheelflat_contact.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main(sys.argv[1:])
