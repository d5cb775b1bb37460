"""Creep-force sensitivities of every contact rung: d(Fx, Fy, Mz)/d(xi, eta, phi, N) at an operating point.

The matrix J (3 x 4) has rows (Fx, Fy, Mz) (:data:`ROWS`; on the wheel, contact frame, as the models give them) and
columns (xi, eta, phi, N) (:data:`COLUMNS`): longitudinal and lateral creepage (-), spin creepage (1/m) and the
normal force (N, force control: the patch grows with N as the rung's normal problem makes it). Units:
dF/dxi, dF/deta in N; dF/dphi in N m; dF/dN dimensionless; dMz/dxi, dMz/deta in N m; dMz/dphi in N m^2;
dMz/dN in m.

**Analytic** where the rung has a closed form:

* ``hertz``: J = 0 (no creep forces).
* ``linear`` (Kalker's linear theory, seed eq 50-52, :mod:`.linear`): the coefficients themselves,
  dFx/dxi = -G a b C11, dFy/deta = -G a b C22, dFy/dphi = -G (ab)^1.5 C23, dMz/deta = G (ab)^1.5 C23,
  dMz/dphi = -G (ab)^2 C33. Under force control Hertz's semi-axes grow as N^(1/3) at a fixed a/b (the C_ij do
  not change), so ab ~ N^(2/3): a term in ab^k contributes (2k/3) (term)/N to dF/dN.
* ``vermeulen-johnson`` (seed eq 53-58 with the cube; the spin enters through its linear term in Ty, which is
  Shen, Hedrick & Elkins' 1983 extension of the law): F = T_bar(T, L) T/|T| with T the linear forces and
  L = mu N, w = |T|/(3 L), T_bar = L (1 - (1 - w)^3) for w < 1, else L. Then
  dF/dT = T_bar' u u^T + (T_bar/|T|) (I - u u^T) (u = T/|T|, T_bar' = (1 - w)^2, 0 beyond w = 1; I at T = 0) and
  dF/dN = dF/dT dT/dN + u mu dT_bar/dL with dT_bar/dL = 1 - (1 - w)^3 - 3 w (1 - w)^2 (1 beyond w = 1).
  No spin moment: the Mz row is NaN.

Polach's creep-force law (the closed form of his 1999/2005 papers) is not a rung here: this project has Polach's
*friction* law (falling friction, :mod:`.friction`), used inside FASTSIM, the strip methods and the BEM, whose
sensitivities come by differences below.

**Central differences** for every other rung (``fastsim``, ``fastrip``, ``kpec``, ``analyn``, ``bem``, user
models; ``auto``: the rung it chose at the operating point): J[:, j] = (F(x + h_j) - F(x - h_j)) / (2 h_j), with
the step chosen from the creepage scale of the patch, the creepage at which the linear force reaches 3 mu N (where
Vermeulen-Johnson saturates): xi* = 3 mu N / (G a b C11), eta* = 3 mu N / (G a b C22), phi* = 3 mu N / (G (ab)^1.5
C23), and h_j = ``relative_step`` x (that scale) (default 1e-4, the BEM 1e-3: :data:`DEFAULT_RELATIVE_STEP`,
:data:`ITERATIVE_RELATIVE_STEPS`; the normal force: ``relative_step`` x N). The
semi-axes are the base solution's, else Hertz's. The error of each entry is estimated by repeating with twice the
steps: ``error_estimate`` = |J(h) - J(2h)|, which for a smooth force is three times J(h)'s own O(h^2) error (so
conservative) and also shows the noise of a grid law whose slip front jumps from element to element and of an
iterative solver's tolerance. A grid rung's perturbed solves keep the base solve's grid (the BEM: its final
``nx``, ``ny``, without its own grid-error estimate, so that all solves are on one grid); the sensitivities then
carry the grid error of that grid (the base result's ``extra`` states it), not estimated here.

At zero creepage the slopes are the linear creep coefficients of the rung: :meth:`CreepSensitivities.coefficients`
returns f11 = -dFx/dxi, f22 = -dFy/deta, f23 = -dFy/dphi and their Kalker-normalised values
c_ij (divided by G a b, G (ab)^1.5); for ``linear`` they are Kalker's C_ij, for FASTSIM and the BEM the grid's
approximation of them (tests/test_sensitivities.py states the grid error against Kalker's Table E.3).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material

ROWS = ("creep_force_long_N", "creep_force_lat_N", "spin_moment_Nm")
"""The rows of :attr:`CreepSensitivities.jacobian`: Fx, Fy, Mz (on the wheel, contact frame)."""
COLUMNS = ("longitudinal", "lateral", "spin_1_per_m", "normal_force_N")
"""The columns: xi (-), eta (-), phi (1/m), N (N)."""
FX, FY, MZ = range(3)
XI, ETA, PHI, NORMAL = range(4)

ANALYTIC_RUNGS = ("hertz", "linear", "vermeulen-johnson")
DEFAULT_RELATIVE_STEP = 1e-4
"""Central-difference step as a fraction of the patch's creepage scale (module docstring), for the rungs that solve
without iterating (FASTSIM, FaStrip, KPEC under approach control): small enough that a step seldom straddles an
element's switch between adhesion and slip (FASTSIM's force is piecewise smooth in the creepages: at 1e-3 the
wheelset Jacobian's FASTSIM columns differed by 0.15 % from the compiled law's own derivative, at 1e-4 by 2e-8,
benchmarks/results/creep_sensitivities.md)."""
ITERATIVE_RELATIVE_STEPS = {"bem": 1e-3, "fea": 1e-2}
"""The step of the rungs that iterate to a tolerance: the BEM's relative tolerance 1e-6 makes a difference quotient
with a step of 1e-3 x the creepage scale noisy at about 1e-6 / 1e-3 of the force's scale (an FEA solve more)."""


class LinearCreepCoefficients(NamedTuple):
    """The slopes at an operating point as the linear theory's coefficients (module docstring).

    f11_N = -dFx/dxi, f22_N = -dFy/deta, f23_Nm = -dFy/dphi; c11, c22, c23 the same divided by G a b, G a b and
    G (ab)^1.5 (Kalker's normalisation, NaN without semi-axes).
    """

    f11_N: float
    f22_N: float
    f23_Nm: float
    c11: float
    c22: float
    c23: float


@dataclass(frozen=True, eq=False)
class CreepSensitivities:
    """d(Fx, Fy, Mz)/d(xi, eta, phi, N) of one patch by one rung (module docstring).

    Attributes:
        method: the rung (for ``auto``: the one it chose, named in ``message``).
        kind: "analytic" or "central-difference".
        success, status, message: "ok"; else why the sensitivities are not available (the base or a perturbed
            solve failed: its status and message). With success False the jacobian is NaN.
        jacobian: (3, 4) array, rows :data:`ROWS`, columns :data:`COLUMNS` (units in the module docstring);
            the Mz row NaN for a rung without a spin moment.
        error_estimate: (3, 4) |J(h) - J(2h)| of the central differences; zeros for an analytic rung.
        steps: (4,) the steps h of the columns (NaN for an analytic rung).
        base: the rung's solution at the operating point.
        semi_axis_long_m, semi_axis_lat_m: a, b used for the creepage scale and the normalisation (m).
        shear_modulus_Pa: G of the material.
        solves: the rung's solves made (base included).
        wall_time_s: s.
    """

    method: str
    kind: str
    success: bool
    status: str
    message: str
    jacobian: np.ndarray
    error_estimate: np.ndarray
    steps: np.ndarray
    base: ContactResult
    semi_axis_long_m: float
    semi_axis_lat_m: float
    shear_modulus_Pa: float
    solves: int = 1
    wall_time_s: float = 0.0
    extra: dict = field(default_factory=dict)

    def d(self, row: str, column: str) -> float:
        """One entry by names, e.g. ``d("creep_force_lat_N", "spin_1_per_m")`` (N m)."""
        if row not in ROWS:
            raise ValueError(f"row = {row!r}: expected one of {', '.join(ROWS)}")
        if column not in COLUMNS:
            raise ValueError(f"column = {column!r}: expected one of {', '.join(COLUMNS)}")
        return float(self.jacobian[ROWS.index(row), COLUMNS.index(column)])

    def coefficients(self) -> LinearCreepCoefficients:
        """The slopes as creep coefficients f11, f22, f23 and Kalker's c11, c22, c23 (module docstring)."""
        j = self.jacobian
        f11, f22, f23 = -j[FX, XI], -j[FY, ETA], -j[FY, PHI]
        ab = self.semi_axis_long_m * self.semi_axis_lat_m
        g = self.shear_modulus_Pa
        scale = g * ab if ab > 0 else math.nan
        scale15 = g * ab**1.5 if ab > 0 else math.nan
        return LinearCreepCoefficients(
            float(f11), float(f22), float(f23), float(f11 / scale), float(f22 / scale), float(f23 / scale15)
        )

    def to_dict(self) -> dict:
        """JSON-ready: the matrix and its error as nested mappings row -> column -> value, and the record."""

        def table(m):
            return {r: {c: (None if not math.isfinite(m[i, k]) else float(m[i, k])) for k, c in enumerate(COLUMNS)}
                    for i, r in enumerate(ROWS)}  # fmt: skip

        coef = self.coefficients()
        return {
            "method": self.method,
            "kind": self.kind,
            "success": self.success,
            "status": self.status,
            "message": self.message,
            "jacobian": table(self.jacobian),
            "error_estimate": table(self.error_estimate),
            "steps": {
                c: (None if not math.isfinite(h) else float(h)) for c, h in zip(COLUMNS, self.steps, strict=True)
            },
            "coefficients": {k: (None if not math.isfinite(v) else v) for k, v in coef._asdict().items()},
            "solves": self.solves,
            "wall_time_s": self.wall_time_s,
        }


class OperatingPoint(NamedTuple):
    """A patch and its operating point: what every rung's ``solve`` takes."""

    geometry: ContactGeometry
    creepage: Creepage
    material: Material
    normal_force_N: float | None = None
    options: Mapping | None = None


def creep_sensitivities(
    model,
    point: OperatingPoint,
    *,
    relative_step: float | None = None,
    method: str | None = None,
    estimate_error: bool = True,
    normal: bool = True,
) -> CreepSensitivities:
    """d(Fx, Fy, Mz)/d(xi, eta, phi, N) of ``model`` (a registered name or a ContactModel) at ``point``.

    Analytic for hertz, linear and vermeulen-johnson; central differences with steps from the creepage scale for
    every other rung, with their error estimated from a second step (module docstring). ``relative_step``: the
    steps as a fraction of the creepage scale (None: :data:`ITERATIVE_RELATIVE_STEPS` for an iterative rung, else
    :data:`DEFAULT_RELATIVE_STEP`). ``method``: force
    "central-difference" (e.g. to check an analytic rung), else None. ``estimate_error`` False: one step only (half
    the solves; ``error_estimate`` NaN); ``normal`` False: no dF/dN column by differences (NaN; a third fewer
    solves), for a caller that needs the creepage columns alone (the wheelset's Jacobian).

    Raises:
        ValueError: bad model name, ``relative_step`` not in (0, 0.1], ``method`` unknown, or bad input of the
            rung (its own messages).
    """
    from rigid_dynamics.contact.registry import get_model

    if relative_step is not None and not (
        isinstance(relative_step, (int, float)) and math.isfinite(relative_step) and 0 < relative_step <= 0.1
    ):
        raise ValueError(f"relative_step = {relative_step!r}: expected a number in (0, 0.1]")
    if method not in (None, "analytic", "central-difference"):
        raise ValueError(f"method = {method!r}: expected None, 'analytic' or 'central-difference'")
    start = time.perf_counter()
    rung = get_model(model)
    base = rung.solve(
        point.geometry, point.creepage, point.material, normal_force_N=point.normal_force_N, options=point.options
    )
    if rung.name == "auto" and base.success and base.status != "no-contact":
        chosen = base.extra.get("selected_model", "auto")
        per_model = dict((point.options or {}).get("model_options") or {})
        if chosen == "bem":
            per_model["bem"] = {
                "grid_tolerance": (point.options or {}).get("tolerance", 0.05),
                **(per_model.get("bem") or {}),
            }
        out = creep_sensitivities(
            chosen,
            point._replace(options=per_model.get(chosen)),
            relative_step=relative_step,
            method=method,
            estimate_error=estimate_error,
            normal=normal,
        )
        return replace(out, message=f"auto chose {chosen}: {out.message}", wall_time_s=time.perf_counter() - start)
    if base.status == "no-contact" or not base.success:
        return _failed(rung.name, base, point.material, f"no sensitivities: the base solve is {base.status}: "
                       f"{base.message}", start)  # fmt: skip
    normal = float(base.normal_force_N)
    point = point._replace(normal_force_N=normal)  # every derivative under force control at the base's N
    if rung.name in ANALYTIC_RUNGS and method != "central-difference":
        return _analytic(rung.name, point, base, start)
    if method == "analytic":
        raise ValueError(f"method = 'analytic': the rung {rung.name!r} has no closed form (one of "
                         f"{', '.join(ANALYTIC_RUNGS)} has)")  # fmt: skip
    if relative_step is None:
        relative_step = ITERATIVE_RELATIVE_STEPS.get(rung.name, DEFAULT_RELATIVE_STEP)
    return _differences(rung, point, base, (relative_step, estimate_error, normal), start)


def _failed(name: str, base: ContactResult, material: Material, message: str, start: float) -> CreepSensitivities:
    nan = np.full((3, 4), np.nan)
    return CreepSensitivities(
        method=name,
        kind="none",
        success=False,
        status=base.status if not base.success else "no-contact",
        message=message,
        jacobian=nan,
        error_estimate=nan.copy(),
        steps=np.full(4, np.nan),
        base=base,
        semi_axis_long_m=float(base.semi_axis_long_m or math.nan),
        semi_axis_lat_m=float(base.semi_axis_lat_m or math.nan),
        shear_modulus_Pa=material.shear_modulus_Pa,
        wall_time_s=time.perf_counter() - start,
    )


def _hertz_axes(point: OperatingPoint) -> tuple[float, float]:
    """Hertz's semi-axes of the patch at the point's normal force (m)."""
    from rigid_dynamics.contact.hertz import hertz_solve_batch

    hz = hertz_solve_batch(
        point.geometry.curvature_long_1_per_m,
        point.geometry.curvature_lat_1_per_m,
        normal_force_N=point.normal_force_N,
        shear_modulus_Pa=point.material.shear_modulus_Pa,
        poisson_ratio=point.material.poisson_ratio,
    )
    return float(hz.semi_axis_long_m), float(hz.semi_axis_lat_m)


def linear_jacobian(a: float, b: float, point: OperatingPoint) -> tuple[np.ndarray, np.ndarray]:
    """(J (3, 4), T (3,)) of Kalker's linear theory on the ellipse a, b (m) at the point (module docstring): the
    analytic sensitivities and the linear forces (Tx, Ty, Mz) themselves.
    """
    from rigid_dynamics.contact.kalker import kalker_coefficients

    mat, c = point.material, point.creepage
    k = kalker_coefficients(a / b, mat.poisson_ratio)
    c11, c22, c23, c33 = (float(v) for v in (k.c11, k.c22, k.c23, k.c33))
    g, ab = mat.shear_modulus_Pa, a * b
    g1, g15, g2 = g * ab, g * ab**1.5, g * ab * ab
    xi, eta, phi = c.longitudinal, c.lateral, c.spin_1_per_m
    n = float(point.normal_force_N)
    jac = np.zeros((3, 4))
    jac[FX, XI] = -g1 * c11
    jac[FY, ETA], jac[FY, PHI] = -g1 * c22, -g15 * c23
    jac[MZ, ETA], jac[MZ, PHI] = g15 * c23, -g2 * c33
    # ab ~ N^(2/3) (Hertz, force control): a term in (ab)^k gives (2 k / 3) term / N
    jac[FX, NORMAL] = (2.0 / 3.0) * (-g1 * c11 * xi) / n
    jac[FY, NORMAL] = ((2.0 / 3.0) * (-g1 * c22 * eta) + (-g15 * c23 * phi)) / n
    jac[MZ, NORMAL] = (g15 * c23 * eta + (4.0 / 3.0) * (-g2 * c33 * phi)) / n
    forces = np.array([-g1 * c11 * xi, -g1 * c22 * eta - g15 * c23 * phi, g15 * c23 * eta - g2 * c33 * phi])
    return jac, forces


def saturation_jacobian(linear: np.ndarray, linear_forces: np.ndarray, point: OperatingPoint) -> np.ndarray:
    """(3, 4) sensitivities of Vermeulen-Johnson's saturated forces (module docstring) from those of the linear
    forces ``linear`` (3, 4) and the linear forces (Tx, Ty, .) themselves; the Mz row NaN (no spin moment).
    """
    mu = point.material.friction_coefficient
    n = float(point.normal_force_N)
    limit = mu * n
    t = linear_forces[:2]
    size = math.hypot(t[0], t[1])
    jac = np.full((3, 4), np.nan)
    if size == 0.0:  # T_bar'(0) = 1, T_bar/T -> 1: the linear slopes; dT_bar/dL = 0 at w = 0
        jac[:2] = linear[:2]
        return jac
    u = t / size
    w = size / (3.0 * limit) if limit > 0 else math.inf
    one = max(1.0 - w, 0.0)
    t_bar = limit * (1.0 - one**3)
    slope = one * one  # dT_bar/dT
    by_limit = 1.0 - one**3 - 3.0 * w * one * one if w < 1.0 else 1.0  # dT_bar/dL at fixed T
    uu = np.outer(u, u)
    d_t = slope * uu + (t_bar / size) * (np.eye(2) - uu)
    jac[:2] = d_t @ linear[:2]
    jac[:2, NORMAL] += u * mu * by_limit
    return jac


def _analytic(name: str, point: OperatingPoint, base: ContactResult, start: float) -> CreepSensitivities:
    a, b = float(base.semi_axis_long_m), float(base.semi_axis_lat_m)
    if name == "hertz":
        jac = np.zeros((3, 4))
    else:
        jac, forces = linear_jacobian(a, b, point)
        if name == "vermeulen-johnson":
            jac = saturation_jacobian(jac, forces, point)
    return CreepSensitivities(
        method=name,
        kind="analytic",
        success=True,
        status="ok" if base.status == "ok" else base.status,
        message="analytic (closed form)" + ("" if base.status == "ok" else f"; the base solve: {base.message}"),
        jacobian=jac,
        error_estimate=np.where(np.isnan(jac), np.nan, 0.0),
        steps=np.full(4, np.nan),
        base=base,
        semi_axis_long_m=a,
        semi_axis_lat_m=b,
        shear_modulus_Pa=point.material.shear_modulus_Pa,
        wall_time_s=time.perf_counter() - start,
    )


def creepage_scales(a: float, b: float, point: OperatingPoint) -> np.ndarray:
    """(xi*, eta*, phi*, N) of the patch (module docstring): the creepages at which the linear force reaches 3 mu N,
    and the normal force; the scale of each column's step.
    """
    from rigid_dynamics.contact.kalker import kalker_coefficients

    mat = point.material
    k = kalker_coefficients(a / b, mat.poisson_ratio)
    n = float(point.normal_force_N)
    force = 3.0 * max(mat.friction_coefficient, 1e-3) * n  # a frictionless pair: the scale of mu = 0.001
    g, ab = mat.shear_modulus_Pa, a * b
    return np.array([force / (g * ab * float(k.c11)), force / (g * ab * float(k.c22)),
                     force / (g * ab**1.5 * float(k.c23)), n])  # fmt: skip


def _fixed_grid_options(rung, options: Mapping | None, base: ContactResult) -> dict | None:
    """The options of the perturbed solves: the BEM on the base's final grid without its own grid-error estimate
    (every solve on one grid); other rungs as given.
    """
    opts = dict(options or {})
    declared = getattr(rung, "OPTIONS", {})
    if "estimate_grid_error" in declared:
        opts["estimate_grid_error"] = False
        named = any(opts.get(k) is not None for k in ("nx", "ny", "element_size_m", "dx_m", "dy_m"))
        if not named and "nx" in base.extra and "ny" in base.extra:
            opts["nx"], opts["ny"] = int(base.extra["nx"]), int(base.extra["ny"])
            opts.pop("element_size_m", None)
    return opts or None


def _forces(result: ContactResult) -> np.ndarray:
    return np.array([
        result.creep_force_long_N if result.creep_force_long_N is not None else np.nan,
        result.creep_force_lat_N if result.creep_force_lat_N is not None else np.nan,
        result.spin_moment_Nm if result.spin_moment_Nm is not None else np.nan,
    ])  # fmt: skip


def _shifted(point: OperatingPoint, column: int, step: float) -> OperatingPoint:
    if column == NORMAL:
        return point._replace(normal_force_N=point.normal_force_N + step)
    c = point.creepage
    values = [c.longitudinal, c.lateral, c.spin_1_per_m]
    values[column] += step
    return point._replace(creepage=Creepage(*values, c.rolling_speed_m_per_s))


def _differences(rung, point: OperatingPoint, base: ContactResult, how: tuple, start) -> CreepSensitivities:
    """Central differences; ``how`` = (relative_step, estimate_error, normal) of :func:`creep_sensitivities`."""
    relative_step, estimate_error, normal = how
    a, b = base.semi_axis_long_m, base.semi_axis_lat_m
    if not (a and b and a > 0 and b > 0):
        a, b = _hertz_axes(point)
    steps = relative_step * creepage_scales(float(a), float(b), point)
    opts = _fixed_grid_options(rung, point.options, base)
    solves = 1
    estimates = []
    for factor in (1.0, 2.0) if estimate_error else (1.0,):
        jac = np.full((3, 4), np.nan)
        for j in range(4) if normal else range(3):
            pair = []
            for sign in (1.0, -1.0):
                shifted = _shifted(point, j, sign * factor * steps[j])
                r = rung.solve(shifted.geometry, shifted.creepage, shifted.material,
                               normal_force_N=shifted.normal_force_N, options=opts)  # fmt: skip
                solves += 1
                if not r.success or r.status == "no-contact":
                    out = _failed(rung.name, base, point.material, f"no sensitivities: the solve at "
                                  f"{COLUMNS[j]} {'+-'[sign < 0]}{factor * steps[j]:.3g} is {r.status}: {r.message}",
                                  start)  # fmt: skip
                    return replace(out, status=r.status if not r.success else "no-contact", solves=solves)
                pair.append(_forces(r))
            jac[:, j] = (pair[0] - pair[1]) / (2.0 * factor * steps[j])
        estimates.append(jac)
    jac = estimates[0]
    error = np.abs(estimates[0] - estimates[1]) if estimate_error else np.full((3, 4), np.nan)
    scale = steps / relative_step
    message = (f"central differences, steps {relative_step:g} x the creepage scale (xi* {scale[XI]:.3g}, "
               f"eta* {scale[ETA]:.3g}, phi* {scale[PHI]:.3g} 1/m) and {relative_step:g} x N; error "
               + ("estimated against twice the steps" if estimate_error else "not estimated"))  # fmt: skip
    if base.status != "ok":
        message += f"; the base solve: {base.status}: {base.message}"
    return CreepSensitivities(
        method=rung.name,
        kind="central-difference",
        success=True,
        status=base.status,
        message=message,
        jacobian=jac,
        error_estimate=error,
        steps=steps,
        base=base,
        semi_axis_long_m=float(a),
        semi_axis_lat_m=float(b),
        shear_modulus_Pa=point.material.shear_modulus_Pa,
        solves=solves,
        wall_time_s=time.perf_counter() - start,
    )
