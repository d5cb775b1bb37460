"""Shared helpers of the tests/test_hardening_*.py modules (bad input, faults; issue 13).

Every such test asserts the same contract: the exit status, exactly one line on stderr starting with
``wheelrail: error:`` that names the key or option and the value, no traceback, and no file under a final
name that is not whole.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np

from wheelrail.cli import main

ROOT = Path(__file__).resolve().parents[1]
PYTHON = sys.executable


STEEL = "\n[material]\nshear_modulus_Pa = 82e9\npoisson_ratio = 0.28\nfriction_coefficient = 0.3\n"
"""The tests' steel as a TOML ``[material]`` table."""


def wheelset_case(tables: str) -> str:
    """The TOML text of the tests' wheelset case (steel, S1002 on UIC60, 80 kN wheel load) followed by ``tables``."""
    return (
        STEEL
        + '[geometry]\nkind = "wheelset"\nwheel_profile = "S1002"\nrail_profile = "UIC60"\n'
        + "[loading]\nwheel_load_N = 8e4\n"
        + tables
    )


def quadric_case(
    *, normal_force_N: str = "1e4", creepage_long: str = "0.001", geometry_extra: str = "", kinematics: bool = True
) -> str:
    """The TOML text of the tests' quadric contact case (steel, R 0.46 / 0.3 m; numbers given as TOML text).

    ``geometry_extra``: lines added to ``[geometry]``; ``kinematics`` False leaves ``[kinematics]`` out.
    """
    text = (
        STEEL
        + '[geometry]\nkind = "quadric"\nradius_long_m = 0.46\nradius_lat_m = 0.3\n'
        + (geometry_extra + "\n" if geometry_extra else "")
        + f"[loading]\nnormal_force_N = {normal_force_N}\n"
    )
    if kinematics:
        text += (
            f"[kinematics]\ncreepage_long = {creepage_long}\ncreepage_lat = 0.0\n"
            "spin_creepage_1_per_m = 0.0\nrolling_speed_m_per_s = 20.0\n"
        )
    return text


QUADRIC = quadric_case()


def run(capsys, *argv) -> tuple[int, str, str]:
    """``wheelrail ARGV`` in this process: (exit status, stdout, stderr); never a traceback."""
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "Traceback" not in captured.out
    return code, captured.out, captured.err


def assert_error(code: int, err: str, *fragments: str, status: int = 2) -> None:
    """Exit status ``status``, exactly one stderr line ``wheelrail: error: ...`` holding every fragment."""
    assert code == status, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("wheelrail: error: "), err
    for fragment in fragments:
        assert fragment in lines[0], f"{fragment!r} not in {lines[0]!r}"


def assert_bad_scene(tmp_path: Path, capsys, scene: str, old: str, new: str, pattern: str) -> None:
    """The embedded ``scene`` with ``old`` replaced by ``new`` fails before any work: ``wheelrail run`` exits 2 with
    one ``wheelrail: error:`` line matching the regular expression ``pattern``, and no output folder."""
    import re

    from wheelrail.scenes import embedded_scenes

    text = embedded_scenes()[scene].read_text()
    assert old in text
    path = write(tmp_path, text.replace(old, new, 1), "bad.toml")
    out = tmp_path / "out"
    code, _, err = run(capsys, "run", path, "--out", out, "--quiet")
    assert_error(code, err)
    assert re.search(pattern, err), err
    assert not out.exists()


def write(tmp_path: Path, text: str, name: str = "input.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def short_scene(tmp_path: Path, duration_s: float = 0.1, name: str = "short.toml") -> Path:
    """The embedded hunting-conical scene cut to ``duration_s`` (a run of well under a second)."""
    from wheelrail.scenes import resolve_scene_path

    text = resolve_scene_path("hunting-conical").read_text(encoding="utf-8")
    assert "duration_s = 3.0" in text
    return write(tmp_path, text.replace("duration_s = 3.0", f"duration_s = {duration_s}"), name)


def assert_whole_files(folder: Path) -> list[str]:
    """Every file under a final (not hidden) name in ``folder`` parses completely; returns their names."""
    names = []
    if not folder.exists():
        return names
    for path in sorted(folder.rglob("*")):
        if not path.is_file() or path.name.startswith("."):
            continue
        names.append(path.name)
        data = path.read_bytes()
        assert data, f"{path} is empty"
        if path.suffix == ".json":
            json.loads(data)
        elif path.suffix == ".toml":
            tomllib.loads(data.decode("utf-8"))
        elif path.suffix == ".npz":
            with np.load(path) as arrays:
                for key in arrays.files:
                    arrays[key]
        elif path.suffix == ".png":
            assert data.startswith(b"\x89PNG") and data.rstrip().endswith(b"IEND\xaeB`\x82"), f"{path} is cut"
    return names


def cli_subprocess(*argv, preexec_fn=None, timeout=300, **kwargs) -> subprocess.Popen:
    """Start ``python -m wheelrail.cli ARGV`` from the repository root (this worktree's packages)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen(
        [PYTHON, "-m", "wheelrail.cli", *map(str, argv)],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=preexec_fn,
        **kwargs,
    )
