"""Causes of the bench slowdown after issue 10's merge, each fixed at its cause (regression tests).

* A frictionless model (``fea``: creep forces None) transmits no tangential force; the wheelset case's vertical
  load was NaN with it (the equilibrium then ran its 40 iterations and failed).
* ``fea.postprocess.pressure_on_grid`` locates grid points by qhull's brute force; checked against scipy's
  ``LinearNDInterpolator`` (an independent implementation of the same piecewise-linear interpolation).
* The bench solves wheelset cases with the case's own force tolerance for every model: the remeshed FEA force
  scatters by +-3 % on a22-flange-root (0.2 % took 54 evaluations there), and the equilibrium now accepts the load
  at the FEA's stated force error (tests/test_fea_wheelset_tolerance.py), no bench-specific tolerance.
* The bench's FEA computes no subsurface stresses (the bench reports none; worn-wheel-worn-rail n3: 49 s -> 9 s
  for the same 6 evaluations).
"""

import dataclasses
import math

import numpy as np
import pytest

from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.contact.wheelset_case import PatchSolution


def _result(fx, fy, n):
    return ContactResult(
        method="x", success=True, status="ok", message="", normal_force_N=n, creep_force_long_N=fx,
        creep_force_lat_N=fy,
    )  # fmt: skip


def test_frictionless_patch_carries_its_normal_force_only():
    d = 0.3  # contact angle: normal tilted about x
    frame = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(d), -math.sin(d)], [0.0, -math.sin(d), -math.cos(d)]])
    geometry = dataclasses.replace(ContactGeometry.quadric(0.46, 0.3), frame=frame)
    creepage = Creepage(0.0, 0.0, 0.0)
    patch = PatchSolution("right", geometry, creepage, _result(None, None, 1.0e4))
    assert np.allclose(patch.force_main_N, 1.0e4 * frame[:, 2])
    assert patch.vertical_force_N == pytest.approx(1.0e4 * math.cos(d))  # closed form: N cos(delta)
    with_creep = PatchSolution("right", geometry, creepage, _result(0.0, 500.0, 1.0e4))
    assert with_creep.vertical_force_N == pytest.approx(1.0e4 * math.cos(d) + 500.0 * math.sin(d))


def test_pressure_on_grid_equals_scipy_linear_interpolation_on_a_graded_mesh():
    from scipy.interpolate import LinearNDInterpolator

    from fea.postprocess import pressure_on_grid

    # graded nodes as on an FE contact face: fine near 0, coarse outside
    s = np.concatenate([-np.geomspace(0.065, 5e-4, 12), np.linspace(-4e-4, 4e-4, 9), np.geomspace(5e-4, 0.065, 12)])
    xx, yy = np.meshgrid(s, 0.5 * s)
    xy = np.column_stack([xx.ravel(), yy.ravel()])
    # jitter (1 % of the finest spacing) so that the Delaunay triangulation is unique (no co-circular points)
    xy = xy + np.random.default_rng(1).uniform(-1e-6, 1e-6, xy.shape)
    pressure = np.clip(1e9 * (1.0 - (xy[:, 0] / 2e-3) ** 2 - (xy[:, 1] / 1e-3) ** 2), 0.0, None)
    x_m, y_m = np.linspace(-4e-3, 4e-3, 64), np.linspace(-2e-3, 2e-3, 64)
    grid, in_contact = pressure_on_grid(xy, pressure, x_m, y_m)
    gx, gy = np.meshgrid(x_m, y_m)
    reference = np.clip(LinearNDInterpolator(xy, pressure, fill_value=0.0)(gx, gy), 0.0, None)
    assert in_contact.any() and not in_contact.all()
    assert np.allclose(grid, np.where(in_contact, reference, 0.0), rtol=0.0, atol=1e-6 * pressure.max())


def test_bench_leaves_the_force_tolerance_to_the_case(monkeypatch):
    import rigid_dynamics.contact.wheelset_case as wc
    from comparisons import bench
    from wheelrail.named_cases import load_named_case

    seen = {}

    def fake(wheelset, material, model, options=None):
        seen[model] = options
        raise RuntimeError("stop")

    monkeypatch.setattr(wc, "solve_wheelset_case", fake)
    case = load_named_case("a22-tread").case
    for model in ("fea", "bem"):
        with pytest.raises(RuntimeError):
            bench.solve_contact_case(case, model, {})
    assert "force_tolerance" not in seen["fea"] and "force_tolerance" not in seen["bem"]


def test_bench_fea_runs_skip_the_subsurface_stresses():
    from comparisons import bench
    from fea.model import FeaOptions

    for _label, options in bench.RESOLUTIONS["fea"]:
        assert FeaOptions.from_mapping(options).stresses is False
        assert FeaOptions.from_mapping(options).mesh_tolerance is not None  # every FEA row states its error
