"""The flange-climbing case's contact by three patch models at the same states: the ellipse at the deepest point
(FASTSIM, multi-Hertzian), KPEC on the sampled gap (semi-Hertzian: compiled, on the candidate's own plane at its
deepest point, and through the callback on the formed patch, ``patch_geometry = "formed"``) and the BEM on the
sampled, formed patch.

The states: ``curve-flange`` (S1002/UIC60 1:40, R = 100 m, cant 0.15 m, 50 km/h) with the primary suspension's
frame held at a yaw (``suspension.frame_yaw_rad``, the leading axle of a bogie; bench_flange_aoa.py) and stiff
longitudinal springs (3e7 N/m), run with ``fastsim`` (RK4, 0.1 ms) for 0.6 s; ``SAMPLES`` states evenly over its last
0.3 s. At each state every model's contact is evaluated by the loop itself (``WheelsetModel.contact``: the compiled
3-D search's candidates and the model's law or the callback), so the kinematics (pose, velocities, creepages at the
candidates) are the same and only the patch model differs. This is a quasi-static comparison: it does not say where
each model's own dynamics would settle (a BEM run costs about 2000 s of CPU per simulated second here), only what
each model makes of the same flanging state.

Per state, the left (flanging) wheel: Q and Y, the vertical and lateral components of the contact force on the wheel
(main frame, summed over its patches), Y/Q (Nadal's flange-climb ratio), and the flange patch's (the left patch of
largest contact angle) contact angle, normal force, area and maximum pressure. The BEM's own grid-error estimate of
each state's solves is recorded (the largest over the state's patches, of the forces and of all quantities: the loop's
own estimate from a solve on a grid twice as coarse, bem.model.grid_error_estimate).

Run: PYTHONPATH=. .venv/bin/python benchmarks/bench_flange_rungs.py [--samples N] [--angles -0.008,-0.0125]
(writes benchmarks/results/flange_rungs.md/.json)
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
MODELS = ("fastsim", "kpec", "kpec-formed", "bem")
"""The patch models compared; ``kpec-formed``: kpec with ``patch_geometry = "formed"`` (the static KPEC on the formed
patch through the callback, as CONTACT applies KPEC)."""
SAMPLES = 24
DURATION_S, WINDOW_S, STEP_S = 0.6, 0.3, 1.0e-4


def scene_at(frame_yaw: float, model: str, geometry: str = "sampled"):
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    path = resolve_scene_path("curve-flange")
    doc = read_toml(path, "scene file")
    doc.update(duration_s=DURATION_S, contact_model=model, patch_geometry=geometry)
    doc["suspension"].update(frame_yaw_rad=frame_yaw, longitudinal_stiffness_N_per_m=3.0e7)
    doc["integrator"].update(fixed_step_s=STEP_S, output_step_s=1.0e-4)
    return parse_scene(doc, base_dir=path.parent)


def flanging_states(frame_yaw: float, samples: int) -> tuple[np.ndarray, np.ndarray, dict]:
    """The FASTSIM run's states at ``samples`` times evenly over the last WINDOW_S, and the run's summary."""
    from rigid_dynamics.wheelset.simulate import simulate

    start = time.perf_counter()
    result = simulate(scene_at(frame_yaw, "fastsim"))
    wall = time.perf_counter() - start
    if result.status != "ok":
        raise RuntimeError(f"frame yaw {frame_yaw}: the FASTSIM run ended {result.status}: {result.message}")
    t = result.t
    times = np.linspace(DURATION_S - WINDOW_S, DURATION_S, samples)
    index = np.searchsorted(t, times - 1e-9)
    index = np.minimum(index, len(t) - 1)
    return t[index], result.states[index], {"status": result.status, "wall_s": wall}


def model_for(frame_yaw: float, name: str):
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.wheelset.simulate import build_provider, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    name, _, formed = name.partition("-")
    scene = scene_at(frame_yaw, name, "formed" if formed else "sampled")
    return WheelsetModel(scene, build_provider(scene), get_model(name), model_options(name, scene))


def left_wheel(model, state) -> dict:
    """Q, Y and the flange patch of the left wheel at ``state`` with ``model`` (module docstring)."""
    callback = getattr(model, "callback", None)
    grid = callback.grid_error if getattr(callback, "bem", False) else None
    if grid is not None:  # the BEM's own grid-error estimate of this state's solves (callback._record_grid_error)
        grid.update(largest_force=0.0, largest=0.0, estimated=0, not_estimated=0)
    try:
        contact = model.contact(state, record=True)
    except Exception as exc:  # the loop's failure (e.g. KPEC's contact-failed) is a status, not a number
        return {"status": "failed", "message": str(exc).splitlines()[0][:160]}
    left = contact.side == 0
    force = contact.force_N[left].sum(axis=0)
    values = contact.record
    serving = np.flatnonzero(left & (np.nan_to_num(values["normal_force_N"]) > 0))
    out = {"status": "ok", "q_N": float(-force[2]), "y_N": float(force[1]), "patches": int(len(serving))}
    out["y_over_q"] = out["y_N"] / out["q_N"] if out["q_N"] > 0 else math.nan
    if len(serving):
        k = int(serving[np.argmax(values["contact_angle_rad"][serving])])
        out.update(
            flange_angle_rad=float(values["contact_angle_rad"][k]),
            flange_normal_force_N=float(values["normal_force_N"][k]),
            flange_area_mm2=float(values["contact_area_m2"][k]) * 1e6,
            flange_max_pressure_MPa=float(values["max_pressure_Pa"][k]) * 1e-6,
            flange_geometry_code=int(values["patch_geometry_code"][k]) if "patch_geometry_code" in values else -1,
        )
    if grid is not None:
        out.update(grid_error_force=float(grid["largest_force"]), grid_error_all=float(grid["largest"]),
                   grid_estimated=int(grid["estimated"]))  # fmt: skip
    return out


def _stats(rows: list[dict], key: str) -> tuple[float, float, float]:
    v = np.array([r[key] for r in rows if r.get("status") == "ok" and key in r], float)
    return (float(np.mean(v)), float(np.min(v)), float(np.max(v))) if v.size else (math.nan,) * 3


def main(argv=None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=SAMPLES)
    parser.add_argument("--angles", default=",".join(str(a) for a in ANGLES_RAD))
    args = parser.parse_args(argv)
    angles = [float(a) for a in args.angles.split(",")]
    data = {"angles": []}
    for frame_yaw in angles:
        times, states, run = flanging_states(frame_yaw, args.samples)
        entry = {"frame_yaw_rad": frame_yaw, "fastsim_run": run, "times_s": times.tolist(), "models": {}}
        for name in MODELS:
            model = model_for(frame_yaw, name)
            start = time.process_time()
            rows = [left_wheel(model, state) for state in states]
            entry["models"][name] = {"rows": rows, "cpu_s": time.process_time() - start}
            ok = sum(r["status"] == "ok" for r in rows)
            print(f"frame yaw {frame_yaw:+.5f}: {name:8s} {ok}/{len(rows)} ok, Y/Q {_stats(rows, 'y_over_q')}, "
                  f"{entry['models'][name]['cpu_s']:.1f} s CPU", flush=True)  # fmt: skip
        data["angles"].append(entry)
    data["machine"] = (f"{platform.node()}, {os.cpu_count()} cores (shared), Python {platform.python_version()}, "
                       f"load average {os.getloadavg()[0]:.1f}")  # fmt: skip
    data["date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    write(data)
    return 0


def _pair_diff(a: list[dict], b: list[dict], key: str) -> tuple[float, int]:
    """Largest |a - b| / |b| over the states where both are ok, and the number of such states."""
    d = [abs(x[key] - y[key]) / abs(y[key]) for x, y in zip(a, b, strict=True)
         if x.get("status") == "ok" and y.get("status") == "ok" and key in x and key in y and y[key] != 0]  # fmt: skip
    return (max(d) if d else math.nan), len(d)


def write(data: dict) -> None:
    from rigid_dynamics.files import write_text

    lines = [
        "# The flange-climbing case's contact by three patch models at the same states "
        "(benchmarks/bench_flange_rungs.py)",
        "",
        (__doc__ or "").split("\n\nRun:")[0],
        "",
        f"Machine: {data['machine']}; {data['date']}.",
        "",
        "| held frame yaw | model | ok states | Y/Q mean (min-max) | Q mean kN | Y mean kN | flange patch angle rad |"
        " flange area mm2 | flange p max MPa | stated grid error: forces / all (largest) | CPU s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for entry in data["angles"]:
        for name, model in entry["models"].items():
            rows = model["rows"]
            ok = sum(r["status"] == "ok" for r in rows)
            yq, q, y = _stats(rows, "y_over_q"), _stats(rows, "q_N"), _stats(rows, "y_N")
            keys = ("flange_angle_rad", "flange_area_mm2", "flange_max_pressure_MPa")
            ang, area, pmax = (_stats(rows, k) for k in keys)
            grid = _stats(rows, "grid_error_force")[2], _stats(rows, "grid_error_all")[2]
            stated = f"{grid[0]:.1%} / {grid[1]:.1%}" if math.isfinite(grid[0]) else "not stated"
            lines.append(
                f"| {entry['frame_yaw_rad'] * 1e3:.2f} mrad | {name} | {ok}/{len(rows)} | {yq[0]:.3f} ({yq[1]:.3f}-"
                f"{yq[2]:.3f}) | {q[0] / 1e3:.1f} | {y[0] / 1e3:.1f} | {ang[1]:.2f}-{ang[2]:.2f} | "
                f"{area[0]:.1f} ({area[1]:.1f}-{area[2]:.1f}) | {pmax[0]:.0f} ({pmax[1]:.0f}-{pmax[2]:.0f}) | "
                f"{stated} | {model['cpu_s']:.1f} |"
            )
    lines += ["", "Largest difference to the BEM on the sampled patch at the same state (relative to the BEM's value):",
              "",
              "| held frame yaw | model | Q | Y | Y/Q | flange area | flange p max | states compared |",
              "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for entry in data["angles"]:
        bem = entry["models"]["bem"]["rows"]
        for name in ("fastsim", "kpec", "kpec-formed"):
            rows = entry["models"][name]["rows"]
            cells = []
            count = 0
            for key in ("q_N", "y_N", "y_over_q", "flange_area_mm2", "flange_max_pressure_MPa"):
                d, count = _pair_diff(rows, bem, key)
                cells.append(f"{d:.1%}" if math.isfinite(d) else "-")
            lines.append(f"| {entry['frame_yaw_rad'] * 1e3:.2f} mrad | {name} | " + " | ".join(cells) + f" | {count} |")
    failures = [(e["frame_yaw_rad"], n, r["message"]) for e in data["angles"] for n, m in e["models"].items()
                for r in m["rows"] if r["status"] != "ok"]  # fmt: skip
    if failures:
        lines += ["", "Failed evaluations (a status, not a number):", ""]
        lines += [f"- {fy * 1e3:.2f} mrad, {n}: {msg}" for fy, n, msg in failures[:12]]
    OUT.mkdir(parents=True, exist_ok=True)
    write_text(OUT / "flange_rungs.md", "\n".join(lines) + "\n")
    write_text(OUT / "flange_rungs.json", json.dumps(data, indent=1) + "\n")


if __name__ == "__main__":
    sys.exit(main())
