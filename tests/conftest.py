import os
import sys
from pathlib import Path

# One BLAS/OpenMP thread per test process, set before anything imports numpy (pytest loads this file first; the CLI
# tests' subprocesses inherit it). `make test` runs two xdist workers on two cores: with OpenBLAS's default of one
# thread per core, four threads share two cores and OpenBLAS's waiting threads spin. Measured on the 2-core machine
# at load ~3: a 198 x 198 complex `numpy.linalg.solve` 18 ms with two threads against 1.7 ms with one, and
# test_dynamics_beam.py's Timoshenko receptance test 233 s against 3.7 s (benchmarks/results/suite_time.md).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

# `make test` runs the suite on two pytest-xdist workers (PYTEST_WORKERS, default 2) with `--dist worksteal`: each
# worker takes one half of the tests in the order below and, when idle, steals from the end of the other's queue, so
# a file's module-scoped fixtures are computed once unless the halves meet in it. Measured in clean-clone CI runs on
# 2026-11-29: 568 s of pytest with worksteal, 675 s with `--dist loadfile` (whole files: the last file left one
# worker idle). `--dist loadgroup` with an xdist_group mark per file was used until then and grouped nothing:
# pytest-xdist 3.8 appends the group to `item._nodeid`, which pytest 9 no longer reads, so it scheduled test by test
# and module fixtures used on both workers were computed twice. The tests that start `mpiexec -n 2` take the
# `mpi_lock` fixture, so two MPI jobs never run at once. Every test writes only under its tmp_path, or atomically
# into the numba and table caches.
FIRST = (
    "test_fea_refinement",
    "test_fea_contact",
    "test_docs",
    "test_dynamics_regression",
    "test_dynamics_stress",
    "test_search_flange",
    "test_fea_field_files",
    "test_hardening_results",
    "test_traction_control",
    "test_fea_friction",
    "test_loop_sampled_run",
)
"""The files that take longest (measured: the suite with --durations=0, 2026-11-29), first in the order the workers
take; the others follow in file order. Only the balance depends on this list."""


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """On an xdist worker: the files of FIRST first (the scheduler hands out tests in collection order)."""
    if not hasattr(config, "workerinput"):
        return
    rank = {name: i for i, name in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(Path(str(item.fspath)).stem, len(FIRST)))  # stable within and after


@pytest.fixture
def mpi_lock(tmp_path_factory):
    """Holds an advisory lock for the test, shared by the xdist workers of the run (their base temporary folders
    have one parent): a test that starts `mpiexec -n 2` takes both cores, and two at once would run at half speed."""
    import fcntl

    with open(tmp_path_factory.getbasetemp().parent / "wheelrail-mpi.lock", "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield
