"""Lost data and malformed inputs of the newer commands (issue 23).

An ``invalid-initial-state`` run writes its outputs and summary; a path that cannot be encoded is refused before
anything is written; two ``compare`` runs into one folder cannot mix; a malformed ``compare`` case folder is one
line (exit 2); a folder turning read-only in the middle of a run ends with exit 3 and one line.
"""

import json
import os
import shutil
import subprocess

import pytest
from hardening_helpers import PYTHON, ROOT, assert_error, assert_whole_files, run, short_scene

from wheelrail.output import LOCK_NAME


def test_invalid_initial_state_run_writes_its_outputs_and_summary(capsys, tmp_path):
    """A 1 kg wheelset with no axle load has no static equilibrium: status invalid-initial-state, exit 1, and every
    output written (the empty time series too) with summary.json; it crashed while writing the CSV before."""
    scene = short_scene(tmp_path, 0.05)
    out = tmp_path / "out"
    code, stdout, err = run(
        capsys, "run", scene, "--out", out, "--quiet", "--set", "wheelset.mass_kg=1", "--set", "loads.axle_load_N=0"
    )
    assert code == 1, err
    assert "invalid-initial-state" in stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "invalid-initial-state" and summary["success"] is False
    names = assert_whole_files(out)
    for name in ("timeseries.csv", "timeseries.npz", "timeseries.parquet", "scene.toml", "summary.json"):
        assert name in names


def test_out_path_not_encodable_as_utf8_is_refused_before_writing(capsys, tmp_path):
    out = tmp_path / os.fsdecode(b"bad-\xff-name")  # non-UTF-8 bytes: a lone surrogate in the str
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", out)
    assert_error(code, err, "--out", "cannot be encoded for UTF-8")
    assert list(tmp_path.iterdir()) == []


def test_out_path_under_the_c_locale_is_refused_before_writing(tmp_path):
    """The C locale without UTF-8 mode: the file system encoding is ASCII, a non-ASCII folder cannot be made."""
    out = tmp_path / "sortie-é"
    env = dict(os.environ, PYTHONPATH=str(ROOT), LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    check = subprocess.run([PYTHON, "-c", "import sys; print(sys.getfilesystemencoding())"], env=env,
                           capture_output=True, text=True)  # fmt: skip
    if check.stdout.strip().lower() in ("utf-8", "utf8"):
        pytest.skip("this Python keeps UTF-8 file names under the C locale")
    proc = subprocess.run(
        [PYTHON, "-m", "wheelrail.cli", "contact", "hertz-quadric", "--out", os.fsencode(str(out))],
        cwd=ROOT, env=env, capture_output=True, timeout=300,
    )  # fmt: skip
    err = proc.stderr.decode("ascii", "backslashreplace")
    assert_error(proc.returncode, err, "--out", "cannot be encoded")
    assert list(tmp_path.iterdir()) == []


def test_two_compares_into_one_folder_do_not_mix(capsys, tmp_path, monkeypatch):
    """The second compare into a folder removes the first one's report and compare.json before its work (a failed
    second compare cannot leave the first one's report beside its own files); while one runs, the folder is locked
    (test_hardening_security: every command honours the lock). The work is replaced by a stand-in writing the
    same files (the folder handling is under test, not the comparison)."""
    import comparisons.compare

    seen = []

    def stand_in(named, out_dir, models, progress=None):
        seen.append(sorted(p.name for p in out_dir.iterdir()))
        if named.name == "hertz-ab-10":
            raise RuntimeError("the second compare fails half-way")
        for name in ("report.md", "report.html", "compare.json"):
            (out_dir / name).write_text(json.dumps({"case": named.name}))
        return {"headlines": [], "success": True}

    monkeypatch.setattr(comparisons.compare, "run_compare", stand_in)
    out = tmp_path / "out"
    code, _, err = run(capsys, "compare", "hertz-ab-1", "--models", "hertz", "--out", out)
    assert code == 0, err
    with pytest.raises(RuntimeError):
        run(capsys, "compare", "hertz-ab-10", "--models", "hertz", "--out", out)
    assert seen[1] == [LOCK_NAME, "case.toml"]  # the first one's report was gone before the second's work
    assert not (out / "report.md").exists() and not (out / "compare.json").exists()
    assert not (out / LOCK_NAME).exists()


def _case_folder(tmp_path, name="hertz-ab-1"):
    folder = tmp_path / "mine"
    shutil.copytree(ROOT / "comparisons" / "cases" / name, folder)
    return folder


@pytest.mark.parametrize(
    ("edit", "fragments"),
    [
        (lambda f: (f / "case.toml").unlink(), ("case.toml", "not found")),
        (lambda f: (f / "reference.toml").write_bytes(b'source = "closed-form"\n\xff\xfe = 1\n'), ("not valid TOML",)),
        (lambda f: (f / "reference.toml").write_text('source = "closed-form"\nreference = 3\n'), ("'reference' = 3",)),
        (
            lambda f: (f / "reference.toml").write_text('source = "closed-form"\n[uncertainty]\nx = "a"\n'),
            ("'uncertainty.x' = 'a'",),
        ),
        (lambda f: (f / "reference.toml").write_text('source = "closed-form"\ntags = "x"\n'), ("'tags' = 'x'",)),
        (lambda f: (f / "reference_field.npz").write_bytes(b"not a zip"), ("reference_field.npz", "NPZ")),
    ],
)
def test_malformed_compare_case_folder_is_one_line(capsys, tmp_path, edit, fragments):
    folder = _case_folder(tmp_path)
    edit(folder)
    out = tmp_path / "out"
    code, _, err = run(capsys, "compare", folder, "--models", "hertz", "--out", out)
    assert_error(code, err, *fragments)
    assert not out.exists()


@pytest.mark.parametrize(
    ("csv_text", "fragments"),
    [(None, ("contact_reference.csv", "cannot be read")), ("a,b\n1,2\n", ("contact_reference.csv", "columns"))],
)
def test_malformed_contact_reference_table_is_one_line(capsys, tmp_path, csv_text, fragments):
    folder = _case_folder(tmp_path, "a22-tread")
    (folder / "reference.toml").write_text('source = "contact-published"\nside = "right"\n')
    if csv_text is None:
        (folder / "contact_reference.csv").unlink()
    else:
        (folder / "contact_reference.csv").write_text(csv_text)
    code, _, err = run(capsys, "compare", folder, "--models", "hertz", "--out", tmp_path / "out")
    assert_error(code, err, *fragments)


def test_folder_turning_read_only_mid_run_is_exit_3_in_one_line(capsys, tmp_path, monkeypatch):
    """After the folder was checked and locked, it turns read-only (simulated: the replace of every file and the
    removal of the lock fail with EACCES, as for root too). One line naming the file, exit 3, no traceback (the
    lock cleanup raised before)."""
    import pathlib

    real_unlink = pathlib.Path.unlink

    def refuse_replace(src, dst, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(dst))

    def refuse_lock_unlink(self, *args, **kwargs):
        if self.name == LOCK_NAME:
            raise PermissionError(13, "Permission denied", str(self))
        return real_unlink(self, *args, **kwargs)

    import wheelrail.output

    real_copy = wheelrail.output.copy_input

    def copy_then_read_only(*args, **kwargs):
        monkeypatch.setattr(os, "replace", refuse_replace)
        monkeypatch.setattr(pathlib.Path, "unlink", refuse_lock_unlink)
        return real_copy(*args, **kwargs)

    monkeypatch.setattr(wheelrail.output, "copy_input", copy_then_read_only)
    out = tmp_path / "out"
    code, _, err = run(capsys, "contact", "hertz-quadric", "--out", out)
    monkeypatch.undo()
    assert_error(code, err, "cannot write", "case.toml", "Permission denied", status=3)
    assert not (out / "summary.json").exists()
