"""The elastic track against Jenkins' P2 formula (dipped joint) and the wheel-flat impact, elastic against rigid.

1. P2 of a dipped rail joint (total angle 2 alpha = 0.01 rad) at 10-50 m/s on Jenkins' equivalent track
   (Mt = 245 kg, Kt = 150 MN/m, Ct = 55.8 kN s/m per wheel, the sleeper layer made rigid; conical wheels, tables
   provider, compiled loop) against Jenkins et al. (1974)'s formula as given in Iwnicki (ed.), Handbook of Railway
   Vehicle Dynamics (2006): P2 = P0 + 2 alpha V sqrt(Mu/(Mu+Mt)) [1 - pi Ct/(4 sqrt(Kt (Mu+Mt)))] sqrt(Kt Mu),
   Mu half the wheelset. Simulated P2: the peak of the force the rail mass puts on its support after the joint
   (the formula's quantity, the spring and damper force of the track); beside it the peak wheel-rail contact force
   (P1, the high-frequency peak through the Hertz spring) and its 2.5 ms running mean.
2. The embedded wheel-flat scene's first impact at 30-120 km/h on the default elastic track and on the rigid one
   (the flat reaches the rail after 0.2 m; each run stops 0.3 m later; 0.025 ms step).

Run: ``.venv/bin/python benchmarks/bench_track.py``; writes benchmarks/results/track.json and track.md.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from test_dynamics_track import dipped_joint_scene, jenkins_p2_N  # noqa: E402

from rigid_dynamics.files import write_text  # noqa: E402
from rigid_dynamics.wheelset import TrackDynamics, simulate  # noqa: E402
from wheelrail.scenes import load_scene, resolve_scene_path  # noqa: E402

OUT = ROOT / "benchmarks" / "results"


def p2_rows():
    rows = []
    for speed in (10.0, 20.0, 30.0, 40.0, 50.0):
        scene = dipped_joint_scene(speed)
        result = simulate(scene)
        tr = scene.track_dynamics
        x, track = result.states[:, 0], result.track_states
        support = tr.pad_stiffness_N_per_m * (track[:, 0] - track[:, 2]) + tr.pad_damping_N_s_per_m * (
            track[:, 4] - track[:, 6]
        )
        contact = -result.contact_force_N[:, 0, 2]
        mean = np.convolve(contact, np.ones(25) / 25, mode="same")
        after = x > 6.0 - 0.05
        p0 = scene.static_wheel_load_N
        jenkins = jenkins_p2_N(scene, 0.01, speed)
        rows.append(
            {
                "speed_m_per_s": speed,
                "status": result.status,
                "static_N": p0,
                "jenkins_p2_N": jenkins,
                "simulated_p2_N": float(support[after].max()),
                "ratio_of_increments": float((support[after].max() - p0) / (jenkins - p0)),
                "p1_contact_N": float(contact[after].max()),
                "contact_running_mean_N": float(mean[after].max()),
                "energy_residual_J": float(np.max(np.abs(result.energy_residual_J))),
            }
        )
        print(rows[-1], flush=True)
    return rows


def flat_rows():
    rows = []
    base = load_scene(resolve_scene_path("wheel-flat"))
    for kmh in (30.0, 60.0, 90.0, 120.0):
        speed = kmh / 3.6
        row = {"speed_km_per_h": kmh}
        for model in ("lumped", "rigid"):
            scene = replace(
                base, speed_m_per_s=speed, duration_s=0.5 / speed, track_dynamics=TrackDynamics(model=model)
            )
            scene = replace(
                scene, integrator=replace(scene.integrator, fixed_step_s=2.5e-5, lift_half_step_check=False)
            )
            result = simulate(scene)
            row[f"{model}_status"] = result.status
            row[f"{model}_peak_N"] = float(np.max(-result.contact_force_N[:, :, 2]))
            row[f"{model}_lifts"] = sum(1 for kind, _, _ in result.events if kind == "wheel-lift")
        row["rigid_over_elastic"] = row["rigid_peak_N"] / row["lumped_peak_N"]
        rows.append(row)
        print(row, flush=True)
    return rows


def render(data) -> str:
    lines = [
        "# Elastic track: Jenkins' P2 and the wheel-flat impact",
        "",
        "Written by `benchmarks/bench_track.py` (see its docstring for the set-up).",
        "",
        "## P2 of a dipped joint (2 alpha = 0.01 rad) against Jenkins et al. (1974)",
        "",
        "| V (m/s) | status | Jenkins P2 (kN) | simulated P2 (kN) | ratio of dynamic increments "
        "| P1 contact peak (kN) | contact 2.5 ms mean peak (kN) | energy residual (J) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in data["p2"]:
        lines.append(
            f"| {r['speed_m_per_s']:.0f} | {r['status']} | {r['jenkins_p2_N'] / 1e3:.1f} "
            f"| {r['simulated_p2_N'] / 1e3:.1f} | {r['ratio_of_increments']:.3f} | {r['p1_contact_N'] / 1e3:.1f} "
            f"| {r['contact_running_mean_N'] / 1e3:.1f} | {r['energy_residual_J']:.2g} |"
        )
    lines += [
        "",
        f"Static wheel load {data['p2'][0]['static_N'] / 1e3:.1f} kN.",
        "",
        "## wheel-flat scene: first impact, elastic (default) against rigid track",
        "",
        "| speed (km/h) | elastic peak (kN) | lifts | rigid peak (kN) | lifts | rigid / elastic |",
        "|---|---|---|---|---|---|",
    ]
    for r in data["flat"]:
        lines.append(
            f"| {r['speed_km_per_h']:.0f} | {r['lumped_peak_N'] / 1e3:.1f} | {r['lumped_lifts']} | "
            f"{r['rigid_peak_N'] / 1e3:.1f} | {r['rigid_lifts']} | {r['rigid_over_elastic']:.2f} |"
        )
    lines.append("")
    return "\n".join(lines)


def main() -> None:
    data = {"p2": p2_rows(), "flat": flat_rows()}
    write_text(OUT / "track.json", json.dumps(data, indent=1) + "\n")
    write_text(OUT / "track.md", render(data))
    print(render(data))


if __name__ == "__main__":
    main()
