"""One named case through Hertz, FASTSIM, BEM and FEA side by side: maps, subsurface stresses and a report.

What is solved:

* every model on the whole case (a wheelset case: search, equilibrium, all patches) for the table of numbers,
  times and errors against the case's reference (as in :mod:`comparisons.bench`);
* the maps use each model's main patch on the reference side (the patch with the largest normal force). FEA is
  solved on the BEM's main patch geometry with the BEM's normal force (one patch, not the whole wheelset: the
  same problem for both, and minutes less), frictionless, refined to its default ``mesh_tolerance`` unless
  ``fea_options`` say otherwise; its numbers carry the error it states, and the report judges FEA against the BEM
  with both stated errors (comparisons.stated_errors; "not yet stated" where the BEM states none).

Pictures (PNG, matplotlib; one 3-D view with pyvista, off-screen):

* ``pressure.png``: pressure of every model on one colour scale, contact outlines (p > 0) drawn;
* ``pressure_difference.png``: p_model - p_BEM on the BEM grid (the BEM is the most exact rung with
  tractions; FEA's pressure is a filtered nodal field, see fea.model);
* ``fields-<model>.png``: traction and slip/adhesion maps (comparisons.contact_plots) of FASTSIM and BEM;
* ``subsurface.png``: von Mises stress and the orthogonal shear s_xd on the cut y = y_pmax (depth below the
  rail surface) and von Mises on the cut x = x_pmax, one colour scale per quantity, from (a) the half-space
  solution of the BEM pressure alone, (b) the half-space solution of the BEM pressure AND tangential tractions
  (rigid_dynamics.contact.subsurface: Boussinesq-Cerruti), (c) FEA (recovered nodal stresses) with the BEM's
  tangential tractions applied as a surface load on the rail block (frictionless where the BEM has none);
* ``subsurface_3d.png``: pyvista view of the von Mises field (b) below the patch.

Stresses are those of the rail (the body below the contact plane); the rail's surface tractions are the
pressure and minus the wheel's tangential tractions.
"""

from __future__ import annotations

import html
import math
import time
from pathlib import Path

import numpy as np

from comparisons.stated_errors import agreement, stated_errors

COMPARE_MODELS = ("hertz", "fastsim", "bem", "fea")
DEFAULT_OPTIONS = {"fastsim": {"nx": 40, "ny": 40}, "bem": {"nx": 64, "ny": 64}}
CUT_POINTS = (41, 25)  # along the surface, in depth


def _hertz_fields(result):
    """Hertz's pressure on a grid over its ellipse (the Hertz model's statement of the field)."""
    from rigid_dynamics.contact.types import ContactFields

    a, b, p0 = result.semi_axis_long_m, result.semi_axis_lat_m, result.max_pressure_Pa
    if not (a and b and p0):
        return None
    x = np.linspace(-1.15 * a, 1.15 * a, 93)
    y = np.linspace(-1.15 * b, 1.15 * b, 93)
    xx, yy = np.meshgrid(x, y)
    p = p0 * np.sqrt(np.clip(1 - (xx / a) ** 2 - (yy / b) ** 2, 0, None))
    return ContactFields(x_m=x, y_m=y, pressure_Pa=p, in_contact=p > 0)


def _main_patch(patches, side):
    on_side = [p for p in patches if p[0] == side]
    if not on_side:
        return None
    return max(on_side, key=lambda p: p[3].normal_force_N or 0.0)


def _resolution(model, options, main) -> str:
    """The grid or mesh of a rung's solution, for the report: FASTSIM's elements per strip x strips, the BEM's
    elements and element size (from its pressure field), Hertz none (FEA: set from its result in run_compare).
    """
    if model == "fastsim":
        return f"{options.get('nx', 20)} x {options.get('ny', 20)} elements (per strip x strips)"
    if model == "bem":
        fields = None if main is None else main[3].fields
        if fields is not None and len(fields.x_m) > 1 and len(fields.y_m) > 1:
            dx, dy = abs(fields.x_m[1] - fields.x_m[0]), abs(fields.y_m[1] - fields.y_m[0])
            return f"{len(fields.x_m)} x {len(fields.y_m)} elements of {dx * 1e3:.3g} x {dy * 1e3:.3g} mm"
        return f"{options.get('nx', 40)} x {options.get('ny', 40)} elements"
    if model == "hertz":
        return "closed form"
    return ""


def _solve_models(named, models, options, progress=None):
    from comparisons.bench import case_errors, side_values, solve_contact_case, warm_up
    from comparisons.stated_errors import side_stated_errors

    out = {}
    for model in models:
        if model == "fea":
            continue
        warm_up(model)
        start = time.perf_counter()
        try:
            patches, success, message = solve_contact_case(named.case, model, options.get(model, {}))
        except Exception as exc:  # numerical failure is a status
            out[model] = {"status": "error", "message": f"{type(exc).__name__}: {exc}", "wall_time_s": math.nan}
            continue
        entry = {
            "status": "ok" if success else "failed",
            "message": message,
            "wall_time_s": time.perf_counter() - start,
            "patches": patches,
            "main": _main_patch(patches, named.side),
        }
        entry["resolution"] = _resolution(model, options.get(model, {}), entry["main"])
        if progress is not None:
            progress(f"{model} solved in {entry['wall_time_s']:.2g} s ({entry['status']})")
        if success:
            entry["values"] = side_values(patches, named.side)
            entry["errors"], entry["error"] = case_errors(named, entry["values"])
            entry["stated_errors"] = side_stated_errors([p[3] for p in patches if p[0] == named.side])
        out[model] = entry
    return out


def _cut_points(fields, depth_max):
    """Cut planes through the pressure maximum: (xz points, yz points, axes)."""
    p = fields.pressure_Pa
    j, i = np.unravel_index(int(np.argmax(p)), p.shape)
    x0, y0 = float(fields.x_m[i]), float(fields.y_m[j])
    inside = p > 0
    xs = fields.x_m[inside.any(axis=0)]
    ys = fields.y_m[inside.any(axis=1)]
    half_x = 1.3 * max(x0 - xs.min(), xs.max() - x0)
    half_y = 1.3 * max(y0 - ys.min(), ys.max() - y0)
    nu_, nd = CUT_POINTS
    depth = np.linspace(depth_max / nd, depth_max, nd)
    xcut = np.linspace(x0 - half_x, x0 + half_x, nu_)
    ycut = np.linspace(y0 - half_y, y0 + half_y, nu_)
    gx, gd = np.meshgrid(xcut, depth)
    xz = np.column_stack([gx.ravel(), np.full(gx.size, y0), gd.ravel()])
    gy, gd2 = np.meshgrid(ycut, depth)
    yz = np.column_stack([np.full(gy.size, x0), gy.ravel(), gd2.ravel()])
    return xz, yz, {"x0": x0, "y0": y0, "xcut": xcut, "ycut": ycut, "depth": depth}


def _stress_summary(name, points, stress):
    from rigid_dynamics.contact.subsurface import max_shear_Pa, von_mises_Pa

    ok = np.all(np.isfinite(stress.reshape(len(stress), -1)), axis=1)
    vm = np.where(ok, von_mises_Pa(np.where(ok[:, None, None], stress, 0.0)), np.nan)
    tau = np.where(ok, max_shear_Pa(np.where(ok[:, None, None], stress, 0.0)), np.nan)
    k = int(np.nanargmax(vm)) if np.any(ok) else -1
    kt = int(np.nanargmax(tau)) if np.any(ok) else -1
    return {
        "source": name,
        "max_von_mises_Pa": float(vm[k]) if k >= 0 else None,
        "max_von_mises_depth_m": float(points[k, 2]) if k >= 0 else None,
        "max_shear_Pa": float(tau[kt]) if kt >= 0 else None,
        "max_shear_depth_m": float(points[kt, 2]) if kt >= 0 else None,
        "max_orthogonal_shear_Pa": float(np.nanmax(np.abs(stress[:, 0, 2]))) if np.any(ok) else None,
        "von_mises": vm,
        "orthogonal_shear": stress[:, 0, 2],
    }


def subsurface(named, bem_main, fea_options=None, with_fea: bool = True):
    """Half-space stresses of the BEM tractions and FEA stresses on the same cuts (see the module docstring).

    Returns:
        (cuts, sources, fea_result): cut axes, list of per-source summaries (xz and yz values), FEA's result.
    """
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.subsurface import halfspace_stress

    side, geometry, creepage, result = bem_main
    f = result.fields
    nu = named.case.material.poisson_ratio
    inside = f.pressure_Pa > 0
    extent = min(np.ptp(f.x_m[inside.any(axis=0)]), np.ptp(f.y_m[inside.any(axis=1)])) + float(abs(f.x_m[1] - f.x_m[0]))
    xz, yz, cuts = _cut_points(f, 0.6 * extent)  # ~1.2 times the smaller semi-axis (max shear at ~0.5-0.8)
    both = np.vstack([xz, yz])
    sources = []
    start = time.perf_counter()
    parts = halfspace_stress(
        f.x_m,
        f.y_m,
        f.pressure_Pa,
        both,
        nu,
        traction_x_Pa=-f.traction_long_Pa,
        traction_y_Pa=-f.traction_lat_Pa,
        separate=True,
    )
    s_p, s_t = parts[0], parts.sum(axis=0)
    cuts["halfspace_time_s"] = time.perf_counter() - start  # reported in the notes
    for name, s in (("BEM pressure, half-space", s_p), ("BEM pressure + tractions, half-space", s_t)):
        sources.append(_stress_summary(name, both, s))
    fea_result = None
    cuts["n_xz"] = len(xz)
    cuts["points"] = both
    if not with_fea:
        return cuts, sources, None
    fea_pts = both * np.array([1.0, 1.0, -1.0])
    opts = {**(fea_options or {}), "stress_points_m": [tuple(p) for p in fea_pts]}
    frictional = bool(np.any(f.traction_long_Pa) or np.any(f.traction_lat_Pa))
    if frictional:
        opts["surface_traction"] = {
            "x_m": f.x_m.tolist(),
            "y_m": f.y_m.tolist(),
            "traction_long_Pa": f.traction_long_Pa.tolist(),
            "traction_lat_Pa": f.traction_lat_Pa.tolist(),
            "source": f"the BEM ({len(f.x_m)}x{len(f.y_m)})",
        }
    fea_label = "FEA (BEM tractions applied)" if frictional else "FEA (frictionless)"
    start = time.perf_counter()
    try:
        fea_result = get_model("fea").solve(
            geometry, creepage, named.case.material, normal_force_N=result.normal_force_N, options=opts
        )
    except Exception as exc:  # numerical failure is a status
        cuts["fea_message"] = f"{type(exc).__name__}: {exc}"
    cuts["fea_time_s"] = time.perf_counter() - start
    if fea_result is not None and fea_result.success:
        raw = fea_result.extra.get("stress_points_Pa") or []
        s_f = np.array([np.full((3, 3), np.nan) if t is None else np.asarray(t) for t in raw])
        # FEA frame: z up (out of the block); flip the shear components with one z index to depth d = -z
        s_f[:, 0, 2] *= -1
        s_f[:, 2, 0] *= -1
        s_f[:, 1, 2] *= -1
        s_f[:, 2, 1] *= -1
        sources.append(_stress_summary(fea_label, both, s_f))
    elif fea_result is not None:
        cuts["fea_message"] = f"{fea_result.status}: {fea_result.message}"
    return cuts, sources, fea_result


_MAP_METADATA = {"Description": "pressure maps: x (rolling) and y (lateral) in mm, equal aspect; pressure in MPa"}


def _patch_box(fields, margin: float = 0.15) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) in mm: the union of the fields' contact areas (p > 0), padded by ``margin`` of its size."""
    xs, ys = [], []
    for f in fields:
        on = np.asarray(f.pressure_Pa) > 0
        if on.any():
            gx, gy = np.meshgrid(f.x_m, f.y_m)
            xs += [gx[on].min(), gx[on].max()]
            ys += [gy[on].min(), gy[on].max()]
    if not xs:
        xs = [min(f.x_m.min() for f in fields), max(f.x_m.max() for f in fields)]
        ys = [min(f.y_m.min() for f in fields), max(f.y_m.max() for f in fields)]
    x0, x1, y0, y1 = (1e3 * v for v in (min(xs), max(xs), min(ys), max(ys)))
    pad_x, pad_y = margin * max(x1 - x0, 1e-3), margin * max(y1 - y0, 1e-3)
    return x0 - pad_x, x1 + pad_x, y0 - pad_y, y1 + pad_y


MAX_MAP_RATIO = 4.0
"""A patch longer than this many times its width (a flange patch: 13 x 0.7 mm) is drawn with y stretched so that
the panel is at most this elongated, and the title says by how much (an equal-aspect sliver shows nothing)."""


def _stretch(box) -> float:
    """The factor by which y (or x) is stretched in the maps of ``box``: 1 (equal aspect) unless the patch is more
    elongated than :data:`MAX_MAP_RATIO`; > 1 stretches y, < 1 stretches x.
    """
    width, height = box[1] - box[0], box[3] - box[2]
    if width <= 0 or height <= 0:
        return 1.0
    ratio = width / height
    if ratio > MAX_MAP_RATIO:
        return ratio / MAX_MAP_RATIO
    if ratio < 1 / MAX_MAP_RATIO:
        return ratio * MAX_MAP_RATIO
    return 1.0


def _map_axes(n: int, box):
    """A row of ``n`` map panels sized to the patch's aspect (a long flange patch gets tall panels, not slivers);
    panels wider than 3:1 are stacked in a column.
    """
    import matplotlib.pyplot as plt

    width, height = box[1] - box[0], box[3] - box[2]
    ratio = height * _stretch(box) / width if width > 0 else 1.0  # drawn height over width
    if ratio < 1 / 2:  # wide, flat patches: one panel per row
        fig, axes = plt.subplots(
            n, 1, figsize=(7.0, (max(1.6, 7.0 * ratio) + 0.5) * n), squeeze=False, layout="constrained"
        )
    else:
        panel = 3.4
        size = (panel * n + 1.2, min(max(panel * ratio, 2.4), 9.0))
        fig, axes = plt.subplots(1, n, figsize=size, squeeze=False, layout="constrained")
    axes = list(axes.flat)
    for ax in axes:
        ax.set_xlabel("x (rolling) [mm]")
        ax.set_ylabel("y (lateral) [mm]")
    return fig, axes


def _zoom(ax, box) -> None:
    """Limits of the patch's box; equal aspect, or the stretch of :func:`_stretch` said in the title."""
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    stretch = _stretch(box)
    ax.set_aspect(stretch)
    if stretch != 1.0:
        what = f"y stretched x{stretch:.3g}" if stretch > 1 else f"x stretched x{1 / stretch:.3g}"
        ax.set_title(f"{ax.get_title()} ({what})", fontsize=9)


def _plot_pressures(entries, bem_fields, out_dir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from comparisons.named_cases import grid_interpolate
    from rigid_dynamics.files import save_figure

    names = [n for n, f in entries if f is not None]
    fields = [f for _, f in entries if f is not None]
    vmax = max(float(np.max(f.pressure_Pa)) for f in fields) / 1e6
    box = _patch_box(fields)
    fig, axes = _map_axes(len(fields), box)
    for ax, name, f in zip(axes, names, fields, strict=True):
        mesh = ax.pcolormesh(f.x_m * 1e3, f.y_m * 1e3, f.pressure_Pa / 1e6, vmin=0, vmax=vmax, shading="auto")
        ax.contour(f.x_m * 1e3, f.y_m * 1e3, (f.pressure_Pa > 0).astype(float), levels=[0.5], colors="w", linewidths=1)
        ax.set_title(name, fontsize=9)
        _zoom(ax, box)
    fig.colorbar(mesh, ax=list(axes), label="pressure [MPa] (one scale)", shrink=0.9)
    save_figure(fig, out_dir / "pressure.png", dpi=110, bbox_inches="tight", metadata=_MAP_METADATA)
    plt.close(fig)
    if bem_fields is None:
        return ["pressure.png"]
    gx, gy = np.meshgrid(bem_fields.x_m, bem_fields.y_m)
    diffs = [
        (n, grid_interpolate(f.x_m, f.y_m, f.pressure_Pa, gx, gy) - bem_fields.pressure_Pa)
        for n, f in zip(names, fields, strict=True)
        if f is not bem_fields
    ]
    if not diffs:
        return ["pressure.png"]
    lim = max(float(np.abs(d).max()) for _, d in diffs) / 1e6 or 1.0
    fig, axes = _map_axes(len(diffs), box)
    for ax, (name, d) in zip(axes, diffs, strict=True):
        mesh = ax.pcolormesh(gx * 1e3, gy * 1e3, d / 1e6, vmin=-lim, vmax=lim, cmap="RdBu_r", shading="auto")
        ax.contour(
            gx * 1e3, gy * 1e3, (bem_fields.pressure_Pa > 0).astype(float), levels=[0.5], colors="k", linewidths=0.8
        )
        ax.set_title(f"{name} - bem", fontsize=9)
        _zoom(ax, box)
    fig.colorbar(mesh, ax=list(axes), label="p - p_BEM [MPa] (black: BEM outline)", shrink=0.9)
    save_figure(fig, out_dir / "pressure_difference.png", dpi=110, bbox_inches="tight", metadata=_MAP_METADATA)
    plt.close(fig)
    return ["pressure.png", "pressure_difference.png"]


def _plot_subsurface(cuts, sources, out_dir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rigid_dynamics.files import save_figure

    n_xz = cuts["n_xz"]
    nd = len(cuts["depth"])
    vmax = max(float(np.nanmax(s["von_mises"])) for s in sources) / 1e6
    smax = max(float(np.nanmax(np.abs(s["orthogonal_shear"][:n_xz]))) for s in sources) / 1e6
    fig, axes = plt.subplots(len(sources), 3, figsize=(13, 2.9 * len(sources)), squeeze=False)
    d_mm = cuts["depth"] * 1e3
    for row, s in zip(axes, sources, strict=True):
        vm_xz = s["von_mises"][:n_xz].reshape(nd, -1) / 1e6
        vm_yz = s["von_mises"][n_xz:].reshape(nd, -1) / 1e6
        tau_xz = s["orthogonal_shear"][:n_xz].reshape(nd, -1) / 1e6
        panels = (
            (cuts["xcut"], vm_xz, "von Mises, cut y = y_pmax", 0, vmax, "inferno", "x [mm]"),
            (cuts["xcut"], tau_xz, "orthogonal shear s_xd, cut y = y_pmax", -smax, smax, "RdBu_r", "x [mm]"),
            (cuts["ycut"], vm_yz, "von Mises, cut x = x_pmax", 0, vmax, "inferno", "y [mm]"),
        )
        for ax, (u, v, title, lo, hi, cmap, xlabel) in zip(row, panels, strict=True):
            mesh = ax.pcolormesh(u * 1e3, d_mm, v, vmin=lo, vmax=hi, cmap=cmap, shading="auto")
            ax.invert_yaxis()
            ax.set_aspect("equal" if np.ptp(u) < 4 * np.ptp(d_mm) * 1e-3 else "auto")  # long flange patches
            ax.set_title(f"{s['source']}\n{title}", fontsize=8)
            ax.set_xlabel(xlabel)
            ax.set_ylabel("depth [mm]")
            fig.colorbar(mesh, ax=ax, label="MPa", shrink=0.8)
        if s["max_von_mises_depth_m"] is not None:
            row[0].axhline(s["max_von_mises_depth_m"] * 1e3, color="c", lw=0.8, ls="--")
    fig.tight_layout()
    save_figure(fig, out_dir / "subsurface.png", dpi=100)
    plt.close(fig)
    return "subsurface.png"


def _plot_3d(cuts, source, pressure_fields, out_dir) -> tuple[str | None, str]:
    """3-D view (pyvista, off-screen) of the two von Mises cuts of ``source`` below the pressure map."""
    try:
        import pyvista as pv
    except Exception as exc:  # pyvista is an optional plotting dependency
        return None, f"{type(exc).__name__}: {exc}"
    with pv.vtk_verbosity("off"):  # no "bad X server connection" warning on a machine without a display
        return _render_3d(pv, cuts, source, pressure_fields, out_dir)


def _render_3d(pv, cuts, source, pressure_fields, out_dir) -> tuple[str | None, str]:
    try:
        n_xz, d = cuts["n_xz"], cuts["depth"] * 1e3
        vm = source["von_mises"] / 1e6
        planes = []
        for u, values, along_x in ((cuts["xcut"], vm[:n_xz], True), (cuts["ycut"], vm[n_xz:], False)):
            uu, dd = np.meshgrid(u * 1e3, d)
            xs = uu if along_x else np.full_like(uu, cuts["x0"] * 1e3)
            ys = np.full_like(uu, cuts["y0"] * 1e3) if along_x else uu
            grid = pv.StructuredGrid(xs[..., None], ys[..., None], -dd[..., None])
            grid.point_data["von Mises [MPa]"] = values.reshape(dd.shape)[..., None].ravel(order="F")
            planes.append(grid)
        f = pressure_fields
        px, py = np.meshgrid(f.x_m * 1e3, f.y_m * 1e3)
        top = pv.StructuredGrid(px[..., None], py[..., None], np.zeros_like(px)[..., None])
        top.point_data["pressure [MPa]"] = (f.pressure_Pa / 1e6)[..., None].ravel(order="F")
        plotter = pv.Plotter(off_screen=True, window_size=(1000, 700))
        bar = {"fmt": "%.0f", "n_labels": 4, "title_font_size": 14, "label_font_size": 12, "width": 0.35}
        for grid in planes:
            plotter.add_mesh(
                grid, scalars="von Mises [MPa]", cmap="inferno", clim=(0, float(np.nanmax(vm))),
                scalar_bar_args={**bar, "position_x": 0.6, "position_y": 0.05},
            )  # fmt: skip
        plotter.add_mesh(
            top, scalars="pressure [MPa]", cmap="viridis", opacity=0.6,
            scalar_bar_args={**bar, "position_x": 0.6, "position_y": 0.24},
        )  # fmt: skip
        # depth drawn at a scale that shows it beside a long patch; the axis title says the scale
        extent = max(np.ptp(px), np.ptp(py), 1e-3)
        zscale = max(1.0, round(extent / (3.0 * max(float(d.max()), 1e-3))))
        plotter.set_scale(zscale=zscale)
        # the axes label the true coordinates (axes_ranges), not the drawn, depth-stretched ones
        ranges = [px.min(), px.max(), py.min(), py.max(), -float(d.max()), 0.0]
        plotter.show_grid(
            axes_ranges=ranges, xtitle="x [mm]", ytitle="y [mm]",
            ztitle=f"-depth [mm] (drawn x{zscale:g})" if zscale != 1 else "-depth [mm]",
            n_xlabels=4, n_ylabels=3, n_zlabels=3, fmt="%.2f", font_size=10,
        )  # fmt: skip
        plotter.view_isometric()
        plotter.add_text(source["source"], font_size=9)
        from rigid_dynamics.files import atomic_write

        path = atomic_write(out_dir / "subsurface_3d.png", lambda tmp: plotter.screenshot(str(tmp)))
        plotter.close()
        return path.name, "ok"
    except Exception as exc:  # rendering needs an off-screen OpenGL context; its absence is reported, not fatal
        return None, f"{type(exc).__name__}: {exc}"


def _fmt(value, scale=1.0, digits=4):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value * scale:.{digits}g}"


def _pct(value):
    if value is None:
        return "-"
    return f"{100 * value:.2g} %" if abs(value) >= 1e-4 else "<0.01 %"


def run_compare(named, out_dir, models=COMPARE_MODELS, options=None, fea_options=None, progress=None) -> dict:
    """Solve, draw and write report.md / report.html / compare.json into ``out_dir`` (see the module docstring).

    ``progress``, when given, is called with one line of text after each step (a rung solved, the stresses, the
    pictures), so that a run of tens of seconds is not silent.
    """
    from comparisons.contact_plots import plot_contact_fields
    from rigid_dynamics.files import write_json, write_text

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    options = {**DEFAULT_OPTIONS, **(options or {})}
    solved = _solve_models(
        named, [m for m in models if m != "fea"] + (["bem"] if "bem" not in models else []), options, progress
    )
    pictures, notes = {}, []
    bem = solved.get("bem", {})
    bem_main = bem.get("main") if bem.get("status") == "ok" else None
    entries = []
    for model in models:
        if (
            model == "fea"
            or model not in solved
            or solved[model].get("status") != "ok"
            or solved[model]["main"] is None
        ):
            continue
        result = solved[model]["main"][3]
        entries.append((model, _hertz_fields(result) if result.fields is None else result.fields))
    cuts, sources, fea_result = None, [], None
    if bem_main is not None and bem_main[3].fields is not None:
        if progress is not None:
            progress("subsurface stresses" + (" and FEA (minutes on a fine mesh)" if "fea" in models else ""))
        cuts, sources, fea_result = subsurface(named, bem_main, fea_options, with_fea="fea" in models)
        if fea_result is not None and fea_result.fields is not None and fea_result.success:
            entries.append(("fea", fea_result.fields))
        notes.append(f"half-space stresses on {len(cuts['points'])} cut points: {cuts['halfspace_time_s']:.1f} s")
        if cuts.get("fea_message"):
            notes.append(f"FEA: {cuts['fea_message']}")
    else:
        notes.append(f"BEM did not give a patch on the {named.side} side: no subsurface stresses or difference maps")
    if progress is not None:
        progress("maps and report")
    if entries:
        pictures["pressure"] = _plot_pressures(entries, bem_main[3].fields if bem_main else None, out_dir)
    for model in ("fastsim", "bem"):
        main = solved.get(model, {}).get("main")
        if main is not None and main[3].fields is not None and main[3].fields.traction_long_Pa is not None:
            name = f"fields-{model}.png"
            plot_contact_fields(main[3], out_dir / name, title=f"{named.name}: {model}")
            pictures.setdefault("fields", []).append(name)
    if sources:
        pictures["subsurface"] = _plot_subsurface(cuts, sources, out_dir)
        view, status = _plot_3d(cuts, sources[1], bem_main[3].fields, out_dir)
        if view:
            pictures["subsurface_3d"] = view
        else:
            notes.append(f"3-D view not drawn ({status})")
    if fea_result is not None:
        solved["fea"] = {
            "status": fea_result.status if fea_result.success else "failed",
            "message": fea_result.message,
            "wall_time_s": cuts.get("fea_time_s", math.nan),
            "values": {
                "normal_force_N": fea_result.normal_force_N,
                "max_pressure_Pa": fea_result.max_pressure_Pa,
                "contact_area_m2": fea_result.contact_area_m2,
            },
            "note": "main BEM patch only, BEM normal force",
            "resolution": _fea_resolution(fea_result),
            "stated_errors": stated_errors(fea_result),
            "element_size_m": fea_result.extra.get("element_size_m"),
            "error_parts": _fea_error_parts(fea_result),
        }
        solved["fea"]["agreement_with_bem"] = _fea_bem_agreement(solved["fea"], bem_main)
        solved["fea"]["verdict_why"] = _fea_bem_why(solved["fea"], solved.get("bem", {}))
    from comparisons.rung_differences import explain

    differences = explain(solved, getattr(named.case, "material", None), options)
    report = _report(named, models, solved, sources, cuts, pictures, notes, differences)
    write_text(out_dir / "report.md", report["markdown"])
    write_text(out_dir / "report.html", report["html"])
    summary = {
        "case": named.name,
        "success": all(solved.get(m, {}).get("status") == "ok" for m in models),
        "models": {m: {k: v for k, v in e.items() if k not in ("patches", "main")} for m, e in solved.items()},
        "subsurface": [{k: v for k, v in s.items() if k not in ("von_mises", "orthogonal_shear")} for s in sources],
        "pictures": pictures,
        "notes": notes,
        "headlines": report["headlines"],
        "rung_differences": [d.removeprefix("- ") for d in differences],
    }
    write_json(out_dir / "compare.json", summary)
    return summary


def _fea_resolution(result) -> str:
    """FEA's mesh for the report: element size at the patch, cells, and the refinement series that stated the
    error (levels, elements per semi-axis of the finest).
    """
    size = result.extra.get("element_size_m")
    mesh = result.extra.get("mesh") or {}
    cells = mesh.get("element_count") or mesh.get("cells") or mesh.get("n_cells")
    text = f"element size {size * 1e3:.3g} mm at the patch" if size else "mesh not reported"
    info = result.extra.get("discretisation_error") or {}
    levels = info.get("levels") or []
    if levels:
        finest = levels[-1]["elements_per_semi_axis"]
        text += f", finest of {len(levels)} refinement levels ({finest:.3g} per semi-axis)"
    box = (info.get("peak_box") or {}).get("box_m")
    window = result.extra.get("max_pressure_window") or {}
    if size and box and window.get("max_pressure_Pa") is not None:
        refinement = info["peak_box"]["refinement"]
        semi = window["semi_axes_m"]
        text += (
            f", {size / refinement * 1e3:.3g} mm in a {2e3 * box[2]:.3g} x {2e3 * box[3]:.3g} mm box at the pressure "
            f"peak (max pressure fitted over a {2e3 * semi[0]:.3g} x {2e3 * semi[1]:.3g} mm ellipse)"
        )
    return text + (f", {cells} cells" if cells else "")


def _fea_error_parts(result) -> dict:
    """The parts of the FEA's stated relative errors (fea.refinement): mesh (Richardson), block size and, for the max
    pressure of a patch with a peak box, the fit window's model error; and each level's max pressure and area.
    """
    info = result.extra.get("discretisation_error") or {}
    parts = {}
    for name in ("max_pressure", "contact_area", "normal_force"):
        parts[name] = {
            "mesh": (info.get("mesh_relative_error") or {}).get(name),
            "block_size": (info.get("block_size_relative_error") or {}).get(name),
            "window": (info.get("window_relative_error") or {}).get(name),
            "observed_order": (info.get("observed_order") or {}).get(name),
        }
    levels = [
        {k: level.get(k) for k in ("elements_per_semi_axis", "dofs", "max_pressure", "contact_area", "normal_force")}
        for level in info.get("levels") or []
    ]
    return {"parts": parts, "levels": levels}


def _source_file(named) -> str | None:
    """The case's SOURCE.md as the report cites it, or None when the case has none (e.g. the demo's peak patch)."""
    folder = getattr(named, "folder", None)
    if folder is None or not (Path(folder) / "SOURCE.md").is_file():
        return None
    return f"comparisons/cases/{named.name}/SOURCE.md"


def _fea_bem_agreement(fea_entry: dict, bem_main) -> dict:
    """FEA against the BEM's main patch (the same patch and normal force) on max pressure and area, judged with both
    stated errors (comparisons.stated_errors.agreement; agree None where the BEM states none).
    """
    bem_result = bem_main[3]
    fea_errors = fea_entry.get("stated_errors") or {}
    bem_errors = stated_errors(bem_result) or {}
    out = {}
    for name, attribute in (
        ("max_pressure", "max_pressure_Pa"),
        ("contact_area", "contact_area_m2"),
        ("normal_force", "normal_force_N"),
    ):
        fea_value, bem_value = fea_entry["values"].get(attribute), getattr(bem_result, attribute)
        if fea_value is None or bem_value is None:
            continue
        out[name] = {
            "fea": fea_value,
            "bem": bem_value,
            "fea_stated": fea_errors.get(name),
            "bem_stated": bem_errors.get(name),
            **agreement(fea_value, bem_value, fea_errors.get(name), bem_errors.get(name)),
        }
        out[name]["verdict"] = verdict(out[name])
    return out


def verdict(a: dict) -> str:
    """One comparison judged with both stated errors: "agree within the stated errors", "differ by X" (beyond the
    sum of the errors) or "undecided" (an error is not stated: no judgement without it).
    """
    if a["agree"] is None:
        missing = [who for who, e in (("FEA", a["fea_stated"]), ("BEM", a["bem_stated"])) if e is None]
        return f"undecided ({' and '.join(missing)} error not stated)"
    if a["agree"]:
        return f"agree within the stated errors ({_pct(a['difference'])} apart, allowed {_pct(a['allowed'])})"
    return f"differ by {_pct(a['difference'])} (beyond the stated {_pct(a['allowed'])})"


def _fea_bem_why(fea_entry: dict, bem_entry: dict) -> str:
    """Sentences on why the FEA and the BEM agree or differ at the patch: the FEA's mesh and status (whether its
    stated error met its tolerance), the BEM's grid, and the problems they solve.
    """
    agreement_ = fea_entry.get("agreement_with_bem") or {}
    verdicts = [a for name, a in agreement_.items() if name != "normal_force"]
    mesh = fea_entry.get("resolution") or "mesh not reported"
    bem = bem_entry.get("resolution") or "its grid"
    parts = []
    if any(a["agree"] is False for a in verdicts):
        parts.append(
            "Why they differ: the two do not solve exactly the same problem: the FEA a finite clamped block with the "
            f"combined modulus under the rigid gap ({mesh}), the BEM the half-space on {bem}; a difference beyond "
            "both stated errors says one of the errors is understated or the finite block matters at this patch."
        )
    elif any(a["agree"] is None for a in verdicts):
        parts.append(f"Why undecided: a model states no error for that quantity (FEA: {mesh}; BEM: {bem}).")
    else:
        parts.append(f"Why they agree: both resolve the patch within their stated errors (FEA {mesh}; BEM {bem}).")
    p = agreement_.get("max_pressure")
    if p is not None and p["fea"] < p["bem"] * (1 - 0.01):
        parts.append(
            "The FEA's max pressure lies below the BEM's: it is the nodal pressure averaged over 1.5 elements "
            "(fea.postprocess), which flattens the peak on a mesh this coarse; its refinement series states that error."
        )
    if fea_entry.get("status") != "ok":
        message = fea_entry.get("message", "")
        start = message.find("discretisation error above")  # by how much, and of what (fea.refinement)
        said = message[start:] if start >= 0 else message[:240]
        parts.append(
            f"The FEA ended {fea_entry.get('status')}: {said}; so the agreement holds only at its larger stated error, "
            "not at its tolerance (mesh: the refinement series; window: the max pressure's fit-window model error; "
            "block size: the truncated half-space; fea.refinement)."
        )
    return " ".join(parts)


def _report(named, models, solved, sources, cuts, pictures, notes, differences=()) -> dict:
    ref = named.reference
    lines = [
        f"# {named.name}: Hertz, FASTSIM, BEM and FEA side by side",
        "",
        f"{named.note}. Reference: {named.source}"
        + (f" ({_source_file(named)})" if _source_file(named) else "")
        + f". Side compared: {named.side}.",
        "",
        "| model | grid / mesh | status | time | N [N] | Fx [N] | Fy [N] | p max [MPa] | area [mm2] | err N | err F | "
        "err p | err area | stated err N / p / area |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        f"| reference | | {named.source} | | {_fmt(ref.get('normal_force_N'))} | "
        f"{_fmt(ref.get('creep_force_long_N'))} | "
        f"{_fmt(ref.get('creep_force_lat_N'))} | {_fmt(ref.get('max_pressure_Pa'), 1e-6)} | "
        f"{_fmt(ref.get('contact_area_m2'), 1e6)} | | | | | |",
    ]
    for model in models:
        e = solved.get(model)
        if e is None:
            continue
        v, err = e.get("values", {}), e.get("errors", {})
        t = e.get("wall_time_s", math.nan)
        status = e["status"] if e["status"] == "ok" else f"{e['status']}: {e.get('message', '')[:80]}"
        if e.get("note"):
            status += f" ({e['note']})"
        lines.append(
            f"| {model} | {e.get('resolution', '')} | {status} | {_fmt(t, 1, 3)} s | {_fmt(v.get('normal_force_N'))} | "
            f"{_fmt(v.get('creep_force_long_N'))} | {_fmt(v.get('creep_force_lat_N'))} | "
            f"{_fmt(v.get('max_pressure_Pa'), 1e-6)} | {_fmt(v.get('contact_area_m2'), 1e6)} | "
            f"{_pct(err.get('err_normal_force'))} | {_pct(err.get('err_creep_force'))} | "
            f"{_pct(err.get('err_max_pressure'))} | {_pct(err.get('err_area'))} | {_stated_cell(model, e)} |"
        )
    lines += [
        "",
        "Times: whole case (a wheelset case includes search and equilibrium); FEA: one patch. `stated err`: the "
        "relative discretisation error a model states for its own normal force, max pressure and area (the FEA's from "
        "its refinement series, fea.refinement; `not stated` where a model states none).",
        "",
    ]
    lines += _agreement_lines(
        solved.get("fea", {}).get("agreement_with_bem"), solved.get("fea", {}).get("verdict_why", "")
    )
    if differences:
        lines += [
            "## Where the rungs differ from the BEM",
            "",
            "Main patch; differences above 5 % (N, p max, area) or 5 % of mu N (creep forces), each with its measured "
            "cause (comparisons/rung_differences.py).",
            "",
            *differences,
            "",
        ]
    for key, caption in (
        ("pressure", "Pressure on one colour scale with the contact outlines, and the difference to the BEM"),
        ("fields", "Tractions and slip/adhesion (FASTSIM, BEM)"),
    ):
        if key in pictures:
            lines += [f"## {caption}", ""] + [f"![{key}]({p})" for p in pictures[key]] + [""]
    headlines = []
    if sources:
        lines += [
            "## Subsurface stresses in the rail",
            "",
            "Half-space solution (Boussinesq-Cerruti point forces integrated over the BEM's uniformly loaded "
            "elements by Gauss quadrature; rigid_dynamics/contact/subsurface.py) of the BEM pressure alone and "
            "with the BEM's tangential tractions; FEA: the frictionless normal contact solved on the same patch "
            "under the BEM's normal force, with minus the BEM's tangential tractions (on the wheel) applied to the "
            "rail block's contact face as a surface load where the BEM has tractions (fea option "
            "surface_traction). Cuts through the point of maximum BEM pressure; one colour scale per quantity.",
            "",
            "| source | max von Mises [MPa] | at depth [mm] | max shear (s1-s3)/2 [MPa] | at depth [mm] "
            "| max abs orthogonal shear s_xd [MPa] |",
            "|---|---|---|---|---|---|",
        ]
        for s in sources:
            lines.append(
                f"| {s['source']} | {_fmt(s['max_von_mises_Pa'], 1e-6)} | {_fmt(s['max_von_mises_depth_m'], 1e3)} | "
                f"{_fmt(s['max_shear_Pa'], 1e-6)} | {_fmt(s['max_shear_depth_m'], 1e3)} | "
                f"{_fmt(s['max_orthogonal_shear_Pa'], 1e-6)} |"
            )
        lines += ["", f"![subsurface]({pictures['subsurface']})", ""]
        if "subsurface_3d" in pictures:
            lines += [f"![3-D von Mises]({pictures['subsurface_3d']})", ""]
        s_t = sources[1]
        headlines.append(
            f"{named.name}: max von Mises {s_t['max_von_mises_Pa'] / 1e6:.0f} MPa at "
            f"{s_t['max_von_mises_depth_m'] * 1e3:.2f} mm depth with tractions "
            f"({sources[0]['max_von_mises_Pa'] / 1e6:.0f} MPa at "
            f"{sources[0]['max_von_mises_depth_m'] * 1e3:.2f} mm without)"
        )
        fea = next((s for s in sources if s["source"].startswith("FEA")), None)
        if fea is not None:
            headlines.append(
                f"{named.name}: {fea['source']} max von Mises {fea['max_von_mises_Pa'] / 1e6:.0f} MPa at "
                f"{fea['max_von_mises_depth_m'] * 1e3:.2f} mm"
            )
    ok = [(m, solved[m]) for m in models if m in solved and solved[m].get("error") is not None]
    if ok:
        cheapest = min((e for e in ok if e[1]["error"] <= 0.05), key=lambda e: e[1]["wall_time_s"], default=None)
        headlines.insert(
            0,
            f"{named.name}: "
            + ", ".join(f"{m} {100 * e['error']:.2g} % in {e['wall_time_s'] * 1e3:.3g} ms" for m, e in ok)
            + (f"; cheapest within 5 %: {cheapest[0]}" if cheapest else "; none within 5 %"),
        )
    if notes:
        lines += ["## Notes", ""] + [f"- {n}" for n in notes] + [""]
    markdown = "\n".join(lines) + "\n"
    return {"markdown": markdown, "html": _html(markdown, named.name), "headlines": headlines}


def _stated_cell(model: str, entry: dict) -> str:
    if model == "hertz":
        return "exact (closed form)"
    errors = entry.get("stated_errors")
    if errors is None:
        return "not stated" if entry.get("status") == "ok" else "-"
    return " / ".join(_pct(errors.get(n)) for n in ("normal_force", "max_pressure", "contact_area"))


def _agreement_lines(agreement_: dict | None, why: str = "") -> list[str]:
    """The report's paragraph on FEA against BEM, judged with both stated errors."""
    if not agreement_:
        return []
    lines = ["## FEA against BEM (same patch, same normal force)", ""]
    for name, a in agreement_.items():
        lines.append(f"- {agreement_sentence(name, a)}")
    if why:
        lines += ["", why]
    lines += [
        "",
        "Creep forces: the FEA here solves no creep force of its own (where the BEM has tangential tractions, they "
        "are applied to the FEA's block as a prescribed load, for the subsurface stresses): its steady rolling "
        "solver's 3-D creep force has no stated error yet (comparisons/bench.py, FEA_CREEP_STATUS).",
    ]
    return lines + [""]


def agreement_sentence(name: str, a: dict) -> str:
    """'max pressure: FEA 1147 MPa +- 1.2 %, BEM 1150 MPa +- 0.3 %: agree within the stated errors (...)'."""
    label = name.replace("_", " ")
    scale, unit = {"max_pressure": (1e-6, "MPa"), "contact_area": (1e6, "mm2"), "normal_force": (1e-3, "kN")}[name]

    def value(v, e):
        return f"{_fmt(v, scale)} {unit}" + ("" if e is None else f" +- {_pct(e)}")

    if name == "normal_force":  # force control: equal by construction, no verdict to draw
        return (
            f"{label}: FEA {value(a['fea'], a['fea_stated'])}, BEM {value(a['bem'], a['bem_stated'])}: equal by "
            "construction (the FEA is solved under the BEM's normal force)"
        )
    return f"{label}: FEA {value(a['fea'], a['fea_stated'])}, BEM {value(a['bem'], a['bem_stated'])}: {verdict(a)}"


def _html(markdown: str, title: str) -> str:
    """The report as a standalone HTML page (markdown-it-py, CommonMark with tables; images scale to the page)."""
    from markdown_it import MarkdownIt

    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(markdown)
    style = (
        "body{font-family:sans-serif;max-width:1100px;margin:2em auto;}table{border-collapse:collapse;font-size:90%}"
        "td,th{border:1px solid #bbb;padding:3px 6px;text-align:right}th{background:#eee}img{max-width:100%}"
    )
    return (
        f"<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
        f"<style>{style}</style></head><body>\n{body}</body></html>\n"
    )
