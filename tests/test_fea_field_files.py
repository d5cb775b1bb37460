"""The FEA field file (fea_solution.vtu) opens in meshio and pyvista with the documented fields and units.

The values are checked against the solution they come from (regression of the file writer against the
model's own result: the largest von Mises in the file equals ``extra['max_von_mises_Pa']``), and the
file of a 2-rank run against the 1-rank file (same grid, same fields up to the solver tolerance).
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fea.model import FeaModel
from fea.output import FIELD_UNITS
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import Material

pytestmark = pytest.mark.fea

ROOT = Path(__file__).resolve().parents[1]
STEEL = Material.from_young(210e9, 0.3, 0.3)
OPTIONS = {"quick": True, "elements_per_semi_axis": 3, "mesh_tolerance": None}
"""One quick mesh: the claims here are the file's contents (the refinement series writes its final level through
the same writer; its accuracy is checked in test_fea_contact.py and test_fea_refinement.py)."""


@pytest.fixture(scope="module")
def fea_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("fea1")
    result = FeaModel().solve(
        ContactGeometry.quadric(0.46, 0.15),
        Creepage(),
        STEEL,
        normal_force_N=1e5,
        options={**OPTIONS, "output_dir": str(out)},
    )
    return result, Path(result.extra["files"]["vtu"])


def test_vtu_reads_in_meshio_with_units_in_names(fea_run):
    import meshio

    result, path = fea_run
    assert result.success and path.is_file() and path.suffix == ".vtu"
    mesh = meshio.read(path)
    assert [block.type for block in mesh.cells] == ["tetra"]
    n = len(mesh.points)
    for name in ("displacement_m", "stress_Pa", "principal_stress_Pa", "von_mises_Pa", "max_shear_Pa"):
        assert name in FIELD_UNITS
        assert mesh.point_data[name].shape[0] == n
    assert mesh.point_data["stress_Pa"].shape == (n, 9)
    # the file holds the solution the model reported on (the lower block's maximum is the global one here)
    assert mesh.point_data["von_mises_Pa"].max() == pytest.approx(result.extra["max_von_mises_Pa"], rel=1e-9)
    # the displacement is a real field: the block is pressed down near the contact (z down is -, + approach)
    assert np.abs(mesh.point_data["displacement_m"]).max() > 1e-6


def test_vtu_reads_in_pyvista_off_screen(fea_run):
    import pyvista

    _, path = fea_run
    grid = pyvista.read(path)
    assert grid.n_points > 0 and grid.n_cells > 0
    assert set(grid.point_data.keys()) >= {"displacement_m", "stress_Pa", "von_mises_Pa"}
    vm = np.asarray(grid.point_data["von_mises_Pa"])
    assert np.isfinite(vm).all() and vm.max() > 1e8
    # a slice across the quarter block (what a 3-D stress view shows) carries the stress field
    cut = grid.slice(normal="y", origin=grid.center)
    assert cut.n_points > 0 and np.asarray(cut.point_data["von_mises_Pa"]).max() > 0


def _mpiexec():
    candidate = Path(sys.executable).parent / "mpiexec"
    return str(candidate) if candidate.exists() else shutil.which("mpiexec")


@pytest.mark.skipif(_mpiexec() is None, reason="mpiexec not found")
def test_two_ranks_write_the_same_grid(fea_run, tmp_path, mpi_lock):
    import meshio

    script = (
        "import dolfinx_solver\n"
        "from fea.model import FeaModel\n"
        "from rigid_dynamics.contact.types import ContactGeometry, Creepage\n"
        "from rigid_dynamics.materials import Material\n"
        "FeaModel().solve(ContactGeometry.quadric(0.46, 0.15), Creepage(), Material.from_young(210e9, 0.3, 0.3),"
        f" normal_force_N=1e5, options={{**{OPTIONS!r}, 'output_dir': {str(tmp_path)!r}}})\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    out = subprocess.run(
        [_mpiexec(), "-n", "2", sys.executable, "-c", script], capture_output=True, text=True, timeout=240, env=env
    )
    assert out.returncode == 0, out.stderr[-2000:]
    one = meshio.read(fea_run[1])
    two = meshio.read(tmp_path / "fea_solution.vtu")
    assert len(two.points) == len(one.points) and len(two.cells[0].data) == len(one.cells[0].data)
    # vertices are numbered differently: compare sorted values
    for name in ("von_mises_Pa", "max_shear_Pa"):
        np.testing.assert_allclose(
            np.sort(two.point_data[name]),
            np.sort(one.point_data[name]),
            rtol=1e-5,
            atol=1e-6 * one.point_data[name].max(),
        )
