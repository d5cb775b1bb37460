"""Manchester Contact Benchmark, case A-2.2: the 21-step sweep against CONTACT's published solution.

P. Shackleton, S.D. Iwnicki, "Comparison of wheel-rail contact codes for railway vehicle simulation: an
introduction to the Manchester Contact Benchmark and initial results", Vehicle System Dynamics 46 (2008)
129-149. Case A-2.2: S1002 wheels on UIC60 rails canted 1:40 (the benchmark's v3 profile files, from the
open-source CONTACT program), gauge 1435 mm measured 14 mm below the top, flange-back distance 1360 mm,
r0 = 460 mm, 10 kN vertical load per wheel, 2 m/s, G = 82 GPa, nu = 0.28, mu = 0.3; lateral shift k x 0.5 mm
with yaw k x 1.2 mrad, k = 0..20.

Reference: CONTACT's solution of the right wheel (E.A.H. Vollebregt, J.J. Kalker; examples/mbench_a22_right,
data/contact_reference/SOURCE.md), read by :func:`contact_reference` and converted to SI and to wheelrail's
conventions at the reader (forces on the wheel, CONTACT's right-side contact angle negated, CKSI = -xi).

Each step is a :class:`~rigid_dynamics.contact.wheelset_case.WheelsetCase` solved by ``solve_wheelset_case``
with kinematics ``"deck"`` (default: CONTACT's deck, the roll and pitch rate prescribed per step and each wheel's
vertical position solved for 10 kN total vertical force) or ``"equilibrium"`` (z and roll of the whole wheelset
solved, pitch rate for zero net axle moment). The ``bem`` rung runs on CONTACT's grid (element size 0.2 mm,
aligned with the contact reference point) unless model options say otherwise.

Output (into ``out_dir``, written to temporary names and renamed): ``manchester_a22.csv`` (one row per patch,
with CONTACT's values and the differences on the right wheel), ``manchester_a22_summary.json`` (largest
differences, and whether they are within the tolerances of ``TOLERANCES``) and the plots
``contact_position.png``, ``contact_angle.png``, ``rolling_radius_difference.png``, ``forces.png``,
``pressure_area.png`` (CONTACT's values as black crosses on the right wheel).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
from functools import cache
from pathlib import Path

from rigid_dynamics.contact.track import build_track
from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
from rigid_dynamics.materials import Material

STEPS = tuple(range(21))
SHIFT_STEP_M = 0.5e-3
YAW_STEP_RAD = 1.2e-3
KINEMATICS = ("deck", "equilibrium")
DECK_PROFILE_SMOOTHING_M = 0.0
"""With CONTACT's deck (kinematics "deck") the profiles' splines interpolate their points, as the deck has them
(SMOOTH = 0 on both profile lines of examples/mbench_a22_right.inp; the MBench v3 files are design profiles sampled
every 0.1-0.5 mm). With the wheelrail default of 2 mm smoothing (kept for "equilibrium") the flange root's arcs are
smeared: the gap there differs from CONTACT's by up to 1 um (1.8e-3 1/mm in its lateral curvature), which moves 9 %
of a small second patch's normal force."""
CONTACT_ELEMENT_SIZE_M = 0.2e-3  # DX = DS of CONTACT's deck
REFERENCE_CSV = Path(__file__).parent / "data" / "contact_reference" / "mbench_a22_right.csv"

MATERIAL = Material(shear_modulus_Pa=82.0e9, poisson_ratio=0.28, friction_coefficient=0.3)

TOLERANCES = {
    "normal_force": 0.01,  # relative
    "creep_force_long": 0.02,  # of mu FN
    "creep_force_lat": 0.02,  # of mu FN
    "max_pressure": 0.03,  # relative
    "contact_area": 0.05,  # relative
    "contact_y_rail": 0.5e-3,  # m
}
"""Largest accepted differences to CONTACT (issue: wheel-rail contact equal to CONTACT)."""

REFERENCE_KEYS = (
    "normal_force_N", "creep_force_long_N", "creep_force_lat_N", "max_pressure_Pa", "contact_area_m2",
    "contact_y_rail_m", "contact_angle_rad", "approach_m", "creepage_long", "creepage_lat", "spin_creepage_1_per_m",
)  # fmt: skip
DIFFERENCE_KEYS = tuple(f"diff_{k}" for k in TOLERANCES)

COLUMNS = (
    "step", "lateral_shift_m", "yaw_rad", "roll_rad", "pitch_rate_rad_per_s", "vertical_position_m",
    "rolling_radius_difference_m", "side", "patch", "combination", "contact_y_rail_m", "contact_z_rail_m",
    "deepest_y_rail_m", "contact_y_wheel_m", "contact_angle_rad", "rolling_radius_m", "approach_m", "is_elliptic",
    "normal_force_N", "creep_force_long_N", "creep_force_lat_N", "spin_moment_Nm", "semi_axis_long_m",
    "semi_axis_lat_m", "max_pressure_Pa", "contact_area_m2", "creepage_long", "creepage_lat", "spin_creepage_1_per_m",
    "vertical_load_N", "status", "grid_error_estimate",
    *(f"contact_{k}" for k in REFERENCE_KEYS), *DIFFERENCE_KEYS,
)  # fmt: skip


@cache
def contact_reference() -> dict[int, dict]:
    """CONTACT's A-2.2 right-wheel solution by step (0-based), in SI units and wheelrail's conventions."""
    out = {}
    with REFERENCE_CSV.open(encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            step = int(row["case"]) - 1
            f = {k: float(v) for k, v in row.items() if k != "case"}
            out.setdefault(step, {
                "lateral_shift_m": f["y_ws_mm"] * 1e-3,
                "yaw_rad": f["yaw_ws_rad"],
                "roll_rad": f["roll_ws_rad"],
                "pitch_rate_rad_per_s": f["vpitch_ws_rad_per_s"],
                "n_patches": int(f["n_patches"]),
                "patches": [],
            })  # fmt: skip
            out[step]["patches"].append({
                "normal_force_N": f["fn_N"],
                "creep_force_long_N": -f["fx_N"],
                "creep_force_lat_N": f["fs_N"],
                "max_pressure_Pa": f["pmax_N_per_mm2"] * 1e6,
                "contact_area_m2": f["contact_area_mm2"] * 1e-6,
                "contact_y_rail_m": f["ycp_rail_mm"] * 1e-3,
                "contact_angle_rad": -f["deltcp_tr_rad"],
                "approach_m": f["approach_mm"] * 1e-3,
                "creepage_long": -f["cksi"],
                "creepage_lat": f["ceta"],
                "spin_creepage_1_per_m": f["cphi_1_per_mm"] * 1e3,
            })  # fmt: skip
    return out


def a22_case(step: int, kinematics: str = "equilibrium") -> WheelsetCase:
    """The WheelsetCase of step k (shift k x 0.5 mm, yaw k x 1.2 mrad).

    ``kinematics = "deck"`` prescribes CONTACT's roll and pitch rate of that step (per-wheel equilibrium);
    ``"equilibrium"`` (the default here) leaves them to the solver.
    """
    if kinematics not in KINEMATICS:
        raise ValueError(f"kinematics = {kinematics!r}: expected one of {', '.join(KINEMATICS)}")
    case = WheelsetCase(
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
    if kinematics == "deck":
        ref = contact_reference()[step]
        case = dataclasses.replace(
            case, roll_rad=ref["roll_rad"], pitch_rate_rad_per_s=ref["pitch_rate_rad_per_s"],
            profile_smoothing_m=DECK_PROFILE_SMOOTHING_M,
        )  # fmt: skip
    return case


def _value(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return int(v)
    return v


def _differences(row: dict, ref: dict) -> dict:
    mu_fn = MATERIAL.friction_coefficient * ref["normal_force_N"]
    return {
        "diff_normal_force": row["normal_force_N"] / ref["normal_force_N"] - 1.0,
        "diff_creep_force_long": (row["creep_force_long_N"] - ref["creep_force_long_N"]) / mu_fn,
        "diff_creep_force_lat": (row["creep_force_lat_N"] - ref["creep_force_lat_N"]) / mu_fn,
        "diff_max_pressure": row["max_pressure_Pa"] / ref["max_pressure_Pa"] - 1.0,
        "diff_contact_area": row["contact_area_m2"] / ref["contact_area_m2"] - 1.0,
        "diff_contact_y_rail": row["contact_y_rail_m"] - ref["contact_y_rail_m"],
    }


def default_model_options(method: str) -> dict | None:
    """CONTACT's grid for the bem rung (0.2 mm elements aligned with the reference point); None otherwise."""
    return {"element_size_m": CONTACT_ELEMENT_SIZE_M} if method == "bem" else None


def sweep(
    method: str = "bem",
    steps=STEPS,
    model_options=None,
    kinematics: str = "deck",
    sides=None,
    material=None,
    track_distance_m: float = 0.0,
    patch_options: dict | None = None,
    creepage_point: str | None = None,
) -> list[dict]:
    """Solve the A-2.2 steps; one dict per patch (keys ``COLUMNS``), CONTACT's values on the right wheel.

    ``material``: the pair's material (None: the deck's, :data:`MATERIAL`; another friction law for the friction
    variants of the deck); ``track_distance_m``: the wheelset's position along the track (CONTACT's S_WS);
    ``patch_options``: the case's patch options (A_SEP, D_SEP, D_COMB of another deck; None: the defaults);
    ``creepage_point``: the wheelset case's option of that name (None: its default).
    """
    track = build_track(a22_case(0, kinematics))
    rows = []
    options = {"model": default_model_options(method) if model_options is None else model_options}
    if sides is not None:
        options["sides"] = tuple(sides)
    if patch_options is not None:
        options["patch"] = dict(patch_options)
    if creepage_point is not None:
        options["creepage_point"] = creepage_point
    reference = contact_reference()
    for step in steps:
        case = dataclasses.replace(a22_case(step, kinematics), track_distance_m=track_distance_m)
        sol = solve_wheelset_case(case, material or MATERIAL, method, options, track=track)
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
        ref = reference.get(step)
        n_right = sum(p.side == "right" for p in sol.patches)
        for p in sol.patches:
            g, r, c = p.geometry, p.result, p.creepage
            row = {
                "step": step,
                "lateral_shift_m": case.lateral_shift_m,
                "yaw_rad": case.yaw_rad,
                "roll_rad": sol.roll_rad,
                "pitch_rate_rad_per_s": -sol.spin_rate_rad_per_s,
                "vertical_position_m": sol.wheel_vertical_position_m.get(p.side, sol.vertical_position_m),
                "rolling_radius_difference_m": delta_r,
                "side": p.side,
                "patch": counters[p.side],
                "combination": p.combination,
                "contact_y_rail_m": g.contact_point_rail_m[0],
                "contact_z_rail_m": g.contact_point_rail_m[1],
                "deepest_y_rail_m": p.deepest_point_rail_m[0],
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
                "contact_area_m2": r.contact_area_m2,
                "creepage_long": c.longitudinal,
                "creepage_lat": c.lateral,
                "spin_creepage_1_per_m": c.spin_1_per_m,
                "vertical_load_N": sol.wheel_vertical_load_N.get(p.side, math.nan),
                "status": sol.status if sol.success else f"{sol.status}: {sol.message}",
                # the model's own estimate of its discretisation error (bem: largest relative; else None)
                "grid_error_estimate": r.extra.get("grid_error_estimate"),
            }
            matched = (
                p.side == "right" and ref is not None and n_right == ref["n_patches"]
                and counters["right"] < len(ref["patches"])
            )  # fmt: skip
            for key in REFERENCE_KEYS:
                row[f"contact_{key}"] = ref["patches"][counters["right"]][key] if matched else None
            diffs = _differences(row, ref["patches"][counters["right"]]) if matched else {}
            for key in DIFFERENCE_KEYS:
                row[key] = diffs.get(key)
            rows.append(row)
            counters[p.side] += 1
    return rows


def _atomic_text(path: Path, text: str) -> None:
    from rigid_dynamics.files import write_text

    write_text(path, text)


def write_table(rows: list[dict], path: Path) -> Path:
    """CSV with the ``COLUMNS`` header, SI units as in the column names (written atomically)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _value(row[k]) for k in COLUMNS})
    _atomic_text(path, buffer.getvalue())
    return path


def write_plots(rows: list[dict], out_dir: Path, method: str = "") -> list[Path]:
    """The PNG plots (matplotlib, imported here), CONTACT's right-wheel values as black crosses."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = []
    style = {"left": ("tab:blue", "o"), "right": ("tab:red", "s")}
    reference = contact_reference()
    steps = sorted({r["step"] for r in rows})

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

    def overlay(ax, key, scale):
        x, y = [], []
        for s in steps:
            for patch in reference.get(s, {"patches": []})["patches"]:
                x.append(1e3 * reference[s]["lateral_shift_m"])
                y.append(scale * patch[key])
        if x:
            ax.plot(x, y, "x", color="k", ms=8, label="CONTACT, right wheel")

    def panel(ax, key, scale, ylabel):
        for side, x, y in by_side(key, scale):
            color, marker = style[side]
            ax.plot(x, y, marker, color=color, label=f"{side} wheel ({method})", ls="none", mfc="none")
        overlay(ax, key, scale)
        ax.set_xlabel("lateral shift [mm] (yaw = 2.4 mrad/mm)")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)

    for key, scale, ylabel, name, title in (
        ("contact_y_rail_m", 1e3, "contact reference point on rail, y_rail [mm] (gauge side < 0)",
         "contact_position.png", "Contact position on the rail"),
        ("contact_angle_rad", 180 / math.pi, "contact angle [deg] (towards the track centre > 0)", "contact_angle.png",
         "Contact angle"),
    ):  # fmt: skip
        fig, ax = plt.subplots(figsize=(7, 4.5))
        panel(ax, key, scale, ylabel)
        ax.set_title(f"Manchester A-2.2: {title}")
        save(fig, name)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    first = [next(r for r in rows if r["step"] == s) for s in steps]
    ax.plot([1e3 * r["lateral_shift_m"] for r in first], [1e3 * r["rolling_radius_difference_m"] for r in first], "k.-")
    ax.set_xlabel("lateral shift [mm]")
    ax.set_ylabel("rolling radius difference r_right - r_left [mm]")
    ax.set_title("Manchester A-2.2: rolling radius difference (main patch of each wheel)")
    ax.grid(alpha=0.3)
    save(fig, "rolling_radius_difference.png")

    fig, axes = plt.subplots(1, 3, figsize=(16, 4.5))
    for ax, key, label in zip(
        axes,
        ("normal_force_N", "creep_force_long_N", "creep_force_lat_N"),
        ("normal force N [kN]", "longitudinal creep force F_x [kN]", "lateral creep force F_y [kN]"),
        strict=True,
    ):
        panel(ax, key, 1e-3, label)
    fig.suptitle("Manchester A-2.2: forces on the wheels (contact frame; each marker one patch)")
    save(fig, "forces.png")

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    panel(axes[0], "max_pressure_Pa", 1e-6, "max pressure [MPa]")
    panel(axes[1], "contact_area_m2", 1e6, "contact area [mm^2]")
    fig.suptitle("Manchester A-2.2: max pressure and contact area")
    save(fig, "pressure_area.png")
    return out


def compare_summary(rows: list[dict]) -> dict:
    """Largest differences to CONTACT over the right wheel's matched patches, and the steps whose patch count
    differs from CONTACT's; ``within_tolerance`` when every difference is inside ``TOLERANCES``.
    """
    reference = contact_reference()
    steps = sorted({r["step"] for r in rows})
    count_mismatch = [
        s for s in steps if s in reference
        and sum(r["side"] == "right" and r["step"] == s for r in rows) != reference[s]["n_patches"]
    ]  # fmt: skip
    largest = {}
    for key in TOLERANCES:
        values = [(abs(r[f"diff_{key}"]), r["step"]) for r in rows if r[f"diff_{key}"] is not None]
        if values:
            value, step = max(values)
            largest[key] = {"value": value, "step": step, "tolerance": TOLERANCES[key]}
    compared = bool(largest)
    within = compared and not count_mismatch and all(v["value"] <= v["tolerance"] for v in largest.values())
    return {"largest_difference": largest, "patch_count_mismatch_steps": count_mismatch, "within_tolerance": within}


def run_manchester_a22(
    out_dir, method: str = "bem", steps=STEPS, plots: bool = True, kinematics: str = "deck", model_options=None
) -> dict:
    """Run the sweep and write table, summary and plots into ``out_dir`` (created if missing).

    Returns:
        The summary dict (also written as ``manchester_a22_summary.json``): method, kinematics, steps, first step
        with flange contact (contact angle > 0.7 rad), the comparison with CONTACT (:func:`compare_summary`),
        whether every step converged, the files written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = sweep(method, steps, model_options=model_options, kinematics=kinematics)
    files = [write_table(rows, out / "manchester_a22.csv")]
    if plots:
        files += write_plots(rows, out, method)
    flange_steps = sorted({r["step"] for r in rows if r["side"] == "right" and r["contact_angle_rad"] > 0.7})
    roll_error = max(
        (
            abs(r["roll_rad"] - contact_reference()[r["step"]]["roll_rad"])
            for r in rows
            if r["step"] in contact_reference()
        ),
        default=math.nan,
    )
    summary = {
        "case": "Manchester Contact Benchmark A-2.2",
        "reference": "CONTACT (Vollebregt & Kalker), examples/mbench_a22_right: comparisons/data/contact_reference",
        "method": method,
        "kinematics": kinematics,
        "steps": list(steps),
        "patches": len(rows),
        "first_flange_contact_shift_m": flange_steps[0] * SHIFT_STEP_M if flange_steps else None,
        "max_roll_difference_to_contact_rad": roll_error,
        "contact_comparison": compare_summary(rows),
        "all_converged": all(r["status"] == "ok" for r in rows),
        "files": [p.name for p in files],
    }
    summary_path = out / "manchester_a22_summary.json"
    _atomic_text(summary_path, json.dumps(summary, indent=2) + "\n")
    summary["files"].append(summary_path.name)
    return summary
