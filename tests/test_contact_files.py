"""Field files of contact runs (wheelrail.contact_files): NPZ and VTU per patch, read back by numpy, meshio, pyvista.

Physics checks against closed forms: the Hertz pressure written for an analytic model integrates to the
normal force (int p dA = P, Johnson 1985 eq 4.39-4.40) and its outline is Hertz's ellipse x^2/a^2 + y^2/b^2 = 1.
FASTSIM's traction field integrates to its creep force (to the O(dx) of the resampling the model documents).
"""

import json
import math

import numpy as np
import pytest

from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import Material
from wheelrail.cli import main
from wheelrail.contact_files import write_patch_files

STEEL = Material.from_young(210e9, 0.3, 0.3)
GEOMETRY = ContactGeometry.quadric(0.46, 0.3)
FORCE_N = 1e4


def _solve(method, creepage=None, options=None):
    creepage = Creepage() if creepage is None else creepage
    return get_model(method).solve(GEOMETRY, creepage, STEEL, normal_force_N=FORCE_N, options=options)


def test_hertz_pressure_file_integrates_to_the_force_and_outlines_the_ellipse(tmp_path):
    result = _solve("hertz")
    files = write_patch_files(tmp_path, "single-0", GEOMETRY, result)
    assert files["source"] == "hertz-closed-form"
    data = np.load(tmp_path / files["npz"])
    x, y, p = data["x_m"], data["y_m"], data["pressure_Pa"]
    assert p.shape == (len(y), len(x))
    total = np.trapezoid(np.trapezoid(p, x, axis=1), y)
    assert total == pytest.approx(FORCE_N, rel=0.01)
    assert p.max() == pytest.approx(result.max_pressure_Pa, rel=0.01)
    a, b = result.semi_axis_long_m, result.semi_axis_lat_m
    outline = data["outline_m"]
    outline = outline[np.isfinite(outline).all(axis=1)]
    radius = np.hypot(outline[:, 0] / a, outline[:, 1] / b)
    spacing = (x[1] - x[0]) / min(a, b)
    assert np.abs(radius - 1.0).max() < spacing
    assert str(data["units"]).count("Pa") >= 1 and str(data["method"]) == "hertz"


def test_fastsim_files_hold_traction_slip_and_adhesion(tmp_path):
    result = _solve("fastsim", Creepage(1e-3, 0.0, 0.0), {"nx": 30, "ny": 20})
    files = write_patch_files(tmp_path, "single-0", GEOMETRY, result)
    assert files["source"] == "model"
    data = np.load(tmp_path / files["npz"])
    for name in ("traction_long_Pa", "traction_lat_Pa", "slip_m_per_s", "in_slip", "in_adhesion", "in_contact"):
        assert data[name].shape == data["pressure_Pa"].shape
    assert data["in_adhesion"].any() and data["in_slip"].any()  # partial slip at this creepage
    assert not (data["in_adhesion"] & data["in_slip"]).any()
    units, dims = json.loads(data["units"][()]), json.loads(data["dims"][()])  # parsed by a reader, not eval
    assert units["slip_m_per_s"] == "m/s" and units["pressure_Pa"] == "Pa" and units["in_slip"] == "1"
    assert dims["pressure_Pa"] == ["y", "x"] and dims["x_m"] == ["x"]
    x, y = data["x_m"], data["y_m"]
    cell = (x[1] - x[0]) * (y[1] - y[0])
    fx = data["traction_long_Pa"].sum() * cell
    assert fx == pytest.approx(result.creep_force_long_N, rel=0.1)


@pytest.mark.parametrize("method", ["hertz", "fastsim"])
def test_vtu_files_read_in_meshio_and_pyvista(tmp_path, method):
    import meshio
    import pyvista

    result = _solve(method, Creepage(1e-3, 0.0, 0.0))
    files = write_patch_files(tmp_path, "single-0", GEOMETRY, result)
    data = np.load(tmp_path / files["npz"])
    for key in ("vtu", "outline_vtu"):
        mesh = meshio.read(tmp_path / files[key])
        grid = pyvista.read(tmp_path / files[key])
        assert grid.n_points == len(mesh.points) > 0
    surface = meshio.read(tmp_path / files["vtu"])
    assert surface.cells[0].type == "quad"
    np.testing.assert_allclose(surface.point_data["pressure_Pa"], data["pressure_Pa"].ravel())
    grid = pyvista.read(tmp_path / files["vtu"])
    np.testing.assert_allclose(grid.point_data["pressure_Pa"], data["pressure_Pa"].ravel())
    if method == "fastsim":
        assert "traction_long_Pa" in grid.point_data and "in_adhesion" in grid.point_data


def test_cli_contact_writes_fields_plot_and_diagnostics(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["contact", "hertz-quadric", "--method", "auto", "--plot", "--out", str(out)])
    capsys.readouterr()
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    (patch,) = summary["patches"]
    assert patch["diagnostics"]["selected_model"] == patch["model"]
    assert patch["diagnostics"]["selection_reason"]
    (files,) = summary["field_files"]
    for key in ("npz", "vtu", "outline_vtu"):
        assert (out / files[key]).stat().st_size > 0
    assert summary["plots"] and (out / summary["plots"][0]).stat().st_size > 0


def test_cli_hertz_plot_draws_the_ellipse(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["contact", "hertz-quadric", "--method", "hertz", "--plot", "--out", str(out)]) == 0
    capsys.readouterr()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["plots"] == ["fields-single-0.png"]
    assert summary["field_files"][0]["source"] == "hertz-closed-form"
    # wall_time_s is the solve (Hertz: well under a millisecond), not the imports and kernel loading before it
    assert summary["wall_time_s"] < 0.05 and summary["setup_s"] > summary["wall_time_s"]
    assert math.isfinite(summary["patches"][0]["semi_axis_long_m"])
