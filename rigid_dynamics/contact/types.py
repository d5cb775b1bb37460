"""Data passed between contact search, contact models and the wheelset.

Frames and signs (used by every contact model):

* The *contact frame* of a patch has x along the rolling direction, y lateral in the
  tangent plane and z the common normal pointing from the rail into the wheel.
  (``ContactGeometry.frame`` holds its axes as columns in the main track frame.)
* The undeformed distance between the bodies near the patch is
  ``h(x, y) = A x^2 + B y^2 - approach`` for an elliptic (Hertzian) patch, A, B in 1/m;
  in general it is sampled on a grid (:class:`UndeformedDistance`).
* Creep forces and the spin moment act **on the wheel**, in the contact frame, and oppose
  the wheel's creepage (seed eq 50-52, Kalker 1990): positive longitudinal creepage gives a
  negative longitudinal force.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Creepage:
    """Rigid creepages of the wheel over the rail, in the contact frame.

    Attributes:
        longitudinal: xi = (v_wheel,x - v_rail,x)/V, dimensionless.
        lateral: eta, dimensionless.
        spin_1_per_m: phi = omega_z / V, 1/m.
        rolling_speed_m_per_s: V, magnitude of the rolling velocity, m/s (> 0).
    """

    longitudinal: float = 0.0
    lateral: float = 0.0
    spin_1_per_m: float = 0.0
    rolling_speed_m_per_s: float = 1.0

    def __post_init__(self) -> None:
        for name in ("longitudinal", "lateral", "spin_1_per_m", "rolling_speed_m_per_s"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")
        if self.rolling_speed_m_per_s <= 0:
            raise ValueError(f"rolling_speed_m_per_s = {self.rolling_speed_m_per_s!r}: expected > 0")


@dataclass(frozen=True, eq=False)
class UndeformedDistance:
    """Undeformed distance between wheel and rail on a regular grid of the contact plane.

    ``distance_m[j, i]`` is the gap at ``(x_m[i], y_m[j])`` with the bodies at their rigid
    approach, i.e. ``h(x, y) - approach`` in the notation of the module docstring: negative
    where the undeformed surfaces overlap. x along rolling, y lateral (contact frame), m.
    Points where the local surfaces are not defined (off the profile) hold +inf.

    ``exact``, when given, evaluates the gap at any points of the plane from the surfaces themselves
    (``exact(x_m, y_m) -> gap``, arrays of one shape); :meth:`evaluate` then uses it instead of interpolating
    the grid, which only sizes the potential contact area (rigid_dynamics.contact.wheelset_patches).
    ``potential_area_m`` (x_min, x_max, y_min, y_max), when given, is a rectangle that holds every point with a
    negative gap (the rigid overlap), hence the whole contact area of quasi-identical elastic bodies (their
    normal surface displacements under pressure are compressive everywhere): solvers use it as their
    potential contact area.

    ``sub_patches_m`` (n, 4) and ``sub_patch_factors`` (n, n), when given (a patch joining interpenetration regions
    D_COMB < d <= D_SEP apart, rigid_dynamics.contact.wheelset_patches): the sub-patches' rectangles (x_min, x_max,
    y_min, y_max) on the plane, m, a later one taking the elements it shares with an earlier one, and the factors
    f_ij that scale the normal displacement of sub-patch j's elements due to sub-patch i's pressure (f_ii = 1):
    CONTACT's reduced interaction of sub-patches (IPLAN = 4). Elements in no rectangle are outside the potential
    contact area. The ``bem`` rung applies them unless its option ``subpatch_interaction`` is "full".
    """

    x_m: np.ndarray
    y_m: np.ndarray
    distance_m: np.ndarray
    exact: Callable | None = None
    potential_area_m: tuple[float, float, float, float] | None = None
    sub_patches_m: np.ndarray | None = None
    sub_patch_factors: np.ndarray | None = None

    def __post_init__(self) -> None:
        if (self.sub_patches_m is None) != (self.sub_patch_factors is None):
            raise ValueError("sub_patches_m and sub_patch_factors: expected both or neither")
        if self.sub_patches_m is not None:
            n = len(self.sub_patches_m)
            if np.shape(self.sub_patches_m) != (n, 4) or np.shape(self.sub_patch_factors) != (n, n):
                raise ValueError(
                    f"sub_patches_m shape {np.shape(self.sub_patches_m)}, sub_patch_factors shape "
                    f"{np.shape(self.sub_patch_factors)}: expected (n, 4) and (n, n)"
                )
        nx, ny = len(self.x_m), len(self.y_m)
        if self.distance_m.shape != (ny, nx):
            raise ValueError(
                f"distance_m has shape {self.distance_m.shape}: expected (len(y_m), len(x_m)) = {(ny, nx)}"
            )

    def evaluate(self, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
        """The gap at arbitrary points: ``exact`` if given, else bilinear interpolation (+inf outside the grid)."""
        if self.exact is not None:
            x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
            return np.asarray(self.exact(x_m, y_m), float).reshape(x_m.shape)
        from scipy.interpolate import RegularGridInterpolator

        interp = RegularGridInterpolator((self.y_m, self.x_m), self.distance_m, bounds_error=False, fill_value=np.inf)
        x_m, y_m = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
        return interp(np.stack([y_m.ravel(), x_m.ravel()], axis=-1)).reshape(x_m.shape)


@dataclass(frozen=True, eq=False)
class ContactGeometry:
    """Geometry of one contact patch, as the contact search or a quadric case gives it.

    Attributes:
        curvature_long_1_per_m: A, relative curvature term along x (h = A x^2 + B y^2 - q), 1/m.
            A = 1/(2 R_long) for relative radius of curvature R_long.
        curvature_lat_1_per_m: B, the same along y, 1/m.
        approach_m: q, rigid approach (interpenetration) of the undeformed bodies, m; > 0 in contact.
        side: "left", "right" or "" (a single patch of a quadric case).
        point_m: contact point in the main track frame (x, y, z), m.
        frame: 3x3 matrix, columns = contact-frame axes (x rolling, y lateral, z normal from rail
            into wheel) in the main track frame.
        contact_angle_rad: angle of the normal to the track's vertical, positive when the normal
            tilts towards the track centre... for a flange contact on either side it is large and
            positive. 0 for quadric cases.
        contact_point_rail_m: (y, z) of the contact point in rail-profile coordinates, m.
        contact_point_wheel_m: (y, z) of the contact point in wheel-profile coordinates, m.
        rolling_radius_m: wheel radius at the contact point, m (nan for quadric cases).
        ellipse_angle_rad: angle from the rolling direction (x) to the principal direction of A, rad.
        undeformed: sampled gap field for non-Hertzian solvers, or None (then the quadric form holds).
        is_elliptic: whether the local gap is well described by the quadric form (Hertz valid).
        friction_place: optional f(varies_with, x_m, y_m) -> the friction law's place variable (rad or m) at points
            of the contact plane (element-wise variation); None: the patch's reference point gives one value for
            the whole patch (contact_angle_rad for "surface_inclination", contact_point_rail_m[0] for
            "rail_lateral", track_distance_m for "track_distance"), as CONTACT does for a planar patch.
        track_distance_m: the patch's position along the track, m (CONTACT's S of the wheelset).
    """

    curvature_long_1_per_m: float
    curvature_lat_1_per_m: float
    approach_m: float = 0.0
    side: str = ""
    point_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    frame: np.ndarray = field(default_factory=lambda: np.eye(3))
    contact_angle_rad: float = 0.0
    contact_point_rail_m: tuple[float, float] = (math.nan, math.nan)
    contact_point_wheel_m: tuple[float, float] = (math.nan, math.nan)
    rolling_radius_m: float = math.nan
    ellipse_angle_rad: float = 0.0
    undeformed: UndeformedDistance | None = None
    is_elliptic: bool = True
    friction_place: Callable | None = None
    track_distance_m: float = 0.0

    def __post_init__(self) -> None:
        for name in ("curvature_long_1_per_m", "curvature_lat_1_per_m", "approach_m"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ValueError(f"{name} = {value!r}: expected a finite number")
        if self.curvature_long_1_per_m <= 0 or self.curvature_lat_1_per_m <= 0:
            raise ValueError(
                f"relative curvatures A = {self.curvature_long_1_per_m!r}, B = {self.curvature_lat_1_per_m!r} 1/m: "
                "expected both > 0 (the bodies must be locally convex against each other)"
            )

    @classmethod
    def quadric(cls, radius_long_m: float, radius_lat_m: float, approach_m: float = 0.0) -> ContactGeometry:
        """Patch of two quadric bodies with relative radii of curvature R_long (along x), R_lat (along y)."""
        for name, value in (("radius_long_m", radius_long_m), ("radius_lat_m", radius_lat_m)):
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        return cls(0.5 / radius_long_m, 0.5 / radius_lat_m, approach_m)

    def gap_m(self, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
        """Undeformed gap h(x, y) - q at points of the contact plane (sampled field if present), m."""
        if self.undeformed is not None:
            return self.undeformed.evaluate(x_m, y_m)
        return (
            self.curvature_long_1_per_m * np.square(x_m) + self.curvature_lat_1_per_m * np.square(y_m) - self.approach_m
        )


@dataclass(frozen=True, eq=False)
class ContactFields:
    """Surface fields of a solved patch on a regular grid of the contact plane (contact frame).

    ``pressure_Pa[j, i]`` etc. at ``(x_m[i], y_m[j])``. Tractions act on the wheel.
    ``slip_m_per_s`` holds the magnitude of the local slip velocity (0 in adhesion);
    ``in_contact`` and ``in_slip`` are boolean masks. Fields a model does not produce are None.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    pressure_Pa: np.ndarray
    traction_long_Pa: np.ndarray | None = None
    traction_lat_Pa: np.ndarray | None = None
    slip_m_per_s: np.ndarray | None = None
    in_contact: np.ndarray | None = None
    in_slip: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class ContactResult:
    """Solution of one contact patch by one model.

    Forces act on the wheel, in the contact frame (x rolling, y lateral, z normal).
    Quantities a model does not compute are None (e.g. creep forces of ``hertz``, semi-axes
    of a non-elliptic patch). When ``success`` is False, ``status`` and ``message`` say why and
    the numbers are the last iterate, not a solution.

    Attributes:
        method: registered model name.
        success: True when the solver converged.
        status: "ok", "not-converged", "no-contact", "invalid-input", ...
        message: human-readable explanation.
        normal_force_N, creep_force_long_N, creep_force_lat_N: N.
        spin_moment_Nm: moment about the normal, N m.
        max_pressure_Pa: Pa.
        semi_axis_long_m, semi_axis_lat_m: semi-axes along x and y of an elliptic patch, m.
        contact_area_m2: m^2.
        approach_m: rigid approach q, m.
        creepage: the creepages solved for.
        fields: optional surface fields.
        iterations, residual, wall_time_s: solver diagnostics.
        extra: further model-specific diagnostics (JSON-serialisable values).
    """

    method: str
    success: bool
    status: str
    message: str
    normal_force_N: float
    creep_force_long_N: float | None = None
    creep_force_lat_N: float | None = None
    spin_moment_Nm: float | None = None
    max_pressure_Pa: float | None = None
    semi_axis_long_m: float | None = None
    semi_axis_lat_m: float | None = None
    contact_area_m2: float | None = None
    approach_m: float | None = None
    creepage: Creepage | None = None
    fields: ContactFields | None = None
    iterations: int = 0
    residual: float = 0.0
    wall_time_s: float = 0.0
    extra: dict = field(default_factory=dict)

    @classmethod
    def no_contact(
        cls, method: str, message: str, creepage: Creepage | None, *, approach_m: float | None, wall_time_s: float, **kw
    ) -> ContactResult:
        """A result without contact: ``success`` True, status "no-contact", every force, moment, pressure and area 0.

        ``kw``: further fields (e.g. the semi-axes 0.0 of an elliptic model, ``extra``).
        """
        fields = {
            "creep_force_long_N": 0.0,
            "creep_force_lat_N": 0.0,
            "spin_moment_Nm": 0.0,
            "max_pressure_Pa": 0.0,
            "contact_area_m2": 0.0,
        }
        fields.update(kw)
        return cls(
            method=method,
            success=True,
            status="no-contact",
            message=message,
            normal_force_N=0.0,
            approach_m=approach_m,
            creepage=creepage,
            wall_time_s=wall_time_s,
            **fields,
        )

    def to_dict(self) -> dict:
        """Every number of the result by name (creepages flattened, ``extra`` kept, fields as arrays or None)."""
        out = {
            name: getattr(self, name)
            for name in self.__dataclass_fields__
            if name not in ("creepage", "fields", "extra")
        }
        if self.creepage is not None:
            out.update(
                creepage_long=self.creepage.longitudinal,
                creepage_lat=self.creepage.lateral,
                spin_creepage_1_per_m=self.creepage.spin_1_per_m,
                rolling_speed_m_per_s=self.creepage.rolling_speed_m_per_s,
            )
        out["extra"] = dict(self.extra)
        out["fields"] = None if self.fields is None else dict(vars(self.fields))
        return out

    def to_dataframe(self):
        """A one-row pandas DataFrame of the scalar numbers (``extra``'s scalars prefixed ``extra.``)."""
        import pandas as pd

        row = {k: v for k, v in self.to_dict().items() if k not in ("extra", "fields")}
        row.update({f"extra.{k}": v for k, v in self.extra.items() if isinstance(v, (int, float, str, bool))})
        return pd.DataFrame([row])

    def _repr_markdown_(self) -> str:
        """A table for notebooks: the forces on the wheel (contact frame), max pressure, patch size, in N, MPa, mm."""

        def cell(value, scale=1.0):
            return "-" if value is None else f"{value * scale:.5g}"

        rows = (
            ("normal force N", self.normal_force_N, 1.0, "N"),
            ("creep force Fx (on the wheel)", self.creep_force_long_N, 1.0, "N"),
            ("creep force Fy (on the wheel)", self.creep_force_lat_N, 1.0, "N"),
            ("spin moment Mz", self.spin_moment_Nm, 1.0, "N m"),
            ("max pressure", self.max_pressure_Pa, 1e-6, "MPa"),
            ("semi-axis a (rolling)", self.semi_axis_long_m, 1e3, "mm"),
            ("semi-axis b (lateral)", self.semi_axis_lat_m, 1e3, "mm"),
            ("contact area", self.contact_area_m2, 1e6, "mm^2"),
        )
        lines = [
            f"**{self.method}**: {self.status}" + (f" ({self.message})" if self.message else ""),
            "",
            "| quantity | value | unit |",
            "|---|---:|---|",
            *(f"| {name} | {cell(value, scale)} | {unit} |" for name, value, scale, unit in rows),
        ]
        return "\n".join(lines) + "\n"

    def __repr__(self) -> str:
        def num(value, scale=1.0, unit=""):
            return "None" if value is None else f"{value * scale:.5g}{unit}"

        return (
            f"ContactResult(method={self.method!r}, status={self.status!r}, "
            f"normal_force_N={num(self.normal_force_N)}, creep_force_long_N={num(self.creep_force_long_N)}, "
            f"creep_force_lat_N={num(self.creep_force_lat_N)}, max_pressure_Pa={num(self.max_pressure_Pa)}, "
            f"semi_axes_m=({num(self.semi_axis_long_m)}, {num(self.semi_axis_lat_m)}), "
            f"fields={'yes' if self.fields is not None else 'no'}, message={self.message!r})"
        )
