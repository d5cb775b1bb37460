"""The contact area's edge error: where the contact edge lies inside the cells that hold it (the BEM's element count).

A discretised normal problem states its contact as a set of cells (the BEM: elements whose centre carries
pressure) or of nodes (the FEA: active nodes, each with its lumped face area). Its area, the count of the cells or
the sum of the nodes' areas, puts the edge half a cell beyond the last cell in contact, wherever the true edge lies
between that cell and the next one out. The edge is therefore known only to within a cell, and the area only to
within about perimeter x h / 2; and the count does not converge smoothly: as the grid is refined the edge crosses
cell centres at different places along the perimeter, so the area of successive grids moves up and down by a
fraction of that (the demo's peak patch, BEM on a sampled gap: 193.0, 191.4, 189.9, 189.7, 189.5 mm2 on
32 ... 512 elements a side, the first two steps equal, the next ten times smaller: no power law).

Where in the cell the edge lies follows from the pressure itself: near the edge of a non-conforming contact the
pressure falls as the square root of the distance to the edge (Johnson 1985, sec. 3.4 and eq 3.63 for Hertz; any
smooth gap whose contact is not conforming), so p^2 is linear in that distance, and the zero of p^2 extrapolated
from the last cells in contact towards the first one out is where the edge is (a parabola through the last three
cells, exact for Hertz's p^2 along a row; a line through the last two where there are only two). The area inside
those zeros (the reconstructed area, :func:`grid_edge_area`) differs from the count by the edge's position within
its cells (the BEM's element count: the pressure of an element is its collocation value at the centre; the FEA's
nodal pressures N_i / w_i at the last active nodes are not, their lumped areas straddle the edge: 0.89-0.97 of
Hertz's at 4-9 elements per semi-axis, so the FEA's nodal area is estimated otherwise, fea.refinement), and

    e_A = |A - A_edge(h)| + |A_edge(h) - A_edge(r h)| / (r - 1)

times a factor of safety ``EDGE_SAFETY``, is the estimate of the count's error: the first term the edge within its
cells on this grid, the second the reconstruction's own error (Richardson at first order, ``RECONSTRUCTION_ORDER``,
from its change since the grid r times as coarse: the BEM's companion, r = 2). The reconstruction is made along the
rows and along the columns (the row-wise sum is a midpoint rule across the rows with sub-cell extents along them;
the two are averaged).
"""

from __future__ import annotations

import numpy as np

RECONSTRUCTION_ORDER = 1.0
"""Order of the reconstructed area's own error in Richardson's term of :func:`edge_error`. The parabola through the
last three cells is exact for Hertz's p^2 along a row, so the reconstruction should converge faster than first order
(the line alone: 1.69, 0.55, 0.14 % off on Hertz's pressure sampled at 16, 32, 64 cells, order 1.6-2.0); but at
order 2 the estimate fell short of the count's error on that sampled pressure at 24 cells (2.77 % stated, 2.94 %
true: the reconstruction is not yet asymptotic at 10 cells per semi-axis), so order 1, which bracketed every case
measured (benchmarks/results/area_edge_error_findings.md)."""
EDGE_SAFETY = 1.25
"""Factor of safety on :func:`edge_error` (Roache's 1.25 for a grid-convergence index whose order is known): on the
Hertz closed forms the bare estimate came within 2 % below the true error at 80 and 160 elements (the
reconstruction's residual error and the count's error have one sign there; benchmarks/results/area_edge_error.md)."""


def _row_edges(squared: np.ndarray, contact: np.ndarray, h: float) -> float:
    """Sum over the rows (axis 1) of the edge's offset from the cell-count edge: the area (per unit row width) the
    sub-cell edge adds to the count. ``squared``: p^2 (0 out of contact).
    """
    total = 0.0
    for step in (1, -1):
        q = squared if step == 1 else squared[:, ::-1]
        c = contact if step == 1 else contact[:, ::-1]
        face = c.copy()
        face[:, :-1] &= ~c[:, 1:]  # in contact, the next cell along the row out (or the grid's end)
        rows, cols = np.nonzero(face)
        q0 = q[rows, cols]
        q1 = np.where(cols >= 1, q[rows, np.maximum(cols - 1, 0)], 0.0)
        q2 = np.where(cols >= 2, q[rows, np.maximum(cols - 2, 0)], 0.0)
        has1 = (cols >= 1) & c[rows, np.maximum(cols - 1, 0)]
        has2 = has1 & (cols >= 2) & c[rows, np.maximum(cols - 2, 0)]
        offset = np.full(len(q0), 0.5 * h)  # one cell: nothing better than "within the next cell"
        # two cells: the line through (-h, q1), (0, q0); its zero at h q0 / (q1 - q0) beyond the last centre
        falling = has1 & (q1 > q0)
        offset = np.where(falling, h * q0 / np.where(falling, q1 - q0, 1.0), offset)
        # three cells: the parabola through (-2h, q2), (-h, q1), (0, q0) (exact for Hertz's p^2 along a row)
        c2 = (q2 - 2 * q1 + q0) / (2 * h * h)
        c1 = (q0 - q1) / h + c2 * h
        disc = c1 * c1 - 4 * c2 * q0
        curved = has2 & falling & (c2 < 0) & (disc >= 0)
        root = np.where(curved, (-c1 - np.sqrt(np.where(curved, disc, 0.0))) / np.where(curved, 2 * c2, 1.0), offset)
        offset = np.where(curved & (root >= 0) & (root <= h), root, offset)
        total += float(np.sum(np.clip(offset, 0.0, h) - 0.5 * h))
    return total


def grid_edge_area(pressure: np.ndarray, contact: np.ndarray, dx: float, dy: float) -> float:
    """Reconstructed contact area of a regular grid (module docstring): cells (ny, nx) of dx along axis 1 and dy
    along axis 0, ``contact`` the cells in contact, ``pressure`` their pressure. m^2 when dx, dy are in m.
    """
    contact = np.asarray(contact, bool)
    squared = np.where(contact, np.asarray(pressure, float), 0.0) ** 2
    count = float(contact.sum()) * dx * dy
    rows = count + dy * _row_edges(squared, contact, dx)
    columns = count + dx * _row_edges(squared.T, contact.T, dy)
    return 0.5 * (rows + columns)


def edge_error(area: float, edge: float, edge_coarse: float | None, ratio: float = 2.0) -> float:
    """The estimate e_A = |A - A_edge(h)| + |A_edge(h) - A_edge(r h)| / (r^p - 1) of the module docstring (absolute;
    r = 2 the BEM's companion; p ``RECONSTRUCTION_ORDER``), without ``EDGE_SAFETY``.
    """
    if edge_coarse is None:
        return abs(area - edge)
    return abs(area - edge) + abs(edge - edge_coarse) / (ratio**RECONSTRUCTION_ORDER - 1.0)
