"""gmsh models of local wheel and rail sections built from real profiles, around a contact point.

Profile input: a curve with ``z(y_m)`` (e.g. :class:`rigid_dynamics.geometry.profile.ProfileCurve`)
in profile coordinates (y_p lateral towards the field side, z_p DOWN, see that module).

Local frame of each section (m): X along the rolling direction, Y = y_p - y_c (lateral), Z UP
(Z = -(z_p - z_c)) with the contact point (y_c, z_c) of the profile at the origin; after
``align_normal=True`` the frame is turned about X so that the profile's normal at the contact point
is +Z for the rail and -Z for the wheel (the contact plane is Z = 0, as in the contact frame).

* Rail section: the profile between y_c - w and y_c + w, closed by a horizontal line at depth d
  below the contact point, extruded over -L <= X <= L. Rail material below the surface.
* Wheel section: the wheel profile gives the rolling radius R(y) = r0 + z_p(y) (the geometry module's
  convention R_id = r0 + z_p - z_p(0)); the section between y_c +- w and the radius R(y_c) - d is
  revolved about the axle (parallel to Y, at height R(y_c) above the contact point) through
  +- L / R(y_c). Wheel material above the surface.

Refinement: the MathEval size field of :mod:`meshing.hertz` (element size h_c inside the expected
patch with semi-axes a, b, growing quadratically outside). Physical groups (named): ``body``,
``contact`` (the profile surface), ``base`` (rail foot cut / wheel inner cut), ``ends``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from meshing.session import gmsh_number, set_size_field

SECTION_KINDS = ("rail", "wheel")


@dataclass(frozen=True)
class ProfileSectionSpec:
    """Parameters of a local profile section (SI units).

    Attributes:
        kind: "rail" or "wheel".
        contact_y_m: y_c, lateral profile coordinate of the contact point, m.
        half_width_m: w, lateral half-width of the section, m (> 0; clipped to the profile's range).
        half_length_m: L, half-length along the rolling direction, m (> 0).
        depth_m: d, thickness of the section below (rail) / above (wheel) the contact point, m (> 0).
        semi_axis_long_m, semi_axis_lat_m: expected patch semi-axes a, b (refinement), m (> 0).
        elements_per_semi_axis: n, element size at the patch min(a, b)/n (>= 1).
        nominal_radius_m: r0, wheel radius at the tape circle, m (wheel only, > 0).
        profile_points: samples of the profile used for the gmsh spline (>= 8).
    """

    kind: str
    contact_y_m: float
    half_width_m: float
    half_length_m: float
    depth_m: float
    semi_axis_long_m: float
    semi_axis_lat_m: float
    elements_per_semi_axis: float = 4.0
    nominal_radius_m: float = 0.46
    profile_points: int = 80

    def __post_init__(self) -> None:
        if self.kind not in SECTION_KINDS:
            raise ValueError(f"kind = {self.kind!r}: expected one of {SECTION_KINDS}")
        if not math.isfinite(self.contact_y_m):
            raise ValueError(f"contact_y_m = {self.contact_y_m!r}: expected a finite number")
        for name in (
            "half_width_m",
            "half_length_m",
            "depth_m",
            "semi_axis_long_m",
            "semi_axis_lat_m",
            "nominal_radius_m",
        ):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        if not self.elements_per_semi_axis >= 1:
            raise ValueError(f"elements_per_semi_axis = {self.elements_per_semi_axis!r}: expected >= 1")
        if int(self.profile_points) != self.profile_points or self.profile_points < 8:
            raise ValueError(f"profile_points = {self.profile_points!r}: expected an integer >= 8")

    @property
    def contact_size_m(self) -> float:
        """h_c, element size at the patch, m."""
        return min(self.semi_axis_long_m, self.semi_axis_lat_m) / self.elements_per_semi_axis


def section_surface_points(curve, spec: ProfileSectionSpec) -> tuple[np.ndarray, np.ndarray]:
    """(Y, Z) samples of the profile in the local section frame (Z up, contact point at 0), m."""
    lo = max(spec.contact_y_m - spec.half_width_m, curve.y_min_m)
    hi = min(spec.contact_y_m + spec.half_width_m, curve.y_max_m)
    if not lo < spec.contact_y_m < hi:
        raise ValueError(
            f"contact_y_m = {spec.contact_y_m!r}: expected inside the profile range ({curve.y_min_m}, {curve.y_max_m})"
        )
    y = np.linspace(lo, hi, spec.profile_points)
    z_c = float(curve.z(spec.contact_y_m))
    return y - spec.contact_y_m, -(np.asarray(curve.z(y), dtype=float) - z_c)


def normal_angle_rad(curve, contact_y_m: float) -> float:
    """Angle about X that turns the profile's tangent at y_c into the Y axis (local frame, Z up), rad."""
    slope = -float(curve.z(contact_y_m, 1))  # dZ/dY in the local frame
    return math.atan(slope)


def build_profile_section(
    model, curve, spec: ProfileSectionSpec, *, align_normal: bool = True, prefix: str = "", size_field: bool = True
) -> dict:
    """Add a rail or wheel section (see the module docstring) to the current gmsh model.

    Args:
        model: the ``gmsh.model`` API object (current model receives the geometry).
        curve: profile curve with ``z(y_m, derivative=0)``, ``y_min_m``, ``y_max_m``.
        spec: section parameters.
        align_normal: rotate about X so the contact plane is Z = 0.
        prefix: group names become ``prefix`` (body) and ``prefix_contact`` etc. (default: plain names),
            so a rail and a wheel section can share one model.
        size_field: install the refinement field (once per model is enough).

    Returns:
        physical group name -> (dimension, tag). The mesh is not generated.

    Raises:
        ValueError: contact point outside the profile, or a section thinner than the profile's relief.
    """
    Y, Z = section_surface_points(curve, spec)
    occ = model.occ
    d = spec.depth_m
    if spec.kind == "rail":
        if Z.min() <= -d:
            raise ValueError(
                f"depth_m = {d!r}: the rail profile drops below the section's base; expected a larger depth"
            )
        base_z = -d
    else:
        if Z.max() >= d:
            raise ValueError(
                f"depth_m = {d!r}: the wheel profile rises above the section's base; expected a larger depth"
            )
        base_z = d
    surface_pts = [occ.addPoint(0.0, float(y), float(z)) for y, z in zip(Y, Z, strict=True)]
    spline = occ.addSpline(surface_pts)
    corner_a = occ.addPoint(0.0, float(Y[-1]), base_z)
    corner_b = occ.addPoint(0.0, float(Y[0]), base_z)
    loop = occ.addCurveLoop(
        [
            spline,
            occ.addLine(surface_pts[-1], corner_a),
            occ.addLine(corner_a, corner_b),
            occ.addLine(corner_b, surface_pts[0]),
        ]
    )
    face = occ.addPlaneSurface([loop])
    if spec.kind == "rail":
        occ.translate([(2, face)], -spec.half_length_m, 0.0, 0.0)
        out = occ.extrude([(2, face)], 2.0 * spec.half_length_m, 0.0, 0.0)
    else:
        z_tape = float(curve.z(0.0)) if curve.y_min_m < 0.0 < curve.y_max_m else 0.0
        radius_c = spec.nominal_radius_m + float(curve.z(spec.contact_y_m)) - z_tape
        angle = spec.half_length_m / radius_c
        occ.rotate([(2, face)], 0.0, 0.0, radius_c, 0.0, 1.0, 0.0, -angle)
        out = occ.revolve([(2, face)], 0.0, 0.0, radius_c, 0.0, 1.0, 0.0, 2.0 * angle)
    volumes = [tag for dim, tag in out if dim == 3]
    if align_normal:
        occ.rotate([(3, v) for v in volumes], 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -normal_angle_rad(curve, spec.contact_y_m))
    occ.synchronize()

    # Classify the faces: the contact face contains the origin, the base is farthest from it in Z.
    faces = [tag for _, tag in model.getBoundary([(3, v) for v in volumes], oriented=False) if _ == 2]
    contact, base, ends = [], [], []
    dist = {}
    for tag in faces:
        xyz = model.getClosestPoint(2, tag, [0.0, 0.0, 0.0])[0]
        dist[tag] = float(np.linalg.norm(xyz))
    contact = [min(dist, key=dist.get)]
    far = {}
    for tag in faces:
        if tag in contact:
            continue
        lo_hi = np.array(model.getBoundingBox(2, tag)).reshape(2, 3)
        far[tag] = abs(lo_hi[:, 2]).min()
    base = [max(far, key=far.get)]
    ends = [t for t in faces if t not in contact and t not in base]
    groups = {}
    for name, dim, tags in (("body", 3, volumes), ("contact", 2, contact), ("base", 2, base), ("ends", 2, ends)):
        if prefix:
            name = prefix if name == "body" else f"{prefix}_{name}"
        groups[name] = (dim, model.addPhysicalGroup(dim, tags, name=name))
    if not size_field:
        return groups

    a, b = spec.semi_axis_long_m, spec.semi_axis_lat_m
    c = math.sqrt(a * b)
    h_c = spec.contact_size_m
    h_max = max(d, spec.half_width_m, spec.half_length_m) / 4.0

    rho2 = f"((x/{gmsh_number(a)})^2+(y/{gmsh_number(b)})^2+(z/{gmsh_number(c)})^2)"
    set_size_field(model, f"min({gmsh_number(h_max)}, {gmsh_number(h_c)}*sqrt(1+({rho2}/1.69)^2))")
    return groups
