"""The numeric core stays light: importing it pulls in no mesher, FE library or plotting package."""

import subprocess
import sys

import pytest


def _python(code: str, *args: str, timeout: float = 300):
    """``python -c code args...`` in a fresh interpreter from the repository's root (what a user's process
    imports and loads); the completed process, output as text."""
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=str(__import__("pathlib").Path(__file__).resolve().parents[1]),
    )


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
    done = _python(CODE.replace("{heavy}", repr(set(HEAVY))))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "", f"heavy modules imported: {done.stdout.strip()}"


CONTACT_CODE = """
import contextlib, io, sys
from wheelrail.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    code = main(["contact", "hertz-quadric", "--json"{method}])
heavy = {heavy}
print(code, ",".join(sorted(m for m in sys.modules if m.split(".")[0] in heavy or m in heavy)))
"""

CONTACT_HEAVY = set(HEAVY) | {"meshio", "h5py", "scipy.interpolate", "scipy.optimize", "scipy.integrate"}
CONTACT_HEAVY |= {"scipy.sparse", "scipy.stats", "scipy.signal", "scipy.ndimage"}
CONTACT_HEAVY |= {
    "rigid_dynamics.wheelset",
    "rigid_dynamics.contact.fastsim",
    "rigid_dynamics.contact.wheelset_case",
    "rigid_dynamics.contact.semi_hertzian",
    "wheelrail.scenes",
}
"""What ``wheelrail contact <quadric case> --json`` (no output folder, no plots) must not import: the files' and
plots' libraries, the FE stack, and the scipy packages the contact models used to import at module level (PCHIP of
Kalker's table, the Hertz root) -- a fifth to a third of the command's start-up (benchmarks/results/startup.md) --
nor scipy's other packages, nor the dynamics, FASTSIM, the wheelset-case search, the semi-Hertzian models or the
scenes: none of them is used by a quadric case solved by hertz, bem, or auto choosing bem."""


@pytest.mark.parametrize("method", [None, "hertz", "bem"])
def test_contact_json_imports_no_heavy_module(method):
    """``wheelrail contact hertz-quadric --json`` (auto, which chooses bem here; hertz; bem) imports none of
    ``CONTACT_HEAVY``."""
    extra = "" if method is None else f', "--method", "{method}"'
    done = _python(CONTACT_CODE.replace("{method}", extra).replace("{heavy}", repr(CONTACT_HEAVY)))
    assert done.returncode == 0, done.stderr
    code, _, imported = done.stdout.strip().partition(" ")
    assert code == "0", done.stdout
    assert imported == "", f"heavy modules imported by wheelrail contact --json: {imported}"


NO_KERNEL_METHODS = {"hertz": "0", "linear": "1", "vermeulen-johnson": "0"}
"""Methods whose ``wheelrail contact <quadric case>`` run needs no compiled kernel, with the command's exit status
(linear: 1, its ``warning`` -- full adhesion past the friction bound on this case): they must not import numba
(its import and CPU target cost 0.6-0.8 s CPU, benchmarks/results/startup.md; the loops of hertz.py, kalker.py,
linear.py and vermeulen_johnson.py run as Python for one patch, rigid_dynamics/contact/lazy_kernels.py)."""


@pytest.mark.parametrize("method", NO_KERNEL_METHODS)
def test_contact_json_without_kernels_imports_no_numba(method):
    """``wheelrail contact hertz-quadric --method <hertz, linear, vermeulen-johnson> --json`` imports neither numba
    nor llvmlite, nor any of ``CONTACT_HEAVY``."""
    heavy = CONTACT_HEAVY | {"numba", "llvmlite"}
    extra = f', "--method", "{method}"'
    done = _python(CONTACT_CODE.replace("{method}", extra).replace("{heavy}", repr(heavy)))
    assert done.returncode == 0, done.stderr
    code, _, imported = done.stdout.strip().partition(" ")
    assert code == NO_KERNEL_METHODS[method], done.stdout
    assert imported == "", f"modules imported by wheelrail contact --method {method} --json: {imported}"


def test_fastsim_choices_written_in_models_agree_with_fastsim():
    """models.py writes FASTSIM's option choices itself (so that it need not import the FASTSIM kernels); they are
    fastsim.py's."""
    from rigid_dynamics.contact import fastsim, models

    assert models.TRACTION_BOUNDS == fastsim.TRACTION_BOUNDS
    assert models.FLEXIBILITIES == fastsim.FLEXIBILITIES


AUTO_ANALYTIC_CODE = """
import contextlib, io, json, sys
from pathlib import Path
from wheelrail.cli import main
text = Path("wheelrail/cases/hertz-quadric.toml").read_text()
for old, new in (("spin_creepage_1_per_m = 0.1", "spin_creepage_1_per_m = 0.0"), ("creepage_long = 0.001",
                 "creepage_long = 0.0001"), ("creepage_lat = -0.0005", "creepage_lat = -0.00005")):
    assert old in text, old
    text = text.replace(old, new)
Path(sys.argv[1]).write_text(text)
out = io.StringIO()
with contextlib.redirect_stdout(out):
    code = main(["contact", sys.argv[1], "--json"])
print(code, json.loads(out.getvalue())["patches"][0]["model"], "numba" in sys.modules)
"""


def test_auto_choosing_an_analytic_model_imports_no_numba(tmp_path):
    """``wheelrail contact <quadric case> --json`` whose ``auto`` choice is the linear theory (hertz-quadric with a
    tenth of its creepages and no spin) warms up only the chosen model and imports no numba."""
    done = _python(AUTO_ANALYTIC_CODE, str(tmp_path / "small-creep.toml"))
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["0", "linear", "False"], done.stdout


KERNELS_CODE = """
import contextlib, io, sys
from wheelrail.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    code = main(["contact", "hertz-quadric", "--json"{method}])
from numba.core.registry import CPUDispatcher
from rigid_dynamics.contact import lazy_kernels
loaded = {name for name, module in list(sys.modules.items()) if name.startswith(("rigid_dynamics", "wheelrail"))
          for value in list(vars(module).values()) if isinstance(value, CPUDispatcher) and value.overloads}
loaded |= {source + " (compiled copies)" for source in lazy_kernels._COPIES}
print(code, ",".join(sorted(loaded)))
"""


@pytest.mark.parametrize("method", [None, "bem"])
def test_contact_json_loads_only_the_bem_kernels(method):
    """``wheelrail contact hertz-quadric --json`` (auto, which chooses bem here) and ``--method bem`` load (from
    numba's cache) only the BEM's kernels (bem/norm.py, bem/tang.py): none of the compiled copies of Hertz, Kalker's
    table, the linear theory or the friction law, which ``auto`` and the BEM call a few times each, as Python
    (lazy_kernels.PYTHON_CALLS_LIMIT; 2-4 ms a kernel, benchmarks/results/startup.md)."""
    extra = "" if method is None else f', "--method", "{method}"'
    done = _python(KERNELS_CODE.replace("{method}", extra))
    assert done.returncode == 0, done.stderr
    code, _, loaded = done.stdout.strip().partition(" ")
    assert code == "0", done.stdout
    assert loaded == "rigid_dynamics.contact.bem.norm,rigid_dynamics.contact.bem.tang", loaded


EXIT_CODE = """
import atexit, gc, json, sys
atexit.register(lambda: print("frozen at exit:", gc.get_freeze_count(), file=sys.stderr))  # runs after main's
from wheelrail.cli import main
threshold = gc.get_threshold()
code = main(["contact", "hertz-quadric", "--json"])
print("frozen at return:", gc.get_freeze_count(), file=sys.stderr)
print("threshold restored:", gc.get_threshold() == threshold, file=sys.stderr)
sys.exit(code)
"""


def test_contact_skips_the_collection_at_exit():
    """``wheelrail contact`` freezes the garbage collector's objects at the interpreter's exit (not when it returns:
    a caller that goes on is untouched), which spares the shutdown's full collections over numba's registries
    (0.2-0.25 s, benchmarks/results/startup.md); the JSON still comes out whole and the exit status is the
    command's. The collector's young threshold, raised while the command runs, is restored when it returns."""
    done = _python(EXIT_CODE)
    assert done.returncode == 0, done.stderr
    assert __import__("json").loads(done.stdout)["status"] == "ok"
    lines = dict(line.split(": ") for line in done.stderr.strip().splitlines())
    assert int(lines["frozen at exit"]) > int(lines["frozen at return"]) + 10_000, done.stderr
    assert lines["threshold restored"] == "True", done.stderr  # raised while the command runs (cli.py)


RUN_EXIT_CODE = """
import atexit, gc, sys
atexit.register(lambda: print("frozen at exit:", gc.get_freeze_count(), file=sys.stderr))  # runs after main's
from wheelrail.cli import main
code = main(["run", "hunting-conical", "--no-plots", "--quiet", "--set", "duration_s=0.01", "--out", sys.argv[1]])
print("frozen at return:", gc.get_freeze_count(), file=sys.stderr)
print("pandas imported:", "pandas" in sys.modules, file=sys.stderr)
sys.exit(code)
"""


def test_run_skips_the_collection_at_exit(tmp_path):
    """``wheelrail run`` freezes the collector's objects at exit as ``contact`` does (0.3 s CPU of a short run's
    shutdown), not when it returns; the run's outputs are written whole and its exit status is the run's. It
    writes its tables (CSV, Parquet) without importing pandas (0.25-0.33 s; rigid_dynamics/wheelset/table.py)."""
    done = _python(RUN_EXIT_CODE, str(tmp_path / "out"), timeout=600)
    assert done.returncode == 0, done.stderr
    assert __import__("json").loads((tmp_path / "out" / "summary.json").read_text())["status"] == "ok"
    lines = dict(line.split(": ") for line in done.stderr.strip().splitlines() if ": " in line)
    assert int(lines["frozen at exit"]) > int(lines["frozen at return"]) + 10_000, done.stderr
    assert lines["pandas imported"] == "False", done.stderr
    assert {"timeseries.csv", "timeseries.parquet"} <= {p.name for p in (tmp_path / "out").iterdir()}
