"""gmsh Hertz block: named groups, refinement at the patch, quality checks and their error paths."""

import pytest

from meshing.hertz import HertzBlockSpec, build_hertz_block
from meshing.quality import MeshQuality, MeshQualityError, QualityLimits, check_quality, mesh_quality
from meshing.session import generate, gmsh_model

pytestmark = pytest.mark.fea


def _mesh(spec):
    with gmsh_model("test") as model:
        groups = build_hertz_block(model, spec)
        generate(model)
        quality = mesh_quality(model)
        contact_nodes, contact_xyz = model.mesh.getNodesForPhysicalGroup(*groups["contact"])
    return groups, quality, contact_xyz.reshape(-1, 3), None


def test_quarter_block_has_named_groups_and_is_refined_at_the_patch():
    import gmsh

    spec = HertzBlockSpec(0.008, 0.004, elements_per_semi_axis=4, domain_factor=10)
    groups, quality, xyz, _ = _mesh(spec)
    assert set(groups) == {"body", "contact", "base", "symmetry_x", "symmetry_y"}
    assert groups["body"][0] == 3 and groups["contact"][0] == 2
    assert quality.element_count > 100 and quality.min_quality > 0.1
    # contact face is z = 0; the nodes inside the patch are much denser than the face average
    assert abs(xyz[:, 2]).max() < 1e-12
    inside = ((xyz[:, 0] / 0.008) ** 2 + (xyz[:, 1] / 0.004) ** 2 < 1).sum()
    patch_fraction = 3.14159 * 0.008 * 0.004 / 4 / spec.half_width_m**2
    assert inside / len(xyz) > 20 * patch_fraction
    assert not gmsh.isInitialized()  # the session left no global state behind


def test_full_block_is_centred_and_has_no_symmetry_groups():
    spec = HertzBlockSpec(
        0.004, 0.004, elements_per_semi_axis=2, domain_factor=6, center_m=(0.01, -0.002), symmetry="full"
    )
    groups, quality, xyz, _ = _mesh(spec)
    assert set(groups) == {"body", "contact", "base"}
    assert xyz[:, 0].min() == pytest.approx(0.01 - spec.half_width_m)
    assert xyz[:, 1].max() == pytest.approx(-0.002 + spec.half_width_m)


def test_quality_checks_raise_clear_errors():
    good = MeshQuality(element_count=1000, node_count=300, min_quality=0.3, mean_quality=0.7)
    assert check_quality(good, QualityLimits()) is good
    with pytest.raises(MeshQualityError, match="min quality"):
        check_quality(good, QualityLimits(min_quality=0.5))
    with pytest.raises(MeshQualityError, match="1000 elements"):
        check_quality(good, QualityLimits(max_elements=999))
    with pytest.raises(MeshQualityError, match="no volume elements"):
        check_quality(MeshQuality(0, 0, float("nan"), float("nan")), QualityLimits())


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"semi_axis_long_m": -1.0}, "semi_axis_long_m"),
        ({"elements_per_semi_axis": 0.5}, "elements_per_semi_axis"),
        ({"domain_factor": 2.0}, "domain_factor"),
        ({"symmetry": "half"}, "symmetry"),
        ({"center_m": (0.1, 0.0)}, "quarter model"),
    ],
)
def test_bad_spec_raises(kwargs, match):
    base = {"semi_axis_long_m": 0.01, "semi_axis_lat_m": 0.01}
    with pytest.raises(ValueError, match=match):
        HertzBlockSpec(**{**base, **kwargs})


@pytest.mark.parametrize(
    ("kwargs", "match"), [({"min_quality": 0.0}, "min_quality"), ({"max_elements": 0}, "max_elements")]
)
def test_bad_limits_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        QualityLimits(**kwargs)
