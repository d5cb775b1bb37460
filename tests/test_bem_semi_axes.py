"""Semi-axes reported by the bem model on elliptic patches, against Hertz's closed form.

Independent reference: the Hertz semi-axes of rigid_dynamics.contact.hertz, which are themselves
verified against an independent quadrature (tests/test_hertz.py). The BEM estimates them from a
least-squares fit of p^2 over the contact elements, so the error is far below the element size.
"""

import pytest

from rigid_dynamics.contact.bem.model import BemModel
from rigid_dynamics.contact.hertz import hertz_solve_batch
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.materials import STEEL


@pytest.mark.parametrize(("radius_long_m", "radius_lat_m"), [(0.46, 0.3), (0.3, 0.3), (0.46, 0.08), (0.1, 0.6)])
def test_semi_axes_match_hertz_well_below_the_element_size(radius_long_m, radius_lat_m):
    geometry = ContactGeometry.quadric(radius_long_m, radius_lat_m)
    result = BemModel().solve(geometry, Creepage(), STEEL, normal_force_N=1e4, options={"nx": 40, "ny": 40})
    hertz = hertz_solve_batch(
        geometry.curvature_long_1_per_m,
        geometry.curvature_lat_1_per_m,
        normal_force_N=1e4,
        shear_modulus_Pa=STEEL.shear_modulus_Pa,
        poisson_ratio=STEEL.poisson_ratio,
    )
    a, b = float(hertz.semi_axis_long_m), float(hertz.semi_axis_lat_m)
    dx = result.extra["dx_m"]
    assert result.semi_axis_long_m == pytest.approx(a, rel=5e-3)
    assert result.semi_axis_lat_m == pytest.approx(b, rel=5e-3)
    # far below the quantisation of the element extents (about dx/2)
    assert abs(result.semi_axis_long_m - a) < 0.1 * dx
