"""Maps of the surface fields of a solved contact patch (any model that returns ``ContactResult.fields``).

matplotlib is imported inside the function (Agg backend, no display needed).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rigid_dynamics.contact.types import ContactResult


def _edges(centres: np.ndarray) -> np.ndarray:
    """Cell edges of a (possibly non-uniform) 1-D grid of centres."""
    c = np.asarray(centres, float)
    if c.size == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])


def plot_contact_fields(result: ContactResult, path: str | Path | None = None, *, title: str | None = None):
    """Write a PNG with the pressure, tangential traction and slip/adhesion maps of ``result``.

    Panels (contact frame, x rolling to the right, y lateral up, mm):

    * pressure p (MPa) with the contact outline;
    * traction magnitude |t| (MPa) with arrows of (t_x, t_y) on the wheel, if the model gives tractions;
    * slip velocity |s| (mm/s) with the adhesion (stick) area hatched, if the model gives slip or masks.

    Missing fields are skipped (a normal-only model gives the pressure panel alone).

    Args:
        result: a solved patch with ``fields`` set.
        path: output file (PNG); parent directories are created. None returns the Figure (shown inline in a
            notebook) instead.
        title: figure title (default: method, forces).

    Returns:
        The path written, or the matplotlib Figure when ``path`` is None.

    Raises:
        ValueError: ``result.fields`` is None.
    """
    if result.fields is None:
        raise ValueError(f"result.fields is None for method {result.method!r}: expected surface fields to plot")
    from matplotlib.figure import Figure  # no pyplot: the caller's backend (a notebook's inline one) is left alone

    f = result.fields
    x_mm, y_mm = 1e3 * np.asarray(f.x_m), 1e3 * np.asarray(f.y_m)
    xe, ye = _edges(x_mm), _edges(y_mm)
    p = np.asarray(f.pressure_Pa, float)
    contact = np.asarray(f.in_contact, bool) if f.in_contact is not None else p > 0
    has_traction = f.traction_long_Pa is not None and f.traction_lat_Pa is not None
    has_slip = f.slip_m_per_s is not None or f.in_slip is not None
    panels = 1 + int(has_traction) + int(has_slip)
    span_x = xe[-1] - xe[0]
    span_y = ye[-1] - ye[0]
    width = 4.2 * panels
    height = max(2.6, min(6.0, 4.2 * span_y / max(span_x, 1e-12))) + 1.0
    fig = Figure(figsize=(width, height))
    axes = fig.subplots(1, panels, squeeze=False)[0]

    def outline(ax):
        if contact.any() and contact.shape[0] > 1 and contact.shape[1] > 1:
            ax.contour(x_mm, y_mm, contact.astype(float), levels=[0.5], colors="k", linewidths=0.8)

    ax = axes[0]
    mesh = ax.pcolormesh(xe, ye, np.ma.masked_where(p <= 0, p) / 1e6, cmap="viridis", shading="flat")
    fig.colorbar(mesh, ax=ax, label="pressure [MPa]", shrink=0.85)
    outline(ax)
    ax.set_title("pressure")
    k = 1
    if has_traction:
        tx, ty = np.asarray(f.traction_long_Pa, float), np.asarray(f.traction_lat_Pa, float)
        mag = np.hypot(tx, ty)
        ax = axes[k]
        k += 1
        mesh = ax.pcolormesh(xe, ye, np.ma.masked_where(~contact, mag) / 1e6, cmap="magma", shading="flat")
        fig.colorbar(mesh, ax=ax, label="|traction| [MPa]", shrink=0.85)
        step_x = max(1, x_mm.size // 16)
        step_y = max(1, y_mm.size // 12)
        xx, yy = np.meshgrid(x_mm, y_mm)
        sel = (slice(None, None, step_y), slice(None, None, step_x))
        if mag.max() > 0:
            ax.quiver(xx[sel], yy[sel], tx[sel], ty[sel], color="w", scale=mag.max() * 20, width=0.004)
        outline(ax)
        ax.set_title("traction on the wheel")
    if has_slip:
        ax = axes[k]
        slip = np.asarray(f.slip_m_per_s, float) if f.slip_m_per_s is not None else np.zeros_like(p)
        in_slip = np.asarray(f.in_slip, bool) if f.in_slip is not None else slip > 0
        mesh = ax.pcolormesh(xe, ye, np.ma.masked_where(~contact, slip) * 1e3, cmap="cividis", shading="flat")
        fig.colorbar(mesh, ax=ax, label="slip velocity [mm/s]", shrink=0.85)
        stick = contact & ~in_slip
        if stick.any() and stick.shape[0] > 1 and stick.shape[1] > 1:
            ax.contourf(x_mm, y_mm, stick.astype(float), levels=[0.5, 1.5], colors="none", hatches=["//"])
            ax.contour(x_mm, y_mm, stick.astype(float), levels=[0.5], colors="r", linewidths=0.8)
        outline(ax)
        ax.set_title("slip (adhesion hatched)")
    for ax in axes:
        ax.set_xlabel("x (rolling) [mm]")
        ax.set_ylabel("y (lateral) [mm]")
        ax.set_aspect("equal" if 0.1 < span_y / max(span_x, 1e-12) < 10 else "auto")
    if title is None:
        parts = [f"{result.method}: F_N = {result.normal_force_N / 1e3:.2f} kN"]
        if result.creep_force_long_N is not None and result.creep_force_lat_N is not None:
            parts.append(f"F_x = {result.creep_force_long_N / 1e3:.2f} kN")
            parts.append(f"F_y = {result.creep_force_lat_N / 1e3:.2f} kN")
        if result.max_pressure_Pa is not None:
            parts.append(f"p_max = {result.max_pressure_Pa / 1e6:.0f} MPa")
        title = ", ".join(parts)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path is None:
        return fig
    from rigid_dynamics.files import save_figure

    return save_figure(fig, path, dpi=110)  # atomic: a killed run leaves no half PNG under the final name
