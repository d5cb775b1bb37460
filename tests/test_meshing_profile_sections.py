"""Local wheel and rail sections from real profiles (meshing.profile_sections)."""

import math

import numpy as np
import pytest

from meshing.profile_sections import ProfileSectionSpec, build_profile_section, normal_angle_rad
from meshing.quality import mesh_quality
from meshing.session import generate, gmsh_model
from rigid_dynamics.geometry.readers import load_profile

pytestmark = pytest.mark.fea


def _section(kind, name, y_c, align=False, **kw):
    curve = load_profile(name, kind).curve()
    spec = ProfileSectionSpec(kind, y_c, 0.015, 0.02, 0.03, 0.006, 0.003, **kw)
    with gmsh_model("section") as model:
        groups = build_profile_section(model, curve, spec, align_normal=align)
        generate(model)
        quality = mesh_quality(model)
        _, xyz = model.mesh.getNodesForPhysicalGroup(*groups["contact"])
    return curve, spec, groups, quality, xyz.reshape(-1, 3)


def test_rail_section_surface_follows_the_profile():
    curve, spec, groups, quality, xyz = _section("rail", "MBench_UIC60_v3", 0.005)
    assert {"body", "contact", "base", "ends"} <= set(groups)
    assert quality.min_quality > 0.1
    # extruded along X: Z = -(z_p(y_c + Y) - z_p(y_c)) at every X
    expected = -(curve.z(spec.contact_y_m + xyz[:, 1]) - curve.z(spec.contact_y_m))
    assert np.abs(xyz[:, 2] - expected).max() < 2e-6
    assert xyz[:, 0].min() == pytest.approx(-0.02) and xyz[:, 0].max() == pytest.approx(0.02)


def test_wheel_section_surface_is_the_revolved_profile():
    curve, spec, groups, quality, xyz = _section("wheel", "MBench_S1002_v3", -0.004)
    radius_c = spec.nominal_radius_m + curve.z(spec.contact_y_m) - curve.z(0.0)
    # distance from the axle (parallel to Y at height R(y_c)) equals R(y) = r0 + z_p(y) - z_p(0)
    dist = np.hypot(xyz[:, 0], radius_c - xyz[:, 2])
    expected = spec.nominal_radius_m + curve.z(spec.contact_y_m + xyz[:, 1]) - curve.z(0.0)
    assert np.abs(dist - expected).max() < 2e-6
    assert quality.element_count > 100


def test_aligned_rail_section_has_horizontal_contact_plane():
    curve, spec, groups, quality, xyz = _section("rail", "MBench_UIC60_v3", -0.025, align=True)
    near = np.hypot(xyz[:, 0], xyz[:, 1]) < 1.5e-3
    assert near.sum() > 3
    # within 1.5 mm of the contact point the surface stays within curvature * r^2 of Z = 0
    assert np.abs(xyz[near, 2]).max() < 0.5 * abs(curve.z(spec.contact_y_m, 2)) * 1.5e-3**2 * 1.5 + 1e-7
    assert abs(normal_angle_rad(curve, -0.025)) > 0.05  # gauge-side point: the profile is inclined there


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"kind": "axle"}, "kind"),
        ({"depth_m": 0.0}, "depth_m"),
        ({"profile_points": 3}, "profile_points"),
        ({"elements_per_semi_axis": 0.1}, "elements_per_semi_axis"),
    ],
)
def test_bad_spec_raises(kwargs, match):
    base = dict(
        kind="rail",
        contact_y_m=0.0,
        half_width_m=0.01,
        half_length_m=0.01,
        depth_m=0.02,
        semi_axis_long_m=0.005,
        semi_axis_lat_m=0.003,
    )
    with pytest.raises(ValueError, match=match):
        ProfileSectionSpec(**{**base, **kwargs})


def test_contact_point_outside_profile_and_too_thin_section_raise():
    curve = load_profile("MBench_UIC60_v3", "rail").curve()
    with gmsh_model("bad") as model:
        with pytest.raises(ValueError, match="inside the profile range"):
            build_profile_section(model, curve, ProfileSectionSpec("rail", 0.5, 0.01, 0.01, 0.02, 0.005, 0.003))
    with gmsh_model("thin") as model:
        with pytest.raises(ValueError, match="larger depth"):
            build_profile_section(model, curve, ProfileSectionSpec("rail", -0.02, 0.02, 0.01, 0.001, 0.005, 0.003))
    assert math.isfinite(normal_angle_rad(curve, 0.0))
