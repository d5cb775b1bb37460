"""``auto``'s thresholds: the derivation, the choice against the bench data, the records, bad input.

The bench data are the stored thresholds' own sources, kept in the thresholds file: the rows of the bench run of
the tangential rungs on the named cases and of the creep sweep (BEM Richardson references). The re-derivation
test runs the tangential rungs of a quick bench and the quick sweep now (about a minute) and compares.
"""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from rigid_dynamics.contact.auto import (
    AUTO_RUNGS,
    FEATURES,
    LEVELS,
    choose_rung,
    derive_thresholds,
    fastsim_rung,
    level_for,
    load_thresholds,
)

ROOT = Path(__file__).resolve().parents[1]


def _feat(**kw):
    return {f: kw.get(f, 0.0) for f in FEATURES}


def test_derive_box_stops_before_a_missed_case():
    """Hand-made data: linear meets 5 % at w' 0.01, 0.02 and 0.3 but misses at 0.1; the box ends at 0.02."""
    features = {
        "a": _feat(saturation=0.01),
        "b": _feat(saturation=0.02),
        "c": _feat(saturation=0.1),
        "d": _feat(saturation=0.3),
    }
    errors = {"a": 0.01, "b": 0.03, "c": 0.2, "d": 0.04}
    rows = [
        {"case": c, "model": "linear", "resolution": "-", "status": "ok", "error": str(e)} for c, e in errors.items()
    ]
    rows.append({"case": "a", "model": "bem", "resolution": "16x16", "status": "ok", "error": "0.5"})  # ignored
    out = derive_thresholds(rows, features, levels=(0.05, 0.02))
    lin = out["levels"]["0.05"]["linear"]
    assert lin["thresholds"]["saturation"] == 0.02 and lin["limited_by"] == "c"
    assert lin["cases_in_box"] == ["a", "b"] and lin["cases_missed"] == ["c"]
    assert out["levels"]["0.02"]["linear"]["thresholds"]["saturation"] == 0.01
    assert set(out["levels"]["0.05"]) == {"linear"}
    # a failed run (status not ok) is a miss even with a small error
    rows[0]["status"] = "failed"
    assert derive_thresholds(rows, features, levels=(0.05,))["levels"]["0.05"]["linear"]["thresholds"] is None


def test_levels_and_fastsim_grids():
    data = load_thresholds()
    assert level_for(0.05, data) == "0.05" and level_for(0.07, data) == "0.05" and level_for(0.5, data) == "0.1"
    assert level_for(0.005, data) is None
    level = data["levels"]["0.05"]
    assert fastsim_rung(20, 20, level) == "fastsim 20x20"
    assert fastsim_rung(30, 25, level) == "fastsim 20x20"  # finest bench grid with no more elements
    assert fastsim_rung(3, 3, level) is None
    choice = choose_rung(_feat(saturation=1e-4), 0.005, data=data)
    assert choice["model"] == "bem" and "below the smallest measured level" in choice["reason"]


def _measured():
    """(case, rung) -> error from the stored thresholds' own data: the bench rows and the sweep rows."""
    data = load_thresholds()
    out = {}
    for row in [*data["bench_rows"], *data["sweep_rows"]]:
        err = row["error"]
        err = None if err in (None, "") or row["status"] != "ok" else float(err)
        rung = row["model"] if row["resolution"] in ("-", "") else f"{row['model']} {row['resolution']}"
        out[(row["case"], rung)] = err
    return data, out


@pytest.mark.parametrize("level", LEVELS)
def test_choice_meets_the_tolerance_on_every_measured_case(level):
    """On every bench and sweep case, the rung auto picks at a tolerance level was measured within it there; and a
    case the bench puts in linear's box (e.g. linear met 5 % there) gets linear.
    """
    data, measured = _measured()
    feats = data["case_features"]
    for case, f in feats.items():
        choice = choose_rung(f, level, data=data)
        if choice["model"] == "bem":
            continue
        err = measured[(case, choice["rung"])]
        assert err is not None and err <= level, (case, choice)
    linear = data["levels"][f"{level:g}"]["linear"]
    assert linear["cases_in_box"], "the bench shows linear within every level on the small-creep cases"
    for case in linear["cases_in_box"]:
        assert measured[(case, "linear")] <= level
        assert choose_rung(feats[case], level, data=data)["model"] == "linear"


def test_known_cases_from_the_bench():
    """Named cases by what the bench measured: small creep -> linear at 5 %; CONTACT's large spin (VJ 15 %, FASTSIM
    5.1 % off) -> bem at 5 %; the wheel flat (every analytic rung 28 % off) -> bem even at 10 %.
    """
    data = load_thresholds()
    feats = data["case_features"]
    assert choose_rung(feats["creep-long-small"], 0.05, data=data)["model"] == "linear"
    assert choose_rung(feats["large-spin"], 0.05, data=data)["model"] == "bem"
    assert choose_rung(feats["wheel-flat"], 0.10, data=data)["model"] == "bem"
    assert choose_rung(feats["creep-long-saturated"], 0.05, data=data)["model"] == "vermeulen-johnson"


def test_stored_thresholds_name_their_bench_run():
    data = load_thresholds()
    bench = data["sources"]["bench"]
    for key in ("commit", "date", "machine", "command", "cases"):
        assert bench.get(key), key
    for key in ("date", "commit", "machine", "command"):
        assert data["derived"].get(key), key
    assert "a22-tread" in bench["cases"] and data["sources"]["sweep"]["max_reference_error"] < 0.02


@pytest.mark.slow
def test_rederive_from_a_quick_bench_matches_the_stored_thresholds():
    """Regression: the tangential rungs of ``wheelrail bench --quick`` and the quick sweep, run now, give the stored
    boxes for the rungs both hold (linear, vermeulen-johnson, fastsim 10x10 and 20x20).

    Tolerance: the same cases in each box and thresholds equal to 1e-6 relative. Thresholds are features of measured
    cases (no fit), and errors do not depend on timing, so a re-run on the same code reproduces them to round-off;
    a change here means the rungs' errors or the features moved since the stored bench run (re-derive the file).
    """
    from comparisons.auto_thresholds import thresholds_document

    stored = load_thresholds()
    fresh = thresholds_document(None, quick=True, command="tests/test_auto_thresholds.py")
    for level, rungs in fresh["levels"].items():
        for rung, entry in rungs.items():
            old = stored["levels"][level][rung]
            assert entry["cases_in_box"] == old["cases_in_box"], (level, rung)
            if entry["thresholds"] is None:
                assert old["thresholds"] is None
                continue
            for f in FEATURES:
                assert entry["thresholds"][f] == pytest.approx(old["thresholds"][f], rel=1e-6, abs=1e-12), (
                    level,
                    rung,
                    f,
                )


def test_records_in_the_contact_json(tmp_path):
    from wheelrail.cli import main

    out = tmp_path / "c"
    assert main(["contact", "hertz-quadric", "--method", "auto", "--out", str(out)]) == 0
    (summary,) = out.rglob("summary.json")
    text = summary.read_text()
    for key in (
        "auto_features",
        "auto_rung",
        "auto_level",
        "auto_deciding_feature",
        "auto_thresholds",
        "selection_reason",
    ):
        assert f'"{key}"' in text, key
    doc = json.loads(text)

    def find(node):
        if isinstance(node, dict):
            if "auto_features" in node:
                return node
            for v in node.values():
                if (hit := find(v)) is not None:
                    return hit
        if isinstance(node, list):
            for v in node:
                if (hit := find(v)) is not None:
                    return hit
        return None

    extra = find(doc)
    assert set(extra["auto_features"]) == set(FEATURES)
    assert extra["auto_rung"] in ("linear", "vermeulen-johnson", "bem") or extra["auto_rung"].startswith("fastsim")


def test_records_in_the_dynamics_time_series():
    from rigid_dynamics.wheelset.simulate import simulate, timeseries_arrays
    from wheelrail.config import read_toml
    from wheelrail.scenes import parse_scene, resolve_scene_path

    path = resolve_scene_path("hunting-conical")
    doc = read_toml(path, "scene file")
    doc.update({"duration_s": 0.01, "contact_model": "auto"})
    result = simulate(parse_scene(doc, base_dir=path.parent))
    assert result.status == "ok"
    arrays = timeseries_arrays(result)
    normal = arrays["patch_normal_force_N"]
    rung = arrays["patch_auto_rung"]
    touching = np.nan_to_num(normal) > 0
    assert touching.any() and np.all(np.isfinite(rung[touching])) and np.all(np.isnan(rung[~touching]))
    assert list(arrays["auto_rung_names"]) == list(AUTO_RUNGS)
    sat = arrays["patch_auto_saturation"][touching]
    assert np.all(sat >= 0) and np.all(np.isfinite(arrays["patch_auto_deciding_threshold"][touching]))
    # the recorded choice is the one choose_rung gives for the recorded features
    data = load_thresholds()
    k = tuple(np.argwhere(touching)[0])
    feats = {f: float(arrays[f"patch_auto_{f}"][k]) for f in FEATURES}
    expected = choose_rung(feats, result.scene.contact_tolerance, data=data)["model"]
    assert AUTO_RUNGS[int(rung[k])] == expected


def test_bad_inputs_exit_2(tmp_path, capsys):
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import derive_auto_thresholds

    assert derive_auto_thresholds.main(["--bench-csv", str(tmp_path / "missing.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("wheelrail: error: --bench-csv")
    from wheelrail.cli import main

    case = tmp_path / "c.toml"
    case.write_text(
        'name = "x"\n[material]\nshear_modulus_Pa = 82e9\npoisson_ratio = 0.28\nfriction_coefficient = 0.3\n'
        '[geometry]\nkind = "quadric"\nradius_long_m = 0.46\nradius_lat_m = 0.3\n[loading]\nnormal_force_N = 1e4\n'
        "[kinematics]\ncreepage_long = 1e-4\n[solver]\ntolerance = 0.0\n"
    )
    assert main(["contact", str(case), "--method", "auto", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("wheelrail: error:") and "tolerance" in err[-1]
    assert math.isfinite(load_thresholds()["levels"]["0.05"]["linear"]["thresholds"]["saturation"])
