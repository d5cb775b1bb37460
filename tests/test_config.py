"""The generic TOML -> frozen dataclass mapping used for scenes."""

from dataclasses import dataclass, field

import pytest

from wheelrail.config import ConfigError, build_dataclass


@dataclass(frozen=True)
class Inner:
    radius_m: float
    order: int = 3

    def __post_init__(self):
        if self.radius_m <= 0:
            raise ValueError(f"radius_m = {self.radius_m!r}: expected > 0")


@dataclass(frozen=True)
class Outer:
    name: str
    inner: Inner
    amplitudes_m: tuple[float, ...] = ()
    optional_m: float | None = None
    enabled: bool = True
    extra: Inner = field(default_factory=lambda: Inner(1.0))


def test_builds_nested_tables():
    got = build_dataclass(Outer, {"name": "a", "inner": {"radius_m": 2}, "amplitudes_m": [1, 2.5], "optional_m": 3})
    assert got == Outer("a", Inner(2.0), (1.0, 2.5), 3.0)
    assert isinstance(got.inner.radius_m, float)


@pytest.mark.parametrize(
    ("table", "pattern"),
    [
        ({"name": "a", "inner": {"radius_m": 1}, "colour": 1}, r"unknown key 'colour' at the top level"),
        ({"name": "a", "inner": {"radius_m": 1, "radus": 2}}, r"unknown key 'inner.radus' in table \[inner\]"),
        ({"name": "a"}, r"missing key 'inner': expected a table \(Inner\)"),
        ({"name": "a", "inner": {}}, r"missing key 'inner.radius_m'"),
        ({"name": "a", "inner": {"radius_m": -1}}, r"\[inner\] radius_m = -1.0: expected > 0"),
        ({"name": "a", "inner": {"radius_m": 1, "order": 2.5}}, r"'inner.order' = 2.5: expected an integer"),
        ({"name": "a", "inner": 5}, r"'inner' = 5: expected a table"),
        ({"name": 5, "inner": {"radius_m": 1}}, r"'name' = 5: expected a string"),
        ({"name": "a", "inner": {"radius_m": 1}, "amplitudes_m": [1, "x"]}, r"'amplitudes_m\[1\]' = 'x'"),
        ({"name": "a", "inner": {"radius_m": float("inf")}}, r"'inner.radius_m' = inf: expected a finite number"),
        ({"name": "a", "inner": {"radius_m": 1}, "enabled": 1}, r"'enabled' = 1: expected true or false"),
    ],
)
def test_errors_name_the_key(table, pattern):
    with pytest.raises(ConfigError, match=pattern):
        build_dataclass(Outer, table)
