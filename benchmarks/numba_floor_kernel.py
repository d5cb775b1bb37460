"""One trivial cached numba kernel: ``python benchmarks/numba_floor_kernel.py`` is the whole-process floor of any
command that calls a compiled kernel (numba's import, its CPU target's registries -- which import scipy.linalg for
BLAS -- and one kernel loaded from the disk cache). Timed by benchmarks/bench_startup.py."""

from numba import njit


@njit(cache=True)
def add_one(x):
    return x + 1.0


if __name__ == "__main__":
    add_one(1.0)
