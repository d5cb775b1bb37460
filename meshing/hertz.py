"""gmsh model of the canonical Hertz verification body: an elastic block under a rigid quadric.

Within linear (half-space) contact theory the contact of two elastic quadric bodies equals the
contact of one elastic half-space with the combined modulus E* against a rigid indenter whose
surface is the undeformed gap h(x, y) = A x^2 + B y^2 (Johnson 1985, sec. 4.2). The block is the
half-space truncated at a distance of many semi-axes; its top face z = 0 is the contact surface,
the material is at z < 0 (z is the outward normal of the contact face), the base z = -depth is
clamped.

Model variants (``symmetry``):

* ``"quarter"``: x >= 0, y >= 0 with symmetry planes x = 0 and y = 0 (an elliptic patch with its
  axes along x and y, centred at the origin);
* ``"full"``: the whole block |x - x_c|, |y - y_c| <= half-width (any gap shape).

The mesh is refined in a box around the expected patch by a gmsh MathEval size field with a
bounded grading rate g (size grows by at most g per unit distance):

    size = min(h_max, h_c + g d),   d = distance to the box |x - x_c| <= rho_0 a, |y - y_c| <= rho_0 b,
                                        |z| <= rho_0 min(a, b),

h_c = min(a, b)/n, g = ``grading`` (0.4), h_max = half-width / 3. a, b are the expected semi-axes (e.g.
Hertz's), n the elements per semi-axis. A patch of several separate regions (``refine_boxes_m``: a sampled gap whose
interpenetration falls apart, e.g. the joined flange-root patch of manchester-a22, two strips 10 mm apart) is refined
in one box per region instead, size = min over the boxes of (h_c + g d_i), h_c = the narrowest region's
min(a_i, b_i)/n: one box around both at the size of the box's own semi-axes gave 1.7 to 4 elements across each strip
and a max pressure and area that did not converge to 10 % by 1e5 unknowns.
(An earlier field, h_c sqrt(1 + (rho/rho_0)^4) with an elliptic
rho, grows quadratically: its grading rate grows without bound with the distance, and on elongated patches
(flange contact, a/b ~ 10, full block) gmsh produced sliver tetrahedra with minSICN ~1e-5, the
MeshQualityError of ``wheelrail contact manchester-a22 --method fea`` at flange positions.)

Physical groups (named): ``body`` (3-D), ``contact`` (top face), ``base`` (bottom face),
``symmetry_x`` (plane x = 0, quarter model), ``symmetry_y`` (plane y = 0, quarter model).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from meshing.session import gmsh_number, set_size_field

SYMMETRIES = ("quarter", "full")


@dataclass(frozen=True)
class HertzBlockSpec:
    """Parameters of the Hertz block mesh (SI units).

    Attributes:
        semi_axis_long_m: expected semi-axis a of the patch along x, m (> 0).
        semi_axis_lat_m: expected semi-axis b along y, m (> 0).
        elements_per_semi_axis: n, element size at the patch h_c = min(a, b)/n (>= 1).
        domain_factor: half-width and depth of the block in units of max(a, b) (>= 4).
        refine_radius: rho_0, size of the uniformly refined region in units of the semi-axes (> 0).
        grading: g, largest growth of the element size per unit distance outside that region (> 0).
        center_m: (x_c, y_c), centre of the refined region, m (must be (0, 0) for the quarter model).
        symmetry: "quarter" or "full".
        refine_boxes_m: ((x_c, y_c, a_i, b_i), ...), separate regions of the patch, each refined in its own box
            (module docstring); empty: the one box of the semi-axes above.
        peak_boxes_m: ((x_c, y_c, a_i, b_i, h_i), ...), boxes |x - x_c| <= a_i, |y - y_c| <= b_i, |z| <= min(a_i, b_i)
            meshed at the element size h_i (smaller than h_c), the size growing by g away from them (the pressure
            peak of a sampled patch, fea.model: the module docstring's "Peak box").
    """

    semi_axis_long_m: float
    semi_axis_lat_m: float
    elements_per_semi_axis: float = 6.0
    domain_factor: float = 20.0
    refine_radius: float = 1.3
    grading: float = 0.4
    center_m: tuple[float, float] = (0.0, 0.0)
    symmetry: str = "quarter"
    refine_boxes_m: tuple = ()
    peak_boxes_m: tuple = ()

    def __post_init__(self) -> None:
        for name in ("semi_axis_long_m", "semi_axis_lat_m", "refine_radius", "grading"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        if not (math.isfinite(self.elements_per_semi_axis) and self.elements_per_semi_axis >= 1):
            raise ValueError(f"elements_per_semi_axis = {self.elements_per_semi_axis!r}: expected a number >= 1")
        if not (math.isfinite(self.domain_factor) and self.domain_factor >= 4):
            raise ValueError(f"domain_factor = {self.domain_factor!r}: expected a number >= 4")
        if self.symmetry not in SYMMETRIES:
            raise ValueError(f"symmetry = {self.symmetry!r}: expected one of {SYMMETRIES}")
        if len(self.center_m) != 2 or not all(math.isfinite(c) for c in self.center_m):
            raise ValueError(f"center_m = {self.center_m!r}: expected two finite numbers")
        if self.symmetry == "quarter" and any(c != 0 for c in self.center_m):
            raise ValueError(f"center_m = {self.center_m!r}: the quarter model needs the patch centre at (0, 0)")
        for box in self.refine_boxes_m:
            if len(box) != 4 or not all(math.isfinite(v) for v in box) or min(box[2:]) <= 0:
                raise ValueError(f"refine_boxes_m entry {box!r}: expected (x_c, y_c, a > 0, b > 0)")
        for box in self.peak_boxes_m:
            if len(box) != 5 or not all(math.isfinite(v) for v in box) or min(box[2:]) <= 0:
                raise ValueError(f"peak_boxes_m entry {box!r}: expected (x_c, y_c, a > 0, b > 0, h > 0)")
        if self.peak_boxes_m and self.symmetry == "quarter":
            raise ValueError("peak_boxes_m: expected symmetry 'full'")
        if self.refine_boxes_m and self.symmetry == "quarter":
            raise ValueError("refine_boxes_m: expected symmetry 'full' (separate regions have no quarter symmetry)")

    @property
    def contact_size_m(self) -> float:
        """h_c, element size in the patch, m (the narrowest region's with ``refine_boxes_m``)."""
        if self.refine_boxes_m:
            return min(min(box[2], box[3]) for box in self.refine_boxes_m) / self.elements_per_semi_axis
        return min(self.semi_axis_long_m, self.semi_axis_lat_m) / self.elements_per_semi_axis

    @property
    def half_width_m(self) -> float:
        """Half-width (and depth) of the block, m."""
        return self.domain_factor * max(self.semi_axis_long_m, self.semi_axis_lat_m)


def build_hertz_block(model, spec: HertzBlockSpec) -> dict[str, tuple[int, int]]:
    """Add the block geometry, its physical groups and the size field to the current gmsh model.

    Args:
        model: the ``gmsh.model`` API object; its current model receives the geometry (the caller
            owns gmsh's initialisation and the model's lifetime, see :func:`meshing.session.gmsh_model`).
        spec: block parameters.

    Returns:
        physical group name -> (dimension, physical tag).
        The mesh is not generated (call :func:`meshing.session.generate`).
    """
    import numpy as np

    half = spec.half_width_m
    depth = half
    xc, yc = spec.center_m
    if spec.symmetry == "quarter":
        x0, y0, dx, dy = 0.0, 0.0, half, half
    else:
        x0, y0, dx, dy = xc - half, yc - half, 2 * half, 2 * half
    volume = model.occ.addBox(x0, y0, -depth, dx, dy, depth)
    model.occ.synchronize()

    # Classify the six faces by the coordinate that is constant on them (robust to gmsh's bbox padding).
    faces = {}
    for _, tag in model.getEntities(2):
        lo_hi = np.array(model.getBoundingBox(2, tag)).reshape(2, 3)
        axis = int(np.argmin(lo_hi[1] - lo_hi[0]))
        faces[(axis, float(lo_hi.mean(axis=0)[axis]))] = tag

    def faces_at(axis, value):
        scale = max(half, 1e-300)
        return [tag for (ax, val), tag in faces.items() if ax == axis and abs(val - value) < 1e-6 * scale]

    groups: dict[str, tuple[int, int]] = {}

    def add(dim, tags, name):
        if not tags:
            raise ValueError(f"physical group {name!r}: no entity found (geometry construction failed)")
        groups[name] = (dim, model.addPhysicalGroup(dim, tags, name=name))

    add(3, [volume], "body")
    add(2, faces_at(2, 0.0), "contact")
    add(2, faces_at(2, -depth), "base")
    if spec.symmetry == "quarter":
        add(2, faces_at(0, 0.0), "symmetry_x")
        add(2, faces_at(1, 0.0), "symmetry_y")

    _size_field(model, spec)
    return groups


def build_hertz_pair(model, spec: HertzBlockSpec) -> dict[str, tuple[int, int]]:
    """Two blocks touching at z = 0 (not fused: each has its own contact face and nodes).

    ``lower`` occupies z in [-depth, 0], ``upper`` z in [0, depth], same lateral extent as
    :func:`build_hertz_block`. The caller gives the faces their curvature (e.g. by morphing the mesh:
    lower top to z = -f1(x, y), upper bottom to z = +f2(x, y)), so that the undeformed distance is
    h = f1 + f2. Groups: ``lower``, ``upper`` (3-D), ``lower_contact``, ``upper_contact``,
    ``lower_base`` (z = -depth), ``upper_base`` (z = +depth), and for the quarter model
    ``symmetry_x``, ``symmetry_y`` (faces of both blocks).
    """
    import numpy as np

    half = spec.half_width_m
    xc, yc = spec.center_m
    if spec.symmetry == "quarter":
        x0, y0, dx, dy = 0.0, 0.0, half, half
    else:
        x0, y0, dx, dy = xc - half, yc - half, 2 * half, 2 * half
    lower = model.occ.addBox(x0, y0, -half, dx, dy, half)
    upper = model.occ.addBox(x0, y0, 0.0, dx, dy, half)
    model.occ.synchronize()
    groups: dict[str, tuple[int, int]] = {}
    sym_x, sym_y = [], []
    for body, name in ((lower, "lower"), (upper, "upper")):
        groups[name] = (3, model.addPhysicalGroup(3, [body], name=name))
        faces = {}
        for _, tag in model.getBoundary([(3, body)], oriented=False):
            lo_hi = np.array(model.getBoundingBox(2, tag)).reshape(2, 3)
            axis = int(np.argmin(lo_hi[1] - lo_hi[0]))
            faces[tag] = (axis, float(lo_hi.mean(axis=0)[axis]))
        tol = 1e-6 * half
        contact = [t for t, (ax, v) in faces.items() if ax == 2 and abs(v) < tol]
        base = [t for t, (ax, v) in faces.items() if ax == 2 and abs(abs(v) - half) < tol]
        groups[f"{name}_contact"] = (2, model.addPhysicalGroup(2, contact, name=f"{name}_contact"))
        groups[f"{name}_base"] = (2, model.addPhysicalGroup(2, base, name=f"{name}_base"))
        if spec.symmetry == "quarter":
            sym_x += [t for t, (ax, v) in faces.items() if ax == 0 and abs(v) < tol]
            sym_y += [t for t, (ax, v) in faces.items() if ax == 1 and abs(v) < tol]
    if spec.symmetry == "quarter":
        groups["symmetry_x"] = (2, model.addPhysicalGroup(2, sym_x, name="symmetry_x"))
        groups["symmetry_y"] = (2, model.addPhysicalGroup(2, sym_y, name="symmetry_y"))
    _size_field(model, spec)
    return groups


def _size_field(model, spec: HertzBlockSpec) -> None:
    """MathEval size field of the module docstring (refined box around the expected patch, bounded grading)."""
    r0 = spec.refine_radius
    h_max = spec.half_width_m / 3.0
    boxes = spec.refine_boxes_m or ((*spec.center_m, spec.semi_axis_long_m, spec.semi_axis_lat_m),)
    # every box as (x_c, y_c, half-width along x, along y, element size): the patch boxes widened by r0 at h_c, the
    # peak boxes as given
    sized = [(xc, yc, r0 * a, r0 * b, spec.contact_size_m) for xc, yc, a, b in boxes] + list(spec.peak_boxes_m)
    terms = []
    for xc, yc, a, b, size in sized:
        dx = f"max(abs(x-({gmsh_number(xc)}))-{gmsh_number(a)},0)"
        dy = f"max(abs(y-({gmsh_number(yc)}))-{gmsh_number(b)},0)"
        dz = f"max(abs(z)-{gmsh_number(min(a, b))},0)"
        terms.append(f"{gmsh_number(size)}+{gmsh_number(spec.grading)}*sqrt({dx}^2+{dy}^2+{dz}^2)")
    expression = gmsh_number(h_max)
    for term in terms:  # gmsh's MathEval min takes two arguments
        expression = f"min({expression},{term})"
    set_size_field(model, expression)
