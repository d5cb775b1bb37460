"""Security (issue 23): no code runs from a local port, nothing is written outside the chosen folder.

Each test tries the attack: a local process connecting to the sweep's dask scheduler and asking it to run code,
a case ``name`` with ``..``, a symbolic link planted inside ``--out``, a case's ``[solver] output_dir`` pointing
elsewhere. Every one must fail without writing anything outside the output folder.
"""

import gc

import pytest
from hardening_helpers import QUADRIC, assert_error, run, wheelset_case, write

from wheelrail.output import LOCK_NAME, WriteError, output_folder, safe_name, subfolder


def test_local_dask_cluster_runs_no_code_for_another_local_process(tmp_path):
    """The attack of the issue: ``Client(address).run_on_scheduler(...)`` from another client, without and with
    TLS credentials of its own; the scheduler must refuse it (the sweep's own client still works)."""
    from distributed import Client
    from distributed.security import Security

    from comparisons.stress import local_dask_client

    marker = tmp_path / "pwned"

    def payload(path=str(marker)):
        open(path, "w").close()
        return "ran"

    gc.collect()  # clients an earlier test left to the collector are closed here, not inside the next start
    with local_dask_client(1) as client:
        address = client.scheduler.address
        assert address.startswith("tls://127.0.0.1:")
        assert client.submit(lambda x: x + 1, 1).result() == 2  # the sweep's own client runs tasks
        attempts = [
            {"address": address},  # plain client: no TLS context
            {"address": address.replace("tls://", "tcp://")},  # plain TCP on the TLS port
            {"address": address, "security": Security.temporary()},  # TLS with credentials the cluster never made
        ]
        for attempt in attempts:
            # refused by an error of distributed's (OSError/TypeError/ValueError; in a long test session its loop
            # runner's own AssertionError): what matters is that no code ran (the marker below)
            with pytest.raises((OSError, TypeError, ValueError, AssertionError)):
                with Client(attempt.pop("address"), timeout="3s", set_as_default=False, **attempt) as intruder:
                    intruder.run_on_scheduler(payload)
            # the refused client is half built: collect it now, not inside the next Client's start (its __del__
            # closing its loop runner there waits on the lock that start holds: the suite hung there once)
            gc.collect()
    assert not marker.exists()


def test_case_name_with_dots_stays_inside_the_output_folder(capsys, tmp_path, monkeypatch):
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    case = write(tmp_path, 'name = "../../../escape"\n' + QUADRIC, "case.toml")
    code, out, err = run(capsys, "contact", case, "--plot")
    assert code == 0, err
    outputs = list((work / "wheelrail-out").iterdir())
    assert len(outputs) == 1 and outputs[0].name.startswith("contact-escape-"), outputs
    assert (outputs[0] / "summary.json").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml", "work"]  # nothing outside
    assert sorted(p.name for p in work.iterdir()) == ["wheelrail-out"]


@pytest.mark.parametrize(
    ("text", "expected"),
    [("../../x", "x"), ("a/b\\c", "a_b_c"), ("..", "case"), ("", "case"), ("ok-name_1.2", "ok-name_1.2")],
)
def test_safe_name(text, expected):
    assert safe_name(text) == expected


def test_planted_points_link_is_refused_before_any_work(capsys, tmp_path):
    """A ``points/`` link inside ``--out`` to a folder elsewhere: the sweep exits 2 naming the link, writes nothing
    there and starts no worker."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "points").symlink_to(elsewhere, target_is_directory=True)
    sweep = write(tmp_path, 'scene = "hunting-conical"\n[set]\nduration_s = 0.01\n[grid]\nspeed_m_per_s = [10.0]\n')
    code, _, err = run(capsys, "sweep", sweep, "--out", out, "--workers", "1", "--quiet")
    assert_error(code, err, f"--out {str(out)!r}", "symbolic link", "points")
    assert list(elsewhere.iterdir()) == []
    assert sorted(p.name for p in out.iterdir()) == ["points"]


def test_a_link_planted_after_the_check_is_not_followed(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    with output_folder(tmp_path / "out", "x") as out:
        (out / "fea").symlink_to(elsewhere, target_is_directory=True)
        with pytest.raises(WriteError, match="symbolic link"):
            subfolder(out, "fea")
        assert subfolder(out, "points").is_dir()
    assert list(elsewhere.iterdir()) == []


@pytest.mark.parametrize(
    ("text", "key"),
    [
        (QUADRIC + '[solver]\noutput_dir = "{target}"\n', "solver.output_dir"),
        (wheelset_case('[solver.model]\noutput_dir = "{target}"\n'), "solver.model.output_dir"),
    ],
)
def test_solver_output_dir_of_a_case_file_is_refused(capsys, tmp_path, text, key):
    target = tmp_path / "elsewhere"
    case = write(tmp_path, text.format(target=target), "case.toml")
    code, _, err = run(capsys, "contact", case, "--method", "fea", "--json")
    assert_error(code, err, f"key '{key}'", str(target), "--out")
    assert not target.exists()


COMMANDS_WITH_OUT = [
    ("run", "hunting-conical", "--quiet"),
    ("contact", "hertz-quadric"),
    ("stress", "hunting-conical", "--quick"),
    ("sweep", "{sweep}", "--workers", "1"),
    ("critical-speed", "hunting-conical"),
    ("compare", "creep-long-small", "--models", "hertz"),
    ("bench", "--quick", "--cases", "creep-long-small", "--models", "hertz"),
    ("demo", "--models", "hertz"),
    ("manchester",),
]


def _argv(command: tuple, tmp_path) -> list:
    sweep = write(tmp_path, 'scene = "hunting-conical"\n[grid]\nspeed_m_per_s = [10.0]\n', "sweep.toml")
    return [a.format(sweep=sweep) for a in command]


@pytest.mark.parametrize("command", COMMANDS_WITH_OUT, ids=[c[0] for c in COMMANDS_WITH_OUT])
def test_empty_out_is_refused_by_every_command(capsys, tmp_path, monkeypatch, command):
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    code, _, err = run(capsys, *_argv(command, tmp_path), "--out", "")
    assert_error(code, err, "--out", "''", "expected a folder path")
    assert list(work.iterdir()) == []


@pytest.mark.parametrize("command", COMMANDS_WITH_OUT, ids=[c[0] for c in COMMANDS_WITH_OUT])
def test_every_command_honours_the_lock(capsys, tmp_path, command):
    """A folder another run holds is refused by every command, which writes nothing into it."""
    out = tmp_path / "held"
    with output_folder(out, "x"):
        code, _, err = run(capsys, *_argv(command, tmp_path), "--out", out)
        assert_error(code, err, f"--out {str(out)!r}", "another wheelrail run", LOCK_NAME)
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]


def test_unrelated_links_in_a_users_folder_are_left_alone(capsys, tmp_path):
    """Only the sub-folders a run writes into are searched for links: ``--out .`` in a project with a virtual
    environment's links works, and the link is not followed or touched."""
    out = tmp_path / "project"
    (out / "venv").mkdir(parents=True)
    (out / "venv" / "python").symlink_to("/usr/bin/env")
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", out)
    assert code == 0, err
    assert (out / "summary.json").is_file() and (out / "venv" / "python").is_symlink()
