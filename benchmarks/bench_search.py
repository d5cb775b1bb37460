"""Run time and error of the 3-D wheel-rail contact search (both sides of one wheelset pose).

Poses of the Manchester benchmark A-2.2 (S1002 on UIC60 1:40, equilibrium z and roll for 10 kN per wheel):
shift 0 mm (tread), 5 mm with 12 mrad yaw (tread + flange-root two-point contact), 7 mm with 16.8 mrad yaw
(flange). For each pose:

* time of ``WheelsetTrack.search`` for both sides (best of repeats; numba kernels compiled beforehand), without
  the sampled undeformed-distance field, with it (31 x 31 points per patch), and the profile-only fast path;
* error: deepest approach of each patch against a dense brute-force scan (h on a 0.002 rad x 0.1 mm grid with
  the numpy implementation of eq 11, which converges to the same surfaces but shares no minimisation code),
  max |q_search - q_scan| over the patches (the scan's grid error is O(grid^2 x curvature), so the search is
  expected to be as deep or deeper: the column is the scan's deficit);
* the full wheelset case (equilibrium + Hertz per patch) for comparison.

Irregular surfaces (same equilibrium poses, moved to x = 13 mm and spin 0.02 rad so that the flat is under
the wheel): a 3rd-order polygon (0.3 mm), a 50 mm rounded flat, 50 mm / 30 um corrugation. Time of both sides
by the compiled path (Hermite table + closed-form irregularities in numba) and by the general numpy path on the
exact surfaces (what ran before the compiled irregular path existed), and the largest difference between the
two (approach, contact point, relative A and B, frame).

Writes benchmarks/results/search.json and search.md. Run: .venv/bin/python benchmarks/bench_search.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.contact.search import SIDES, WheelsetPose, _SideGeometry, search_side  # noqa: E402
from rigid_dynamics.contact.track import build_track  # noqa: E402
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case  # noqa: E402
from rigid_dynamics.materials import STEEL  # noqa: E402

POSES = (0.0, 5.0, 7.0)  # shift in mm; yaw 2.4 mrad per mm


def best_time(func, repeats=30, inner=5):
    func()
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            func()
        best = min(best, (time.perf_counter() - t0) / inner)
    return best


def scan(track, pose, side):
    from scipy import ndimage

    wheel, rail = track.fast[side]
    geo = _SideGeometry(wheel, rail, pose, side, wheel.y_range_m, rail.y_range_m)
    a, y = np.meshgrid(
        np.pi / 2 + np.arange(-0.1, 0.1 + 1e-12, 0.002), np.arange(*wheel.y_range_m, 1e-4), indexing="ij"
    )
    h = geo.distance(a, y, 12)[0]
    labels, count = ndimage.label(h < 0)
    return sorted(-float(np.min(np.where(labels == k, h, np.inf))) for k in range(1, count + 1))


def measure(shift_mm):
    case = WheelsetCase(
        "MBench_S1002_v3", "MBench_UIC60_v3", lateral_shift_m=shift_mm * 1e-3, yaw_rad=shift_mm * 2.4e-3,
        rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4, rolling_speed_m_per_s=2.0,
    )  # fmt: skip
    track = build_track(case)
    options = {"search": {"field": False}}
    sol = solve_wheelset_case(case, STEEL, "hertz", options, track=track)
    pose = sol.pose
    ideal = WheelsetPose(y_m=pose.y_m, z_m=pose.z_m, roll_rad=pose.roll_rad)  # no yaw: profile-only is exact

    def both(search_options, p=pose):
        return [track.search(p, side, search_options) for side in SIDES]

    t_plain = best_time(lambda: both({"field": False}))
    t_field = best_time(lambda: both({"field": True}), repeats=10)
    t_profile = best_time(lambda: both({"field": False, "profile_only": True}, ideal))
    t_case = best_time(lambda: solve_wheelset_case(case, STEEL, "hertz", options, track=track), repeats=3, inner=1)
    result = both({"field": False})
    deficit = 0.0
    n_patches = 0
    for side, res in zip(SIDES, result, strict=True):
        found = sorted(p.approach_m for p in res.patches)
        reference = scan(track, pose, side)
        if len(found) != len(reference):
            deficit = math.inf
            continue
        n_patches += len(found)
        deficit = max(deficit, max((q - r for q, r in zip(found, reference, strict=True)), default=0.0))
    return pose, {
        "shift_mm": shift_mm,
        "yaw_mrad": shift_mm * 2.4,
        "patches": n_patches,
        "search_both_sides_ms": 1e3 * t_plain,
        "search_with_field_ms": 1e3 * t_field,
        "profile_only_no_yaw_ms": 1e3 * t_profile,
        "wheelset_case_ms": 1e3 * t_case,
        "scan_deficit_m": deficit,
    }


def irregular_scenes():
    from rigid_dynamics.geometry import HarmonicOutOfRoundness, RailCorrugation, WheelFlat

    return {
        "polygon 3rd order 0.3 mm": {"wheel_irregularities": {s: (HarmonicOutOfRoundness(3, 3e-4),) for s in SIDES}},
        "rounded flat 50 mm": {"wheel_irregularities": {s: (WheelFlat(0.05, 0.46),) for s in SIDES}},
        "corrugation 50 mm, 30 um": {"rail_irregularities": {s: (RailCorrugation(0.05, 3e-5),) for s in SIDES}},
    }


def measure_irregular(scene, kwargs, shift_mm, pose):
    case = WheelsetCase(
        "MBench_S1002_v3", "MBench_UIC60_v3", lateral_shift_m=shift_mm * 1e-3, yaw_rad=shift_mm * 2.4e-3,
        rail_inclination_rad=math.atan(1 / 40), wheel_load_N=1e4, rolling_speed_m_per_s=2.0,
    )  # fmt: skip
    track = build_track(case, **kwargs)
    pose = WheelsetPose(0.013, pose.y_m, pose.z_m, pose.yaw_rad, pose.roll_rad, 0.02)
    opts = {"field": False}

    def compiled():
        return [track.search(pose, side, opts) for side in SIDES]

    def numpy_path():
        return [
            search_side(
                track.wheels[s], track.rails[s], pose, s, wheel_lateral_range_m=track.wheels[s].y_range_m,
                rail_lateral_range_m=track.rails[s].y_range_m, options=opts,
            )
            for s in SIDES
        ]  # fmt: skip

    t_fast = best_time(compiled)
    t_slow = best_time(numpy_path, repeats=5, inner=2)
    diff = {"approach_m": 0.0, "point_m": 0.0, "a_rel": 0.0, "b_rel": 0.0, "frame": 0.0}
    n_patches, same = 0, True
    for fast, slow in zip(compiled(), numpy_path(), strict=True):
        if len(fast.patches) != len(slow.patches):
            same = False
            continue
        for p, q in zip(fast.patches, slow.patches, strict=True):
            n_patches += 1
            diff["approach_m"] = max(diff["approach_m"], abs(p.approach_m - q.approach_m))
            diff["point_m"] = max(diff["point_m"], float(np.max(np.abs(p.point_m - q.point_m))))
            diff["a_rel"] = max(diff["a_rel"], abs(p.curvature_long_1_per_m / q.curvature_long_1_per_m - 1))
            diff["b_rel"] = max(diff["b_rel"], abs(p.curvature_lat_1_per_m / q.curvature_lat_1_per_m - 1))
            diff["frame"] = max(diff["frame"], float(np.max(np.abs(p.frame - q.frame))))
    return {
        "scene": scene,
        "shift_mm": shift_mm,
        "patches": n_patches,
        "same_patch_count": same,
        "compiled_ms": 1e3 * t_fast,
        "numpy_ms": 1e3 * t_slow,
        "speed_up": t_slow / t_fast,
        "max_difference": diff,
    }


def main():
    measured = [measure(shift_mm) for shift_mm in POSES]
    rows = [row for _, row in measured]
    irregular = [
        measure_irregular(scene, kwargs, shift_mm, pose)
        for scene, kwargs in irregular_scenes().items()
        for shift_mm, (pose, _) in zip(POSES, measured, strict=True)
    ]
    out = {
        "benchmark": "3-D contact search, one wheelset pose (both sides)",
        "target_ms": 2.0,
        "machine": {
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "cpu_count": os.cpu_count(),
            "python": platform.python_version(),
            "threads": "1 (OMP/OPENBLAS/NUMBA_NUM_THREADS=1)",
        },
        "settings": "alpha grid 11 points over +-0.1 rad, lateral step 1 mm, Hermite tables 20 um, numba kernels",
        "rows": rows,
        "irregular_rows": irregular,
    }
    results = ROOT / "benchmarks" / "results"
    results.mkdir(parents=True, exist_ok=True)
    (results / "search.json").write_text(json.dumps(out, indent=2) + "\n")
    lines = [
        "# Contact search benchmark",
        "",
        f"Machine: {out['machine']['platform']}, {out['machine']['processor']}, {out['machine']['cpu_count']} CPUs "
        f"(shared), Python {out['machine']['python']}, one thread. Target: <= {out['target_ms']} ms per pose.",
        "",
        f"Settings: {out['settings']}. Poses: Manchester A-2.2 equilibrium (S1002/UIC60 1:40, 10 kN per wheel).",
        "",
        "| shift mm | yaw mrad | patches | search ms (both sides) | with gap field ms | profile-only ms "
        "| wheelset case ms | approach deficit of dense scan m |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['shift_mm']:.1f} | {r['yaw_mrad']:.1f} | {r['patches']} | {r['search_both_sides_ms']:.2f} "
            f"| {r['search_with_field_ms']:.2f} | {r['profile_only_no_yaw_ms']:.2f} | {r['wheelset_case_ms']:.1f} "
            f"| {r['scan_deficit_m']:.2e} |"
        )
    lines += [
        "",
        "Error column: deepest approach found by the search minus that of a dense brute-force scan (0.002 rad x",
        "0.1 mm grid, numpy implementation); >= 0 means the search is at least as deep (the scan misses the",
        "exact minimum by its grid error); inf would mean a patch count mismatch. The gap-field column grew",
        "from 9 to ~21 ms at 0 mm since the first run of this script with the fitted field (the code before the",
        "compiled irregular path gives the same 22 ms on this machine: not a change of the search kernels).",
        "",
        "## Irregular surfaces: compiled path against the numpy path",
        "",
        "Same equilibrium poses moved to x = 13 mm, spin 0.02 rad (the flat, centred at the lowest point of the",
        "unrotated wheel, is under the wheel 9 mm from its centre). Compiled: Hermite table of the ideal profile +",
        "closed-form irregularities in numba. numpy: the general path on the exact surfaces (scipy profile splines",
        "point by point), which irregular surfaces took before. Differences: largest over the patches of both sides.",
        "",
        "| scene | shift mm | patches | compiled ms (both sides) | numpy ms | speed-up | max dq m | max dpoint m "
        "| max dA/A | max dB/B | max dframe |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in irregular:
        d = r["max_difference"]
        count = str(r["patches"]) if r["same_patch_count"] else f"{r['patches']} (count differs)"
        lines.append(
            f"| {r['scene']} | {r['shift_mm']:.1f} | {count} | {r['compiled_ms']:.2f} | {r['numpy_ms']:.1f} "
            f"| {r['speed_up']:.1f} | {d['approach_m']:.1e} | {d['point_m']:.1e} | {d['a_rel']:.1e} "
            f"| {d['b_rel']:.1e} | {d['frame']:.1e} |"
        )
    (results / "search.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
