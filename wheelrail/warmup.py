"""Compile the numba kernels once, at setup (``python -m wheelrail.warmup``; tools/setup_venv.sh runs it).

numba compiles a kernel on its first call and stores it in its on-disk cache (``__pycache__`` next to the
source), so every later process only loads it (about 0.1 s). Without this step the first compiled run on a
fresh machine spends a minute or more compiling, silently. Here each embedded scene runs for two steps (one
compilation of the loop serves every contact model: the model is a run-time code; ``auto`` and the callback are in
it), each contact model with numba kernels solves one small patch, and one wheelset case with an out-of-round
wheel and a measured wheel's spline compile the Python contact search's kernels, with a progress line per item on
stderr. The runs' numbers are not used.
"""

from __future__ import annotations

import dataclasses
import sys
import time


def warm_up_all(stream=sys.stderr) -> dict[str, float]:
    """Compile (or load) every numba kernel the embedded scenes and the contact models use; {item: seconds}."""
    from rigid_dynamics.materials import STEEL
    from rigid_dynamics.wheelset import simulate
    from wheelrail.cases import WARM_UP_OPTIONS, warm_up
    from wheelrail.scenes import embedded_scenes, load_scene

    timings = {}
    start_all = time.perf_counter()
    for method in WARM_UP_OPTIONS:
        print(f"setup: compiling the {method} contact kernels ...", file=stream, flush=True)
        timings[f"contact {method}"] = warm_up(method, STEEL)
    print("setup: compiling the batched Hertz / Kalker / linear / Vermeulen-Johnson loops ...", file=stream, flush=True)
    start = time.perf_counter()
    _warm_up_batches()
    timings["contact batches"] = time.perf_counter() - start
    print("setup: compiling the wheelset contact search kernels (round, out-of-round and measured wheels) ...",
          file=stream, flush=True)  # fmt: skip
    start = time.perf_counter()
    try:
        _warm_up_wheelset_search()
    except Exception as exc:  # never fail the setup: the first wheelset case then compiles them
        print(f"setup: warning: wheelset search not compiled ({type(exc).__name__}: {exc})", file=stream, flush=True)
    timings["wheelset search"] = time.perf_counter() - start
    for name, path in embedded_scenes().items():
        scene = load_scene(path)
        # every scene: scipy's methods call the same compiled right-hand side (with the given geometry of the
        # conical provider) as the compiled loop, whose one compilation serves RK4, DP54 and BS32 (the same types)
        step = scene.integrator.fixed_step_s
        short = dataclasses.replace(scene, duration_s=2 * step)
        print(f"setup: compiling the dynamics kernels of scene {name} (up to a minute) ...", file=stream, flush=True)
        start = time.perf_counter()
        try:
            simulate(short)
        except Exception as exc:  # never fail the setup: the scene then compiles on its first run
            print(f"setup: warning: scene {name} not compiled ({type(exc).__name__}: {exc})", file=stream, flush=True)
        timings[f"scene {name}"] = time.perf_counter() - start
    total = time.perf_counter() - start_all
    print(f"setup: numba kernels ready in {total:.0f} s (cached on disk for every later run)", file=stream, flush=True)
    return timings


def _warm_up_batches() -> None:
    """The compiled copies of the analytic models' loops (a one-patch solve runs them as Python, lazy_kernels.py)."""
    import numpy as np

    from rigid_dynamics.contact.hertz import hertz_solve_batch
    from rigid_dynamics.contact.lazy_kernels import PYTHON_BATCH_LIMIT
    from rigid_dynamics.contact.linear import linear_creep_forces
    from rigid_dynamics.contact.vermeulen_johnson import vermeulen_johnson_saturation

    n = PYTHON_BATCH_LIMIT + 1
    hertz = hertz_solve_batch(
        np.full(n, 2.0), np.full(n, 3.0), normal_force_N=1e4, shear_modulus_Pa=8e10, poisson_ratio=0.3
    )
    fx, fy, _ = linear_creep_forces(
        hertz.semi_axis_long_m, hertz.semi_axis_lat_m, 1e-3, 1e-3, 0.1, shear_modulus_Pa=8e10, poisson_ratio=0.3
    )
    vermeulen_johnson_saturation(fx, fy, hertz.normal_force_N, 0.3)


def _warm_up_wheelset_search() -> None:
    """The kernels that `wheelrail contact` on a wheelset case (``solve_case``, the Python contact search of
    contact.wheelset_patches) and a measured wheel's surface call from Python: the contact locus, the plane gap, the
    out-of-round wheel's locus (contact._patch_kernels) and the bicubic spline of a measured wheel
    (geometry._bicubic). The compiled dynamics loop has its own copies (compiled with the scenes); without this
    step the first wheelset case compiled these for about 30 s on the 2-core machine (2026-11-30), silently.
    """
    import numpy as np

    from rigid_dynamics.contact.track import build_track
    from rigid_dynamics.contact.wheelset_case import WheelsetCase, solve_wheelset_case
    from rigid_dynamics.geometry import HarmonicOutOfRoundness
    from rigid_dynamics.geometry.irregularities import MeasuredWheelIrregularity
    from rigid_dynamics.materials import STEEL

    case = WheelsetCase(wheel_profile="S1002", rail_profile="UIC60", rail_inclination_rad=0.025, wheel_load_N=8e4)
    track = build_track(case, wheel_irregularities={"right": (HarmonicOutOfRoundness(3, 3.0e-4),)})
    solve_wheelset_case(case, STEEL, "hertz", track=track)  # left wheel round, right wheel out of round
    angles = np.linspace(0.0, 6.0, 8)
    lateral = np.linspace(-0.05, 0.05, 6)
    MeasuredWheelIrregularity(angles, lateral, np.zeros((8, 6))).evaluate(np.array([0.1, 0.2]), np.array([0.0, 0.01]))


if __name__ == "__main__":
    warm_up_all()
