"""Creep-force sensitivities: time and error per rung, the slope at zero creepage against Kalker, the wheelset
Jacobian's velocity columns, and the linear critical speed per rung.

1. Sensitivities of each rung at one patch (a/b from 0.46 m / 0.30 m relative radii, N = 100 kN, G = 82 GPa,
   nu = 0.25, mu = 0.3; xi = 1e-3, eta = -5e-4, phi = 0.2 1/m): solves, wall time and the largest stated error
   (|J(h) - J(2h)| relative to the row's largest entry); for the analytic rungs the difference to their own central
   differences instead.
2. The slope at zero creepage against Kalker's Table E.3 (a/b = 1, nu = 0.25: C11 4.12, C22 3.67, C23 1.47) on
   refined grids: FASTSIM and the BEM.
3. The velocity columns of the wheelset's Jacobian on hunting-conical at a creeping state (y = 2 mm,
   y' = 0.05 m/s, psi' = 0.02 rad/s): from the sensitivities (rigid_dynamics.wheelset.creep_jacobian) and by
   differences of the right-hand side (central with the steps 1e-7 and 1e-5 x max(1, |v|), and the forward
   differences of drivers.state_jacobian that Radau and BDF use, step sqrt(eps) max(1, |v|)), each against the
   central differences at 1e-5 (the BEM) or 1e-7 (the compiled rungs), with the time of each.
4. The linear critical speed of hunting-conical with k_x = k_y = 0.5 MN/m per side, with each rung's slopes at
   zero creepage.

Writes benchmarks/results/creep_sensitivities.json and .md.
Run: .venv/bin/python benchmarks/bench_creep_sensitivities.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import dataclasses  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.contact.sensitivities import OperatingPoint, creep_sensitivities  # noqa: E402
from rigid_dynamics.contact.types import ContactGeometry, Creepage  # noqa: E402
from rigid_dynamics.files import atomic_write  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

MAT = Material(82e9, 0.25, 0.3)
KALKER = {"c11": 4.12, "c22": 3.67, "c23": 1.47}


def row_relative(values: np.ndarray, scale: np.ndarray) -> float:
    """Largest |value| / (largest |scale| of its row, creepage columns), over the finite rows."""
    out = 0.0
    for i in range(3):
        if not np.all(np.isfinite(scale[i, :3])):
            continue
        ref = np.max(np.abs(scale[i, :3]))
        if ref > 0:
            out = max(out, float(np.max(np.abs(values[i, :3])) / ref))
    return out


def part_rungs() -> list[dict]:
    point = OperatingPoint(ContactGeometry.quadric(0.46, 0.30), Creepage(1e-3, -5e-4, 0.2, 20.0), MAT, 1e5)
    rows = []
    for name in ("linear", "vermeulen-johnson", "fastsim", "fastrip", "kpec", "bem"):
        creep_sensitivities(name, point)  # compile / warm
        best = None
        for _ in range(3):
            s = creep_sensitivities(name, point)
            best = s if best is None or s.wall_time_s < best.wall_time_s else best
        row = {"rung": name, "kind": best.kind, "solves": best.solves, "wall_time_s": best.wall_time_s}
        if best.kind == "analytic":
            fd = creep_sensitivities(name, point, method="central-difference")
            row["difference_to_central_differences"] = row_relative(fd.jacobian - best.jacobian, best.jacobian)
        else:
            row["stated_error"] = row_relative(best.error_estimate, best.jacobian)
        rows.append(row)
    return rows


def part_kalker() -> list[dict]:
    point = OperatingPoint(ContactGeometry.quadric(0.46, 0.46), Creepage(0.0, 0.0, 0.0, 20.0), MAT, 1e5)
    rows = []
    for name, grids in (("fastsim", (10, 20, 40, 80)), ("bem", (16, 32, 64))):
        for n in grids:
            s = creep_sensitivities(name, point._replace(options={"nx": n, "ny": n}))
            c = s.coefficients()
            rows.append({"rung": name, "grid": n, "wall_time_s": s.wall_time_s,
                         **{k: getattr(c, k) for k in KALKER},
                         **{f"{k}_error": getattr(c, k) / v - 1 for k, v in KALKER.items()}})  # fmt: skip
    return rows


def part_jacobian() -> list[dict]:
    from rigid_dynamics.wheelset.creep_jacobian import (
        creep_velocity_columns,
        difference_velocity_columns,
        relative_difference,
    )
    from rigid_dynamics.wheelset.drivers import state_jacobian
    from rigid_dynamics.wheelset.simulate import build_provider, get_contact_model, initial_state, model_options
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel
    from wheelrail.scenes import load_scene

    scene = load_scene("hunting-conical")
    provider = build_provider(scene)
    rows = []
    for name in ("linear", "vermeulen-johnson", "fastsim", "bem"):
        sc = dataclasses.replace(scene, contact_model=name)
        model = WheelsetModel(sc, provider, get_contact_model(name), model_options(name, sc))
        state, ok, why = model.static_state(initial_state(sc)[:12])
        full = model.full_state(state)
        full[1] += 0.002
        full[7] += 0.05
        full[9] += 0.02
        reference = difference_velocity_columns(model, 0.0, full, rel_step=1e-5 if name == "bem" else 1e-7)
        timed = {}
        for label, fn in (
            ("sensitivities", lambda m=model, f=full: creep_velocity_columns(m, 0.0, f).columns),
            ("central 1e-7", lambda m=model, f=full: difference_velocity_columns(m, 0.0, f, rel_step=1e-7)),
            ("central 1e-5", lambda m=model, f=full: difference_velocity_columns(m, 0.0, f, rel_step=1e-5)),
            ("forward sqrt(eps) (Radau, BDF)",
             lambda m=model, f=full: state_jacobian(m.derivative)(0.0, f)[:, 6:12]),
        ):  # fmt: skip
            fn()
            start = time.perf_counter()
            columns = fn()
            elapsed = time.perf_counter() - start
            timed[label] = {"wall_time_s": elapsed, "difference": relative_difference(columns, reference)}
        rows.append({"rung": name, "reference": "central 1e-5" if name == "bem" else "central 1e-7", **timed})
    return rows


def part_critical() -> list[dict]:
    from wheelrail.critical import linear_critical_speed
    from wheelrail.scenes import load_scene

    scene = load_scene("hunting-conical")
    scene = dataclasses.replace(scene, suspension=dataclasses.replace(
        scene.suspension, longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5))  # fmt: skip
    rows = []
    for name in ("linear", "vermeulen-johnson", "fastsim", "kpec", "bem"):
        start = time.perf_counter()
        out = linear_critical_speed(dataclasses.replace(scene, contact_model=name))
        rows.append({"rung": name, "speed_m_per_s": out["speed_m_per_s"], "f11_N": out["creep_coefficients_N"][0],
                     "f22_N": out["creep_coefficients_N"][1], "c11": out["creep_coefficients"]["c11"][0],
                     "c22": out["creep_coefficients"]["c22"][0],
                     "f11_difference_error_N": out["creep_coefficients"]["f11_difference_error_N"],
                     "wall_time_s": time.perf_counter() - start})  # fmt: skip
    return rows


def main() -> None:
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "note": "machine shared with other jobs (2 cores, 8 sessions); one thread; best of 3 where said",
    }
    result = {"machine": machine, "rungs": part_rungs(), "kalker": part_kalker(), "jacobian": part_jacobian(),
              "critical_speed": part_critical()}  # fmt: skip
    out_dir = ROOT / "benchmarks" / "results"
    atomic_write(out_dir / "creep_sensitivities.json", lambda p: p.write_text(json.dumps(result, indent=2) + "\n"))
    lines = [
        "# Creep-force sensitivities",
        "",
        "Written by `benchmarks/bench_creep_sensitivities.py` (its docstring says what each part measures).",
        f"Machine: {machine['platform']}, {machine['processor']}, os.cpu_count() = {machine['cpu_count']}, "
        f"Python {machine['python']}, numpy {machine['numpy']}; {machine['note']}.",
        "",
        "## 1. Sensitivities per rung (one patch, mid creepage; best of 3)",
        "",
        "| rung | kind | solves | time [ms] | error (stated, or against own differences) |",
        "|---|---|---|---|---|",
    ]
    for r in result["rungs"]:
        err = r.get("stated_error", r.get("difference_to_central_differences"))
        lines.append(f"| {r['rung']} | {r['kind']} | {r['solves']} | {1e3 * r['wall_time_s']:.3g} | {err:.2g} |")
    lines += ["", "## 2. Slope at zero creepage against Kalker's Table E.3 (a/b = 1, nu = 0.25)", "",
              "| rung | grid | c11 (error) | c22 (error) | c23 (error) | time [s] |",
              "|---|---|---|---|---|---|"]  # fmt: skip
    for r in result["kalker"]:
        cells = " | ".join(f"{r[k]:.4f} ({100 * r[k + '_error']:+.2f} %)" for k in KALKER)
        lines.append(f"| {r['rung']} | {r['grid']} x {r['grid']} | {cells} | {r['wall_time_s']:.3g} |")
    lines += ["", "## 3. Velocity columns of the wheelset Jacobian (hunting-conical, creeping state)", "",
              "Difference: largest |column - reference| over each acceleration row, relative to the row's largest "
              "reference entry.", "",
              "| rung | reference | method | time [ms] | difference |", "|---|---|---|---|---|"]  # fmt: skip
    for r in result["jacobian"]:
        for label in ("sensitivities", "central 1e-7", "central 1e-5", "forward sqrt(eps) (Radau, BDF)"):
            v = r[label]
            lines.append(f"| {r['rung']} | {r['reference']} | {label} | {1e3 * v['wall_time_s']:.3g} | "
                         f"{v['difference']:.2g} |")  # fmt: skip
    lines += ["", "## 4. Linear critical speed per rung (slopes at zero creepage on the static patch)", "",
              "| rung | f11 [MN] | f22 [MN] | c11 | c22 | f11 difference error [N] | speed [m/s] | time [s] |",
              "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in result["critical_speed"]:
        lines.append(f"| {r['rung']} | {1e-6 * r['f11_N']:.4f} | {1e-6 * r['f22_N']:.4f} | {r['c11']:.4f} | "
                     f"{r['c22']:.4f} | {r['f11_difference_error_N']:.3g} | {r['speed_m_per_s']:.4f} | "
                     f"{r['wall_time_s']:.3g} |")  # fmt: skip
    atomic_write(out_dir / "creep_sensitivities.md", lambda p: p.write_text("\n".join(lines) + "\n"))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
