"""Every shipped scene (wheelrail/scenes/*.toml) at its defaults against its converged reference, with the run's own
statement of its discretisation errors (summary.json ``discretisation_errors``) beside the measured difference.

The reference of a scene: the step / 8 (RK4; an embedded pair: both tolerances / 100), FASTSIM 40 x 40, the 3-D
search as the geometry (on a conical track the analytic conical provider with scipy's RK45: the cone's closed form,
the geometry of Klingel's formula), and the beam's modes to 20 kHz. ``wheel-flat``'s reference is not re-run here
(its 20 kHz run costs about 300 s wall under load): the 20 kHz row of benchmarks/results/wheelflat_cutoff.md
(bench_wheelflat_cutoff.py) is read instead; its default run is timed here.

Measured per scene: wall time of the default and of the reference run, status, the stated errors, and the largest
difference of the settled peaks (normal, longitudinal and lateral creep force per wheel) relative to the static
wheel load and relative to the reference peak itself (peak magnitudes: an oscillating force's signed peak may flip
sign between runs at equal size).

Run: ``.venv/bin/python benchmarks/bench_scene_defaults.py [scene ...]`` (a subset replaces those scenes' records;
the machine line is the last run's; ``--render`` rewrites the .md from the .json); writes
benchmarks/results/scene_defaults_error.json and scene_defaults_error.md.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.files import write_text  # noqa: E402  (atomic)
from rigid_dynamics.wheelset import simulate  # noqa: E402
from wheelrail.scenes import load_scene  # noqa: E402

SCENES = sorted(p.stem for p in (ROOT / "wheelrail" / "scenes").glob("*.toml"))
OUT = ROOT / "benchmarks" / "results" / "scene_defaults_error"
PEAKS = ("normal_force_N", "creep_force_long_N", "creep_force_lat_N")


def reference(scene):
    """The scene's converged reference (module docstring)."""
    integ = scene.integrator
    if integ.method == "RK4":
        integ = replace(integ, fixed_step_s=integ.fixed_step_s / 8)
    else:
        integ = replace(
            integ, relative_tolerance=integ.relative_tolerance / 100, absolute_tolerance=integ.absolute_tolerance / 100
        )
    changes = {"integrator": integ, "fastsim_elements_per_strip": 40, "fastsim_strips": 40}
    if scene.track.is_conical:
        changes["contact_provider"] = "conical"
        changes["integrator"] = replace(integ, method="RK45")
    else:
        changes["contact_provider"] = "search"
    if scene.track_dynamics.model == "beam":
        changes["track_dynamics"] = replace(scene.track_dynamics, cutoff_frequency_Hz=20000.0)
    return replace(scene, **changes)


def peaks(summary) -> dict:
    return {f"{k}/{s}": summary["peaks"][k][s]["value"] for k in PEAKS for s in ("left", "right")}


def wheelflat_reference() -> dict:
    """The 20 kHz row of wheelflat_cutoff.md: settled peaks (kN -> N), both wheels."""
    text = (ROOT / "benchmarks" / "results" / "wheelflat_cutoff.md").read_text(encoding="utf-8")
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells and cells[0] == "20000":
            values = [[float(v) * 1e3 for v in cells[i].split("/")] for i in (2, 4, 6)]
            names = ("normal_force_N", "creep_force_lat_N", "creep_force_long_N")
            return {
                f"{n}/{s}": v[j] for n, v in zip(names, values, strict=True) for j, s in enumerate(("left", "right"))
            }
    raise SystemExit("wheelflat_cutoff.md: no 20000 Hz row")


def compare(record) -> None:
    """The largest difference of the settled peak magnitudes (a peak is the signed value of largest magnitude: an
    oscillating force's peak may take either sign at equal size), relative to the static load and to the peak."""
    load, ref_peaks = record["static_wheel_load_N"], record["reference_peaks"]
    diffs = {
        k: (abs(abs(v) - abs(ref_peaks[k])) / load, abs(abs(v) - abs(ref_peaks[k])) / max(abs(ref_peaks[k]), 1e-9))
        for k, v in record["peaks"].items()
        if v is not None and ref_peaks.get(k) is not None
    }
    record["worst_of_static_load"] = max(d[0] for d in diffs.values())
    record["worst_key"] = max(diffs, key=lambda k: diffs[k][0])
    record["worst_of_own_peak"] = max(d[1] for d in diffs.values())
    record["worst_own_key"] = max(diffs, key=lambda k: diffs[k][1])


def rerender() -> None:
    """Rewrite the .md from the .json (the comparison recomputed from the stored peaks)."""
    data = json.loads(OUT.with_suffix(".json").read_text(encoding="utf-8"))
    for record in data["records"]:
        record.setdefault("static_wheel_load_N", load_scene(record["scene"]).static_wheel_load_N)
        compare(record)
    write_text(OUT.with_suffix(".json"), json.dumps(data, indent=1))
    write_text(OUT.with_suffix(".md"), render(data["machine"], data["records"]))


def run(scene):
    start = time.perf_counter()
    result = simulate(scene)
    return result, time.perf_counter() - start


def main(names) -> None:
    records = []
    load_start = os.getloadavg()
    for name in names:
        scene = load_scene(name)
        result, wall = run(scene)
        summary = result.summary()
        record = {
            "scene": name,
            "status": result.status,
            "message": result.message,
            "wall_s": wall,
            "stated": {k: v.get("estimate") for k, v in summary["discretisation_errors"].items()},
            "peaks": peaks(summary),
        }
        if name == "wheel-flat":
            ref_peaks, ref_wall, ref_status = wheelflat_reference(), None, "read: wheelflat_cutoff.md 20 kHz"
        else:
            ref, ref_wall = run(reference(scene))
            ref_peaks, ref_status = peaks(ref.summary()), ref.status
        record.update(reference_status=ref_status, reference_wall_s=ref_wall, reference_peaks=ref_peaks)
        record["static_wheel_load_N"] = scene.static_wheel_load_N
        record["run"] = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "load_start": os.getloadavg()}
        compare(record)
        records.append(record)
        print(name, record["status"], f"{wall:.1f} s", record["worst_of_static_load"], record["stated"], flush=True)
    previous = OUT.with_suffix(".json")
    if previous.exists() and set(names) != set(SCENES):  # a subset re-run keeps the other scenes' records
        before = json.loads(previous.read_text(encoding="utf-8"))
        kept = [r for r in before["records"] if r["scene"] not in names]
        for r in kept:  # a record written before records carried their own run: the file's machine line was theirs
            r.setdefault("run", {"date": before["machine"]["date"], "load_start": before["machine"]["load_start"]})
        records = sorted(kept + records, key=lambda r: r["scene"])
    machine = {
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "load_start": load_start,
        "load_end": os.getloadavg(),
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
    }
    write_text(OUT.with_suffix(".json"), json.dumps({"machine": machine, "records": records}, indent=1))
    write_text(OUT.with_suffix(".md"), render(machine, records))


def render(machine, records) -> str:
    def g(v):
        return "-" if v is None else f"{v:.2g}"

    lines = [
        "# Shipped scenes at their defaults against their converged references (benchmarks/bench_scene_defaults.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        f"Machine: {machine['platform']}, {machine['cpus']} CPUs, Python {machine['python']}; load average at start "
        f"{[round(x, 2) for x in machine['load_start']]}, at end {[round(x, 2) for x in machine['load_end']]} (shared "
        f"machine: wall times scatter); {machine['date']}.",
        "",
        "Rows run: "
        + "; ".join(
            f"{r['scene']} {r['run']['date']} (load {r['run']['load_start'][0]:.2f})" for r in records if "run" in r
        )
        + ".",
        "",
        "| scene | status | default wall s | reference wall s | stated: step | grid | modal | geometry | "
        "measured: largest peak diff / static load | (peak) | largest diff / own peak | (peak) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in records:
        s = r["stated"]
        ref_wall = "-" if r["reference_wall_s"] is None else f"{r['reference_wall_s']:.1f}"
        lines.append(
            f"| {r['scene']} | {r['status']} | {r['wall_s']:.1f} | {ref_wall} | {g(s.get('step'))} | "
            f"{g(s.get('contact_grid'))} | {g(s.get('modal_cutoff'))} | {g(s.get('geometry_tables'))} | "
            f"{100 * r['worst_of_static_load']:.3f} % | {r['worst_key']} | {100 * r['worst_of_own_peak']:.2f} % | "
            f"{r['worst_own_key']} |"
        )
    lines += ["", "Reference status per scene: " + "; ".join(f"{r['scene']} {r['reference_status']}" for r in records)]
    lines += ["", "Messages of the default runs:", ""] + [f"* {r['scene']}: {r['message']}" for r in records]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    if sys.argv[1:] == ["--render"]:
        rerender()
        raise SystemExit(0)
    chosen = sys.argv[1:] or SCENES
    unknown = sorted(set(chosen) - set(SCENES))
    if unknown:
        raise SystemExit(f"unknown scene(s) {unknown}: expected {SCENES}")
    main(chosen)
