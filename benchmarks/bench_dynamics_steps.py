"""Step sensitivity of fixed-step RK4 on the embedded scenes, with the force error indicators beside it.

For each embedded scene, runs at several RK4 steps against a run at the finest step (the reference), and records
per run:

* ``status`` and the force error estimate of the run (simulate.py: RK4 against its embedded third-order solution,
  per-wheel normal / longitudinal / lateral contact force, relative to the static wheel load), after the scene's
  settling distance (what the status judges) and over the full run;
* how much the results move against the reference, relative to the static wheel load: the settled peak normal
  force per wheel, the settled mean longitudinal creep force per wheel, the settled peak |lateral creep force|;
  ``moved`` is the largest of the three;
* two other indicators, to measure which one catches the steps whose results move: the number of steps per
  contact passage of the shortest irregularity (flat length, corrugation wavelength or polygon wavelength over the
  speed), and step doubling (one step of 2h against two of h from recorded settled states, force difference / 15,
  the Richardson estimate of RK4's error; evaluated at up to 100 settled samples with the compiled right-hand side);
* wall time and real-time factor (the machine is shared: timings scatter).

A verdict per run: ``ok-and-unmoved`` / ``warning-and-moved`` (the status says what the results do),
``OK-BUT-MOVED`` (the defect this benchmark exists to catch) or ``warning-but-unmoved`` (conservative).

Run: ``.venv/bin/python benchmarks/bench_dynamics_steps.py`` (``--render``: rewrite the .md from the .json);
writes benchmarks/results/step_sensitivity.json and step_sensitivity.md.
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.files import write_text  # noqa: E402  (atomic)
from rigid_dynamics.wheelset import simulate  # noqa: E402
from wheelrail.scenes import load_scene  # noqa: E402

CASES = (
    # (scene, track model, reference step, steps), s; "beam" is the wheel-flat scene's own track (RK4's stability
    # limit on it is 0.03 ms at the start: its stiffest rail modes), "lumped" the corrugation scene's (0.57 ms);
    # "rigid" is issue 12's table
    ("polygonal-wheel", "rigid", 6.25e-5, (1.25e-4, 2.5e-4, 5e-4, 1e-3, 2e-3)),
    ("polygonal-wheel", "lumped", 6.25e-5, (1.25e-4, 2.5e-4, 5e-4, 1e-3)),
    ("wheel-flat", "beam", 1.25e-5, (2.5e-5, 5e-5, 1e-4, 1e-3, 5e-3)),
    ("wheel-flat", "lumped", 1.25e-5, (2.5e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3)),
    ("wheel-flat", "rigid", 2.5e-5, (5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3)),
    ("corrugation", "lumped", 2.5e-5, (5e-5, 1e-4, 2e-4, 5e-4, 1e-3)),
    ("corrugation", "rigid", 2.5e-5, (5e-5, 1e-4, 2e-4, 5e-4, 1e-3)),
    ("hunting-conical", "rigid", 2.5e-4, (5e-4, 1e-3, 2e-3)),  # the Python RK4 path (conical provider), 1 s
)
DURATIONS = {"hunting-conical": 1.0}


def at_step(scene, step_s):
    integ = replace(
        scene.integrator,
        method="RK4",
        fixed_step_s=step_s,
        output_step_s=max(step_s, scene.integrator.output_step_s),
    )
    return replace(scene, integrator=integ)


def wheel_series(result, name):
    touching = np.nan_to_num(result.patches["normal_force_N"], nan=0.0) > 0
    return np.where(touching, np.nan_to_num(result.patches[name], nan=0.0), 0.0).sum(axis=2)


def measures(result):
    """Settled result measures per wheel: peak normal force, mean longitudinal creep force, peak |lateral|, N."""
    mask = result.settled
    if not np.any(mask):
        return None
    normal = wheel_series(result, "normal_force_N")[mask]
    longitudinal = wheel_series(result, "creep_force_long_N")[mask]
    lateral = wheel_series(result, "creep_force_lat_N")[mask]
    return {
        "peak_normal_force_N": normal.max(axis=0).tolist(),
        "mean_creep_force_long_N": longitudinal.mean(axis=0).tolist(),
        "peak_abs_creep_force_lat_N": np.abs(lateral).max(axis=0).tolist(),
    }


def passage_steps(scene, step_s):
    """Steps per contact passage of the shortest running-direction irregularity (None without one)."""
    irr = scene.irregularities
    lengths = []
    if irr.flat_length_m > 0:
        lengths.append(irr.flat_length_m)
    if irr.corrugation_amplitude_m > 0:
        lengths.append(irr.corrugation_wavelength_m)
    if irr.polygon_order > 0 and irr.polygon_amplitude_m > 0:
        lengths.append(2 * math.pi * scene.wheelset.nominal_radius_m / irr.polygon_order)
    if not lengths:
        return None
    return min(lengths) / scene.speed_m_per_s / step_s


def doubling_estimate(scene, result, samples=100):
    """Step doubling at up to ``samples`` settled recorded states (compiled right-hand side; None when the scene
    does not run compiled)."""
    from rigid_dynamics.wheelset.compiled_rhs import rhs_once
    from rigid_dynamics.wheelset.layout import N_FIELDS, NORMAL_FORCE
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    if not result.compiled:
        return None
    provider = build_provider(scene)
    law = get_contact_model(scene.contact_model)
    model = WheelsetModel(scene, provider, law, model_options(law.name, scene))
    run = model.packed
    sides = run.sides
    run.par["frame_x0_m"] = result.states[0, 0]
    rec = np.zeros((len(sides) + 2, N_FIELDS))
    h = scene.integrator.fixed_step_s

    def rhs(t, y):
        out = np.zeros(len(y))
        rhs_once(t, y, run, out, rec)
        forces = np.zeros((2, 3))
        for c in range(len(sides)):
            if rec[c, NORMAL_FORCE] > 0:
                forces[sides[c]] += rec[c, :3]
        return out, forces

    def step(t, y, hh):
        k1 = rhs(t, y)[0]
        k2 = rhs(t + hh / 2, y + hh / 2 * k1)[0]
        k3 = rhs(t + hh / 2, y + hh / 2 * k2)[0]
        k4 = rhs(t + hh, y + hh * k3)[0]
        return y + hh / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    index = np.flatnonzero(result.settled[:-2])
    if len(index) == 0:
        return None
    index = index[:: max(1, len(index) // samples)]
    worst = 0.0
    for k in index:
        track = result.track_full_states[k] if scene.track_dynamics.elastic else []
        y = np.concatenate([result.states[k], [0.0, 0.0], track])
        t = float(result.t[k])
        two = step(t + h, step(t, y, h), h)
        one = step(t, y, 2 * h)
        worst = max(worst, float(np.max(np.abs(rhs(t + 2 * h, two)[1] - rhs(t + 2 * h, one)[1]))) / 15.0)
    return worst / scene.static_wheel_load_N


def main():
    if "--render" in sys.argv:
        payload = json.loads((ROOT / "benchmarks" / "results" / "step_sensitivity.json").read_text())
        write(payload["runs"], payload["machine"])
        return
    records = []
    load_before = os.getloadavg()
    only = [a.split("=", 1)[1] for a in sys.argv[1:] if a.startswith("--only=")]
    for name, track, ref_step, steps in CASES:
        if only and f"{name}/{track}" not in only:
            continue
        base = load_scene(name)
        base = replace(
            base,
            duration_s=DURATIONS.get(name, base.duration_s),
            track_dynamics=replace(base.track_dynamics, model=track),
        )
        reference = simulate(at_step(base, ref_step))
        ref = measures(reference)
        load = base.static_wheel_load_N
        tol = base.integrator.force_tolerance
        for step in (ref_step, *steps):
            scene = at_step(base, step)
            result = reference if step == ref_step else simulate(scene)
            summary = result.summary()
            got = measures(result)
            moved = None
            if got is not None and ref is not None and result.status in ("ok", "warning"):
                moved = max(max(abs(a - b) for a, b in zip(got[key], ref[key], strict=True)) / load for key in got)
            rec = {
                "scene": name,
                "track": track,
                "step_ms": step * 1e3,
                "reference": step == ref_step,
                "status": result.status,
                "message": result.message,
                "force_error_estimate": summary.get("force_error_estimate"),
                "full_run_force_error_estimate": summary.get("full_run_force_error_estimate"),
                "moved": moved,
                "measures": got,
                "passage_steps": passage_steps(base, step),
                "doubling_estimate": doubling_estimate(scene, result) if step != ref_step else None,
                "wall_s": result.wall_time_s,
                "real_time_factor": result.real_time_factor,
                "compiled": result.compiled,
            }
            if step == ref_step:
                rec["verdict"] = "reference"
            elif moved is None:
                rec["verdict"] = "stopped" if result.status not in ("ok", "warning") else "no settled samples"
            elif result.status == "ok":
                rec["verdict"] = "ok-and-unmoved" if moved <= tol else "OK-BUT-MOVED"
            else:
                rec["verdict"] = "warning-and-moved" if moved > tol else "warning-but-unmoved"
            records.append(rec)
            print(
                f"{name}/{track} {step * 1e3:g} ms: {rec['status']} est {rec['force_error_estimate']} moved {moved} "
                f"doubling {rec['doubling_estimate']} {rec['verdict']}",
                flush=True,
            )
    load_after = os.getloadavg()
    machine = {
        "load_average_1min_start_end": [round(load_before[0], 1), round(load_after[0], 1)],
        "platform": platform.platform(),
        "cpu": cpu_model(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "note": f"one process on a 2-core machine shared with other jobs (1-min load average {load_before[0]:.1f} "
        f"at the start, {load_after[0]:.1f} at the end: timings scatter and run slow)",
    }
    if only:  # the other cases' runs stay as last measured; the machine line says which ones were rerun
        previous = json.loads((ROOT / "benchmarks" / "results" / "step_sensitivity.json").read_text())
        order = [f"{n}/{t}" for n, t, _, _ in CASES]
        kept = [r for r in previous["runs"] if f"{r['scene']}/{r['track']}" not in only]
        records = sorted(kept + records, key=lambda r: order.index(f"{r['scene']}/{r['track']}"))
        machine = {**previous["machine"], "rerun": sorted(set(previous["machine"].get("rerun", [])) | set(only))}
        machine["rerun_note"] = f"{', '.join(only)} rerun at load {load_before[0]:.1f}-{load_after[0]:.1f}"
    write(records, machine)


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo (Linux), else platform.processor()."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def write(records, machine):
    """step_sensitivity.md and .json from the run records."""
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)

    def fmt(v, spec=".3g"):
        return "-" if v is None else format(v, spec)

    lines = [
        "# Step sensitivity of fixed-step RK4 and the force error estimate",
        "",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs ({machine.get('cpu', 'unknown')}), "
        f"Python {machine['python']}, numpy "
        f"{machine['numpy']}; {machine['note']}"
        + (f"; later, {machine['rerun_note']}" if machine.get("rerun_note") else "")
        + ". Script: benchmarks/bench_dynamics_steps.py.",
        "",
        "Forces relative to the static wheel load N0. `estimate`: the run's force error estimate after the settling "
        "distance (the status judges it against force_tolerance = 0.02), `full run`: including the start-up. "
        "`moved`: the largest change against the reference run of the settled peak normal force, mean longitudinal "
        "creep force and peak |lateral creep force| per wheel. `passage`: steps per contact passage of the "
        "shortest irregularity. `doubling`: step-doubling (Richardson) estimate at up to 100 settled samples.",
        "",
        "| scene | track | step ms | status | estimate | full run | moved | passage | doubling | peak N kN (L/R) | "
        "mean Fx kN (L/R) | wall s | RTF | verdict |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in records:
        m = r["measures"]
        peak = "-" if m is None else "/".join(f"{v / 1e3:.0f}" for v in m["peak_normal_force_N"])
        mean = "-" if m is None else "/".join(f"{v / 1e3:.2f}" for v in m["mean_creep_force_long_N"])
        lines.append(
            f"| {r['scene']} | {r.get('track', 'rigid')} | {r['step_ms']:g} | {r['status']} | "
            f"{fmt(r['force_error_estimate'])} | "
            f"{fmt(r['full_run_force_error_estimate'])} | {fmt(r['moved'])} | {fmt(r['passage_steps'], '.1f')} | "
            f"{fmt(r['doubling_estimate'])} | {peak} | {mean} | {r['wall_s']:.2f} | {fmt(r['real_time_factor'])} | "
            f"{r['verdict']} |"
        )
    lines += ["", NOTES]
    payload = {"benchmark": "RK4 step sensitivity", "machine": machine, "runs": records}
    for fname, text in (
        ("step_sensitivity.json", json.dumps(payload, indent=2) + "\n"),
        ("step_sensitivity.md", "\n".join(lines) + "\n"),
    ):
        write_text(out / fname, text)
    print("\n".join(lines))


NOTES = """Notes.

* Three tracks. `beam` is the discretely supported rail (track.py), the wheel-flat scene's default: at its own
  0.025 ms it moves by 0.0015 against a 0.0125 ms reference; 0.05 ms and above lie beyond RK4's stability limit
  of the beam's stiffest rail modes (0.0305 ms at the start, Timoshenko's shear branch at 14.7 kHz) and end
  `step-unstable`. `lumped` (a rail mass on a pad on a sleeper mass on the ballast under each wheel) is the
  corrugation scene's default and was wheel-flat's; `rigid` is issue 12's original table. No row
  with status `ok` moves by more than force_tolerance = 0.02 of the static load: the largest among them is
  wheel-flat on the rigid track at 0.05 ms (0.0097); on the elastic track wheel-flat at its own 0.025 ms moves by
  0.00084 against a 0.0125 ms reference, corrugation at 0.2 ms by 0.0034, polygonal-wheel at 0.5 ms by 0.00033.
* Which indicator catches the steps whose results move. The force error estimate (RK4 against its embedded
  third-order solution) flags every run above whose results move by more than 2 % of the static load, except
  wheel-flat at 0.1 ms on the rigid track and at 0.05 ms on the elastic one, which the half-step check of runs
  with a wheel lift flags (below). The contact passage (steps per passage of the shortest irregularity) cannot
  see polygonal-wheel at 1 ms on the rigid track: 35 steps per polygon wavelength, yet the longitudinal creep
  force is biased to -3.9 kN per wheel against 0.0 (the stiff creep mode of the spin and fore-aft motion,
  lambda h ~ 1.9, well resolved in space, not in time). Step doubling (Richardson, divided by 15) underestimates
  that case (0.009 < 0.02) and costs three extra right-hand sides per check against one. So the status uses the
  embedded estimate, evaluated at the output samples and at least every millisecond.
* The estimate is local. It does not see results moved by a changed sequence of contact switches: on wheel-flat
  the wheel lifts after each impact and the re-impacts depend on the flight times; on the rigid track at 0.1 ms
  later impacts move by 3.6 % of the static load with a largest estimate of 9e-4, on the elastic track at
  0.05 ms by 2.3 % with 9e-4. A fixed-step run in which a wheel lifts off after the settling distance is
  therefore run again at half the step and the settled peaks compared (simulate._half_step_check, on by
  default): rigid track 2.6 % at 0.1 ms (warning), elastic track 2.2 % at 0.05 ms (warning) and 0.08 % at the
  scene's 0.025 ms (ok). Its cost: the runs with lifts take about three times as long (the wall column includes
  the second run). On polygonal-wheel the flips of the S1002/UIC60 two-point contact in the start-up (first
  ~10 m after the 1 mm offset) move the start-up peaks: the scene's settling distance is 10 m, the full-run
  estimate (0.053 rigid, 0.15 elastic at 0.5 ms) and full-run peaks are reported apart, and the message says
  that the start-up is not converged.
* RK4's stability limit (stability.py). Linearised at the start: 1.15 ms for polygonal-wheel (rigid), 0.61 ms
  on the elastic track, 0.57 ms for wheel-flat on either track, 0.57 ms (elastic) and 0.68 ms (rigid) for
  corrugation, 1.09 ms for hunting-conical.
  Runs beyond it that fail end `step-unstable` (polygonal-wheel elastic at 1 ms, wheel-flat at 1-5 ms elastic
  and 2-5 ms rigid, corrugation elastic at 1 ms, hunting-conical at 2 ms); those that finish end `warning`.
  wheel-flat on the elastic track at 0.5 ms, within the start's limit, derailed after its first impact: the
  Hertz mode stiffens with the impact force, and a failed run is now also judged at the recorded state of its
  largest contact force (limit 0.35 ms there), so it ends `step-unstable` too instead of `derailed`.
* hunting-conical (conical provider, linear creep, Python RK4 path, 1 s): the estimate stays below 1e-7 up to
  1 ms.
* The output samples carry the estimate; a check costs one right-hand side per output sample (12.5 % at the
  polygonal-wheel scene's 0.5 ms step and 1 ms output, 25 % when every step is an output sample).
"""

if __name__ == "__main__":
    main()
