"""The order at which the FEA's max pressure converges on the A-2.2 flange-root patch, and what its estimate states.

The right patch of ``wheelrail contact manchester-a22`` at the BEM equilibrium's approach (approach control, as in
the wheelset equilibrium; frictionless FEA, rigid formulation, P1) is solved at 4, 6 and 9 elements per semi-axis of
its mesh box (the default series' first two levels and the one coarser level that fea.refinement's
``measure_order`` adds for sampled patches). Every level's max pressure is brought to the BEM's force by Hertz's
scaling p N^(1/3) (as the load-balanced estimate does, fea.refinement) and recovered two ways from the same nodal
contact forces:

* the reported one: the quadric cap of fea.postprocess.peak_pressure within sqrt(3 h min(a, b)) (shrinks with h);
* a fixed window: the same cap fitted over the nodes within an ellipse of 0.8 times the strip's semi-axes (a window
  that does not shrink with h, so its level-to-level change is the solution's).

Reference: CONTACT's Manchester A-2.2 case 11 (comparisons/cases/a22-flange-root/contact_grid.csv, right wheel,
N 9619 N): 1572 MPa at 0.1 and 0.05 mm elements, area 14.955 mm2 at 0.05 mm.

Usage::

    .venv/bin/python benchmarks/bench_fea_flange_root_order.py   # writes fea_flange_root_order.json/md
"""

from __future__ import annotations

import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
RATIO = 1.5
LEVELS = (4.0, 6.0, 9.0)
CONTACT = {"normal_force_N": 9619.0, "max_pressure_Pa": 1572e6, "contact_area_m2": 14.955e-6}
WINDOW = 0.8


def _window_fit(xy, p, usable, centre, semi) -> float | None:
    """The cap of fea.postprocess.peak_pressure (postprocess.quadric_cap_peak) fitted over the usable nodes within
    an ellipse of semi-axes ``semi`` around ``centre`` (None: no cap, or its top outside the ellipse)."""
    from fea.postprocess import quadric_cap_peak

    d = (xy - centre) / np.asarray(semi)
    near = usable & (np.hypot(d[:, 0], d[:, 1]) <= 1.0)
    return quadric_cap_peak(d[near], p[near])


def _strip(xy, p, usable, guess) -> tuple[np.ndarray, tuple[float, float]]:
    """Centre and semi-axes of the connected high-pressure strip around ``guess`` (nodes with p above 1/4 of the
    guess's neighbourhood's, within 1 mm laterally of it)."""
    near = usable & (np.abs(xy[:, 1] - guess[1]) < 1.5e-3)
    sel = near & (p > 0.05 * p[near].max())
    x, y = xy[sel, 0], xy[sel, 1]
    centre = np.array([0.5 * (x.min() + x.max()), 0.5 * (y.min() + y.max())])
    return centre, (0.5 * (x.max() - x.min()), 0.5 * (y.max() - y.min()))


def run() -> dict:
    import dolfinx_solver  # noqa: F401

    from fea import postprocess as post
    from fea.model import FeaModel
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case
    from wheelrail.cases import load_case

    captured = []
    original = post.peak_pressure

    def spy(xy, pressure, usable, guess, radius):
        captured.append((xy.copy(), pressure.copy(), usable.copy(), np.asarray(guess, float), radius))
        return original(xy, pressure, usable, guess, radius)

    post.peak_pressure = spy
    case = load_case("manchester-a22")
    bem = solve_wheelset_case(case.wheelset, case.material, "bem", options={})
    patch = next(p for p in bem.patches if p.side == "right")
    force = patch.result.normal_force_N
    rows = []
    try:
        for n in LEVELS:
            k = math.log(n / 6.0) / math.log(RATIO)
            opts = {"stresses": False, "mesh_tolerance": None, "elements_per_semi_axis": n, "grading": 0.4 / RATIO**k}
            start = time.perf_counter()
            r = FeaModel().solve(patch.geometry, patch.creepage, case.material, normal_force_N=None, options=opts)
            wall = time.perf_counter() - start
            xy, p, usable, guess, radius = captured[-1]
            centre, semi = _strip(xy, p, usable, guess)
            scale = (force / r.normal_force_N) ** (1.0 / 3.0)
            window = _window_fit(xy, p, usable, centre, (WINDOW * semi[0], WINDOW * semi[1]))
            rows.append({
                "elements_per_semi_axis": n, "element_size_m": r.extra.get("element_size_m"),
                "dofs": r.extra.get("dofs"), "wall_time_s": wall, "normal_force_N": r.normal_force_N,
                "fit_radius_m": radius, "strip_semi_axes_m": semi,
                "max_pressure_Pa": r.max_pressure_Pa * scale,
                "max_pressure_window_Pa": None if window is None else window * scale,
                "contact_area_m2": r.contact_area_m2 * scale**2,
            })  # fmt: skip
    finally:
        post.peak_pressure = original
    from fea.refinement import estimate

    def levels(names):
        return [{"max_pressure": row[names], "contact_area": row["contact_area_m2"]} for row in rows]

    estimates = {}
    for label, key in (("reported fit", "max_pressure_Pa"), ("fixed window", "max_pressure_window_Pa")):
        if any(row[key] is None for row in rows):
            continue
        two = estimate(levels(key)[1:], None)
        three = estimate(levels(key), None)
        estimates[label] = {
            "two_levels": two["mesh_relative_error"]["max_pressure"],
            "three_levels": three["mesh_relative_error"]["max_pressure"],
            "observed_order": three["observed_order"]["max_pressure"],
            "difference_from_contact": rows[-1][key]
            * (CONTACT["normal_force_N"] / force) ** (1 / 3)
            / CONTACT["max_pressure_Pa"]
            - 1.0,
        }
    return {
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}",
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "bem": {"normal_force_N": force, "max_pressure_Pa": patch.result.max_pressure_Pa,
                "contact_area_m2": patch.result.contact_area_m2},
        "contact": CONTACT, "levels": rows, "estimates": estimates,
    }  # fmt: skip


def markdown(data: dict) -> str:
    force = data["bem"]["normal_force_N"]
    lines = [
        "# FEA max pressure on the A-2.2 flange-root patch: observed order and stated error (issue 22)",
        "",
        f"Run {data['date']} on {data['machine']} by benchmarks/bench_fea_flange_root_order.py (its docstring says",
        "what is computed). Max pressures and areas brought to the BEM's force at this approach "
        f"({force:.0f} N) by p N^(1/3), A N^(2/3).",
        "",
        "| n/semi-axis | h [mm] | DOFs | time / s | N [N] | fit radius [mm] | p reported fit [MPa] "
        "| p fixed window [MPa] | area [mm2] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in data["levels"]:
        window = r["max_pressure_window_Pa"]
        lines.append(
            f"| {r['elements_per_semi_axis']:g} | {r['element_size_m'] * 1e3:.3f} | {r['dofs']} | "
            f"{r['wall_time_s']:.1f} | {r['normal_force_N']:.0f} | {r['fit_radius_m'] * 1e3:.2f} | "
            f"{r['max_pressure_Pa'] / 1e6:.1f} | {'-' if window is None else f'{window / 1e6:.1f}'} | "
            f"{r['contact_area_m2'] * 1e6:.3f} |"
        )
    c = data["contact"]
    lines += [
        "",
        f"CONTACT (0.05 mm, N {c['normal_force_N']:.0f} N): {c['max_pressure_Pa'] / 1e6:.0f} MPa, "
        f"{c['contact_area_m2'] * 1e6:.3f} mm2; our BEM (40 x 40) at this approach "
        f"{data['bem']['max_pressure_Pa'] / 1e6:.0f} MPa, {data['bem']['contact_area_m2'] * 1e6:.2f} mm2.",
        "",
        "| max pressure | mesh error, two finest levels (order assumed 1) | mesh error, three levels "
        "| observed order | finest level against CONTACT (at CONTACT's force) |",
        "|---|---|---|---|---|",
    ]
    for label, e in data["estimates"].items():
        order = "-" if e["observed_order"] is None else f"{e['observed_order']:.2f}"
        lines.append(
            f"| {label} | {e['two_levels']:.2%} | {e['three_levels']:.2%} | {order} | "
            f"{e['difference_from_contact']:+.2%} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    from rigid_dynamics.files import write_text

    data = run()
    write_text(OUT / "fea_flange_root_order.json", json.dumps(data, indent=1, default=float))
    write_text(OUT / "fea_flange_root_order.md", markdown(data))
    print(markdown(data))


if __name__ == "__main__":
    main()
