"""The BEM's grid-error estimate against the actual error, and the cost of meeting ``grid_tolerance`` by default.

Part 1, the named quadric cases (``comparisons/cases``): the model ``bem`` at its defaults (grid refined from
40 x 40 until the estimate meets ``grid_tolerance`` = 2 %) and on the former default 40 x 40 grid (named, not
refined): final grid, largest relative estimate, the creep-force / max-pressure / area estimates and actual errors
against independent references (max pressure and area: Hertz's closed form, the normal problem of these
quasi-identical quadric cases being Hertz's; creep forces: the case's reference, the BEM limits of 40/80/160
elements with their uncertainty of 0.3-1.2 %; the large-spin case also against its converged F_y/(mu F_N) = -0.6254 from
benchmarks/results/bem_rolling_coarse.md and CONTACT's -0.6215 quoted in issue 27), wall time (best of 3).

The column "vs CONTACT": the creep force against CONTACT's exact theory run here on the same cases (decks written for
this project, 44/88/176 elements; its limit by first-order Richardson of its two finest grids, the extrapolation
step as its uncertainty: comparisons/data/contact_quadric_creep/SOURCE.md).

Part 1b, the linear range against Kalker's exact theory (independent of our BEM): the quadric of the named creep
cases (R 0.46 / 0.30 m, 10 kN) with one small creepage each (xi = 1e-5, eta = 1e-5, phi = 0.01 1/m: F near
0.01 mu F_N, where the exact theory lies within about 0.4 % of its linear limit), against F = -G a b C11 xi,
-G a b C22 eta, -G (ab)^1.5 C23 phi with Kalker's C_ij (Kalker 1990, Table E.3; rigid_dynamics.contact.kalker).
The large-spin case's creep force at CONTACT's own 44 x 44 grid (examples/fastsim.inp, DX 0.4 mm, DY 0.2 mm,
CONTACT's -0.6074 in fastsim.ref_out) and the creep-lat-spin case's bracket (the two slip points at 320 x 320, which
converge from opposite sides) are printed below the table.

Part 2, Manchester A-2.2 (kinematics "deck", right wheel) at CONTACT's 0.2 mm elements (option element_size_m):
our estimate against the actual difference to CONTACT's finest run of the same step (benchmarks/results/
contact_grid.md: 0.025 mm for the flange, 0.05 mm for the tread and the flange root).

Run: ``.venv/bin/python benchmarks/bench_bem_grid_error.py`` -> benchmarks/results/bem_grid_error.json and .md.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import tomllib  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rigid_dynamics.contact.bem.model import BemModel, hertz_ellipse  # noqa: E402
from rigid_dynamics.contact.types import ContactGeometry, Creepage  # noqa: E402
from rigid_dynamics.files import write_text  # noqa: E402
from rigid_dynamics.materials import Material  # noqa: E402

CASES = (
    "hertz-ab-1",
    "hertz-ab-0.1",
    "hertz-ab-10",
    "creep-long-small",
    "creep-long-mid",
    "creep-long-saturated",
    "creep-lat-spin",
    "creep-spin-only",
    "large-spin",
)
LARGE_SPIN = {"converged": -0.6254, "CONTACT": -0.6215}
CONTACT_44 = -0.6074  # CONTACT's examples/fastsim.ref_out, case 1 (exact theory on 44 x 44, DX 0.4 mm, DY 0.2 mm)
LINEAR = (("linear-xi", (1e-5, 0.0, 0.0)), ("linear-eta", (0.0, 1e-5, 0.0)), ("linear-phi", (0.0, 0.0, 0.01)))
# contact_grid.md: CONTACT's step (our a22_case(step - 1)) -> (case, DX mm, FN, FX, FS, PMAX MPa, area mm2)
CONTACT_FINEST = {
    6: ("a22-tread", 0.05, 9787.0, -456.2, -2900.0, 730.6, 20.24),
    11: ("a22-flange-root", 0.05, 9619.0, -762.5, -2738.0, 1572.0, 14.96),
    17: ("a22-flange", 0.025, 12730.0, -2073.0, -3194.0, 2597.0, 7.428),
}


def _case(name):
    folder = ROOT / "comparisons" / "cases" / name
    case = tomllib.loads((folder / "case.toml").read_text())
    ref = tomllib.loads((folder / "reference.toml").read_text())["reference"]
    m, g, k = case["material"], case["geometry"], case["kinematics"]
    material = Material(m["shear_modulus_Pa"], m["poisson_ratio"], m["friction_coefficient"])
    geometry = ContactGeometry.quadric(g["radius_long_m"], g["radius_lat_m"])
    creepage = Creepage(k["creepage_long"], k["creepage_lat"], k["spin_creepage_1_per_m"], k["rolling_speed_m_per_s"])
    return geometry, creepage, material, case["loading"]["normal_force_N"], ref


def _timed(fn, repeats=3):
    best, result = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return result, best


CONTACT_RUNS = ROOT / "comparisons" / "data" / "contact_quadric_creep" / "quadric_creep.csv"


def _contact_limit(name):
    """CONTACT's limit (F_x, F_y) and its uncertainty (N) from its two finest grids (first-order Richardson; the
    extrapolation step as uncertainty; comparisons/data/contact_quadric_creep/SOURCE.md), or None."""
    import csv

    with CONTACT_RUNS.open() as handle:
        rows = sorted((r for r in csv.DictReader(handle) if r["case"] == name), key=lambda r: int(r["mx"]))
    if len(rows) < 2:
        return None
    coarse, fine = rows[-2], rows[-1]
    ratio = int(fine["mx"]) / int(coarse["mx"])
    limit, step = [], []
    for key in ("fx_N", "fy_N"):
        v_f, v_c = float(fine[key]), float(coarse[key])
        limit.append(v_f + (v_f - v_c) / (ratio - 1))
        step.append(abs(v_f - v_c) / (ratio - 1))
    return limit, math.hypot(*step), [int(r["mx"]) for r in rows]


def _quadric_row(name, options):
    geometry, creepage, material, force, ref = _case(name)
    e_star = material.shear_modulus_Pa / (1 - material.poisson_ratio)
    curvatures = (geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m)
    a, b, p0, *_ = hertz_ellipse(*curvatures, e_star, normal_force_N=force)  # the normal problem is Hertz's
    res, wall = _timed(lambda: BemModel().solve(geometry, creepage, material, normal_force_N=force, options=options))
    mu_fn = material.friction_coefficient * force
    ref_fx, ref_fy = ref.get("creep_force_long_N", 0.0), ref.get("creep_force_lat_N", 0.0)
    scale = max(math.hypot(ref_fx, ref_fy), 0.01 * mu_fn)
    grid = res.extra["grid_error"]
    row = {
        "case": name,
        "options": options,
        "status": res.status,
        "grid": f"{res.extra['nx']}x{res.extra['ny']}",
        "refinements": grid["refinements"],
        "wall_s": wall,
        "estimate_largest": grid.get("largest_relative"),
        "estimate": grid.get("relative"),
        "error": {
            "creep_force_N": math.hypot(res.creep_force_long_N - ref_fx, res.creep_force_lat_N - ref_fy) / scale,
            "max_pressure_Pa": abs(res.max_pressure_Pa / p0 - 1),
            "contact_area_m2": abs(res.contact_area_m2 / (math.pi * a * b) - 1),
        },
    }
    contact = _contact_limit(name)
    if contact is not None:
        (c_fx, c_fy), unc, grids = contact
        c_scale = max(math.hypot(c_fx, c_fy), 0.01 * mu_fn)
        row["contact_limit_N"] = [c_fx, c_fy]
        row["contact_grids"] = grids
        row["contact_uncertainty"] = unc / c_scale
        row["error_vs_contact"] = math.hypot(res.creep_force_long_N - c_fx, res.creep_force_lat_N - c_fy) / c_scale
    if name == "large-spin":
        ratio = res.creep_force_lat_N / mu_fn
        row["fy_over_mu_fn"] = ratio
        row["error_vs"] = {k: abs(ratio / v - 1) for k, v in LARGE_SPIN.items()}
    return row


def _linear_row(name, creepages, options):
    from rigid_dynamics.contact.kalker import kalker_coefficients

    material = Material(82e9, 0.28, 0.3)
    geometry = ContactGeometry.quadric(0.46, 0.30)
    force = 1e4
    e_star = material.shear_modulus_Pa / (1 - material.poisson_ratio)
    curvatures = (geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m)
    a, b, *_ = hertz_ellipse(*curvatures, e_star, normal_force_N=force)
    c = kalker_coefficients(a / b, material.poisson_ratio)
    xi, eta, phi = creepages
    g = material.shear_modulus_Pa
    ref_fx = -g * a * b * float(c.c11) * xi
    ref_fy = -g * a * b * float(c.c22) * eta - g * (a * b) ** 1.5 * float(c.c23) * phi
    creepage = Creepage(xi, eta, phi, 10.0)
    res, wall = _timed(lambda: BemModel().solve(geometry, creepage, material, normal_force_N=force, options=options))
    scale = max(math.hypot(ref_fx, ref_fy), 0.01 * material.friction_coefficient * force)
    grid = res.extra["grid_error"]
    return {
        "case": name,
        "options": options,
        "status": res.status,
        "grid": f"{res.extra['nx']}x{res.extra['ny']}",
        "refinements": grid["refinements"],
        "wall_s": wall,
        "estimate_largest": grid.get("largest_relative"),
        "estimate": grid.get("relative"),
        "kalker_force_N": [ref_fx, ref_fy],
        "error": {
            "creep_force_N": math.hypot(res.creep_force_long_N - ref_fx, res.creep_force_lat_N - ref_fy) / scale,
            "max_pressure_Pa": None,
            "contact_area_m2": None,
        },
    }


def _contact_grid_spin():
    """The large-spin case on CONTACT's 44 x 44 grid (margin 1.1) and creep-lat-spin's two-slip-point bracket."""
    geometry, creepage, material, force, _ = _case("large-spin")
    res = BemModel().solve(geometry, creepage, material, normal_force_N=force, options={"nx": 44, "ny": 44,
                                                                                        "margin": 1.1})  # fmt: skip
    spin = {
        "fy_over_mu_fn": res.creep_force_lat_N / (material.friction_coefficient * force),
        "estimate": res.extra["grid_error"]["relative"]["creep_force_N"],
        "dx_m": res.extra["dx_m"],
        "dy_m": res.extra["dy_m"],
    }
    geometry, creepage, material, force, _ = _case("creep-lat-spin")
    bracket = {}
    for point in ("centre", "midpoint"):
        opts = {"nx": 320, "ny": 320, "rolling_slip_point": point, "estimate_grid_error": False}
        bracket[point] = (
            BemModel().solve(geometry, creepage, material, normal_force_N=force, options=opts).creep_force_lat_N
        )
    default = BemModel().solve(geometry, creepage, material, normal_force_N=force)
    return spin, {**bracket, "default": default.creep_force_lat_N, "default_grid": default.extra["nx"],
                  "default_estimate": default.extra["grid_error"]["relative"]["creep_force_N"]}  # fmt: skip


def _a22_rows():
    from comparisons.manchester import MATERIAL, a22_case
    from rigid_dynamics.contact.wheelset_case import solve_wheelset_case

    rows = []
    for step, (name, dx_mm, fn, fx, fs, pmax, area) in CONTACT_FINEST.items():
        options = {"model": {"element_size_m": 0.2e-3}, "sides": ("right",)}
        sol, wall = _timed(
            lambda step=step, options=options: solve_wheelset_case(
                a22_case(step - 1, "deck"), MATERIAL, "bem", options
            ),
            repeats=1,
        )
        (patch,) = [p.result for p in sol.patches if p.side == "right"]
        grid = patch.extra["grid_error"]
        mu_fn = MATERIAL.friction_coefficient * fn
        # forces on the rail in CONTACT's table; ours act on the wheel: compare magnitudes of the tangential force
        ft_ours, ft_contact = math.hypot(patch.creep_force_long_N, patch.creep_force_lat_N), math.hypot(fx, fs)
        rows.append({
            "step": step,
            "case": name,
            "contact_finest_dx_mm": dx_mm,
            "status": patch.status,
            "grid": f"{patch.extra['nx']}x{patch.extra['ny']}",
            "wall_s": wall,
            "estimate": grid.get("relative"),
            "difference_to_contact_finest": {
                "normal_force_N": abs(patch.normal_force_N / fn - 1),
                "creep_force_N": abs(ft_ours - ft_contact) / max(ft_contact, 0.01 * mu_fn),
                "max_pressure_Pa": abs(patch.max_pressure_Pa / (pmax * 1e6) - 1),
                "contact_area_m2": abs(patch.contact_area_m2 / (area * 1e-6) - 1),
            },
        })  # fmt: skip
    return rows


def _pct(value):
    return "-" if value is None else f"{100 * value:.2f} %"


def main():
    quadric = []
    for name in CASES:
        quadric.append(_quadric_row(name, {}))
        quadric.append(_quadric_row(name, {"nx": 40, "ny": 40}))
    for name, creepages in LINEAR:
        quadric.append(_linear_row(name, creepages, {}))
        quadric.append(_linear_row(name, creepages, {"nx": 40, "ny": 40}))
    spin44, bracket = _contact_grid_spin()
    a22 = _a22_rows()
    machine = {
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_at_end": [round(v, 2) for v in os.getloadavg()],
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    out = ROOT / "benchmarks" / "results"
    write_text(
        out / "bem_grid_error.json",
        json.dumps(
            {
                "machine": machine,
                "quadric": quadric,
                "large_spin_44": spin44,
                "creep_lat_spin_bracket": bracket,
                "a22": a22,
            },
            indent=2,
        ),
    )
    lines = [
        "# The BEM's grid-error estimate and the cost of the default grid (benchmarks/bench_bem_grid_error.py)",
        "",
        __doc__.split("\n\n")[1].replace("\n", " "),
        "",
        __doc__.split("\n\n")[2].replace("\n", " "),
        "",
        __doc__.split("\n\n")[3].replace("\n", " "),
        "",
        f"Machine: {machine['platform']}, {machine['cpu_count']} CPUs, one thread, Python {machine['python']}; "
        f"load average at end {machine['load_average_at_end']} (shared machine); {machine['date_utc']} UTC. "
        "Each cell: estimate / actual error. Wall time best of 3 (NORM + TANG on the grid and its companions).",
        "",
        "| case | options | status | grid | creep force est. / err. | creep force err. vs CONTACT (its unc.) | "
        "max pressure est. / err. | area est. / err. | wall ms |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in quadric:
        est = r["estimate"] or {}
        cells = [
            r["case"],
            "default" if not r["options"] else "nx = ny = 40",
            r["status"],
            f"{r['grid']} ({r['refinements']} ref.)",
        ]
        for key in ("creep_force_N", "max_pressure_Pa", "contact_area_m2"):
            cells.append(f"{_pct(est.get(key))} / {_pct(r['error'][key])}")
            if key == "creep_force_N":
                cells.append(
                    f"{_pct(r['error_vs_contact'])} ({_pct(r['contact_uncertainty'])})"
                    if "error_vs_contact" in r
                    else "-"
                )
        cells.append(f"{1e3 * r['wall_s']:.0f}")
        lines.append("| " + " | ".join(cells) + " |")
    spin = [r for r in quadric if r["case"] == "large-spin"]
    lines += [""] + [
        f"Large-spin F_y/(mu F_N) with {'the defaults' if not r['options'] else '40 x 40'}: {r['fy_over_mu_fn']:.4f}, "
        f"{_pct(r['error_vs']['converged'])} from the converged -0.6254, {_pct(r['error_vs']['CONTACT'])} from "
        "CONTACT's -0.6215."
        for r in spin
    ]
    lo, hi = sorted((abs(bracket["centre"]), abs(bracket["midpoint"])))
    spin_limit = _contact_limit("large-spin")[0][1] / (0.3 * 82000.0)
    lat_limit = _contact_limit("creep-lat-spin")[0][1]
    lines += [
        f"Large-spin on CONTACT's 44 x 44 grid (DX {1e3 * spin44['dx_m']:.2f} mm, DY {1e3 * spin44['dy_m']:.2f} mm): "
        f"ours {spin44['fy_over_mu_fn']:.4f}, CONTACT's {CONTACT_44} (CONTACT takes the rolling slip elsewhere in "
        f"the element); our estimate there {_pct(spin44['estimate'])}; against CONTACT's limit {spin_limit:.4f} "
        f"(-0.6209 on 176 x 176, extrapolated) CONTACT's own error at that grid is "
        f"{_pct(abs(CONTACT_44 / spin_limit - 1))}, ours {_pct(abs(spin44['fy_over_mu_fn'] / spin_limit - 1))}.",
        f"creep-lat-spin at 320 x 320: F_y {bracket['centre']:.2f} N (element centre), {bracket['midpoint']:.2f} N "
        f"(midpoint); the two slip points converge from opposite sides, so the limit lies in [{-hi:.1f}, {-lo:.1f}] N; "
        f"CONTACT's limit {lat_limit:.1f} N lies inside, the named reference -322.93 N (Richardson of 40/80/160, "
        f"stated uncertainty 0.28 %) outside. The default: {bracket['default']:.2f} N on {bracket['default_grid']} x "
        f"{bracket['default_grid']}, estimate {_pct(bracket['default_estimate'])}, "
        f"{_pct(abs(bracket['default'] / lat_limit - 1))} from CONTACT's limit.",
    ]
    default_ms = sum(r["wall_s"] for r in quadric if not r["options"])
    fixed_ms = sum(r["wall_s"] for r in quadric if r["options"])
    lines += [
        "",
        f"Cost: the twelve cases at the defaults take {1e3 * default_ms:.0f} ms in all against {1e3 * fixed_ms:.0f} ms "
        f"on the 40 x 40 grid with its companions ({default_ms / fixed_ms:.1f}x).",
        "",
        "## Manchester A-2.2 at CONTACT's 0.2 mm elements (right wheel, deck kinematics)",
        "",
        "Each cell: our estimate / our difference to CONTACT's finest run of the step (the two codes agree within "
        "0.5 % at equal elements except the flange root's max pressure, 3 %: contact_grid.md).",
        "",
        "| step | case | status | grid | normal force | creep force | max pressure | area | wall s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in a22:
        est, diff = r["estimate"] or {}, r["difference_to_contact_finest"]
        cells = [str(r["step"]), r["case"], r["status"], r["grid"]]
        for key in ("normal_force_N", "creep_force_N", "max_pressure_Pa", "contact_area_m2"):
            cells.append(f"{_pct(est.get(key))} / {_pct(diff[key])}")
        cells.append(f"{r['wall_s']:.2f}")
        lines.append("| " + " | ".join(cells) + " |")
    write_text(out / "bem_grid_error.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
