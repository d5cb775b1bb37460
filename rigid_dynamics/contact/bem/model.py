"""The boundary-element contact model ``bem``: NORM + TANG on a grid over the potential contact area.

Steps (Kalker 1990, ch. 5; the approach of his program CONTACT):

1. Potential contact area: a rectangle in the contact plane. For an elliptic (quadric) geometry
   it is the Hertz ellipse's bounding box [-m a, m a] x [-m b, m b] (a, b from Hertz for the given
   force or approach, m the margin). For a sampled undeformed distance h it is the bounding box of
   {h <= h_min + (-h_min) m^2/2} (approach control) or {h <= h_min + delta_H m^2/2} (force control,
   delta_H the Hertz approach of the quadric part for that force); for a Hertzian h both give the
   Hertz contact enlarged by m (the rigid overlap region is sqrt(2) times the contact). If the
   contact found by NORM touches the edge of that area it is enlarged by 1.3 (within the sampled
   field) and NORM is redone, up to 3 times.
2. NORM (:func:`~.norm.solve_norm`) for the pressure; TANG (:func:`~.tang.solve_tang`) for the
   tractions of steady rolling with rigid slip w = (xi - phi y, eta + phi x) and Coulomb friction.
   For different materials (option ``difference_parameter`` K != 0) both are alternated until the
   normal force settles (Panagiotopoulos' process, Kalker 1990 sec. 5.4).
3. Forces on the wheel in the contact frame: F_x = dA sum t_x, F_y = dA sum t_y,
   F_N = dA sum p, spin moment M_z = dA sum (x t_y - y t_x), N and N m.

Hertz sizing (Johnson 1985, sec. 4.2; seed eq 34-37): with a along the direction of the smaller
relative curvature, e^2 = 1 - (b/a)^2, K(e), E(e) complete elliptic integrals of modulus e, E*
the combined modulus G/(1 - nu)::

    A_small = p0 b (K - E)/(E* a^2 e^2),  A_large = p0 b ((a/b)^2 E - K)/(E* a^2 e^2),
    approach = p0 b K/E*,  F_N = 2 pi a b p0/3.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping

import numpy as np

from rigid_dynamics.contact.bem.influence import InfluenceGrid
from rigid_dynamics.contact.bem.norm import solve_norm
from rigid_dynamics.contact.bem.tang import rigid_slip, solve_tang
from rigid_dynamics.contact.options import Option, declare, validate_options
from rigid_dynamics.contact.options import defaults as option_defaults
from rigid_dynamics.contact.types import ContactFields, ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

OPTIONS = declare(
    Option("nx", int, 40, "elements along x (rolling direction)", minimum=1, maximum=4096),
    Option("ny", int, 40, "elements along y (lateral)", minimum=1, maximum=4096),
    Option("margin", float, 1.15, "potential contact area in Hertz semi-axes", minimum=1.0),
    Option("tolerance", float, 1e-6, "relative tolerance of NORM and TANG", minimum=0.0, exclusive_minimum=True),
    Option("max_iterations", int, 500, "NORM CG iterations and TANG Newton steps, each", minimum=1),
    Option(
        "difference_parameter",
        float,
        0.0,
        "Kalker's K (dissimilar materials)",
        minimum=-0.5,
        maximum=0.5,
        exclusive_minimum=True,
        exclusive_maximum=True,
    ),
    Option(
        "element_size_m",
        float,
        None,
        "element size (CONTACT's DX = DS), m; replaces nx, ny: centres at multiples of it from the reference point",
        minimum=0.0,
        maximum=0.1,
        exclusive_minimum=True,
        allow_none=True,
    ),
    Option("max_elements", int, 250_000, "element_size_m: sizes doubled above this many elements", minimum=16),
)
"""Options of :class:`BemModel` (name, type, range, default; :mod:`rigid_dynamics.contact.options`): grid
(nx, ny elements), margin m of the potential area, tolerance, iteration limit (NORM CG iterations and TANG
Newton steps each), Kalker's K (|K| < 0.5).

``element_size_m`` replaces the element counts by a size, as CONTACT's DX and DS: element centres then lie at
integer multiples of the size from the origin of the contact plane (the patch's reference point), the grid covers
the potential area, and nx, ny follow from it. When nx ny would exceed ``max_elements`` the sizes are doubled (in
the direction with more than 10 elements), as CONTACT does, and the result's ``extra`` says so."""
DEFAULT_OPTIONS: dict = option_defaults(OPTIONS)


def hertz_ellipse(
    curvature_long_1_per_m: float,
    curvature_lat_1_per_m: float,
    combined_modulus_Pa: float,
    *,
    normal_force_N: float | None = None,
    approach_m: float | None = None,
) -> tuple[float, float, float, float, float]:
    """Hertz contact ellipse for h = A x^2 + B y^2 (module docstring formulas).

    Give exactly one of ``normal_force_N`` (> 0) and ``approach_m`` (> 0).

    Returns:
        (a_x, b_y, p0, F_N, approach): semi-axes along x and y (m), maximum pressure (Pa),
        normal force (N), approach (m).
    """
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipk

    if (normal_force_N is None) == (approach_m is None):
        raise ValueError("hertz_ellipse: expected exactly one of normal_force_N and approach_m")
    a_c, b_c = curvature_long_1_per_m, curvature_lat_1_per_m
    small, large = min(a_c, b_c), max(a_c, b_c)
    if small <= 0:
        raise ValueError(f"curvatures A = {a_c!r}, B = {b_c!r} 1/m: expected both > 0")
    ratio = large / small
    if ratio - 1.0 < 1e-9:
        radius = 0.5 / small
        if normal_force_N is not None:
            a = (3.0 * normal_force_N * radius / (4.0 * combined_modulus_Pa)) ** (1.0 / 3.0)
        else:
            a = math.sqrt(approach_m * radius)
        force = 4.0 * combined_modulus_Pa * a**3 / (3.0 * radius)
        p0 = 3.0 * force / (2.0 * math.pi * a * a)
        return a, a, p0, force, a * a / radius

    def mismatch(e2: float) -> float:
        k, e = ellipk(e2), ellipe(e2)
        return (e / (1.0 - e2) - k) / (k - e) - ratio

    e2 = brentq(mismatch, 1e-12, 1.0 - 1e-15, xtol=1e-15, rtol=1e-14)
    k, e = float(ellipk(e2)), float(ellipe(e2))
    if normal_force_N is not None:
        a = (3.0 * normal_force_N * (k - e) / (2.0 * math.pi * combined_modulus_Pa * small * e2)) ** (1.0 / 3.0)
        b = a * math.sqrt(1.0 - e2)
        p0 = 3.0 * normal_force_N / (2.0 * math.pi * a * b)
    else:
        a = math.sqrt(approach_m * (k - e) / (k * e2 * small))
        b = a * math.sqrt(1.0 - e2)
        p0 = approach_m * combined_modulus_Pa / (b * k)
    force = 2.0 * math.pi * a * b * p0 / 3.0
    approach = p0 * b * k / combined_modulus_Pa
    if a_c <= b_c:
        return a, b, p0, force, approach
    return b, a, p0, force, approach


def _options(options: Mapping | None) -> dict:
    opts = validate_options(OPTIONS, options, "bem")
    if opts["element_size_m"] is not None:
        opts["element_size_m"] = (float(opts["element_size_m"]), float(opts["element_size_m"]))
    return opts


class BemModel:
    """Boundary-element NORM + TANG (Kalker's exact theory discretised; the CONTACT approach)."""

    name = "bem"
    description = "boundary elements: CONTACT-style NORM + TANG"
    OPTIONS = OPTIONS

    def solve(
        self,
        geometry: ContactGeometry,
        creepage: Creepage,
        material: Material,
        *,
        normal_force_N: float | None = None,
        options: Mapping | None = None,
    ) -> ContactResult:
        """Solve one patch (see the module docstring); forces on the wheel in the contact frame.

        Args:
            geometry: patch geometry; ``geometry.undeformed`` (if set) is used as h, else the quadric.
            creepage: xi, eta, phi and the rolling speed V (slip velocities are V times the slip).
            material: G, nu, mu of the (quasi-identical) pair.
            normal_force_N: None = approach control with ``geometry.approach_m``; else F_N > 0, N.
            options: see :data:`DEFAULT_OPTIONS`; unknown keys raise ValueError.

        Returns:
            ContactResult with fields on the grid; semi-axes (extents of the contact along x, y)
            only when ``geometry.is_elliptic`` (else None); ``success`` False with status
            "not-converged" when NORM or TANG did not converge.
        """
        start = time.perf_counter()
        opts = _options(options)
        if normal_force_N is not None and (not math.isfinite(normal_force_N) or normal_force_N <= 0):
            raise ValueError(f"normal_force_N = {normal_force_N!r}: expected None or a finite number > 0")
        g_mod, nu, mu = material.shear_modulus_Pa, material.poisson_ratio, material.friction_coefficient
        e_star = g_mod / (1.0 - nu)
        curv = (geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m)
        margin = float(opts["margin"])
        nx, ny = int(opts["nx"]), int(opts["ny"])

        def no_contact(message: str) -> ContactResult:
            return ContactResult(
                method=self.name,
                success=True,
                status="no-contact",
                message=message,
                normal_force_N=0.0,
                creep_force_long_N=0.0,
                creep_force_lat_N=0.0,
                spin_moment_Nm=0.0,
                max_pressure_Pa=0.0,
                contact_area_m2=0.0,
                approach_m=geometry.approach_m,
                creepage=creepage,
                wall_time_s=time.perf_counter() - start,
            )

        # 1. potential contact area
        if geometry.undeformed is None:
            if normal_force_N is None:
                if geometry.approach_m <= 0:
                    return no_contact(f"approach {geometry.approach_m!r} m <= 0: the bodies do not touch")
                ax, by, *_ = hertz_ellipse(*curv, e_star, approach_m=geometry.approach_m)
            else:
                ax, by, *_ = hertz_ellipse(*curv, e_star, normal_force_N=normal_force_N)
            x_lim = (-margin * ax, margin * ax)
            y_lim = (-margin * by, margin * by)
        else:
            und = geometry.undeformed
            d = np.asarray(und.distance_m, float)
            finite = np.isfinite(d)
            if not finite.any():
                return no_contact("the sampled undeformed distance has no finite value")
            d_min = float(d[finite].min())
            if normal_force_N is None:
                if d_min >= 0:
                    return no_contact(f"minimum undeformed distance {d_min!r} m >= 0: the bodies do not touch")
                depth = -d_min
            else:
                *_, depth = hertz_ellipse(*curv, e_star, normal_force_N=normal_force_N)
            if und.potential_area_m is not None:  # a rectangle known to hold the whole rigid overlap
                x_lim, y_lim = tuple(und.potential_area_m[:2]), tuple(und.potential_area_m[2:])
            region = finite & (d <= d_min + 0.5 * depth * margin**2)
            if und.potential_area_m is None:
                jj, ii = np.nonzero(region)
                xs, ys = np.asarray(und.x_m), np.asarray(und.y_m)
                hx = 0.5 * (np.abs(np.diff(xs)).min() if xs.size > 1 else 0.0)
                hy = 0.5 * (np.abs(np.diff(ys)).min() if ys.size > 1 else 0.0)
                x_lim = (float(xs[ii].min()) - hx, float(xs[ii].max()) + hx)
                y_lim = (float(ys[jj].min()) - hy, float(ys[jj].max()) + hy)
            if x_lim[1] <= x_lim[0] or y_lim[1] <= y_lim[0]:
                return no_contact("the sampled undeformed distance gives an empty potential contact area")
        k_diff = float(opts["difference_parameter"])
        tol, max_it = float(opts["tolerance"]), int(opts["max_iterations"])
        if geometry.undeformed is not None:
            xs, ys = np.asarray(geometry.undeformed.x_m), np.asarray(geometry.undeformed.y_m)
            field_box = (float(xs.min()), float(xs.max()), float(ys.min()), float(ys.max()))
        grown = 0
        coarsened = 0
        while True:
            if opts["element_size_m"] is not None:
                (x_lim, y_lim, nx, ny), coarsened = _aligned_grid(
                    x_lim, y_lim, *opts["element_size_m"], opts["max_elements"]
                )
            dx = (x_lim[1] - x_lim[0]) / nx
            dy = (y_lim[1] - y_lim[0]) / ny
            x = x_lim[0] + dx * (np.arange(nx) + 0.5)
            y = y_lim[0] + dy * (np.arange(ny) + 0.5)
            xx, yy = np.meshgrid(x, y)
            h = np.asarray(geometry.gap_m(xx, yy), float)
            influence = InfluenceGrid(nx, ny, dx, dy, g_mod, nu, k_diff)
            norm = solve_norm(influence, h, normal_force_N=normal_force_N, tolerance=tol, max_iterations=max_it)
            contact = norm.pressure_Pa > 0
            edge = bool(contact[0, :].any() or contact[-1, :].any() or contact[:, 0].any() or contact[:, -1].any())
            if (
                not edge
                or geometry.undeformed is None
                or geometry.undeformed.potential_area_m is not None
                or grown >= 3
            ):
                break
            # a sampled field's contact reached the potential area's edge: enlarge it (within the field) and redo
            cx, cy = 0.5 * (x_lim[0] + x_lim[1]), 0.5 * (y_lim[0] + y_lim[1])
            hx, hy = 0.65 * (x_lim[1] - x_lim[0]), 0.65 * (y_lim[1] - y_lim[0])
            new_x = (max(cx - hx, field_box[0]), min(cx + hx, field_box[1]))
            new_y = (max(cy - hy, field_box[2]), min(cy + hy, field_box[3]))
            if new_x == x_lim and new_y == y_lim:
                break
            x_lim, y_lim = new_x, new_y
            grown += 1

        # 2. TANG (alternated with NORM for K != 0: Panagiotopoulos' process)
        wx, wy = rigid_slip(x, y, creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m)
        previous = norm.normal_force_N
        for _ in range(1 if k_diff == 0.0 else 20):
            tang = solve_tang(influence, norm.pressure_Pa, mu, wx, wy, tolerance=tol, max_iterations=max_it)
            if k_diff == 0.0:
                break
            norm = solve_norm(
                influence,
                h,
                normal_force_N=normal_force_N,
                tolerance=tol,
                max_iterations=max_it,
                tractions_Pa=(tang.traction_x_Pa, tang.traction_y_Pa),
                initial_pressure_Pa=norm.pressure_Pa,
            )
            change = abs(norm.normal_force_N - previous)
            previous = norm.normal_force_N
            if change <= tol * max(norm.normal_force_N, 1e-300) and np.array_equal(norm.pressure_Pa > 0, contact):
                break
            contact = norm.pressure_Pa > 0
        p = norm.pressure_Pa
        contact = p > 0
        if not contact.any():
            return no_contact("NORM found no element in contact")
        area = dx * dy
        tx, ty = tang.traction_x_Pa, tang.traction_y_Pa
        fx, fy = float(tx.sum() * area), float(ty.sum() * area)
        mz = float((xx * ty - yy * tx).sum() * area)
        slip_speed = creepage.rolling_speed_m_per_s * np.hypot(tang.slip_x, tang.slip_y)
        fields = ContactFields(
            x_m=x,
            y_m=y,
            pressure_Pa=p,
            traction_long_Pa=tx,
            traction_lat_Pa=ty,
            slip_m_per_s=slip_speed,
            in_contact=contact,
            in_slip=tang.in_slip & contact,
        )
        semi_long = semi_lat = None
        if geometry.is_elliptic:
            semi_long, semi_lat = _elliptic_semi_axes(x, y, p, contact, dx, dy)
        success = bool(norm.converged and tang.converged)
        if success:
            status, message = "ok", "NORM and TANG converged"
        else:
            status = "not-converged"
            parts = []
            if not norm.converged:
                parts.append(f"NORM did not converge in {norm.iterations} iterations (residual {norm.residual:.3g})")
            if not tang.converged:
                parts.append(f"TANG did not converge in {tang.iterations} iterations (residual {tang.residual:.3g})")
            message = "; ".join(parts)
        edge = bool(contact[0, :].any() or contact[-1, :].any() or contact[:, 0].any() or contact[:, -1].any())
        if edge:
            message += "; the contact reaches the edge of the potential contact area (enlarge margin or the field)"
        return ContactResult(
            method=self.name,
            success=success,
            status=status,
            message=message,
            normal_force_N=float(p.sum() * area),
            creep_force_long_N=fx,
            creep_force_lat_N=fy,
            spin_moment_Nm=mz,
            max_pressure_Pa=float(p.max()),
            semi_axis_long_m=semi_long,
            semi_axis_lat_m=semi_lat,
            contact_area_m2=float(contact.sum() * area),
            approach_m=float(geometry.approach_m + norm.approach_shift_m),
            creepage=creepage,
            fields=fields,
            iterations=int(norm.iterations + tang.iterations),
            residual=float(max(norm.residual, tang.residual)),
            wall_time_s=time.perf_counter() - start,
            extra={
                "nx": nx,
                "ny": ny,
                "dx_m": float(dx),
                "dy_m": float(dy),
                "potential_area_m": [float(x_lim[0]), float(x_lim[1]), float(y_lim[0]), float(y_lim[1])],
                "norm_iterations": int(norm.iterations),
                "norm_residual": float(norm.residual),
                "tang_iterations": int(tang.iterations),
                "tang_linear_iterations": int(tang.linear_iterations),
                "tang_residual": float(tang.residual),
                "slip_elements": int((tang.in_slip & contact).sum()),
                "contact_touches_potential_area_edge": edge,
                "potential_area_enlargements": grown,
                "element_size_doublings": coarsened,
            },
        )


def _aligned_grid(x_lim, y_lim, dx: float, dy: float, max_elements: int):
    """Grid of element size (dx, dy) with element centres at integer multiples of it, covering the limits.

    Returns ((x_lim, y_lim, nx, ny), doublings): the sizes are doubled while nx ny > max_elements (CONTACT's rule).
    """
    doublings = 0
    while True:
        i0, i1 = math.floor(x_lim[0] / dx + 0.5), math.ceil(x_lim[1] / dx - 0.5)
        j0, j1 = math.floor(y_lim[0] / dy + 0.5), math.ceil(y_lim[1] / dy - 0.5)
        nx, ny = i1 - i0 + 1, j1 - j0 + 1
        if nx * ny <= max_elements or (nx <= 10 and ny <= 10):
            break
        doublings += 1
        if nx > 10:
            dx *= 2.0
        if ny > 10:
            dy *= 2.0
    return (((i0 - 0.5) * dx, (i1 + 0.5) * dx), ((j0 - 0.5) * dy, (j1 + 0.5) * dy), nx, ny), doublings


def _elliptic_semi_axes(x, y, pressure, contact, dx, dy) -> tuple[float, float]:
    """Semi-axes (along x, y) of an elliptic patch from a least-squares fit of the pressure field.

    For Hertzian pressure p^2 = p0^2 (1 - (x - xc)^2/a^2 - (y - yc)^2/b^2) (Johnson 1985, eq 4.22), so
    p^2 is linear in (x - xc)^2 and (y - yc)^2 over the contact elements; a = sqrt(-c0/c1), b = sqrt(-c0/c2)
    for the fitted p^2 = c0 + c1 (x - xc)^2 + c2 (y - yc)^2, with (xc, yc) the pressure centroid. This is
    not quantised by the element size as the extent of the contact elements is; the extents (outer edges of
    the elements in contact) are the fall-back when the fit is degenerate (fewer than 6 elements).
    """
    jj, ii = np.nonzero(contact)
    extents = (float(0.5 * (x[ii].max() - x[ii].min() + dx)), float(0.5 * (y[jj].max() - y[jj].min() + dy)))
    if len(ii) < 6:
        return extents
    weights = pressure[jj, ii]
    xc = float(np.sum(weights * x[ii]) / np.sum(weights))
    yc = float(np.sum(weights * y[jj]) / np.sum(weights))
    design = np.stack([np.ones(len(ii)), (x[ii] - xc) ** 2, (y[jj] - yc) ** 2], axis=1)
    c0, c1, c2 = np.linalg.lstsq(design, weights**2, rcond=None)[0]
    if not (c0 > 0 and c1 < 0 and c2 < 0):
        return extents
    return float(np.sqrt(-c0 / c1)), float(np.sqrt(-c0 / c2))
