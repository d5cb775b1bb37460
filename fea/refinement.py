"""The FEA's discretisation error: a refinement series with Richardson's estimate, run until a tolerance is met.

Estimate. Level k solves on the mesh with n_k = n_0 r^k elements per semi-axis at the patch and the grading
g_k = g_0 / r^k away from it (the whole mesh is refined by r, not only the patch: with a fixed grading the
approach of the Hertz case stagnated at -4.8 % from 12 to 18 elements per semi-axis while the patch converged).
For a quantity Q with Q_k = Q + C h_k^p + ..., the error of the finest level is (Richardson)

    e_k = |Q_k - Q_{k-1}| / (r^p - 1),

with p the observed order log(|Q_{k-1} - Q_{k-2}| / |Q_k - Q_{k-1}|) / log r of the last three levels, clipped to
[0.5, 1]: the contact edge moves by whole elements, so the pressure and the area carry a first-order term
(observed 1.0-1.2 for the L1 error of the pressure, tests/test_fea_contact.py), and a larger observed order over
three levels is as often a coincidence of the scattered nodal values as a property of the method: the cap keeps
the estimate on the safe side. With two levels p = 1. When the last difference collapses (observed order above 3,
beyond the method's), the values have crossed their limit by chance (the Hertz area: 0.31 % then 0.01 %) and
|Q_{k-1} - Q_{k-2}| / r^p replaces |Q_k - Q_{k-1}|. A second solve on a finer mesh was chosen over an
a-posteriori (residual) estimator because the quantities asked for (max pressure, area, force of a contact
problem) are not energy-norm quantities: a residual estimator bounds the energy error, not them, and needs the
same refined solve to calibrate its constant.

Block size. The "rigid" and "two-body" formulations truncate the half-space at a clamped block of half-width
D = ``domain_factor`` max(a, b). The approach (load control) and the force (approach control) depend on the
compliance of the whole block and decay as 1/D (Hertz case, P2: -2.08 %, -1.10 %, -0.62 % at D = 20, 40, 80
semi-axes, a decay D^-s with s = 0.92 then 0.83): one more solve on the first level's mesh with 2 D estimates the
truncation error as |Q(2D) - Q(D)| / (1 - 2^-s) with s = 0.75 (``BLOCK_DECAY_ORDER``), added to the mesh error.
The max pressure feels the block less, and at a fixed load (load control) only at second order: the truncation
changes the compliance far from the patch, i.e. nearly uniformly over it, which moves the approach and not the
pressure. P2 Hertz case (0.46 / 0.15 m, 100 kN, 4 and 6 elements per semi-axis): max pressure -0.104, -0.135,
-0.131, -0.122 % and +0.025, +0.009, -0.015, -0.011 % at D = 10, 20, 40, 80 while the approach moved 2.0, 1.0,
0.5 %; on the demo's sampled peak patch (P1, peak box) 975.9 / 976.4 / 979.2 MPa at one level and 965.8 / 964.1 /
962.6 at the next: the difference of the two blocks' meshes is their scatter (0.15-0.6 % between two meshes of the
same nominal size), not the truncation. Under load control the max pressure therefore gets the fixed second-order
term ``LOAD_CONTROL_BLOCK_ERROR`` (0.5 % (20 / D)^2, at least ten times the P2 measurement; it keeps the compare
test's Hertz circle bracketed: 0.37 % true against 0.26 % mesh error stated), not the two blocks' difference
(which had stated 1.34 % on the demo's patch, 2.5 times its 0.53 % mesh scatter).
Under approach control (the wheelset equilibrium) the two blocks' coarse meshes differ at the patch, and their max
pressures differ by that mesh's scatter, not by the truncation: on the manchester-a22 flange patch (P2, 3 elements
per semi-axis) 1414 against 1546 MPa (9 %) while the force moved 0.9 %; there the truncation acts as a change of the
approach felt by the patch, N ~ q^(3/2) and p ~ q^(1/2), and the max pressure's block-size error is a third of the
force's (``PRESSURE_PER_FORCE``).
The area's truncation error (about -0.3 % at D = 20) is below the scatter of the area between the two blocks'
meshes (the estimate then said 2.2 % on the P2 Hertz series whose true area error was 0.3 %): it is not
estimated, and the area's stated error is its mesh error alone.

Oscillating series. When the last two differences have opposite signs (the contact edge and the nodal scatter
move the value up and down from one mesh to the next: the area of the A-2.2 tread patch 27.93, 28.26, 27.86 mm2 at
one load), Richardson's model Q_k = Q + C h_k^p does not hold and the observed order means nothing; the error is
then the range of the last three levels (Stern, Wilson, Coleman & Paterson, J. Fluids Eng. 123 (2001) 793-802,
take half the range for oscillatory convergence; the full range is a factor of safety of two).

Collapse after a measured order. With four levels or more, a last difference that collapses (observed order above
``CROSSING_ORDER``) follows three levels whose own order was measured. The demo's peak patch (polygonal-wheel, 99 kN,
window fit): 1016.4, 982.5, 967.4, 964.7 MPa at 4, 6, 9, 13.5 elements per semi-axis, differences 33.9, 15.1, 2.7
(orders 2.0, then 4.2), against the half-space BEM's converged 965.8 MPa (512 x 512 elements; 0.11 % from the finest
level, the block's second-order term 0.125 %): the crossing rule at the capped order 1 stated 15.1 / 1.5 / 0.5 =
20.2 MPa (2.1 %, 18 times the difference from the BEM). The earlier order (2.0, clipped to
``EARLIER_ORDER_BOUNDS``) then replaces the cap, for the reduction of the previous difference and in the
denominator: 15.1 / 1.5^2 / (1.5^2 - 1) = 5.4 MPa (0.56 %, five times that difference, twice the difference plus
the block's term). Three levels keep the capped order (the A-2.2 flange-root series below: a crossing whose limit lay
beyond the previous level, where only the capped order brackets).

Area of a sampled patch. A sampled patch's area is the sum of the active nodes' lumped areas (a quadric's is the
fitted ellipse's, estimated as the other quantities). Its error has two parts: a first-order bias (the P1 block is
stiff, so at a fixed load its contact is small: the demo's peak patch 183.5, 187.8, 186.4, 187.4 mm2 at 4 ... 13.5
elements per semi-axis against the BEM's converged 189.3-189.7; a Hertz gap given as samples 230.5, 233.3, 235.3
against 235.7 at 4, 6, 9), and a scatter of a fraction of the boundary nodes' areas from mesh to mesh (which nodes
the edge happens to enclose). Richardson's model holds for neither: the last two levels of the demo stated 0.74 %
(the oscillation range) where the true error was 1.0-1.25 %. The estimate (:func:`nodal_area_error`) is the
least-squares line A_k = A + C h_k over all levels, |A_last - A| plus the rms residual about the line: 1.76 % on the
demo (1.4-1.7 times the true error), 1.65 % on the Hertz samples (9 times the true 0.18 %, which converged faster
than first order there; benchmarks/results/area_edge_error.md).

Load-balanced use (option ``load_balanced``: a wheelset equilibrium that balances each wheel's load with the FEA's own
force). Each level is solved at the same approach, so its force differs from the finest level's by the mesh's
stiffness error (4-6 % from 6 to 13.5 elements per semi-axis on the A-2.2 patches, 12 % per level on the flange root),
and the max pressure and area of the levels differ by that load change as much as by the mesh. What the equilibrium
reports is the patch at its load, so every level coarser than the finest is solved again on its own mesh under load
control at the finest level's force N_f (``finest_force``; a coarser level put before the first is solved there at
once), and the max pressure and area of the series are those at N_f: no assumption on how the patch grows with the
load. Hertz's scaling, p (N_f/N_k)^(1/3), A (N_f/N_k)^(2/3) (Johnson 1985, eq 3.64), was used before and is kept only
for a solve that takes no force (``LOAD_SCALING``): on the A-2.2 flange root, a conformal strip whose area the BEM on
the same gap finds growing as N^1.12 and max pressure as N^0.22 (9960 to 11008 N), it turned the levels' areas at one
load into an oscillation and understated the area's error (3.11 % stated, 4.3 % from the BEM at the same force). At
the BEM's pose (N_f 10484 N; 2.67, 4, 6 elements per semi-axis, the two coarser put before the first) the levels at
N_f are 15.53, 15.85, 16.00 mm2 and 1653.6, 1606.7, 1576.6 MPa, stated 2.92 % and 4.56 % (mesh 3.81 %); Hertz's
scaling had made them 15.86, 16.20, 16.00 mm2 (an oscillation) and 1629.8, 1597.3, 1576.6 MPa, stating 3.11 % and
3.37 %. The two coarser levels' solves at their own and at N_f give the exponents 0.216 / 0.215 (p) and 0.84 / 1.12
(area). Cost: a load-control solve costs what an approach-control one does (one factorisation per active-set iteration);
a level coarser than a new finest level is solved once more at its force (one coarse solve for a first estimate of two
levels; the flange root's two coarser levels, put before the first, none).
Measuring the exponents on the coarsest mesh instead (one more solve there at another approach) was tried and left:
the max pressure's came out right (0.215-0.226 on the flange root, 0.31-0.34 on the Hertz quadric), but the area's
moves by whole boundary nodes on that mesh (0.71 to 1.41 on the flange root for 14 to 38 % less force, against the
BEM's 1.12; 0.49 to 0.66 on the Hertz quadric; 0.08 to 0.18 against the closed form's 0.4 on an r^4 punch).
Where Hertz holds the two agree: on the Hertz quadric (tests/test_fea_refinement.py) the coarse level's own and
finest-force values give the exponents 0.305 and 0.615 (1/3 and 2/3 of the closed form).
The force itself is not judged: its mesh and block errors are a compliance error, i.e. an error of the approach at the
load, which the equilibrium absorbs (the block check is not run; its mesh error is estimated and reported over the
levels solved at their own force, the finest and those solved before it: none when the coarser levels were all put
before the first, as on the flange root, where it is then unknown). The block's truncation then matters only through its
second-order effect on the pressure distribution at a fixed load (its first-order effect, an offset of the whole contact
face, is an approach change): measured on the Hertz case under load control, +0.5 % in p0 and -0.3 % in area at D = 20
semi-axes (the block check's coarse meshes differ at the patch by more than that, so it is not measured per case), added
as those values times (20 / D)^2 (``LOAD_CONTROL_BLOCK_ERROR``). The equilibrium accepts a wheel's load within
``LOAD_SHARE`` of the tolerance (``load_tolerance`` in the estimate): a load error e moves the area by 2 e / 3 and the
max pressure by e / 3 on a Hertz patch (by 1.1 e and 0.22 e on the flange root).

Measured order (``measure_order``: sampled patches). With two levels the order is assumed (1), which is
conservative only if the quantity converges at order 1 or faster. On the A-2.2 flange-root patch (a strip 1.4 mm
wide, 2 to 5 elements across its half width at 4, 6, 9 elements per semi-axis of its box) the max pressure brought
to one load went 1637, 1557, 1543 MPa with the default fit and 1614, 1573, 1537 MPa with a fit window that does not
shrink with h (observed order 0.27): pre-asymptotic, and the two finest levels alone stated a mesh error of 1.90 %
where the difference from CONTACT's converged 1572 MPa is 1.87 % (benchmarks/results/fea_flange_root_order.md).
A sampled patch's series therefore solves one level coarser than its first before its first estimate (a third of
the first level's cost), so that every estimate has an observed order: a slower one is then used (down to 0.5), a
crossing or an oscillation caught, and the status follows.

Tolerance. The max pressure, the contact area and, under approach control, the normal force are judged (their
relative error estimate <= ``mesh_tolerance``); the approach, the semi-axes and the largest von Mises stress are
estimated and reported. The series stops when the judged estimates meet the tolerance (status "ok"), or when the
next level would exceed ``max_dofs`` (predicted from the growth of the unknowns between the last two levels;
status "mesh-tolerance-not-met", ``success`` True: the numbers are a solution, with a larger error than asked).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time

REFINEMENT_RATIO = 1.5
"""r, the ratio of the element sizes of two successive levels."""
ORDER_BOUNDS = (0.5, 1.0)
"""The observed order used in Richardson's estimate is clipped to this range (module docstring)."""
CROSSING_ORDER = 3.0
"""An observed order above this (the last difference fell by more than r^3) is taken as the sequence crossing its
limit by chance: the estimate then uses the previous difference reduced at the order used (module docstring)."""
EARLIER_ORDER_BOUNDS = (0.5, 2.0)
"""When the last difference collapses after a power law measured over the three levels before it (four levels or
more), that earlier order, clipped to this range, replaces the cap of ``ORDER_BOUNDS`` (module docstring, "Collapse
after a measured order")."""
BLOCK_DECAY_ORDER = 0.75
"""s of the block-size error C D^-s: measured 0.92 and 0.83 for the Hertz approach from D = 20 to 40 to 80; the error
of Q(D) is |Q(2D) - Q(D)| / (1 - 2^-s), 2.5 times the difference with s = 0.75 (2 with s = 1)."""
NODAL_KEY = "contact_area_is_nodal"
"""A level's flag: its contact area is the sum of its active nodes' lumped areas (a sampled patch; a quadric's is the
fitted ellipse's), estimated by :func:`nodal_area_error` (module docstring, "Area of a sampled patch")."""
JUDGED = ("max_pressure", "contact_area", "normal_force")
"""Quantities whose relative error estimate must meet ``mesh_tolerance``."""
PRESSURE_PER_FORCE = 1.0 / 3.0
"""Under approach control, the relative block-size error of the max pressure per that of the normal force: the
truncated block changes the compliance far from the patch, i.e. the approach felt by the patch, and at a fixed patch
shape N ~ q^(3/2), p ~ q^(1/2) (Hertz, Johnson 1985 eq 3.64), so dp/p = dN/(3 N) (module docstring)."""
BLOCK_SENSITIVE = ("normal_force", "approach", "max_pressure")
"""Quantities with an estimated block-size (truncation) error (module docstring)."""
LOAD_SCALING = {"max_pressure": 1.0 / 3.0, "contact_area": 2.0 / 3.0, "semi_axis_long": 1.0 / 3.0,
                "semi_axis_lat": 1.0 / 3.0, "max_von_mises": 1.0 / 3.0}  # fmt: skip
"""Exponents e of Q ~ N^e at a fixed patch shape (Hertz, Johnson 1985 eq 3.64). A load-balanced series solves its
coarser levels at the finest level's force (``FORCE_KEY``) and needs no scaling; a level given only at its own force
(a caller whose solve takes no force) is brought to the finest level's with these, which holds for Hertz patches only
(module docstring, "Load-balanced use")."""
FORCE_KEY = "solved_at_force"
"""A level's record: the force, N, at which its max pressure, area, semi-axes, von Mises and approach were solved (load
control on its own mesh) when that is not its own force under approach control, which stays its ``normal_force``."""
LOAD_CONTROL_BLOCK_ERROR = {"max_pressure": 0.005, "contact_area": 0.003}
"""Relative error of the max pressure and the area at a fixed load from the block's truncation at D = 20 semi-axes,
measured on the Hertz case (module docstring); scaled by (20 / D)^2. Used under load control for the max pressure
and by a load-balanced series for both (module docstring)."""
ORDER_LEVEL_MIN_N = 2.0
"""With ``measure_order``, the level one coarser than the first is solved when it has at least this many elements per
semi-axis (module docstring, "Measured order")."""
FIRST_LEVEL_BUDGET_COARSER = 2
"""When the first level is already the finest ``max_dofs`` affords (a narrow patch: a22-flange's first level has
1.7e5 unknowns), this many coarser levels are solved before it so that it is still estimated (at the observed order
of three levels) instead of ending "not estimated"."""
LOAD_SHARE = 0.25
"""A load-balanced equilibrium accepts a wheel's load within this fraction of ``mesh_tolerance`` (module docstring)."""


def _quantities(result) -> dict[str, float | None]:
    """The estimated quantities of one level's :class:`ContactResult`."""
    extra = result.extra
    nodal_area = extra.get("contact_area_nodal_m2") is not None and extra["contact_area_nodal_m2"] == (
        result.contact_area_m2
    )  # a sampled patch: the area is the active nodes' (a quadric's is the fitted ellipse's)
    return {
        "max_pressure": result.max_pressure_Pa,
        "contact_area": result.contact_area_m2,
        NODAL_KEY: True if nodal_area else None,
        "normal_force": result.normal_force_N,
        "approach": result.approach_m,
        "semi_axis_long": result.semi_axis_long_m,
        "semi_axis_lat": result.semi_axis_lat_m,
        "max_von_mises": extra.get("max_von_mises_Pa"),
    }


def richardson_error(values: list[float], ratio: float = REFINEMENT_RATIO) -> tuple[float, float, float | None]:
    """Richardson's error estimate of the last of ``values`` (coarse to fine, at least two; module docstring).

    Returns:
        (absolute error estimate, order used, observed order or None when fewer than three levels or a
        difference is zero).
    """
    if len(values) < 2:
        raise ValueError(f"values = {values!r}: expected at least two levels")
    d_last = abs(values[-1] - values[-2])
    observed = None
    if len(values) >= 3:
        d_prev = abs(values[-2] - values[-3])
        if d_last > 0 and d_prev > 0:
            observed = math.log(d_prev / d_last) / math.log(ratio)
    lo, hi = ORDER_BOUNDS
    order = hi if observed is None else min(max(observed, lo), hi)
    if len(values) >= 3 and (values[-1] - values[-2]) * (values[-2] - values[-3]) < 0:
        # oscillating: no power law; the range of the last three levels (Stern et al. 2001, safety factor 2)
        return max(values[-3:]) - min(values[-3:]), order, observed
    if len(values) >= 3 and (observed is None or observed > CROSSING_ORDER):
        earlier = _earlier_order(values, ratio)
        if earlier is not None:  # four levels or more: the collapse reduced at the order measured before it
            order = earlier
        d_last = max(d_last, abs(values[-2] - values[-3]) / ratio**order)  # a crossing, not convergence
    return d_last / (ratio**order - 1.0), order, observed


def _earlier_order(values: list[float], ratio: float) -> float | None:
    """The order observed over the three levels before the last (module docstring, "Collapse after a measured
    order"), clipped to ``EARLIER_ORDER_BOUNDS``; None with fewer than four levels, or when those three do not
    follow a power law (differences of opposite sign or zero, or their own collapse).
    """
    if len(values) < 4:
        return None
    d_prev, d_before = values[-2] - values[-3], values[-3] - values[-4]
    if d_prev * d_before <= 0:
        return None
    earlier = math.log(abs(d_before) / abs(d_prev)) / math.log(ratio)
    if not ORDER_BOUNDS[0] <= earlier <= CROSSING_ORDER:
        return None
    return min(earlier, EARLIER_ORDER_BOUNDS[1])


def nodal_area_error(values: list[float], ratio: float = REFINEMENT_RATIO) -> float:
    """Absolute error of the last of ``values`` (coarse to fine; element size h_k = r^-k), the nodal contact area of
    a sampled patch (module docstring, "Area of a sampled patch"): the least-squares line A_k = A + C h_k over all
    levels, |A_last - A| + the rms residual about the line (n - 2 degrees of freedom); with two levels first-order
    Richardson, |d| / (r - 1).
    """
    if len(values) < 2:
        raise ValueError(f"values = {values!r}: expected at least two levels")
    if len(values) == 2:
        return abs(values[1] - values[0]) / (ratio - 1.0)
    h = [ratio**-k for k in range(len(values))]
    mean_h, mean_a = sum(h) / len(h), sum(values) / len(values)
    slope = sum((x - mean_h) * (v - mean_a) for x, v in zip(h, values, strict=True)) / sum((x - mean_h) ** 2 for x in h)
    limit = mean_a - slope * mean_h
    residuals = [v - limit - slope * x for x, v in zip(h, values, strict=True)]
    scatter = math.sqrt(sum(r * r for r in residuals) / (len(values) - 2))
    return abs(values[-1] - limit) + scatter


def _relative(error: float, value: float | None) -> float | None:
    if value is None or not math.isfinite(value) or value == 0:
        return None if error == 0 or value is None else math.inf
    return error / abs(value)


def estimate(
    levels: list[dict], block: dict | None, approach_control: bool = False, load_balanced: bool = False,
    block_factor: float = 20.0, block_level: int = 0,
) -> dict:  # fmt: skip
    """Relative error estimates of the finest of ``levels`` (each a dict of :func:`_quantities`).

    ``block``: the quantities of the level ``levels[block_level]`` solved with twice the block size, or None (the
    first level of the series; 1 when a coarser level was put before it, ``measure_order``).
    ``approach_control``: the force is an output; the max pressure's block-size error is then a third of the
    force's (module docstring, ``PRESSURE_PER_FORCE``), not the difference of the two blocks' coarse meshes.
    ``load_balanced`` (with ``approach_control``): the caller balances the load with the force; the max pressure, the
    area, the semi-axes and von Mises are estimated at the finest level's force (the levels solved there, ``FORCE_KEY``;
    a level without one is scaled to it by Hertz's exponents, ``LOAD_SCALING``), with the block's second-order error at
    a fixed load (``LOAD_CONTROL_BLOCK_ERROR``, scaled by (20 / ``block_factor``)^2) (module docstring).

    Returns:
        {"relative_error": {name: e or None}, "mesh_relative_error", "block_size_relative_error",
        "order_used", "observed_order"} (None where a quantity is missing on a level).
    """
    out = {"relative_error": {}, "mesh_relative_error": {}, "block_size_relative_error": {}, "order_used": {},
           "observed_order": {}}  # fmt: skip
    area_method = "Richardson over the levels"
    finest = levels[-1]
    balanced = approach_control and load_balanced
    forces = [level.get("normal_force") for level in levels]
    forces = [level.get(FORCE_KEY) or f for level, f in zip(levels, forces, strict=True)]  # at the finest's force
    scalable = balanced and all(f is not None and math.isfinite(f) and f > 0 for f in forces)
    for name in finest:
        if name in (NODAL_KEY, FORCE_KEY):
            continue
        series = [level[name] for level in levels]
        if name == "normal_force" and scalable:  # own forces: a coarser level solved only at the finest's has none
            known = list(itertools.takewhile(lambda v: v is not None, reversed(series)))[::-1]
            series = known if len(known) >= 2 else series
        if any(v is None or not math.isfinite(v) for v in series):
            for key in out:
                out[key][name] = None
            continue
        if scalable and name in LOAD_SCALING:
            series = [v * (forces[-1] / f) ** LOAD_SCALING[name] for v, f in zip(series, forces, strict=True)]
        error, order, observed = richardson_error(series)
        if name == "contact_area" and all(level.get(NODAL_KEY) for level in levels):
            error = nodal_area_error(series)  # a nodal area: first order with a scatter (module docstring)
            area_method = "nodal area: first-order least-squares line over the levels plus its scatter"
        mesh = _relative(error, finest[name])
        block_error = None
        fixed_load = block is not None and name == "max_pressure" and not approach_control  # second order there
        if (balanced and name in LOAD_CONTROL_BLOCK_ERROR) or fixed_load:
            block_error = LOAD_CONTROL_BLOCK_ERROR[name] * (20.0 / block_factor) ** 2
        elif block is not None and name in BLOCK_SENSITIVE and block.get(name) is not None:
            base = levels[block_level]
            difference = abs(block[name] - base[name])
            block_error = _relative(difference / (1.0 - 2.0**-BLOCK_DECAY_ORDER), finest[name])
            if name == "max_pressure" and approach_control and block.get("normal_force") is not None:
                force = abs(block["normal_force"] - base["normal_force"]) / (1.0 - 2.0**-BLOCK_DECAY_ORDER)
                block_error = PRESSURE_PER_FORCE * _relative(force, finest["normal_force"])
        out["mesh_relative_error"][name] = mesh
        out["block_size_relative_error"][name] = block_error
        out["relative_error"][name] = None if mesh is None else mesh + (block_error or 0.0)
        out["order_used"][name] = order
        out["observed_order"][name] = observed
    return {**out, "area_method": area_method}


def _parts(info: dict, name: str, error: float | None) -> str:
    """``name 2.18% (mesh 0.57%, window 1.49%, block size 0.13%)``: a judged error and what it is made of."""
    if error is None:
        return f"{name} unknown"
    parts = [("mesh", info.get("mesh_relative_error", {}).get(name)),
             ("window", (info.get("window_relative_error") or {}).get(name)),
             ("block size", info.get("block_size_relative_error", {}).get(name))]  # fmt: skip
    shown = ", ".join(f"{label} {value:.2%}" for label, value in parts if value)
    return f"{name} {error:.2%}" + (f" ({shown})" if shown else "")


def _window_record(result) -> dict:
    """A level's record of its fixed-window max pressure (fea.model, "Peak box"): empty without a peak box."""
    window = result.extra.get("max_pressure_window")
    if window is None:
        return {}
    fitted = window.get("max_pressure_Pa") is not None
    return {"window_fit": fitted, "window_relative_error": window.get("relative_error")}


def _add_window_error(info: dict, window: dict | None, records: list[dict] = ()) -> None:
    """Add the finest level's fit-window (model) error of the max pressure (fea.model, "Peak box") to its estimate.
    The max pressure's error becomes unknown (None) when the window's second fit failed on the finest level, or when
    a level's window fit failed and it reported the shrinking-radius fit instead (two estimators in one series).
    """
    if window is None:
        return
    if window.get("max_pressure_Pa") is None or not all(r.get("window_fit", True) for r in records):
        info["window_relative_error"] = {"max_pressure": None}
        info["relative_error"]["max_pressure"] = None
        info["window_note"] = "the fixed-window fit failed on a level: max pressure error not estimated"
        return
    error = window.get("relative_error")
    info["window_relative_error"] = {"max_pressure": error}
    mesh = info["relative_error"].get("max_pressure")
    info["relative_error"]["max_pressure"] = None if error is None or mesh is None else mesh + error


def _level_options(opts, elements_per_semi_axis: float, grading: float):
    """The options of one level of the series: ``opts`` at this element count per semi-axis and grading (the
    series sets the mesh by these, not by ``mesh_size_factor``).
    """
    return dataclasses.replace(
        opts, elements_per_semi_axis=elements_per_semi_axis, mesh_size_factor=1.0, grading=grading
    )


def _insert_coarser(solve_level, opts, levels: list, records: list, info: dict, count: int, force=None) -> None:
    """Solve up to ``count`` levels coarser than the first (``n0 / r``, ``n0 / r^2``, ...; at least
    ``ORDER_LEVEL_MIN_N`` elements per semi-axis) and put them before it, marked ``order_level``; a level that
    fails is left out and said in ``info["order_level"]`` (module docstring, "Measured order"). ``force``: solve
    them at this force (:func:`_at_finest_force`), else as the series' levels.
    """
    n0, g0, ratio = opts.n_per_semi_axis, opts.grading, REFINEMENT_RATIO
    for j in range(1, count + 1):
        n = n0 / ratio**j
        if n < ORDER_LEVEL_MIN_N:
            return
        level_opts = _level_options(opts, n, g0 * ratio**j)
        t_level = time.perf_counter()
        coarse, _ = solve_level(level_opts) if force is None else solve_level(level_opts, force_N=force)
        if coarse.status != "ok":
            info["order_level"] = f"not used: {coarse.status} ({coarse.message})"
            return
        levels.insert(0, _quantities(coarse) if force is None else _forced(coarse, None, force))
        records.insert(0, {"elements_per_semi_axis": n, "grading": g0 * ratio**j,
                           "dofs": int(coarse.extra.get("dofs", 0)), "order_level": True,
                           "wall_time_s": time.perf_counter() - t_level, **levels[0],
                           **_window_record(coarse)})  # fmt: skip


def _forced(result, own_force: float | None, force: float) -> dict:
    """The quantities of a level solved under load control at ``force`` (:func:`_at_finest_force`): its
    ``normal_force`` is its own under approach control (``own_force``; None when it was not solved so, a coarser level
    put before the first: the force is then not estimated on it), the rest at ``force`` (``FORCE_KEY``).
    """
    quantities = _quantities(result)
    return {**quantities, "normal_force": own_force, FORCE_KEY: force}


def _at_finest_force(solve_level, opts, levels: list, records: list, info: dict) -> None:
    """A load-balanced series (module docstring, "Load-balanced use"): every level coarser than the finest is solved
    again on its own mesh under load control at the finest level's force, where it was not yet; when that solve fails,
    the level and the coarser ones are left out of the series, said in ``info["finest_force_dropped"]``.
    """
    force = levels[-1]["normal_force"]
    for j in range(len(levels) - 2, -1, -1):
        if levels[j].get(FORCE_KEY) == force:
            continue
        record = records[j]
        level_opts = _level_options(opts, record["elements_per_semi_axis"], record["grading"])
        t_level = time.perf_counter()
        result, _ = solve_level(level_opts, force_N=force)
        if result.status != "ok":  # this level and the coarser ones leave the series (its levels stay consecutive)
            info["finest_force_dropped"] = (
                f"{j + 1} coarser level(s) left out: {record['elements_per_semi_axis']:.3g} elements per semi-axis "
                f"at {force:.6g} N {result.status} ({result.message})"
            )
            del levels[: j + 1], records[: j + 1]
            return
        if FORCE_KEY not in levels[j]:  # its values at its own force, kept for the record
            record.update({f"own_force_{name}": levels[j][name] for name in ("max_pressure", "contact_area")})
        levels[j] = _forced(result, levels[j]["normal_force"], force)
        record.update(levels[j], **_window_record(result))
        record["wall_time_s"] = record.get("wall_time_s", 0.0) + time.perf_counter() - t_level


def solve_to_tolerance(
    solve_level, opts, *, approach_control: bool, block_estimate: bool, t0: float, measure_order: bool = False,
    finest_force: bool = False,
):  # fmt: skip
    """Run the refinement series of the module docstring.

    Args:
        solve_level: (options) -> (ContactResult, write), ``write()`` writes that level's output files.
        opts: :class:`fea.model.FeaOptions` (``mesh_tolerance``, ``max_dofs``, the first level's mesh).
        approach_control: the force is an output (judged and block-sensitive).
        block_estimate: estimate the block-size error (formulations with a truncated block).
        t0: start time of the model's solve (the result's wall time counts every level).
        measure_order: before the first estimate, solve one level coarser than the first (``ORDER_LEVEL``) so that
            no estimate rests on the assumed order (module docstring, "Measured order"; sampled patches).
        finest_force: a load-balanced series solves its coarser levels at its finest level's force
            (``solve_level(options, force_N=...)``; module docstring, "Load-balanced use"); False: a caller whose
            solve takes no force, its levels scaled by Hertz's exponents (``LOAD_SCALING``).

    Returns:
        The finest level's ContactResult with status, message and ``extra["discretisation_error"]`` set.
    """
    n0, g0, ratio = opts.n_per_semi_axis, opts.grading, REFINEMENT_RATIO
    tol = opts.mesh_tolerance
    if tol is None:
        result, write = solve_level(opts)
        write()
        if result.status != "ok":
            return result
        info = {"estimated": False, "reason": "mesh_tolerance is None: one mesh, no error estimate"}
        return dataclasses.replace(
            result,
            status="error-not-estimated",
            message=f"{result.message}; discretisation error not estimated (mesh_tolerance None)",
            extra={**result.extra, "discretisation_error": info},
        )
    levels, records, block, result, write = [], [], None, None, None
    balanced = approach_control and opts.load_balanced
    judged = [name for name in JUDGED if (approach_control and not balanced) or name != "normal_force"]
    info: dict = {"estimated": False, "tolerance": tol, "refinement_ratio": ratio, "max_dofs": opts.max_dofs,
                  "judged": judged, "method": "Richardson over a refinement series (fea.refinement)"}  # fmt: skip
    if balanced:
        info["load_balanced"] = (
            "max pressure and area estimated at the finest level's force (every coarser level solved again there, "
            "on its own mesh under load control); the force's error is an approach error the load balance absorbs"
            if finest_force
            else "max pressure and area estimated at the finest level's force (Hertz's scaling of every level: "
            "the solve takes no force); the force's error is an approach error the load balance absorbs"
        )
        info["load_tolerance"] = LOAD_SHARE * tol
        info["block_size_check"] = ("not run: at a fixed load the block's truncation enters the max pressure and the "
                                    "area at second order (LOAD_CONTROL_BLOCK_ERROR); the force's and the approach's "
                                    "block-size errors are not estimated")  # fmt: skip
    k = 0
    while True:
        n, g = n0 * ratio**k, g0 / ratio**k
        level_opts = _level_options(opts, n, g)
        t_level = time.perf_counter()
        result, write = solve_level(level_opts)
        if result.status != "ok":
            info["levels"] = records
            message = f"refinement level {k} ({n:.3g} elements per semi-axis): {result.message}"
            return dataclasses.replace(result, message=message, extra={**result.extra, "discretisation_error": info})
        levels.append(_quantities(result))
        records.append({"elements_per_semi_axis": n, "grading": g, "dofs": int(result.extra.get("dofs", 0)),
                        "wall_time_s": time.perf_counter() - t_level, **levels[-1]})  # fmt: skip
        records[-1].update(_window_record(result))
        if k == 0 and block_estimate and not balanced:  # load-balanced: the fixed second-order term instead
            wide = dataclasses.replace(level_opts, domain_factor=2.0 * opts.block_factor, stresses=False)
            wide_result, _ = solve_level(wide)
            if wide_result.status == "ok":
                block = _quantities(wide_result)
                info["block_size_check"] = {"domain_factor": 2.0 * opts.block_factor, **block}
        common = levels[-1]["normal_force"] if balanced and finest_force else None
        if k == 1 and measure_order and n0 / ratio >= ORDER_LEVEL_MIN_N:
            _insert_coarser(solve_level, opts, levels, records, info, 1, common)
        dofs = records[-1]["dofs"]
        growth = dofs / records[-2]["dofs"] if len(records) >= 2 and records[-2]["dofs"] > 0 else ratio**3
        last = dofs * growth > opts.max_dofs
        if k == 0 and last:
            # the first level is the finest the budget affords: the levels below it give its estimate
            _insert_coarser(solve_level, opts, levels, records, info, FIRST_LEVEL_BUDGET_COARSER, common)
        if common is not None:
            _at_finest_force(solve_level, opts, levels, records, info)
        if len(levels) >= 2:
            block_level = sum(1 for r in records if r.get("order_level"))  # the block check's mesh: the first's
            info.update(estimate(levels, block, approach_control, balanced, opts.block_factor, block_level))
            _add_window_error(info, result.extra.get("max_pressure_window"), records)
            info["estimated"] = True
            worst = {name: info["relative_error"].get(name) for name in judged}
            if all(e is not None and e <= tol for e in worst.values()):
                status, verdict = "ok", f"discretisation error within {tol:g}"
                break
        if last:
            status = "mesh-tolerance-not-met"
            if len(levels) < 2:
                verdict = (f"discretisation error not estimated: the second level (~{dofs * growth:.3g} unknowns) "
                           f"exceeds max_dofs = {opts.max_dofs}")  # fmt: skip
            else:
                above = {n: e for n, e in worst.items() if e is None or e > tol}
                shown = ", ".join(_parts(info, n, e) for n, e in above.items())
                within = [f"{n} {e:.2%}" for n, e in worst.items() if n not in above]
                shown += f"; within it: {', '.join(within)}" if within else ""
                verdict = (f"discretisation error above mesh_tolerance = {tol:g} ({shown}); the next level "
                           f"(~{dofs * growth:.3g} unknowns) exceeds max_dofs = {opts.max_dofs}")  # fmt: skip
            break
        k += 1
    info["levels"] = records
    write()
    errors = info.get("relative_error", {})
    shown = ", ".join(f"{name} {errors[name]:.2%}" for name in judged if errors.get(name) is not None)
    message = f"{result.message}; {verdict}" + (f" ({shown}, {len(levels)} levels)" if status == "ok" else "")
    return dataclasses.replace(
        result,
        status=status,
        message=message,
        wall_time_s=time.perf_counter() - t0,
        extra={**result.extra, "discretisation_error": info},
    )
