"""The documentation site builds, warnings as errors, so that it cannot rot (CI runs this through `make test`).

Also: the Python tour of docs/getting-started.md runs, the gallery shows every example's code unchanged, and the
results page has one section per file of benchmarks/results/. These are regression tests of the documentation
(no physics is checked here; the examples check theirs in tests/test_examples.py), and the README's BEM case's
refinement and rebalancing (checked on the solution the README's block computes, so it is solved once).
"""

import os
import runpy
import subprocess
import sys
import time
from pathlib import Path

import jupytext
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import wheelrail_docs  # noqa: E402

BUILD_TIMEOUT_S = 600


@pytest.mark.slow
def test_the_site_builds_without_warnings(tmp_path):
    """`python -m sphinx -W --keep-going`: every page, the API of every module, the gallery, the results page."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    started = time.perf_counter()
    build = subprocess.run(
        [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q", str(DOCS), str(tmp_path)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=BUILD_TIMEOUT_S,
    )
    elapsed = time.perf_counter() - started
    assert build.returncode == 0, f"docs build failed after {elapsed:.0f} s:\n{build.stderr[-6000:]}"
    for page in (
        "index",
        "getting-started",
        "cli",
        "files",
        "models",
        "verification",
        "results",
        "api",
        "seed-equations",
        "gallery/index",
        "gallery/01_hertz_check",
    ):
        assert (tmp_path / f"{page}.html").is_file(), page
    api = (tmp_path / "api" / "generated" / "rigid_dynamics.contact.fastrip.html").read_text(encoding="utf-8")
    assert "FastripModel" in api
    results = (tmp_path / "results.html").read_text(encoding="utf-8")
    assert "Contact bench: run time against error" in results
    print(f"docs built in {elapsed:.1f} s")


def test_the_python_tour_runs(capsys):
    """The snippet shown in docs/getting-started.md (literalinclude of docs/snippets/tour.py) runs as shown."""
    runpy.run_path(str(DOCS / "snippets" / "tour.py"), run_name="__main__")
    out = capsys.readouterr().out
    for name in ("linear", "vermeulen-johnson", "fastsim", "fastrip"):
        assert f"{name} " in out
    assert "reached t = 0.2 s" in out


@pytest.mark.parametrize("path", sorted((ROOT / "examples").glob("*.py")), ids=lambda p: p.stem)
def test_the_gallery_shows_the_code_unchanged(path):
    """Each example's sphinx-gallery script carries the example's code cells verbatim, in order."""
    gallery = wheelrail_docs.example_to_gallery_script(path)
    code = [cell.source.strip("\n") for cell in jupytext.read(path, fmt="py:light").cells if cell.cell_type == "code"]
    position = 0
    for source in code:
        found = gallery.find(source, position)
        assert found >= 0, source[:200]
        position = found + len(source)
    first = jupytext.read(path, fmt="py:light").cells[0].source.splitlines()[0]
    title = first.removeprefix("# ").replace("`", "")
    assert gallery.startswith('r"""\n') and title in gallery.replace("``", "")


def test_markdown_to_rst():
    text = "# Title with `code`\n\nA `span\nover lines`, a [link](https://example.org).\n\n## Part"
    rst = wheelrail_docs.markdown_to_rst(text)
    assert rst.splitlines()[:2] == ["Title with ``code``", "=" * len("Title with ``code``")]
    assert "``span over lines``" in rst and "`link <https://example.org>`__" in rst
    assert rst.splitlines()[-2:] == ["Part", "----"]


def test_the_results_page_has_a_section_per_file():
    files = wheelrail_docs.results_files()
    assert len(files) >= 20 and ROOT / "benchmarks" / "results" / "bench" / "bench.md" in files
    page = wheelrail_docs.results_page([(path, path.read_text(encoding="utf-8")) for path in files])
    for path in files:
        assert f"*From `{path.relative_to(ROOT).as_posix()}`.*" in page or f"## {path.name}" in page
    sections = [line for line in page.splitlines() if line.startswith("## ")]
    assert len(sections) == len(files)
    assert "](../benchmarks/results/bench/time_vs_error-large-spin.png)" in page


README_BEM_LINE = 'solution = wr.solve_case("manchester-a22", "bem")'


@pytest.fixture(scope="module")
def readme_run():
    """The README's Python block (its five-minute tour) executed once, as written: (its namespace, what it printed).

    Shared by the two tests below: the block's `wr.solve_case("manchester-a22", "bem")` is the costliest line of the
    block (about 25 s on the 2-core machine: the BEM refines the final patches to 320 x 320) and the rebalancing
    test checks that very solution instead of solving the case a second time.
    """
    import contextlib
    import io
    import re

    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) == 1
    namespace = {"__name__": "readme"}
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(blocks[0], "README.md", "exec"), namespace)  # noqa: S102
    return blocks[0], namespace, printed.getvalue()


def test_the_readme_python_snippet_runs(readme_run):
    """The README's Python block (its five-minute tour) runs as written: what a new user copies first."""
    _, _, out = readme_run
    assert out.startswith("ok ")


def test_default_bem_rebalances_on_the_grids_that_meet_its_tolerance(readme_run):
    """README's `wheelrail contact manchester-a22 --method bem` (the solution of the README's Python block, which runs
    `wr.solve_case("manchester-a22", "bem")`): at the defaults the final patches are refined until the BEM's
    estimate meets grid_tolerance (the right wheel's joined tread-flange patch 40 x 40 -> 320 x 320, its max pressure
    estimate 20 % -> 1.2 %) and the equilibrium is rebalanced on those grids (the load is carried by the refined
    patches' forces, not the default grid's). A grid the caller names is solved as named.

    Moved here from tests/test_wheelset_case.py so that the case is solved once for both tests (same assertions).
    """
    import dataclasses

    import wheelrail as wr

    block, namespace, _ = readme_run
    # the solution checked is the case's default BEM solve (the line as the README writes it, without its comment)
    assert README_BEM_LINE in [line.partition("#")[0].strip() for line in block.splitlines()]
    solution = namespace["solution"]
    assert solution.success, solution.message
    assert "rebalanced on the grids its patches were refined to" in solution.message
    grids = {side: (result.extra["nx"], result.extra["ny"]) for side, _, _, result in solution.patches}
    assert grids["right"][0] >= 160 and grids["left"][0] >= 80
    for side, _, _, result in solution.patches:
        assert result.status == "ok", (side, result.message)
        assert result.extra["grid_error_estimate"] <= 0.02
    loads = solution.extra["wheel_vertical_load_N"]
    assert all(load == pytest.approx(1.0e4, rel=1e-5) for load in loads.values())
    case = wr.load_case("manchester-a22")
    named = wr.solve_case(dataclasses.replace(case, solver_options={"model": {"nx": 40, "ny": 40}}), "bem")
    assert named.success and "rebalanced" not in named.message
    assert {result.extra["nx"] for _, _, _, result in named.patches} == {40}
    right = next(result for side, _, _, result in named.patches if side == "right")
    assert right.status == "warning" and right.extra["grid_error_estimate"] > 0.1  # 40 x 40 states its 20 %
