"""Non-Hertzian contact report: boundary elements (``bem``) against Hertz and FASTSIM on real profiles.

Cases: steps of the Manchester Contact Benchmark A-2.2 sweep (Shackleton & Iwnicki, VSD 46 (2008)
129-149; S1002 wheels on UIC60 rails canted 1:40, 10 kN per wheel, lateral shift k x 0.5 mm with yaw
k x 1.2 mrad, see :mod:`comparisons.manchester`). At 6-7 mm shift the right wheel's contact runs towards the
flange root, where the gap is far from the quadric form and Hertz/FASTSIM (which assume an ellipse from the
curvatures at the contact point) misjudge the patch; the BEM solves NORM and TANG on the sampled undeformed
distance of the contact search (``ContactGeometry.undeformed``).

Each patch is solved by the three models with the same geometry, creepages and normal force (force control
with the patch's Hertz share of the wheel load, by ``solve_wheelset_case``).

Output (into ``out_dir``): ``bem_report.json`` (all numbers), ``bem_report.md`` (tables and notes),
``bem_step<k>_<side>.png`` (BEM pressure/traction/slip maps) and ``bem_step<k>_<side>_profiles.png``
(pressure along the lateral and longitudinal lines through the BEM's pressure maximum: BEM, FASTSIM's
Hertzian pressure, and the Hertz ellipse).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import platform
from pathlib import Path

import numpy as np

from comparisons.contact_plots import plot_contact_fields
from comparisons.manchester import MATERIAL, a22_case
from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import solve_wheelset_case
from rigid_dynamics.files import save_figure, write_text

MODELS = ("hertz", "fastsim", "bem")
DEFAULT_STEPS = (0, 12, 13, 14)
SEARCH_OPTIONS = {"field_scale": 3.0, "field_points": 81}
"""Gap-field sampling for the report: +-3 rigid-overlap semi-axes (the search's default 1.6 is sized for
Hertzian patches and truncates the long non-elliptic tread patch of step 0), 81 x 81 points."""
KEYS = (
    "normal_force_N",
    "creep_force_long_N",
    "creep_force_lat_N",
    "spin_moment_Nm",
    "max_pressure_Pa",
    "contact_area_m2",
    "semi_axis_long_m",
    "semi_axis_lat_m",
    "success",
    "wall_time_s",
)


def _record(result) -> dict:
    out = {k: getattr(result, k) for k in KEYS}
    # the model's own estimate of its discretisation error (bem: largest relative; None for the others)
    out["status"] = result.status
    out["grid_error_estimate"] = result.extra.get("grid_error_estimate")
    return {
        k: (float(v) if isinstance(v, (int, float, np.floating)) and not isinstance(v, bool) else v)
        for k, v in out.items()
    }


def _profiles_png(path: Path, bem, fastsim, hertz, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f = bem.fields
    j, i = np.unravel_index(np.argmax(f.pressure_Pa), f.pressure_Pa.shape)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    for ax, axis in zip(axes, ("y", "x"), strict=True):
        coord = f.y_m if axis == "y" else f.x_m
        line = f.pressure_Pa[:, i] if axis == "y" else f.pressure_Pa[j, :]
        centre = coord[j] if axis == "y" else coord[i]
        ax.step(1e3 * coord, line / 1e6, where="mid", label="bem (sampled gap)")
        semi = hertz.semi_axis_lat_m if axis == "y" else hertz.semi_axis_long_m
        if semi and hertz.max_pressure_Pa:
            s = np.linspace(-semi, semi, 201)
            ax.plot(
                1e3 * (centre + s), hertz.max_pressure_Pa * np.sqrt(1 - (s / semi) ** 2) / 1e6, "k--", label="Hertz"
            )
        ff = fastsim.fields if fastsim is not None else None
        if ff is not None:
            fc = ff.y_m if axis == "y" else ff.x_m
            jj = int(np.argmin(np.abs(ff.y_m))) if axis == "x" else None
            ii = int(np.argmin(np.abs(ff.x_m))) if axis == "y" else None
            fline = ff.pressure_Pa[:, ii] if axis == "y" else ff.pressure_Pa[jj, :]
            ax.plot(1e3 * (fc + centre), fline / 1e6, ":", label="FASTSIM (its pressure)")
        ax.set_xlabel(f"{axis} [mm] ({'lateral' if axis == 'y' else 'rolling'}, contact frame)")
        ax.set_ylabel("pressure [MPa]")
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def write_bem_report(out_dir: str | Path, steps=DEFAULT_STEPS, bem_options: dict | None = None) -> dict:
    """Solve the steps with hertz, fastsim and bem; write JSON, Markdown and PNGs into ``out_dir``.

    Args:
        out_dir: output folder (created).
        steps: A-2.2 step numbers k (shift k x 0.5 mm, yaw k x 1.2 mrad).
        bem_options: options of the ``bem`` model (default 40 x 40 elements).

    Returns:
        The report as a dict (also written to ``bem_report.json``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    bem_options = dict(bem_options or {"nx": 40, "ny": 40})
    report = {
        "source": "Manchester Contact Benchmark A-2.2 (Shackleton & Iwnicki 2008), models hertz, fastsim, bem",
        "bem_options": bem_options,
        "search_options": SEARCH_OPTIONS,
        "machine": {"platform": platform.platform(), "cpu_count": os.cpu_count()},
        "steps": [],
    }
    for step in steps:
        case = a22_case(step)
        track = build_track(case)
        # the equilibrium with Hertz on the search's patches (plane at the deepest point); every model then solves
        # each patch under force control with Hertz's normal force, so the report compares the models at the same
        # normal force per patch
        hertz = solve_wheelset_case(
            case, MATERIAL, model="hertz", options={"patches": "search", "search": SEARCH_OPTIONS}, track=track
        )
        solutions = {"hertz": hertz}
        for name in MODELS:
            if name == "hertz":
                continue
            model = get_model(name)
            opts = bem_options if name == "bem" else None
            patches = [
                dataclasses.replace(
                    p,
                    result=model.solve(
                        p.geometry, p.creepage, MATERIAL, normal_force_N=p.result.normal_force_N, options=opts
                    ),
                )
                for p in hertz.patches
            ]
            solutions[name] = dataclasses.replace(hertz, patches=patches)
        entry = {
            "step": step,
            "lateral_shift_m": case.lateral_shift_m,
            "yaw_rad": case.yaw_rad,
            "status": {k: v.status for k, v in solutions.items()},
            "patches": [],
        }
        for index, patch in enumerate(solutions["bem"].patches):
            g = patch.geometry
            row = {
                "side": patch.side,
                "index": index,
                "is_elliptic": bool(g.is_elliptic),
                "contact_angle_rad": float(g.contact_angle_rad),
                "contact_point_rail_m": [float(v) for v in g.contact_point_rail_m],
                "creepage": [patch.creepage.longitudinal, patch.creepage.lateral, patch.creepage.spin_1_per_m],
                "bem_contact_reaches_field_edge": bool(
                    patch.result.extra.get("contact_touches_potential_area_edge", False)
                ),
                "models": {},
            }
            others = {}
            for name in MODELS:
                patches = solutions[name].patches
                match = patches[index] if index < len(patches) else None
                if match is not None and match.side == patch.side:
                    row["models"][name] = _record(match.result)
                    others[name] = match.result
            bem_result = patch.result
            if bem_result.fields is not None:
                png = out / f"bem_step{step}_{patch.side}{index}.png"
                plot_contact_fields(bem_result, png, title=f"A-2.2 step {step} ({patch.side}): bem")
                row["fields_png"] = png.name
                if "hertz" in others:
                    prof = out / f"bem_step{step}_{patch.side}{index}_profiles.png"
                    _profiles_png(
                        prof,
                        bem_result,
                        others.get("fastsim"),
                        others["hertz"],
                        f"A-2.2 step {step}, {patch.side} wheel, "
                        f"contact angle {math.degrees(g.contact_angle_rad):.1f} deg",
                    )
                    row["profiles_png"] = prof.name
            entry["patches"].append(row)
        report["steps"].append(entry)
    write_text(out / "bem_report.json", json.dumps(report, indent=2, default=str))
    write_text(out / "bem_report.md", _markdown(report))
    return report


def _fmt(v, scale=1.0, digits=3):
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    return f"{v * scale:.{digits}g}"


def _markdown(report: dict) -> str:
    lines = [
        "# Non-Hertzian contact: boundary elements vs Hertz and FASTSIM (comparisons/bem_report.py)",
        "",
        report["source"] + f"; bem options {report['bem_options']}; search options {report['search_options']}.",
        "Every model carries the same normal force per patch (the Hertz share of the 10 kN wheel load); the",
        "creepages are those of the freely rolling yawed wheelset. Forces on the wheel, contact frame.",
        "",
    ]
    for entry in report["steps"]:
        lines.append(
            f"## Step {entry['step']}: shift {1e3 * entry['lateral_shift_m']:.1f} mm, "
            f"yaw {1e3 * entry['yaw_rad']:.1f} mrad"
        )
        lines.append("")
        lines.append(
            "| patch | elliptic | angle deg | model | FN kN | Fx kN | Fy kN | Mz N m | pmax MPa | area mm2 "
            "| a mm | b mm | ok | status | grid error est. |"
        )
        lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for p in entry["patches"]:
            for name, m in p["models"].items():
                lines.append(
                    f"| {p['side']}{p['index']} | {'yes' if p['is_elliptic'] else 'no'} | "
                    f"{math.degrees(p['contact_angle_rad']):.1f} | {name} | {_fmt(m['normal_force_N'], 1e-3)} | "
                    f"{_fmt(m['creep_force_long_N'], 1e-3)} | {_fmt(m['creep_force_lat_N'], 1e-3)} | "
                    f"{_fmt(m['spin_moment_Nm'])} | {_fmt(m['max_pressure_Pa'], 1e-6)} | "
                    f"{_fmt(m['contact_area_m2'], 1e6)} | {_fmt(m['semi_axis_long_m'], 1e3)} | "
                    f"{_fmt(m['semi_axis_lat_m'], 1e3)} | {_fmt(m['success'])} | {m['status']} | "
                    f"{_fmt(m['grid_error_estimate'])} |"
                )
        lines.append("")
        for p in entry["patches"]:
            if p["bem_contact_reaches_field_edge"]:
                lines.append(
                    f"Note: the bem contact of {p['side']}{p['index']} reaches the edge of the sampled gap field."
                )
        lines.append("")
        for p in entry["patches"]:
            if "fields_png" in p:
                lines.append(f"![step {entry['step']} {p['side']}]({p['fields_png']})")
            if "profiles_png" in p:
                lines.append(f"![profiles]({p['profiles_png']})")
        lines.append("")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import sys

    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/bem_report")
    write_bem_report(target)
    print(f"written {target / 'bem_report.md'}")
