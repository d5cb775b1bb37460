"""Bad input found before any work (issue 23): exit status 2, one line naming the key or option, nothing written.

Sweep points, ``--scheduler`` addresses, ``critical-speed``'s speed range and duration, ``--workers``, contact patch
options; and the cause fixed in the CLI: a ValueError raised in the middle of the work is a failure of the work
(exit 1, one line), not bad input.
"""

import socket
import time

import pytest
from hardening_helpers import assert_error, run, wheelset_case, write

SWEEP = 'scene = "hunting-conical"\n[set]\nduration_s = 0.01\n[grid]\nspeed_m_per_s = [10.0, 20.0]\n'


@pytest.mark.parametrize(
    ("text", "extra", "fragments"),
    [
        (SWEEP.replace("[10.0, 20.0]", "[10.0, -5.0]"), (), ("speed_m_per_s = -5.0", "'speed_m_per_s'")),
        (SWEEP.replace("duration_s = 0.01", "duration_s = -1.0"), (), ("'duration_s' = -1.0",)),
        (SWEEP.replace("duration_s = 0.01", "no_such_key = 1.0"), (), ("no_such_key",)),
        (SWEEP, ("--set", "material.friction_coefficient=-0.3"), ("friction_coefficient", "-0.3")),
        (SWEEP + '[[points]]\ncontact_model = "nope"\n', (), ("contact_model = 'nope'", "expected one of")),
        ('case = "hertz-quadric"\nmethod = "nope"\n[grid]\n"loading.normal_force_N" = [1e4]\n', (), ("'nope'",)),
        ('case = "hertz-quadric"\n[grid]\nmethod = ["hertz", "bogus"]\n', (), ("method = 'bogus'",)),
        ('case = "hertz-quadric"\n[grid]\n"solver.nx" = [-2]\n', (), ("solver.nx",)),
    ],
)
def test_bad_sweep_point_exits_2_before_any_work(capsys, tmp_path, text, extra, fragments):
    sweep = write(tmp_path, text, "sweep.toml")
    out = tmp_path / "out"
    code, _, err = run(capsys, "sweep", sweep, "--out", out, "--workers", "1", "--quiet", *extra)
    assert_error(code, err, *fragments)
    assert not out.exists()


@pytest.mark.parametrize("address", ["", "   ", "not an address", "tcp://127.0.0.1:99999", "http://host:80", "host"])
def test_bad_scheduler_address_is_named(capsys, tmp_path, address):
    sweep = write(tmp_path, SWEEP, "sweep.toml")
    out = tmp_path / "out"
    code, _, err = run(capsys, "sweep", sweep, "--out", out, "--scheduler", address)
    assert_error(code, err, f"--scheduler {address!r}", "HOST:PORT")
    assert not out.exists()


def _closed_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.mark.parametrize("kind", ["closed", "silent"])
def test_unreachable_scheduler_ends_in_one_line_within_the_timeout(capsys, tmp_path, monkeypatch, kind):
    """A closed port, and a port that accepts but never answers (it hung forever before): one line naming
    ``--scheduler`` after the (here shortened) timeout, exit 2, no folder."""
    import wheelrail.sweep as sweep_module

    monkeypatch.setattr(sweep_module, "SCHEDULER_TIMEOUT_S", 2.0)
    listener = None
    if kind == "closed":
        port = _closed_port()
    else:
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen(8)  # accepts connections (kernel backlog) and never says a word
        port = listener.getsockname()[1]
    sweep = write(tmp_path, SWEEP, "sweep.toml")
    out = tmp_path / "out"
    start = time.perf_counter()
    try:
        code, _, err = run(capsys, "sweep", sweep, "--out", out, "--scheduler", f"tcp://127.0.0.1:{port}")
    finally:
        if listener is not None:
            listener.close()
    assert time.perf_counter() - start < 30.0
    assert_error(code, err, f"--scheduler 'tcp://127.0.0.1:{port}'", "no dask scheduler answered within 2 s")
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "fragments"),
    [
        (("--high", "500"), ("--high 500.0", "from 0 to 200")),
        (("--low", "300"), ("--low 300.0", "from 0 to 200")),
        (("--low", "150", "--high", "100"), ("--low 150.0", "below --high 100.0")),
        (("--low", "199"), ("--low 199.0", "expected a speed below --high")),  # above the default (1.2 x linear)
        (("--duration", "1e7"), ("--duration 10000000.0", "from 0 to 86400")),
        (("--steps", "100000"), ("--steps 100000", "from 1 to 1000")),
    ],
)
def test_critical_speed_range_is_checked_before_writing(capsys, tmp_path, argv, fragments):
    out = tmp_path / "out"
    code, _, err = run(capsys, "critical-speed", "hunting-conical", "--out", out, *argv)
    assert_error(code, err, *fragments)
    assert not out.exists()


@pytest.mark.parametrize("command", [("sweep", "{sweep}"), ("stress", "hunting-conical")])
def test_huge_workers_refused_with_the_estimate(capsys, tmp_path, command):
    sweep = write(tmp_path, SWEEP, "sweep.toml")
    out = tmp_path / "out"
    argv = [a.format(sweep=sweep) for a in command]
    code, _, err = run(capsys, *argv, "--out", out, "--workers", "100000")
    assert_error(code, err, "--workers 100000", "GiB")
    assert not out.exists()


@pytest.mark.parametrize(
    ("table", "key", "value"),
    [
        ("[solver.patch]\ndistance_separation_m = -1.0\n", "solver.patch.distance_separation_m", "-1.0"),
        ("[solver.patch]\ndistance_turning_m = -1.0\n", "solver.patch.distance_turning_m", "-1.0"),
        ("[solver.patch]\nfield_points = -3\n", "solver.patch.field_points", "-3"),
        ("[solver.search]\nfield_points = -3\n", "solver.search.field_points", "-3"),
        ("[solver.patch]\nlocus_step_m = 0.0\n", "solver.patch.locus_step_m", "0.0"),
    ],
)
def test_contact_patch_options_are_named(capsys, tmp_path, table, key, value):
    case = write(tmp_path, wheelset_case('[solver]\npatches = "contact"\n' + table), "case.toml")
    out = tmp_path / "out"
    code, _, err = run(capsys, "contact", case, "--method", "hertz", "--out", out)
    assert_error(code, err, f"key {key!r} = {value}")
    assert not out.exists()


def test_a_value_error_during_the_work_is_a_failure_not_bad_input(capsys, tmp_path, monkeypatch):
    """The cause of several wrong exit statuses: a library ValueError raised mid-work was reported as bad input
    (exit 2). Now one line naming the failure, exit 1."""
    import wheelrail.cases

    def broken(case, method, progress=None):
        raise ValueError("a check deep inside the solver failed")

    monkeypatch.setattr(wheelrail.cases, "solve_case", broken)
    code, _, err = run(capsys, "contact", "hertz-quadric")
    assert_error(code, err, "the work failed: ValueError: a check deep inside the solver failed", status=1)


def test_huge_sweep_grid_is_refused_with_the_estimate(capsys, tmp_path):
    """A 1000 x 1000 grid raised MemoryError (or ran for hours); now refused before any point is built."""
    values = ", ".join(f"{v}.0" for v in range(1, 1001))
    sweep = write(tmp_path, f'scene = "hunting-conical"\n[grid]\nspeed_m_per_s = [{values}]\nduration_s = [{values}]\n')
    out = tmp_path / "out"
    code, _, err = run(capsys, "sweep", sweep, "--out", out)
    assert_error(code, err, "table [grid] (1000 x 1000 = 1000000 points)", "at most 100000", "minutes")
    assert not out.exists()


def test_beam_over_an_enormous_travel_is_refused_at_once(capsys, tmp_path):
    """wheel-flat's beam track over a day of travel (1440 km): the modes were counted one by one before the size
    check (minutes); now refused in well under a second of work, naming the beam's size."""
    out = tmp_path / "out"
    start = time.perf_counter()
    code, _, err = run(capsys, "run", "wheel-flat", "--set", "duration_s=86400", "--out", out, "--quiet")
    assert time.perf_counter() - start < 30.0
    assert_error(code, err, "track_dynamics.model = 'beam'", "expected at most 8000")
    assert not out.exists()
