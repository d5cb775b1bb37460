"""The steady-rolling creep force of the FEA with a stated discretisation error, from a constant-ratio mesh series.

One mesh gives a creep force whose error is not known: :func:`fea.friction.solve_rolling` collocates Coulomb's law at
the face nodes, which makes the force too large by a first-order error (Carter's two-dimensional closed form,
tests/test_fea_rolling.py). Its size can be stated only from a series of meshes on which the error is a regular
function of the element size h: the rolling block of :mod:`meshing.rolling_block` (a structured box of cubes under
the patch, its face rows along the rolling direction x, each row's contact nodes ending on the expected patch edge),
at n, r n, r^2 n elements per semi-axis (the same grid scaled by 1/r).

From the three forces F_1, F_2, F_3 (coarse to fine) the observed order is p = ln((F_1 - F_2)/(F_2 - F_3))/ln r
(Richardson; Roache 1998, ch. 5). The stated error of the finest force is the Richardson estimate of its distance
to the limit, |F_3 - F_2|/(r^q - 1) with q = min(p, 1): the first order that Carter's case shows (the proven
order of the nodal stick/slip boundary), or the observed order when that is lower. With p > 1 this overstates the
error (measured on the Hertz circle: p = 1.6 to 1.9, the first-order estimate about twice the error against the BEM,
benchmarks/results/fea_friction.md); the extrapolation with the observed order, F_3 + (F_3 - F_2)/(r^p - 1), is
returned beside it. The series is "irregular" (no error stated, a status, never a number) when the differences
change sign or p falls outside [0.5, 4].

Resolution: the series states an error only when every level resolves the slip zone (at least as many slip nodes
as face rows in contact). At small creepage the slip zone at the trailing edge is narrower than a cell (Carter:
2 (a - c) = 2 a xi R/(mu a), 0.04 a at the circle's xi = 5e-5), every row sticks to its last node, and the force is
the no-slip discretisation's, whose traction is singular at the trailing edge: measured on the circle at xi = 5e-5,
+21.2/+10.8/+6.6/+3.0 % at n = 4/6/9/13.5, observed order 2.2 from 4/6/9 but 0.43 from 6/9/13.5 (a first-order
estimate from 6 and 9 would state 8.5 % on n = 9, and was right only by the luck of the coarse meshes). Such a
series is "unresolved", a status. A fully sliding patch (no stick node) has F = mu P on every mesh.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

ORDER_RANGE = (0.5, 4.0)


@dataclass(frozen=True)
class SeriesEstimate:
    """Richardson estimate of one quantity from three meshes at a constant ratio.

    Attributes:
        status: "ok" or "irregular" (no error stated; ``message`` says why).
        message: explanation.
        value: the finest mesh's value.
        stated_error: |F_3 - F_2|/(r^q - 1), q = min(p, 1): the stated error of ``value`` (nan unless "ok").
        observed_order: p (nan when the differences change sign or vanish).
        extrapolated: F_3 + (F_3 - F_2)/(r^p - 1) (nan unless "ok").
        ratio: r = n_2/n_1 = n_3/n_2.
    """

    status: str
    message: str
    value: float
    stated_error: float
    observed_order: float
    extrapolated: float
    ratio: float


def richardson_estimate(elements, values, *, order_range=ORDER_RANGE) -> SeriesEstimate:
    """Observed order, extrapolation and stated error of the last of three values on meshes n_1 < n_2 < n_3.

    Args:
        elements: (n_1, n_2, n_3), elements per semi-axis at a constant ratio r = n_2/n_1 = n_3/n_2 > 1.
        values: the quantity on each mesh.
        order_range: the observed orders accepted as regular.

    Raises:
        ValueError: not three finite values, or the meshes not at a constant ratio > 1.
    """
    n1, n2, n3 = (float(v) for v in elements)
    f1, f2, f3 = (float(v) for v in values)
    if not all(math.isfinite(v) for v in (n1, n2, n3, f1, f2, f3)):
        raise ValueError(f"elements = {elements!r}, values = {values!r}: expected three finite numbers each")
    if not (0 < n1 < n2 < n3) or abs(n3 / n2 - n2 / n1) > 1e-6 * (n2 / n1):
        raise ValueError(f"elements = {elements!r}: expected a constant ratio n2/n1 = n3/n2 > 1")
    r = n2 / n1
    d12, d23 = f1 - f2, f2 - f3
    nan = math.nan
    if d12 * d23 <= 0:
        return SeriesEstimate(
            "irregular", f"the differences {d12:.6g}, {d23:.6g} change sign or vanish", f3, nan, nan, nan, r
        )
    p = math.log(d12 / d23) / math.log(r)
    if not (order_range[0] <= p <= order_range[1]):
        return SeriesEstimate(
            "irregular", f"observed order {p:.3g} outside [{order_range[0]:g}, {order_range[1]:g}]", f3, nan, p, nan, r
        )
    q = min(p, 1.0)
    return SeriesEstimate(
        "ok",
        f"observed order {p:.3g}; error stated with order {q:.3g}",
        f3,
        abs(d23) / (r**q - 1.0),
        p,
        f3 - d23 / (r**p - 1.0),
        r,
    )


@dataclass(eq=False)
class RollingSeries:
    """Creep force of steady rolling with its stated error from a mesh series (:func:`solve_rolling_series`).

    Attributes:
        status: "ok", "irregular" (the series does not state an error), "unresolved" (the slip zone is narrower
            than a cell on some level: fewer slip nodes than face rows in contact; no error stated) or
            "not-converged" (a level failed).
        message: explanation.
        creep_force_N: (F_x, F_y) on the wheel, the finest mesh's, N.
        stated_error_N: (e_x, e_y), stated error of each component, N (nan unless "ok").
        extrapolated_N: (F_x, F_y) extrapolated with the observed order, N (nan unless "ok").
        observed_order: (p_x, p_y).
        estimates: (x, y) :class:`SeriesEstimate`.
        levels: per mesh: {"n", "dofs", "contact_nodes", "creep_force_N", "status", "cpu_s"}.
    """

    status: str
    message: str
    creep_force_N: tuple
    stated_error_N: tuple
    extrapolated_N: tuple
    observed_order: tuple
    estimates: tuple
    levels: list = field(default_factory=list)


def solve_rolling_series(
    semi_axis_long_m: float,
    semi_axis_lat_m: float,
    gap_function,
    young_modulus_Pa: float,
    poisson_ratio: float,
    friction_coefficient: float,
    normal_force_N: float,
    creepage: tuple[float, float, float],
    *,
    elements: tuple[float, float, float] = (4.0, 6.0, 9.0),
    initial_approach_m: float | None = None,
    domain_factor: float = 10.0,
    insignificant_fraction: float = 5e-3,
) -> RollingSeries:
    """Steady rolling on three rolling blocks (n, r n, r^2 n elements per semi-axis) and the force's stated error.

    Each level: :func:`fea.domain.rolling_block_domain` (edge-fitted rows), the frictionless normal solve under
    ``normal_force_N`` (:func:`fea.solver.solve_rigid_indenter`), :func:`fea.friction.solve_rolling` with the step
    h/2; then :func:`richardson_estimate` per force component.

    Args:
        semi_axis_long_m, semi_axis_lat_m: the expected patch's semi-axes a (along x, rolling) and b, m.
        gap_function: h(x_m, y_m) of the rigid indenter (the pair's undeformed gap), m.
        young_modulus_Pa, poisson_ratio: the equivalent block's constants (E* (1 - nu^2) for two equal bodies).
        friction_coefficient: mu.
        normal_force_N: P.
        creepage: (xi, eta, phi).
        elements: (n_1, n_2, n_3) at a constant ratio (coarse to fine).
        initial_approach_m: first guess of the approach (e.g. Hertz's).
        domain_factor: block half-width in units of max(a, b).
        insignificant_fraction: a component whose three forces all stay below this fraction of the largest force
            magnitude of the series is reported without an order, its error stated as its largest magnitude (e.g.
            F_y of a pure longitudinal creepage: zero by the box's symmetry, up to 8e-4 of F_x measured, the
            unstructured rest of the block not being symmetric).

    Returns:
        :class:`RollingSeries`; a failed level or an irregular series is a status. Serial only.
    """
    import dolfinx_solver  # noqa: F401
    import numpy as np

    from fea.domain import rolling_block_domain
    from fea.friction import solve_rolling
    from fea.solver import solve_rigid_indenter
    from meshing.rolling_block import RollingBlockSpec

    short = min(semi_axis_long_m, semi_axis_lat_m)
    levels = []
    nan2 = (math.nan, math.nan)
    for n in elements:
        t0 = time.process_time()
        spec = RollingBlockSpec(semi_axis_long_m, semi_axis_lat_m, float(n), domain_factor=domain_factor)
        domain = rolling_block_domain(spec)
        normal = solve_rigid_indenter(
            domain, gap_function, young_modulus_Pa, poisson_ratio, normal_force_N=normal_force_N,
            initial_approach_m=initial_approach_m, length_scale_m=short,
        )  # fmt: skip
        if not normal.success:
            return RollingSeries(
                "not-converged", f"n = {n:g}: normal solve {normal.status}: {normal.message}", nan2, nan2, nan2,
                nan2, (), levels,
            )  # fmt: skip
        sol = solve_rolling(
            domain, normal, young_modulus_Pa, poisson_ratio, friction_coefficient, creepage,
            step_m=spec.contact_size_m / 2, length_scale_m=short, row_transport=True,
        )  # fmt: skip
        levels.append(
            {
                "n": float(n),
                "dofs": sol.dofs,
                "contact_nodes": len(sol.node_xy_m),
                "creep_force_N": tuple(sol.creep_force_N),
                "slip_nodes": int(np.count_nonzero(~sol.stick)),
                "rows": len(np.unique(np.round(sol.node_xy_m[:, 1] / spec.contact_size_m))),
                "status": sol.status,
                "cpu_s": time.process_time() - t0,
            }
        )
        if not sol.success:
            return RollingSeries(
                "not-converged", f"n = {n:g}: rolling {sol.status}: {sol.message}", nan2, nan2, nan2, nan2, (), levels
            )
    return series_from_levels(levels, elements, insignificant_fraction=insignificant_fraction)


def series_from_levels(levels: list, elements, *, insignificant_fraction: float = 5e-3) -> RollingSeries:
    """The decision of :func:`solve_rolling_series` from its three levels (module docstring: statuses and rules).

    Args:
        levels: per mesh, coarse to fine: {"n", "creep_force_N": (F_x, F_y), "contact_nodes", "slip_nodes",
            "rows" (face rows holding contact nodes), ...}.
        elements: (n_1, n_2, n_3).
        insignificant_fraction: see :func:`solve_rolling_series`.
    """
    nan2 = (math.nan, math.nan)
    if all(lv["creep_force_N"] == (0.0, 0.0) for lv in levels):
        zero = (0.0, 0.0)
        return RollingSeries("ok", "no creepage: F = 0 on every mesh", zero, zero, zero, nan2, (), levels)
    unresolved = [lv["n"] for lv in levels if lv["slip_nodes"] < lv["rows"]]
    if unresolved:
        return RollingSeries(
            "unresolved",
            f"n = {', '.join(f'{n:g}' for n in unresolved)}: fewer slip nodes than rows (the slip zone narrower than "
            "a cell: the no-slip regime, whose singular trailing edge converges at an order below 1)",
            nan2, nan2, nan2, nan2, (), levels,
        )  # fmt: skip
    if all(lv["slip_nodes"] == lv["contact_nodes"] for lv in levels):
        final = levels[-1]["creep_force_N"]
        spread = tuple(max(abs(lv["creep_force_N"][k] - final[k]) for lv in levels) for k in (0, 1))
        return RollingSeries(
            "ok", "the whole patch slides on every mesh: F = mu P along the slip (error: the levels' spread)",
            tuple(final), spread, tuple(final), nan2, (), levels,
        )  # fmt: skip
    estimates = []
    magnitude = max(math.hypot(*lv["creep_force_N"]) for lv in levels)
    for k in (0, 1):
        values = [lv["creep_force_N"][k] for lv in levels]
        largest = max(abs(v) for v in values)
        if largest <= insignificant_fraction * magnitude:
            estimates.append(
                SeriesEstimate("ok", "below the significant force", values[-1], largest, math.nan, values[-1], 0.0)
            )
        else:
            estimates.append(richardson_estimate(elements, values))
    bad = [f"F_{'xy'[k]}: {e.message}" for k, e in enumerate(estimates) if e.status != "ok"]
    return RollingSeries(
        status="irregular" if bad else "ok",
        message="; ".join(bad) if bad else "; ".join(f"F_{'xy'[k]}: {e.message}" for k, e in enumerate(estimates)),
        creep_force_N=tuple(e.value for e in estimates),
        stated_error_N=tuple(e.stated_error for e in estimates),
        extrapolated_N=tuple(e.extrapolated for e in estimates),
        observed_order=tuple(e.observed_order for e in estimates),
        estimates=tuple(estimates),
        levels=levels,
    )
