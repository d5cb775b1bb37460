"""The contact tables' disk cache (rigid_dynamics/wheelset/providers/table_cache.py): a second build loads the file
and gives the same table bit for bit (a regression test of the cache against the build it stores); a corrupted
file is rebuilt with a note; a changed parameter is another key."""

import dataclasses

import numpy as np
import pytest

from rigid_dynamics.wheelset.parameters import TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers import ProfileSectionProvider, table_cache
from rigid_dynamics.wheelset.providers.tables import TableProvider

WHEELSET = WheelsetParameters()
TRACK = TrackGeometry(wheel_profile="S1002", rail_profile="UIC60", rail_inclination_rad=0.025)
SMALL = {"lateral_range_m": 0.004, "lateral_step_m": 1e-3, "roll_points": 3}


def _tables(track=TRACK):
    section = ProfileSectionProvider(WHEELSET, track)
    return TableProvider(section, WHEELSET.nominal_radius_m, cache_parameters=(WHEELSET, track), **SMALL)


@pytest.fixture(autouse=True)
def _cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("WHEELRAIL_CACHE_DIR", str(tmp_path))


def test_second_build_loads_the_same_table(tmp_path):
    first = _tables()
    assert first.cache.status == "built" and first.cache.note == ""
    assert first.cache.path.parent == tmp_path / "tables" and first.cache.path.exists()
    second = _tables()
    assert second.cache.status == "hit"
    np.testing.assert_array_equal(second.table, first.table)
    plain = TableProvider(ProfileSectionProvider(WHEELSET, TRACK), WHEELSET.nominal_radius_m, **SMALL)
    assert plain.cache is None
    np.testing.assert_array_equal(plain.table, first.table)


@pytest.mark.parametrize("damage", ["truncate", "garbage"])
def test_corrupted_file_is_rebuilt_with_a_note(damage):
    first = _tables()
    path = first.cache.path
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2] if damage == "truncate" else b"not a numpy file")
    again = _tables()
    assert again.cache.status == "rebuilt"
    assert str(path) in again.cache.note and "rebuilt" in again.cache.note
    np.testing.assert_array_equal(again.table, first.table)
    assert _tables().cache.status == "hit"  # rewritten whole


def test_changed_parameter_is_another_key():
    first = _tables()
    other = _tables(dataclasses.replace(TRACK, rail_inclination_rad=1.0 / 20.0))
    assert other.cache.status == "built" and other.cache.path != first.cache.path
    assert not np.array_equal(other.table, first.table)


def test_unwritable_folder_costs_only_the_saving(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("WHEELRAIL_CACHE_DIR", str(blocker))  # its 'tables' folder cannot be made
    built = _tables()
    assert built.cache.status == "built" and built.cache.path is None and "not cached" in built.cache.note
    assert table_cache.cache_dir() == blocker / "tables"
