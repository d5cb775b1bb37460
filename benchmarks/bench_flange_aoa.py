"""The leading wheelset of a bogie at a held angle of attack in ``curve-flange``'s curve: the flange patch as one
interpenetration region from the flange root to the flank, and what the single-point patch models do with it.

``curve-flange`` (S1002/UIC60 1:40, R = 100 m, cant 0.15 m, 50 km/h) with the primary suspension's frame yawed and
held (``suspension.frame_yaw_rad``: a bogie frame's angle at its axle, the leading axle of a bogie of semi-wheelbase
a at about -a/R; a = 1.25 m gives -12.5 mrad) and stiff longitudinal springs (3e7 N/m per side: the wheelset's yaw
stays within 0.3 mrad of the frame's), RK4 at 0.1 ms (half the step changes nothing visible: the table gives both),
0.6 s from the centred start (the flange is reached within 0.05 s). Per held angle: the left (flanging) wheel's
contact force over the last 0.3 s, main frame, on the wheel: Q the vertical, Y the lateral component, their means
and range; the share of samples whose patch sits on the flank (contact angle > 1.0 rad) and the range of the contact
point's y; the run's status with ``fastsim`` (Hertz's ellipse at the point) and ``kpec`` (the sampled gap, KPEC +
FASTSIM per strip).

Run: PYTHONPATH=. .venv/bin/python benchmarks/bench_flange_aoa.py  (writes benchmarks/results/flange_aoa.md/.json);
with ``--formed`` the -12.5 mrad runs of FASTSIM against KPEC on the formed patch (flange_aoa_formed.md/.json).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
OUT = ROOT / "benchmarks" / "results"
ANGLES_RAD = (0.0, -0.00455, -0.008, -0.0125)
"""Held frame yaws: none (the frame radial), curve-flange's own settled yaw, and two bogie leading-axle angles."""


def run(
    frame_yaw: float, model: str, step: float, duration: float = 0.6, geometry: str = "sampled", window: float = 0.3
) -> dict:
    from rigid_dynamics.wheelset.simulate import simulate
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    path = resolve_scene_path("curve-flange")
    doc = read_toml(path, "scene file")
    doc.update(duration_s=duration, contact_model=model, patch_geometry=geometry)
    doc["suspension"].update(frame_yaw_rad=frame_yaw, longitudinal_stiffness_N_per_m=3.0e7)
    doc["integrator"].update(fixed_step_s=step, output_step_s=1.0e-4)
    scene = parse_scene(doc, base_dir=path.parent)
    start = time.perf_counter()
    result = simulate(scene)
    wall = time.perf_counter() - start
    out = {"frame_yaw_rad": frame_yaw, "model": model, "patch_geometry": geometry, "step_s": step,
           "status": result.status,
           "message": result.message, "simulated_s": float(result.t[-1]) if len(result.t) else 0.0,
           "wall_s": wall}  # fmt: skip
    t = result.t
    late = t >= duration - window - 1e-12
    if result.status not in ("ok", "warning") or not late.any():  # a warning's numbers stand with its message
        return out
    force = result.contact_force_N[late, 0, :]  # left wheel, main frame
    q, y = -force[:, 2], force[:, 1]
    angle = result.patches["contact_angle_rad"][late, 0, :]
    point = result.patches["contact_point_y_m"][late, 0, :]
    flank = np.nanmax(angle, axis=1) > 1.0
    out.update(
        yaw_mean_rad=float(np.mean(result.states[late, 3])),
        q_mean_N=float(np.mean(q)), q_min_N=float(np.min(q)), q_max_N=float(np.max(q)),
        y_mean_N=float(np.mean(y)), y_min_N=float(np.min(y)), y_max_N=float(np.max(y)),
        y_over_q_mean=float(np.mean(y) / np.mean(q)),
        y_over_q_max=float(np.max(y[q > 0] / q[q > 0])) if np.any(q > 0) else math.nan,
        flank_share=float(np.mean(flank)),
        point_y_range_m=[float(np.nanmin(point)), float(np.nanmax(point))],
        angle_range_rad=[float(np.nanmin(angle)), float(np.nanmax(angle))],
    )  # fmt: skip
    return out


FORMED_YAW_RAD = -0.0125
FORMED_DURATION_S, FORMED_WINDOW_S = 0.3, 0.15


def formed() -> int:
    """``--formed``: at -12.5 mrad, FASTSIM on the ellipse against KPEC on the formed patch (``patch_geometry =
    "formed"``: the root-to-flank region joined and solved in the plane of its weighted contact angle), each at 0.1
    and 0.05 ms, 0.3 s (KPEC on formed patches costs about 800 s of CPU per simulated second here), the left wheel
    over the last 0.15 s (the flange is reached within 0.05 s). Writes flange_aoa_formed.md/.json.
    """
    from rigid_dynamics.files import write_json, write_text

    rows = []
    for model, geometry in (("fastsim", "sampled"), ("kpec", "formed")):
        for step in (1.0e-4, 5.0e-5):
            row = run(FORMED_YAW_RAD, model, step, FORMED_DURATION_S, geometry, FORMED_WINDOW_S)
            rows.append(row)
            print(json.dumps(row), flush=True)
    machine = (f"{platform.node()}, {os.cpu_count()} cores (shared), Python {platform.python_version()}; "
               f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")  # fmt: skip
    write_json(OUT / "flange_aoa_formed.json", {"machine": machine, "rows": rows})
    lines = [
        "# The flange-climbing case in the dynamics: the ellipse at the deepest point against KPEC on the formed patch",
        "",
        "(benchmarks/bench_flange_aoa.py --formed)",
        "",
        f"Machine: {machine}. curve-flange (R 100 m, 50 km/h) with the suspension frame held at -12.5 mrad (kx 3e7 "
        "N/m per side), RK4, 0.3 s; the left (flanging) wheel over the last 0.15 s, main frame. Y/Q max: the largest "
        "instantaneous ratio (samples every 0.1 ms).",
        "",
        "| model | patch | step | status | yaw | Q mean (min-max) kN | Y mean (min-max) kN | Y/Q of means | Y/Q max | "
        "contact angle range | wall |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "q_mean_N" not in r:
            lines.append(f"| {r['model']} | {r['patch_geometry']} | {1e3 * r['step_s']:.2f} ms | {r['status']}: "
                         f"{r['message'][:160]} | | | | | | | {r['wall_s']:.0f} s |")  # fmt: skip
            continue
        lines.append(
            f"| {r['model']} | {'formed' if r['patch_geometry'] == 'formed' else 'ellipse at the deepest point'} | "
            f"{1e3 * r['step_s']:.2f} ms | {r['status']} | {1e3 * r['yaw_mean_rad']:.2f} mrad | "
            f"{r['q_mean_N'] / 1e3:.1f} ({r['q_min_N'] / 1e3:.1f}-{r['q_max_N'] / 1e3:.1f}) | "
            f"{r['y_mean_N'] / 1e3:.1f} ({r['y_min_N'] / 1e3:.1f}-{r['y_max_N'] / 1e3:.1f}) | "
            f"{r['y_over_q_mean']:.3f} | {r['y_over_q_max']:.2f} | {r['angle_range_rad'][0]:.2f}-"
            f"{r['angle_range_rad'][1]:.2f} rad | {r['wall_s']:.0f} s |"
        )
    lines += ["", "Messages of the runs:", ""]
    lines += [f"- {r['model']} ({r['patch_geometry']}), {1e3 * r['step_s']:.2f} ms: {r['message']}" for r in rows]
    write_text(OUT / "flange_aoa_formed.md", "\n".join(lines) + "\n")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--formed", action="store_true", help="the -12.5 mrad runs with KPEC on the formed patch")
    if parser.parse_args(argv).formed:
        return formed()
    rows = []
    for frame_yaw in ANGLES_RAD:
        for model, step in (("fastsim", 1.0e-4), ("fastsim", 5.0e-5), ("kpec", 1.0e-4)):
            row = run(frame_yaw, model, step)
            rows.append(row)
            print(json.dumps(row), flush=True)
    from rigid_dynamics.files import write_json, write_text

    machine = f"{platform.node()}, {os.cpu_count()} cores, Python {platform.python_version()}"
    write_json(OUT / "flange_aoa.json", {"machine": machine, "rows": rows})
    lines = [
        "# A held angle of attack on the flange: one region from root to flank (benchmarks/bench_flange_aoa.py)",
        "",
        f"Machine: {machine}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}. curve-flange (R 100 m, 50 km/h) "
        "with the suspension frame held at the angle (kx 3e7 N/m per side), RK4, 0.6 s; the left (flanging) wheel "
        "over the last 0.3 s, main frame.",
        "",
        "| frame yaw | model | step | status | yaw | Q mean (min-max) kN | Y mean (min-max) kN | Y/Q of means | on the "
        "flank | contact angle range | wall |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "q_mean_N" not in r:
            lines.append(
                f"| {1e3 * r['frame_yaw_rad']:.2f} mrad | {r['model']} | {1e3 * r['step_s']:.2f} ms | {r['status']}: "
                f"{r['message'][:160]} | | | | | | | {r['wall_s']:.0f} s |"
            )
            continue
        lines.append(
            f"| {1e3 * r['frame_yaw_rad']:.2f} mrad | {r['model']} | {1e3 * r['step_s']:.2f} ms | {r['status']} | "
            f"{1e3 * r['yaw_mean_rad']:.2f} mrad | {r['q_mean_N'] / 1e3:.1f} ({r['q_min_N'] / 1e3:.1f}-"
            f"{r['q_max_N'] / 1e3:.1f}) | {r['y_mean_N'] / 1e3:.1f} ({r['y_min_N'] / 1e3:.1f}-"
            f"{r['y_max_N'] / 1e3:.1f}) "
            f"| {r['y_over_q_mean']:.2f} | {100 * r['flank_share']:.0f} % | {r['angle_range_rad'][0]:.2f}-"
            f"{r['angle_range_rad'][1]:.2f} rad | {r['wall_s']:.0f} s |"
        )
    write_text(OUT / "flange_aoa.md", "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
