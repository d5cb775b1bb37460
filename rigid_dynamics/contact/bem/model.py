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

import dataclasses
import math
import time
from collections.abc import Mapping

import numpy as np

from rigid_dynamics.contact.bem.influence import InfluenceGrid, SubPatchInfluence
from rigid_dynamics.contact.bem.norm import METHODS as NORM_METHODS
from rigid_dynamics.contact.bem.norm import solve_norm
from rigid_dynamics.contact.bem.tang import rigid_slip, solve_tang, solve_tang_law
from rigid_dynamics.contact.edge_area import EDGE_SAFETY, edge_error, grid_edge_area
from rigid_dynamics.contact.options import Option, declare, validate_options
from rigid_dynamics.contact.options import defaults as option_defaults
from rigid_dynamics.contact.types import ContactFields, ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

OPTIONS = declare(
    Option("nx", int, 40, "elements along x (rolling direction)", minimum=1, maximum=4096),
    Option("ny", int, 40, "elements along y (lateral)", minimum=1, maximum=4096),
    Option("element_size_m", float, None, "square elements of this side instead of nx, ny (CONTACT's DX = DS), m",
           minimum=0.0, maximum=0.1, exclusive_minimum=True, allow_none=True),
    Option("dx_m", float, None, "element size along x instead of nx (CONTACT's DX), m", minimum=0.0, maximum=0.1,
           exclusive_minimum=True, allow_none=True),
    Option("dy_m", float, None, "element size along y instead of ny (CONTACT's DY; None: dx_m), m", minimum=0.0,
           maximum=0.1, exclusive_minimum=True, allow_none=True),
    Option("grid_tolerance", float, 0.02, "accepted estimated relative grid error of forces, max pressure and area",
           minimum=0.0, exclusive_minimum=True),
    Option("max_refinements", int, 3, "halvings of the default grid's elements while the estimate exceeds "
           "grid_tolerance", minimum=0, maximum=5),
    Option("estimate_grid_error", bool, True, "estimate the grid error (false: for the inner solves of an "
           "iteration whose final patches are estimated by with_grid_error)"),
    Option("margin", float, 1.15, "potential contact area in Hertz semi-axes", minimum=1.0),
    Option("tolerance", float, 1e-6, "relative tolerance of NORM and TANG", minimum=0.0, exclusive_minimum=True),
    Option("max_iterations", int, 500, "NORM CG iterations and TANG Newton steps, each", minimum=1),
    Option("difference_parameter", float, 0.0, "Kalker's K (dissimilar materials)", minimum=-0.5, maximum=0.5,
           exclusive_minimum=True, exclusive_maximum=True),
    Option("norm_method", str, "normcg", "NORM solver", choices=tuple(NORM_METHODS)),
    Option("subpatch_interaction", str, "contact", "interaction of a patch's sub-patches (D_COMB < d <= D_SEP)",
           choices=("contact", "full")),
    Option("extrapolate", bool, False, "Richardson extrapolation of the creep forces from a 2 x 2-merged grid"),
    Option("rolling_slip_point", str, "centre", "where the rolling slip is taken", choices=("centre", "midpoint")),
    Option("problem", str, "rolling", "tangential problem", choices=("rolling", "shift", "transient")),
    Option("shift_long_m", float, 0.0, "shift problem: rigid shift along x, m"),
    Option("shift_lat_m", float, 0.0, "shift problem: rigid shift along y, m"),
    Option("shift_rotation_rad", float, 0.0, "shift problem: rigid rotation about the normal, rad"),
    Option("kinetic_friction_coefficient", float, None, "withdrawn: give a falling friction law ([friction])",
           minimum=0.0, exclusive_minimum=True, allow_none=True),
    Option("max_friction_iterations", int, 100, "outer iterations of a falling friction law", minimum=1),
    Option("transient_steps", int, None, "transient problem: rolling steps of dx (None: nx)", minimum=1,
           allow_none=True),
)  # fmt: skip
DEFAULT_OPTIONS: dict = option_defaults(OPTIONS)
"""Options of :class:`BemModel` and their defaults:

* ``nx``, ``ny`` (int >= 1): elements along x (rolling) and y (lateral) over the potential contact area;
* ``element_size_m`` (float > 0 or None): square elements of this side (m; CONTACT's DX = DS) instead of
  ``nx``, ``ny``: the counts follow from the potential area, widened to whole elements whose centres lie at
  integer multiples of the size from the contact plane's origin (the patch's reference point), as CONTACT's grid
  (not together with ``nx`` or ``ny``; at most ``MAX_ELEMENTS`` elements);
* ``dx_m``, ``dy_m`` (float > 0 or None): rectangular elements of these sides (CONTACT's DX and DY; ``dy_m``
  None: ``dx_m``) instead of ``nx``, ``ny``, placed as for ``element_size_m`` (not together with it, nor with
  ``nx``, ``ny``);
* ``grid_tolerance`` (float > 0, default 0.02) and ``max_refinements`` (int >= 0, default 3): every solution
  carries an estimate of its discretisation error (``extra["grid_error"]``, :func:`grid_error_estimate`) from two
  companion solutions over the same potential area with elements twice and four times as large. When neither
  ``nx``/``ny`` nor an element size is given, the grid starts at the default counts and its elements are halved
  (counts doubled, the finer solution taking the place of the fine one and the two coarser companions reused)
  while the largest relative estimate exceeds ``grid_tolerance``, at most ``max_refinements`` times. A grid the
  caller names is solved as named. A solution whose estimate still exceeds ``grid_tolerance``, or whose grid is
  too coarse for the estimate (fewer than 6 elements along x or y), ends with status ``"warning"`` (``success``
  True, the numbers are the solution's) and a message naming the estimate and the tolerance;
* ``estimate_grid_error`` (bool, default True): False skips the companions and the refinement (the result says
  it is not estimated); for an iterative caller, which then estimates its final patches with
  :meth:`BemModel.with_grid_error` (the wheelset case does);
* a patch whose ``undeformed.potential_area_m`` is given (the wheelset case's CONTACT-style patches: a rectangle
  holding the whole rigid overlap) is solved on that area, without the margin rule and its enlargements;
* ``margin`` (>= 1): margin m of the potential area (module docstring);
* ``tolerance``, ``max_iterations``: NORM's relative update tolerance and CG limit, TANG's tolerance and Newton
  limit;
* ``difference_parameter``: Kalker's K (|K| < 0.5; 0 for quasi-identical bodies);
* ``norm_method``: ``"normcg"`` (preconditioned) or ``"polonsky-keer"`` (:func:`~.norm.solve_norm`);
* ``subpatch_interaction``: for a patch whose ``undeformed`` carries sub-patches (the wheelset case's regions
  D_COMB < d <= D_SEP apart), ``"contact"`` (default) solves NORM as CONTACT does (IPLAN = 4): the normal
  displacement between sub-patches i and j scaled by the factor f_ij, elements outside every sub-patch's rectangle
  outside the potential contact area (:class:`~.influence.SubPatchInfluence`); ``"full"`` joins them fully (one
  influence matrix over the whole potential area; before that option it was the only way);
* ``extrapolate`` (bool): Richardson extrapolation of the creep forces and spin moment from this grid and the
  grid of 2 x 2 merged elements over the same potential area, F = 2 F_h - F_2h (the steady-rolling
  discretisation is first order: the leading edge of each row is quantised to element edges); the result
  reports both grids' values and the estimated error F_h - F of the fine grid (``extra["richardson"]``).
  Needs even element counts (``element_size_m`` rounds them up to even). Costs about a third more.
* ``rolling_slip_point``: where the rigid slip of steady rolling is taken, ``"centre"`` (the element centre x_I,
  as CONTACT without its empirical spin offset) or ``"midpoint"`` (x_I + dx/2, the point at which the upwind
  difference (u(x_I) - u(x_I + dx))/dx approximates -du/dx to second order). Both are first order overall and
  converge to one limit from opposite sides; with ``extrapolate`` the midpoint is the better choice
  (benchmarks/results/bem_rolling_coarse.md);
* ``problem``: ``"rolling"`` (steady rolling with the creepages, default) or ``"shift"`` (Cattaneo's shift
  problem from the unloaded state: the bodies are pressed together and then shifted rigidly, the creepages are
  not used): the rigid shift of the wheel over the rail is w = (s_x - theta y, s_y + theta x) with ``shift_long_m``
  s_x, ``shift_lat_m`` s_y (m) and ``shift_rotation_rad`` theta about the normal (rad); the result's slip field is
  then None (the slip is a distance) and ``extra["slip_distance_max_m"]`` its largest value;
* ``problem = "transient"``: transient rolling from the state without tangential traction (the bodies pressed
  together, then rolling starts with the creepages): ``transient_steps`` (int >= 1; None: nx) steps of the
  rolling distance dq = dx (CONTACT's DQ = DX), each a shift problem whose rigid shift is
  dq w - u'(x + dq), u' the previous step's displacement difference carried along with the particles (Kalker 1990,
  sec. 5.2); the result is the last step's, ``extra["transient_forces_N"]`` the (F_x, F_y, M_z) of every step.
  With dq = dx the steady state of this recursion is exactly the steady-rolling discretisation. Quasi-identical
  bodies only (K = 0);
* ``kinetic_friction_coefficient``: withdrawn (any value but None is an error naming the replacement). It gave a
  kinetic coefficient below the static one, CONTACT's Coulomb law before v23.1. CONTACT v23.1 on uses one
  coefficient for adhesion and slip (rev 2707 copies FSTAT into FKIN for L = 0), and friction that drops once an element
  slides is a falling law of the slip velocity: the material's friction law (``Material.friction``, a case's
  ``[friction]`` table), solved element-wise (:func:`~.tang.solve_tang_law`);
* ``max_friction_iterations`` (int >= 1, default 100): outer iterations of a falling friction law (the traction
  bound of the slip elements updated from their slip velocities); the solution is "not-converged" beyond it.

Friction: the material's law (:meth:`~rigid_dynamics.materials.Material.friction_law`) bounds the traction
element-wise: mu_s = mu(0, place) bounds adhesion, an element in slip carries mu(V |s|, place) p. The place of an
element is ``geometry.friction_place`` at its centre, or the patch's reference point for the whole patch (the
contact angle, the rail-profile lateral coordinate of the contact point, or ``geometry.track_distance_m``), as
CONTACT does for a planar patch (CONTACT's V = 1, 2). Falling friction is solved for steady rolling only.
"""

GRID_OPTIONS = ("nx", "ny", "element_size_m", "dx_m", "dy_m")
"""The options by which a caller names the grid: solved as named, never refined."""

PROBLEMS = ("rolling", "shift", "transient")
"""Tangential problems of the option ``problem``."""

ROLLING_SLIP_POINTS = {"centre": 0.0, "midpoint": 0.5}
"""Offset of the rigid slip from the element centre, in elements along x (option ``rolling_slip_point``)."""

MIN_COMPANION_ELEMENTS = 3
"""Fewest elements along x or y of a coarse companion grid of the error estimate (a coarser one says nothing of
the fine grid: it is left out, and without the companion twice as coarse the error is not estimated)."""

MAX_ELEMENTS = 4_000_000
"""Largest grid ``nx`` x ``ny`` or ``element_size_m`` may produce (about 1 GB of FFT work arrays)."""
SECONDS_PER_ELEMENT = 2.4e-5
"""Measured solve time per element at 400 x 400 (hertz-quadric with creepage and spin, grid-error companions
included, one core of the shared 2-core machine, 2026-11-28: 3.8 s); larger grids need more iterations per
element, so the estimate made from it is a lower bound."""


def _grid_budget(nx: int, ny: int, name: str, value) -> None:
    """Refuse a grid beyond :data:`MAX_ELEMENTS` up front, naming the option, with its memory and time estimate."""
    if nx * ny > MAX_ELEMENTS:
        memory_gb = 4 * (2 * nx) * (2 * ny) * 16 / 1e9  # complex FFT work arrays over the doubled grid
        raise ValueError(
            f"option {name} = {value!r} gives {nx} x {ny} = {nx * ny} elements: expected at most {MAX_ELEMENTS} "
            f"(this grid needs about {memory_gb:.1f} GB of FFT work arrays and at least "
            f"{nx * ny * SECONDS_PER_ELEMENT / 60:.0f} minutes)"
        )


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

    # the ratio grows monotonically with e^2 from 1 to infinity: bisection to the last bit (no scipy.optimize,
    # whose import costs a small command a fifth of its start-up)
    low, high = 1e-12, 1.0 - 1e-15
    while True:
        e2 = 0.5 * (low + high)
        if not low < e2 < high:
            break
        if mismatch(e2) < 0.0:
            low = e2
        else:
            high = e2
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


class BemWarmStart:
    """The last solution of one patch per grid (element counts and sizes), the initial guess of the next solve of
    the same patch on the same grid (the dynamics loop: the previous step's solve of the same contact candidate).

    NORM starts from the stored pressure (``solve_norm(initial_pressure_Pa=...)``), TANG from the stored tractions
    and slip area (``solve_tang(initial_traction=..., initial_slip=...)``), index by index of the grid (its origin
    is the patch's contact point, which moves with the patch). Only the start changes: the solution is the same to
    the solvers' tolerance. The influence numbers of a grid are reused by InfluenceGrid's shared cache whenever the
    counts and sizes repeat. ``solves``, ``warm_solves`` and ``iterations`` (NORM + TANG, all solves) count the use;
    with ``enabled`` False it only counts (every solve starts cold: the reference for the saving).
    """

    def __init__(self, enabled: bool = True):
        self.enabled = bool(enabled)
        self.grids: dict = {}
        self.solves = 0
        self.warm_solves = 0
        self.iterations = 0

    def guess(self, nx: int, ny: int, dx: float, dy: float):
        """(pressure, (t_x, t_y), slip) stored for this grid, or None (always None when not ``enabled``)."""
        entry = self.grids.get((nx, ny)) if self.enabled else None
        if entry is None or not (math.isclose(entry[0], dx, rel_tol=1e-9) and math.isclose(entry[1], dy, rel_tol=1e-9)):
            return None
        return entry[2]

    def store(self, nx: int, ny: int, dx: float, dy: float, solution, warm: bool, iterations: int) -> None:
        self.grids[(nx, ny)] = (dx, dy, solution)
        self.solves += 1
        self.warm_solves += int(warm)
        self.iterations += int(iterations)


def _friction_places(geometry: ContactGeometry, law, xx: np.ndarray, yy: np.ndarray):
    """The friction law's place variable at the element centres (see :data:`DEFAULT_OPTIONS`, "Friction")."""
    if not law.varies:
        return 0.0
    if geometry.friction_place is not None:
        return np.asarray(geometry.friction_place(law.varies_with, xx, yy), float)
    value = {
        "surface_inclination": geometry.contact_angle_rad,
        "rail_lateral": geometry.contact_point_rail_m[0],
        "track_distance": geometry.track_distance_m,
    }[law.varies_with]
    if not math.isfinite(value):
        raise ValueError(f"friction varies_with = {law.varies_with!r}: the patch has no such place ({value!r})")
    return float(value)


def _sub_patch_labels(geometry: ContactGeometry, xx: np.ndarray, yy: np.ndarray, opts):
    """(labels, factors) of the patch's sub-patches on the element centres (xx, yy), or None (none, or option
    ``subpatch_interaction = "full"``): label k + 1 where the centre lies in rectangle k (a later rectangle takes
    the elements it shares with an earlier one), 0 in none (CONTACT's eldiv_cpatches).
    """
    und = geometry.undeformed
    if und is None or und.sub_patches_m is None or opts["subpatch_interaction"] == "full":
        return None
    labels = np.zeros(xx.shape, np.int64)
    for k, (x0, x1, y0, y1) in enumerate(np.asarray(und.sub_patches_m, float)):
        labels[(xx >= x0) & (xx <= x1) & (yy >= y0) & (yy <= y1)] = k + 1
    return labels, np.asarray(und.sub_patch_factors, float)


def _options(options: Mapping | None) -> dict:
    opts = validate_options(OPTIONS, options, "bem")
    options = options or {}
    if opts["kinetic_friction_coefficient"] is not None:
        raise ValueError(
            f"option kinetic_friction_coefficient = {opts['kinetic_friction_coefficient']!r}: withdrawn (CONTACT "
            "v23.1 on uses one coefficient for adhesion and slip); expected a falling friction law instead, a "
            '[friction] table with law = "linear", "rational", "exponential" or "polach"'
        )
    size = opts["element_size_m"]
    if size is not None:
        both = [k for k in ("nx", "ny", "dx_m", "dy_m") if k in options]
        if both:
            raise ValueError(
                f"option element_size_m = {size!r} together with {' and '.join(both)}: expected either the element "
                "size or the element counts"
            )
    if opts["dy_m"] is not None and opts["dx_m"] is None:
        raise ValueError(f"option dy_m = {opts['dy_m']!r} without dx_m: expected dx_m as well (or element_size_m)")
    if opts["dx_m"] is not None:
        both = [k for k in ("nx", "ny") if k in options]
        if both:
            raise ValueError(
                f"option dx_m = {opts['dx_m']!r} together with {' and '.join(both)}: expected either the element "
                "sizes or the element counts"
            )
        size = opts["dx_m"], opts["dy_m"] if opts["dy_m"] is not None else opts["dx_m"]
    elif size is not None:
        size = size, size
    opts["element_sizes_m"] = size
    if size is None:
        _grid_budget(opts["nx"], opts["ny"], "nx, ny", (opts["nx"], opts["ny"]))
    opts["grid_named"] = any(k in options for k in GRID_OPTIONS)
    if opts["extrapolate"] and size is None and (opts["nx"] % 2 or opts["ny"] % 2 or opts["nx"] < 4):
        raise ValueError(
            f"option extrapolate = true with nx = {opts['nx']!r}, ny = {opts['ny']!r}: expected even element counts "
            "(nx >= 4), so that 2 x 2 elements merge into the coarse grid"
        )
    if opts["problem"] != "rolling" and opts["extrapolate"]:
        raise ValueError(
            f"option extrapolate = true with problem = {opts['problem']!r}: expected false (it is for steady rolling)"
        )
    if opts["problem"] == "transient" and opts["difference_parameter"] != 0.0:
        raise ValueError(
            f"option difference_parameter = {opts['difference_parameter']!r} with problem = 'transient': expected 0"
        )
    if opts["problem"] == "rolling" and any(
        opts[k] != 0.0 for k in ("shift_long_m", "shift_lat_m", "shift_rotation_rad")
    ):
        raise ValueError("options shift_*: expected problem = 'shift' (a steady-rolling case uses the creepages)")
    return opts


class BemModel:
    """Boundary-element NORM + TANG (Kalker's exact theory discretised; the CONTACT approach)."""

    name = "bem"
    description = "boundary elements: CONTACT-style NORM + TANG"
    OPTIONS = OPTIONS

    @staticmethod
    def check_options(options: Mapping | None) -> dict:
        """Validate ``options`` (:data:`DEFAULT_OPTIONS`) without solving; ValueError naming the option and value."""
        return _options(options)

    def solve(
        self,
        geometry: ContactGeometry,
        creepage: Creepage,
        material: Material,
        *,
        normal_force_N: float | None = None,
        options: Mapping | None = None,
        warm_start: BemWarmStart | None = None,
    ) -> ContactResult:
        """Solve one patch (see the module docstring); forces on the wheel in the contact frame.

        Args:
            geometry: patch geometry; ``geometry.undeformed`` (if set) is used as h, else the quadric.
            creepage: xi, eta, phi and the rolling speed V (slip velocities are V times the slip).
            material: G, nu, mu of the (quasi-identical) pair.
            normal_force_N: None = approach control with ``geometry.approach_m``; else F_N > 0, N.
            options: see :data:`DEFAULT_OPTIONS`; unknown keys raise ValueError.
            warm_start: optional :class:`BemWarmStart` of this patch: its last solution on the same grid starts
                NORM and TANG (and is replaced by this one's), the solution unchanged to the tolerance.

        Returns:
            ContactResult with fields on the grid; semi-axes (extents of the contact along x, y)
            only when ``geometry.is_elliptic`` (else None); ``success`` False with status
            "not-converged" when NORM or TANG did not converge.
        """
        start = time.perf_counter()
        opts = _options(options)
        opts["warm_start"] = warm_start
        fine = self._solve(geometry, creepage, material, normal_force_N, opts, None, start)
        if fine.status == "no-contact" or not fine.success:
            return fine
        if not opts["estimate_grid_error"]:
            if opts["extrapolate"]:
                fine = self._extrapolated(geometry, creepage, material, normal_force_N, opts, fine, start)
            return _without_grid_error(fine, NOT_ESTIMATED_REASON, time.perf_counter() - start)
        return self._estimate(geometry, creepage, material, normal_force_N, opts, fine, start, refine=True)

    def with_grid_error(
        self,
        geometry: ContactGeometry,
        creepage: Creepage,
        material: Material,
        result: ContactResult,
        *,
        normal_force_N: float | None = None,
        options: Mapping | None = None,
    ) -> ContactResult:
        """``result`` (this model's, solved with ``estimate_grid_error = false`` and the same arguments) with its
        grid-error estimate, status and message as :meth:`solve` gives them, without refining its grid (an
        iterative caller such as the wheelset case estimates only its final patches; the numbers stay the ones its
        equilibrium holds). An extrapolated result is returned as it is (not estimated).
        """
        start = time.perf_counter()
        opts = _options(options)
        opts["warm_start"] = None
        if result.status == "no-contact" or not result.success or opts["extrapolate"]:
            return result
        # the inner solve's "not estimated" note gives way to the estimate
        result = dataclasses.replace(result, message=result.message.replace(_not_estimated_note(), ""))
        out = self._estimate(geometry, creepage, material, normal_force_N, opts, result, start, refine=False)
        return dataclasses.replace(out, wall_time_s=result.wall_time_s + time.perf_counter() - start)

    def _extrapolated(self, geometry, creepage, material, normal_force_N, opts, fine, start) -> ContactResult:
        """Richardson extrapolation of ``fine`` with the merged grid (option ``extrapolate``)."""
        x0, x1, y0, y1 = fine.extra["potential_area_m"]
        coarse_opts = dict(opts, nx=fine.extra["nx"] // 2, ny=max(fine.extra["ny"] // 2, 1), element_sizes_m=None,
                           extrapolate=False)  # fmt: skip
        coarse = self._solve(geometry, creepage, material, normal_force_N, coarse_opts, ((x0, x1), (y0, y1)), start)
        return _richardson(fine, coarse, time.perf_counter() - start)

    def _estimate(self, geometry, creepage, material, normal_force_N, opts, fine, start, refine) -> ContactResult:
        """The grid-error estimate of ``fine`` from its companions, refining the default grid (``refine`` and no
        grid named) while it exceeds ``grid_tolerance``; see :data:`DEFAULT_OPTIONS`.
        """
        x0, x1, y0, y1 = fine.extra["potential_area_m"]
        area = ((x0, x1), (y0, y1))

        first_nx = fine.extra["nx"]

        def on_grid(nx: int, ny: int) -> ContactResult:
            grid_opts = dict(opts, nx=nx, ny=ny, element_sizes_m=None, extrapolate=False)
            if opts["transient_steps"] is not None:  # roll the same distance on every grid
                grid_opts["transient_steps"] = max(1, round(opts["transient_steps"] * nx / first_nx))
            return self._solve(geometry, creepage, material, normal_force_N, grid_opts, area, start)

        def coarser(result: ContactResult, factor: int) -> ContactResult | None:
            nx, ny = round(result.extra["nx"] / factor), round(result.extra["ny"] / factor)
            if min(nx, ny) < MIN_COMPANION_ELEMENTS:
                return None
            return on_grid(nx, ny)

        tolerance = float(opts["grid_tolerance"])
        levels = [fine, coarser(fine, 2), coarser(fine, 4)]
        estimate = grid_error_estimate(levels, material.friction_coefficient)
        refinements = 0
        while (
            refine
            and not opts["grid_named"]
            and refinements < opts["max_refinements"]
            and (estimate is None or estimate["largest_relative"] > tolerance)
            and 4 * fine.extra["nx"] * fine.extra["ny"] <= MAX_ELEMENTS
        ):
            finer = on_grid(2 * fine.extra["nx"], 2 * fine.extra["ny"])
            if not finer.success:
                break
            levels = [finer, levels[0], levels[1]]
            fine = finer
            refinements += 1
            estimate = grid_error_estimate(levels, material.friction_coefficient)
        result = fine
        if opts["extrapolate"]:  # the companion twice as coarse is the merged grid (unless it was too small)
            result = (
                _richardson(fine, levels[1], time.perf_counter() - start)
                if levels[1] is not None
                else self._extrapolated(geometry, creepage, material, normal_force_N, opts, fine, start)
            )
        return _with_grid_error(result, estimate, tolerance, refinements, time.perf_counter() - start)

    def _solve(self, geometry, creepage, material, normal_force_N, opts, fixed_area, start) -> ContactResult:
        """:meth:`solve` on one grid; ``fixed_area`` ((x0, x1), (y0, y1)) imposes the potential area (m)."""
        if normal_force_N is not None and (not math.isfinite(normal_force_N) or normal_force_N <= 0):
            raise ValueError(f"normal_force_N = {normal_force_N!r}: expected None or a finite number > 0")
        g_mod, nu = material.shear_modulus_Pa, material.poisson_ratio
        e_star = g_mod / (1.0 - nu)
        curv = (geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m)
        margin = float(opts["margin"])
        nx, ny = int(opts["nx"]), int(opts["ny"])

        def no_contact(message: str) -> ContactResult:
            return ContactResult.no_contact(
                self.name, message, creepage, approach_m=geometry.approach_m, wall_time_s=time.perf_counter() - start
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
            else:
                region = finite & (d <= d_min + 0.5 * depth * margin**2)
                jj, ii = np.nonzero(region)
                xs, ys = np.asarray(und.x_m), np.asarray(und.y_m)
                hx = 0.5 * (np.abs(np.diff(xs)).min() if xs.size > 1 else 0.0)
                hy = 0.5 * (np.abs(np.diff(ys)).min() if ys.size > 1 else 0.0)
                x_lim = (float(xs[ii].min()) - hx, float(xs[ii].max()) + hx)
                y_lim = (float(ys[jj].min()) - hy, float(ys[jj].max()) + hy)
            if x_lim[1] <= x_lim[0] or y_lim[1] <= y_lim[0]:
                return no_contact("the sampled undeformed distance gives an empty potential contact area")
        k_diff = float(opts["difference_parameter"])
        warm = opts.get("warm_start") if opts["problem"] == "rolling" and k_diff == 0.0 else None
        norm_method = opts["norm_method"]
        tol, max_it = float(opts["tolerance"]), int(opts["max_iterations"])
        if geometry.undeformed is not None:
            xs, ys = np.asarray(geometry.undeformed.x_m), np.asarray(geometry.undeformed.y_m)
            field_box = (float(xs.min()), float(xs.max()), float(ys.min()), float(ys.max()))
        grown = 0
        size = opts["element_sizes_m"]
        if fixed_area is not None:
            x_lim, y_lim = fixed_area
            size = None
        even = bool(opts["extrapolate"])
        while True:
            if size is not None:
                x_lim, nx = _whole_elements(x_lim, float(size[0]), even)
                y_lim, ny = _whole_elements(y_lim, float(size[1]), even)
                name = "element_size_m" if opts["element_size_m"] is not None else "dx_m"
                _grid_budget(nx, ny, name, opts[name])
            dx = (x_lim[1] - x_lim[0]) / nx
            dy = (y_lim[1] - y_lim[0]) / ny
            x = x_lim[0] + dx * (np.arange(nx) + 0.5)
            y = y_lim[0] + dy * (np.arange(ny) + 0.5)
            xx, yy = np.meshgrid(x, y)
            h = np.asarray(geometry.gap_m(xx, yy), float)
            influence = InfluenceGrid(nx, ny, dx, dy, g_mod, nu, k_diff)
            subs = _sub_patch_labels(geometry, xx, yy, opts)
            if subs is not None:
                h = np.where(subs[0] > 0, h, np.inf)
                influence = SubPatchInfluence(influence, *subs)
            guess = warm.guess(nx, ny, dx, dy) if warm is not None else None
            norm = solve_norm(
                influence, h, normal_force_N=normal_force_N, tolerance=tol, max_iterations=max_it, method=norm_method,
                initial_pressure_Pa=None if guess is None else guess[0],
            )  # fmt: skip
            contact = norm.pressure_Pa > 0
            edge = bool(contact[0, :].any() or contact[-1, :].any() or contact[:, 0].any() or contact[:, -1].any())
            given = geometry.undeformed is not None and geometry.undeformed.potential_area_m is not None
            if not edge or geometry.undeformed is None or grown >= 3 or fixed_area is not None or given:
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
        offset = ROLLING_SLIP_POINTS[opts["rolling_slip_point"]] * dx
        problem = opts["problem"]
        if problem == "shift":
            # rigid shift (m) of the wheel over the rail: translation and rotation about the normal
            wx, wy = rigid_slip(x, y, opts["shift_long_m"], opts["shift_lat_m"], opts["shift_rotation_rad"])
        else:
            wx, wy = rigid_slip(x + offset, y, creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m)
        law = material.friction_law()
        places = _friction_places(geometry, law, xx, yy)
        if problem != "rolling" and not law.is_coulomb:
            raise ValueError(f"problem = {problem!r}: a falling friction law is solved for steady rolling only")
        mu_place = np.broadcast_to(np.vectorize(law.static_coefficient, otypes=[float])(places), xx.shape)
        previous = norm.normal_force_N
        history = None
        for _ in range(1 if k_diff == 0.0 or problem == "transient" else 20):
            if problem == "transient":
                steps = int(opts["transient_steps"] or nx)
                fields_in = (norm.pressure_Pa, (wx, wy), (xx, yy))
                tang, history = _transient(influence, mu_place, fields_in, steps, tol, max_it, opts)
                break
            if problem == "rolling":
                tang = solve_tang_law(
                    influence, norm.pressure_Pa, law, places, wx, wy, creepage.rolling_speed_m_per_s,
                    tolerance=tol, max_iterations=max_it, max_friction_iterations=opts["max_friction_iterations"],
                    **_warm_traction(guess, norm.pressure_Pa),
                )  # fmt: skip
            else:
                tang = solve_tang(
                    influence, norm.pressure_Pa, mu_place, wx, wy, problem=problem, tolerance=tol,
                    max_iterations=max_it, **_warm_traction(guess, norm.pressure_Pa),
                )  # fmt: skip
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
                method=norm_method,
            )
            change = abs(norm.normal_force_N - previous)
            previous = norm.normal_force_N
            if change <= tol * max(norm.normal_force_N, 1e-300) and np.array_equal(norm.pressure_Pa > 0, contact):
                break
            contact = norm.pressure_Pa > 0
        p = norm.pressure_Pa
        contact = p > 0
        if warm is not None:
            solution = (p, (tang.traction_x_Pa, tang.traction_y_Pa), tang.in_slip & contact)
            warm.store(nx, ny, dx, dy, solution, guess is not None, norm.iterations + tang.iterations)
        if not contact.any():
            return no_contact("NORM found no element in contact")
        area = dx * dy
        tx, ty = tang.traction_x_Pa, tang.traction_y_Pa
        fx, fy = float(tx.sum() * area), float(ty.sum() * area)
        mz = float((xx * ty - yy * tx).sum() * area)
        slip_size = np.hypot(tang.slip_x, tang.slip_y)
        slip_speed = None
        if problem == "rolling":
            slip_speed = creepage.rolling_speed_m_per_s * slip_size
        elif problem == "transient":  # slip distance per rolling step dq = dx
            slip_speed = creepage.rolling_speed_m_per_s * slip_size / dx
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
            semi_long, semi_lat, fitted = _elliptic_semi_axes(x, y, p, contact, dx, dy)
        # a quadric patch's area from the fitted ellipse (converges smoothly, within 0.4 % of Hertz from 10 x 10
        # elements); the element count jumps by several % as the edge crosses element centres. A sampled field's
        # pressure need not be elliptic: its area is the element count, as CONTACT's.
        quadric = semi_long is not None and fitted and geometry.undeformed is None
        contact_area = math.pi * semi_long * semi_lat if quadric else contact.sum() * area
        # the element count's edge within its cells (rigid_dynamics.contact.edge_area): its error estimate
        edge_area = None if quadric or not contact.any() else grid_edge_area(p, contact, dx, dy)
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
            contact_area_m2=float(contact_area),
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
                "contact_area_edge_m2": edge_area,
                "norm_iterations": int(norm.iterations),
                "norm_residual": float(norm.residual),
                "tang_iterations": int(tang.iterations),
                "tang_linear_iterations": int(tang.linear_iterations),
                "tang_residual": float(tang.residual),
                "slip_elements": int((tang.in_slip & contact).sum()),
                "contact_touches_potential_area_edge": edge,
                "potential_area_enlargements": grown,
                "problem": problem,
                "slip_distance_max_m": float(slip_size.max()) if problem == "shift" else None,
                "transient_forces_N": history,
            },
        )


def _warm_traction(guess, pressure_Pa) -> dict:
    """solve_tang's warm-start arguments from a BemWarmStart guess (none without one or without contact)."""
    if guess is None or not (pressure_Pa > 0).any():
        return {}
    return {"initial_traction": guess[1], "initial_slip": guess[2]}


def _transient(influence, mu, fields_in, steps, tol, max_it, opts):
    """Transient rolling from zero tangential traction (option problem = "transient"); (last TangSolution, history).

    Step k: the shift problem with the rigid shift W = dx w - u'(x + dx), where u'(x + dx) = u'(x) - dx L t' is the
    previous displacement difference one element ahead (L the rolling operator: (u(x) - u(x + dx))/dx), so that
    the slip distance of the step is S = dx w + u(x) - u'(x + dx). History: [F_x, F_y, M_z] per step (N, N m).
    """
    area = influence.dx_m * influence.dy_m
    pressure, (wx, wy), (xx, yy) = fields_in
    tx = np.zeros(pressure.shape)
    ty = np.zeros(pressure.shape)
    history = []
    tang = None
    dx = influence.dx_m
    for _ in range(steps):
        ux, uy = influence.tangential(tx, ty, rolling=False)
        lx, ly = influence.tangential(tx, ty, rolling=True)
        tang = solve_tang(
            influence,
            pressure,
            mu,
            dx * wx - (ux - dx * lx),
            dx * wy - (uy - dx * ly),
            problem="shift",
            tolerance=tol,
            max_iterations=max_it,
            coarse_start=False,
        )
        tx, ty = tang.traction_x_Pa, tang.traction_y_Pa
        history.append([float(tx.sum() * area), float(ty.sum() * area), float((xx * ty - yy * tx).sum() * area)])
        if not tang.converged:
            break
    return tang, history


def _whole_elements(limits: tuple[float, float], size_m: float, even: bool = False) -> tuple[tuple[float, float], int]:
    """Widen ``limits`` (m) to whole elements of ``size_m`` whose centres lie at integer multiples of the size from
    the contact plane's origin (the patch's reference point), as CONTACT's grid; (limits, count).

    The count is >= 1, or even and >= 4 if ``even`` (elements added alternately at the upper and lower end).
    """
    first = math.floor(limits[0] / size_m + 0.5 + 1e-9)
    last = max(math.ceil(limits[1] / size_m - 0.5 - 1e-9), first)
    minimum = 4 if even else 1
    while last - first + 1 < minimum or (even and (last - first + 1) % 2):
        if (last - first) % 2:
            first -= 1
        else:
            last += 1
    return ((first - 0.5) * size_m, (last + 0.5) * size_m), last - first + 1


def _richardson(fine: ContactResult, coarse: ContactResult, wall_time_s: float) -> ContactResult:
    """Richardson extrapolation (order 1) of F_x, F_y, M_z from the fine grid h and the merged grid 2h.

    F = 2 F_h - F_2h; the fine grid's estimated error F_h - F = F_2h - F_h is reported per quantity. The
    normal solution, the fields and the other outputs are the fine grid's.
    """
    names = ("creep_force_long_N", "creep_force_lat_N", "spin_moment_Nm")
    values = {k: 2.0 * getattr(fine, k) - getattr(coarse, k) for k in names}
    success = bool(fine.success and coarse.success)
    message = fine.message
    if not coarse.success:
        message = f"{fine.message}; coarse grid of the extrapolation: {coarse.message}"
    message += (
        f"; F_x, F_y, M_z Richardson-extrapolated (order 1) from {fine.extra['nx']} x {fine.extra['ny']} and "
        f"{coarse.extra['nx']} x {coarse.extra['ny']} elements"
    )
    extra = dict(fine.extra)
    extra["richardson"] = {
        "coarse_nx": coarse.extra["nx"],
        "coarse_ny": coarse.extra["ny"],
        "fine": {k: getattr(fine, k) for k in names},
        "coarse": {k: getattr(coarse, k) for k in names},
        "fine_error_estimate": {k: getattr(fine, k) - values[k] for k in names},
    }
    return dataclasses.replace(
        fine,
        success=success,
        status=coarse.status if fine.success and not coarse.success else fine.status,
        message=message,
        wall_time_s=wall_time_s,
        extra=extra,
        **values,
    )


GRID_ERROR_QUANTITIES = (
    ("normal_force_N", "normal force"),
    ("creep_force_N", "creep force"),
    ("max_pressure_Pa", "max pressure"),
    ("contact_area_m2", "contact area"),
)
"""The quantities whose relative grid-error estimate is held against ``grid_tolerance`` (key, words)."""


GRID_ERROR_MIN_ORDER = 0.6
"""The smallest convergence order the estimate extrapolates with (:func:`_smooth_error`): a slower observed
contraction is treated as this order (the estimate at most |d1|/(sqrt 2 - 1) = 2.4 |d1|)."""


def _smooth_error(fine: float, coarse: float, coarsest: float | None) -> float:
    """Estimated error of ``fine`` from the values on elements 1, 2 and 4 times as large.

    Differences d1 = v_h - v_2h, d2 = v_2h - v_4h, observed order p = log2(|d2|/|d1|) when they have one sign.

    * 0 < p < 1 (slower than first order): |d1|/(2^p - 1), Richardson's error at the observed order (p at least
      :data:`GRID_ERROR_MIN_ORDER`);
    * otherwise the bound max(|d1|, |d2|/2): Richardson's error |d1| of a first-order method (steady rolling's
      upwind slip and the element-count area are first order), or half the coarse pair's difference when that is
      larger (observed orders above 1 on coarse grids are pre-asymptotic: the large-spin case's order tends to 1.0,
      benchmarks/results/bem_rolling_coarse.md; the linear-range creep cases jump from 20 to 40 elements and move
      little from 40 to 80, where |d1| alone was measured to be a third of the error against Kalker's exact
      coefficients: benchmarks/results/bem_grid_error.md), or for oscillating differences; for the second-order
      normal problem this overestimates by 2-4.

    Without v_4h, |d1|.
    """
    d1 = fine - coarse
    if coarsest is None:
        return abs(d1)
    d2 = coarse - coarsest
    if d1 * d2 > 0 and abs(d1) < abs(d2) < 2.0 * abs(d1):
        order = math.log2(abs(d2) / abs(d1))
        return abs(d1) / (2.0 ** max(order, GRID_ERROR_MIN_ORDER) - 1.0)
    return max(abs(d1), abs(d2) / 2.0)


def grid_error_estimate(levels, friction_coefficient: float) -> dict | None:
    """Discretisation-error estimate of ``levels[0]`` from companions on coarser grids over the same area.

    Args:
        levels: [fine, coarse, coarsest] ContactResults with elements 1, 2 and 4 times as large (the last may be
            None; the coarse one None means no estimate).
        friction_coefficient: mu, for the floor of the creep-force scale.

    Returns:
        None when the coarse companion is missing or failed; else a dict with the absolute estimates
        ``normal_force_N``, ``creep_force_N`` (|(e_x, e_y)| of the two creep-force components),
        ``spin_moment_Nm``, ``max_pressure_Pa``, ``contact_area_m2``; ``relative`` (each against the fine value;
        the creep force against max(|F_t|, 0.01 mu F_N), the scale of ``wheelrail bench``), ``largest_relative``
        (over :data:`GRID_ERROR_QUANTITIES`) and ``grids`` [[nx, ny], ...]. Each quantity by :func:`_smooth_error`,
        except the area of a sampled patch (an element count), estimated from where its edge lies within its cells
        (:mod:`rigid_dynamics.contact.edge_area`; benchmarks/results/area_edge_error.md)
        (measured against Hertz and the converged creep forces of the named cases:
        ``benchmarks/results/bem_grid_error.md``).
    """
    fine, coarse, coarsest = levels
    if coarse is None or not coarse.success or coarse.status == "no-contact":
        return None
    if coarsest is not None and (not coarsest.success or coarsest.status == "no-contact"):
        coarsest = None

    def values(name):
        return [None if r is None else getattr(r, name) for r in (fine, coarse, coarsest)]

    def smooth(name):
        v = values(name)
        return _smooth_error(v[0], v[1], v[2])

    creep = (
        math.hypot(smooth("creep_force_long_N"), smooth("creep_force_lat_N"))
        if fine.creep_force_long_N is not None
        else 0.0
    )
    absolute = {
        "normal_force_N": smooth("normal_force_N"),
        "creep_force_N": creep,
        "spin_moment_Nm": smooth("spin_moment_Nm") if fine.spin_moment_Nm is not None else 0.0,
        "max_pressure_Pa": smooth("max_pressure_Pa"),
        "contact_area_m2": smooth("contact_area_m2"),
    }
    edge = fine.extra.get("contact_area_edge_m2")
    if edge is not None:
        # an element count: the edge's place within its cells (rigid_dynamics.contact.edge_area), not the companions'
        # differences (the count moves up and down by a fraction of a cell's row as the edge crosses cell centres)
        absolute["contact_area_m2"] = EDGE_SAFETY * edge_error(
            fine.contact_area_m2, edge, coarse.extra.get("contact_area_edge_m2"), 2.0
        )
    creep_scale = max(
        math.hypot(fine.creep_force_long_N or 0.0, fine.creep_force_lat_N or 0.0),
        0.01 * friction_coefficient * fine.normal_force_N,
    )
    scales = {
        "normal_force_N": fine.normal_force_N,
        "creep_force_N": creep_scale,
        "max_pressure_Pa": fine.max_pressure_Pa,
        "contact_area_m2": fine.contact_area_m2,
    }
    relative = {k: (absolute[k] / scales[k] if scales[k] > 0 else math.inf) for k, _ in GRID_ERROR_QUANTITIES}
    return {
        **absolute,
        "relative": relative,
        "largest_relative": max(relative.values()),
        "grids": [[r.extra["nx"], r.extra["ny"]] for r in (fine, coarse, coarsest) if r is not None],
    }


NOT_ESTIMATED_REASON = "estimate_grid_error = false"
"""The reason a solve with ``estimate_grid_error = false`` gives for its missing estimate."""


def _not_estimated_note(reason: str = NOT_ESTIMATED_REASON) -> str:
    """The message part of a result whose grid error is not estimated (:func:`_without_grid_error`)."""
    return f"; grid error not estimated ({reason})"


def _without_grid_error(result: ContactResult, reason: str, wall_time_s: float) -> ContactResult:
    """``result`` marked as not estimated (``extra["grid_error"]["estimated"]`` False, the reason in the message)."""
    extra = dict(result.extra)
    extra["grid_error"] = {"estimated": False, "reason": reason}
    extra["grid_error_estimate"] = None
    message = result.message + _not_estimated_note(reason)
    return dataclasses.replace(result, message=message, extra=extra, wall_time_s=wall_time_s)


def _with_grid_error(result: ContactResult, estimate, tolerance: float, refinements: int, wall_time_s: float):
    """``result`` with ``extra["grid_error"]`` (and ``grid_error_estimate``, the largest relative estimate) and,
    when the estimate is missing or above ``tolerance``, status "warning" with the reason in the message.
    """
    extra = dict(result.extra)
    nx, ny = extra["nx"], extra["ny"]
    status, message = result.status, result.message
    if estimate is None:
        extra["grid_error"] = {"tolerance": tolerance, "refinements": refinements, "estimated": False}
        extra["grid_error_estimate"] = None
        if status == "ok":
            status = "warning"
        message += (
            f"; the grid error is not estimated: {nx} x {ny} elements are too few for a companion grid twice as "
            f"coarse (or it failed); expected at least {2 * MIN_COMPANION_ELEMENTS} elements along x and y"
        )
    else:
        extra["grid_error"] = {**estimate, "tolerance": tolerance, "refinements": refinements, "estimated": True}
        extra["grid_error_estimate"] = estimate["largest_relative"]
        relative = estimate["relative"]
        # the layout every rung that states its error uses (comparisons.stated_errors; the FEA's fea.refinement)
        extra["discretisation_error"] = {
            "method": "companion grids with elements 2x and 4x as large (grid_error_estimate)",
            "relative_error": {
                "normal_force": relative["normal_force_N"],
                "max_pressure": relative["max_pressure_Pa"],
                "contact_area": relative["contact_area_m2"],
                "creep_force_long": relative["creep_force_N"],
                "creep_force_lat": relative["creep_force_N"],
            },
        }
        worst = [
            f"{words} {estimate['relative'][k]:.2%}"
            for k, words in GRID_ERROR_QUANTITIES
            if estimate["relative"][k] > tolerance
        ]
        if worst:
            if status == "ok":
                status = "warning"
            message += (
                f"; estimated grid error above grid_tolerance {tolerance:g} ({tolerance:.2%}) at {nx} x {ny} elements: "
                + ", ".join(worst)
                + " (a finer grid: smaller dx_m/element_size_m, larger nx/ny, or more max_refinements)"
            )
        else:
            message += (
                f"; estimated grid error {estimate['largest_relative']:.2%} <= grid_tolerance {tolerance:g} "
                f"({tolerance:.2%}) at {nx} x {ny}"
            )
    return dataclasses.replace(result, status=status, message=message, extra=extra, wall_time_s=wall_time_s)


def _elliptic_semi_axes(x, y, pressure, contact, dx, dy) -> tuple[float, float, bool]:
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
        return (*extents, False)
    weights = pressure[jj, ii]
    xc = float(np.sum(weights * x[ii]) / np.sum(weights))
    yc = float(np.sum(weights * y[jj]) / np.sum(weights))
    design = np.stack([np.ones(len(ii)), (x[ii] - xc) ** 2, (y[jj] - yc) ** 2], axis=1)
    c0, c1, c2 = np.linalg.lstsq(design, weights**2, rcond=None)[0]
    if not (c0 > 0 and c1 < 0 and c2 < 0):
        return (*extents, False)
    return float(np.sqrt(-c0 / c1)), float(np.sqrt(-c0 / c2)), True
