"""The public API of ``import wheelrail`` and the result methods (to_dict, to_dataframe, repr).

Physics checks: solve_batch with scalar curvatures and an array of creepages equals the one-patch models
of the registry patch by patch (a second code path, regression); combined_from_pair gives Hertz's
combined modulus of two different materials, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson 1985, eq 4.22).
"""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import wheelrail as wr

ROOT = Path(__file__).resolve().parents[1]


def test_every_public_name_resolves_and_has_a_description():
    descriptions = wr.api()
    assert set(descriptions) == set(wr.__all__) - {"api", "__version__"}
    for name in descriptions:
        assert getattr(wr, name) is not None, name
        assert descriptions[name] and "\n" not in descriptions[name]
    for needed in ("load_profile", "load_case", "solve_case", "load_scene", "simulate", "get_model", "plot_patch"):
        assert needed in wr.__all__
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        wr.nope  # noqa: B018


def test_import_wheelrail_is_light():
    heavy = {"numpy", "numba", "scipy", "matplotlib", "pandas", "rigid_dynamics"}
    code = f"import sys, wheelrail; print(sorted(m for m in sys.modules if m.split('.')[0] in {heavy!r}))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_solve_batch_broadcasts_scalar_curvatures_with_array_creepages():
    steel = wr.STEEL
    creepages = np.linspace(-2e-3, 2e-3, 5)
    for method in ("hertz", "linear", "vermeulen-johnson", "fastsim", "auto"):
        batch = wr.solve_batch(method, 1.087, 1.667, creepages, 0.0, 0.2, steel, normal_force_N=1e4)
        assert batch.creep_force_long_N.shape == batch.normal_force_N.shape == (5,)
        for k, xi in enumerate(creepages):
            one = wr.get_model(method).solve(
                wr.ContactGeometry(curvature_long_1_per_m=1.087, curvature_lat_1_per_m=1.667),
                wr.Creepage(xi, 0.0, 0.2),
                steel,
                normal_force_N=1e4,
            )
            assert batch.creep_force_long_N[k] == pytest.approx(one.creep_force_long_N, rel=1e-9, abs=1e-9), method
            assert batch.semi_axis_long_m[k] == pytest.approx(one.semi_axis_long_m, rel=1e-12)
    frame = batch.to_dataframe()
    assert len(frame) == 5 and "creep_force_long_N" in frame.columns
    with pytest.raises(ValueError, match=r"longitudinal \(4,\).*expected shapes that broadcast together"):
        wr.solve_batch("linear", np.ones(3), 1.0, np.ones(4), 0.0, 0.0, steel, normal_force_N=1e4)


def test_combined_from_pair_gives_hertz_combined_modulus():
    e1, nu1, e2, nu2 = 210e9, 0.3, 70e9, 0.33
    pair = wr.combined_from_pair(e1 / (2 * (1 + nu1)), nu1, e2 / (2 * (1 + nu2)), nu2, 0.3)
    e_star = 1.0 / ((1 - nu1**2) / e1 + (1 - nu2**2) / e2)
    assert pair.combined_modulus_Pa == pytest.approx(e_star, rel=1e-12)
    same = wr.combined_from_pair(82e9, 0.28, 82e9, 0.28, 0.3)
    assert same.shear_modulus_Pa == pytest.approx(82e9) and same.poisson_ratio == pytest.approx(0.28)
    with pytest.raises(ValueError, match=r"poisson_ratio_2 = 0.6: expected a value in \(-1, 0.5\)"):
        wr.combined_from_pair(82e9, 0.28, 82e9, 0.6, 0.3)


def test_contact_results_have_dict_dataframe_and_short_repr():
    solution = wr.solve_case(wr.load_case("hertz-quadric"), "fastsim")
    record = solution.to_dict()
    assert record["patches"][0]["normal_force_N"] == pytest.approx(solution.patches[0][3].normal_force_N)
    frame = solution.to_dataframe()
    assert list(frame["side"]) == ["single"] and "max_pressure_Pa" in frame.columns
    result = solution.patches[0][3]
    as_dict = result.to_dict()
    assert as_dict["creepage_long"] == result.creepage.longitudinal and as_dict["fields"]["pressure_Pa"] is not None
    row = result.to_dataframe()
    assert len(row) == 1 and row["normal_force_N"][0] == result.normal_force_N
    assert "method='fastsim'" in repr(result) and len(repr(result)) < 400
    assert "CaseSolution(method='fastsim'" in repr(solution) and len(repr(solution)) < 400


def test_notebook_use_names_accepted_rich_display_and_figures_returned():
    """In a notebook: case and scene names are accepted where objects were (an AttributeError before), results show
    as Markdown tables, and the plot functions return a Figure when no path is given, without switching the
    caller's matplotlib backend (a notebook's inline backend stays)."""
    import matplotlib

    backend = matplotlib.get_backend()
    solution = wr.solve_case("hertz-quadric", "fastsim")
    table = solution._repr_markdown_()
    assert "| single | ok |" in table and "p max [MPa]" in table
    result = solution.patches[0][3]
    assert "max pressure" in result._repr_markdown_() and "MPa" in result._repr_markdown_()
    figure = wr.plot_patch(result)
    assert type(figure).__name__ == "Figure" and figure.axes
    assert wr.plot_patch(wr.solve_case("hertz-quadric", "hertz").patches[0][3]).axes
    assert matplotlib.get_backend() == backend


def test_simulate_takes_a_scene_file_name(tmp_path):
    """wr.simulate reads a scene given by its file (or embedded name) instead of failing on a string."""
    text = wr.embedded_scenes()["hunting-conical"].read_text()
    lines = [("duration_s = 0.02" if line.startswith("duration_s") else line) for line in text.splitlines()]
    path = tmp_path / "short.toml"
    path.write_text("\n".join(lines) + "\n")
    run = wr.simulate(str(path))
    assert run.success and run.t[-1] == pytest.approx(0.02)
