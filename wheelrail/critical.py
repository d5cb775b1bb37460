"""``wheelrail critical-speed SCENE``: linear (eigenvalue) and nonlinear (limit-cycle) critical speed of a scene.

Linear: the eigenvalues of the linearised wheelset (rigid_dynamics.wheelset.linear) with the creep coefficients of
the scene's contact model at its static load (the slopes at zero creepage of its creep forces,
rigid_dynamics.contact.sensitivities: Kalker's for the linear rung, the grid's for FASTSIM, KPEC and the BEM); the
conicity is the scene's (conical track) or, for real profiles,
the EN 15302 equivalent conicity at 3 mm amplitude (an estimate: the linear model of a profile pair is a cone).
Nonlinear: the lowest speed at which the hunting limit cycle survives, followed down in speed from
``--high`` (default 1.2 x the linear speed) by comparisons.limit_cycle.limit_cycle_search.
Writes ``summary.json`` and ``critical_speed.png`` (cycle amplitude against speed) into the output folder.
"""

from __future__ import annotations

import dataclasses
import math
import sys

from wheelrail.config import PHYSICAL_RANGES, ConfigError

MAX_SPEED_M_PER_S = PHYSICAL_RANGES["speed_m_per_s"][1]
MAX_STEPS = 1000
"""Continuation steps at most (each is a run of --duration: 1000 x 3 s is hours already)."""


def linear_critical_speed(scene) -> dict:
    """The linear critical speed of a scene: dict with speed, frequency, conicity used and how it was found."""
    from rigid_dynamics.wheelset import critical_speed, linear_model_for_scene
    from rigid_dynamics.wheelset.linear import creep_sensitivities_at_rest

    track = scene.track
    note = "conical track"
    proxy = scene
    conicity_problem = None
    if not track.is_conical:
        from rigid_dynamics.contact.conicity import equivalent_conicity_from_names
        from rigid_dynamics.geometry import load_profile

        table = equivalent_conicity_from_names(
            wheel_profile=load_profile(track.wheel_profile, "wheel"),
            rail_profile=load_profile(track.rail_profile, "rail"),
            gauge_m=track.gauge_m,
            gauge_height_m=track.gauge_height_m,
            flange_back_distance_m=track.flange_back_distance_m,
            nominal_radius_m=scene.wheelset.nominal_radius_m,
            rail_inclination_rad=track.rail_inclination_rad,
            amplitude_m=0.003,
        )
        conicity = table["equivalent_conicity"]
        if table["status"] != "ok":
            conicity_problem = f"the equivalent conicity is {table['status']}: {table['message']}"
        cone = dataclasses.replace(track, wheel_profile="conical", rail_profile="circular", conicity=conicity)
        proxy = dataclasses.replace(
            scene, track=cone, contact_provider="conical", irregularities=type(scene.irregularities)()
        )
        note = (
            f"cone of the EN 15302 equivalent conicity {conicity:.4f} (3 mm, +- "
            f"{100 * table['discretisation_error_estimate']:.2g} % from its table) of the profile pair"
        )
    try:
        sensitivities = creep_sensitivities_at_rest(proxy)
    except ValueError as exc:
        return {"success": False, "status": "no-creep-coefficients", "message": str(exc), "speed_m_per_s": None,
                "frequency_Hz": None, "conicity": proxy.track.conicity, "model": note}  # fmt: skip
    coef = [s.coefficients() for s in sensitivities]
    f11, f22 = float(sum(c.f11_N for c in coef) / len(coef)), float(sum(c.f22_N for c in coef) / len(coef))
    result = critical_speed(linear_model_for_scene(proxy, f11, f22))
    error = [max(float(s.error_estimate[row, row]) for s in sensitivities) for row in (0, 1)]  # dFx/dxi, dFy/deta
    status, message = result.status, result.message
    if conicity_problem is not None and status == "ok":  # a number from a conicity that is not ok is not ok
        status, message = "warning", f"{message}; {conicity_problem}"
    return {
        "success": status == "ok",
        "status": status,
        "message": message,
        "speed_m_per_s": result.speed_m_per_s if math.isfinite(result.speed_m_per_s) else None,
        "frequency_Hz": result.frequency_Hz if math.isfinite(result.frequency_Hz) else None,
        "conicity": proxy.track.conicity,
        "model": note,
        "creep_coefficients_N": [f11, f22],
        "creep_coefficients": {
            "rung": sensitivities[0].method,
            "kind": sensitivities[0].kind,
            "f11_difference_error_N": error[0],
            "f22_difference_error_N": error[1],
            "c11": [c.c11 for c in coef],
            "c22": [c.c22 for c in coef],
            "note": "slopes at zero creepage of the rung's creep forces at the static patch "
            "(rigid_dynamics.contact.sensitivities); the grid error of a grid rung is not in the difference error",
        },
    }


def cmd_critical_speed(args) -> int:
    """``wheelrail critical-speed``: print and write the linear and nonlinear critical speeds."""
    from comparisons.limit_cycle import PERSIST_RATIO, limit_cycle_search, plot_branch
    from wheelrail.output import copy_input, output_folder, write_json
    from wheelrail.overrides import load_scene_with

    scene, source, overrides = load_scene_with(args.scene, args.set)
    for name in ("high", "low", "duration", "threshold_mm"):
        value = getattr(args, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ConfigError(f"--{name.replace('_', '-')} {value!r}: expected a finite number > 0")
    if args.steps < 1:
        raise ConfigError(f"--steps {args.steps!r}: expected an integer >= 1")
    if scene.track.curved:  # the linear model and the limit cycle about the centred straight-track state
        raise ConfigError(
            f"key 'track.curve_direction' = {scene.track.curve_direction!r} (cant_m = {scene.track.cant_m!r}): "
            "expected a straight track without cant for critical-speed (the analyses are about the straight track's "
            "centred state)"
        )
    from wheelrail.config import check_physical_range

    for name, key in (("high", "speed_m_per_s"), ("low", "speed_m_per_s"), ("duration", "duration_s")):
        if getattr(args, name) is not None:
            check_physical_range(f"--{name}", getattr(args, name), key)
    if args.steps > MAX_STEPS:
        raise ConfigError(f"--steps {args.steps!r}: expected an integer from 1 to {MAX_STEPS}")
    if args.low is not None and args.high is not None and not args.low < args.high:
        raise ConfigError(f"--low {args.low!r}: expected a speed below --high {args.high!r}")
    from functools import partial

    from rigid_dynamics.wheelset import build_provider, simulate

    # the linear speed (quick, writes nothing) fixes the default range: a bad --low is refused before any file
    linear = linear_critical_speed(scene)
    v_lin = linear["speed_m_per_s"]
    high = args.high or min(1.2 * v_lin if v_lin else 2.0 * scene.speed_m_per_s, MAX_SPEED_M_PER_S)
    low = args.low or 0.4 * high
    if not low < high:
        given = "--low" if args.low is not None else "the default --low (0.4 x --high)"
        raise ConfigError(f"{given} {low!r}: expected a speed below --high {high!r} (1.2 x the linear speed)")
    try:
        provider = build_provider(scene)  # the contact geometry does not depend on the speed: build it once
    except ValueError as exc:
        raise ConfigError(f"scene {args.scene!r}: {exc}") from None

    with output_folder(args.out, f"critical-speed-{source.stem}") as out_dir:  # checked before the work
        copy_input(source, out_dir, "scene.toml")
        print(f"{source.stem}: linear critical speed {_speed(linear['speed_m_per_s'])} ({linear['model']})")
        nonlinear = limit_cycle_search(
            scene,
            high,
            low,
            duration_s=args.duration or 3.0,
            speed_steps=args.steps,
            threshold_m=1e-3 * args.threshold_mm,
            simulate=partial(simulate, provider=provider),
            progress=lambda text: print(f"critical-speed: {text}", file=sys.stderr, flush=True),
        )
        speed = _speed(nonlinear["speed_m_per_s"])
        print(f"{source.stem}: nonlinear critical speed {speed}: {nonlinear['message']}")
        png = plot_branch(nonlinear, out_dir / "critical_speed.png", v_lin, persist_ratio=PERSIST_RATIO)
        summary = {"linear": linear, "nonlinear": nonlinear, "overrides": overrides, "files": [png.name]}
        write_json(out_dir / "summary.json", summary)  # last
    print(f"output written to {out_dir}")
    return 0 if nonlinear["success"] and linear["success"] else 1


def _speed(value) -> str:
    return "not found" if value is None else f"{value:.4g} m/s ({value * 3.6:.4g} km/h)"


def register(sub) -> None:
    """Add the ``critical-speed`` sub-command to the CLI's sub-parsers."""
    from wheelrail.cli import out_path

    parser = sub.add_parser("critical-speed", help="linear and nonlinear (limit-cycle) critical speed of a scene")
    parser.add_argument("scene", help="embedded scene name or TOML file")
    parser.add_argument("--high", type=float, help="start speed of the limit-cycle search, m/s (default 1.2 x linear)")
    parser.add_argument("--low", type=float, help="lowest speed tried, m/s (default 0.4 x --high)")
    parser.add_argument("--steps", type=int, default=6, help="continuation steps from --high to --low (default 6)")
    parser.add_argument("--duration", type=float, help="simulated time per run, s (default 3)")
    parser.add_argument(
        "--threshold-mm", type=float, default=1.0, help="smallest lateral amplitude counted as a cycle, mm (default 1)"
    )
    parser.add_argument("--out", type=out_path, help="output folder")
    parser.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene key (repeatable)")
    parser.set_defaults(func=cmd_critical_speed)
