"""KPEC: the semi-Hertzian normal method of Kik and Piotrowski with ellipse correction, and FASTSIM on its patch.

Kik-Piotrowski (W. Kik, J. Piotrowski, Proc. 2nd Mini Conf. on Contact Mechanics, Budapest 1996; J. Piotrowski,
W. Kik, Vehicle System Dynamics 46 (2008) 27-48) with the ellipse correction of the open-source CONTACT program
(E.A.H. Vollebregt, eve70a/CONTACT, user guide sec. "Fast or detailed solution": a variable virtual-penetration
factor from Hertz's theory, exact for elliptic patches); compared with the BEM and ANALYN by M. Sh. Sichani,
R. Enblom, M. Berg, Wear 314 (2014) 111-117. Written from the method's description.

Given the undeformed distance h0(x, y) >= 0 (0 at the deepest point) on a regular grid and the approach delta:

1. Equivalent ellipse: A = curvature of h0 along x through the deepest point (parabola through the deepest
   point and the first points on either side with h0 > delta/2), B = (delta/2)/w^2 with w the half-width in y
   of {h0 <= delta/2} (rows interpolated linearly on the rows' minima of h0), centred at y_m; Hertz's ellipse
   of h = A x^2 + B (y - y_m)^2 at approach delta gives semi-axes a (x), b (y).
2. Contact area: {h0(x, y) <= A a^2 - (A a^2 - B b^2) ((y - y_m)/b)^2} (clipped to [0, delta]): Kik-Piotrowski's
   virtual-penetration region with a factor varying with y so that a quadric h gives Hertz's ellipse exactly.
3. Pressure: in each row the contact runs from x_t to x_l (edges interpolated linearly on h0), and
   p = p_max sqrt((L_y/2)^2 - (x - x_c)^2)/(L_max/2), L_y = x_l - x_t, x_c the row's middle, L_max the longest
   row (Hertz's distribution for a quadric h).
4. p_max from the elastic approach: the half-space displacement (Love's rectangle coefficients,
   :func:`~.bem.influence.rectangle_influence`) of that pressure at the deepest element equals delta.
   Force control: delta is found by the secant method on log F(delta) (F ~ delta^1.5).

Tangential part (model ``kpec``): FASTSIM (Kalker 1982, :mod:`.fastsim`) along every row of the KPEC patch from
its leading edge (+x) with traction bound mu p and the flexibilities L1, L2, L3 of the equivalent ellipse a, b
(C_ij for a/b from Kalker's table; blended towards one flexibility at large creepage as :mod:`.fastsim`'s
default "three").

Symbols: h0, delta (m); A, B (1/m); a, b (m); p (Pa); x rolling direction (leading edge at +x), y lateral.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit

from rigid_dynamics.contact.options import Option, declare
from rigid_dynamics.contact.options import defaults as option_defaults


@dataclass(frozen=True, eq=False)
class KpecSolution:
    """Result of :func:`kpec_pressure`.

    Attributes:
        pressure_Pa: p (ny, nx), Pa; x_m (nx,), y_m (ny,): element centres, m.
        normal_force_N: dA sum p, N.
        approach_m: delta, m.
        semi_axis_long_m, semi_axis_lat_m: a, b of the equivalent Hertz ellipse, m.
        curvature_long_1_per_m, curvature_lat_1_per_m: its A, B, 1/m.
        contact_area_m2: dA times the number of elements in contact, m^2.
    """

    pressure_Pa: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    normal_force_N: float
    approach_m: float
    semi_axis_long_m: float
    semi_axis_lat_m: float
    curvature_long_1_per_m: float
    curvature_lat_1_per_m: float
    contact_area_m2: float


def _equivalent_ellipse(h0, x, y, delta, e_star):
    """(A, B, y_m, a, b, j_min, i_min) of step 1 (module docstring)."""
    from rigid_dynamics.contact.bem.model import hertz_ellipse

    ny, nx = h0.shape
    j0, i0 = np.unravel_index(int(np.argmin(h0)), h0.shape)
    half = 0.5 * delta
    lo, hi = i0 - 1, i0 + 1
    while lo > 0 and hi < nx - 1 and max(h0[j0, lo], h0[j0, hi]) <= half:
        lo -= 1
        hi += 1
    lo, hi = max(lo, 0), min(hi, nx - 1)
    dist = max(x[hi] - x[i0], x[i0] - x[lo])
    curv_a = (h0[j0, hi] - 2.0 * h0[j0, i0] + h0[j0, lo]) / (2.0 * dist * dist) if dist > 0 else 0.0
    row_min = h0.min(axis=1)
    inside = np.nonzero(row_min <= half)[0]
    r0, r1 = int(inside[0]), int(inside[-1])
    dy = y[1] - y[0] if ny > 1 else 1.0
    y_sta = y[r0] - 0.5 * dy
    if r0 > 0 and row_min[r0 - 1] > row_min[r0]:
        y_sta = y[r0] - (half - row_min[r0]) * dy / (row_min[r0 - 1] - row_min[r0])
    y_end = y[r1] + 0.5 * dy
    if r1 < ny - 1 and row_min[r1 + 1] > row_min[r1]:
        y_end = y[r1] + (half - row_min[r1]) * dy / (row_min[r1 + 1] - row_min[r1])
    y_mid = 0.5 * (y_sta + y_end)
    width = max(0.5 * (y_end - y_sta), 1e-12)
    curv_b = half / width**2
    curv_a = max(curv_a, 1e-6 * curv_b)
    a, b, *_ = hertz_ellipse(curv_a, curv_b, e_star, approach_m=delta)
    return curv_a, curv_b, y_mid, a, b, j0, i0


@njit(cache=True)
def _kpec_rows(h0, x, threshold, pressure):
    """Steps 2-3 with p_max = 1: threshold[j] per row; fills pressure; returns the longest row L_max (m)."""
    ny, nx = h0.shape
    dx = x[1] - x[0] if nx > 1 else 1.0
    lengths = np.zeros(ny)
    mids = np.zeros(ny)
    for j in range(ny):
        first = -1
        last = -1
        for i in range(nx):
            if h0[j, i] <= threshold[j]:
                if first < 0:
                    first = i
                last = i
        if first < 0:
            continue
        if first == 0:
            x_t = x[0] - 0.5 * dx
        else:
            x_t = x[first - 1] + dx * (threshold[j] - h0[j, first - 1]) / (h0[j, first] - h0[j, first - 1])
        if last == nx - 1:
            x_l = x[nx - 1] + 0.5 * dx
        else:
            x_l = x[last] + dx * (threshold[j] - h0[j, last]) / (h0[j, last + 1] - h0[j, last])
        lengths[j] = x_l - x_t
        mids[j] = 0.5 * (x_l + x_t)
    l_max = lengths.max()
    for j in range(ny):
        half = 0.5 * lengths[j]
        for i in range(nx):
            pressure[j, i] = 0.0
            if h0[j, i] <= threshold[j] and half > 0.0:
                u = x[i] - mids[j]
                pressure[j, i] = math.sqrt(max(0.0, half * half - u * u)) / (0.5 * l_max)
    return l_max


def _normal_influence_at(x, y, i0, j0, dx, dy, shear_modulus_Pa, poisson_ratio) -> np.ndarray:
    """Displacement difference at element (j0, i0) per unit uniform pressure on each element, (ny, nx), m/Pa.

    Love's rectangle coefficient (1 - nu)/(pi G) * integral of 1/r over the element, from the primitive
    X asinh(Y/|X|) + Y asinh(X/|Y|) on the element corners (as :func:`~.bem.influence.rectangle_influence`'s zz,
    evaluated once per corner).
    """
    from rigid_dynamics.contact.bem.influence import _x_asinh_y_over_x

    cx = x[i0] - (x[0] - 0.5 * dx) - dx * np.arange(x.size + 1)  # X at the element edges, decreasing
    cy = y[j0] - (y[0] - 0.5 * dy) - dy * np.arange(y.size + 1)
    gx, gy = np.meshgrid(cx, cy)
    prim = _x_asinh_y_over_x(gx, gy) + _x_asinh_y_over_x(gy, gx)
    acc = prim[:-1, :-1] - prim[:-1, 1:] - prim[1:, :-1] + prim[1:, 1:]
    return (1.0 - poisson_ratio) / (math.pi * shear_modulus_Pa) * acc


def kpec_pressure(
    undeformed_m: np.ndarray,
    x_m: np.ndarray,
    y_m: np.ndarray,
    approach_m: float,
    *,
    shear_modulus_Pa: float,
    poisson_ratio: float,
) -> KpecSolution:
    """KPEC (module docstring, steps 1-4) for approach control.

    Args:
        undeformed_m: h0 (ny, nx) >= 0 up to a constant (its minimum is subtracted), m, at element centres.
        x_m (nx,), y_m (ny,): equally spaced element centres, m.
        approach_m: delta > 0, m.
        shear_modulus_Pa, poisson_ratio: combined G, nu of the pair.
    """
    h = np.asarray(undeformed_m, float)
    h0 = h - np.nanmin(h)
    h0 = np.where(np.isfinite(h0), h0, np.inf)
    x, y = np.asarray(x_m, float), np.asarray(y_m, float)
    delta = float(approach_m)
    e_star = shear_modulus_Pa / (1.0 - poisson_ratio)
    curv_a, curv_b, y_mid, a, b, j0, i0 = _equivalent_ellipse(h0, x, y, delta, e_star)
    level = curv_a * a * a - (curv_a * a * a - curv_b * b * b) * ((y - y_mid) / b) ** 2
    threshold = np.clip(level, 0.0, delta)
    threshold[j0] = max(threshold[j0], 0.0)
    pressure = np.zeros(h0.shape)
    _kpec_rows(h0, x, threshold, pressure)
    dx = x[1] - x[0] if x.size > 1 else 1.0
    dy = y[1] - y[0] if y.size > 1 else 1.0
    u_mid = float(np.sum(_normal_influence_at(x, y, i0, j0, dx, dy, shear_modulus_Pa, poisson_ratio) * pressure))
    p_max = delta / u_mid if u_mid > 0 else 0.0
    pressure *= p_max
    contact = pressure > 0
    return KpecSolution(
        pressure,
        x,
        y,
        float(pressure.sum() * dx * dy),
        delta,
        float(a),
        float(b),
        float(curv_a),
        float(curv_b),
        float(contact.sum() * dx * dy),
    )


@njit(cache=True)
def _fastsim_rows(pressure, x, y, mu, xi, eta, phi, l1, l2, l3, tx_out, ty_out, slip_out):
    """FASTSIM along each row from its leading edge (+x) with bound mu p; returns (Fx, Fy, Mz) per unit area."""
    ny, nx = pressure.shape
    dx = x[1] - x[0] if nx > 1 else 1.0
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for j in range(ny):
        px = 0.0
        py = 0.0
        x_prev = 0.0
        started = False
        for i in range(nx - 1, -1, -1):
            tx_out[j, i] = 0.0
            ty_out[j, i] = 0.0
            slip_out[j, i] = False
            p = pressure[j, i]
            if p <= 0.0:
                px = 0.0
                py = 0.0
                started = False
                continue
            if not started:
                x_prev = x[i] + 0.5 * dx
                started = True
            step = x_prev - x[i]
            xm = 0.5 * (x_prev + x[i])
            qx = px - (xi / l1 - phi / l3 * y[j]) * step
            qy = py - (eta / l2 + phi / l3 * xm) * step
            g = mu * p
            qn = math.sqrt(qx * qx + qy * qy)
            if qn > g:
                qx *= g / qn
                qy *= g / qn
                slip_out[j, i] = True
            px = qx
            py = qy
            x_prev = x[i]
            tx_out[j, i] = qx
            ty_out[j, i] = qy
            fx += qx
            fy += qy
            mz += x[i] * qy - y[j] * qx
    return fx, fy, mz


OPTIONS = declare(
    Option("nx", int, 40, "elements along x over the rigid-overlap region", minimum=4, maximum=4096),
    Option("ny", int, 40, "elements along y over the rigid-overlap region", minimum=4, maximum=4096),
    Option("margin", float, 1.1, "enlargement of the rigid-overlap region", minimum=1.0),
)
"""Options of :class:`KpecModel`: grid ``nx`` x ``ny`` (int >= 4) over the rigid-overlap region of the patch
(enlarged by ``margin`` >= 1)."""
DEFAULTS: dict = option_defaults(OPTIONS)


class KpecModel:
    """KPEC normal method + FASTSIM on its patch (module docstring): the registered model ``kpec``.

    The geometry's sampled undeformed distance is used if present (``geometry.undeformed``), else its quadric.
    The grid covers the rigid-overlap region {h <= 0} at the approach (force control: at each secant step),
    widened by ``margin``. Forces on the wheel, contact frame; fields on the grid.
    """

    name = "kpec"
    description = "KPEC semi-Hertzian normal + FASTSIM (non-elliptic patches)"
    OPTIONS = OPTIONS

    def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None):
        """One patch (see the class docstring); :class:`~.types.ContactResult`."""
        from rigid_dynamics.contact.fastsim import effective_flexibilities
        from rigid_dynamics.contact.kalker import kalker_coefficients
        from rigid_dynamics.contact.models import _options
        from rigid_dynamics.contact.types import ContactFields, ContactResult

        start = time.perf_counter()
        opts = _options(options, self.OPTIONS, self.name)
        for key in ("nx", "ny"):
            value = opts[key]
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 4:
                raise ValueError(f"kpec: option {key} = {value!r}: expected an integer >= 4")
        margin = opts["margin"]
        if isinstance(margin, bool) or not isinstance(margin, (int, float)) or not margin >= 1:
            raise ValueError(f"kpec: option margin = {margin!r}: expected a number >= 1")
        if normal_force_N is not None and (not math.isfinite(normal_force_N) or normal_force_N <= 0):
            raise ValueError(f"normal_force_N = {normal_force_N!r}: expected None or a finite number > 0")
        g_mod, nu, mu = material.shear_modulus_Pa, material.poisson_ratio, material.friction_coefficient
        h_min = _minimum_gap(geometry)

        def solve_at(delta: float) -> KpecSolution:
            x, y = _overlap_grid(geometry, h_min + delta, h_min, int(opts["nx"]), int(opts["ny"]), float(margin))
            xx, yy = np.meshgrid(x, y)
            return kpec_pressure(geometry.gap_m(xx, yy), x, y, delta, shear_modulus_Pa=g_mod, poisson_ratio=nu)

        iterations = 0
        if normal_force_N is None:
            delta = -h_min
            if delta <= 0:
                return _no_contact(self.name, geometry, creepage, start, f"approach {delta!r} m <= 0: no contact")
            sol = solve_at(delta)
        else:
            delta = _hertz_start_delta(geometry, normal_force_N, g_mod / (1 - nu))
            sol = solve_at(delta)
            prev = None
            for iterations in range(1, 40):  # noqa: B007
                if abs(sol.normal_force_N / normal_force_N - 1.0) < 1e-10:
                    break
                slope = 1.5
                if prev is not None and prev[1] != sol.normal_force_N and prev[0] != delta:
                    slope = math.log(sol.normal_force_N / prev[1]) / math.log(delta / prev[0])
                    slope = min(max(slope, 0.5), 3.0)
                prev = (delta, sol.normal_force_N)
                delta *= (normal_force_N / sol.normal_force_N) ** (1.0 / slope)
                sol = solve_at(delta)
        converged = normal_force_N is None or abs(sol.normal_force_N / normal_force_N - 1.0) < 1e-8
        coef = kalker_coefficients(sol.semi_axis_long_m / sol.semi_axis_lat_m, nu)
        l1, l2, l3 = effective_flexibilities(
            sol.semi_axis_long_m,
            sol.semi_axis_lat_m,
            sol.normal_force_N,
            creepage.longitudinal,
            creepage.lateral,
            creepage.spin_1_per_m,
            shear_modulus_Pa=g_mod,
            friction_coefficient=mu,
            coefficients=coef,
            flexibility="three",
        )
        tx = np.zeros(sol.pressure_Pa.shape)
        ty = np.zeros(sol.pressure_Pa.shape)
        slip = np.zeros(sol.pressure_Pa.shape, dtype=np.bool_)
        fx, fy, mz = _fastsim_rows(
            sol.pressure_Pa, sol.x_m, sol.y_m, mu, creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m,
            float(l1), float(l2), float(l3), tx, ty, slip,
        )  # fmt: skip
        dx = sol.x_m[1] - sol.x_m[0]
        dy = sol.y_m[1] - sol.y_m[0]
        area = dx * dy
        contact = sol.pressure_Pa > 0
        fields = ContactFields(
            x_m=sol.x_m,
            y_m=sol.y_m,
            pressure_Pa=sol.pressure_Pa,
            traction_long_Pa=tx,
            traction_lat_Pa=ty,
            in_contact=contact,
            in_slip=slip,
        )
        return ContactResult(
            method=self.name,
            success=bool(converged),
            status="ok" if converged else "not-converged",
            message="KPEC + FASTSIM" if converged else f"force control did not converge in {iterations} steps",
            normal_force_N=sol.normal_force_N,
            creep_force_long_N=float(fx * area),
            creep_force_lat_N=float(fy * area),
            spin_moment_Nm=float(mz * area),
            max_pressure_Pa=float(sol.pressure_Pa.max()),
            semi_axis_long_m=sol.semi_axis_long_m if geometry.is_elliptic else None,
            semi_axis_lat_m=sol.semi_axis_lat_m if geometry.is_elliptic else None,
            contact_area_m2=sol.contact_area_m2,
            approach_m=float(geometry.approach_m + (sol.approach_m + h_min)),
            creepage=creepage,
            fields=fields,
            iterations=int(iterations),
            wall_time_s=time.perf_counter() - start,
            extra={
                "nx": int(opts["nx"]),
                "ny": int(opts["ny"]),
                "equivalent_ellipse_m": [sol.semi_axis_long_m, sol.semi_axis_lat_m],
                "equivalent_curvatures_1_per_m": [sol.curvature_long_1_per_m, sol.curvature_lat_1_per_m],
                "penetration_m": sol.approach_m,
            },
        )


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
