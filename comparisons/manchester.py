"""Manchester Contact Benchmark, case A-2.2: the 21-step sweep, a table and plots.

P. Shackleton, S.D. Iwnicki, "Comparison of wheel-rail contact codes for railway vehicle simulation: an
introduction to the Manchester Contact Benchmark and initial results", Vehicle System Dynamics 46 (2008)
129-149. Case A-2.2: S1002 wheels on UIC60 rails canted 1:40 (the benchmark's v3 profile files, from the
open-source CONTACT program), gauge 1435 mm measured 14 mm below the top, flange-back distance 1360 mm,
r0 = 460 mm, 10 kN vertical load per wheel, 2 m/s, G = 82 GPa, nu = 0.28, mu = 0.3; lateral shift k x 0.5 mm
with yaw k x 1.2 mrad, k = 0..20.

Each step is a :class:`~rigid_dynamics.contact.wheelset_case.WheelsetCase` solved by
``solve_wheelset_case`` (vertical position and roll carrying the loads, Hertz per patch for the equilibrium,
then the requested model per patch). The wheel spin rate is V over the mean rolling radius of the two wheels
(``spin_rate = "mean-rolling-radius"``), as in CONTACT's own A-2.2 input (examples/mbench_a22_right.inp,
whose roll angles are also given as ``CONTACT_ROLL_RAD`` for comparison).

Output (into ``out_dir``, written to temporary names and renamed): ``manchester_a22.csv`` (one row per patch),
``manchester_a22_summary.json`` and the plots ``contact_position.png``, ``contact_angle.png``,
``rolling_radius_difference.png``, ``forces.png``.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
from rigid_dynamics.materials import Material

STEPS = tuple(range(21))
SHIFT_STEP_M = 0.5e-3
YAW_STEP_RAD = 1.2e-3

CONTACT_ROLL_RAD = (
    0.0, -0.00002304, -0.00005049, -0.00008103, -0.00011280, -0.00014570, -0.00018030, -0.00021680, -0.00025570,
    -0.00029770, -0.00035540, -0.00047770, -0.00062720, -0.00437600, -0.00639300, -0.00764200, -0.00860600,
    -0.00940800, -0.01010113, -0.01071386, -0.01126431,
)  # fmt: skip
"""Roll angle of each step as computed by CONTACT (E.A.H. Vollebregt; eve70a/CONTACT, Apache-2.0,
examples/mbench_a22_right.inp), rad."""

MATERIAL = Material(shear_modulus_Pa=82.0e9, poisson_ratio=0.28, friction_coefficient=0.3)

COLUMNS = (
    "step", "lateral_shift_m", "yaw_rad", "roll_rad", "roll_contact_program_rad", "vertical_position_m",
    "rolling_radius_difference_m", "side", "patch", "contact_y_rail_m", "contact_z_rail_m", "contact_y_wheel_m",
    "contact_angle_rad", "rolling_radius_m", "approach_m", "is_elliptic", "normal_force_N", "creep_force_long_N",
    "creep_force_lat_N", "spin_moment_Nm", "semi_axis_long_m", "semi_axis_lat_m", "max_pressure_Pa",
    "creepage_long", "creepage_lat", "spin_creepage_1_per_m", "status",
)  # fmt: skip


def a22_case(step: int) -> WheelsetCase:
    """The WheelsetCase of step k (shift k x 0.5 mm, yaw k x 1.2 mrad)."""
    return WheelsetCase(
        wheel_profile="MBench_S1002_v3",
        rail_profile="MBench_UIC60_v3",
        lateral_shift_m=step * SHIFT_STEP_M,
        yaw_rad=step * YAW_STEP_RAD,
        gauge_m=1.435,
        gauge_height_m=0.014,
        flange_back_distance_m=1.360,
        nominal_radius_m=0.46,
        rail_inclination_rad=math.atan(1.0 / 40.0),
        wheel_load_N=10.0e3,
        rolling_speed_m_per_s=2.0,
    )


def _value(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return int(v)
    return v


def sweep(method: str = "fastsim", steps=STEPS, model_options=None) -> list[dict]:
    """Solve the A-2.2 steps; one dict per patch (keys ``COLUMNS``)."""
    track = build_track(a22_case(0))
    rows = []
    options = {"spin_rate": "mean-rolling-radius", "model": model_options}
    for step in steps:
        case = a22_case(step)
        sol = solve_wheelset_case(case, MATERIAL, method, options, track=track)
        main = {}
        for p in sol.patches:
            if p.side not in main or p.result.normal_force_N > main[p.side].result.normal_force_N:
                main[p.side] = p
        delta_r = (
            main["right"].geometry.rolling_radius_m - main["left"].geometry.rolling_radius_m
            if len(main) == 2
            else math.nan
        )
        counters = {"left": 0, "right": 0}
        for p in sol.patches:
            g, r, c = p.geometry, p.result, p.creepage
            rows.append(
                {
                    "step": step,
                    "lateral_shift_m": case.lateral_shift_m,
                    "yaw_rad": case.yaw_rad,
                    "roll_rad": sol.roll_rad,
                    "roll_contact_program_rad": CONTACT_ROLL_RAD[step] if step < len(CONTACT_ROLL_RAD) else math.nan,
                    "vertical_position_m": sol.vertical_position_m,
                    "rolling_radius_difference_m": delta_r,
                    "side": p.side,
                    "patch": counters[p.side],
                    "contact_y_rail_m": g.contact_point_rail_m[0],
                    "contact_z_rail_m": g.contact_point_rail_m[1],
                    "contact_y_wheel_m": g.contact_point_wheel_m[0],
                    "contact_angle_rad": g.contact_angle_rad,
                    "rolling_radius_m": g.rolling_radius_m,
                    "approach_m": g.approach_m,
                    "is_elliptic": g.is_elliptic,
                    "normal_force_N": r.normal_force_N,
                    "creep_force_long_N": r.creep_force_long_N,
                    "creep_force_lat_N": r.creep_force_lat_N,
                    "spin_moment_Nm": r.spin_moment_Nm,
                    "semi_axis_long_m": r.semi_axis_long_m,
                    "semi_axis_lat_m": r.semi_axis_lat_m,
                    "max_pressure_Pa": r.max_pressure_Pa,
                    "creepage_long": c.longitudinal,
                    "creepage_lat": c.lateral,
                    "spin_creepage_1_per_m": c.spin_1_per_m,
                    "status": sol.status if sol.success else f"{sol.status}: {sol.message}",
                }
            )
            counters[p.side] += 1
    return rows


def _atomic_text(path: Path, text: str) -> None:
    from rigid_dynamics.files import write_text

    write_text(path, text)


def write_table(rows: list[dict], path: Path) -> Path:
    """CSV with the ``COLUMNS`` header, SI units as in the column names (written atomically)."""
    import io

    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _value(row[k]) for k in COLUMNS})
    _atomic_text(path, buffer.getvalue())
    return path


def write_plots(rows: list[dict], out_dir: Path) -> list[Path]:
    """The four PNG plots (matplotlib, imported here)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = []
    style = {"left": ("tab:blue", "o"), "right": ("tab:red", "s")}

    def save(fig, name):
        from rigid_dynamics.files import save_figure

        path = out_dir / name
        try:
            save_figure(fig, path, dpi=120, bbox_inches="tight")
        finally:
            plt.close(fig)
        out.append(path)

    def by_side(key, scale=1.0):
        for side in ("left", "right"):
            sel = [r for r in rows if r["side"] == side and r[key] is not None]
            yield side, [1e3 * r["lateral_shift_m"] for r in sel], [scale * r[key] for r in sel]

    for key, scale, ylabel, name, title in (
        ("contact_y_rail_m", 1e3, "contact point on rail, y_rail [mm] (gauge face < 0)", "contact_position.png",
         "Contact position on the rail"),
        ("contact_angle_rad", 180 / math.pi, "contact angle [deg]", "contact_angle.png", "Contact angle"),
    ):  # fmt: skip
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for side, x, y in by_side(key, scale):
            color, marker = style[side]
            ax.plot(x, y, marker, color=color, label=f"{side} wheel", ls="none")
        ax.set_xlabel("lateral shift [mm] (yaw = 2.4 mrad/mm)")
        ax.set_ylabel(ylabel)
        ax.set_title(f"Manchester A-2.2: {title}")
        ax.grid(alpha=0.3)
        ax.legend()
        save(fig, name)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    steps = sorted({r["step"] for r in rows})
    first = [next(r for r in rows if r["step"] == s) for s in steps]
    ax.plot([1e3 * r["lateral_shift_m"] for r in first], [1e3 * r["rolling_radius_difference_m"] for r in first], "k.-")
    ax.set_xlabel("lateral shift [mm]")
    ax.set_ylabel("rolling radius difference r_right - r_left [mm]")
    ax.set_title("Manchester A-2.2: rolling radius difference (main patch of each wheel)")
    ax.grid(alpha=0.3)
    save(fig, "rolling_radius_difference.png")

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for ax, key, label in zip(
        axes,
        ("normal_force_N", "creep_force_long_N", "creep_force_lat_N"),
        ("normal force N [kN]", "longitudinal creep force [kN]", "lateral creep force [kN]"),
        strict=True,
    ):
        for side, x, y in by_side(key, 1e-3):
            color, marker = style[side]
            ax.plot(x, y, marker, color=color, label=f"{side} wheel", ls="none")
        ax.set_xlabel("lateral shift [mm]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle("Manchester A-2.2: forces on the wheels (contact frame; each marker one patch)")
    save(fig, "forces.png")
    return out


def run_manchester_a22(out_dir, method: str = "fastsim", steps=STEPS, plots: bool = True) -> dict:
    """Run the sweep and write table, summary and plots into ``out_dir`` (created if missing).

    Returns:
        The summary dict (also written as ``manchester_a22_summary.json``): method, steps, first step with
        flange contact (contact angle > 0.7 rad), largest roll difference to CONTACT, files written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = sweep(method, steps)
    files = [write_table(rows, out / "manchester_a22.csv")]
    if plots:
        files += write_plots(rows, out)
    flange_steps = sorted({r["step"] for r in rows if r["side"] == "right" and r["contact_angle_rad"] > 0.7})
    roll_error = max(
        (
            abs(r["roll_rad"] - r["roll_contact_program_rad"])
            for r in rows
            if math.isfinite(r["roll_contact_program_rad"])
        ),
        default=math.nan,
    )
    summary = {
        "case": "Manchester Contact Benchmark A-2.2",
        "method": method,
        "steps": list(steps),
        "patches": len(rows),
        "first_flange_contact_shift_m": flange_steps[0] * SHIFT_STEP_M if flange_steps else None,
        "max_roll_difference_to_contact_rad": roll_error,
        "all_converged": all(r["status"] == "ok" for r in rows),
        "files": [p.name for p in files],
    }
    summary_path = out / "manchester_a22_summary.json"
    _atomic_text(summary_path, json.dumps(summary, indent=2) + "\n")
    summary["files"].append(summary_path.name)
    return summary
