"""Bad ``--out`` and write failures: checked before the work starts; never a summary claiming success.

Folder problems found before the work: exit status 2, one line naming ``--out`` and the value, nothing created.
A write failing after the work: exit status 3, one line naming the file, no summary.json.
"""

import os
import stat

import pytest
from hardening_helpers import assert_error, assert_whole_files, run

from wheelrail.output import LOCK_NAME, write_json


def test_out_that_is_a_file(capsys, tmp_path):
    target = tmp_path / "a-file"
    target.write_text("x")
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", target)
    assert_error(code, err, f"--out {str(target)!r}", "found a file")
    assert target.read_text() == "x"


def test_out_under_a_file(capsys, tmp_path):
    (tmp_path / "a-file").write_text("x")
    target = tmp_path / "a-file" / "sub"
    code, _, err = run(capsys, "run", "--out", target, "--quiet")
    assert_error(code, err, f"--out {str(target)!r}", "is a file")


def test_out_empty(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", "")
    assert_error(code, err, "--out", "''", "expected a folder path")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root writes into read-only folders")
def test_out_read_only(capsys, tmp_path):
    locked = tmp_path / "ro"
    locked.mkdir()
    locked.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        code, _, err = run(capsys, "contact", "hertz-quadric", "--out", locked / "x")
        assert_error(code, err, f"--out {str(locked / 'x')!r}", "Permission denied")
    finally:
        locked.chmod(stat.S_IRWXU)


def test_out_unwritable_by_mock(capsys, tmp_path, monkeypatch):
    """The write probe (the lock file) fails with EACCES, as in a read-only place (also when run as root)."""
    import wheelrail.output as output

    real_open = os.open

    def refuse(path, flags, *args):
        if str(path).endswith(LOCK_NAME):
            raise PermissionError(13, "Permission denied", str(path))
        return real_open(path, flags, *args)

    monkeypatch.setattr(output.os, "open", refuse)
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", tmp_path / "x")
    assert_error(code, err, "--out", "cannot be written (Permission denied)")
    assert not (tmp_path / "x").exists()


def test_files_get_the_usual_permissions(capsys, tmp_path):
    old = os.umask(0o022)
    try:
        code, _, _ = run(capsys, "contact", "hertz-quadric", "--method", "fastsim", "--plot", "--out", tmp_path / "o")
    finally:
        os.umask(old)
    assert code == 0
    names = assert_whole_files(tmp_path / "o")
    assert sorted(names) == ["case.toml", "fields-single-0.png", "summary.json"]
    for name in names:
        assert stat.S_IMODE((tmp_path / "o" / name).stat().st_mode) == 0o644, name
    assert not (tmp_path / "o" / LOCK_NAME).exists()


def test_failed_plot_leaves_no_summary(capsys, tmp_path, monkeypatch):
    """A plot that cannot be written: exit 3 naming the file; no summary.json (also not one of an earlier run)."""
    import comparisons.contact_plots as plots

    out = tmp_path / "o"
    write_json(out / "summary.json", {"success": True, "from": "an earlier run"})

    def fail(result, path, **kwargs):
        from rigid_dynamics.files import atomic_write

        def writer(tmp):
            tmp.write_bytes(b"\x89PNG half")
            raise OSError(28, "No space left on device")

        return atomic_write(path, writer)

    monkeypatch.setattr(plots, "plot_contact_fields", fail)
    code, _, err = run(capsys, "contact", "hertz-quadric", "--method", "fastsim", "--plot", "--out", out)
    assert_error(code, err, "cannot write", "fields-single-0.png", "No space left on device", status=3)
    assert sorted(p.name for p in out.iterdir()) == ["case.toml"]  # no summary, no temporary, no lock
    assert_whole_files(out)


def test_atomic_write_follows_the_umask(tmp_path):
    """Every writer of the project (data, plots, the library's save_timeseries) gets 0666 minus the umask."""
    from rigid_dynamics.files import atomic_write, write_text

    for mask, mode in ((0o022, 0o644), (0o002, 0o664), (0o077, 0o600)):
        old = os.umask(mask)
        try:
            path = write_text(tmp_path / f"t-{mask:o}.txt", "x")
            blob = atomic_write(tmp_path / f"b-{mask:o}.npz", lambda tmp: tmp.write_bytes(b"PK"))
        finally:
            os.umask(old)
        assert stat.S_IMODE(path.stat().st_mode) == mode and stat.S_IMODE(blob.stat().st_mode) == mode
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
