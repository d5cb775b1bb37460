"""Gauge-face lubrication in a tight curve: curve-flange dry (mu 0.4 everywhere) against the lubricated gauge face
(the embedded scene curve-flange-lubricated: mu 0.4 on the rail head up to 0.2 rad surface inclination, 0.1 from
0.4 rad, linear between; each patch placed by its contact angle).

Both runs: the embedded curve-flange set-up (S1002/UIC60 1:40, R = 100 m, cant 0.15 m, 50 km/h, the 3-D search,
Hertz + FASTSIM 20 x 20, RK4 at 0.5 ms over 2 s). Reported at the end of the run (settled: the embedded scene
settles within 1 s) per wheel: the contact forces on the wheel in the main frame (Y lateral, Q vertical), Y/Q, and
per patch the normal force, the creep forces (contact frame) and the friction coefficient at its contact angle.

Discretisation errors, per quantity, from two extra runs of each case: FASTSIM on 40 x 40 (the grid) and RK4 at
0.25 ms (the step); the larger of the two differences is stated beside each number. The dry-lubricated difference is
called significant when it exceeds the sum of the two cases' errors.

Run: ``.venv/bin/python benchmarks/study_gauge_face_lubrication.py``; writes
benchmarks/results/gauge_face_lubrication.json and .md.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.files import write_text  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402
from rigid_dynamics.wheelset import simulate  # noqa: E402
from wheelrail.scenes import load_scene  # noqa: E402

OUT = ROOT / "benchmarks" / "results"
DRY_MU = 0.4
SIDES = ("outer", "inner")
"""The curve turns right: the left wheel is the outer one."""
WINDOW_START_S = 1.0
"""The statistics' window: t from 1 s to the end (2 s); the embedded scene settles within 1 s."""
GAUGE_SIDE_RAD = 0.2
"""A patch beyond the rail head: contact angle above the lubricated scene's first node."""


def scenes():
    """(dry 0.4, dry 0.3, lubricated): the embedded curve-flange-lubricated, and the same with one Coulomb
    coefficient everywhere (0.4: the lubricated scene's rail head; 0.3: the embedded curve-flange's)."""
    lubricated = load_scene("curve-flange-lubricated")
    m = lubricated.material

    def dry(mu):
        material = Material(m.shear_modulus_Pa, m.poisson_ratio, mu)
        return replace(lubricated, name=f"curve-flange-dry-{mu:g}", material=material)

    return dry(DRY_MU), dry(0.3), lubricated


def variants(scene):
    """The base run and its two error probes (FASTSIM 40 x 40; RK4 at half the step)."""
    step = scene.integrator.fixed_step_s
    return {
        "base": scene,
        "grid_40x40": replace(scene, fastsim_elements_per_strip=40, fastsim_strips=40),
        "half_step": replace(scene, integrator=replace(scene.integrator, fixed_step_s=0.5 * step)),
    }


def _stat(reduce, values) -> float:
    """``reduce`` over ``values``; NaN when there are none (a run that failed before the window says why)."""
    return float(reduce(values)) if np.size(values) else float("nan")


def quantities(result) -> dict:
    """Statistics over the window t >= WINDOW_START_S (module text): per wheel the mean and the largest of Y/Q,
    the mean Y and Q (main frame, on the wheel), the sums over its patches of the normal force and the creep forces
    (contact frames); for the outer wheel the largest normal force of a patch beyond the rail head (contact angle
    above the first node, 0.2 rad: on the gauge corner or face) and the range of its contact angle.
    """
    keep = result.t >= WINDOW_START_S
    p, f = result.patches, result.contact_force_N[keep]
    normal = np.nan_to_num(p["normal_force_N"][keep])
    angle = p["contact_angle_rad"][keep]
    out = {}
    for i, side in enumerate(SIDES):
        loaded = f[:, i, 2] != 0.0  # Q = 0: the wheel lifted (Y/Q undefined there; counted below)
        ratio = f[loaded, i, 1] / f[loaded, i, 2]
        out[f"{side}: Y/Q mean"] = _stat(np.mean, ratio)
        out[f"{side}: |Y/Q| max"] = _stat(np.max, np.abs(ratio))
        out[f"{side}: Y mean (N)"] = _stat(np.mean, f[:, i, 1])
        out[f"{side}: Q mean (N)"] = _stat(np.mean, f[:, i, 2])
        out[f"{side}: N mean (N)"] = _stat(np.mean, normal[:, i].sum(axis=1))
        out[f"{side}: T_x mean (N)"] = _stat(np.mean, np.nansum(p["creep_force_long_N"][keep][:, i], axis=1))
        out[f"{side}: T_y mean (N)"] = _stat(np.mean, np.nansum(p["creep_force_lat_N"][keep][:, i], axis=1))
    gauge = np.where((angle[:, 0] > GAUGE_SIDE_RAD) & (normal[:, 0] > 0), normal[:, 0], 0.0)
    out["outer: gauge-side patch N max (N)"] = _stat(np.max, gauge)
    out["outer: gauge-side patch N mean (N)"] = _stat(np.mean, gauge.sum(axis=1))
    touching = angle[:, 0][normal[:, 0] > 0]
    out["outer: contact angle min (rad)"] = _stat(np.min, touching)
    out["outer: contact angle max (rad)"] = _stat(np.max, touching)
    out["wheel lifts in the window"] = float(
        sum(1 for kind, _, time_s in result.events if kind == "wheel-lift" and time_s >= WINDOW_START_S)
    )
    return out


def run() -> dict:
    data = {"cases": {}, "machine": machine()}
    for scene in scenes():
        runs = {}
        for label, variant in variants(scene).items():
            start = time.perf_counter()
            result = simulate(variant)
            runs[label] = {
                "status": result.status,
                "message": result.message,
                "wall_time_s": time.perf_counter() - start,
                "values": quantities(result),
            }
            print(f"{scene.name} {label}: {result.status} in {runs[label]['wall_time_s']:.1f} s", flush=True)
        base = runs["base"]["values"]
        errors = {}
        for key, value in base.items():
            diffs = [abs(runs[v]["values"].get(key, np.nan) - value) for v in ("grid_40x40", "half_step")]
            errors[key] = {"grid": diffs[0], "step": diffs[1], "stated": float(np.nanmax(diffs + [0.0]))}
        data["cases"][scene.name] = {"runs": runs, "errors": errors}
    return data


def machine() -> dict:
    return {
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "load_average_1min_start": os.getloadavg()[0],
    }


def render(data: dict) -> str:
    names = list(data["cases"])
    cases = [data["cases"][n] for n in names]
    keys = list(cases[0]["runs"]["base"]["values"])
    m = data["machine"]
    lines = [
        "# Gauge-face lubrication on curve-flange (benchmarks/study_gauge_face_lubrication.py)",
        "",
        "curve-flange (S1002/UIC60 1:40, R = 100 m, cant 0.15 m, 50 km/h, the 3-D search, Hertz + FASTSIM 20 x 20, "
        "RK4 0.5 ms, 2 s): the lubricated gauge face (scene curve-flange-lubricated: Coulomb mu 0.4 on the rail head "
        "up to 0.2 rad surface inclination, 0.1 from 0.4 rad, linear between, by each patch's contact angle) against "
        "one coefficient everywhere, 0.4 (dry) and 0.3 (the embedded curve-flange). Statistics over t = 1-2 s; "
        "forces on the wheel, Y and Q in the main frame (z down: Q < 0), N, T_x, T_y summed over the wheel's "
        "patches in their contact frames. Error (in brackets): the larger change of the statistic in a run with "
        "FASTSIM 40 x 40 or with RK4 at 0.25 ms.",
        "",
        "| quantity | " + " | ".join(names) + " |",
        "|---|" + "---|" * len(names),
    ]
    for key in keys:
        cells = []
        for case in cases:
            value, error = case["runs"]["base"]["values"][key], case["errors"][key]["stated"]
            cells.append(f"{value:.4g} ({error:.2g})")
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    lines += ["", "Runs:", ""]
    for name, case in data["cases"].items():
        for label, r in case["runs"].items():
            lines.append(f"- {name} {label}: status {r['status']} ({r['message']}), {r['wall_time_s']:.1f} s")
    lines += [
        "",
        f"Machine: {m['platform']}, {m['cpu_count']} CPUs, Python {m['python']}, numpy {m['numpy']}; shared with "
        f"other jobs (1-min load average {m['load_average_1min_start']:.2f} at the start).",
        "",
    ]
    return "\n".join(lines)


def main() -> None:
    json_path, md_path = OUT / "gauge_face_lubrication.json", OUT / "gauge_face_lubrication.md"
    data = json.loads(json_path.read_text()) if "--render" in sys.argv else run()
    if "--render" not in sys.argv:
        write_text(json_path, json.dumps(data, indent=2) + "\n")
    write_text(md_path, render(data))
    print(render(data))


if __name__ == "__main__":
    main()
