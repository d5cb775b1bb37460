"""Two runs given the same ``--out``: the second is refused (a lock file), never interleaved.

A lock left by a killed run (its pid is gone) is taken over; default folders started in the same second
get different names.
"""

import os
import signal
import socket
import subprocess
import sys

from hardening_helpers import assert_error, assert_whole_files, cli_subprocess, run
from test_hardening_kill import wait_for

from wheelrail.output import LOCK_NAME, new_output_dir, output_folder


def test_folder_held_by_another_run_is_refused(capsys, tmp_path):
    out = tmp_path / "o"
    with output_folder(out, "x"):
        code, _, err = run(capsys, "contact", "hertz-quadric", "--out", out)
        assert_error(code, err, f"--out {str(out)!r}", f"another wheelrail run (pid {os.getpid()}", LOCK_NAME)
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]  # nothing of the refused run
    assert not out.exists()  # released; the folder was empty and created by the holder


def test_stale_lock_of_a_killed_run_is_taken_over(capsys, tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    out = tmp_path / "o"
    out.mkdir()
    (out / LOCK_NAME).write_text(f"{dead.pid} {socket.gethostname()} then\n")
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", out)
    assert code == 0, err
    assert sorted(assert_whole_files(out)) == ["case.toml", "summary.json"]
    assert not (out / LOCK_NAME).exists()


def test_default_folders_in_the_same_second_differ(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    first, second = new_output_dir(None, "run-x"), new_output_dir(None, "run-x")
    assert first != second and first.is_dir() and second.is_dir()


def test_two_processes_on_one_folder(tmp_path):
    """A second run on the folder of a running one exits 2 at once and writes nothing there.

    The first run (3 s of simulated time, ~30 s here) is then stopped with SIGTERM to keep the test short.
    """
    out = tmp_path / "o"
    first = cli_subprocess("run", "hunting-conical", "--out", out, "--quiet", "--no-plots")
    try:
        assert wait_for(lambda: (out / LOCK_NAME).exists())
        second = cli_subprocess("contact", "hertz-quadric", "--out", out)
        _, err = second.communicate(timeout=120)
        assert_error(second.returncode, err, f"--out {str(out)!r}", f"(pid {first.pid} ")
        assert first.poll() is None, "the first run ended before the second was refused"
        first.send_signal(signal.SIGTERM)
        _, first_err = first.communicate(timeout=120)
    finally:
        first.kill()
    assert first.returncode == 143, first_err
    assert "case.toml" not in assert_whole_files(out)  # nothing of the refused run
