"""How the reports read a model's stated error (comparisons.stated_errors): the FEA's layout, a model that states
none (never read as 0) and the agreement rule |a - b| <= (e_a + e_b) max(|a|, |b|).
"""

from types import SimpleNamespace

import pytest

from comparisons.stated_errors import agreement, largest, side_stated_errors, stated_errors


def _result(info=None, attribute=None):
    extra = {} if info is None else {"discretisation_error": info}
    return SimpleNamespace(extra=extra, discretisation_error=attribute)


def test_reads_the_fea_layout_and_an_attribute():
    fea = _result({"estimated": True, "relative_error": {"max_pressure": 0.01, "contact_area": 0.02, "approach": 0.1}})
    assert stated_errors(fea) == {"max_pressure": 0.01, "contact_area": 0.02}
    assert stated_errors(_result(attribute={"max_pressure": 0.003})) == {"max_pressure": 0.003}
    assert stated_errors(_result()) is None
    assert stated_errors(_result({"estimated": False, "reason": "mesh_tolerance is None"})) is None


def test_a_side_is_only_as_known_as_its_least_known_patch():
    a = _result({"relative_error": {"max_pressure": 0.01, "normal_force": 0.02}})
    b = _result({"relative_error": {"max_pressure": 0.03, "normal_force": 0.01}})
    assert side_stated_errors([a, b]) == {"normal_force": 0.02, "max_pressure": 0.03}
    assert side_stated_errors([a, _result()]) is None
    assert largest({"normal_force": 0.02, "max_pressure": 0.03}) == 0.03
    assert largest(None) is None


def test_agreement_within_the_sum_of_the_stated_errors():
    assert agreement(1000.0, 1030.0, 0.02, 0.015) == pytest.approx(
        {"difference": 30 / 1030, "allowed": 0.035, "agree": True}
    )
    assert agreement(1000.0, 1100.0, 0.02, 0.015)["agree"] is False
    assert agreement(1000.0, 1100.0, 0.02, None)["agree"] is None
