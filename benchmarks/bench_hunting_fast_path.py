"""hunting-conical: its default path (scipy RK45 with the Python right-hand side on the analytic cone) against the
compiled error-controlled loop (DP54, the same tolerances) on the cone's contact tables, both judged against a
converged reference (scipy RK45 at rtol 1e-9, atol 1e-12, analytic cone). CPU of the run alone (after one short
untimed run that loads the kernels), and the worst relative difference of the summary's peaks (normal-force, creep-
force and Y peaks, the largest lateral displacement, the dominant wavelength; entries above 1e-3 of the largest
magnitude) from the reference's.

Run: ``.venv/bin/python benchmarks/bench_hunting_fast_path.py`` -> benchmarks/results/hunting_fast_path.md|json.
"""

import dataclasses as dc
import json
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.wheelset import simulate  # noqa: E402
from wheelrail.scenes import load_scene  # noqa: E402

KEYS = (
    "peak_normal_force_N",
    "peaks",
    "full_run_peaks",
    "max_abs_lateral_displacement_m",
    "dominant_lateral_wavelength_m",
)


def flat(d, prefix=""):
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(flat(v, f"{prefix}{k}."))
        elif isinstance(v, float):
            out[prefix + k] = v
    return out


def main():
    scene = load_scene("hunting-conical")
    tight = dc.replace(scene.integrator, relative_tolerance=1e-9, absolute_tolerance=1e-12)
    variants = {
        "default: scipy RK45 rtol 1e-6 (Python RHS), analytic cone": scene,
        "compiled DP54 rtol 1e-6 on the cone's tables": dc.replace(
            scene, contact_provider="tables", integrator=dc.replace(scene.integrator, method="DP54")
        ),
        "reference: scipy RK45 rtol 1e-9, analytic cone": dc.replace(scene, integrator=tight),
    }
    runs = {}
    load_start = os.getloadavg()
    for name, variant in variants.items():
        simulate(dc.replace(variant, duration_s=0.01))
        start = time.process_time()
        result = simulate(variant)
        cpu = time.process_time() - start
        summary = result.summary()
        runs[name] = {"cpu_s": cpu, "status": result.status, "compiled": result.compiled,
                      "provider": result.provider, "method": result.method,
                      "force_error_estimate": summary.get("force_error_estimate"),
                      "values": flat({k: summary[k] for k in KEYS})}  # fmt: skip
    ref = runs["reference: scipy RK45 rtol 1e-9, analytic cone"]["values"]
    scale = max(abs(v) for v in ref.values())
    for run in runs.values():
        diffs = {k: (run["values"][k] - v) / abs(v) for k, v in ref.items() if abs(v) > 1e-3 * scale}
        worst = max(diffs, key=lambda k: abs(diffs[k]))
        run["worst_entry"], run["worst_relative_difference"] = worst, diffs[worst]
    machine = {"platform": platform.platform(), "cpu_count": os.cpu_count(), "python": platform.python_version(),
               "load_start": load_start, "load_end": os.getloadavg(),
               "date_utc": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}  # fmt: skip
    out = ROOT / "benchmarks" / "results"
    (out / "hunting_fast_path.json").write_text(json.dumps({"machine": machine, "runs": runs}, indent=2, default=str))
    lines = [
        "# hunting-conical: default scipy path against the compiled loop on the cone's tables",
        "",
        __doc__.split("\n\n")[0].replace("\n", " "),
        "",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs, Python {machine['python']}; load average "
        f"{machine['load_start']} at the start, {machine['load_end']} at the end; {machine['date_utc']}.",
        "",
        "| path | CPU s (3 s simulated) | status | worst relative difference from the reference (entry) | "
        "run's force error estimate |",
        "|---|---|---|---|---|",
    ]
    for name, run in runs.items():
        lines.append(
            f"| {name} | {run['cpu_s']:.3f} | {run['status']} | {run['worst_relative_difference']:.2e} "
            f"({run['worst_entry']}) | {run['force_error_estimate']} |"
        )
    (out / "hunting_fast_path.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
