"""comparisons.contact_plots.plot_contact_fields: generic over ContactResult.fields (smoke tests of the files)."""

import dataclasses

import pytest

from comparisons.contact_plots import plot_contact_fields
from rigid_dynamics.contact.bem.model import BemModel
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import Material


@pytest.fixture(scope="module")
def result():
    return BemModel().solve(
        ContactGeometry.quadric(0.46, 0.3),
        Creepage(0.0, -6e-4, 0.6),
        Material(),
        normal_force_N=5e4,
        options={"nx": 16, "ny": 16},
    )


def test_full_fields_png(result, tmp_path):
    path = plot_contact_fields(result, tmp_path / "sub" / "fields.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_pressure_only_png(result, tmp_path):
    fields = dataclasses.replace(result.fields, traction_long_Pa=None, traction_lat_Pa=None, slip_m_per_s=None)
    fields = dataclasses.replace(fields, in_slip=None, in_contact=None)
    path = plot_contact_fields(dataclasses.replace(result, fields=fields), tmp_path / "p.png")
    assert path.stat().st_size > 1000


def test_no_fields_raises(result, tmp_path):
    with pytest.raises(ValueError, match="fields is None"):
        plot_contact_fields(dataclasses.replace(result, fields=None), tmp_path / "x.png")
