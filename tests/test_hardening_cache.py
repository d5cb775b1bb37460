"""A corrupted numba cache (issue 23): the command rebuilds the cache and goes on, with a one-line note.

Before, loading the corrupted index raised UnpicklingError with a traceback. A kernel with ``cache=True`` is
compiled in a child process (which writes its cache next to the source), its index is overwritten with garbage, and
a command using it runs in this process.
"""

import importlib
import subprocess
import sys

from hardening_helpers import PYTHON

import wheelrail.cli

KERNEL = """
import numba


@numba.njit(cache=True)
def twice(x):
    return 2.0 * x
"""


def test_corrupted_numba_cache_is_rebuilt_with_a_note(capsys, tmp_path, monkeypatch):
    (tmp_path / "h23_cached_kernel.py").write_text(KERNEL)
    subprocess.run([PYTHON, "-c", "import h23_cached_kernel as k; assert k.twice(2.0) == 4.0"], cwd=tmp_path,
                   check=True, timeout=300)  # fmt: skip
    indexes = list((tmp_path / "__pycache__").glob("h23_cached_kernel.twice-*.nbi"))
    assert len(indexes) == 1
    indexes[0].write_bytes(b"\x80\x04garbage, not a pickle")

    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop("h23_cached_kernel", None)
    calls = []

    def command(args):
        kernel = importlib.import_module("h23_cached_kernel")
        calls.append(1)
        print(f"twice(3) = {kernel.twice(3.0)}")
        return 0

    monkeypatch.setattr(wheelrail.cli, "cmd_models", command)
    code = wheelrail.cli.main(["models"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "twice(3) = 6.0" in captured.out
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("wheelrail: note: the compiled-code cache "), captured.err
    assert "could not be read" in lines[0] and "Traceback" not in captured.err
    assert len(calls) == 2
    rebuilt = list((tmp_path / "__pycache__").glob("h23_cached_kernel.twice-*.nbi"))
    assert len(rebuilt) == 1 and not rebuilt[0].read_bytes().startswith(b"\x80\x04garbage")
