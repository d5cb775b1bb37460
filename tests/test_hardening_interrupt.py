"""Ctrl-C during a command running a local dask cluster (issue 23): one line, exit status 130, no worker traceback.

A Ctrl-C in a terminal sends SIGINT to the whole foreground process group: here the command and its worker
processes. The workers are started ignoring SIGINT; the command stops, closes its cluster and says so once. (Each
test takes about 20 s on a loaded 2-core machine: the cluster's start and stop.)
"""

import os
import signal

import pytest
from hardening_helpers import cli_subprocess, write
from test_hardening_kill import wait_for

from wheelrail.output import LOCK_NAME

SWEEP = (
    # the analytic cone with scipy's RK45 (seconds per point; the scene's compiled default takes 0.1 s): points are
    # still running when the interrupt comes
    'scene = "hunting-conical"\n[set]\nduration_s = 2.0\ncontact_provider = "conical"\n"integrator.method" = "RK45"\n'
    "[grid]\nspeed_m_per_s = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0]\n"
)


def _workers(pid: int) -> int:
    """Worker processes (multiprocessing's spawned children) of the process ``pid``."""
    count = 0
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as handle:
                ppid = int(handle.read().rsplit(")", 1)[1].split()[1])
            with open(f"/proc/{entry}/cmdline", "rb") as handle:
                spawned = b"spawn_main" in handle.read()
        except (OSError, ValueError, IndexError):
            continue
        count += ppid == pid and spawned
    return count


def _sigint_default() -> None:
    """In the command's process before exec: SIGINT to its default, as in a terminal (a suite run as a background
    job inherits SIGINT ignored, and Python then installs no handler: the interrupt would be lost)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _catches_sigint(pid: int) -> bool:
    """Whether the process ``pid`` has a handler installed for SIGINT (its SigCgt mask in /proc)."""
    try:
        with open(f"/proc/{pid}/status") as handle:
            caught = next(line for line in handle if line.startswith("SigCgt:"))
    except (OSError, StopIteration):
        return False
    return bool(int(caught.split()[1], 16) & (1 << (signal.SIGINT - 1)))


@pytest.mark.slow
@pytest.mark.parametrize("command", ["sweep", "stress"])
def test_ctrl_c_to_the_process_group_ends_quietly_with_130(tmp_path, command):
    out = tmp_path / "out"
    if command == "sweep":
        argv = ["sweep", write(tmp_path, SWEEP, "sweep.toml"), "--workers", "2", "--quiet"]
    else:
        argv = ["stress", "hunting-conical", "--quick", "--workers", "2"]
    proc = cli_subprocess(*argv, "--out", out, start_new_session=True, preexec_fn=_sigint_default)
    try:
        # the two worker processes are up (while the cluster starts, SIGINT is ignored: its workers inherit that)
        assert wait_for(lambda: _workers(proc.pid) >= 2, 240.0), "no workers"
        # the cluster has started when the command catches SIGINT again (a fixed 1 s after the workers appeared
        # fell inside that window on a fast machine: the interrupt was ignored and the run ended 0)
        assert wait_for(lambda: _catches_sigint(proc.pid), 120.0), "SIGINT still ignored"
        assert proc.poll() is None, "ended before the interrupt"
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("wheelrail: interrupted after"), err
    assert not (out / LOCK_NAME).exists()
    assert not (out / "summary.json").exists()
