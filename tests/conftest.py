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

# `make test` runs the suite on two pytest-xdist workers (PYTEST_WORKERS, default 2) with `--dist loadgroup`. Each
# test file is one group (its module-scoped fixtures are computed once, on one worker), except the tests that start
# `mpiexec -n 2`: they share the group MPI_GROUP with the whole of test_fea_field_files.py (whose two-rank test uses
# the file's fixture), so two MPI jobs never run at once. Every test writes only under its tmp_path, or atomically
# into the numba and table caches.
MPI_GROUP = "mpi"
MPI_FILES = {"test_fea_field_files"}
MPI_TESTS = {"test_fea_contact.py::test_two_ranks_agree_with_one_rank"}
FIRST = (
    "test_fea_contact",
    MPI_GROUP,
    "test_compare",
    "test_examples",
    "test_dynamics_regression",
    "test_docs",
    "test_dynamics_search",
    "test_contact_force_control",
    "test_geometry_slices",
)
"""The groups that take longest (measured, benchmarks/results/suite_time.md), handed out first so that the two
workers end together; the others follow in file order. Only the balance depends on this list."""


def _group(item) -> str:
    path = Path(str(item.fspath))
    if path.stem in MPI_FILES or f"{path.name}::{item.name}" in MPI_TESTS:
        return MPI_GROUP
    return path.stem


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    if getattr(config.option, "dist", "no") != "loadgroup":
        return
    for item in items:
        if not any(item.iter_markers("xdist_group")):
            item.add_marker(pytest.mark.xdist_group(_group(item)))
    rank = {name: i for i, name in enumerate(FIRST)}
    items.sort(key=lambda item: rank.get(_group(item), len(FIRST)))  # stable: file order within and after
