"""Stress sweep of a suspended conical wheelset (comparisons.stress), recorded in benchmarks/results.

Base: conical wheels (lambda 0.05, rail heads R 50 mm), k_x = k_y = 0.5 MN/m per side, Hertz + Vermeulen-Johnson,
speeds through the linear critical speed (rigid_dynamics.wheelset.linear), 0.5 s per run. Writes
benchmarks/results/dynamics_stress.csv/.json/.png.

Run: ``.venv/bin/python benchmarks/stress_dynamics.py``.
"""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from comparisons.dynamics_plots import plot_stress  # noqa: E402
from comparisons.stress import stress_sweep, write_records  # noqa: E402
from rigid_dynamics.wheelset import (  # noqa: E402
    DynamicsScene,
    InitialConditions,
    SuspensionParameters,
    TrackGeometry,
    critical_speed,
    linear_model_for_scene,
)
from rigid_dynamics.wheelset.linear import creep_coefficients  # noqa: E402


def main():
    base = DynamicsScene(
        name="stress-conical",
        track=TrackGeometry(conicity=0.05, rail_head_radius_m=0.05),
        suspension=SuspensionParameters(longitudinal_stiffness_N_per_m=5e5, lateral_stiffness_N_per_m=5e5),
        contact_model="vermeulen-johnson",
        speed_m_per_s=40.0,
        duration_s=0.5,
        initial=InitialConditions(lateral_displacement_m=0.002),
    )
    v_c = critical_speed(linear_model_for_scene(base, *creep_coefficients(base))).speed_m_per_s
    sweeps = {
        "fixed_step_s": (1e-4, 5e-4, 1e-3, 2e-3, 5e-3),
        "relative_tolerance": (1e-3, 1e-5, 1e-7, 1e-9),
        "speed_m_per_s": tuple(round(v_c * f, 3) for f in (0.5, 0.9, 1.1, 1.3, 2.0)),
        "friction_coefficient": (0.02, 0.1, 0.3, 0.6),
        "shear_modulus_Pa": (8.2e9, 8.2e10, 8.2e11),
    }
    records = stress_sweep(base, sweeps, max_wall_time_s=120.0)
    out = ROOT / "benchmarks" / "results"
    write_records(records, out, stem="dynamics_stress")
    plot_stress(records, out / "dynamics_stress.png")
    print(f"linear critical speed {v_c:.2f} m/s")
    for r in records:
        print(
            f"{r['parameter']:>22} {r['value']:<12.4g} {r['status']:<15} "
            f"energy {r['energy_balance_relative'] or 0:.2e} "
            f"force ratio {r['max_force_ratio'] or 0:.3g} |y|max {r['max_abs_lateral_displacement_m'] or 0:.3g} "
            f"wall {r['wall_time_s']:.2f} s"
        )


if __name__ == "__main__":
    main()
