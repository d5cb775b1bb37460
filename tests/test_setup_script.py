"""tools/find_python.sh: finds a Python >= 3.12 or stops with a message saying what to install."""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "tools" / "find_python.sh"


def run(env):
    return subprocess.run(["bash", str(SCRIPT)], env=env, capture_output=True, text=True, timeout=60)


def test_finds_a_python_312_or_newer_on_path(tmp_path):
    # A PATH holding only this interpreter (>= 3.12, the test suite runs in the project's venv).
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "python3.12").symlink_to(sys.executable)
    done = run({"PATH": f"{bin_dir}:/usr/bin:/bin", "HOME": str(tmp_path)})
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str(bin_dir / "python3.12")


def test_finds_pyenv_versions(tmp_path):
    version_bin = tmp_path / ".pyenv" / "versions" / "3.12.9" / "bin"
    version_bin.mkdir(parents=True)
    (version_bin / "python3").symlink_to(sys.executable)
    empty = tmp_path / "empty"
    empty.mkdir()
    done = run({"PATH": f"{empty}:/bin", "HOME": str(tmp_path)})
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str(version_bin / "python3")


def test_stops_with_a_message_when_none(tmp_path):
    old = tmp_path / "bin"
    old.mkdir()
    fake = old / "python3"
    fake.write_text("#!/bin/sh\nexit 1\n")  # an interpreter that fails the version check
    fake.chmod(0o755)
    done = run({"PATH": f"{old}:/bin", "HOME": str(tmp_path), "PYENV_ROOT": str(tmp_path / "none")})
    assert done.returncode == 1
    assert "needs Python >= 3.12" in done.stderr and "pyenv install 3.12" in done.stderr
    assert done.stdout == ""


def test_script_is_used_by_setup():
    assert "find_python.sh" in (ROOT / "tools" / "setup_venv.sh").read_text()
    assert os.access(SCRIPT, os.R_OK)


def test_setup_compiles_the_numba_kernels_with_progress():
    text = (ROOT / "tools" / "setup_venv.sh").read_text()
    assert "-m wheelrail.warmup" in text and "compiling the numba kernels" in text
    assert text.index("pip install") < text.index("wheelrail.warmup") < text.index(".installed")
