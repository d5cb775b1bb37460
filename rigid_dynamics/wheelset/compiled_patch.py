"""The sampled patch in the compiled loop: per candidate and right-hand side, the undeformed distance on a grid that
follows the patch, for the compiled laws that solve a gap (compiled_laws.LAW_KPEC).

* Search mode (layout.GEOMETRY_SEARCH) with ``patch_sampled`` (DynamicsScene.patch_geometry = "sampled"): the gap
  along the normal is sampled from the real surfaces (the search's Hermite tables and closed-form irregularities)
  by contact._gap_kernels, the one sampler of the static wheelset case (search._gap_at), on the box of
  search._fitted_field (the rigid overlap plus ``kpec_margin`` of its extent and two spacings each side; first box
  +-1.6 times the quadric's overlap semi-axes) with ``kpec_nx`` x ``kpec_ny`` points, and the ellipticity residual
  (search.ellipticity_error) of that field against the quadric of the patch's curvatures is computed.
* Otherwise (``patch_geometry = "ellipse"``, the tables, a geometry given by Python): the quadric gap
  A x'^2 + B y'^2 - q sampled on the same number of points over the quadric's overlap box with the same margin
  (compiled_laws._kpec_law fills it): the multi-Hertzian patch, so the difference is measurable.

The contact frame is search._patch's (e_x = main x projected on the contact plane, e_y = n x e_x); the patch centre
is the candidate's contact point (the midpoint of the wheel and rail points). The wheel parameters of the point:
y_d from the geometry row, alpha from the wheel point (C_D^T (point - centre)). Everything runs in the workspace's
arrays (:class:`PatchScratch`), no allocation per call.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact._gap_kernels import (
    BOX_X_HI,
    BOX_X_LO,
    BOX_Y_HI,
    BOX_Y_LO,
    COLUMN_SCRATCH,
    GapPatch,
    GapSurfaces,
    GridFit,
    curvature_change,
    ellipticity_residual,
    fitted_grid,
    second_patch_nearness,
    warm_grid,
)
from rigid_dynamics.wheelset.compiled_search import (
    S_NEWTON,
    S_RLO,
    S_RLOW,
    S_RSIGN,
    S_RSTEP,
    S_WLOW,
    S_WSTEP,
    S_YLO,
)
from rigid_dynamics.wheelset.layout import (
    G_APPROACH,
    G_CURVATURE_LAT,
    G_CURVATURE_LONG,
    G_ELLIPSE_ANGLE,
    G_LEVER,
    G_NORMAL,
    G_WHEEL_LATERAL,
)
from rigid_dynamics.wheelset.state import X, Y, Z
from rigid_dynamics.wheelset.track import rail_lateral_under_wheel, rail_under_wheel

FIRST_BOX_SCALE = 1.6  # search._patch: the first box is +-1.6 times the quadric's overlap semi-axes
MIN_HALF_SIZE_M = 1.0e-3  # search.DEFAULT_OPTIONS["field_min_half_size_m"]
FAR_GAP_M = 1.0  # a grid point whose normal misses a surface: far from contact (the static KpecModel's stand-in)


class PatchScratch(NamedTuple):
    """The sampled patches of a right-hand side and the gap law's scratch: per candidate the gap (ncand, ny, nx), m,
    its grid xs (ncand, nx), ys (ncand, ny), m, the ellipticity residual (ncand,), auto's other two geometric
    features (ncand,: contact.auto's curvature change and second-patch nearness, _gap_kernels.curvature_change and
    second_patch_nearness) and whether it was sampled (ncand,: 1 sampled, 0 the quadric); the law's fields
    (ny, nx): pressure, in_contact, tractions t_x, t_y, in_slip; the rows' first and last element in contact (ny,);
    per candidate the last sampled box (ncand, 4: x_lo, x_hi, y_lo, y_hi, m; NaN: none); the sampler's column
    scratch (nx, COLUMN_SCRATCH: _gap_kernels.sample_grid).
    """

    gap: np.ndarray
    xs: np.ndarray
    ys: np.ndarray
    residual: np.ndarray
    curvature_change: np.ndarray
    nearness: np.ndarray
    sampled: np.ndarray
    pressure: np.ndarray
    contact: np.ndarray
    tx: np.ndarray
    ty: np.ndarray
    slip: np.ndarray
    first: np.ndarray
    last: np.ndarray
    box: np.ndarray
    columns: np.ndarray


@njit(cache=True)
def patch_scratch(par, ncand):
    """A :class:`PatchScratch` for ncand candidates at the run's grid (kpec_nx x kpec_ny; 2 x 2 when the law
    solves no gap).
    """
    nx, ny = max(int(par.kpec_nx), 2), max(int(par.kpec_ny), 2)
    return PatchScratch(
        np.zeros((ncand, ny, nx)), np.zeros((ncand, nx)), np.zeros((ncand, ny)), np.full(ncand, np.nan),
        np.zeros(ncand), np.zeros(ncand), np.zeros(ncand), np.zeros((ny, nx)), np.zeros((ny, nx), np.bool_),
        np.zeros((ny, nx)), np.zeros((ny, nx)), np.zeros((ny, nx), np.bool_), np.zeros(ny, np.int64),
        np.zeros(ny, np.int64), np.full((ncand, 4), np.nan), np.zeros((nx, COLUMN_SCRATCH)),
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def _side_centre(y, par, side, centre):
    """The wheelset centre the search used for this side (raised by the elastic track's rail deflection and moved
    by minus its lateral displacement: compiled_search.search_geometry_on_track) into centre (3,).
    """
    centre[0], centre[1], centre[2] = y[X], y[Y], y[Z]
    if par.elastic_track > 0:
        centre[1] -= rail_lateral_under_wheel(par, y, side)[0]
        centre[2] -= rail_under_wheel(par, y, side)[0]


@njit(cache=True, _nrt=False)
def sample_candidates(y, run, cg, field, centre):
    """The sampled gap, its ellipticity residual and auto's other geometric features of every candidate in contact
    (q > 0) into ``field``
    (:class:`PatchScratch`) at the state y, from the search's surfaces (run.search: its tables, irregularity rows
    and the rotation of this evaluation); centre: a scratch 3-vector. Returns the number of grid samplings.
    """
    search, par = run.search, run.par
    sp, tabs, irrs, rot = search.sp, search.tabs, search.irrs, search.rot
    total = 0
    for c in range(cg.shape[0]):
        g = cg[c]
        q = g[G_APPROACH]
        field.sampled[c] = 0.0
        field.residual[c] = np.nan
        field.curvature_change[c] = field.nearness[c] = 0.0
        if not q > 0.0:
            field.box[c, :] = np.nan
            continue
        s = run.sides[c]
        surf = GapSurfaces(
            (sp[s, S_WLOW], sp[s, S_WSTEP], tabs[2 * s][0], tabs[2 * s][1], tabs[2 * s][2]),
            (sp[s, S_RLOW], sp[s, S_RSTEP], tabs[2 * s + 1][0], tabs[2 * s + 1][1], tabs[2 * s + 1][2]),
            irrs[2 * s], irrs[2 * s + 1], sp[s, S_RSIGN : S_RSIGN + 2], sp[s, S_YLO : S_YLO + 2],
            sp[s, S_RLO : S_RLO + 2],
        )  # fmt: skip
        _side_centre(y, par, s, centre)
        n0, n1, n2 = g[G_NORMAL], g[G_NORMAL + 1], g[G_NORMAL + 2]
        e0, e1, e2 = 1.0 - n0 * n0, -n0 * n1, -n0 * n2
        norm = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        e0, e1, e2 = e0 / norm, e1 / norm, e2 / norm
        f0, f1, f2 = n1 * e2 - n2 * e1, n2 * e0 - n0 * e2, n0 * e1 - n1 * e0
        # lever: from the search's centre of this side (the levers are those of that pose)
        l0, l1, l2 = g[G_LEVER], g[G_LEVER + 1], g[G_LEVER + 2]
        xd0 = rot[0, 0] * l0 + rot[1, 0] * l1 + rot[2, 0] * l2
        xd2 = rot[0, 2] * l0 + rot[1, 2] * l1 + rot[2, 2] * l2
        patch = GapPatch(
            rot, centre, (centre[0] + l0, centre[1] + l1, centre[2] + l2), (e0, e1, e2), (f0, f1, f2), (n0, n1, n2),
            math.atan2(xd2, xd0), g[G_WHEEL_LATERAL], int(sp[s, S_NEWTON]),
        )  # fmt: skip
        ca, cb = g[G_CURVATURE_LONG], g[G_CURVATURE_LAT]
        fit = GridFit(FIRST_BOX_SCALE * math.sqrt(q / ca), FIRST_BOX_SCALE * math.sqrt(q / cb), par.kpec_margin,
                      MIN_HALF_SIZE_M)  # fmt: skip
        gap, xs, ys, box = field.gap[c], field.xs[c], field.ys[c], field.box[c]
        # the last box of this candidate when it still holds the overlap as the fitted box would (one sampling;
        # shrunk as fitted_grid's last step when too large: two), else the fitted box from the quadric's start
        # (2-3 samplings)
        warm = warm_grid(surf, patch, box, par.kpec_margin, xs, ys, gap, field.columns)
        if warm > 0:
            total += warm
        else:
            total += 1 + fitted_grid(surf, patch, fit, xs, ys, gap, field.columns)
        box[BOX_X_LO], box[BOX_X_HI], box[BOX_Y_LO], box[BOX_Y_HI] = xs[0], xs[-1], ys[0], ys[-1]
        angle = g[G_ELLIPSE_ANGLE]
        if not math.isfinite(angle):
            angle = 0.0
        field.residual[c] = ellipticity_residual(xs, ys, gap, (ca, cb, angle), q)
        field.curvature_change[c] = curvature_change(xs, ys, gap, ca, cb)
        field.nearness[c] = second_patch_nearness(ys, gap)
        for j in range(gap.shape[0]):
            for i in range(gap.shape[1]):
                if not math.isfinite(gap[j, i]):
                    gap[j, i] = FAR_GAP_M
        field.sampled[c] = 1.0
    return total
