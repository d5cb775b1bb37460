"""gmsh model of a plane-strain slab: the two-dimensional (Carter) verification body of the rolling FEA.

A rectangle x in [-L, L], z in [-L, 0] (the contact face z = 0, the material below, the base z = -L clamped) meshed
in two dimensions with triangles refined around the expected patch |x| <= a (the size field of
:mod:`meshing.hertz`: size = min(L/3, h_c + g d), d the distance to the box |x| <= rho_0 a, |z| <= rho_0 a,
h_c = a/n), then extruded by one layer of thickness h_c along y. Every node lies on y = 0 or y = h_c, so the
constraint u_y = 0 on both faces (physical group ``symmetry_y``, which the FEA solvers hold) makes the 3-D
tetrahedral model a plane-strain one: a long cylinder of contact half-width a per unit length = the slab
thickness.

Physical groups: ``body`` (3-D), ``contact`` (z = 0), ``base`` (z = -L), ``symmetry_y`` (both faces y = 0 and
y = h_c).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from meshing.session import gmsh_number, set_size_field


@dataclass(frozen=True)
class SlabSpec:
    """Parameters of the plane-strain slab.

    Attributes:
        semi_axis_m: a, the expected contact half-width (along x), m.
        elements_per_semi_axis: n, element size at the patch h_c = a/n (>= 1); also the slab's thickness.
        domain_factor: L/a, the half-width and depth of the slab in units of a (>= 4).
        refine_radius: rho_0, half-size of the uniformly refined box in units of a (> 0).
        grading: g, largest growth of the element size per unit distance outside that box (> 0).
    """

    semi_axis_m: float
    elements_per_semi_axis: float = 16.0
    domain_factor: float = 20.0
    refine_radius: float = 1.5
    grading: float = 0.3

    def __post_init__(self) -> None:
        for name in ("semi_axis_m", "refine_radius", "grading"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        if not (math.isfinite(self.elements_per_semi_axis) and self.elements_per_semi_axis >= 1):
            raise ValueError(f"elements_per_semi_axis = {self.elements_per_semi_axis!r}: expected a number >= 1")
        if not (math.isfinite(self.domain_factor) and self.domain_factor >= 4):
            raise ValueError(f"domain_factor = {self.domain_factor!r}: expected a number >= 4")

    @property
    def contact_size_m(self) -> float:
        """h_c, element size in the patch and thickness of the slab, m."""
        return self.semi_axis_m / self.elements_per_semi_axis

    @property
    def half_width_m(self) -> float:
        """L, m."""
        return self.domain_factor * self.semi_axis_m


def build_slab(model, spec: SlabSpec) -> dict[str, tuple[int, int]]:
    """Add the extruded slab, its physical groups and its size field to the current gmsh model (not meshed)."""
    half, h_c = spec.half_width_m, spec.contact_size_m
    geo = model.geo
    corners = [(-half, -half), (half, -half), (half, 0.0), (-half, 0.0)]
    points = [geo.addPoint(x, 0.0, z) for x, z in corners]
    lines = [geo.addLine(points[i], points[(i + 1) % 4]) for i in range(4)]  # base, right, top (contact), left
    surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    out = geo.extrude([(2, surface)], 0.0, h_c, 0.0, numElements=[1])
    geo.synchronize()
    volume = next(tag for dim, tag in out if dim == 3)
    back = out[0][1]  # the copy of the surface at y = h_c
    sides = [tag for dim, tag in out[2:] if dim == 2]  # extruded from base, right, top, left in that order
    groups: dict[str, tuple[int, int]] = {}

    def add(dim, tags, name):
        groups[name] = (dim, model.addPhysicalGroup(dim, tags, name=name))

    add(3, [volume], "body")
    add(2, [sides[2]], "contact")
    add(2, [sides[0]], "base")
    add(2, [surface, back], "symmetry_y")

    r0 = spec.refine_radius * spec.semi_axis_m
    d = f"sqrt(max(abs(x)-{gmsh_number(r0)},0)^2+max(abs(z)-{gmsh_number(r0)},0)^2)"
    set_size_field(model, f"min({gmsh_number(half / 3)},{gmsh_number(h_c)}+{gmsh_number(spec.grading)}*{d})")
    return groups
