"""The wheel-flat scene's peaks against the beam's modal cut-off (issue 27: its lateral peaks were judged at 5 kHz).

The embedded ``wheel-flat`` scene (discretely supported Timoshenko beam, RK4) with ``[track_dynamics]
cutoff_frequency_Hz`` = 5, 10, 15, 20 kHz and the finest as the converged reference; at each cut-off the step
is the scene's or, where the start's stability check refuses it, the scene's halved until it passes (the wall
time includes the refused starts). Recorded per
run: status, step, settled peaks of each wheel's normal force and of its lateral and longitudinal creep force
(forces on the wheel, patch frames summed per wheel), their difference to the reference (relative to the
reference peak), the run's own force-error estimate, and the wall time.

Run: ``.venv/bin/python benchmarks/bench_wheelflat_cutoff.py [--cutoffs 5000 10000 20000] [--duration 0.4]`` ->
benchmarks/results/wheelflat_cutoff.json and .md.
"""

import argparse
import dataclasses
import json
import os
import platform
import sys
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

QUANTITIES = ("normal_force_N", "creep_force_lat_N", "creep_force_long_N")


def run(cutoff_hz: float, duration_s: float | None) -> dict:
    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    scene = load_scene("wheel-flat")
    scene = dataclasses.replace(
        scene, track_dynamics=dataclasses.replace(scene.track_dynamics, cutoff_frequency_Hz=float(cutoff_hz))
    )
    if duration_s is not None:
        scene = dataclasses.replace(scene, duration_s=float(duration_s))
    start = time.perf_counter()
    for _ in range(4):  # the scene's step, halved while the start's stability check refuses it
        result = simulate(scene)
        if result.status != "step-unstable":
            break
        integrator = dataclasses.replace(scene.integrator, fixed_step_s=scene.integrator.fixed_step_s / 2)
        scene = dataclasses.replace(scene, integrator=integrator)
    wall = time.perf_counter() - start
    summary = result.summary()
    peaks = result.peaks(settled=True)
    return {
        "cutoff_Hz": cutoff_hz,
        "status": result.status,
        "message": result.message,
        "step_s": scene.integrator.fixed_step_s,
        "wall_s": wall,
        "force_error_estimate": summary.get("force_error_estimate"),
        "peaks": {q: {side: peaks[q][side]["value"] for side in peaks[q]} for q in QUANTITIES},
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cutoffs", type=float, nargs="+", default=[5000.0, 10000.0, 15000.0, 20000.0])
    parser.add_argument("--duration", type=float, default=None, help="shorter runs (s); the scene's 0.4 s if absent")
    args = parser.parse_args(argv)
    rows = [run(c, args.duration) for c in sorted(args.cutoffs)]
    reference = rows[-1]
    for r in rows:
        r["difference_to_finest"] = {
            q: {
                side: (None if v is None or not reference["peaks"][q][side] else
                       abs(v - reference["peaks"][q][side]) / abs(reference["peaks"][q][side]))
                for side, v in r["peaks"][q].items()
            }
            for q in QUANTITIES
        }  # fmt: skip
    machine = {
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_at_end": [round(v, 2) for v in os.getloadavg()],
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    from rigid_dynamics.files import write_text

    out = ROOT / "benchmarks" / "results"
    write_text(out / "wheelflat_cutoff.json", json.dumps({"machine": machine, "rows": rows}, indent=2) + "\n")
    lines = [
        "# wheel-flat: peaks against the beam's modal cut-off (benchmarks/bench_wheelflat_cutoff.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs, Python {machine['python']}; load average at "
        f"end {machine['load_average_at_end']} (shared); {machine['date_utc']} UTC. Duration: "
        f"{args.duration or 'the scene'}; reference: {reference['cutoff_Hz']:.0f} Hz.",
        "",
        "| cut-off Hz | status | N peak L / R kN | diff | F_y peak L / R kN | diff | F_x peak L / R kN | diff | "
        "force error est. | wall s |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        cells = [f"{r['cutoff_Hz']:.0f}", r["status"]]
        for q in QUANTITIES:
            p, d = r["peaks"][q], r["difference_to_finest"][q]
            cells.append(" / ".join("-" if v is None else f"{v / 1e3:.3f}" for v in p.values()))
            cells.append(" / ".join("-" if v is None else f"{100 * v:.2f} %" for v in d.values()))
        est = r["force_error_estimate"]
        cells.append("-" if est is None else f"{est:.2e}")
        cells.append(f"{r['wall_s']:.1f}")
        lines.append("| " + " | ".join(cells) + " |")
    write_text(out / "wheelflat_cutoff.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
