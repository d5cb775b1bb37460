"""Contact-geometry providers and the contact evaluation of the wheelset model.

Independent references: closed forms of a cone on a circular rail head (derived in the test docstrings),
a second method (the 2-D profile section on analytic cone/circle surfaces vs the analytic conical provider),
exact symmetric cases of the running-direction irregularities, and the project's own contact models and
creepage/kinematics modules, which the fast paths of the dynamics must reproduce.
"""

import math

import numpy as np
import pytest
from wheelset_surfaces import conical_surfaces

from rigid_dynamics.contact.creepage import patch_kinematics
from rigid_dynamics.contact.registry import get_model
from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.kinematics import angular_velocity, wheelset_rotation
from rigid_dynamics.materials import STEEL
from rigid_dynamics.wheelset.parameters import Irregularities, TrackGeometry, WheelsetParameters
from rigid_dynamics.wheelset.providers import ConicalProvider, ProfileSectionProvider, TableProvider
from rigid_dynamics.wheelset.wheelset_model import _creepages, rotation_and_rates

R0, E0, LAM = 0.46, 0.75, 0.05


def conical(rail_radius=0.3, irregularities=None):
    return ConicalProvider(WheelsetParameters(), TrackGeometry(rail_head_radius_m=rail_radius), irregularities)


@pytest.mark.parametrize("shift", [-0.008, -0.002, 0.0, 0.003, 0.01])
def test_conical_lateral_shift_closed_form(shift):
    """theta = psi = 0, z = -r0: q_R,L = +-lambda y / sqrt(1 + lambda^2), r_R,L = r0 +- (lambda y - lambda^2 q_R c).

    The wheel's lowest line moves laterally by y; the rail point T whose slope equals the cone's stays put,
    so at touch the wheel meets it at y_d = +-(e0 - y), radius r0 +- lambda y (the exact linear law). Here the
    line also passes lambda y lower (right) / higher (left) at T: vertical overlap lambda y, normal overlap
    q = lambda y c with c = cos(atan(lambda)) = 1/sqrt(1 + lambda^2); the reported point is the foot of the
    perpendicular from the rail-head centre, q n_l = q (lambda, 1) c beyond T, which moves it by
    q lambda c along y and changes the radius by -lambda^2 q c.
    """
    p = conical().patches(np.array([0.0, shift, -R0]), 0.0, 0.0, 0.0)
    c = 1 / math.sqrt(1 + LAM**2)
    q = LAM * shift * c
    expected = [R0 - (LAM * shift - LAM**2 * q * c), R0 + (LAM * shift - LAM**2 * q * c)]
    np.testing.assert_allclose(p.rolling_radius_m, expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(p.approach_m, [-q, q], rtol=0, atol=1e-15)
    np.testing.assert_allclose(p.contact_angle_rad, math.atan(LAM), rtol=1e-13)
    np.testing.assert_allclose(p.curvature_long_1_per_m, 0.5 / (p.rolling_radius_m * math.sqrt(1 + LAM**2)))
    np.testing.assert_allclose(p.normal[1], [0.0, -LAM / math.sqrt(1 + LAM**2), -1 / math.sqrt(1 + LAM**2)], atol=1e-15)


def test_conical_approach_is_linear_in_height():
    """dq/dz = cos(gamma) = 1/sqrt(1 + lambda^2) exactly (the line moves along z, the circle stays)."""
    provider = conical()
    a = provider.patches(np.array([0.0, 0.002, -R0]), 0.0, 0.001, 0.0).approach_m
    b = provider.patches(np.array([0.0, 0.002, -R0 + 1e-4]), 0.0, 0.001, 0.0).approach_m
    cos_gamma = np.array(
        [math.cos(math.atan(LAM) + s * 0.001) for s in (1, -1)]
    )  # roll turns the cone's normal by -+theta on the left/right
    np.testing.assert_allclose((b - a) / 1e-4, cos_gamma, rtol=1e-9)


@pytest.mark.parametrize(("shift", "roll"), [(0.0, 0.0), (0.004, 3e-4), (-0.007, -1e-3), (0.012, 2e-3)])
def test_profile_section_matches_conical(shift, roll):
    """Second method: vertical-gap minimisation on sampled cone/circle surfaces vs the exact line-circle contact."""
    ws, tr = WheelsetParameters(), TrackGeometry(rail_head_radius_m=0.3)
    exact = ConicalProvider(ws, tr).patches(np.array([0.0, shift, -R0 + 5e-5]), 0.0, roll, 0.0)
    section = ProfileSectionProvider(ws, tr, surfaces=conical_surfaces()).patches(
        np.array([0.0, shift, -R0 + 5e-5]), 0.0, roll, 0.0
    )
    tread = section.slot == 0
    np.testing.assert_allclose(section.approach_m[tread], exact.approach_m, rtol=0, atol=1e-9)
    np.testing.assert_allclose(section.rolling_radius_m[tread], exact.rolling_radius_m, rtol=0, atol=1e-5)
    np.testing.assert_allclose(section.contact_angle_rad[tread], exact.contact_angle_rad, rtol=0, atol=1e-6)
    np.testing.assert_allclose(section.curvature_lat_1_per_m[tread], exact.curvature_lat_1_per_m, rtol=1e-6)
    assert np.all(section.approach_m[~tread] < 0)  # a cone has no second contact


def test_table_matches_conical_off_grid():
    provider = conical()
    table = TableProvider(
        provider, R0, lateral_range_m=0.01, lateral_step_m=2.5e-4, roll_range_rad=0.004, roll_points=9
    )
    rng = np.random.default_rng(3)
    for _ in range(20):
        y, theta, z = rng.uniform(-0.009, 0.009), rng.uniform(-0.003, 0.003), -R0 + rng.uniform(-2e-4, 2e-4)
        a = provider.patches(np.array([0.0, y, z]), 0.0, theta, 0.0)
        b = table.patches(np.array([0.0, y, z]), 0.0, theta, 0.0)
        np.testing.assert_allclose(b.approach_m, a.approach_m, rtol=0, atol=3e-7)
        np.testing.assert_allclose(b.rolling_radius_m, a.rolling_radius_m, rtol=0, atol=1e-6)
        np.testing.assert_allclose(b.normal, a.normal, rtol=0, atol=1e-6)


def test_running_irregularities_symmetric_extremes():
    """At a symmetric extreme under the wheel the approach changes by the irregularity times cos(gamma).

    Polygon order 3 with its crest at the lowest point (alpha = pi/2 - phi = 0): +A. Rounded flat centred at
    the lowest point (convex: d < L^2/(2 pi^2 r0)): -d. Rail corrugation crest (N_irr = -A at x = w/2): +A.
    """
    centre = np.array([0.0, 0.0, -R0 + 1e-4])
    base = conical().patches(centre, 0.0, 0.0, 0.5 * math.pi).approach_m
    cos_gamma = 1 / math.sqrt(1 + LAM**2)
    polygon = conical(irregularities=Irregularities(polygon_order=3, polygon_amplitude_m=3e-4))
    np.testing.assert_allclose(
        polygon.patches(centre, 0.0, 0.0, 0.5 * math.pi).approach_m - base, 3e-4 * cos_gamma, atol=1e-12
    )
    flat = Irregularities(flat_length_m=0.1, flat_depth_m=5e-4, flat_angle_rad=0.0)
    got = conical(irregularities=flat).patches(centre, 0.0, 0.0, 0.5 * math.pi).approach_m - base
    np.testing.assert_allclose(got, -5e-4 * cos_gamma, atol=1e-12)
    corrugation = Irregularities(corrugation_wavelength_m=0.05, corrugation_amplitude_m=3e-5, side="right")
    crest = centre + np.array([0.025, 0.0, 0.0])
    got = conical(irregularities=corrugation).patches(crest, 0.0, 0.0, 0.0).approach_m - base
    np.testing.assert_allclose(got, [0.0, 3e-5 * cos_gamma], atol=1e-12)


def test_rotation_and_rates_match_kinematics():
    angles = (0.1, -0.05, 2.3)
    rates = (0.7, -0.4, 40.0)
    c_d, rzx, omega = rotation_and_rates(*angles, *rates)
    np.testing.assert_allclose(c_d, wheelset_rotation(*angles), atol=1e-15)
    np.testing.assert_allclose(rzx, wheelset_rotation(angles[0], angles[1], 0.0), atol=1e-15)
    np.testing.assert_allclose(omega, angular_velocity(angles[0], angles[1], *rates), atol=1e-13)


def test_creepages_match_contact_creepage_module():
    rng = np.random.default_rng(7)
    lever = rng.normal(size=(3, 3)) * 0.5
    normal = np.array([[0.02, -0.05, -1.0], [0.0, 0.6, -0.8], [-0.01, 0.03, -1.0]])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    omega = np.array([0.3, -43.0, 0.2])
    v_c = np.array([20.0, 0.1, -0.02])
    frames, speed, xi, eta, spin = _creepages(lever, normal, omega, v_c)
    ref = patch_kinematics(lever, np.eye(3), omega, v_c, normal)
    np.testing.assert_allclose(frames, ref.contact_frame, atol=1e-14)
    np.testing.assert_allclose(speed, ref.rolling_speed_m_per_s, rtol=1e-14)
    np.testing.assert_allclose(
        np.stack([xi, eta, spin]), np.stack([ref.longitudinal, ref.lateral, ref.spin_1_per_m]), atol=1e-13
    )


def _compiled_law(name):
    """The parameter record and tables of the compiled right-hand side for the registry model ``name`` on STEEL."""
    from rigid_dynamics.wheelset.compiled_laws import hertz_kalker_tables, tables_for
    from rigid_dynamics.wheelset.compiled_records import law_code
    from rigid_dynamics.wheelset.layout import new_parameters

    tables = tables_for(STEEL.shear_modulus_Pa, STEEL.poisson_ratio)
    par = new_parameters()
    par["shear_modulus_Pa"], par["contact_modulus_Pa"] = STEEL.shear_modulus_Pa, tables.e_star
    par["friction_coefficient"] = STEEL.friction_coefficient
    par["model_code"] = law_code(get_model(name))
    par["fastsim_nx"], par["fastsim_ny"] = 20, 20
    return par, hertz_kalker_tables(tables)


@pytest.mark.parametrize("name", ["hertz", "linear", "vermeulen-johnson", "fastsim"])
def test_compiled_laws_equal_model_solve(name):
    """The compiled laws of the dynamics (tabulated Hertz/C_ij + kernels, compiled_laws._law) equal the registry's
    models (contact.models: the exact Hertz solver and Kalker's coefficients) to the tables' interpolation accuracy."""
    from rigid_dynamics.wheelset.compiled_laws import patch_forces

    rng = np.random.default_rng(11)
    n = 6
    curv_a = rng.uniform(0.8, 1.4, n)
    curv_b = rng.uniform(0.5, 30.0, n)
    approach = rng.uniform(2e-5, 2e-4, n)
    xi, eta, spin = rng.normal(0, 2e-3, n), rng.normal(0, 2e-3, n), rng.normal(0, 0.3, n)
    par, tables = _compiled_law(name)
    model = get_model(name)
    for k in range(n):
        res = model.solve(
            ContactGeometry(curv_a[k], curv_b[k], approach[k]), Creepage(xi[k], eta[k], spin[k], 20.0), STEEL
        )
        got = patch_forces(par, tables, approach[k], curv_a[k], curv_b[k], xi[k], eta[k], spin[k])
        assert not got[6]
        want = [res.normal_force_N, res.creep_force_long_N, res.creep_force_lat_N, res.spin_moment_Nm or 0.0,
                res.semi_axis_long_m, res.semi_axis_lat_m]  # fmt: skip
        scale = [res.normal_force_N] * 4 + [res.semi_axis_long_m, res.semi_axis_lat_m]
        np.testing.assert_allclose(np.array(got[:6]) / scale, np.array(want) / scale, rtol=0, atol=2e-7)


def test_models_declare_their_compiled_law():
    """A model declares the law the loop compiles in its place; bem, fea-like and user models (no declaration) go
    through the callback; a user's subclass of a compiled law keeps it (the module of its class does not matter)."""
    from rigid_dynamics.contact.models import FastsimModel
    from rigid_dynamics.wheelset.compiled_laws import LAW_AUTO, LAW_CALLBACK, LAW_CODES, LAW_FASTSIM
    from rigid_dynamics.wheelset.compiled_records import law_code

    assert law_code(get_model("bem")) == LAW_CALLBACK
    assert law_code(get_model("fastrip")) == LAW_CALLBACK
    assert law_code(get_model("auto")) == LAW_AUTO
    for name in ("hertz", "linear", "vermeulen-johnson", "fastsim"):
        assert law_code(get_model(name)) == LAW_CODES[name]

    class MyFastsim(FastsimModel):
        name = "my-fastsim"

    class MyLaw(FastsimModel):
        name = "my-law"
        compiled_law = None  # a subclass that changes the law says so

    assert law_code(MyFastsim()) == LAW_FASTSIM
    assert law_code(MyLaw()) == LAW_CALLBACK
