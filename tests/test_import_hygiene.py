"""The numeric core stays light: importing it pulls in no mesher, FE library or plotting package."""

import subprocess
import sys

HEAVY = (
    "gmsh",
    "dolfinx",
    "petsc4py",
    "mpi4py",
    "pyvista",
    "matplotlib",
    "ufl",
    "basix",
    "meshio",
    "dask",
    "distributed",
    "pandas",
    "pyarrow",
    "contourpy",
)

CODE = """
import sys, importlib, pkgutil
import rigid_dynamics
for info in pkgutil.walk_packages(rigid_dynamics.__path__, "rigid_dynamics."):
    importlib.import_module(info.name)
import fea.model, meshing, wheelrail.cli, wheelrail.cases, wheelrail.scenes
from rigid_dynamics.contact.registry import get_model
for name in ("hertz", "linear", "vermeulen-johnson", "fastsim", "bem", "auto", "fea"):
    get_model(name)
print(",".join(sorted(m for m in sys.modules if m.split(".")[0] in {heavy})))
"""


def test_core_and_front_import_no_heavy_package():
    done = subprocess.run(
        [sys.executable, "-c", CODE.replace("{heavy}", repr(set(HEAVY)))],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=str(__import__("pathlib").Path(__file__).resolve().parents[1]),
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "", f"heavy modules imported: {done.stdout.strip()}"
