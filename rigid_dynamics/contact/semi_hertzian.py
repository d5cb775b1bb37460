"""The semi-Hertzian rungs ``kpec`` and ``analyn``: CONTACT's KPEC or ANALYN normal method with FASTSIM (or
FaStrip) per strip, on the sampled gap.

The method and its compiled kernels are in :mod:`rigid_dynamics.contact.kpec` (equal to the open-source CONTACT
program's KPEC, B = 5, and ANALYN, B = 6, with its FASTSIM, M = 3: tests/test_kpec_contact.py against its
``mbench_a22_kpec`` example; option ``tangential = "fastrip"``: FaStrip per strip, CONTACT's M = 5, which has no
published output to compare with: tested against Kalker's linear theory, Coulomb's bound and our Hertz + FaStrip).
This module is the static driver: it chooses the grid, evaluates the gap at the element centres from the patch
geometry (``ContactGeometry.gap_m``: for the wheelset case's CONTACT-style patches the undeformed distance evaluated
exactly from the surfaces, the one sampler the BEM uses too), runs the kernels, and returns a
:class:`~rigid_dynamics.contact.types.ContactResult`.

Grid (options): ``element_size_m`` (CONTACT's DX = DS) gives square elements whose centres lie at integer
multiples of the size from the contact reference point, over the patch's potential contact area
(``undeformed.potential_area_m``, else the rigid-overlap box widened by ``margin``), as the BEM's and CONTACT's
grid; else ``nx`` x ``ny`` elements over that area. The rung solves the joined gap of several interpenetration
regions itself (``solves_undeformed_distance``), so the wheelset case forms patches as CONTACT does for KPEC.

Normal problem: approach control with the geometry's gap (the wheelset case), or force control
(``normal_force_N``): the penetration found by a secant iteration on log F(pen) (F ~ pen^1.5), the grid following
the rigid overlap when the geometry gives no potential area.

Grid error: every solve is repeated on grids with elements 2 and 4 times as large over the same area (about 31 %
more cost), and the estimate per quantity (normal force, creep force against max(|F_t|, 0.01 mu F_N), max pressure,
area) is GRID_ERROR_SAFETY = 2 times the BEM's companion estimate (bem.model.grid_error_estimate: max(|d1|, |d2|/2)
or Richardson's at an observed order below 1): KPEC's and ANALYN's creep forces converge at first order but not
monotonically. Measured against 320 x 320 on quadric patches (a/b 0.2 to 5, longitudinal, lateral with spin, large
spin; grids 20, 40, 80): true error / estimate at most 0.55 for both rungs and every quantity; at the old fixed
40 x 40 the creep forces were 2.7-4.2 % off (KPEC) and 3.4-32 % (ANALYN, the largest on creep-lat-spin). A grid
the caller did not name (no nx, ny or element_size_m) is doubled up to ``max_refinements`` times while the
estimate exceeds ``grid_tolerance`` (5 %); a result still above it is a ``warning``
(``extra["grid_error"]``, ``extra["discretisation_error"]``, as the BEM's).

Accuracy: the method is approximate by nature. Its error against the exact half-space solution (the ``bem`` rung,
or CONTACT's full solution) is measured per case in benchmarks/results/kpec.md (e.g. max pressure +31 % at the
A-2.2 tread contact, as CONTACT's own KPEC); the result reports it in ``extra["method_error"]`` as "not
estimated" (no per-patch estimate exists), and ``is_elliptic`` patches get the equivalent ellipse's semi-axes.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from rigid_dynamics.contact.options import Option, declare
from rigid_dynamics.contact.options import defaults as option_defaults

TANGENTIAL = ("fastsim", "fastrip")
"""Per-strip tangential methods of the option ``tangential``: FASTSIM (CONTACT's M = 3) or FaStrip (M = 5)."""

OPTIONS = declare(
    Option("nx", int, 40, "elements along x over the potential contact area", minimum=4, maximum=4096),
    Option("ny", int, 40, "elements along y over the potential contact area", minimum=4, maximum=4096),
    Option("element_size_m", float, None, "square elements of this side aligned with the reference point "
           "(CONTACT's DX = DS) instead of nx, ny, m", minimum=0, exclusive_minimum=True, allow_none=True),
    Option("margin", float, 1.1, "enlargement of the rigid-overlap region (no given potential area)", minimum=1.0),
    Option("max_iterations", int, 40, "force control: secant steps", minimum=1),
    Option("tangential", str, "fastsim", "per-strip tangential method", choices=TANGENTIAL),
    Option("grid_tolerance", float, 0.05, "accepted estimated relative grid error of forces, max pressure and area",
           minimum=0.0, exclusive_minimum=True),
    Option("max_refinements", int, 2, "doublings of the default grid's elements per direction while the estimate "
           "exceeds grid_tolerance (a grid given by nx, ny or element_size_m is not refined)", minimum=0, maximum=4),
    Option("estimate_grid_error", bool, True, "estimate the grid error (false: one solve on the given grid, e.g. the "
           "perturbed solves of the sensitivities, on their base's grid)"),
)  # fmt: skip
"""Options of :class:`KpecModel` (module docstring): grid ``nx`` x ``ny`` (>= 4) or ``element_size_m``,
``margin`` (>= 1) of the rigid-overlap box, ``max_iterations`` of force control, ``tangential``: ``"fastsim"``
(FASTSIM per strip, :func:`~rigid_dynamics.contact.kpec.fastsim_strips`, as CONTACT's KPEC example) or
``"fastrip"`` (FaStrip per strip, :func:`~rigid_dynamics.contact.kpec.fastrip_strips`); ``grid_tolerance``,
``max_refinements`` and ``estimate_grid_error`` (the grid error, module docstring)."""
DEFAULTS: dict = option_defaults(OPTIONS)

MAX_ELEMENTS = 4_000_000
"""Largest grid ``element_size_m`` may produce."""


class KpecModel:
    """CONTACT's KPEC + FASTSIM per strip (module docstring): the registered model ``kpec``.

    Forces on the wheel in the contact frame; spin moment about the contact reference point (grid origin);
    fields on the grid.
    """

    name = "kpec"
    description = "CONTACT's KPEC semi-Hertzian normal + FASTSIM per strip (non-elliptic patches)"
    OPTIONS = OPTIONS
    solves_undeformed_distance = True
    compiled_law = "kpec"

    def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None):
        """One patch with its grid error (class and module docstrings); :class:`~.types.ContactResult`."""
        from rigid_dynamics.contact.bem.model import NOT_ESTIMATED_REASON, _with_grid_error, _without_grid_error

        start = time.perf_counter()
        opts, base, grid = self._grid_options(options)
        if not opts["estimate_grid_error"]:
            one = self._solve_grid(geometry, creepage, material, normal_force_N=normal_force_N, options=options)
            if not one.success or one.status == "no-contact":
                return one
            return _without_grid_error(one, NOT_ESTIMATED_REASON, time.perf_counter() - start)
        named = any(key in (options or {}) for key in ("nx", "ny", "element_size_m"))
        refinements = 0
        while True:
            fine = self._solve_grid(
                geometry, creepage, material, normal_force_N=normal_force_N, options={**base, **grid}
            )
            if not fine.success or fine.status == "no-contact":
                return fine
            estimate = self._estimate(geometry, creepage, material, normal_force_N, (base, grid), fine)
            done = estimate is not None and estimate["largest_relative"] <= opts["grid_tolerance"]
            if done or named or refinements >= opts["max_refinements"] or _scaled_grid(grid, 0.5) is None:
                break
            grid = _scaled_grid(grid, 0.5)
            refinements += 1
        return _with_grid_error(fine, estimate, opts["grid_tolerance"], refinements, time.perf_counter() - start)

    def with_grid_error(self, geometry, creepage, material, result, *, normal_force_N=None, options=None):
        """``result`` (this model's, solved with ``estimate_grid_error = false`` and the same arguments) with its
        grid-error estimate, status and message as :meth:`solve` gives them, without refining its grid (as the
        BEM's: the wheelset case estimates only its final patches, whose numbers its equilibrium holds).
        """
        from rigid_dynamics.contact.bem.model import _not_estimated_note, _with_grid_error

        start = time.perf_counter()
        if result.status == "no-contact" or not result.success:
            return result
        opts, base, grid = self._grid_options(options)
        if "element_size_m" not in grid:
            grid = {"nx": int(result.extra["nx"]), "ny": int(result.extra["ny"])}
        estimate = self._estimate(geometry, creepage, material, normal_force_N, (base, grid), result)
        result = dataclasses.replace(result, message=result.message.replace(_not_estimated_note(), ""))
        out = _with_grid_error(result, estimate, opts["grid_tolerance"], 0, 0.0)
        return dataclasses.replace(out, wall_time_s=result.wall_time_s + time.perf_counter() - start)

    def _grid_options(self, options):
        """(validated options, the caller's options without the grid's, the grid: element size or nx, ny)."""
        from rigid_dynamics.contact.models import _options

        opts = _options(options, self.OPTIONS, self.name)
        given = dict(options or {})
        if opts["element_size_m"] is not None and any(k in given for k in ("nx", "ny")):
            raise ValueError(
                f"kpec option element_size_m = {opts['element_size_m']!r} together with nx or ny: expected either "
                "the element size or the element counts"
            )
        base = {k: v for k, v in given.items() if k not in ("nx", "ny", "element_size_m", "estimate_grid_error")}
        if opts["element_size_m"] is not None:
            return opts, base, {"element_size_m": float(opts["element_size_m"])}
        return opts, base, {"nx": int(opts["nx"]), "ny": int(opts["ny"])}

    def _estimate(self, geometry, creepage, material, normal_force_N, grid_of, fine):
        """The grid-error estimate of ``fine`` (solved on ``grid_of`` = (options, grid)) from companions with
        elements 2 and 4 times as large (module docstring); None when the companion twice as coarse is missing.
        """
        from rigid_dynamics.contact.bem.model import grid_error_estimate

        base, grid = grid_of
        companions = [
            None if level is None else self._solve_grid(
                geometry, creepage, material, normal_force_N=normal_force_N, options={**base, **level}
            )
            for level in (_scaled_grid(grid, 2), _scaled_grid(grid, 4))
        ]  # fmt: skip
        estimate = grid_error_estimate([fine, *companions], material.friction_coefficient)
        return None if estimate is None else _safety(estimate, GRID_ERROR_SAFETY)

    def _solve_grid(self, geometry, creepage, material, *, normal_force_N=None, options=None):
        """One patch on one grid (see the class docstring); :class:`~.types.ContactResult`."""
        from rigid_dynamics.contact.kpec import fastrip_strips, fastsim_strips, simplified_flexibilities
        from rigid_dynamics.contact.models import _options, coulomb_for_patch
        from rigid_dynamics.contact.types import ContactFields, ContactResult

        start = time.perf_counter()
        opts = _options(options, self.OPTIONS, self.name)
        if normal_force_N is not None and (not math.isfinite(normal_force_N) or normal_force_N <= 0):
            raise ValueError(f"normal_force_N = {normal_force_N!r}: expected None or a finite number > 0")
        material, friction_note = coulomb_for_patch(geometry, creepage, material)
        g_mod, nu, mu = material.shear_modulus_Pa, material.poisson_ratio, material.friction_coefficient
        h_min = _minimum_gap(geometry)

        def solve_at(pen: float):
            """KPEC with the gap shifted so that its sampled minimum is -pen; (x, y, h, p, contact, kernel out)."""
            x, y = _grid(geometry, h_min + pen, h_min, opts)
            xx, yy = np.meshgrid(x, y)
            h = np.ascontiguousarray(geometry.gap_m(xx, yy), dtype=float) - (pen + h_min)
            h = np.where(np.isfinite(h), h, 1.0)  # off the surfaces: far from contact
            p = np.zeros(h.shape)
            contact = np.zeros(h.shape, dtype=np.bool_)
            out = self._normal(h, x, y, g_mod, nu, p, contact)
            return x, y, h, p, contact, out

        iterations = 0
        if normal_force_N is None:
            pen = -h_min
            if pen <= 0:
                return _no_contact(self.name, geometry, creepage, start, f"approach {pen!r} m <= 0: no contact")
            x, y, h, p, contact, out = solve_at(pen)
        else:
            pen = _hertz_start_delta(geometry, normal_force_N, g_mod / (1 - nu))
            x, y, h, p, contact, out = solve_at(pen)
            prev = None
            for iterations in range(1, int(opts["max_iterations"]) + 1):  # noqa: B007
                force = _force(p, x, y)
                if force > 0 and abs(force / normal_force_N - 1.0) < 1e-10:
                    break
                slope = 1.5
                if prev is not None and force > 0 and prev[1] > 0 and prev[1] != force and prev[0] != pen:
                    slope = min(max(math.log(force / prev[1]) / math.log(pen / prev[0]), 0.5), 3.0)
                prev = (pen, force)
                pen *= (normal_force_N / force) ** (1.0 / slope) if force > 0 else 2.0
                x, y, h, p, contact, out = solve_at(pen)
        force = _force(p, x, y)
        fn_kpec, p_max, curv_a, curv_b, y_mid, a_eq, b_eq, penetration = out
        if not contact.any():
            if penetration > 0.0:  # the gap overlaps, yet no element carries pressure: a failure
                return ContactResult(
                    method=self.name,
                    success=False,
                    status="no-pressure",
                    message=f"{self.name.upper()} put pressure on no element of a gap that overlaps by "
                    f"{float(penetration):.3g} m (its equivalent ellipse misses the deepest row)",
                    normal_force_N=math.nan,
                    creepage=creepage,
                    wall_time_s=time.perf_counter() - start,
                )
            return _no_contact(self.name, geometry, creepage, start, "KPEC found no element in contact")
        converged = normal_force_N is None or abs(force / normal_force_N - 1.0) < 1e-8
        message = f"{self.name.upper()} + {'FaStrip' if opts['tangential'] == 'fastrip' else 'FASTSIM'} per strip"
        if not converged:
            message = f"force control did not converge in {iterations} steps: F_N = {force!r} N"
        elif friction_note is not None:
            message = f"{message}; {friction_note}"
        dx, dy = x[1] - x[0], y[1] - y[0]
        l1, l2, l3, a_fl, b_fl = simplified_flexibilities(
            contact, dx, dy, fn_kpec, g_mod, nu, mu, creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m
        )
        tx, ty = np.zeros(p.shape), np.zeros(p.shape)
        slip = np.zeros(p.shape, dtype=np.bool_)
        xi, eta, phi = creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m
        if opts["tangential"] == "fastrip":
            from rigid_dynamics.contact.fastrip import StripTheory, strip_creepages

            xi_s, eta_s, phi_s, p0, *_ = strip_creepages(
                a_fl, b_fl, fn_kpec, xi, eta, phi, shear_modulus_Pa=g_mod, poisson_ratio=nu, friction_coefficient=mu
            )
            strip = StripTheory(a_fl, p0, nu, xi_s, eta_s, phi_s)
            fx, fy, mz = fastrip_strips((p, contact), (x, y), (mu, xi, eta, phi), (l1, l2, l3), (tx, ty, slip), strip)
        else:
            fx, fy, mz = fastsim_strips((p, contact), (x, y), (mu, xi, eta, phi), (l1, l2, l3), (tx, ty, slip))
        edge = bool(contact[0, :].any() or contact[-1, :].any() or contact[:, 0].any() or contact[:, -1].any())
        fields = ContactFields(
            x_m=x, y_m=y, pressure_Pa=p, traction_long_Pa=tx, traction_lat_Pa=ty, in_contact=contact, in_slip=slip
        )
        return ContactResult(
            method=self.name,
            success=bool(converged),
            status="ok" if converged else "not-converged",
            message=message,
            normal_force_N=force,
            creep_force_long_N=float(fx),
            creep_force_lat_N=float(fy),
            spin_moment_Nm=float(mz),
            max_pressure_Pa=float(p.max()),
            semi_axis_long_m=_finite(a_eq, a_fl) if geometry.is_elliptic else None,
            semi_axis_lat_m=_finite(b_eq, b_fl) if geometry.is_elliptic else None,
            contact_area_m2=float(contact.sum() * dx * dy),
            approach_m=float(geometry.approach_m + (penetration + h_min)),
            creepage=creepage,
            fields=fields,
            iterations=int(iterations),
            wall_time_s=time.perf_counter() - start,
            extra={
                "nx": int(x.size),
                "ny": int(y.size),
                "element_size_m": [float(dx), float(dy)],
                "equivalent_ellipse_m": [_finite(a_eq), _finite(b_eq)],
                "equivalent_curvatures_1_per_m": [_finite(curv_a), _finite(curv_b)],
                "ellipse_centre_lat_m": _finite(y_mid),
                "penetration_m": float(penetration),
                "flexibilities_m_per_Pa": [float(l1), float(l2), float(l3)],
                "flexibility_ellipse_m": [float(a_fl), float(b_fl)],
                "contact_touches_potential_area_edge": edge,
                "method_error": "not estimated (approximate method; benchmarks/results/kpec.md)",
                **({"friction_coefficient_used": float(mu)} if friction_note is not None else {}),
            },
        )

    @staticmethod
    def _normal(h, x, y, shear_modulus_Pa, poisson_ratio, pressure, in_contact):
        """The normal kernel: (F_N for the flexibilities, p_max, A, B, y_m, a, b, penetration) (kpec.py)."""
        from rigid_dynamics.contact.kpec import kpec_pressure

        return kpec_pressure(h, x, y, shear_modulus_Pa, poisson_ratio, pressure, in_contact)


class AnalynModel(KpecModel):
    """CONTACT's modified ANALYN normal method (B = 6) + FASTSIM per strip: the registered model ``analyn``.

    As :class:`KpecModel` with :func:`~rigid_dynamics.contact.kpec.analyn_pressure` for the normal problem (no
    equivalent ellipse: ``extra`` reports NaN for its fields).
    """

    name = "analyn"
    description = "CONTACT's ANALYN semi-Hertzian normal + FASTSIM per strip (non-elliptic patches)"
    compiled_law = None  # not compiled into the dynamics loop: its patches go through the callback

    @staticmethod
    def _normal(h, x, y, shear_modulus_Pa, poisson_ratio, pressure, in_contact):
        from rigid_dynamics.contact.kpec import analyn_pressure

        force = analyn_pressure(h, x, y, shear_modulus_Pa, poisson_ratio, pressure, in_contact)
        nan = math.nan
        return force, float(pressure.max()), nan, nan, nan, nan, nan, float(-h.min())


GRID_ERROR_SAFETY = 2.0
"""Factor on the BEM's companion estimate for KPEC and ANALYN (module docstring, measured)."""


def _scaled_grid(grid: dict, factor: float) -> dict | None:
    """The grid option with elements ``factor`` times as large (None: fewer elements than the option's minimum 4 or
    the BEM's companion minimum, or more than 4096).
    """
    from rigid_dynamics.contact.bem.model import MIN_COMPANION_ELEMENTS

    if "element_size_m" in grid:
        return {"element_size_m": grid["element_size_m"] * factor}
    nx, ny = (int(round(grid[k] / factor)) for k in ("nx", "ny"))
    if min(nx, ny) < max(4, MIN_COMPANION_ELEMENTS) or max(nx, ny) > 4096:
        return None
    return {"nx": nx, "ny": ny}


def _safety(estimate: dict, factor: float) -> dict:
    """The BEM's grid-error estimate dict with every estimate multiplied by ``factor``."""
    out = {k: (v * factor if isinstance(v, float) else v) for k, v in estimate.items()}
    out["relative"] = {k: v * factor for k, v in estimate["relative"].items()}
    out["largest_relative"] = estimate["largest_relative"] * factor
    return out


def _finite(value, fallback=None):
    """float(value), or ``fallback`` when it is not finite (ANALYN has no equivalent ellipse)."""
    return float(value) if math.isfinite(value) else fallback


def _force(p, x, y) -> float:
    return float(p.sum() * (x[1] - x[0]) * (y[1] - y[0]))


def _grid(geometry, level, h_min, opts):
    """Element centres (x, y) of the grid (module docstring) for the rigid overlap {h <= level}."""
    und = geometry.undeformed
    size = opts["element_size_m"]
    if und is not None and und.potential_area_m is not None:
        x0, x1, y0, y1 = und.potential_area_m
        x_lim, y_lim = (float(x0), float(x1)), (float(y0), float(y1))
    else:
        x, y = _overlap_grid(geometry, level, h_min, 2, 2, float(opts["margin"]))
        hx, hy = x[1] - x[0], y[1] - y[0]
        x_lim, y_lim = (x[0] - 0.5 * hx, x[1] + 0.5 * hx), (y[0] - 0.5 * hy, y[1] + 0.5 * hy)
    if size is None:
        nx, ny = int(opts["nx"]), int(opts["ny"])
    else:
        from rigid_dynamics.contact.bem.model import _whole_elements

        x_lim, nx = _whole_elements(x_lim, float(size))
        y_lim, ny = _whole_elements(y_lim, float(size))
        if nx * ny > MAX_ELEMENTS:
            raise ValueError(
                f"kpec option element_size_m = {size!r} gives {nx} x {ny} elements over the potential contact area: "
                f"expected at most {MAX_ELEMENTS} (a larger element size)"
            )
    dx = (x_lim[1] - x_lim[0]) / nx
    dy = (y_lim[1] - y_lim[0]) / ny
    return x_lim[0] + dx * (np.arange(nx) + 0.5), y_lim[0] + dy * (np.arange(ny) + 0.5)


def _minimum_gap(geometry) -> float:
    """Minimum of the undeformed gap h (approach subtracted), m (quadric: -approach)."""
    if geometry.undeformed is None:
        return -float(geometry.approach_m)
    d = np.asarray(geometry.undeformed.distance_m, float)
    return float(d[np.isfinite(d)].min())


def _hertz_start_delta(geometry, normal_force_N, e_star) -> float:
    """Hertz approach of the geometry's quadric part for F_N (the secant method's start)."""
    from rigid_dynamics.contact.bem.model import hertz_ellipse

    *_, approach = hertz_ellipse(
        geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m, e_star, normal_force_N=normal_force_N
    )
    return float(approach)


def _overlap_grid(geometry, level, h_min, nx, ny, margin):
    """Element centres (x, y) of an nx x ny grid over {h <= level} (rigid overlap at that level) widened by margin."""
    if geometry.undeformed is None:
        depth = level - h_min
        half_x = margin * math.sqrt(depth / geometry.curvature_long_1_per_m)
        half_y = margin * math.sqrt(depth / geometry.curvature_lat_1_per_m)
        box = (-half_x, half_x, -half_y, half_y)
    else:
        und = geometry.undeformed
        d = np.asarray(und.distance_m, float)
        xs, ys = np.asarray(und.x_m, float), np.asarray(und.y_m, float)
        jj, ii = np.nonzero(np.isfinite(d) & (d <= level))
        hx = 0.5 * float(np.abs(np.diff(xs)).min()) if xs.size > 1 else 0.0
        hy = 0.5 * float(np.abs(np.diff(ys)).min()) if ys.size > 1 else 0.0
        x0, x1 = float(xs[ii].min()) - hx, float(xs[ii].max()) + hx
        y0, y1 = float(ys[jj].min()) - hy, float(ys[jj].max()) + hy
        cx, cy, wx, wy = 0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * margin * (x1 - x0), 0.5 * margin * (y1 - y0)
        box = (max(cx - wx, xs.min()), min(cx + wx, xs.max()), max(cy - wy, ys.min()), min(cy + wy, ys.max()))
    dx = (box[1] - box[0]) / nx
    dy = (box[3] - box[2]) / ny
    return box[0] + dx * (np.arange(nx) + 0.5), box[2] + dy * (np.arange(ny) + 0.5)


def _no_contact(name, geometry, creepage, start, message):
    from rigid_dynamics.contact.types import ContactResult

    return ContactResult.no_contact(
        name, message, creepage, approach_m=geometry.approach_m, wall_time_s=time.perf_counter() - start
    )
