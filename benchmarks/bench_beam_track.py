"""The discretely supported beam track (``[track_dynamics] model = "beam"``): its checks, a second method for it, and
the wheel-flat impact against speed on it beside the lumped and the rigid track.

1. Track checks from the beam's matrices (rigid_dynamics.wheelset.track_matrices.TrackSystem), UIC60 on 0.6 m seats:
   static point stiffness, pinned-pinned frequency against the closed forms, P2 resonance of half the wheelset
   against Jenkins et al. (1974).
2. Second method: comparisons/wheelflat_fe_beam.py, the vertical half-wheelset on an Euler-Bernoulli rail of
   Hermite finite elements (Newmark), against the wheelset model on the Euler-Bernoulli modal beam (rail loss
   factor 0 in both): the wheel-flat peak (50 and 100 mm flats, 20-120 km/h), and the sleeper-passing force
   ripple on a round wheel at 60 and 120 km/h. The FE model's element size and step are halved once to show it
   converged.
3. The embedded wheel-flat scene on the default beam (Timoshenko, loss factor 0.02, modes up to 5 kHz) over 0.5 m
   (the flat's centre at 0.2 m), the peak vertical wheel-rail force with the change at half the RK4 step, beside
   the lumped and the rigid track of benchmarks/results/wheelflat_study.json (same scene, same definition of the
   peak).
4. The beam's discretisation: the 50 mm, 60 km/h peak against the cut-off frequency and the end margin.

Run: ``.venv/bin/python benchmarks/bench_beam_track.py`` (``--render``: rewrite the .md from the .json); writes
benchmarks/results/beam_track.json and beam_track.md.
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_wheelflat_study import (  # noqa: E402
    DISTANCE_M,
    FLAT_LENGTHS_M,
    SPEEDS_KM_PER_H,
    STEP_S,
    flat_centre_m,
    flat_scene,
    hertz_constant,
    peak_vertical_N,
)

from comparisons.wheelflat_fe_beam import fe_track_from_scene, simulate_passage_fe  # noqa: E402
from comparisons.wheelflat_vertical import from_scene  # noqa: E402
from rigid_dynamics.files import write_text  # noqa: E402
from rigid_dynamics.wheelset import DynamicsScene, Irregularities, TrackDynamics, simulate  # noqa: E402
from rigid_dynamics.wheelset.track import beam_layout, travel_m  # noqa: E402
from rigid_dynamics.wheelset.track_matrices import TrackSystem  # noqa: E402

OUT = ROOT / "benchmarks" / "results"
JENKINS_KT, JENKINS_MT = 150.0e6, 245.0


def track_checks() -> dict:
    out = {}
    unsprung = 0.5 * DynamicsScene().wheelset.mass_kg
    for theory in ("euler-bernoulli", "timoshenko"):
        track = TrackDynamics(model="beam", rail_theory=theory)
        system = TrackSystem(track, 3.0)
        x_seat = system.start_position_m()
        x_mid = x_seat + 0.5 * track.sleeper_spacing_m
        f = np.arange(20.0, 200.0, 0.5)
        alpha = system.receptance_m_per_N(f, x_mid)
        p2 = f[np.argmax(np.abs(1.0 / (1.0 - (2.0 * math.pi * f) ** 2 * unsprung * alpha)))]
        hi = np.arange(800.0, 2000.0, 1.0) if theory == "timoshenko" else np.arange(1100.0, 2000.0, 1.0)
        mid = np.abs(system.receptance_m_per_N(hi, x_mid))
        seat = np.abs(system.receptance_m_per_N(hi, x_seat))
        k = int(np.argmax(mid))
        out[theory] = {
            "static_at_seat_N_per_m": 1.0 / abs(system.receptance_m_per_N([1.0], x_seat)[0]),
            "static_mid_span_N_per_m": 1.0 / abs(system.receptance_m_per_N([1.0], x_mid)[0]),
            "p2_resonance_Hz": float(p2),
            "pinned_pinned_peak_Hz": float(hi[k]),
            "mid_over_seat_at_peak": float(mid[k] / seat[k]),
            "modes_per_3m_run": beam_layout(track, 3.0).n_modes,
        }
    a = 0.6
    tr = TrackDynamics(model="beam")
    ei, ra, ga, ri = (tr.rail_bending_stiffness_N_m2, tr.rail_mass_per_length_kg_per_m, tr.rail_shear_stiffness_N,
                      tr.rail_rotary_inertia_kg_m)  # fmt: skip
    kk = math.pi / a
    coeffs = [
        ra * ri,
        -(ga * kk * kk * ri + ra * (ei * kk * kk + ga)),
        ga * kk * kk * (ei * kk * kk + ga) - (ga * kk) ** 2,
    ]
    out["closed_form_pinned_pinned_Hz"] = {
        "euler-bernoulli": math.pi / (2 * a * a) * math.sqrt(ei / ra),
        "timoshenko": math.sqrt(min(np.roots(coeffs).real)) / (2 * math.pi),
    }
    out["jenkins_p2_Hz"] = math.sqrt(JENKINS_KT / (unsprung + JENKINS_MT)) / (2 * math.pi)
    print(out, flush=True)
    return out


def _eb(scene):
    return replace(
        scene, track_dynamics=replace(scene.track_dynamics, rail_theory="euler-bernoulli", rail_loss_factor=0.0)
    )


def _fe(scene, result, speed, elements=6, step=1e-5, flat=True):
    layout = beam_layout(scene.track_dynamics, travel_m(scene))
    wheel = from_scene(
        replace(scene, track_dynamics=replace(scene.track_dynamics, model="lumped")),
        hertz_constant(result),
        flat_centre_m(scene),
    )
    if not flat:
        wheel = replace(wheel, flat_length_m=0.05, flat_depth_m=0.0)
    track = fe_track_from_scene(scene.track_dynamics, layout.n_sleepers, elements)
    return simulate_passage_fe(wheel, track, speed, layout.margin_m, DISTANCE_M, step)


def second_method() -> list:
    rows = []
    for length in FLAT_LENGTHS_M:
        for kmh in SPEEDS_KM_PER_H:
            speed = kmh / 3.6
            scene = _eb(flat_scene(length, speed, "beam", half_step_check=False))
            result = simulate(scene)
            start = time.perf_counter()
            _, _, force = _fe(scene, result, speed)
            row = {
                "flat_length_m": length,
                "speed_km_per_h": kmh,
                "status": result.status,
                "wheelset_peak_N": peak_vertical_N(result),
                "fe_peak_N": float(force.max()),
                "fe_wall_s": time.perf_counter() - start,
            }
            if length == FLAT_LENGTHS_M[0] and kmh == 60.0:
                _, _, fine = _fe(scene, result, speed, elements=12, step=5e-6)
                row["fe_fine_peak_N"] = float(fine.max())
            rows.append(row)
            print(row, flush=True)
    return rows


def ripple() -> list:
    """Sleeper passing on a round wheel: the modal beam at its default cut-off (5 kHz) and at 20 kHz (RK4 at
    0.01 ms, inside the stability limit of its stiffest mode) against the FE rail."""
    out = []
    for kmh in (60.0, 120.0):
        speed = kmh / 3.6
        row = {"speed_km_per_h": kmh}
        for cutoff, step in ((5000.0, STEP_S), (20000.0, 1e-5)):
            base = _eb(flat_scene(0.05, speed, "beam", step, half_step_check=False))
            scene = replace(
                base,
                irregularities=Irregularities(),
                contact_provider="auto",
                track_dynamics=replace(base.track_dynamics, cutoff_frequency_Hz=cutoff),
                integrator=replace(base.integrator, output_step_s=STEP_S),
            )
            result = simulate(scene)
            x = result.states[:, 0] - result.states[0, 0]
            force = -result.contact_force_N[x > 0.1, 0, 2]
            row[f"status_{cutoff:.0f}"] = result.status
            row[f"wheelset_{cutoff:.0f}_min_N"], row[f"wheelset_{cutoff:.0f}_max_N"] = (
                float(force.min()),
                float(force.max()),
            )
        _, travel, fe = _fe(scene, result, speed, flat=False)
        fe = fe[travel > 0.1]
        row["fe_min_N"], row["fe_max_N"] = float(fe.min()), float(fe.max())
        out.append(row)
        print(row, flush=True)
    return out


def default_beam() -> list:
    rows = []
    for length in FLAT_LENGTHS_M:
        for kmh in SPEEDS_KM_PER_H:
            speed = kmh / 3.6
            result = simulate(flat_scene(length, speed, "beam"))
            half_scene = flat_scene(length, speed, "beam", STEP_S / 2, half_step_check=False)
            half = simulate(replace(half_scene, integrator=replace(half_scene.integrator, output_step_s=STEP_S)))
            peak, peak_half = peak_vertical_N(result), peak_vertical_N(half)
            rows.append({
                "flat_length_m": length, "speed_km_per_h": kmh, "status": result.status,
                "peak_N": peak, "half_step_change": abs(peak - peak_half) / peak_half,
                "lifts": sum(1 for kind, _, _ in result.events if kind == "wheel-lift"),
                "wall_s": result.wall_time_s,
            })  # fmt: skip
            print(rows[-1], flush=True)
    return rows


def discretisation() -> list:
    rows = []
    speed = 60.0 / 3.6
    for cutoff, margin in ((2500.0, 6.0), (5000.0, 6.0), (10000.0, 6.0), (5000.0, 3.0), (5000.0, 12.0)):
        scene = flat_scene(0.05, speed, "beam", half_step_check=False)
        scene = replace(
            scene, track_dynamics=replace(scene.track_dynamics, cutoff_frequency_Hz=cutoff, end_margin_m=margin)
        )
        step = min(STEP_S, 1.25e-5 if cutoff > 5000 else STEP_S)
        scene = replace(scene, integrator=replace(scene.integrator, fixed_step_s=step, output_step_s=STEP_S))
        result = simulate(scene)
        layout = beam_layout(scene.track_dynamics, travel_m(scene))
        rows.append({
            "cutoff_Hz": cutoff, "margin_m": margin, "status": result.status, "peak_N": peak_vertical_N(result),
            "modes": layout.n_modes, "seats": layout.n_sleepers, "wall_s": result.wall_time_s,
        })  # fmt: skip
        print(rows[-1], flush=True)
    return rows


def render(data) -> str:
    m, c = data["machine"], data["checks"]
    study = json.loads((OUT / "wheelflat_study.json").read_text())
    lumped = {(r["flat_length_m"], r["speed_km_per_h"]): r for r in study["rows"]}
    cf = c["closed_form_pinned_pinned_Hz"]
    lines = [
        "# Discretely supported beam track: checks, a second method, and the wheel-flat impact on it",
        "",
        f"Written by `benchmarks/bench_beam_track.py` (its docstring has the set-up). Machine: {m['platform']}, "
        f"{m['cpu_count']} CPUs, Python {m['python']}, numpy {m['numpy']}; one process on a 2-core machine shared with "
        f"other jobs (1-min load average {m['load_average_1min_start']} at the start), {m['wall_s']} s wall.",
        "",
        "## The track (UIC60 on 0.6 m seats: pad 120 MN/m, half sleeper 125 kg, ballast 140 MN/m per seat)",
        "",
        "| rail | static stiffness at a seat / mid-span (MN/m) | P2 resonance, 906.5 kg (Hz) | pinned-pinned: "
        "closed form / mid-span receptance peak (Hz) | mid-span / seat receptance there |",
        "|---|---|---|---|---|",
    ]
    for theory in ("euler-bernoulli", "timoshenko"):
        t = c[theory]
        lines.append(
            f"| {theory} | {t['static_at_seat_N_per_m'] / 1e6:.1f} / {t['static_mid_span_N_per_m'] / 1e6:.1f} "
            f"| {t['p2_resonance_Hz']:.1f} | {cf[theory]:.0f} / {t['pinned_pinned_peak_Hz']:.0f} "
            f"| {t['mid_over_seat_at_peak']:.1f} |"
        )
    lines += [
        "",
        f"Jenkins et al. (1974): 150 MN/m, P2 resonance sqrt(Kt/(Mu+Mt))/2pi = {c['jenkins_p2_Hz']:.1f} Hz. "
        "tests/test_dynamics_beam.py checks these and the static deflection line against the Winkler beam.",
        "",
        "## Second method: finite-element rail (Euler-Bernoulli, Newmark) against the wheelset on the modal beam",
        "",
        "Both on the Euler-Bernoulli rail without rail damping. Peak = largest vertical wheel-rail force in 0.5 m "
        "(flat centre at 0.2 m). The vertical model differs from the wheelset model also in its contact (a point "
        "Hertz spring fed with the wheel-centre trajectory against the 3-D contact of the flattened tread): on the "
        "lumped and the rigid track the same comparison gave ratios 0.88-1.07 (wheelflat_study.md).",
        "",
        "| flat | V km/h | wheelset, modal beam (kN) | status | vertical, FE rail (kN) | ratio |",
        "|---|---|---|---|---|---|",
    ]
    for r in data["second"]:
        lines.append(
            f"| {r['flat_length_m'] * 1e3:.0f} mm | {r['speed_km_per_h']:.0f} | {r['wheelset_peak_N'] / 1e3:.1f} "
            f"| {r['status']} | {r['fe_peak_N'] / 1e3:.1f} | {r['wheelset_peak_N'] / r['fe_peak_N']:.3f} |"
        )
    fine = [r for r in data["second"] if "fe_fine_peak_N" in r][0]
    lines += [
        "",
        f"FE convergence (50 mm, 60 km/h): 6 elements per span and 10 us: {fine['fe_peak_N'] / 1e3:.2f} kN; 12 "
        f"elements and 5 us: {fine['fe_fine_peak_N'] / 1e3:.2f} kN.",
        "",
        "Sleeper passing on a round wheel (no flat; left wheel's vertical force after the first 0.1 m): the ripple "
        "is the stiffness varying between seat and mid-span, which the modal beam resolves only with modes short "
        "against the sleeper spacing. Static deflection under 100 kN, Euler-Bernoulli, mid-span over seat: +0.91 % "
        "with modes to 5 kHz (50 modes on a 16 m beam), +1.48 % at 10 kHz, +1.49 % at 20 kHz; Timoshenko: +4.9 % at "
        "5 kHz, +5.2 % at 10 kHz, +5.4 % at 20 kHz, +5.5 % at 40 kHz.",
        "",
        "| V km/h | modal, 5 kHz: min-max (kN), ripple | modal, 20 kHz | FE rail | status |",
        "|---|---|---|---|---|",
    ]
    for r in data["ripple"]:
        cells = []
        for key in ("wheelset_5000", "wheelset_20000", "fe"):
            lo, hi = r[f"{key}_min_N"], r[f"{key}_max_N"]
            cells.append(f"{lo / 1e3:.2f} - {hi / 1e3:.2f}, {(hi - lo) / 1e3:.2f}")
        lines.append(f"| {r['speed_km_per_h']:.0f} | {' | '.join(cells)} | {r['status_5000']}, {r['status_20000']} |")
    lines += [
        "",
        "## The wheel-flat scene on the default beam (Timoshenko), the lumped and the rigid track",
        "",
        "Beam: this benchmark (RK4 0.025 ms; `h/2` the peak's change at 0.0125 ms). Lumped and rigid: "
        "benchmarks/results/wheelflat_study.json (same scene, distance and peak).",
        "",
        "| flat | V km/h | beam (kN) | h/2 | lifts | status | lumped (kN) | rigid (kN) | lumped / beam "
        "| rigid / beam |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in data["beam"]:
        o = lumped[(r["flat_length_m"], r["speed_km_per_h"])]
        e, g = o["lumped"]["peak_N"], o["rigid"]["peak_N"]
        lines.append(
            f"| {r['flat_length_m'] * 1e3:.0f} mm | {r['speed_km_per_h']:.0f} | {r['peak_N'] / 1e3:.0f} "
            f"| {100 * r['half_step_change']:.1f} % | {r['lifts']} | {r['status']} | {e / 1e3:.0f} | {g / 1e3:.0f} "
            f"| {e / r['peak_N']:.2f} | {g / r['peak_N']:.2f} |"
        )
    lines += [
        "",
        "## The beam's discretisation (50 mm flat, 60 km/h, Timoshenko)",
        "",
        "| cut-off (Hz) | end margin (m) | modes | seats | peak (kN) | status | loop wall (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in data["discretisation"]:
        lines.append(
            f"| {r['cutoff_Hz']:.0f} | {r['margin_m']:.0f} | {r['modes']} | {r['seats']} | {r['peak_N'] / 1e3:.1f} "
            f"| {r['status']} | {r['wall_s']:.1f} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    if "--render" in sys.argv:
        data = json.loads((OUT / "beam_track.json").read_text())
        write_text(OUT / "beam_track.md", render(data))
        return
    parts = [a.split("=", 1)[1].split(",") for a in sys.argv[1:] if a.startswith("--only=")]
    if parts:  # recompute some parts into the existing results
        data = json.loads((OUT / "beam_track.json").read_text())
        for part in parts[0]:
            data[part] = {"checks": track_checks, "ripple": ripple, "second": second_method, "beam": default_beam,
                          "discretisation": discretisation}[part]()  # fmt: skip
        data["machine"]["partial_reruns"] = data["machine"].get("partial_reruns", []) + parts[0]
        write_text(OUT / "beam_track.json", json.dumps(data, indent=1) + "\n")
        write_text(OUT / "beam_track.md", render(data))
        return
    start = time.perf_counter()
    load = os.getloadavg()[0]
    data = {"checks": track_checks(), "second": second_method(), "ripple": ripple(), "beam": default_beam()}
    data["discretisation"] = discretisation()
    data["machine"] = {
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "load_average_1min_start": round(load, 1),
        "wall_s": round(time.perf_counter() - start, 1),
    }
    write_text(OUT / "beam_track.json", json.dumps(data, indent=1) + "\n")
    text = render(data)
    write_text(OUT / "beam_track.md", text)
    print(text)


if __name__ == "__main__":
    main()
