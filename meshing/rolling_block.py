"""gmsh model of the rolling (creep-force) verification body: a full block with a structured box under the patch.

The block is :mod:`meshing.hertz`'s full block (|x|, |y| <= L, -L <= z <= 0, contact face z = 0, base z = -L clamped)
with one difference: a box around the expected patch, |x| <= X, |y| <= Y, -Z <= z <= 0, is meshed by gmsh's
transfinite algorithm, i.e. a uniform grid of cubes of edge h = min(a, b)/n, each split into six tetrahedra
(transfinite curves, surfaces and volumes; the box in two halves y < 0 and y > 0, mirror images of each other, so
that the mesh is symmetric about the plane y = 0), and the rest of the block is meshed
with unstructured tetrahedra conforming to the box's faces, their size growing away from the box by at most g per unit
distance (the size field of :mod:`meshing.hertz`: size = min(L/3, h + g d), d the distance to the box).

Why (steady rolling, :func:`fea.friction.solve_rolling`): the slip of a face node is the upwind difference of the
surface displacement over the rolled step dq along x, and Coulomb's law is collocated at the nodes, so the creep
force's discretisation error is set by where the stick/slip boundary and the trailing edge fall between the nodes of
each row along x. On an unstructured face those positions change at random from mesh to mesh (the measured error of
the Hertz circle, +14.8/+6.2/+6.3/+4.1 % at 4/6/8/12 elements per semi-axis, was not monotone). On this face the nodes
lie on rows y = j h with nodes at x = i h (the grid contains the origin, the patch centre), the transport x + dq runs
along a row, and every mesh of a series n, r n, r^2 n is the same grid scaled by 1/r inside the box: the slab's
(Carter's) situation, where the error falls at first order.

The box half-sizes are whole numbers of cells: X = ceil(rho_0 a/h) h, Y = ceil(rho_0 b/h) h,
Z = ceil(rho_z min(a, b)/h) h (rho_0 = ``box_radius``, rho_z = ``box_depth``), so the box covers the patch and the
transport's reach (a + dq) and keeps its shape to within one cell along a series.

Edge-fitted rows (``fit_edge``, :func:`fit_rows_to_edge`): the grid alone leaves one irregular term. The patch edge
x_e(y_j) = a sqrt(1 - y_j^2/b^2) of row j falls at a fraction of a cell that changes from row to row and from mesh to
mesh (the lattice points of an ellipse; near y = 0 the edge is stationary, so neighbouring rows share the fraction
and their edge errors add up instead of averaging out). Measured on the Hertz circle against the BEM at 4/6/9
elements per semi-axis on the grid without the fit: +12.1/+8.7/+3.9 % at xi = 5e-4 and +14.6/+11.3/+6.6 % at
xi = 5e-5, not a regular series (the differences grow from 4-6 to 6-9). With the rows' nodes moved along x so that
each row's m-th node lies on x_e (m = round(x_e/h)): +11.3/+5.8/+2.7/+1.1 % at 4/6/9/13.5 (xi = 5e-4), observed
order 1.45 (4/6/9) and 1.56 (6/9/13.5) (benchmarks/results/fea_friction.md).

Physical groups (named): ``body`` (3-D, both volumes), ``contact`` (the face z = 0, both parts), ``base`` (z = -L).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from meshing.session import gmsh_number, set_size_field


@dataclass(frozen=True)
class RollingBlockSpec:
    """Parameters of the rolling block (SI units; the patch centred at the origin, axes along x and y).

    Attributes:
        semi_axis_long_m: expected semi-axis a of the patch along x (the rolling direction), m (> 0).
        semi_axis_lat_m: expected semi-axis b along y, m (> 0).
        elements_per_semi_axis: n, the grid step h = min(a, b)/n (>= 2).
        domain_factor: L in units of max(a, b) (>= 4).
        box_radius: rho_0, half-size of the structured box along x and y in units of the semi-axes (> 1).
        box_depth: rho_z, its depth in units of min(a, b) (> 0).
        grading: g, largest growth of the element size per unit distance outside the box (> 0).
        fit_edge: move the box's face rows so that each row's contact nodes end on the expected patch edge
            (:func:`fit_rows_to_edge`, applied by :func:`fea.domain.rolling_block_domain` after meshing).
    """

    semi_axis_long_m: float
    semi_axis_lat_m: float
    elements_per_semi_axis: float = 6.0
    domain_factor: float = 10.0
    box_radius: float = 1.5
    box_depth: float = 1.0
    grading: float = 0.4
    fit_edge: bool = True

    def __post_init__(self) -> None:
        for name in ("semi_axis_long_m", "semi_axis_lat_m", "box_depth", "grading"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        if not (math.isfinite(self.elements_per_semi_axis) and self.elements_per_semi_axis >= 2):
            raise ValueError(f"elements_per_semi_axis = {self.elements_per_semi_axis!r}: expected a number >= 2")
        if not (math.isfinite(self.box_radius) and self.box_radius > 1):
            raise ValueError(f"box_radius = {self.box_radius!r}: expected a number > 1")
        if not (math.isfinite(self.domain_factor) and self.domain_factor >= 4):
            raise ValueError(f"domain_factor = {self.domain_factor!r}: expected a number >= 4")
        if self.domain_factor * max(self.semi_axis_long_m, self.semi_axis_lat_m) <= 1.5 * max(self.box_half_sizes_m):
            raise ValueError(f"domain_factor = {self.domain_factor!r}: the block must be wider than the structured box")

    @property
    def contact_size_m(self) -> float:
        """h, the grid step (cube edge) of the structured box, m."""
        return min(self.semi_axis_long_m, self.semi_axis_lat_m) / self.elements_per_semi_axis

    @property
    def box_cells(self) -> tuple[int, int, int]:
        """Cells of the structured box along x (per half), y (per half) and z."""
        h = self.contact_size_m

        def cells(length):
            return max(1, math.ceil(length / h - 1e-9))

        short = min(self.semi_axis_long_m, self.semi_axis_lat_m)
        return (
            cells(self.box_radius * self.semi_axis_long_m),
            cells(self.box_radius * self.semi_axis_lat_m),
            cells(self.box_depth * short),
        )

    @property
    def box_half_sizes_m(self) -> tuple[float, float, float]:
        """(X, Y, Z): the structured box |x| <= X, |y| <= Y, -Z <= z <= 0, m."""
        h = self.contact_size_m
        return tuple(k * h for k in self.box_cells)

    @property
    def half_width_m(self) -> float:
        """L, half-width and depth of the block, m."""
        return self.domain_factor * max(self.semi_axis_long_m, self.semi_axis_lat_m)


def build_rolling_block(model, spec: RollingBlockSpec) -> dict[str, tuple[int, int]]:
    """Add the block, its structured box, the physical groups and the size field to the current gmsh model.

    Args:
        model: the ``gmsh.model`` API object (the caller owns gmsh's lifetime, :func:`meshing.session.gmsh_model`).
        spec: block parameters.

    Returns:
        physical group name -> (dimension, physical tag). The mesh is not generated.
    """
    import numpy as np

    half = spec.half_width_m
    bx, by, bz = spec.box_half_sizes_m
    h = spec.contact_size_m
    outer = model.occ.addBox(-half, -half, -half, 2 * half, 2 * half, half)
    upper = model.occ.addBox(-bx, 0.0, -bz, 2 * bx, by, bz)
    lower = model.occ.addBox(-bx, -by, -bz, 2 * bx, by, bz)
    model.occ.fragment([(3, outer)], [(3, upper), (3, lower)])
    model.occ.synchronize()

    def box(dim, tag):
        return np.array(model.getBoundingBox(dim, tag)).reshape(2, 3)

    tol = 1e-2 * h  # above the OCC bounding boxes' padding (about 1e-7 m)
    volumes = [tag for _, tag in model.getEntities(3)]
    halves = [t for t in volumes if np.all(np.abs(box(3, t)[:, :2]) <= np.array([bx, by]) + tol)]
    if len(volumes) != 3 or len(halves) != 2:
        raise ValueError(f"rolling block: expected the block and the box's two halves, got {len(volumes)} volumes")
    for vol in halves:
        # the half y < 0 is parametrised as the mirror image of the half y > 0 (corners and face corners in mirrored
        # order), so the cubes' split into tetrahedra is mirror-symmetric about y = 0 (F_y = 0 under pure xi)
        sign = np.array([1.0, 1.0 if box(3, vol)[1, 1] > tol else -1.0, 1.0])
        faces = [tag for _, tag in model.getBoundary([(3, vol)], oriented=False)]
        for face in faces:
            for _, c in model.getBoundary([(2, face)], oriented=False):
                lo, hi = box(1, abs(c))
                model.mesh.setTransfiniteCurve(abs(c), int(round(float(np.max(hi - lo)) / h)) + 1)
            corners = sorted({p for _, p in model.getBoundary([(2, face)], oriented=False, recursive=True)})
            xyz = np.array([model.getValue(0, p, []) for p in corners]) * sign
            u, v = (k for k in range(3) if np.ptp(xyz[:, k]) > tol)
            order = sorted(range(4), key=lambda k: (xyz[k, v], xyz[k, u]))
            # "Left": every quad split along the same diagonal, as the transfinite volume splits its cubes
            # ("Alternate" faces do not match the volume's tetrahedra: a non-conforming mesh)
            model.mesh.setTransfiniteSurface(face, "Left", [corners[order[i]] for i in (0, 1, 3, 2)])
        points = sorted({p for _, p in model.getBoundary([(3, vol)], oriented=False, recursive=True)})
        xyz = np.array([model.getValue(0, p, []) for p in points]) * sign
        bottom = sorted((k for k in range(8) if xyz[k, 2] < -tol), key=lambda k: (xyz[k, 1], xyz[k, 0]))
        top = sorted((k for k in range(8) if xyz[k, 2] >= -tol), key=lambda k: (xyz[k, 1], xyz[k, 0]))
        loop = [bottom[i] for i in (0, 1, 3, 2)] + [top[i] for i in (0, 1, 3, 2)]
        model.mesh.setTransfiniteVolume(vol, [points[k] for k in loop])

    groups: dict[str, tuple[int, int]] = {}

    def add(dim, tags, name):
        if not tags:
            raise ValueError(f"physical group {name!r}: no entity found (geometry construction failed)")
        groups[name] = (dim, model.addPhysicalGroup(dim, tags, name=name))

    def flat_at(z):
        out = []
        for _, tag in model.getEntities(2):
            lo, hi = box(2, tag)
            if int(np.argmin(hi - lo)) == 2 and abs(0.5 * (lo[2] + hi[2]) - z) < tol:
                out.append(tag)
        return out

    add(3, volumes, "body")
    add(2, flat_at(0.0), "contact")
    add(2, flat_at(-half), "base")

    dx, dy = f"max(abs(x)-{gmsh_number(bx)},0)", f"max(abs(y)-{gmsh_number(by)},0)"
    dz = f"max(abs(z+{gmsh_number(bz / 2)})-{gmsh_number(bz / 2)},0)"
    d = f"sqrt({dx}^2+{dy}^2+{dz}^2)"
    set_size_field(model, f"min({gmsh_number(half / 3)},{gmsh_number(h)}+{gmsh_number(spec.grading)}*{d})")
    return groups


def fit_rows_to_edge(spec: RollingBlockSpec, points_m):
    """Move the box's nodes along x so that every row's contact nodes end on the expected patch edge (numpy).

    Row y_j = j h (|y_j| < b) of the face grid has its nodes at x = i h; the patch edge x_e = a sqrt(1 - y_j^2/b^2)
    falls at a fraction of a cell that changes from row to row and from mesh to mesh (the lattice points of an
    ellipse). The map x -> x x_e/(m h) for |x| <= m h, m = round(x_e/h) >= 1, and linear from (m h, x_e) to
    (X, X) beyond (mirrored for x < 0), puts the row's m-th node on the edge; it fades linearly with the depth
    (zero at z = -Z) and is zero outside the box, so the box's faces and the unstructured mesh do not move.
    Rows with m = 0 or |y_j| >= b are not moved. All nodes of the box lie on the planes y = j h, so the map moves
    whole rows of every layer of cubes and the tetrahedra stay valid (the row's cells are stretched by at most
    1/(2 m)).

    Args:
        spec: the block's parameters.
        points_m: (k, 3) node coordinates, m.

    Returns:
        (k, 3) moved coordinates, m.
    """
    import numpy as np

    pts = np.array(points_m, dtype=float, copy=True)
    h = spec.contact_size_m
    big_x, big_y, big_z = spec.box_half_sizes_m
    a, b = spec.semi_axis_long_m, spec.semi_axis_lat_m
    x, y, z = pts[:, 0], pts[:, 1], pts[:, 2]
    tol = 1e-9 * h
    inside = (np.abs(x) < big_x - tol) & (np.abs(y) < b - tol) & (z > -big_z + tol)
    row = np.round(y / h)
    on_row = np.abs(y - row * h) <= 1e-6 * h
    edge = a * np.sqrt(np.clip(1.0 - (row * h / b) ** 2, 0.0, None))
    m = np.round(edge / h)
    move = inside & on_row & (m >= 1)
    ax = np.abs(x)
    inner = ax <= m * h
    mapped = np.where(
        inner,
        ax * edge / np.maximum(m * h, tol),
        edge + (ax - m * h) * (big_x - edge) / np.maximum(big_x - m * h, tol),
    )
    fade = 1.0 + z / big_z
    new_x = x + (np.sign(x) * mapped - x) * fade
    pts[:, 0] = np.where(move, new_x, x)
    return pts
