"""The tidy time-series table of a dynamics run (rigid_dynamics.wheelset.table) loads in pandas as it is.

Regression test of the export against the recorded arrays it is built from (the NPZ of the same run):
every column equals its slice of the (n, 2, 2) / (n, 12) arrays, CSV and Parquet round-trip exactly.
"""

import numpy as np
import pytest

from rigid_dynamics.wheelset.layout import PATCH_FIELDS
from rigid_dynamics.wheelset.state import STATE_NAMES
from rigid_dynamics.wheelset.table import result_columns, timeseries_columns, write_table
from wheelrail.cli import main


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    assert main(["run", "hunting-conical", "--set", "duration_s=0.2", "--out", str(out), "--quiet", "--no-plots"]) == 0
    return out


def test_set_overrides_the_scene_and_is_recorded(run_dir, tmp_path, capsys):
    import json

    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["overrides"] == {"duration_s": 0.2} and summary["simulated_time_s"] == pytest.approx(0.2)
    assert main(["run", "hunting-conical", "--set", "speed_m_per_s=-1", "--out", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("wheelrail: error:") and "speed_m_per_s" in err and len(err.strip().splitlines()) == 1


def test_csv_and_parquet_load_in_pandas_and_match_the_npz(run_dir):
    import json

    import pandas as pd

    summary = json.loads((run_dir / "summary.json").read_text())
    assert {"timeseries.csv", "timeseries.parquet"} <= set(summary["files"])
    assert summary["startup_s"] >= 0 and summary["setup_s"] >= 0  # reported apart from the model's wall_time_s

    csv = pd.read_csv(run_dir / "timeseries.csv")
    parquet = pd.read_parquet(run_dir / "timeseries.parquet")
    assert list(csv.columns) == list(parquet.columns)
    assert csv.columns[0] == "time_s" and set(STATE_NAMES) <= set(csv.columns)
    assert all(pd.api.types.is_float_dtype(dtype) for dtype in csv.dtypes)
    with np.load(run_dir / "timeseries.npz") as data:
        np.testing.assert_array_equal(csv["time_s"], data["t"])
        np.testing.assert_array_equal(parquet["roll_rad"], data["states"][:, 4])
        for name in PATCH_FIELDS:
            np.testing.assert_array_equal(csv[f"right_tread_{name}"], data[f"patch_{name}"][:, 1, 0])
            np.testing.assert_array_equal(parquet[f"left_second_{name}"], data[f"patch_{name}"][:, 0, 1])
        np.testing.assert_array_equal(csv["left_wheel_contact_force_z_N"], data["contact_force_N"][:, 0, 2])
        np.testing.assert_array_equal(parquet["work_contact_J"], data["work_contact_J"])
    # every column name ends in a unit or says it is a code (or is a dimensionless creepage or residual)
    for name in csv.columns:
        unit = name.rsplit("_", 1)[-1]
        assert unit in {"s", "m", "m2", "Pa", "rad", "N", "Nm", "J", "per_s", "per_m", "code"} or any(
            word in name for word in ("creepage", "residual")
        ), name


def test_result_methods_and_bad_suffix(tmp_path):
    import dataclasses

    from rigid_dynamics.wheelset import simulate
    from wheelrail.scenes import load_scene

    scene = dataclasses.replace(load_scene("hunting-conical"), duration_s=0.05)
    result = simulate(scene)
    frame = result.to_dataframe()
    assert len(frame) == len(result.t) and frame.columns[0] == "time_s"
    assert set(result.to_dict()["timeseries"]) == set(result_columns(result))
    assert "status='ok'" in repr(result) and len(repr(result)) < 400
    with pytest.raises(ValueError, match=r"expected a \.csv or \.parquet file"):
        write_table(result, tmp_path / "series.xlsx")
    with pytest.raises(ValueError, match=r"expected \(n, 12\)"):
        timeseries_columns(np.zeros(3), np.zeros((3, 5)), {}, np.zeros((3, 2, 3)))
