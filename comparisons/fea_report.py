"""FEA vs BEM vs Hertz on a non-Hertzian wheel-rail patch (Manchester benchmark profiles).

The wheelset case (``rigid_dynamics.contact.wheelset_case``) places the Manchester Contact Benchmark
profiles (S1002 wheel, UIC60 rail inclined 1:40; Shackleton & Iwnicki, VSD 46 (2008) 129-149) at a
lateral shift, finds the equilibrium under a wheel load with Hertz's theory and samples the
undeformed distance h(x, y) of each patch. Every patch is then solved, under the same normal force
(its Hertz share of the wheel load), by

* ``bem``: half-space boundary elements (Kalker's NORM), and
* ``fea`` (rigid): FEniCSx, an elastic block with the combined modulus against the same sampled gap
  (fea.model; half-space-equivalent, so both solve the same problem), and
* ``fea`` (profiles): FEniCSx, two elastic bodies, local rail and wheel sections meshed from the real
  profiles around the search's contact points (finite bodies, yaw neglected).

Metrics on the BEM grid (cells of equal area; the FEA pressure interpolated bilinearly onto it):

* force-weighted pressure difference  D_p = sum |p_fea - p_bem| / sum p_bem  (dimensionless)
* contact-area difference              D_A = (A_fea - A_bem) / A_bem  (areas as the models report them)
* outline mismatch                     D_O = area(C_fea XOR C_bem) / A_bem  on the grid masks

Writes ``fea_report.json``, ``fea_report.md``, ``fea_vs_bem_<side>_<k>.png`` and the FEA's own
VTU/PNG files (``fea_<side>_<k>/``) into the output folder. Under ``mpiexec -n N`` the FEA runs in
parallel and rank 0 writes the report files.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from comparisons.stated_errors import stated_errors
from rigid_dynamics.files import save_figure, write_text
from rigid_dynamics.materials import STEEL, Material

DEFAULT_FEA_OPTIONS = {"elements_per_semi_axis": 8}
DEFAULT_BEM_OPTIONS = {"nx": 40, "ny": 40}


def compare_fields(bem_fields, fea_fields) -> dict:
    """Pressure and outline differences of two ContactFields, on the BEM grid (see the module docstring)."""
    from scipy.interpolate import RegularGridInterpolator

    interp = RegularGridInterpolator(
        (fea_fields.y_m, fea_fields.x_m), fea_fields.pressure_Pa, bounds_error=False, fill_value=0.0
    )
    gx, gy = np.meshgrid(bem_fields.x_m, bem_fields.y_m)
    p_fea = interp(np.column_stack([gy.ravel(), gx.ravel()])).reshape(gx.shape)
    p_bem = bem_fields.pressure_Pa
    cell = float(np.diff(bem_fields.x_m).mean() * np.diff(bem_fields.y_m).mean())
    c_bem, c_fea = p_bem > 0, p_fea > 0
    a_bem = c_bem.sum() * cell
    return {
        "pressure_difference_force_weighted": float(np.abs(p_fea - p_bem).sum() / p_bem.sum()),
        "outline_mismatch": float((c_bem ^ c_fea).sum() * cell / a_bem) if a_bem > 0 else math.nan,
        "fea_pressure_on_bem_grid": p_fea,
    }


def run_fea_report(
    output_dir,
    *,
    lateral_shift_m: float = 6e-3,
    wheel_load_N: float = 5e4,
    wheel_profile: str = "MBench_S1002_v3",
    rail_profile: str = "MBench_UIC60_v3",
    material: Material = STEEL,
    sides: tuple[str, ...] = ("left", "right"),
    fea_options: Mapping | None = None,
    bem_options: Mapping | None = None,
) -> dict:
    """Solve the case, compare FEA, BEM and Hertz per patch and write the report (returns the summary).

    Args:
        output_dir: folder for the report files (created).
        lateral_shift_m: wheelset lateral shift towards the right rail, m (6 mm: the right wheel runs
            near its flange root, the left patch is wide and non-elliptic).
        wheel_load_N: vertical load per wheel, N.
        wheel_profile, rail_profile: built-in profile names or files.
        material: elastic constants (G, nu).
        sides: which wheels' patches to compare.
        fea_options, bem_options: options of the two models.
    """
    import dolfinx_solver  # noqa: F401
    from mpi4py import MPI

    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case

    comm = MPI.COMM_WORLD
    out = Path(output_dir)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    case = WheelsetCase(
        wheel_profile=wheel_profile,
        rail_profile=rail_profile,
        lateral_shift_m=lateral_shift_m,
        wheel_load_N=wheel_load_N,
    )
    started = time.perf_counter()
    # the search's patch (plane at the deepest point, midpoint of the two surfaces): the frame the FE sections of the
    # real profiles are cut in
    case_sol = solve_wheelset_case(
        case, material, "hertz", options={"patches": "search", "search": {"field": True}, "spin_rate": "nominal"}
    )
    summary = {
        "case": {
            "wheel_profile": wheel_profile,
            "rail_profile": rail_profile,
            "lateral_shift_m": lateral_shift_m,
            "wheel_load_N": wheel_load_N,
            "shear_modulus_Pa": material.shear_modulus_Pa,
            "poisson_ratio": material.poisson_ratio,
        },
        "equilibrium": {"status": case_sol.status, "message": case_sol.message},
        "fea_options": dict(fea_options or DEFAULT_FEA_OPTIONS),
        "bem_options": dict(bem_options or DEFAULT_BEM_OPTIONS),
        "patches": [],
        "mpi_ranks": comm.size,
    }
    bem, fea = get_model("bem"), get_model("fea")
    counter: dict[str, int] = {}
    for patch in case_sol.patches:
        if patch.side not in sides:
            continue
        k = counter.get(patch.side, 0)
        counter[patch.side] = k + 1
        tag = f"{patch.side}_{k}"
        force = float(patch.result.normal_force_N)
        t = time.perf_counter()
        r_bem = bem.solve(
            patch.geometry,
            patch.creepage,
            material,
            normal_force_N=force,
            options=dict(bem_options or DEFAULT_BEM_OPTIONS),
        )
        t_bem = time.perf_counter() - t
        options = {**dict(fea_options or DEFAULT_FEA_OPTIONS), "output_dir": str(out / f"fea_{tag}")}
        r_fea = fea.solve(patch.geometry, patch.creepage, material, normal_force_N=force, options=options)
        options_p = {
            **options,
            "formulation": "profiles",
            "wheel_profile": wheel_profile,
            "rail_profile": rail_profile,
            "output_dir": str(out / f"fea_profiles_{tag}"),
        }
        r_prof = fea.solve(patch.geometry, patch.creepage, material, normal_force_N=force, options=options_p)
        entry = {
            "side": patch.side,
            "index": k,
            "contact_angle_rad": float(patch.geometry.contact_angle_rad),
            "curvatures_1_per_m": [patch.geometry.curvature_long_1_per_m, patch.geometry.curvature_lat_1_per_m],
            "normal_force_N": force,
            "hertz": _numbers(patch.result),
            "bem": {**_numbers(r_bem), "wall_time_s": t_bem},
            "fea": {**_numbers(r_fea), "dofs": r_fea.extra.get("dofs"), "iterations": r_fea.iterations},
            "fea_profiles": {**_numbers(r_prof), "dofs": r_prof.extra.get("dofs"), "iterations": r_prof.iterations},
        }
        if r_bem.success and r_prof.success and r_prof.fields is not None:
            metrics_p = compare_fields(r_bem.fields, r_prof.fields)
            entry["profiles_pressure_difference_force_weighted"] = metrics_p["pressure_difference_force_weighted"]
            entry["profiles_outline_mismatch"] = metrics_p["outline_mismatch"]
            entry["profiles_contact_area_difference"] = r_prof.contact_area_m2 / r_bem.contact_area_m2 - 1.0
        if r_bem.success and r_fea.success and r_bem.fields is not None and r_fea.fields is not None:
            metrics = compare_fields(r_bem.fields, r_fea.fields)
            entry["pressure_difference_force_weighted"] = metrics["pressure_difference_force_weighted"]
            entry["outline_mismatch"] = metrics["outline_mismatch"]
            entry["contact_area_difference"] = r_fea.contact_area_m2 / r_bem.contact_area_m2 - 1.0
            entry["max_pressure_difference"] = r_fea.max_pressure_Pa / r_bem.max_pressure_Pa - 1.0
            if comm.rank == 0:
                entry["png"] = _plot(out / f"fea_vs_bem_{tag}.png", r_bem.fields, metrics["fea_pressure_on_bem_grid"])
        summary["patches"].append(entry)
    summary["wall_time_s"] = time.perf_counter() - started
    if comm.rank == 0:
        write_text(out / "fea_report.json", json.dumps(summary, indent=2, default=float))
        write_text(out / "fea_report.md", _markdown(summary))
    return summary


def _numbers(result) -> dict:
    return {
        "success": bool(result.success),
        "status": result.status,
        "normal_force_N": result.normal_force_N,
        "max_pressure_Pa": result.max_pressure_Pa,
        "contact_area_m2": result.contact_area_m2,
        "semi_axes_m": [result.semi_axis_long_m, result.semi_axis_lat_m],
        "wall_time_s": result.wall_time_s,
        "stated_errors": stated_errors(result),
    }


def _plot(path: Path, bem_fields, p_fea) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x, y = bem_fields.x_m * 1e3, bem_fields.y_m * 1e3
    p_bem = bem_fields.pressure_Pa / 1e6
    vmax = max(p_bem.max(), p_fea.max() / 1e6)
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), sharey=True)
    for ax, data, title in ((axes[0], p_bem, "BEM"), (axes[1], p_fea / 1e6, "FEA (on the BEM grid)")):
        m = ax.pcolormesh(x, y, data, shading="auto", vmin=0, vmax=vmax, cmap="viridis")
        ax.set_title(f"{title} pressure / MPa")
        fig.colorbar(m, ax=ax)
    diff = p_fea / 1e6 - p_bem
    lim = np.abs(diff).max() or 1.0
    m = axes[2].pcolormesh(x, y, diff, shading="auto", cmap="RdBu_r", vmin=-lim, vmax=lim)
    axes[2].set_title("FEA - BEM / MPa")
    fig.colorbar(m, ax=axes[2])
    for ax in axes:
        ax.set_xlabel("x (rolling) / mm")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (lateral) / mm")
    save_figure(fig, path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return str(path)


def _markdown(summary: dict) -> str:
    c = summary["case"]
    lines = [
        "# FEA vs BEM vs Hertz",
        "",
        f"Profiles {c['wheel_profile']} / {c['rail_profile']}, lateral shift {c['lateral_shift_m'] * 1e3:.1f} mm, "
        f"wheel load {c['wheel_load_N'] / 1e3:.1f} kN, G = {c['shear_modulus_Pa'] / 1e9:.0f} GPa, "
        f"nu = {c['poisson_ratio']}. Equilibrium: {summary['equilibrium']['status']}. "
        f"FEA options {summary['fea_options']}, BEM options {summary['bem_options']}, {summary['mpi_ranks']} rank(s).",
        "",
        "D_p = sum|p_fea - p_bem| / sum p_bem on the BEM grid; D_A = A_fea/A_bem - 1; "
        "D_O = outline mismatch area / A_bem.",
        "",
        "FEA = rigid-indenter block on the sampled gap; FEA-prof = two elastic bodies from the real profiles. "
        "`stated err`: the relative discretisation errors each FEA states (fea.refinement; `not stated` on one mesh).",
        "",
        "| patch | N / kN | p_max Hertz / BEM / FEA / FEA-prof (MPa) | area Hertz / BEM / FEA / FEA-prof (mm^2) "
        "| D_p FEA / prof | D_A FEA / prof | D_O FEA / prof | FEA / prof stated err p, area |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for p in summary["patches"]:

        def f(x, scale):
            return "-" if x is None else f"{x * scale:.0f}"

        def g(key, fmt, p=p):
            value = p.get(key)
            return "-" if value is None else format(value, fmt)

        lines.append(
            f"| {p['side']} {p['index']} | {p['normal_force_N'] / 1e3:.1f} | "
            f"{f(p['hertz']['max_pressure_Pa'], 1e-6)} / {f(p['bem']['max_pressure_Pa'], 1e-6)} / "
            f"{f(p['fea']['max_pressure_Pa'], 1e-6)} / {f(p['fea_profiles']['max_pressure_Pa'], 1e-6)} | "
            f"{f(p['hertz']['contact_area_m2'], 1e6)} / {f(p['bem']['contact_area_m2'], 1e6)} / "
            f"{f(p['fea']['contact_area_m2'], 1e6)} / {f(p['fea_profiles']['contact_area_m2'], 1e6)} | "
            f"{g('pressure_difference_force_weighted', '.3f')} / "
            f"{g('profiles_pressure_difference_force_weighted', '.3f')} | "
            f"{g('contact_area_difference', '+.3f')} / {g('profiles_contact_area_difference', '+.3f')} | "
            f"{g('outline_mismatch', '.3f')} / {g('profiles_outline_mismatch', '.3f')} | "
            f"{_stated(p['fea'])} / {_stated(p['fea_profiles'])} |"
        )
    return "\n".join(lines) + "\n"


def _stated(numbers: dict) -> str:
    """The FEA's stated relative errors of max pressure and area, or "not stated" (mesh_tolerance None)."""
    errors = numbers.get("stated_errors")
    if not errors:
        return "not stated"
    return ", ".join(
        "-" if errors.get(k) is None else f"{100 * errors[k]:.2g} %" for k in ("max_pressure", "contact_area")
    )


def main(argv=None) -> int:
    """``python -m comparisons.fea_report OUTPUT_DIR [--shift-mm 6] [--load-kN 50]`` (also under mpiexec)."""
    import argparse

    parser = argparse.ArgumentParser(description="FEA vs BEM vs Hertz on a Manchester-profile wheelset position")
    parser.add_argument("output_dir")
    parser.add_argument("--shift-mm", type=float, default=6.0)
    parser.add_argument("--load-kN", type=float, default=50.0)
    parser.add_argument("--elements-per-semi-axis", type=float, default=8.0)
    args = parser.parse_args(argv)
    run_fea_report(
        args.output_dir,
        lateral_shift_m=args.shift_mm * 1e-3,
        wheel_load_N=args.load_kN * 1e3,
        fea_options={"elements_per_semi_axis": args.elements_per_semi_axis},
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
