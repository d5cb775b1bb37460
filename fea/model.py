"""The ``fea`` contact model: FEniCSx frictionless normal contact of one patch (three formulations).

Registered as ``"fea.model:FeaModel"`` in :mod:`rigid_dynamics.contact.registry`. Importing this
module is cheap: gmsh, DOLFINx and PETSc are imported inside :meth:`FeaModel.solve`.

Formulations (option ``formulation``):

* ``"rigid"`` (default, fast verification mode; :mod:`fea.solver`): half-space theory of two
  quasi-identical bodies, i.e. one elastic block with E_body = E* (1 - nu^2) (E* = G / (1 - nu),
  :attr:`Material.combined_modulus_Pa`) against a rigid surface at the undeformed distance h(x, y)
  of the patch (``geometry.gap_m`` + approach). A quadric patch (``geometry.undeformed is None``)
  uses a quarter model with symmetry planes x = 0 and y = 0; a sampled gap uses the full block.
  P1 or P2 displacements.
* ``"two-body"`` (:mod:`fea.two_body`): two elastic quadric bodies (E, nu each, the relative
  curvature split equally), node-to-surface pairing updated in the Newton iterations.
* ``"profiles"``: local rail and wheel sections meshed from the real profiles around the patch's
  contact points (:mod:`meshing.profile_sections`), same two-body solver; yaw is neglected.

Creep forces (option ``rolling``, default ``"series"``): a quadric patch under load control with longitudinal and/or
lateral creepage and no spin, rigid formulation, Coulomb friction, one MPI rank, gets the steady-rolling creep force
of :func:`fea.rolling_series.solve_rolling_series` (three rolling blocks at ``rolling_elements`` elements per
semi-axis, sized by Hertz's semi-axes at the normal force, each with its own frictionless normal solve; the force of
the finest, on the wheel in the contact frame, with its first-order Richardson error; about 25 s CPU at 4/6/9 on the
Hertz circle). Its stated error goes where every rung states its errors (``extra["discretisation_error"]
["relative_error"]["creep_force_long"]`` and ``["creep_force_lat"]``: |(e_x, e_y)| / max(|F|, 0.01 mu N), the BEM's
scale; a stated error above ``mesh_tolerance`` makes the status "mesh-tolerance-not-met", as the normal problem's),
the series in ``extra["tangential"]``. Every other case, and a series whose status is not "ok"
("unresolved": the slip zone narrower than a cell, e.g. the linear range; "irregular"; "not-converged"), gives creep
forces None, ``extra["tangential"]["status"]`` and ``["message"]`` saying why. Spin is not solved: the series was
measured against the BEM at pure xi and eta only (docs/models.md, FEA with Coulomb friction). The normal problem's
results (N, p max, area, stresses, their stated errors) are the normal solve's, on its own meshes.

Peak box (sampled patches, rigid formulation, solved to ``mesh_tolerance``). The pressure top of a sampled patch can
be much narrower than the patch: at the demo's peak (polygonal-wheel, 98 kN) a ridge about 2 mm wide across a patch
20 mm long, 1.4 mm from its edge, where the isotropic mesh of the patch box put 2-4 elements (0.47-1.07 mm) and the
max pressure converged at order 0.29 (benchmarks/results/fea_peak_pressure.md). Before the series, one solve a
refinement step coarser than its first level finds a first box: the nodes whose patch-averaged pressure is at least
``PEAK_LEVEL`` (0.85) of the largest, their bounding box padded by that solve's element size (the patch's). That level
is solved again with this box meshed finer, and the box is taken again from its nodes, averaged inside the box over
1.5 of the box's element sizes: the first solve alone (1.6 mm elements and a 2.4 mm average on the demo's patch) spread
the ridge to 750-990 MPa with the node placement, below 0.85 / 0.77 times the patch's second top (744 MPa, 13 mm away)
on four of five block sizes, and the box then held both (8 x 18.7 mm against 5.96 x 4.03 mm; the block size changed
only gmsh's node placement). The second pass gives 7.9-8.2 x 4.5-4.8 mm at y = -11.28 mm for blocks of 19 to 40
semi-axes, holding the half-space solution's (the BEM's) >= 0.85 region. Every level of the
series then meshes this box (fixed across the levels) ``peak_refinement`` (3) times finer than the patch
(``meshing.hertz`` ``peak_boxes_m``: the size grows with the same grading away from it), at about 35 % more unknowns
on that patch. The max pressure is the peak of the quadric cap fitted to p^2 = (N_i / w_i)^2, weighted by w_i, over
the ellipse of fixed semi-axes R = ``WINDOW_FRACTION`` (0.6) times the box's half-widths (fea.postprocess.window_peak;
an ellipse of the box's proportions, so that the fit sees the top's fall along a ridge as well as across it: a disc
of 0.6 times the smaller half-width, 0.36 mm on manchester-a22's 5.2 x 1.2 mm flange box, saw too little of the fall
along the ridge, and its top fell outside it on some level): a fixed region, so the value converges with the mesh as
the pressure's weighted averages do, to the continuous fit whose model error is O(R^4) on a smooth non-quadric top
(zero on Hertz's p^2, at any axes); that model error is estimated from a second fit over R / 1.5 centred at the first
one's top, |p(R) - p(R/1.5)| / (1 - 1.5^-4), and added to the max pressure's Richardson estimate
(``discretisation_error.window_relative_error``). Chosen over a fit radius that
shrinks with h (its bias fell as h^(1/2) on the ridge) and over a fixed-count radius (r = 3-6 local elements: the
nodal scatter of a few per cent then does not average out, level-to-level changes of 0.5-2 % of either sign), by the
measured series of benchmarks/results/fea_peak_pressure.md.

Frame: contact frame of the patch (x rolling, y lateral, z normal rail -> wheel); the block stands
for the body below the contact plane, the pressure acts on the wheel along +z. Units SI.

Runs unchanged under ``mpiexec -n N``: the mesh is built on rank 0 and partitioned, every rank
returns the same :class:`ContactResult` (fields gathered); the VTU grid is gathered to rank 0, which
writes it and the PNGs.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from fea.solver import LINEAR_SOLVERS
from rigid_dynamics.contact.options import declare_dataclass, validate_options
from rigid_dynamics.contact.types import ContactFields, ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

FORMULATIONS = ("rigid", "two-body", "profiles")
ROLLING = ("series", "off")


@dataclass(frozen=True)
class FeaOptions:
    """Options of :class:`FeaModel` (pass them as a mapping to ``solve``; unknown keys raise ValueError).

    Attributes:
        quick: coarse mesh (4 elements per semi-axis, block of 12 semi-axes) for a fast estimate.
        formulation: "rigid" (one block with E* against the rigid gap; fast verification mode) or
            "two-body" (two elastic quadric bodies with E, nu each, node-to-surface pairing; quadric
            geometries only, see fea.two_body) or "profiles" (local rail and wheel sections meshed from the
            real profiles ``rail_profile`` / ``wheel_profile`` around the patch's contact points, two elastic
            bodies with node-to-surface pairing; yaw neglected).
        wheel_profile, rail_profile: built-in profile names or files (formulation "profiles").
        mesh_size_factor: multiplies the element size at the patch (1 = min(a, b)/6), > 0.
        elements_per_semi_axis: element count per semi-axis at the patch (overrides quick's 4 / default 6).
        domain_factor: half-width and depth of the block in semi-axes (>= 4).
        degree: displacement degree, 1 or 2 (2: rigid formulation only).
        linear_solver: "auto", "mumps" or "cg-gamg".
        max_iterations: active-set iterations.
        grid_points: points per side of the regular output grid of the pressure.
        filter_radius_factor: pressure averaging radius in element sizes (see fea.postprocess).
        stresses: compute subsurface stresses.
        edge_area: also reconstruct the contact area inside the edge from the free nodes' separation
            (fea.postprocess.edge_reconstructed_area; ``extra['contact_area_edge_m2']``), a measured diagnostic,
            not the reported area (benchmarks/results/fea_edge_area.md); off by default: it costs up to seconds
            per level.
        output_dir: folder for the VTU grid and PNG output, or None.
        min_mesh_quality: smallest accepted minSICN. max_elements: largest accepted element count.
        surface_traction: tangential tractions ON THE WHEEL on a grid of the contact plane, as a mapping with
            ``x_m``, ``y_m`` (grid), ``traction_long_Pa``, ``traction_lat_Pa`` ([j][i] at (x_m[i], y_m[j]); e.g.
            a BEM or FASTSIM solution's fields) and optionally ``source`` (a label); the block (the rail) is
            loaded with minus these (bilinear, 0 outside the grid) as a surface load on its contact face, so
            its subsurface stresses include the friction of that solution. Rigid formulation only; the model
            becomes a full block (the load breaks the quarter symmetry). The creep forces of the result stay
            None (prescribed, not solved). None: frictionless.
        stress_points_m: points (x, y, z) of the contact frame (z < 0: in the body below the contact plane) at
            which the recovered stress tensor is returned in ``extra["stress_points_Pa"]`` (a list of 3 x 3
            tensors, Pa; None where a point lies outside the mesh), or None. Quarter models mirror the point
            into x, y >= 0 and flip the shear components that are odd in x or y.
        mesh_tolerance: relative discretisation error asked of the max pressure, the contact area and (approach
            control) the normal force; the mesh is refined (:mod:`fea.refinement`) until the estimate meets it or
            the next level would exceed ``max_dofs`` (status "mesh-tolerance-not-met"). None: one solve on the
            given mesh, no error estimate (status "error-not-estimated").
        max_dofs: budget of the refinement series: the largest number of displacement unknowns of a level.
        grading: g, the growth of the element size per unit distance away from the patch on the first level
            (meshing.hertz); every refinement divides it by the refinement ratio, so the far field is refined
            with the patch (with a fixed grading the approach stagnates: measured on the Hertz case).
        load_balanced: the caller balances the load with this solve's force under approach control (a wheelset
            equilibrium, :meth:`FeaModel.load_balanced_options`): the max pressure and area are judged at the
            finest level's force and the force is not judged (fea.refinement, load-balanced use).
        peak_refinement: a sampled patch solved to ``mesh_tolerance`` (rigid formulation) is meshed ``peak_refinement``
            times finer in a box around its pressure peak, located by one coarse solve first (module docstring,
            "Peak box"); 1: no peak box.
        rolling: "series": the creep forces of a quadric patch with creepage from the rolling mesh series with their
            stated error (module docstring, "Creep forces"); "off": creep forces None.
        rolling_elements: (n_1, n_2, n_3) elements per semi-axis of the rolling series, at a constant ratio > 1 (e.g.
            (6, 9, 13.5): about four times the cost, half the stated error).
    """

    quick: bool = False
    formulation: str = "rigid"
    wheel_profile: str | None = None
    rail_profile: str | None = None
    mesh_size_factor: float = 1.0
    elements_per_semi_axis: float | None = None
    domain_factor: float | None = None
    degree: int = 1
    linear_solver: str = "auto"
    max_iterations: int = 40
    grid_points: int = 64
    filter_radius_factor: float = 1.5
    stresses: bool = True
    edge_area: bool = False
    output_dir: str | None = None
    min_mesh_quality: float = 0.05
    max_elements: int = 2_000_000
    stress_points_m: tuple | None = None
    surface_traction: dict | None = None
    mesh_tolerance: float | None = 0.02
    max_dofs: int = 200_000
    grading: float = 0.4
    load_balanced: bool = False
    peak_refinement: float = 3.0
    rolling: str = "series"
    rolling_elements: tuple = (4.0, 6.0, 9.0)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mesh_size_factor) and self.mesh_size_factor > 0):
            raise ValueError(f"mesh_size_factor = {self.mesh_size_factor!r}: expected a finite number > 0")
        if self.elements_per_semi_axis is not None and not self.elements_per_semi_axis >= 1:
            raise ValueError(f"elements_per_semi_axis = {self.elements_per_semi_axis!r}: expected >= 1")
        if self.domain_factor is not None and not self.domain_factor >= 4:
            raise ValueError(f"domain_factor = {self.domain_factor!r}: expected >= 4")
        if self.formulation not in FORMULATIONS:
            raise ValueError(f"formulation = {self.formulation!r}: expected one of {FORMULATIONS}")
        if self.formulation == "profiles" and (not self.wheel_profile or not self.rail_profile):
            raise ValueError("formulation = 'profiles': expected the options wheel_profile and rail_profile")
        if self.degree not in (1, 2):
            raise ValueError(f"degree = {self.degree!r}: expected 1 or 2")
        if self.degree == 2 and self.formulation != "rigid":
            raise ValueError(f"degree = 2 with formulation = {self.formulation!r}: expected formulation 'rigid'")
        if int(self.grid_points) != self.grid_points or self.grid_points < 8:
            raise ValueError(f"grid_points = {self.grid_points!r}: expected an integer >= 8")
        if not (math.isfinite(self.filter_radius_factor) and self.filter_radius_factor >= 0):
            raise ValueError(f"filter_radius_factor = {self.filter_radius_factor!r}: expected a number >= 0")
        if self.surface_traction is not None:
            t = self.surface_traction
            missing = {"x_m", "y_m", "traction_long_Pa", "traction_lat_Pa"} - set(t)
            if missing:
                raise ValueError(f"surface_traction: missing {sorted(missing)}")
            shape = (len(t["y_m"]), len(t["x_m"]))
            for key in ("traction_long_Pa", "traction_lat_Pa"):
                arr = np.asarray(t[key], dtype=float)
                if arr.shape != shape or not np.all(np.isfinite(arr)):
                    raise ValueError(f"surface_traction.{key}: expected finite values of shape {shape}")
            if self.formulation != "rigid":
                raise ValueError(f"surface_traction with formulation = {self.formulation!r}: expected 'rigid'")
        if self.mesh_tolerance is not None and not (math.isfinite(self.mesh_tolerance) and self.mesh_tolerance > 0):
            raise ValueError(f"mesh_tolerance = {self.mesh_tolerance!r}: expected a finite number > 0 or None")
        if not (math.isfinite(self.grading) and self.grading > 0):
            raise ValueError(f"grading = {self.grading!r}: expected a finite number > 0")
        if not (math.isfinite(self.peak_refinement) and self.peak_refinement >= 1):
            raise ValueError(f"peak_refinement = {self.peak_refinement!r}: expected a finite number >= 1")
        if self.rolling not in ROLLING:
            raise ValueError(f"rolling = {self.rolling!r}: expected one of {ROLLING}")
        levels = self.rolling_elements
        if (
            not isinstance(levels, (tuple, list))
            or len(levels) != 3
            or not all(isinstance(v, (int, float)) and math.isfinite(v) and v >= 2 for v in levels)
            or not levels[0] < levels[1] < levels[2]
            or abs(levels[2] / levels[1] - levels[1] / levels[0]) > 1e-6 * levels[1] / levels[0]
        ):
            raise ValueError(
                f"rolling_elements = {levels!r}: expected three numbers >= 2 at a constant ratio n2/n1 = n3/n2 > 1"
            )
        if self.stress_points_m is not None:
            pts = np.asarray(self.stress_points_m, dtype=float)
            if pts.ndim != 2 or pts.shape[1] != 3 or not np.all(np.isfinite(pts)):
                raise ValueError("stress_points_m: expected a sequence of finite (x, y, z) points")

    @classmethod
    def from_mapping(cls, options: Mapping | None) -> FeaOptions:
        """Validate a mapping of options (unknown keys raise ValueError naming them)."""
        return cls(**validate_options(OPTIONS, options, "fea"))

    @property
    def n_per_semi_axis(self) -> float:
        """Elements per semi-axis actually used."""
        base = self.elements_per_semi_axis or (4.0 if self.quick else 6.0)
        return base / self.mesh_size_factor

    @property
    def block_factor(self) -> float:
        """Block size in semi-axes actually used."""
        return self.domain_factor or (12.0 if self.quick else 20.0)


OPTIONS = declare_dataclass(
    FeaOptions,
    {
        "quick": {"help": "coarse mesh (4 elements per semi-axis, block of 12 semi-axes)"},
        "formulation": {"help": "rigid indenter, two elastic quadrics or real profiles", "choices": FORMULATIONS},
        "wheel_profile": {"help": "wheel profile name or file (formulation 'profiles')"},
        "rail_profile": {"help": "rail profile name or file (formulation 'profiles')"},
        "mesh_size_factor": {
            "help": "element size at the patch / (min(a, b)/6)",
            "minimum": 0,
            "exclusive_minimum": True,
        },
        "elements_per_semi_axis": {"help": "elements per semi-axis at the patch", "minimum": 1},
        "domain_factor": {"help": "half-width and depth of the block in semi-axes", "minimum": 4},
        "degree": {"help": "displacement degree (2: formulation 'rigid' only)", "minimum": 1, "maximum": 2},
        "linear_solver": {"help": "linear solver", "choices": LINEAR_SOLVERS},
        "max_iterations": {"help": "active-set iterations", "minimum": 1},
        "grid_points": {"help": "points per side of the output pressure grid", "minimum": 8},
        "filter_radius_factor": {"help": "pressure averaging radius in element sizes", "minimum": 0},
        "stresses": {"help": "compute subsurface stresses"},
        "edge_area": {"help": "also reconstruct the area inside the edge (a diagnostic, not the reported area)"},
        "output_dir": {"help": "folder for the VTU grid and PNG output"},
        "min_mesh_quality": {"help": "smallest accepted minSICN", "minimum": 0, "maximum": 1},
        "max_elements": {"help": "largest accepted element count", "minimum": 1},
        "stress_points_m": {"help": "contact-frame points (x, y, z < 0) where the stress tensor is returned"},
        "surface_traction": {
            "help": "tangential tractions on the wheel on a grid (x_m, y_m, traction_long_Pa, traction_lat_Pa), "
            "applied negated to the rail block's contact face"
        },
        "mesh_tolerance": {
            "help": "relative discretisation error asked of max pressure, area and force (None: one mesh, no estimate)",
            "minimum": 0,
            "exclusive_minimum": True,
        },
        "max_dofs": {"help": "budget of the mesh refinement: largest number of unknowns of a level", "minimum": 1},
        "grading": {
            "help": "element size growth per unit distance from the patch (first level)",
            "minimum": 0,
            "exclusive_minimum": True,
        },
        "load_balanced": {
            "help": "the caller balances the load with the force (approach control): judge p and area "
            "at the finest level's force, not the force"
        },
        "peak_refinement": {
            "help": "sampled patches solved to mesh_tolerance: element size at the pressure peak / in the patch "
            "(1: no peak box)",
            "minimum": 1,
        },
        "rolling": {
            "help": "creep forces of a quadric patch with creepage: the rolling mesh series (stated error) or off",
            "choices": ROLLING,
        },
        "rolling_elements": {"help": "elements per semi-axis of the rolling series' three meshes (constant ratio)"},
    },
)
"""Options of :class:`FeaModel`: types and defaults from :class:`FeaOptions`, ranges here (``__post_init__``
adds the rules that join two options)."""


class FeaModel:
    """Finite-element contact (elastic block with combined modulus vs rigid indenter; creep forces of quadric patches
    from the rolling series).
    """

    name = "fea"
    description = "finite elements (FEniCSx): normal contact, subsurface stresses, creep forces of quadric patches"
    OPTIONS = OPTIONS

    @staticmethod
    def coarse_options(options: Mapping | None) -> dict | None:
        """Options of one solve on the first mesh of the refinement series (no error estimate), for an iteration
        that calls the model many times on nearby geometries (the wheelset equilibrium: it balances the load with
        these first, then with ``options``); None when ``options`` ask for one mesh already.
        """
        opts = FeaOptions.from_mapping(options)
        if opts.mesh_tolerance is None:
            return None
        return {**(options or {}), "mesh_tolerance": None}

    @staticmethod
    def load_balanced_options(options: Mapping | None) -> dict:
        """Options of the solves of an iteration that balances a load with this model's force under approach control
        (the wheelset equilibrium's full solves): ``load_balanced`` True (fea.refinement, load-balanced use).
        """
        FeaOptions.from_mapping(options)
        return {**(options or {}), "load_balanced": True}

    @staticmethod
    def check_options(options: Mapping | None) -> None:
        """Check the options with the rules joining two of them (ValueError), without solving."""
        FeaOptions.from_mapping(options)

    def solve(
        self,
        geometry: ContactGeometry,
        creepage: Creepage,
        material: Material,
        *,
        normal_force_N: float | None = None,
        options: Mapping | None = None,
        comm=None,
    ) -> ContactResult:
        """Solve the normal contact of one patch and, where the patch has them, its creep forces (module docstring,
        "Creep forces").

        Args:
            geometry: patch geometry (quadric if ``geometry.undeformed`` is None).
            creepage: (xi, eta) of a quadric patch under load control: the creep forces of the rolling series;
                otherwise stored in the result (creep forces None, ``extra["tangential"]`` says why).
            material: elastic constants (E* = G/(1 - nu)).
            normal_force_N: P (load control), N; None = approach control with ``geometry.approach_m``.
            options: see :class:`FeaOptions`.
            comm: MPI communicator (default COMM_WORLD).

        Returns:
            ContactResult with method "fea": normal force (sum of the nodal contact forces), max
            pressure (filtered nodal field), semi-axes (elliptic fit; quadric patches only), contact
            area, pressure on a regular grid, creep forces (or None); extra holds dofs, iterations, stress maxima and
            depths, ``tangential`` (the rolling series or why there is none).
        """
        t0 = time.perf_counter()
        opts = FeaOptions.from_mapping(options)
        if normal_force_N is not None and not (math.isfinite(normal_force_N) and normal_force_N > 0):
            raise ValueError(f"normal_force_N = {normal_force_N!r}: expected a finite number > 0 or None")
        if normal_force_N is None and geometry.undeformed is None and geometry.approach_m <= 0:
            return self._empty(geometry, creepage, "no-contact", "approach_m <= 0: the surfaces do not touch", t0)
        from fea.refinement import solve_to_tolerance

        solve_level, peak = self.level_solver((geometry, creepage, material, normal_force_N), comm, t0)
        key = None
        if opts.load_balanced and normal_force_N is None and opts.mesh_tolerance is not None:
            key = (_series_key(geometry, material, options), math.degrees(geometry.contact_angle_rad))
            memo = self._memo_entry(key)
            peak["box"] = memo.get("peak_box") if memo is not None else None
            reused = self._reuse_series(key, solve_level, t0)
            if reused is not None:
                return _with_rolling(reused, geometry, creepage, material, normal_force_N, opts, comm, t0)
        use_peak_box = (
            geometry.undeformed is not None
            and opts.formulation == "rigid"
            and opts.mesh_tolerance is not None
            and opts.peak_refinement > 1
        )
        locator = None
        if use_peak_box:
            peak["box"], locator = self._locate_peak(solve_level, opts, peak)
        result = solve_to_tolerance(
            solve_level,
            opts,
            approach_control=normal_force_N is None,
            block_estimate=opts.formulation != "profiles",
            t0=t0,
            measure_order=geometry.undeformed is not None,
            finest_force=True,
        )
        info = result.extra.get("discretisation_error") or {}
        if use_peak_box:
            info["peak_box"] = locator
        previous = self._memo_entry(key) if key is not None else None
        if previous is not None and "rerun" in previous:
            info["series_rerun"] = previous["rerun"]  # why the previous series was not reused
        if key is not None and info.get("estimated") and result.status in ("ok", "mesh-tolerance-not-met"):
            last = info["levels"][-1]
            finest = dataclasses.replace(
                opts,
                elements_per_semi_axis=last["elements_per_semi_axis"],
                mesh_size_factor=1.0,
                grading=last["grading"],
                mesh_tolerance=None,
            )
            mesh = (result.extra.get("element_size_m"), result.extra.get("block_half_width_m"))
            entries = self.series_memo.setdefault(key[0], [])
            if previous is not None:
                entries.remove(previous)
            entries.append({
                "angle_deg": key[1],
                "options": finest,
                "status": result.status,
                "info": info,
                "normal_force_N": result.normal_force_N,
                "mesh": mesh,
                "peak_box": peak["box"],
            })  # fmt: skip
        return _with_rolling(result, geometry, creepage, material, normal_force_N, opts, comm, t0)

    def level_solver(self, patch: tuple, comm=None, t0: float | None = None):
        """(solve_level, peak) for one patch = (geometry, creepage, material, normal force or None): solve_level(level
        options, force_N=None) solves one refinement level (``_solve_level``) with the peak box ``peak["box"]``
        (None: none yet) and keeps that level's peak nodes in ``peak["nodes"]`` (for :meth:`_locate_peak`); the
        series, the peak locator, the tests and the benchmarks share it. ``force_N`` (a patch under approach control)
        solves that level under load control at this force, on the mesh the approach sizes (a load-balanced series'
        coarser levels at its finest level's force, fea.refinement "Load-balanced use").
        """
        geometry, creepage, material, normal_force_N = patch
        t0 = time.perf_counter() if t0 is None else t0
        peak: dict = {"box": None}

        def solve_level(level_opts, force_N=None):
            result, write = self._solve_level(
                geometry, creepage, material, normal_force_N, level_opts, comm, t0, peak_box=peak["box"],
                force_N=force_N,
            )  # fmt: skip
            peak["nodes"] = result.extra.pop("peak_nodes_m", None)
            return result, write

        return solve_level, peak

    @staticmethod
    def _locate_peak(solve_level, opts, peak) -> tuple[tuple | None, dict]:
        """The peak box of a sampled patch (module docstring, "Peak box"): two solves one refinement step coarser than
        the series' first level, the first without a box, the second with the first's box meshed ``peak_refinement``
        times finer; the box holds the second solve's nodes whose patch-averaged pressure is at least ``PEAK_LEVEL``
        of its largest, padded by the patch's element size of that level.

        Returns:
            ((x_c, y_c, a, b) or None when a locating solve failed, a record for ``discretisation_error``).
        """
        from fea.refinement import REFINEMENT_RATIO

        n = max(opts.n_per_semi_axis / REFINEMENT_RATIO, 2.0)
        level = dataclasses.replace(
            opts, elements_per_semi_axis=n, mesh_size_factor=1.0, grading=opts.grading * REFINEMENT_RATIO,
            stresses=False, mesh_tolerance=None, output_dir=None,
        )  # fmt: skip
        record = {"elements_per_semi_axis": n, "refinement": opts.peak_refinement, "level": PEAK_LEVEL, "passes": []}
        t = time.perf_counter()
        box = None
        for step in ("coarse", "resolved"):
            peak["box"] = box
            result, _ = solve_level(level)
            nodes = peak.get("nodes")
            if result.status != "ok" or nodes is None or not len(nodes):
                peak["box"] = None
                record.update(box_m=None, why=f"locating solve ({step}) {result.status}: {result.message}",
                              wall_time_s=time.perf_counter() - t)  # fmt: skip
                return None, record
            pad = result.extra["element_size_m"]  # the patch's element size: the same on both passes
            lo, hi = nodes.min(axis=0) - pad, nodes.max(axis=0) + pad
            box = (*(0.5 * (lo + hi)).tolist(), *(0.5 * (hi - lo)).tolist())
            filtered = result.extra.get("max_pressure_filtered_Pa")
            record["passes"].append({"step": step, "box_m": list(box), "dofs": int(result.extra.get("dofs", 0)),
                                     "max_pressure_filtered_Pa": filtered})  # fmt: skip
        peak["box"] = None
        record["box_m"] = list(box)
        record["wall_time_s"] = time.perf_counter() - t
        return tuple(box), record

    def _memo_entry(self, key) -> dict | None:
        """The memorised series of the patch ``key`` = (identity, contact angle in degrees): the entry of that
        identity with the nearest contact angle within ``REUSE_ANGLE_DEG`` (a wheel's tread and flange patches differ
        by more; a fixed rounding of the angle split one patch's poses 0.02 degrees apart).
        """
        entries = self.series_memo.get(key[0]) or []
        near = [e for e in entries if abs(e["angle_deg"] - key[1]) <= REUSE_ANGLE_DEG]
        return min(near, key=lambda e: abs(e["angle_deg"] - key[1])) if near else None

    @property
    def series_memo(self) -> dict:
        """The last refinement series of each load-balanced patch (:meth:`_reuse_series`)."""
        if not hasattr(self, "_series_memo"):
            self._series_memo = {}
        return self._series_memo

    def _reuse_series(self, key, solve_level, t0) -> ContactResult | None:
        """A load-balanced solve of a patch whose series ran at a nearby pose: one solve on that series' finest mesh,
        with its error estimate, when the mesh at the patch is the same (:func:`_same_patch_mesh`) and the force
        within ``REUSE_FORCE_CHANGE`` of the series' (the wheelset equilibrium's later evaluations: the series costs
        three to four solves, and the relative errors of the max pressure and area at a load a few per cent away are
        the same to their own accuracy). None: run the series.
        """
        memo = self._memo_entry(key)
        if memo is None:
            return None
        result, write = solve_level(memo["options"])
        mesh = (result.extra.get("element_size_m"), result.extra.get("block_half_width_m"))
        if result.status != "ok" or not _same_patch_mesh(mesh, memo["mesh"]):
            memo["rerun"] = f"mesh changed ({mesh} against {memo['mesh']}) or status {result.status}"
            return None
        if abs(result.normal_force_N / memo["normal_force_N"] - 1.0) > REUSE_FORCE_CHANGE:
            memo["rerun"] = f"force {result.normal_force_N:.6g} N against {memo['normal_force_N']:.6g} N"
            return None
        write()
        force = memo["normal_force_N"]
        where = "the same meshes"
        if mesh != memo["mesh"]:
            blocks = f"{mesh[1] * 1e3:.4g} mm against the series' {memo['mesh'][1] * 1e3:.4g} mm"
            where = f"the same patch mesh (block half-width {blocks})"
        info = {
            **memo["info"],
            "reused": f"series run at this patch's previous solve on {where} (force {force:.6g} N)",
        }
        errors = info.get("relative_error", {})
        shown = ", ".join(f"{n} {errors[n]:.2%}" for n in info.get("judged", ()) if errors.get(n) is not None)
        met = "met" if memo["status"] == "ok" else "not met"
        message = (
            f"{result.message}; discretisation error ({shown}) from the series at force {force:.6g} N on {where}, "
            f"tolerance {info.get('tolerance'):g} {met}"
        )
        return dataclasses.replace(
            result,
            status=memo["status"],
            message=message,
            wall_time_s=time.perf_counter() - t0,
            extra={**result.extra, "discretisation_error": info},
        )

    def _solve_level(self, geometry, creepage, material, normal_force_N, opts, comm, t0, peak_box=None, force_N=None):
        """One solve on the mesh of ``opts``: (ContactResult with status "ok" or a failure, write()), ``write()``
        writing the VTU grid and the PNGs of this level when ``opts.output_dir`` is set. ``force_N`` (with
        ``normal_force_N`` None): load control at this force on the mesh sized by ``geometry.approach_m`` (the
        solver starts from that approach).
        """
        import dolfinx_solver  # noqa: F401  (must precede dolfinx/petsc4py/mpi4py)
        from mpi4py import MPI

        from fea import postprocess as post
        from fea.domain import hertz_block_domain
        from fea.hertz_reference import hertz_elliptic, hertz_force_from_approach
        from fea.solver import SolverSettings, solve_rigid_indenter
        from meshing.hertz import HertzBlockSpec
        from meshing.quality import QualityLimits

        comm = MPI.COMM_WORLD if comm is None else comm
        if force_N is not None and normal_force_N is not None:
            raise ValueError("force_N: expected a patch under approach control (normal_force_N None)")
        solver_force = normal_force_N if force_N is None else force_N
        e_star = material.combined_modulus_Pa
        nu = material.poisson_ratio
        a_curv, b_curv = geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m
        quadric = geometry.undeformed is None

        # Expected patch (Hertz) sizes the mesh.
        regions = ()
        if quadric:
            if normal_force_N is not None:
                expected = hertz_elliptic(a_curv, b_curv, normal_force_N, e_star)
            else:
                expected = hertz_force_from_approach(a_curv, b_curv, geometry.approach_m, e_star)
            semi = (expected.semi_axis_long_m, expected.semi_axis_lat_m)
            center = (0.0, 0.0)
            h_offset = 0.0
            q0 = expected.approach_m

            def gap0(x, y):
                return a_curv * x**2 + b_curv * y**2

        else:
            und = geometry.undeformed
            h_grid = und.distance_m + geometry.approach_m  # h at zero approach
            finite = np.isfinite(h_grid)
            if not finite.any():
                raise ValueError("geometry.undeformed has no finite distance: expected a sampled gap")
            h_offset = float(h_grid[finite].min())
            if normal_force_N is not None:
                expected = hertz_elliptic(a_curv, b_curv, normal_force_N, e_star)
                q0 = h_offset + expected.approach_m
            else:
                q0 = geometry.approach_m
                if q0 <= h_offset:
                    empty = self._empty(geometry, creepage, "no-contact", "no overlap at the given approach", t0)
                    return empty, _nothing
            overlap = finite & (h_grid < q0)
            gx, gy = np.meshgrid(und.x_m, und.y_m)
            dx = float(np.diff(und.x_m).mean()) if len(und.x_m) > 1 else 0.0
            dy = float(np.diff(und.y_m).mean()) if len(und.y_m) > 1 else 0.0
            x_lo, x_hi = gx[overlap].min() - dx, gx[overlap].max() + dx
            y_lo, y_hi = gy[overlap].min() - dy, gy[overlap].max() + dy
            center = (0.5 * (x_lo + x_hi), 0.5 * (y_lo + y_hi))
            semi = (0.5 * (x_hi - x_lo) / math.sqrt(2.0), 0.5 * (y_hi - y_lo) / math.sqrt(2.0))
            regions = _overlap_regions(overlap, gx, gy, dx, dy)

            def gap0(x, y):
                return geometry.gap_m(x, y) + geometry.approach_m

        if opts.formulation == "two-body" and not quadric:
            raise ValueError(
                "formulation = 'two-body': expected a quadric geometry (geometry.undeformed is None); "
                "sampled gaps use the rigid formulation"
            )
        if opts.formulation == "profiles":
            semi = (expected.semi_axis_long_m, expected.semi_axis_lat_m)
            center = (0.0, 0.0)
            q0 = expected.approach_m
            for name in ("contact_point_rail_m", "contact_point_wheel_m"):
                if not all(math.isfinite(v) for v in getattr(geometry, name)):
                    raise ValueError(f"geometry.{name} = {getattr(geometry, name)!r}: expected profile coordinates")
        semi, center = _mesh_box(semi, center)
        boxes = ()
        if not quadric and opts.formulation == "rigid" and len(regions) > 1:
            boxes = tuple((*c, *r) for r, c in (_mesh_box(r[2:], r[:2]) for r in regions))
        spec = HertzBlockSpec(
            semi_axis_long_m=semi[0],
            semi_axis_lat_m=semi[1],
            elements_per_semi_axis=opts.n_per_semi_axis,
            domain_factor=opts.block_factor,
            grading=opts.grading,
            center_m=center,
            symmetry="quarter" if quadric and opts.formulation != "profiles" and not opts.surface_traction else "full",
            refine_boxes_m=boxes,
        )
        if peak_box is not None and spec.symmetry == "full" and opts.formulation == "rigid":
            spec = dataclasses.replace(spec, peak_boxes_m=((*peak_box, spec.contact_size_m / opts.peak_refinement),))
        h_local = spec.contact_size_m / (opts.peak_refinement if spec.peak_boxes_m else 1.0)
        t_mesh = time.perf_counter()
        limits = QualityLimits(opts.min_mesh_quality, opts.max_elements)
        settings = SolverSettings(
            degree=opts.degree, linear_solver=opts.linear_solver, max_iterations=opts.max_iterations
        )
        if opts.formulation in ("profiles", "two-body"):
            from fea.two_body import hertz_pair_domain, solve_two_body

            if opts.formulation == "profiles":
                domain, _ = _profile_domain(geometry, opts, semi, spec.contact_size_m, comm, limits)
            else:
                half_curv = (0.5 * a_curv, 0.5 * b_curv)
                domain = hertz_pair_domain(spec, half_curv, half_curv, comm, limits)
            t_mesh = time.perf_counter() - t_mesh
            young_body = material.young_modulus_Pa
            sol = solve_two_body(
                domain,
                young_body,
                nu,
                normal_force_N=solver_force,
                approach_m=None if solver_force is not None else geometry.approach_m,
                initial_approach_m=q0,
                contact_size_m=spec.contact_size_m,
                settings=settings,
            )
            if opts.formulation == "profiles":
                sol.node_xy_m[:, 1] *= _lateral_sign(geometry)
                quadric = False
        else:
            domain = hertz_block_domain(spec, comm, limits)
            t_mesh = time.perf_counter() - t_mesh

            def initial_active(x, y):
                return ((x - center[0]) / semi[0]) ** 2 + ((y - center[1]) / semi[1]) ** 2 < 1.0

            young_body = e_star * (1.0 - nu**2)
            traction = _traction_function(opts.surface_traction) if opts.surface_traction else None
            sol = solve_rigid_indenter(
                domain,
                gap0,
                young_body,
                nu,
                normal_force_N=solver_force,
                approach_m=None if solver_force is not None else geometry.approach_m,
                initial_approach_m=q0,
                initial_active=initial_active if quadric else None,
                length_scale_m=min(semi),
                settings=settings,
                surface_traction=traction,
            )

        extra = {
            "dofs": int(sol.dofs),
            "newton_iterations": int(sol.iterations),
            "mpi_ranks": int(comm.size),
            "model": (
                "rail and wheel sections from real profiles, node-to-surface penalty"
                if opts.formulation == "profiles"
                else "two elastic quadric bodies (quarter model), node-to-surface penalty"
                if opts.formulation == "two-body"
                else "quarter block, rigid quadric indenter"
                if spec.symmetry == "quarter"
                else f"full block, rigid {'quadric' if quadric else 'sampled'} indenter"
            ),
            "surface_traction": (
                f"minus the wheel tractions of {opts.surface_traction.get('source', 'the given fields')}"
                if opts.surface_traction
                else "none (frictionless)"
            ),
            "tangential": {
                "status": "not-solved",
                "message": "creep forces None: one normal solve (FeaModel.solve adds the rolling series)",
            },
            "young_modulus_Pa": young_body,
            "element_size_m": spec.contact_size_m,
            "block_half_width_m": spec.half_width_m,
            "mesh": domain.quality.as_dict(),
            "complementarity_residual": sol.complementarity_residual,
            "timings_s": {"mesh": t_mesh, **{k: v for k, v in sol.timings.items() if k.endswith("_s")}},
            "linear_solver": sol.timings.get("linear_solver", ""),
            "approach_note": "approach of a clamped finite block, smaller than the half-space value",
        }
        if sol.status == "no-contact":
            return self._empty(geometry, creepage, "no-contact", sol.message, t0, extra=extra), _nothing

        # Pressure field (full patch).
        xy, force, weight = sol.node_xy_m, sol.node_force_N, sol.node_weight_m2
        if spec.symmetry == "quarter":
            xy, force, weight = post.mirror_quarter(xy, force, weight)
        radius = opts.filter_radius_factor * spec.contact_size_m / opts.degree  # P2: nodes at h/2
        in_contact_nodes = np.tile(sol.active, 4) if len(xy) == 4 * len(sol.active) else sol.active.copy()
        if radius > 0:
            pressure = post.filtered_pressure(
                xy[in_contact_nodes], force[in_contact_nodes], weight[in_contact_nodes], xy, radius
            )
        else:
            pressure = np.where(weight > 0, force / np.where(weight > 0, weight, 1.0), 0.0)
        pressure = np.where(in_contact_nodes, pressure, 0.0)
        max_pressure = float(pressure.max()) if pressure.size else 0.0
        usable = in_contact_nodes & (weight > 1e-9 * weight.max())
        nodal = np.where(usable, force / np.where(usable, weight, 1.0), 0.0)
        peak = (
            post.peak_pressure(xy, nodal, usable, xy[int(np.argmax(pressure))], _peak_fit_radius(spec, h_local))
            if pressure.size
            else None
        )
        extra["max_pressure_filtered_Pa"] = max_pressure
        extra["max_pressure_peak_fit_Pa"] = peak
        window = _window_peak(spec, xy, force, weight, usable, h_local, post) if spec.peak_boxes_m else None
        extra["peak_nodes_m"] = _peak_nodes(spec, xy, force, weight, in_contact_nodes, pressure, radius, post)
        if peak is not None:
            max_pressure = peak
        if window is not None:
            extra["max_pressure_window"] = window
            if window["max_pressure_Pa"] is not None:
                max_pressure = window["max_pressure_Pa"]
        area_nodal = float(sol.node_weight_m2[sol.active].sum()) * domain.symmetry_factor
        weighted = sol.node_weight_m2 > 1e-9 * sol.node_weight_m2.max()
        extra["max_nodal_pressure_Pa"] = float((sol.node_force_N[weighted] / sol.node_weight_m2[weighted]).max())
        extra["contact_area_nodal_m2"] = area_nodal
        if opts.edge_area:  # issue 22, measured (benchmarks/results/fea_edge_area.md): not the reported area
            # the nodes, activity and weights mirrored above for the pressure field; the gap mirrored the same way
            gap = np.tile(sol.node_gap_m, 4) if len(xy) == 4 * len(sol.active) else sol.node_gap_m
            t_edge = time.perf_counter()
            edge = post.edge_reconstructed_area(xy, gap, in_contact_nodes.astype(bool), weight_m2=weight)
            extra["contact_area_edge"] = {**edge, "time_s": time.perf_counter() - t_edge}
            extra["contact_area_edge_m2"] = edge["area_m2"] if math.isfinite(edge["area_m2"]) else None
        extra["max_pressure_definition"] = (
            f"peak of a quadric fitted to the squared nodal pressures N_i / w_i, weighted by w_i, over a fixed ellipse "
            f"of semi-axes {window['semi_axes_m'][0] * 1e3:.3g} x {window['semi_axes_m'][1] * 1e3:.3g} mm (0.6 of "
            f"the peak box's half-widths) in the peak box meshed {opts.peak_refinement:g} times finer "
            "(fea.postprocess.window_peak; fea.model, 'Peak box')"
            if window is not None and window["max_pressure_Pa"] is not None
            else "peak of a quadric fitted to the squared nodal pressures N_i / w_i within "
            f"{_peak_fit_radius(spec, h_local) * 1e3:.3g} mm of the largest patch average "
            "(fea.postprocess.peak_pressure): the "
            "nodal values scatter by several per cent from node to node and their maximum is biased upwards "
            "(max_nodal_pressure_Pa); the largest patch average (max_pressure_filtered_Pa) is below the top"
            if peak is not None
            else f"largest force-weighted average of the nodal pressures within {opts.filter_radius_factor:g} element "
            "sizes (fea.postprocess.filtered_pressure; no quadric cap could be fitted at the top): the nodal values "
            "N_i / w_i scatter by several per cent from node to node (max_nodal_pressure_Pa is their maximum)"
            if radius > 0
            else "largest nodal pressure N_i / w_i (filter_radius_factor 0)"
        )

        semi_long = semi_lat = None
        area = area_nodal
        if quadric:
            # nodes with a lumped weight (all P1 nodes; P2 edge midpoints, whose N_i / w_i is the pressure)
            has_weight = weight > 1e-9 * weight.max()  # P2 vertices have w = 0 (rounding)
            raw = np.where(in_contact_nodes & has_weight, force / np.where(has_weight, weight, 1.0), 0.0)
            fit = post.fit_elliptic_pressure(xy[has_weight], raw[has_weight])
            extra["elliptic_fit"] = fit
            if math.isfinite(fit["semi_axis_long_m"]):
                semi_long, semi_lat = fit["semi_axis_long_m"], fit["semi_axis_lat_m"]
                area = math.pi * semi_long * semi_lat

        fields = None
        if in_contact_nodes.any():
            act = xy[in_contact_nodes]
            span_x = max(np.abs(act[:, 0] - center[0]).max() * 1.25, radius)
            span_y = max(np.abs(act[:, 1] - center[1]).max() * 1.25, radius)
            x_m = np.linspace(center[0] - span_x, center[0] + span_x, opts.grid_points)
            y_m = np.linspace(center[1] - span_y, center[1] + span_y, opts.grid_points)
            grid, mask = post.pressure_on_grid(xy, pressure, x_m, y_m)
            fields = ContactFields(x_m=x_m, y_m=y_m, pressure_Pa=grid, in_contact=mask)

        stress_fn = None
        if opts.stresses:
            stress_fn, coords, stress = post.recover_nodal_stress(sol.displacement, young_body, nu)
            lower = _lower_body_nodes(domain, stress_fn, len(coords), coords, spec)
            extra.update(_stress_maxima(comm, coords[lower], stress[lower], spec, quadric, post))
            if opts.stress_points_m is not None:
                extra["stress_points_Pa"] = _stress_at_points(
                    comm, stress_fn, np.asarray(opts.stress_points_m, float), domain.symmetry == "quarter"
                )

        def write():
            if opts.output_dir is not None:
                from fea.output import write_outputs

                extra["files"] = write_outputs(
                    _patch_output_dir(opts.output_dir, geometry),
                    sol,
                    stress_fn,
                    fields,
                    domain,
                    spec,
                    young_body,
                    nu,
                    comm=comm,
                )

        result = ContactResult(
            method=self.name,
            success=sol.success,
            status=sol.status,
            message=sol.message,
            normal_force_N=float(sol.normal_force_N),
            max_pressure_Pa=max_pressure,
            semi_axis_long_m=semi_long,
            semi_axis_lat_m=semi_lat,
            contact_area_m2=area,
            approach_m=float(sol.approach_m),
            creepage=creepage,
            fields=fields,
            iterations=int(sol.iterations),
            residual=float(sol.complementarity_residual),
            wall_time_s=time.perf_counter() - t0,
            extra=extra,
        )
        return result, write

    def _empty(self, geometry, creepage, status, message, t0, extra=None) -> ContactResult:
        return ContactResult(
            method=self.name,
            success=True,
            status=status,
            message=message,
            normal_force_N=0.0,
            max_pressure_Pa=0.0,
            contact_area_m2=0.0,
            approach_m=geometry.approach_m,
            creepage=creepage,
            wall_time_s=time.perf_counter() - t0,
            extra=extra or {},
        )


def _rolling_precondition(geometry, creepage, material, normal_force_N, opts, comm, result) -> str | None:
    """Why the rolling series is not run for this patch (a sentence), or None when it is (module docstring, "Creep
    forces").
    """
    if opts.rolling == "off":
        return "option rolling = 'off'"
    if creepage.longitudinal == 0.0 and creepage.lateral == 0.0 and creepage.spin_1_per_m == 0.0:
        return "no creepage"
    if creepage.spin_1_per_m != 0.0:
        return (
            f"spin {creepage.spin_1_per_m:g} 1/m: the rolling series is measured against the BEM at pure "
            "longitudinal and lateral creepage only (docs/models.md, FEA with Coulomb friction)"
        )
    if geometry.undeformed is not None:
        return "a sampled patch: the rolling block is built for a quadric patch centred at the contact frame's origin"
    if opts.formulation != "rigid":
        return f"formulation {opts.formulation!r}: the rolling series uses the rigid formulation's equivalent block"
    if opts.surface_traction:
        return "the tractions are prescribed (surface_traction), not solved"
    if normal_force_N is None:
        return (
            "approach control: the series runs under load control (one series per evaluation of a wheelset "
            "equilibrium would cost three rolling solves each)"
        )
    if material.friction is not None:
        return "a friction law is given: the FEA's rolling solver takes Coulomb's law with one coefficient"
    if comm is not None and comm.size != 1:
        return f"{comm.size} MPI ranks: the rolling solver runs on one rank"
    if not result.success or result.status == "no-contact":
        return f"the normal solve ended {result.status}"
    return None


def _with_rolling(result, geometry, creepage, material, normal_force_N, opts, comm, t0) -> ContactResult:
    """``result`` (the normal solve) with the creep forces of the rolling series and their stated error where the
    patch has them (module docstring, "Creep forces"), else creep forces None and ``extra["tangential"]`` saying why.
    """
    extra = dict(result.extra)
    why = _rolling_precondition(geometry, creepage, material, normal_force_N, opts, comm, result)
    if why is not None:
        status = "off" if opts.rolling == "off" else "no-creepage" if why == "no creepage" else "not-solved"
        extra["tangential"] = {"status": status, "message": f"creep forces None: {why}"}
        return dataclasses.replace(result, extra=extra)
    from fea.hertz_reference import hertz_elliptic
    from fea.rolling_series import solve_rolling_series

    mu = material.friction_coefficient
    xi, eta = creepage.longitudinal, creepage.lateral
    a_curv, b_curv = geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m
    nu = material.poisson_ratio
    hertz = hertz_elliptic(a_curv, b_curv, normal_force_N, material.combined_modulus_Pa)
    method = (
        "steady rolling (fea.friction.solve_rolling) on rolling blocks (meshing.rolling_block, edge-fitted rows) at "
        f"{'/'.join(f'{n:g}' for n in opts.rolling_elements)} elements per semi-axis of Hertz's patch "
        f"({hertz.semi_axis_long_m * 1e3:.4g} x {hertz.semi_axis_lat_m * 1e3:.4g} mm), each with its own normal "
        "solve; first-order Richardson error of the finest (fea.rolling_series)"
    )
    t_series = time.perf_counter()
    if mu == 0.0:
        fx = fy = 0.0
        tangential = {"status": "ok", "message": "no friction: F = 0", "method": "mu = 0", "creep_force_N": [0.0, 0.0],
                      "stated_error_N": [0.0, 0.0]}  # fmt: skip
        error = (0.0, 0.0)
    else:
        try:
            series = solve_rolling_series(
                hertz.semi_axis_long_m, hertz.semi_axis_lat_m, lambda x, y: a_curv * x**2 + b_curv * y**2,
                material.combined_modulus_Pa * (1.0 - nu**2), nu, mu, normal_force_N, (xi, eta, 0.0),
                elements=tuple(float(n) for n in opts.rolling_elements), initial_approach_m=hertz.approach_m,
            )  # fmt: skip
        except (ValueError, RuntimeError, ArithmeticError) as exc:  # a failed series is a status, never a number
            extra["tangential"] = {
                "status": "failed",
                "message": f"creep forces None: the rolling series raised {type(exc).__name__}: {exc}",
                "method": method,
                "wall_time_s": time.perf_counter() - t_series,
            }
            return dataclasses.replace(result, extra=extra, wall_time_s=time.perf_counter() - t0)
        tangential = {
            "status": series.status,
            "message": series.message,
            "method": method,
            "elements": [float(n) for n in opts.rolling_elements],
            "creep_force_N": list(series.creep_force_N),
            "stated_error_N": list(series.stated_error_N),
            "extrapolated_N": list(series.extrapolated_N),
            "observed_order": list(series.observed_order),
            "levels": [{k: (list(v) if isinstance(v, tuple) else v) for k, v in lv.items()} for lv in series.levels],
        }
        fx, fy = series.creep_force_N
        error = series.stated_error_N
        ok = series.status == "ok" and all(math.isfinite(v) for v in (fx, fy, *error))
        if not ok:
            tangential["message"] = f"creep forces None: series {series.status}: {series.message}"
            tangential["creep_force_N"] = tangential["stated_error_N"] = None  # a status, never a number
            tangential["finest_level_force_N"] = list(series.creep_force_N)  # diagnostic, not a result
            tangential["wall_time_s"] = time.perf_counter() - t_series
            extra["tangential"] = tangential
            return dataclasses.replace(result, extra=extra, wall_time_s=time.perf_counter() - t0)
    scale = max(math.hypot(fx, fy), 0.01 * mu * result.normal_force_N)
    relative = math.hypot(*error) / scale if scale > 0 else 0.0
    tangential["relative_error"] = relative
    tangential["wall_time_s"] = time.perf_counter() - t_series
    extra["tangential"] = tangential
    info = dict(extra.get("discretisation_error") or {})
    info["relative_error"] = {
        **(info.get("relative_error") or {}),
        "creep_force_long": relative,
        "creep_force_lat": relative,
    }  # the creep force as a vector, against max(|F|, 0.01 mu N), as the BEM states it (comparisons.stated_errors)
    info["creep_force_method"] = method
    extra["discretisation_error"] = info
    message = f"{result.message}; creep forces from the rolling series, stated error {relative:.2%}"
    status = result.status
    if opts.mesh_tolerance is not None and relative > opts.mesh_tolerance:
        # as the normal problem's series: a solution with a larger error than asked (the levels are fixed options)
        message += (
            f" above mesh_tolerance = {opts.mesh_tolerance:g} at rolling_elements = "
            f"{'/'.join(f'{n:g}' for n in opts.rolling_elements)} (finer levels, e.g. 6/9/13.5, state less)"
        )
        status = "mesh-tolerance-not-met" if status == "ok" else status
    return dataclasses.replace(
        result, creep_force_long_N=float(fx), creep_force_lat_N=float(fy), status=status, message=message,
        extra=extra, wall_time_s=time.perf_counter() - t0,
    )  # fmt: skip


WINDOW_FRACTION = 0.6
"""The semi-axes of the max-pressure fit's ellipse in a peak box: this fraction of the box's half-widths (module
docstring, "Peak box")."""
WINDOW_RATIO = 1.5
"""The fit's model error is estimated from a second fit over a disc this many times smaller (module docstring)."""
WINDOW_ORDER = 4.0
"""Order in the radius of the model error of a quadric-cap fit centred at a smooth top (module docstring)."""
PEAK_LEVEL = 0.85
"""The peak box holds the locating solve's nodes whose patch-averaged pressure is at least this fraction of the
largest (module docstring, "Peak box")."""
REUSE_ANGLE_DEG = 1.0
"""A load-balanced solve reuses the series of the same side's patch whose contact angle is within this, degrees."""
REUSE_FORCE_CHANGE = 0.1
"""A load-balanced solve reuses its patch's last series estimate when its force is within this fraction of the
series' (:meth:`FeaModel._reuse_series`)."""


def _series_key(geometry, material, options) -> tuple:
    """Identity of a patch for :meth:`FeaModel._reuse_series` within one model instance (one wheelset case): side,
    material and options (the contact angle is matched within ``REUSE_ANGLE_DEG``, the mesh itself, the rounded mesh
    box, is compared after the solve; the sampled patch's fitted curvatures move in their fourth digit from one pose
    to the next: not a key).
    """
    return (
        geometry.side,
        material.combined_modulus_Pa,
        material.poisson_ratio,
        repr(sorted((options or {}).items())),
    )


MESH_SIZE_STEP = 1.1
"""The semi-axes that size the mesh are rounded to powers of this ratio (see :func:`_mesh_box`)."""
MESH_CENTRE_STEP = 0.25
"""The centre of the refined box is rounded to multiples of this fraction of the smaller rounded semi-axis."""


def _same_patch_mesh(mesh, memo_mesh) -> bool:
    """Whether a solve's mesh (element size at the patch, block half-width) is the one a memorised series' error
    belongs to (:meth:`FeaModel._reuse_series`): the same element size, and a block of the same size or one rounding
    step (``MESH_SIZE_STEP``) of the larger semi-axis apart. The block is ``domain_factor`` times the rounded larger
    semi-axis, and the load-balanced series states its truncation at a fixed load as a term in those semi-axes
    (fea.refinement, ``LOAD_CONTROL_BLOCK_ERROR``, ten times the measured value), not from the meshes: a block
    10 % wider with the same patch mesh changes neither. manchester-a22's tread patch crossed that rounding between
    two evaluations 2.9 % of load apart (block half-width 59.7 against 65.7 mm, element size equal) and its series
    (two locating solves, three levels) ran again: 374 of the run's 1012 s.
    """
    size, block = mesh
    memo_size, memo_block = memo_mesh
    if size is None or block is None or memo_size is None or memo_block is None or size != memo_size:
        return False
    return abs(math.log(block / memo_block)) <= math.log(MESH_SIZE_STEP) * (1.0 + 1e-9)


def _mesh_box(semi, center):
    """The expected patch (semi-axes, centre) that sizes and places the mesh, rounded to a grid.

    The mesh is a function of this box only (not of the gap), and gmsh meshes the same box the same way: nearby
    poses of a wheelset equilibrium then solve on one mesh, and the force is a smooth function of the approach
    instead of jumping with every remeshing (the box followed the sampled overlap, and approaches 4e-8 m apart gave
    forces +-3 % apart on a22-flange-root). The rounding moves the element size by at most 5 % and the box by
    1/8 of a semi-axis (the refined region reaches 1.3 semi-axes).
    """
    step = math.log(MESH_SIZE_STEP)
    rounded = tuple(math.exp(round(math.log(s) / step) * step) for s in semi)
    unit = MESH_CENTRE_STEP * min(rounded)
    return rounded, tuple(round(c / unit) * unit for c in center)


def _window_peak(spec, xy, force, weight, usable, h_local, post) -> dict:
    """The max pressure of a patch with a peak box (module docstring, "Peak box"): the weighted quadric-cap fit over
    the ellipse of semi-axes ``WINDOW_FRACTION`` times the box's half-widths (fixed across the refinement series),
    first centred at the largest patch average within the box (radius 1.5 local element sizes), and its model error
    |p(R) - p(R / WINDOW_RATIO)| / (1 - WINDOW_RATIO^-WINDOW_ORDER) relative to p(R), the second fit over the
    ellipse WINDOW_RATIO times smaller centred at the first one's top. Values None where a fit failed (fewer than 12
    nodes, no cap, top outside its window).

    The window follows the box's shape, not only its smaller half-width: the box bounds the level set p >=
    ``PEAK_LEVEL`` p_max, so an ellipse of its proportions sees the same fraction of the top's fall in both
    directions. A disc of 0.6 times the smaller half-width did not: on manchester-a22's flange patch (box 5.2 x
    1.2 mm, a ridge along x) the 0.36 mm disc saw p^2 curve 600 times less along the ridge than across it, the
    scatter of the nodal values set that curvature's sign and size, and the fitted top fell outside the disc (20
    radii away) on one level or another, so the series had no max-pressure error at all.
    """
    xc, yc, a, b, _ = spec.peak_boxes_m[0]
    semi = (WINDOW_FRACTION * a, WINDOW_FRACTION * b)
    out = {"semi_axes_m": list(semi), "max_pressure_Pa": None, "small_window_Pa": None, "relative_error": None}
    inside = usable & (np.abs(xy[:, 0] - xc) <= a) & (np.abs(xy[:, 1] - yc) <= b)
    if not inside.any():
        return out
    pts, f, w = xy[usable], force[usable], weight[usable]
    average = post.filtered_pressure(pts, f, w, xy[inside], 1.5 * h_local)
    big = post.window_peak(pts, f, w, xy[inside][int(np.argmax(average))], semi)
    if big is None:
        return out
    out["max_pressure_Pa"] = big[0]
    out["top_m"] = big[1].tolist()
    small = post.window_peak(pts, f, w, big[1], (semi[0] / WINDOW_RATIO, semi[1] / WINDOW_RATIO))
    if small is not None:
        out["small_window_Pa"] = small[0]
        out["relative_error"] = abs(big[0] - small[0]) / (1.0 - WINDOW_RATIO**-WINDOW_ORDER) / big[0]
    return out


def _peak_nodes(spec, xy, force, weight, in_contact, pressure, radius, post):
    """The nodes whose patch-averaged pressure is at least ``PEAK_LEVEL`` of the largest (the peak box's locator,
    module docstring "Peak box"), None without pressure. Inside a peak box the average is taken over the same number
    of the box's element sizes as elsewhere of the patch's (``radius`` times the box's size over the patch's): an
    average over the patch's radius (2.4 mm on the demo's patch) spreads a ridge 1.5 mm wide and brought its top
    (960 MPa) below 0.85 / 0.77 times the patch's second top (744 MPa), so that the box grew to both.
    """
    locate = pressure
    if spec.peak_boxes_m and radius > 0:
        xc, yc, a, b, h_box = spec.peak_boxes_m[0]
        in_box = in_contact & (np.abs(xy[:, 0] - xc) <= a) & (np.abs(xy[:, 1] - yc) <= b)
        locate = pressure.copy()
        local = radius * h_box / spec.contact_size_m
        locate[in_box] = post.filtered_pressure(
            xy[in_contact], force[in_contact], weight[in_contact], xy[in_box], local
        )
    top = float(locate.max()) if locate.size else 0.0
    return xy[locate >= PEAK_LEVEL * top] if top > 0 else None


def _peak_fit_radius(spec, h_local) -> float:
    """Radius of the peak-pressure fit (fea.postprocess.peak_pressure): sqrt(3 h_c min(a, b)), 0.71 min(a, b) at 6
    elements per semi-axis, shrinking as h^(1/2): the fit's bias O(r^4) then falls as h^2 while the number of nodes
    it averages grows as 1/h. min(a, b) = n h_c: the narrowest region's for a patch of separate regions.
    """
    return math.sqrt(3.0 * h_local * spec.contact_size_m * spec.elements_per_semi_axis)


REGION_FLOOR = 1.0 / 3.0
"""A separate region's semi-axes that size its refined box are at least this fraction of the largest region's
narrower semi-axis (a region of a few sampled points must not set the element size of the whole patch)."""


def _overlap_regions(overlap: np.ndarray, gx: np.ndarray, gy: np.ndarray, dx: float, dy: float) -> tuple:
    """Separate regions of a sampled interpenetration (8-connected components of ``overlap`` on its grid), each as
    (x_c, y_c, a, b): centre and semi-axes of its box padded by one sample, over sqrt(2) (as the one box of the whole
    overlap, the interpenetration of two quadrics being sqrt(2) times their contact patch), largest region first.
    """
    from scipy import ndimage

    labels, count = ndimage.label(overlap, structure=np.ones((3, 3), dtype=int))
    if count < 2:
        return ()
    regions = []
    for k in range(1, count + 1):
        mask = labels == k
        x_lo, x_hi = gx[mask].min() - dx, gx[mask].max() + dx
        y_lo, y_hi = gy[mask].min() - dy, gy[mask].max() + dy
        a, b = 0.5 * (x_hi - x_lo) / math.sqrt(2.0), 0.5 * (y_hi - y_lo) / math.sqrt(2.0)
        regions.append((int(mask.sum()), (0.5 * (x_lo + x_hi), 0.5 * (y_lo + y_hi), a, b)))
    regions.sort(key=lambda item: -item[0])
    floor = REGION_FLOOR * min(regions[0][1][2:])
    return tuple((xc, yc, max(a, floor), max(b, floor)) for _, (xc, yc, a, b) in regions)


def _nothing() -> None:
    """The output writer of a level without contact (nothing to write)."""


def _traction_function(traction: Mapping):
    """(x, y) -> minus the wheel's tractions (the rail block's surface load), bilinear, 0 outside the grid."""
    from scipy.interpolate import RegularGridInterpolator

    grid = (np.asarray(traction["y_m"], float), np.asarray(traction["x_m"], float))
    parts = [
        RegularGridInterpolator(grid, -np.asarray(traction[k], float), bounds_error=False, fill_value=0.0)
        for k in ("traction_long_Pa", "traction_lat_Pa")
    ]

    def evaluate(x, y):
        pts = np.column_stack([np.asarray(y, float), np.asarray(x, float)])
        return parts[0](pts), parts[1](pts)

    return evaluate


def _stress_at_points(comm, stress_fn, points: np.ndarray, quarter: bool) -> list:
    """Recovered (P1) stress tensors at ``points`` (contact frame), as nested lists; None outside the mesh."""
    from dolfinx import geometry

    query = points.copy()
    if quarter:
        query[:, :2] = np.abs(query[:, :2])
    msh = stress_fn.function_space.mesh
    tree = geometry.bb_tree(msh, msh.topology.dim)
    candidates = geometry.compute_collisions_points(tree, query)
    colliding = geometry.compute_colliding_cells(msh, candidates, query)
    found, cells = [], []
    for i in range(len(query)):
        links = colliding.links(i)
        if len(links):
            found.append(i)
            cells.append(links[0])
    local = np.full((len(query), 9), np.nan)
    if found:
        local[found] = stress_fn.eval(query[found], np.asarray(cells, dtype=np.int32))
    merged = np.full((len(query), 9), np.nan)
    for part in comm.allgather(local):
        take = np.isnan(merged[:, 0]) & ~np.isnan(part[:, 0])
        merged[take] = part[take]
    tensors = merged.reshape(-1, 3, 3)
    if quarter:
        sx, sy = np.where(points[:, 0] < 0, -1.0, 1.0), np.where(points[:, 1] < 0, -1.0, 1.0)
        for (i, j), sign in (((0, 1), sx * sy), ((0, 2), sx), ((1, 2), sy)):
            tensors[:, i, j] *= sign
            tensors[:, j, i] *= sign
    return [None if np.isnan(t[0, 0]) else t.tolist() for t in tensors]


def _lower_body_nodes(domain, stress_fn, n, coords, spec):
    """Mask of the owned stress nodes in the body below the contact plane (rail / block)."""
    if "lower" not in domain.groups:
        return np.ones(n, dtype=bool)
    from dolfinx import fem

    cells = domain.cell_tags.find(domain.groups["lower"])
    blocks = fem.locate_dofs_topological(stress_fn.function_space, 3, cells)
    mask = np.zeros(n, dtype=bool)
    mask[blocks[blocks < n]] = True
    return mask


def _lateral_sign(geometry) -> float:
    """+1 if the contact frame's y axis points towards the field side (profile y_p), else -1."""
    toward_field = {"right": 1.0, "left": -1.0}.get(geometry.side, 0.0)
    if toward_field == 0.0:
        return 1.0
    return 1.0 if geometry.frame[1, 1] * toward_field >= 0 else -1.0


def _profile_domain(geometry, opts, semi, contact_size_m, comm, limits):
    """Rail and wheel sections around the patch's contact points (sizes in units of the Hertz semi-axes)."""
    import dataclasses

    from fea.two_body import profile_pair_domain
    from meshing.profile_sections import ProfileSectionSpec, section_surface_points
    from rigid_dynamics.geometry.readers import load_profile

    rail_curve = load_profile(opts.rail_profile, "rail").curve()
    wheel_curve = load_profile(opts.wheel_profile, "wheel").curve()
    a, b = semi
    width, length, depth = 2.0 * max(a, b), 5.0 * a, 3.0 * max(a, b)
    n = min(a, b) / contact_size_m
    radius = geometry.rolling_radius_m if math.isfinite(geometry.rolling_radius_m) else 0.46
    rail = ProfileSectionSpec("rail", geometry.contact_point_rail_m[0], width, length, 1.0, a, b, n)
    wheel = ProfileSectionSpec("wheel", geometry.contact_point_wheel_m[0], width, length, 1.0, a, b, n, radius)
    _, z_rail = section_surface_points(rail_curve, rail)
    _, z_wheel = section_surface_points(wheel_curve, wheel)
    rail = dataclasses.replace(rail, depth_m=depth - min(float(z_rail.min()), 0.0))
    wheel = dataclasses.replace(wheel, depth_m=depth + max(float(z_wheel.max()), 0.0))
    # The wheel builder takes R(y_c) from r0 and the profile; pass r0 so that R(y_c) = rolling radius.
    z_tape = float(wheel_curve.z(0.0)) if wheel_curve.y_min_m < 0.0 < wheel_curve.y_max_m else 0.0
    r0 = radius - (float(wheel_curve.z(wheel.contact_y_m)) - z_tape)
    wheel = dataclasses.replace(wheel, nominal_radius_m=r0)
    domain = profile_pair_domain(rail_curve, wheel_curve, rail, wheel, comm, limits)
    return domain, (rail, wheel)


def _stress_maxima(comm, coords, stress, spec, quadric, post) -> dict:
    """Extremes of von Mises, maximum shear (Tresca, (s1 - s3)/2) and the most compressive principal stress.

    Keys: ``max_von_mises_Pa``, ``max_shear_Pa``, ``min_principal_Pa`` (most negative s3), each with
    ``_point_m`` (x, y, z) and ``_depth_m`` (-z); for quadric patches also the maxima along the axis
    x = y = 0 refined by a parabola (``axis_max_von_mises_*``, ``axis_max_shear_*``).
    """
    if len(stress):
        measures = post.principal_measures(stress)
        measures["compression"] = -measures["principal"][:, 2]
    else:
        measures = {"von_mises": np.zeros(0), "max_shear": np.zeros(0), "compression": np.zeros(0)}
    out = {}
    for key, name, sign in (
        ("von_mises", "max_von_mises", 1.0),
        ("max_shear", "max_shear", 1.0),
        ("compression", "min_principal", -1.0),
    ):
        values = measures[key]
        k = int(np.argmax(values)) if len(values) else -1
        local = (float(values[k]), coords[k].tolist()) if k >= 0 else (-math.inf, [math.nan] * 3)
        best = max(comm.allgather(local), key=lambda item: item[0])
        out[f"{name}_Pa"] = sign * best[0]
        out[f"{name}_point_m"] = best[1]
        out[f"{name}_depth_m"] = -best[1][2]
    if quadric:
        tol = 1e-9 * spec.half_width_m
        on_axis = (np.abs(coords[:, 0]) < tol) & (np.abs(coords[:, 1]) < tol)
        depth = np.concatenate(comm.allgather(-coords[on_axis, 2]))
        for key, name in (("von_mises", "axis_max_von_mises"), ("max_shear", "axis_max_shear")):
            vals = np.concatenate(comm.allgather(measures[key][on_axis]))
            if len(vals) >= 3:
                peak, z = post.axis_maximum(depth, vals)
                out[f"{name}_Pa"] = peak
                out[f"{name}_depth_m"] = z
    return out


def _patch_output_dir(output_dir, geometry: ContactGeometry) -> str:
    """``output_dir`` itself for a single patch; a sub-folder per patch of a wheelset case.

    A wheelset case solves several patches with the same options, so each writes into
    ``<output_dir>/<side>-<contact angle in whole degrees>deg`` (e.g. ``right-17deg``).
    """
    if not geometry.side:
        return str(output_dir)
    import math
    from pathlib import Path

    angle = round(math.degrees(geometry.contact_angle_rad))
    return str(Path(output_dir) / f"{geometry.side}-{angle}deg")
