"""Coulomb friction in the FEA (fea/friction.py): time and error of the shift and rolling solvers.

Cases (Hertz circle: R = 0.3 m both ways, P = 10 kN, E 210 GPa, nu 0.3, mu 0.3, two equal bodies):

* Cattaneo-Mindlin shift at Q/(mu P) = 0.5, quarter block of 20 a, 6 and 9 elements per semi-axis; reference
  Johnson (1985) eqs 7.33/7.42 (stick radius c/a, shift delta).
* Steady rolling (transient shifts, step a/n), full block of 10 a, 4 elements per semi-axis: xi = 5e-5 against
  Kalker's linear theory (C11 from the project's table) and xi = 5e-4 against the BEM at its default grid
  tolerance (its stated error beside it).

Usage::

    .venv/bin/python benchmarks/bench_fea_friction.py   # writes benchmarks/results/fea_friction.json and .md
"""

from __future__ import annotations

import json
import math
import os
import platform
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
E_PA, NU, RADIUS_M, FORCE_N, MU = 210e9, 0.3, 0.3, 1e4, 0.3


def _normal(n: float, symmetry: str, domain_factor: float):
    import dolfinx_solver  # noqa: F401

    from fea.domain import hertz_block_domain
    from fea.hertz_reference import hertz_elliptic
    from fea.solver import solve_rigid_indenter
    from meshing.hertz import HertzBlockSpec

    e_star = E_PA / (2 * (1 - NU**2))
    ref = hertz_elliptic(0.5 / RADIUS_M, 0.5 / RADIUS_M, FORCE_N, e_star)
    a = ref.semi_axis_long_m
    domain = hertz_block_domain(HertzBlockSpec(a, a, n, domain_factor=domain_factor, symmetry=symmetry))
    normal = solve_rigid_indenter(
        domain,
        lambda x, y: (x * x + y * y) / (2 * RADIUS_M),
        e_star * (1 - NU**2),
        NU,
        normal_force_N=FORCE_N,
        initial_approach_m=ref.approach_m,
        length_scale_m=a,
    )
    return domain, normal, a, e_star * (1 - NU**2)


def shift_rows() -> list[dict]:
    from fea.friction import cattaneo_mindlin, solve_shift

    rows = []
    for n in (6.0, 9.0):
        t0 = time.process_time()
        domain, normal, a, e_block = _normal(n, "quarter", 20.0)
        q = 0.5 * MU * FORCE_N
        sol = solve_shift(domain, normal, e_block, NU, MU, tangential_force_N=q, length_scale_m=a)
        cpu = time.process_time() - t0
        ref = cattaneo_mindlin(q, FORCE_N, MU, a, e_block / (2 * (1 + NU)), NU)
        c_over_a = math.sqrt(sol.stick_area_m2(domain.symmetry_factor) / math.pi) / a
        rows.append(
            {
                "case": f"shift Q/(mu P) = 0.5, n = {n:g}",
                "status": sol.status,
                "dofs": sol.dofs,
                "cpu_s": cpu,
                "stick_radius_ratio": c_over_a,
                "stick_radius_ratio_ref": ref["stick_radius_ratio"],
                "shift_m": sol.shift_m[0],
                "shift_ref_m": ref["shift_m"],
                "shift_error": sol.shift_m[0] / ref["shift_m"] - 1.0,
            }
        )
    return rows


def rolling_rows() -> list[dict]:
    from fea.friction import solve_rolling
    from rigid_dynamics.contact.kalker import kalker_coefficients
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    rows = []
    n = 4.0
    domain, normal, a, e_block = _normal(n, "full", 10.0)
    g = E_PA / (2 * (1 + NU))
    for xi in (5e-5, 5e-4):
        t0 = time.process_time()
        sol = solve_rolling(
            domain, normal, e_block, NU, MU, (xi, 0.0, 0.0), step_m=a / n, patch_length_m=2 * a, length_scale_m=a
        )
        cpu = time.process_time() - t0
        if xi < 1e-4:
            ref, ref_name, ref_error = -g * a * a * float(kalker_coefficients(1.0, NU).c11) * xi, "Kalker C11", 0.0
        else:
            bem = get_model("bem").solve(
                ContactGeometry.quadric(RADIUS_M, RADIUS_M),
                Creepage(longitudinal=xi),
                Material.from_young(E_PA, NU, MU),
                normal_force_N=FORCE_N,
            )
            ref, ref_name = bem.creep_force_long_N, "BEM"
            ref_error = bem.extra["grid_error"]["relative"]["creep_force_N"]
        rows.append(
            {
                "case": f"rolling xi = {xi:g}, n = {n:g}",
                "status": sol.status,
                "dofs": sol.dofs,
                "steps": sol.steps,
                "cpu_s": cpu,
                "creep_force_N": sol.creep_force_N[0],
                "steady_error_N": sol.steady_error_N,
                "reference": ref_name,
                "reference_N": ref,
                "reference_relative_error": ref_error,
                "error": sol.creep_force_N[0] / ref - 1.0,
            }
        )
    return rows


def markdown(data: dict) -> str:
    lines = [
        "# FEA with Coulomb friction: time and error",
        "",
        f"Machine: {data['machine']}. CPU time of this process (the machine is shared).",
        "",
        "| case | status | DOFs | CPU s | c/a (ref) | shift error |",
        "| --- | --- | ---: | ---: | --- | ---: |",
    ]
    for r in data["shift"]:
        lines.append(
            f"| {r['case']} | {r['status']} | {r['dofs']} | {r['cpu_s']:.1f} | {r['stick_radius_ratio']:.3f} "
            f"({r['stick_radius_ratio_ref']:.3f}) | {100 * r['shift_error']:+.1f} % |"
        )
    lines += [
        "",
        "| case | status | DOFs | steps | CPU s | F_x on the wheel [N] | reference [N] | error |",
        "| --- | --- | ---: | ---: | ---: | ---: | --- | ---: |",
    ]
    for r in data["rolling"]:
        lines.append(
            f"| {r['case']} | {r['status']} | {r['dofs']} | {r['steps']} | {r['cpu_s']:.1f} | "
            f"{r['creep_force_N']:.1f} | {r['reference']} {r['reference_N']:.1f} "
            f"(+-{100 * r['reference_relative_error']:.1f} %) | {100 * r['error']:+.1f} % |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    from rigid_dynamics.files import write_text

    data = {
        "machine": f"{platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}",
        "shift": shift_rows(),
        "rolling": rolling_rows(),
    }
    write_text(OUT / "fea_friction.json", json.dumps(data, indent=1, default=float) + "\n")
    write_text(OUT / "fea_friction.md", markdown(data))
    print(markdown(data))


if __name__ == "__main__":
    main()
