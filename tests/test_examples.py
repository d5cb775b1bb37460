"""Every script in examples/ runs, with small settings (WHEELRAIL_EXAMPLES_QUICK=1), so none can drift.

Each example asserts its own physics (Hertz closed forms, saturation at mu N, CONTACT's roll angles,
Johnson's subsurface shear, ...); this module runs them and checks they are jupytext light-format notebooks.
"""

import runpy
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


def test_the_examples_cover_the_topics():
    names = " ".join(p.stem for p in EXAMPLES)
    for topic in ("hertz", "creep", "manchester", "wheel_flat", "fea", "sweep"):
        assert topic in names, topic


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(path, tmp_path, monkeypatch):
    monkeypatch.setenv("WHEELRAIL_EXAMPLES_QUICK", "1")
    monkeypatch.setenv("WHEELRAIL_EXAMPLES_OUT", str(tmp_path))
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(path), run_name="__main__")
    assert any(tmp_path.rglob("*.png")) or any(tmp_path.rglob("*.csv"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_is_a_light_notebook(path):
    jupytext = pytest.importorskip("jupytext")
    text = path.read_text(encoding="utf-8")
    assert "format_name: light" in text.split("# ---", 2)[1]
    notebook = jupytext.reads(text, fmt="py:light")
    kinds = [cell.cell_type for cell in notebook.cells]
    assert kinds.count("markdown") >= 2 and kinds.count("code") >= 2
    assert notebook.cells[0].cell_type == "markdown" and notebook.cells[0].source.startswith("# ")
