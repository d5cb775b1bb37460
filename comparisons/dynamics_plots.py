"""Plots of a wheelset dynamics run (matplotlib, imported inside the functions).

:func:`plot_dynamics` (and :func:`plot_simulation`, the CLI's entry) draws four panels against the travelled
distance x - x(0): lateral displacement y (mm),
yaw psi (mrad), the normal force of each wheel (kN), and the creep forces of each wheel (kN, longitudinal and
lateral, contact frame, on the wheel). A failed run is plotted up to its last good sample with its status in
the title. :func:`plot_stress` draws the records of comparisons.stress (energy balance and force ratio per
parameter value, failed runs marked).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def _save(fig, path: str | Path) -> Path:
    """Save a figure as PNG atomically (temporary name in the same folder, then os.replace)."""
    path = Path(path)
    if path.suffix.lower() != ".png":
        path = path.with_suffix(".png")
    from rigid_dynamics.files import save_figure

    return save_figure(fig, path, dpi=120)


def plot_dynamics(result, path: str | Path | None = None, *, title: str | None = None):
    """Lateral displacement, yaw, normal and creep forces of both wheels vs distance.

    Args:
        result: a rigid_dynamics.wheelset.SimulationResult.
        path: PNG file to write (atomically); None returns the matplotlib Figure instead.
        title: figure title (default: scene name, status, provider and model).

    Returns:
        The path written, or the Figure when ``path`` is None.
    """
    import matplotlib

    if path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    states = result.states
    distance = states[:, 0] - states[0, 0] if len(states) else np.zeros(0)
    fig, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    axes[0].plot(distance, 1e3 * states[:, 1], color="k")
    axes[0].set_ylabel("lateral y (mm)")
    axes[1].plot(distance, 1e3 * states[:, 3], color="k")
    axes[1].set_ylabel("yaw (mrad)")
    colors = {"left": "tab:blue", "right": "tab:red"}
    patches = result.patches
    for i, side in enumerate(("left", "right")):
        normal = np.nansum(patches["normal_force_N"][:, i, :], axis=1) if len(states) else np.zeros(0)
        axes[2].plot(distance, 1e-3 * normal, color=colors[side], label=side)
        long_ = np.nansum(patches["creep_force_long_N"][:, i, :], axis=1) if len(states) else np.zeros(0)
        lat = np.nansum(patches["creep_force_lat_N"][:, i, :], axis=1) if len(states) else np.zeros(0)
        axes[3].plot(distance, 1e-3 * long_, color=colors[side], label=f"{side} longitudinal")
        axes[3].plot(distance, 1e-3 * lat, color=colors[side], linestyle="--", label=f"{side} lateral")
    axes[2].set_ylabel("normal force (kN)")
    axes[3].set_ylabel("creep force (kN)")
    axes[3].set_xlabel("distance travelled (m)")
    axes[2].legend(loc="best", fontsize=8)
    axes[3].legend(loc="best", fontsize=7, ncol=2)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    scene_name = getattr(result.scene, "name", "") if result.scene is not None else ""
    fig.suptitle(
        title or f"{scene_name}: {result.status} ({result.provider}, {result.contact_model}, {result.method})",
        fontsize=10,
    )
    fig.tight_layout()
    if path is None:
        return fig
    try:
        return _save(fig, path)
    finally:
        plt.close(fig)


def plot_simulation(result, out_dir: str | Path) -> list[Path]:
    """The plots of a run into ``out_dir`` (used by ``wheelrail run``): ``dynamics.png`` (plot_dynamics)."""
    return [plot_dynamics(result, Path(out_dir) / "dynamics.png")]


def plot_stress(records: list[dict], path: str | Path | None = None):
    """Energy balance and largest force ratio of stress records, one column per swept parameter.

    Failed runs (success False) are drawn as red crosses at their last recorded values.

    Returns:
        The path written, or the Figure when ``path`` is None.
    """
    import matplotlib

    if path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    from comparisons.style import label_of

    parameters = list(dict.fromkeys(r["parameter"] for r in records))
    fig, axes = plt.subplots(2, max(len(parameters), 1), figsize=(3.2 * max(len(parameters), 1), 6), squeeze=False)
    for j, name in enumerate(parameters):
        rows = [r for r in records if r["parameter"] == name and r["value"] is not None]
        xlabel, xscale = label_of(name)
        for i, key in enumerate(("energy_balance_relative", "max_force_ratio")):
            ax = axes[i, j]
            kinds = (("ok", "o", "k"), ("warning", "^", "tab:orange"), ("stopped", "x", "tab:red"))
            for kind, marker, color in kinds:
                pts = [
                    (r["value"] * xscale, r[key])
                    for r in rows
                    if r[key] is not None
                    and math.isfinite(r[key])
                    and (r["status"] if r["status"] in ("ok", "warning") else "stopped") == kind
                ]
                if pts:
                    xs, ys = zip(*pts, strict=True)
                    ax.plot(xs, ys, marker, color=color, label=kind)
            missing = [r["value"] * xscale for r in rows if r[key] is None or not math.isfinite(r[key])]
            if missing:  # no number (a run stopped before it): drawn on the axis, not dropped
                ax.plot(missing, [0.0 if key != "energy_balance_relative" else 1e-16] * len(missing), "s",
                        mfc="none", color="tab:red", label="no value")  # fmt: skip
            ax.set_xscale("log" if all((r["value"] or 0) > 0 for r in rows) else "linear")
            if key == "energy_balance_relative":
                ax.set_yscale("log")
                ax.yaxis.set_minor_formatter(NullFormatter())
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel(xlabel)
            ax.set_ylabel(label_of(key)[0])
            ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    if path is None:
        return fig
    try:
        return _save(fig, path)
    finally:
        plt.close(fig)
