"""One trivial cached numba kernel: ``python benchmarks/numba_floor_kernel.py`` is the whole-process floor of any
command that calls a compiled kernel (numba's import, its CPU target's registries -- which import scipy.linalg for
BLAS -- and one kernel loaded from the disk cache). With ``--freeze-at-exit`` the garbage collector's objects are
frozen at exit, as ``wheelrail contact`` does (wheelrail/cli.py): the interpreter's shutdown then skips its full
collections over numba's registries. Timed by benchmarks/bench_startup.py."""

import sys

from numba import njit


@njit(cache=True)
def add_one(x):
    return x + 1.0


if __name__ == "__main__":
    if "--freeze-at-exit" in sys.argv[1:]:
        import atexit
        import gc

        atexit.register(gc.freeze)
    add_one(1.0)
