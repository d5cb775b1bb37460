"""The packaging of pyproject.toml: the numeric core installs with numpy, scipy and numba only; every heavy or
optional library is an extra that ``[all]`` gathers (the README's setup installs ``[all,dev]``); the command line
runs without the ``progress`` extra (no bar)."""

import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _project():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _names(requirements):
    return sorted(r.split(">")[0].split("[")[0].split("=")[0].strip() for r in requirements)


def test_core_is_numpy_scipy_numba_and_all_gathers_the_extras():
    project = _project()
    assert _names(project["dependencies"]) == ["numba", "numpy", "scipy"]
    extras = project["optional-dependencies"]
    assert {"fea", "plots", "sweep", "tables", "progress", "all"} <= set(extras)
    gathered = extras["all"][0].split("[", 1)[1].rstrip("]").split(",")
    assert sorted(gathered) == sorted(set(extras) - {"all", "dev"})
    setup = (ROOT / "tools" / "setup_venv.sh").read_text()
    assert '".[all,dev]"' in setup


def test_command_line_runs_without_tqdm(monkeypatch):
    from wheelrail import cli, comparison_commands

    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm raises ImportError
    update, close = cli._progress_bar(False, "run")
    update(0.5)
    close()
    bar, advance = comparison_commands._bar(3, "bench")
    advance(1, 3, "a case")
    bar.close()
    assert bar.n == 1
