"""Post-processing of the FE contact solution: pressure field, patch size, subsurface stresses.

Pressure. The nodal contact forces N_i of a P1 solution with nodal contact constraints scatter by
several per cent from node to node on an unstructured face mesh (their sum is exact). The pressure
field is therefore the force-weighted patch average p_i = sum_{|x_j - x_i| < r} N_j / sum w_j
(w_j the lumped face weights, r ~ 1.5 element sizes), which keeps the integral of the pressure and
converges as O(h^2) for a smooth pressure.

Semi-axes of a quadric (Hertzian) patch. The continuum pressure is p^2 = p0^2 (1 - x^2/a^2 - y^2/b^2)
(Johnson 1985, eq 3.63): a least-squares fit of c0 + cx x^2 + cy y^2 to p^2 over the nodes in contact
gives a = sqrt(-c0/cx), b = sqrt(-c0/cy); the relative rms residual of the fit is reported so a
non-elliptic patch is visible.

Stresses. sigma(u_h) (constant per P1 cell) is recovered at the nodes by a lumped L2 projection
sigma_i = int sigma phi_i dx / int phi_i dx. Derived: principal stresses s1 >= s2 >= s3, von Mises
sqrt(((s1-s2)^2 + (s2-s3)^2 + (s3-s1)^2)/2), maximum shear (Tresca) (s1 - s3)/2. Depth = -z, m.
"""

from __future__ import annotations

import math

import numpy as np


def mirror_quarter(xy: np.ndarray, *values: np.ndarray) -> tuple[np.ndarray, ...]:
    """Reflect quarter-model node data (x >= 0, y >= 0) into the four quadrants.

    Nodes on a symmetry plane appear twice (on the axis four times) with the forces and weights
    of the quarter model, so force / weight sums over a neighbourhood stay exact.
    """
    signs = ((1, 1), (-1, 1), (1, -1), (-1, -1))
    xy_full = np.concatenate([xy * np.array(s) for s in signs])
    return (xy_full, *(np.tile(v, 4) for v in values))


def filtered_pressure(
    xy_all: np.ndarray, force_all: np.ndarray, weight_all: np.ndarray, points: np.ndarray, radius_m: float
) -> np.ndarray:
    """Force-weighted patch average of the nodal pressure at ``points`` (see the module docstring).

    Args:
        xy_all: (n, 2) node positions, m. force_all, weight_all: (n,) N_i (N) and w_i (m^2).
        points: (k, 2) evaluation points, m. radius_m: averaging radius r, m.

    Returns:
        (k,) pressures, Pa.
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(xy_all)
    out = np.zeros(len(points))
    for i, neighbours in enumerate(tree.query_ball_point(points, radius_m)):
        if neighbours:
            out[i] = force_all[neighbours].sum() / weight_all[neighbours].sum()
    return out


def fit_elliptic_pressure(xy: np.ndarray, pressure: np.ndarray) -> dict:
    """Fit p^2 = c0 + cx x^2 + cy y^2 over the nodes with p > 0 (see the module docstring).

    Returns:
        dict with max_pressure_Pa (sqrt c0), semi_axis_long_m, semi_axis_lat_m (nan if the fit is not
        an ellipse) and relative_rms (rms residual of p^2 / c0).
    """
    mask = pressure > 0
    nan = float("nan")
    if mask.sum() < 4:
        return {"max_pressure_Pa": nan, "semi_axis_long_m": nan, "semi_axis_lat_m": nan, "relative_rms": nan}
    x, y, p = xy[mask, 0], xy[mask, 1], pressure[mask]
    matrix = np.column_stack([np.ones_like(x), x**2, y**2])
    coef, *_ = np.linalg.lstsq(matrix, p**2, rcond=None)
    c0, cx, cy = coef
    ok = c0 > 0 and cx < 0 and cy < 0
    rms = float(np.sqrt(np.mean((matrix @ coef - p**2) ** 2)) / c0) if c0 > 0 else nan
    return {
        "max_pressure_Pa": float(np.sqrt(c0)) if c0 > 0 else nan,
        "semi_axis_long_m": float(np.sqrt(-c0 / cx)) if ok else nan,
        "semi_axis_lat_m": float(np.sqrt(-c0 / cy)) if ok else nan,
        "relative_rms": rms,
    }


def pressure_on_grid(
    xy: np.ndarray, pressure: np.ndarray, x_m: np.ndarray, y_m: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Nodal pressures on the grid (y_m, x_m).

    A grid point is in contact when its nearest node is (so the outline runs half-way between the
    last node in contact and the first free one); the pressure there is the piecewise-linear
    interpolation of the nodal pressures, 0 elsewhere. Duplicated (mirrored) nodes are merged.

    The grid points are located in the nodes' Delaunay triangulation by qhull's brute-force search: its directed
    walk (what ``LinearNDInterpolator`` uses) took from milliseconds to seconds on the same structured, graded
    contact-face nodes (many co-circular points), which made it the largest part of a wheelset-case FEA solve. The
    brute-force search costs (grid points) x (triangles): over the whole contact face it took 20 s of a 50 s solve
    on the A-2.2 flange-root patch (P2, 3e4 unknowns), so only the nodes within half the grid's span of it are
    triangulated (the same triangles where the grid is).

    Returns:
        (pressure, in_contact): arrays of shape (len(y_m), len(x_m)), Pa and bool.
    """
    from scipy.spatial import Delaunay, cKDTree

    first = _distinct_nodes(xy)
    nodes, values = xy[first], pressure[first]
    # only the nodes near the grid enter the triangulation: a Delaunay triangle of all nodes stays one of a subset
    # that holds its vertices, and those of the triangles that hold grid points lie within an element of the grid
    # (the margin, half the grid's span, is wider than the elements at the patch)
    margin = 0.5 * max(np.ptp(x_m), np.ptp(y_m))
    near = (
        (nodes[:, 0] >= x_m.min() - margin)
        & (nodes[:, 0] <= x_m.max() + margin)
        & (nodes[:, 1] >= y_m.min() - margin)
        & (nodes[:, 1] <= y_m.max() + margin)
    )
    if near.sum() >= 16:
        nodes, values = nodes[near], values[near]
    scale = max(np.ptp(nodes[:, 0]), np.ptp(nodes[:, 1]), 1e-300)
    gx, gy = np.meshgrid(x_m, y_m)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    _, nearest = cKDTree(nodes).query(points)
    in_contact = (values[nearest] > 0).reshape(gx.shape)
    origin = nodes.mean(axis=0)
    tri = Delaunay((nodes - origin) / scale)  # unit scale, as LinearNDInterpolator (the same qhull options)
    query = (points - origin) / scale
    simplex = tri.find_simplex(query, bruteforce=True)
    transform = tri.transform[np.maximum(simplex, 0)]
    bary = np.einsum("nij,nj->ni", transform[:, :2], query - transform[:, 2])
    weights = np.column_stack([bary, 1.0 - bary.sum(axis=1)])
    linear = np.einsum("ni,ni->n", values[tri.simplices[np.maximum(simplex, 0)]], weights)
    grid = np.clip(np.where(simplex >= 0, linear, 0.0).reshape(gx.shape), 0.0, None)
    return np.where(in_contact, grid, 0.0), in_contact


def _distinct_nodes(xy: np.ndarray) -> np.ndarray:
    """Indices of the first of each set of coincident face nodes (positions equal to 1e-9 of the face's span: a node
    listed once per cell, or mirrored onto a symmetry plane of a quarter model).
    """
    scale = max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1]), 1e-300)
    keys = np.round(xy / (scale * 1e-9)).astype(np.int64)
    return np.unique(keys, axis=0, return_index=True)[1]


def principal_measures(stress: np.ndarray) -> dict[str, np.ndarray]:
    """Principal stresses, von Mises and maximum shear of stress tensors ``stress`` (n, 3, 3), Pa."""
    eig = np.linalg.eigvalsh(0.5 * (stress + np.swapaxes(stress, 1, 2)))[:, ::-1]
    s1, s2, s3 = eig[:, 0], eig[:, 1], eig[:, 2]
    von_mises = np.sqrt(0.5 * ((s1 - s2) ** 2 + (s2 - s3) ** 2 + (s3 - s1) ** 2))
    return {"principal": eig, "von_mises": von_mises, "max_shear": 0.5 * (s1 - s3)}


def recover_nodal_stress(displacement, young_modulus_Pa: float, poisson_ratio: float):
    """Lumped L2 projection of sigma(u) onto P1 tensors.

    Returns:
        (function, coords, stress): a dolfinx Function on a P1 (3, 3) space (for output), the (n, 3)
        coordinates of the locally owned nodes (m) and their (n, 3, 3) stress tensors (Pa).
    """
    import dolfinx_solver  # noqa: F401
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc
    from petsc4py import PETSc

    msh = displacement.function_space.mesh
    mu = young_modulus_Pa / (2.0 * (1.0 + poisson_ratio))
    lam = young_modulus_Pa * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio))
    eps = ufl.sym(ufl.grad(displacement))
    sigma = lam * ufl.tr(eps) * ufl.Identity(3) + 2.0 * mu * eps
    W = fem.functionspace(msh, ("Lagrange", 1, (3, 3)))
    S = fem.functionspace(msh, ("Lagrange", 1))
    tau, s = ufl.TestFunction(W), ufl.TestFunction(S)
    rhs = fem_petsc.assemble_vector(fem.form(ufl.inner(sigma, tau) * ufl.dx))
    mass = fem_petsc.assemble_vector(fem.form(s * ufl.dx))
    for vec in (rhs, mass):
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    n = W.dofmap.index_map.size_local
    values = rhs.array.reshape(-1, 9)[:n] / mass.array[:n, None]
    stress_fn = fem.Function(W, name="stress")
    stress_fn.x.array[: n * 9] = values.ravel()
    stress_fn.x.scatter_forward()
    coords = W.tabulate_dof_coordinates()[:n]
    rhs.destroy()
    mass.destroy()
    return stress_fn, coords, values.reshape(-1, 3, 3)


def axis_maximum(depth: np.ndarray, value: np.ndarray) -> tuple[float, float]:
    """Maximum of nodal samples along a line, refined by a parabola through the three best nodes.

    Args:
        depth: (k,) sample depths, m. value: (k,) samples.

    Returns:
        (maximum, depth of the maximum).
    """
    order = np.argsort(depth)
    d, v = depth[order], value[order]
    k = int(np.argmax(v))
    if 0 < k < len(v) - 1:
        coef = np.polyfit(d[k - 1 : k + 2], v[k - 1 : k + 2], 2)
        if coef[0] < 0:
            z = -coef[1] / (2 * coef[0])
            if d[k - 1] <= z <= d[k + 1]:
                return float(np.polyval(coef, z)), float(z)
    return float(v[k]), float(d[k])


def peak_pressure(
    xy: np.ndarray, pressure: np.ndarray, usable: np.ndarray, guess_m: np.ndarray, radius_m: float
) -> float | None:
    """Peak of a quadratic surface fitted to the squared nodal pressures around ``guess_m``, Pa (None: no fit).

    p^2 = c0 + c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2 (x, y from the guess) by least squares over the usable nodes
    within ``radius_m``; its stationary point, when the fit is a cap (negative definite) and the point lies within
    the radius, gives the peak sqrt(p^2). Hertz's p^2 is exactly such a quadric (Johnson 1985, eq 3.63), so the fit
    has no bias there; on a smooth non-Hertzian top the bias is O(r^4) in the fit radius r. Against the largest
    patch average (:func:`filtered_pressure`): the average of a hill is below its top by p0 r^2 / (4 a^2) and the
    largest of many noisy averages is biased upwards; the fit averages the nodal scatter over every node within r.

    Args:
        xy: (n, 2) node positions, m. pressure: (n,) nodal pressures N_i / w_i, Pa. usable: (n,) bool (in contact,
        with a lumped weight). guess_m: (2,) the location of the largest patch average, m. radius_m: fit radius, m.
    """
    d = xy - np.asarray(guess_m, float)
    near = usable & (np.hypot(d[:, 0], d[:, 1]) <= radius_m)
    return quadric_cap_peak(d[near] / radius_m, pressure[near])


def quadric_cap_peak(scaled_xy: np.ndarray, pressure: np.ndarray) -> float | None:
    """Peak of the quadric cap fitted to squared pressures on scaled coordinates (None: no fit).

    The fit of :func:`peak_pressure` on nodes given in coordinates scaled so that the fit window is the unit disc
    around the origin (a circle of radius r: positions / r; an ellipse of semi-axes (a, b): positions / (a, b)).
    p^2 = c0 + c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2 by least squares; None with fewer than 12 nodes, when the fit
    is not a cap (Hessian not negative definite), when its top lies outside the window (|top| > 1) or its p^2 there
    is not positive.

    Args:
        scaled_xy: (k, 2) the window's nodes, scaled positions relative to its centre. pressure: (k,) their nodal
        pressures, Pa.
    """
    fit = _cap_top(scaled_xy, pressure)
    return None if fit is None else fit[0]


def _cap_top(scaled_xy: np.ndarray, pressure: np.ndarray, weight: np.ndarray | None = None):
    """(peak pressure in Pa, the top in the scaled coordinates) of the quadric cap fitted to p^2 as
    :func:`quadric_cap_peak` fits it, by least squares weighted by ``weight`` when given; None as there.
    """
    if len(scaled_xy) < 12:
        return None
    x, y, p2 = scaled_xy[:, 0], scaled_xy[:, 1], pressure**2
    root_w = np.ones_like(x) if weight is None else np.sqrt(weight)
    matrix = np.column_stack([np.ones_like(x), x, y, x * x, x * y, y * y])
    c, *_ = np.linalg.lstsq(matrix * root_w[:, None], p2 * root_w, rcond=None)
    hessian = np.array([[2 * c[3], c[4]], [c[4], 2 * c[5]]])
    if not np.all(np.linalg.eigvalsh(hessian) < 0):
        return None
    top = np.linalg.solve(hessian, -c[1:3])
    if np.hypot(*top) > 1.0:
        return None
    value = float(c[0] + c[1:3] @ top + 0.5 * top @ hessian @ top)
    return (math.sqrt(value), top) if value > 0 else None


def window_peak(
    xy: np.ndarray, force: np.ndarray, weight: np.ndarray, centre_m: np.ndarray, window_m
) -> tuple[float, np.ndarray] | None:
    """Peak of the quadric cap fitted to p^2 over a window of fixed physical size, weighted by the nodes' areas.

    p_i = N_i / w_i of the nodes within the window around ``centre_m``; p^2 = c0 + c1 x + c2 y + c3 x^2 + c4 x y +
    c5 y^2 by least squares with weights w_i (the discrete form of the continuous L2 fit over the window, so the
    fitted value converges with the mesh as the integrals of the pressure do, and the nodes of small area, whose
    N_i / w_i scatter most, count as little as their area). Against :func:`peak_pressure` (a radius shrinking with
    the mesh): the value converges at the order of the pressure's weighted averages to the continuous fit over the
    window, whose own (model) error on a non-quadric top is O(size^4) and is estimated by the caller from a second
    window (fea.model, "Peak box"). The quadric family is closed under the axes' scaling, so an ellipse fits Hertz's
    p^2 (a quadric, Johnson 1985 eq 3.63) as exactly as a disc.

    Args:
        xy: (n, 2) node positions in contact, m. force, weight: (n,) N_i (N) and w_i > 0 (m^2).
        centre_m: (2,) first centre (the largest patch average), m.
        window_m: the disc's radius (a number), or the ellipse's semi-axes along x and y (a pair), m.

    Returns:
        (peak pressure in Pa, the fitted top in m), or None (fewer than 12 nodes, not a cap, top outside).
    """
    centre = np.asarray(centre_m, float)
    semi = np.broadcast_to(np.asarray(window_m, float), (2,))
    scaled = (xy - centre) / semi
    near = np.hypot(scaled[:, 0], scaled[:, 1]) <= 1.0
    if near.sum() < 12:
        return None
    fit = _cap_top(scaled[near], force[near] / weight[near], weight[near])
    return None if fit is None else (fit[0], centre + fit[1] * semi)


def edge_reconstructed_area(
    xy: np.ndarray,
    gap_m: np.ndarray,
    active: np.ndarray,
    n_rays: int = 720,
    samples_per_element: int = 8,
    skip: float = 2.0,
    points: int = 2,
    weight_m2: np.ndarray | None = None,
) -> dict:
    """Contact area inside the edge reconstructed from the deformed separation of the free face nodes (issue 22).

    Outside a non-conforming contact the deformed separation d grows as s^(3/2) with the distance s beyond the edge
    (Johnson 1985, sec. 3.4 and 4.2: Hertz, and near the edge any smooth non-conforming gap), so f = d^(2/3) is
    linear in s there. f is interpolated linearly over the Delaunay triangles of the face nodes (0 at the active
    nodes); along rays from the centroid of the active nodes, s1 is the first point in a triangle whose vertices are
    all free, f is sampled at s1 + skip h and one h further (h the median length of the face-mesh edges that join an
    active and a free node: the node spacing at the edge, half an element for P2), and the zero of the line through
    the two (or of the parabola through three, ``points`` 3) is the edge, clamped to the mixed triangles between the
    last all-active triangle and s1. The area is 1/2 sum r_e^2 dtheta over ``n_rays`` equal angles (a patch
    star-shaped about the centroid).

    Why ``skip`` 2 (benchmarks/results/fea_edge_area.md): the FE separation at the free nodes within about 1.5 h of
    the edge is too large (P2 on the Hertz circle at 4.5 elements per semi-axis: f 1.48 / 1.05 / 1.02 times Hertz's
    at 0-0.5 / 0.5-1 / 1-1.5 h), which pulls a zero extrapolated from there inwards (-2.5 % area); from 2 h on it is
    within 0.5 %. On Hertz's exact separation sampled at the same nodes every variant is within 0.2 % from 6.75
    elements per semi-axis on.

    Args:
        xy: (n, 2) face node positions of the full patch (mirrored for a quarter model), m.
        gap_m: (n,) deformed separation d_i, m (<= 0 or any value at the active nodes).
        active: (n,) bool, nodes in contact.
        weight_m2: (n,) lumped face weights, m^2 (optional): a region whose rays fail (fewer than 3 nodes, or a ray
            finds no all-active triangle before a free one: a region thinner than the triangles) then counts its
            nodal area instead (``nodal_fallback_m2``); without weights such a region makes the result nan.

    Returns:
        dict: area_m2 (nan when it fails), rays_clamped (fraction of rays whose zero fell outside the mixed
        triangles), rays_fallback (fraction with no usable pair of samples: edge put midway through the mixed
        triangles), element_size_m (the median length of the face-mesh edges that cross the contact edge).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import Delaunay, QhullError

    nan = float("nan")
    fail = {"area_m2": nan, "rays_clamped": nan, "rays_fallback": nan, "element_size_m": nan, "regions": 0}
    xy = np.asarray(xy, float)
    active = np.asarray(active, bool)
    gap = np.asarray(gap_m, float)
    first = _distinct_nodes(xy)
    xy, active, gap = xy[first], active[first], gap[first]
    weight = None if weight_m2 is None else np.asarray(weight_m2, float)[first]
    # a free node with d = 0 has no gap value (fea.solver: outside the sampled gap): unknown, not in contact
    f = np.where(active, 0.0, np.where(gap > 0, np.clip(gap, 0.0, None), np.nan) ** (2.0 / 3.0))
    if active.sum() < 3 or (~active).sum() < 3:
        return fail
    try:
        tri = Delaunay(xy)
    except QhullError:
        return fail
    simplices = tri.simplices
    pairs = np.concatenate([simplices[:, [0, 1]], simplices[:, [1, 2]], simplices[:, [2, 0]]])
    crossing = active[pairs[:, 0]] != active[pairs[:, 1]]
    if not crossing.any():
        return fail
    # face-mesh (Delaunay) edges that join an active and a free node: the node spacing at the edge
    h = float(np.median(np.hypot(*(xy[pairs[crossing, 0]] - xy[pairs[crossing, 1]]).T)))
    # separate contact regions (connected through active-active edges) get their own rays
    both = active[pairs[:, 0]] & active[pairs[:, 1]]
    graph = coo_matrix((np.ones(both.sum()), (pairs[both, 0], pairs[both, 1])), shape=(len(xy), len(xy)))
    _, label = connected_components(graph, directed=False)
    total, clamped, fallback, rays, regions, nodal = 0.0, 0.0, 0.0, 0, 0, 0.0
    for lab in np.unique(label[active]):
        member = active & (label == lab)
        out = None
        if member.sum() >= 3:
            out = _ray_edge_area(tri, f, active, xy[member], h, n_rays, samples_per_element, skip, points)
        if out is None:
            if weight is None:
                return {**fail, "element_size_m": h}
            nodal += float(weight[member].sum())
            continue
        total += out[0]
        clamped += out[1] * n_rays
        fallback += out[2] * n_rays
        rays += n_rays
        regions += 1
    if rays == 0:
        return {**fail, "element_size_m": h}
    return {
        "area_m2": total + nodal,
        "rays_clamped": clamped / rays,
        "rays_fallback": fallback / rays,
        "element_size_m": h,
        "regions": regions,
        "nodal_fallback_m2": nodal,
    }


def _ray_edge_area(tri, f, active, region_xy, h, n_rays, samples_per_element, skip, points):
    """(area, clamped fraction, fallback fraction) of one contact region by the rays of
    :func:`edge_reconstructed_area` from its centroid, or None (a ray finds no free triangle).
    """
    simplices = tri.simplices
    act_v = active[simplices]
    centre = region_xy.mean(axis=0)
    reach = float(np.hypot(*(region_xy - centre).T).max())
    step = h / samples_per_element
    s = np.arange(0.0, reach + 4.0 * h, step)
    theta = (np.arange(n_rays) + 0.5) * (2.0 * np.pi / n_rays)
    direction = np.column_stack([np.cos(theta), np.sin(theta)])
    ray_points = centre + s[None, :, None] * direction[:, None, :]  # (rays, samples, 2)
    flat = ray_points.reshape(-1, 2)
    simplex = tri.find_simplex(flat)

    def interpolate(p, simp):
        transform = tri.transform[np.maximum(simp, 0)]
        bary = np.einsum("nij,nj->ni", transform[:, :2], p - transform[:, 2])
        weights = np.column_stack([bary, 1.0 - bary.sum(axis=1)])
        return np.einsum("ni,ni->n", f[simplices[np.maximum(simp, 0)]], weights)

    inside = (simplex >= 0).reshape(n_rays, -1)
    all_active = np.where(simplex >= 0, act_v[np.maximum(simplex, 0)].all(axis=1), False).reshape(n_rays, -1)
    all_free = np.where(simplex >= 0, ~act_v[np.maximum(simplex, 0)].any(axis=1), False).reshape(n_rays, -1)
    idx = np.arange(len(s))
    # the first free point along the ray and the last all-active one before it (another region further out along
    # the ray is not this one's)
    first_free = np.argmax(all_free, axis=1)
    last_active = np.where(all_active & (idx[None, :] < first_free[:, None]), idx[None, :], -1).max(axis=1)
    has_free = all_free.any(axis=1) & (last_active >= 0)
    s0 = s[np.maximum(last_active, 0)]
    s1 = s[first_free]
    base = s1 + skip * h
    svals = [base + k * h for k in range(points)]
    fvals, ok = [], has_free & inside.any(axis=1)
    for sv in svals:
        pk = centre + sv[:, None] * direction
        simp = tri.find_simplex(pk)
        ok &= simp >= 0
        fvals.append(interpolate(pk, simp))
    f1, f2 = fvals[0], fvals[1]
    usable = ok & (f2 > f1) & (f1 >= 0)
    zero = base - f1 * h / np.where(usable, f2 - f1, 1.0)
    if points == 3:
        # the parabola through (0, f1), (h, f2), (2 h, f3) in t = s - base; its root nearer the line's
        f3 = fvals[2]
        c2 = (f3 - 2 * f2 + f1) / (2 * h * h)
        c1 = (f2 - f1) / h - c2 * h
        disc = c1 * c1 - 4 * c2 * f1
        good = usable & (disc >= 0) & (np.abs(c2) > 0)
        sq = np.sqrt(np.where(good, disc, 0.0))
        # root with t < 0 closest to 0: t = (-c1 + sq) / (2 c2) when c2 != 0 (stable form 2 f1 / (-c1 - sq))
        t = np.where(good, -2 * f1 / np.where(good, c1 + sq, 1.0), 0.0)
        zero = np.where(good, base + t, zero)
    edge = np.where(usable, zero, 0.5 * (s0 + s1))
    clamped = usable & ((edge < s0) | (edge > s1))
    edge = np.clip(edge, s0, s1)
    if not has_free.all():
        return None
    area = 0.5 * float(np.sum(edge**2)) * (2.0 * np.pi / n_rays)
    return area, float(clamped.mean()), float((~usable).mean())
