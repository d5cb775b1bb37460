"""Patch formation on out-of-round wheels (issue 28): the contact locus, wheel_patches and plane_gap per call, and the
whole ``polygonal-wheel`` run with ``contact_model = "bem"``, before and after the fast out-of-round locus.

Usage: ``python benchmarks/bench_oor_patches.py [BASE_COMMIT [BASE_DIR]]`` (default: the commit before the fast
locus, c67f299). The base commit is exported (git archive) to BASE_DIR (default: a temporary directory; an existing
export keeps its compiled-code cache) and both trees run the same worker
in their own process, interleaved, on the same poses: the polygonal-wheel scene's surfaces (3rd-order polygon of
0.3 mm) at four wheel angles with a lateral shift and yaw, and the wheel-flat scene's (50 mm rounded flat, 0.34 mm
deep) at five angles around the flat (the flat's middle under the wheel: its two lowest points along x), each
lowered 0.1 mm below its first touch. Per pose and tree: process CPU time per call (the least of 5) of
``contact_locus`` (the out-of-round locus), ``wheel_patches`` and ``plane_gap`` on a 60 x 60 grid over the patch
(as the BEM rung asks it at its element centres), and the results; the differences of the results are reported
beside the times. Then ``polygonal-wheel`` with ``contact_model = "bem"`` for 0.01 s in each tree (compiled code
loaded before the clock): the callback's seconds, its patch-sampling seconds and the final state and forces.
Writes ``benchmarks/results/oor_patches.md`` and ``.json``. CPU times, not wall: the machine is shared.
"""

from __future__ import annotations

import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BASE_COMMIT = "c67f299"
SPINS_POLYGON_RAD = (0.1, 0.5, 0.9, 1.3)
FLAT_OFFSETS_RAD = (-0.03, -0.01, 0.0, 0.004, 0.02)
REPEATS = 5


def _best(fn, repeats=REPEATS):
    times, value = [], None
    for _ in range(repeats):
        start = time.process_time()
        value = fn()
        times.append(time.process_time() - start)
    return min(times), value


def worker(out_path: str) -> None:
    """Time and record the pose set with the tree on sys.path (a subprocess of :func:`main`)."""
    import numpy as np

    from rigid_dynamics.contact import wheelset_patches as wp
    from rigid_dynamics.contact.search import WheelsetPose, _SideGeometry
    from rigid_dynamics.wheelset.providers.surfaces import build_surfaces
    from wheelrail.scenes import load_scene, resolve_scene_path

    rows, arrays = [], {}
    for scene_name in ("polygonal-wheel", "wheel-flat"):
        scene = load_scene(resolve_scene_path(scene_name))
        wheel, rail = build_surfaces(scene.wheelset, scene.track, scene.irregularities).fast["right"]

        def geo(pose, wheel=wheel, rail=rail):
            return _SideGeometry(wheel, rail, pose, "right", wheel.y_range_m, rail.y_range_m)

        if scene_name == "polygonal-wheel":
            spins, shift = SPINS_POLYGON_RAD, 0.002
        else:
            spins, shift = [0.5 * math.pi - wheel.irregularity_rows[0, 1] + o for o in FLAT_OFFSETS_RAD], 0.0
        for spin in spins:
            z = -0.46
            for _ in range(3):
                pose = WheelsetPose(y_m=shift, z_m=z, yaw_rad=0.002, spin_rad=spin)
                z += float(np.nanmin(wp.contact_locus(geo(pose)).gap_m))
            pose = WheelsetPose(y_m=shift, z_m=z + 1.0e-4, yaw_rad=0.002, spin_rad=spin)
            g = geo(pose)
            wp.contact_locus(g)  # compiled code loaded
            t_locus, locus = _best(lambda g=g: wp.contact_locus(g))
            kwargs = dict(wheel_lateral_range_m=wheel.y_range_m, rail_lateral_range_m=rail.y_range_m,
                          nominal_radius_m=scene.wheelset.nominal_radius_m)  # fmt: skip
            t_patches, (patches, _) = _best(lambda a=(wheel, rail, pose), k=kwargs: wp.wheel_patches(*a, "right", **k))
            key = f"{scene_name}_{spin:.4f}"
            row = {"scene": scene_name, "spin_rad": spin, "locus_s": t_locus, "patches_s": t_patches,
                   "patches": len(patches), "locus_points": int(locus.gap_m.size)}  # fmt: skip
            for name in ("alpha_rad", "point_m", "gap_m", "weight_line_m3", "weighted_x_m", "overlap_x_m"):
                arrays[f"{key}_locus_{name}"] = getattr(locus, name)
            if patches:
                p = max(patches, key=lambda q: q.geometry.approach_m)
                und = p.geometry.undeformed
                x0, x1, y0, y1 = und.potential_area_m
                gx, gy = np.meshgrid(np.linspace(x0, x1, 60), np.linspace(y0, y1, 60))
                und.exact(gx, gy)
                t_plane, field = _best(lambda und=und, gx=gx, gy=gy: und.exact(gx, gy))
                row["plane_gap_s"] = t_plane
                arrays[f"{key}_plane"] = field
                arrays[f"{key}_patch"] = np.concatenate(
                    [p.geometry.point_m, [p.geometry.contact_angle_rad, p.geometry.approach_m,
                                          p.geometry.curvature_long_1_per_m, p.geometry.curvature_lat_1_per_m]]
                )  # fmt: skip
            rows.append(row)
    np.savez(out_path, **arrays)
    print("ROWS " + json.dumps(rows), flush=True)


def whole_run(duration_s: float) -> None:
    """polygonal-wheel with BEM for duration_s in the tree on sys.path (a subprocess of :func:`main`)."""
    from dataclasses import replace

    import numpy as np

    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene, resolve_scene_path

    scene = replace(load_scene(resolve_scene_path("polygonal-wheel")), contact_model="bem", duration_s=duration_s)
    simulate(replace(scene, duration_s=0.0005))  # compiled code loaded
    cpu, wall = time.process_time(), time.perf_counter()
    result = simulate(scene)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    stats = result.callback_stats or {}
    p = result.patches
    out = {
        "process_cpu_s": cpu, "wall_s": wall, "callback_s": stats.get("seconds"),
        "sampling_s": stats.get("sampling_seconds"), "bem_solves": stats.get("bem", {}).get("solves"),
        "final_state": [float(v) for v in result.states[-1]],
        "normal_force_N": [float(v) for v in np.asarray(p["normal_force_N"])[-1].ravel()],
        "creep_force_long_N": [float(v) for v in np.asarray(p["creep_force_long_N"])[-1].ravel()],
        "creep_force_lat_N": [float(v) for v in np.asarray(p["creep_force_lat_N"])[-1].ravel()],
    }  # fmt: skip
    print("RUN " + json.dumps(out), flush=True)


def _run(tree: Path, args: list[str]) -> str:
    env = dict(os.environ, PYTHONPATH=str(tree))
    done = subprocess.run([sys.executable, __file__, *args], cwd=tree, env=env, capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"{tree}: {done.stderr[-2000:]}")
    return done.stdout


def _max_diff(a, b) -> float:
    import numpy as np

    a, b = np.asarray(a, float), np.asarray(b, float)
    both = np.isfinite(a) & np.isfinite(b)
    if not np.array_equal(np.isfinite(a), np.isfinite(b)):
        return math.inf
    return float(np.max(np.abs(a[both] - b[both]))) if both.any() else 0.0


def main(argv) -> None:
    import numpy as np

    from rigid_dynamics.files import write_text as write_atomic

    base_commit = argv[0] if argv else BASE_COMMIT
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(argv[1]) if len(argv) > 1 else Path(tmp) / "base"
        if not (base / "rigid_dynamics").exists():  # (an existing export is left as it is: numba's cache sees mtimes)
            base.mkdir(exist_ok=True)
            archive = subprocess.run(["git", "-C", str(ROOT), "archive", base_commit], capture_output=True, check=True)
            subprocess.run(["tar", "-x", "-C", str(base)], input=archive.stdout, check=True)
        (base / "benchmarks" / "bench_oor_patches.py").write_text(Path(__file__).read_text())
        trees = {"before": base, "after": ROOT}
        rows, arrays, runs = {}, {}, {}
        for label, tree in trees.items():  # the per-call poses, each tree in its own process
            npz = Path(tmp) / f"{label}.npz"
            out = _run(tree, ["--worker", str(npz)])
            rows[label] = json.loads(out.split("ROWS ", 1)[1])
            arrays[label] = dict(np.load(npz))
        for label, tree in (("before", base), ("after", ROOT)):
            runs[label] = json.loads(_run(tree, ["--run", "0.01"]).split("RUN ", 1)[1])
    machine = {"platform": platform.platform(), "cpu_count": os.cpu_count(), "load_at_end": os.getloadavg()}
    table = []
    for before, after in zip(rows["before"], rows["after"], strict=True):
        key = f"{before['scene']}_{before['spin_rad']:.4f}"
        diffs = {
            name: _max_diff(arrays["before"][f"{key}_locus_{name}"], arrays["after"][f"{key}_locus_{name}"])
            for name in ("alpha_rad", "point_m", "gap_m", "weighted_x_m", "overlap_x_m")
        }
        w0, w1 = arrays["before"][f"{key}_locus_weight_line_m3"], arrays["after"][f"{key}_locus_weight_line_m3"]
        diffs["weight_rel"] = float(np.max(np.abs(w1 - w0)) / max(float(np.max(w0)), 1e-300))
        if f"{key}_plane" in arrays["before"]:
            diffs["plane_gap_m"] = _max_diff(arrays["before"][f"{key}_plane"], arrays["after"][f"{key}_plane"])
            diffs["patch"] = (arrays["after"][f"{key}_patch"] - arrays["before"][f"{key}_patch"]).tolist()
        table.append({"before": before, "after": after, "differences": diffs})
    summary = {"base_commit": base_commit, "commit": head.stdout.strip(), "machine": machine, "poses": table,
               "runs": runs}  # fmt: skip
    out = ROOT / "benchmarks" / "results"
    write_atomic(out / "oor_patches.json", json.dumps(summary, indent=2) + "\n")
    lines = [
        "# Out-of-round patch formation, before and after the fast locus (benchmarks/bench_oor_patches.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Before: {base_commit}; after: {summary['commit']} (+ working tree). Machine {machine['platform']}, "
        f"{machine['cpu_count']} cores shared with other jobs (load average {machine['load_at_end'][0]:.1f} at the "
        "end); process CPU times, the least of 5 calls.",
        "",
        "| scene | spin rad | locus ms before / after (x) | wheel_patches ms before / after (x) | plane_gap 60x60 ms "
        "before / after (x) | max diff: gap m | alpha rad | point m | weight rel | weighted x m | overlap x m | "
        "plane gap m |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]

    def cell(b, a, key):
        if key not in b:
            return "-"
        return f"{1e3 * b[key]:.1f} / {1e3 * a[key]:.1f} ({b[key] / a[key]:.1f})"

    for row in table:
        b, a, d = row["before"], row["after"], row["differences"]
        lines.append(
            f"| {b['scene']} | {b['spin_rad']:.3f} | {cell(b, a, 'locus_s')} | {cell(b, a, 'patches_s')} | "
            f"{cell(b, a, 'plane_gap_s')} | {d['gap_m']:.1e} | {d['alpha_rad']:.1e} | {d['point_m']:.1e} | "
            f"{d['weight_rel']:.1e} | {d['weighted_x_m']:.1e} | {d['overlap_x_m']:.1e} | "
            f"{d.get('plane_gap_m', float('nan')):.1e} |"
        )
    rb, ra = runs["before"], runs["after"]
    state = max(abs(x - y) for x, y in zip(rb["final_state"], ra["final_state"], strict=True))
    forces = {
        k: max(abs(x - y) for x, y in zip(rb[k], ra[k], strict=True) if math.isfinite(x) and math.isfinite(y))
        for k in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")
    }
    lines += [
        "",
        'Whole run: `polygonal-wheel` with contact_model "bem", 0.01 s (20 RK4 steps), each tree in its own process:',
        "",
        "| tree | process CPU s | wall s | callback s | patch sampling s | BEM solves |",
        "|---|---|---|---|---|---|",
    ]
    for label, r in runs.items():
        lines.append(
            f"| {label} | {r['process_cpu_s']:.1f} | {r['wall_s']:.1f} | {r['callback_s']:.1f} | "
            f"{r['sampling_s']:.1f} | {r['bem_solves']} |"
        )
    lines += [
        "",
        f"Callback {rb['callback_s'] / ra['callback_s']:.2f}x, patch sampling "
        f"{rb['sampling_s'] / ra['sampling_s']:.2f}x faster. Results: final state max |difference| {state:.1e} "
        "(SI units), last sample's forces max |difference| "
        + ", ".join(f"{k} {v:.1e} N" for k, v in forces.items())
        + ".",
        "",
        "The callback's and the sampling's seconds are wall time (the callback's own clocks) and the process ran on a "
        "loaded machine: its CPU time (process CPU s) is the steadier ratio of the whole run. The locus's angle "
        "differs from the reference's by up to a few 1e-8 rad: the reference's golden section stops at its rounding "
        "(its last steps compare gaps closer than their round-off); Newton's minimum has the same gap to 1e-15 m "
        "(tests/test_oor_locus_fast.py).",
    ]
    write_atomic(out / "oor_patches.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    if sys.argv[1:2] == ["--worker"]:
        sys.path.insert(0, os.environ.get("PYTHONPATH", str(ROOT)))
        worker(sys.argv[2])
    elif sys.argv[1:2] == ["--run"]:
        whole_run(float(sys.argv[2]))
    else:
        sys.path.insert(0, str(ROOT))
        main(sys.argv[1:])
