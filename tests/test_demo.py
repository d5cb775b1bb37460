"""The demo on a short run (0.1 s of the polygonal-wheel scene, no FEA): the peak patch and the report.

Smoke/regression test of the demo driver; the physics of each step is tested elsewhere.
"""

import pytest

from comparisons import compare
from wheelrail.cli import main
from wheelrail.scenes import resolve_scene_path


@pytest.mark.slow
def test_short_demo_writes_the_report(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(compare, "CUT_POINTS", (11, 7))
    text = resolve_scene_path("polygonal-wheel").read_text().replace("duration_s = 2.0", "duration_s = 0.1")
    scene = tmp_path / "short.toml"
    scene.write_text(text)
    out = tmp_path / "demo"
    assert main(["demo", str(scene), "--models", "hertz", "fastsim", "bem", "--out", str(out)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[-4].startswith("report: ") and lines[-3].startswith("run: 0.1 s")
    assert "max pressure [MPa] Hertz" in lines[-2] and "subsurface max von Mises" in lines[-1]
    report = (out / "report.md").read_text()
    assert "## Time series" in report and "compare/pressure.png" in report
    assert (out / "report.html").exists() and (out / "compare" / "subsurface.png").exists()


@pytest.mark.parametrize(
    ("args", "text"),
    [
        (["--tolerance", "0"], "wheelrail: error: --tolerance 0.0: expected a finite number > 0"),
        (["--tolerance", "nan"], "wheelrail: error: --tolerance nan: expected a finite number > 0"),
        (["--contact-model", "magic"], "wheelrail: error: --contact-model 'magic': expected one of"),
    ],
)
def test_demo_bad_options(tmp_path, capsys, args, text):
    """Bad demo options: one error line naming the option, the value and what was expected; exit 2; no output."""
    out = tmp_path / "demo"
    assert main(["demo", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(text)
    assert not out.exists()


@pytest.mark.slow
def test_demo_says_why_it_exits_1(tmp_path, monkeypatch, capsys):
    """A rung short of its own tolerance (here the FEA's mesh-tolerance-not-met, as the full demo's FEA can end) makes
    the demo exit 1 with one line naming the rung and its status, not a bare exit status."""
    monkeypatch.setattr(compare, "CUT_POINTS", (11, 7))
    real = compare.run_compare

    def short_of_tolerance(*args, **kwargs):
        result = real(*args, **kwargs)
        result["models"]["fastsim"]["status"] = "mesh-tolerance-not-met"
        return {**result, "success": False}

    monkeypatch.setattr(compare, "run_compare", short_of_tolerance)
    text = resolve_scene_path("polygonal-wheel").read_text().replace("duration_s = 2.0", "duration_s = 0.1")
    scene = tmp_path / "short.toml"
    scene.write_text(text)
    assert main(["demo", str(scene), "--models", "hertz", "fastsim", "--out", str(tmp_path / "demo")]) == 1
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("demo: ended with a rung short of its own tolerance or failed (exit 1): ")
    assert "fastsim mesh-tolerance-not-met" in last
