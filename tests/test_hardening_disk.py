"""A full disk or a file-size limit: one line naming the file, exit status 3, no partial file under a final name.

The limit is real (``RLIMIT_FSIZE`` in a subprocess: writes beyond it fail with EFBIG); the full disk is a
mock of the write layer (ENOSPC from ``os.fsync`` / ``os.write``).
"""

import errno
import os
import resource

from hardening_helpers import assert_error, assert_whole_files, cli_subprocess, run, short_scene

import rigid_dynamics.files as files
from wheelrail.output import LOCK_NAME


def test_file_size_limit_in_a_subprocess(tmp_path):
    """20 kB per file: case.toml and the lock fit, the PNG of the fields does not."""
    out = tmp_path / "o"

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    proc = cli_subprocess("contact", "hertz-quadric", "--method", "fastsim", "--plot", "--out", out, preexec_fn=limit)
    stdout, stderr = proc.communicate(timeout=300)
    assert_error(proc.returncode, stderr, "cannot write", "fields-single-0.png", "File too large", status=3)
    assert "Traceback" not in stderr
    names = assert_whole_files(out)
    assert "summary.json" not in names and "fields-single-0.png" not in names
    assert not any(p.name.startswith(".") for p in out.iterdir())  # temporary files and lock removed


def test_disk_full_while_writing(capsys, tmp_path, monkeypatch):
    """The disk fills after the folder check: the first file of the run (scene.toml) cannot be flushed."""
    real_fsync = os.fsync

    def full(fd):
        if ".part" in os.readlink(f"/proc/self/fd/{fd}"):  # the temporary files of atomic_write, not the lock
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_fsync(fd)

    monkeypatch.setattr(files.os, "fsync", full)
    out = tmp_path / "o"
    code, _, err = run(capsys, "run", short_scene(tmp_path), "--out", out, "--quiet", "--no-plots")
    assert_error(code, err, "cannot write", "scene.toml", "No space left on device", status=3)
    assert not out.exists() or list(out.iterdir()) == []


def test_disk_full_before_the_work(capsys, tmp_path, monkeypatch):
    """The folder is probed (the lock file is written) before the work: a full disk stops the run there."""
    import wheelrail.output as output

    def full(fd, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(output.os, "write", full)
    code, _, err = run(capsys, "run", "hunting-conical", "--out", tmp_path / "o", "--quiet")
    assert_error(code, err, "--out", "cannot be written (No space left on device)")
    assert not (tmp_path / "o").exists()
    assert not (tmp_path / "o" / LOCK_NAME).exists()


def test_one_json_sanitiser_writes_nan_and_numpy_values_as_json(tmp_path):
    """rigid_dynamics.files.json_ready (behind wheelrail.output.write_json and the comparisons' JSON): NaN and inf,
    also as numpy float32 scalars and inside arrays, become null; numpy values become numbers and lists."""
    import json
    import math
    from pathlib import Path

    import numpy as np

    data = {
        "nan": math.nan,
        "inf32": np.float32("inf"),
        "array": np.array([1.0, np.nan]),
        "int64": np.int64(3),
        "path": Path("a/b"),
        "nested": ({1: np.float64(-math.inf)},),
    }
    path = files.write_json(tmp_path / "x.json", data)
    assert json.loads(path.read_text(encoding="utf-8"), parse_constant=lambda c: c) == {
        "nan": None,
        "inf32": None,
        "array": [1.0, None],
        "int64": 3,
        "path": "a/b",
        "nested": [{"1": None}],
    }
