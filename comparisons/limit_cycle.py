"""Nonlinear critical speed: the lowest speed at which a hunting limit cycle exists (continuation over speed).

Above the linear critical speed the centred wheelset is unstable and its lateral oscillation grows until a
nonlinearity (flange contact, creep saturation) bounds it: a limit cycle. The cycle can persist below the linear
critical speed (a subcritical Hopf bifurcation, typical of worn profiles), so the speed that matters in service
is the lowest one at which the cycle survives. A bisection on the growth rate of small oscillations finds the
linear speed and fails on the cycle (its growth rate is 0 at every speed above the bifurcation); this search
follows the cycle instead:

1. run at ``high_speed_m_per_s`` from a large lateral disturbance until the oscillation settles;
2. lower the speed step by step, each run starting on the oscillation of the previous one (its lateral
   position, yaw and their rates at the sample of its last third nearest the track centre), i.e. on the cycle;
3. the cycle is present when the lateral amplitude over the last third of a run exceeds ``threshold_m`` and does
   not decay (amplitude of the last sixth >= ``persist_ratio`` x that of the sixth before; a large oscillation
   that decays slowly is run on from its last state before it is judged); the first speed
   without it brackets the critical speed with the last one with it; bisection refines the bracket, each trial
   again started from the cycle at the bracket's upper end.

Returns the speed, the amplitude against speed (the upper branch of the bifurcation diagram) and every run.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

PERSIST_RATIO = 0.9
"""Default of ``limit_cycle_search``'s ``persist_ratio``: a run whose amplitude ratio (last sixth / sixth before)
is below it is decaying."""


def cycle_amplitude(result) -> tuple[float, float]:
    """(amplitude, persistence) of y(t): max |y - mean| over the last third; ratio last sixth / sixth before."""
    y = result.states[:, 1]
    n = len(y)
    if n < 12:
        return math.nan, math.nan
    third = y[-(n // 3) :]
    amplitude = float(np.max(np.abs(third - third.mean())))
    last, before = y[-(n // 6) :], y[-(n // 3) : -(n // 6)]
    a_last = float(np.max(np.abs(last - third.mean())))
    a_before = float(np.max(np.abs(before - third.mean())))
    return amplitude, (a_last / a_before if a_before > 0 else math.nan)


def _start_from(scene, result):
    """The scene started on the oscillation of ``result``: the state of its last third closest to the track
    centre (lateral and yaw position and rates; simulate() sets z and roll to static equilibrium, which needs
    both wheels on their rails, so a point near y = 0 of the cycle is taken rather than the flange-contact end).
    """
    states = result.states[-max(len(result.states) // 3, 1) :]
    s = states[int(np.argmin(np.abs(states[:, 1])))]
    initial = replace(
        scene.initial,
        lateral_displacement_m=float(s[1]),
        yaw_rad=float(s[3]),
        lateral_velocity_m_per_s=float(s[7]),
        yaw_rate_rad_per_s=float(s[9]),
    )
    return replace(scene, initial=initial)


def limit_cycle_search(
    scene,
    high_speed_m_per_s: float,
    low_speed_m_per_s: float,
    *,
    speed_steps: int = 6,
    duration_s: float = 2.0,
    disturbance_m: float = 0.006,
    threshold_m: float = 1e-3,
    persist_ratio: float = PERSIST_RATIO,
    bisections: int = 3,
    extensions: int = 2,
    simulate=None,
    progress=None,
) -> dict:
    """Follow the hunting limit cycle down in speed (module docstring).

    Args:
        scene: the base scene (its speed, duration and initial conditions are replaced).
        high_speed_m_per_s: start speed, where the cycle should exist (e.g. 1.2 x the linear critical speed).
        low_speed_m_per_s: lowest speed tried.
        speed_steps: continuation steps between the two speeds.
        duration_s: simulated time per run, s (long enough for several oscillation periods).
        disturbance_m: initial lateral displacement of the first run, m.
        threshold_m: smallest lateral amplitude counted as a cycle, m. The answer depends on it where the
            oscillation shrinks continuously with speed (S1002/UIC60 keeps sub-millimetre oscillations well below
            the speed where the flange-contact cycle collapses), so it is reported with the result.
        persist_ratio: a run whose amplitude ratio (last sixth / sixth before) is below this is decaying.
        bisections: refinements of the bracket.
        extensions: a run whose oscillation is still large but decaying slowly (ratio in [0.5, persist_ratio))
            is continued from its last state up to this many times before it counts as decaying.
        simulate: the simulate function (default rigid_dynamics.wheelset.simulate).
        progress: called with one line of text after each run (speed, amplitude, verdict), or None.

    Returns:
        dict: ``success``, ``status`` ("ok", "no-cycle-at-start", "cycle-down-to-low-speed", "run-failed"),
        ``message``, ``speed_m_per_s`` (lowest speed with the cycle, None if not found), ``bracket_m_per_s``,
        ``branch`` (speed, amplitude_m) of the cycle, ``runs`` (speed, amplitude_m, persistence, status).
    """
    if simulate is None:
        from rigid_dynamics.wheelset import simulate
    if not (0 < low_speed_m_per_s < high_speed_m_per_s):
        raise ValueError(
            f"speeds {low_speed_m_per_s!r}, {high_speed_m_per_s!r}: expected 0 < low_speed_m_per_s < high_speed_m_per_s"
        )
    runs, branch = [], []

    def usable(result) -> bool:
        # a run ending in "warning" (its force error estimate above the scene's tolerance: peak forces not
        # converged, e.g. flange impacts) still gives the lateral amplitude the search needs; it is recorded
        return result.success or result.status == "warning"

    def run(base, speed):
        result = simulate(replace(base, speed_m_per_s=float(speed), duration_s=duration_s))
        amplitude, persistence = cycle_amplitude(result) if usable(result) else (math.nan, math.nan)
        for _ in range(extensions):  # a slow decay of a large oscillation: run on from where it stopped
            if not (usable(result) and amplitude > threshold_m and 0.5 <= persistence < persist_ratio):
                break
            result = simulate(replace(_start_from(base, result), speed_m_per_s=float(speed), duration_s=duration_s))
            amplitude, persistence = cycle_amplitude(result) if usable(result) else (math.nan, math.nan)
        cycle = usable(result) and amplitude > threshold_m and persistence >= persist_ratio
        runs.append(
            {
                "speed_m_per_s": float(speed),
                "amplitude_m": amplitude,
                "persistence": persistence,
                "cycle": bool(cycle),
                "status": result.status,
                "message": result.message,
            }
        )
        if progress is not None:
            progress(
                f"run {len(runs)} at {speed:.4g} m/s: amplitude {amplitude * 1e3:.3g} mm, persistence "
                f"{persistence:.3g}: {'limit cycle' if cycle else 'decays / none'} ({result.status})"
            )
        return result, cycle

    first = replace(scene, initial=replace(scene.initial, lateral_displacement_m=disturbance_m))
    result, cycle = run(first, high_speed_m_per_s)
    if not usable(result):
        return _outcome(False, "run-failed", f"run at {high_speed_m_per_s:.4g} m/s: {result.message}", None, runs)
    if not cycle:
        message = (
            f"no limit cycle at {high_speed_m_per_s:.4g} m/s (amplitude {runs[-1]['amplitude_m']:.3g} m, "
            f"ratio {runs[-1]['persistence']:.3g}): start higher or disturb more"
        )
        return _outcome(False, "no-cycle-at-start", message, None, runs)
    branch.append((high_speed_m_per_s, runs[-1]["amplitude_m"]))
    on_cycle, upper = result, high_speed_m_per_s
    lower = None
    for speed in np.linspace(high_speed_m_per_s, low_speed_m_per_s, speed_steps + 1)[1:]:
        trial, cycle = run(_start_from(scene, on_cycle), speed)
        if not usable(trial):
            return _outcome(False, "run-failed", f"run at {speed:.4g} m/s: {trial.message}", None, runs, branch)
        if not cycle:
            lower = float(speed)
            break
        on_cycle, upper = trial, float(speed)
        branch.append((upper, runs[-1]["amplitude_m"]))
    if lower is None:
        message = f"the limit cycle persists down to {low_speed_m_per_s:.4g} m/s: lower low_speed_m_per_s"
        return _outcome(False, "cycle-down-to-low-speed", message, None, runs, branch)
    for _ in range(bisections):
        middle = 0.5 * (lower + upper)
        trial, cycle = run(_start_from(scene, on_cycle), middle)
        if cycle:
            on_cycle, upper = trial, middle
            branch.append((upper, runs[-1]["amplitude_m"]))
        else:
            lower = middle
    message = (
        f"limit cycle (amplitude > {threshold_m * 1e3:.3g} mm) down to {upper:.4g} m/s (amplitude "
        f"{branch[-1][1] * 1e3:.3g} mm), none at {lower:.4g} m/s; {len(runs)} runs"
    )
    warned = sum(r["status"] == "warning" for r in runs)
    if warned:
        message += f" ({warned} ended in warning: force error above tolerance, amplitudes used, peaks not converged)"
    return _outcome(True, "ok", message, upper, runs, branch, (lower, upper))


def _outcome(success, status, message, speed, runs, branch=(), bracket=None) -> dict:
    return {
        "success": success,
        "status": status,
        "message": message,
        "speed_m_per_s": speed,
        "bracket_m_per_s": list(bracket) if bracket else None,
        "branch": [{"speed_m_per_s": s, "amplitude_m": a} for s, a in sorted(branch)],
        "runs": runs,
    }


def plot_branch(outcome: dict, path, linear_speed_m_per_s: float | None = None, persist_ratio: float | None = None):
    """PNG of the cycle amplitude against speed (the runs with and without a cycle, the linear speed).

    Each run is labelled with its persistence ratio (the amplitude of the last sixth over the sixth before), the
    number that decided "limit cycle" or "decays": a run with a large amplitude drawn as "decays" is one whose
    oscillation was still shrinking. Runs without a usable amplitude (a failed run: NaN) are drawn on the axis
    as "no amplitude", not dropped.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.2))
    ax = fig.subplots()
    runs = outcome["runs"]
    finite = [r["amplitude_m"] for r in runs if math.isfinite(r["amplitude_m"])]
    for cycle, style, label in ((True, "o", "limit cycle"), (False, "x", "decays / none")):
        pts = [(r["speed_m_per_s"], r["amplitude_m"], r["persistence"]) for r in runs if r["cycle"] == cycle]
        pts = [p for p in pts if math.isfinite(p[1])]
        if pts:
            speeds, amps, ratios = zip(*pts, strict=True)
            ax.plot(speeds, np.array(amps) * 1e3, style, label=label)
            for v, a, ratio in pts:
                if math.isfinite(ratio):
                    ax.annotate(f"{ratio:.2f}", (v, a * 1e3), fontsize=6, xytext=(3, 3), textcoords="offset points")
    missing = [r["speed_m_per_s"] for r in runs if not math.isfinite(r["amplitude_m"])]
    if missing:
        ax.plot(missing, np.zeros(len(missing)), "s", mfc="none", color="tab:red", label="no amplitude (failed run)")
    if outcome["branch"]:
        ax.plot(
            [b["speed_m_per_s"] for b in outcome["branch"]], [b["amplitude_m"] * 1e3 for b in outcome["branch"]], "C0-"
        )
    if outcome["speed_m_per_s"]:
        ax.axvline(outcome["speed_m_per_s"], color="C0", ls="--", label="nonlinear critical speed")
    if linear_speed_m_per_s:
        ax.axvline(linear_speed_m_per_s, color="C3", ls=":", label="linear critical speed")
    ax.set_xlabel("speed [m/s]")
    ax.set_ylabel("lateral amplitude over the last third [mm]")
    rule = f" (a cycle: ratio >= {persist_ratio:g})" if persist_ratio else ""
    ax.set_title(f"numbers: persistence ratio, last sixth / sixth before{rule}", fontsize=8)
    if finite:
        ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    from rigid_dynamics.files import save_figure

    return save_figure(fig, path, dpi=110, bbox_inches="tight")  # atomic
