"""FEniCSx contact model (fea.model.FeaModel) against Hertz's closed forms.

Reference case (issue 6 benchmark): wheel radius 460 mm rolling, transverse radii 300 mm (wheel)
and 300 mm (rail head), i.e. relative radii R_long = 0.46 m, R_lat = 0.15 m; P = 100 kN; steel
E = 210 GPa, nu = 0.3. Exact values from Johnson (1985) eq 3.64 (fea.hertz_reference, itself
checked against Boussinesq integrals in test_fea_reference.py):
p0 = 1604.6 MPa, a = 7.909 mm, b = 3.762 mm.
Circular case for stresses: R = 0.3 m both ways; Johnson (1985): max tau_1 = 0.310 p0 at 0.481 a.
"""

import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fea.hertz_reference import circular_axis_maximum, hertz_elliptic
from fea.model import FeaModel
from rigid_dynamics.contact.types import ContactGeometry, Creepage, UndeformedDistance
from rigid_dynamics.materials import Material

pytestmark = pytest.mark.fea

ROOT = Path(__file__).resolve().parents[1]
STEEL_210 = Material.from_young(210e9, 0.3, 0.3)
FORCE_N = 1e5
ELLIPTIC = ContactGeometry.quadric(0.46, 0.15)


APPROACH_CONTROL_MAX_DOFS = 30000
"""Budget of the approach-controlled series of test_approach_control_reproduces_load_control (its docstring)."""


@pytest.fixture(scope="module")
def elliptic_result():
    return FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N)


def test_elliptic_hertz_p0_a_b_within_5_percent(elliptic_result):
    r = elliptic_result
    ref = hertz_elliptic(
        ELLIPTIC.curvature_long_1_per_m, ELLIPTIC.curvature_lat_1_per_m, FORCE_N, STEEL_210.combined_modulus_Pa
    )
    assert ref.max_pressure_Pa == pytest.approx(1604.6e6, rel=1e-4)
    assert r.success and r.status == "ok" and r.method == "fea"
    assert r.normal_force_N == pytest.approx(FORCE_N, rel=1e-6)  # load control: sum of contact forces
    assert r.max_pressure_Pa == pytest.approx(ref.max_pressure_Pa, rel=0.05)
    assert r.semi_axis_long_m == pytest.approx(ref.semi_axis_long_m, rel=0.05)
    assert r.semi_axis_lat_m == pytest.approx(ref.semi_axis_lat_m, rel=0.05)
    assert r.contact_area_m2 == pytest.approx(math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m, rel=0.05)
    assert r.creep_force_long_N is None and r.creep_force_lat_N is None
    assert r.extra["tangential"]["status"] == "no-creepage"  # said, not silent (fea.model, "Creep forces")
    assert r.extra["dofs"] > 0 and r.extra["newton_iterations"] >= 1


def test_pressure_grid_integrates_to_the_force(elliptic_result):
    f = elliptic_result.fields
    assert f.pressure_Pa.shape == (len(f.y_m), len(f.x_m))
    total = np.trapezoid(np.trapezoid(f.pressure_Pa, f.x_m, axis=1), f.y_m)
    assert total == pytest.approx(FORCE_N, rel=0.05)
    assert f.in_contact[len(f.y_m) // 2, len(f.x_m) // 2] and not f.in_contact[0, 0]


def test_approach_control_reproduces_load_control(elliptic_result):
    """Invariant: imposing the approach found under load control gives back the force.

    Each solve refines its own mesh, so the two agree within their stated errors (the force ~ approach^1.5: 1.5
    times the approach's relative error), not to solver precision. Under approach control the force carries the
    block-size error of the clamped block (about 3 % at the default 20 semi-axes), so the default 2 % may end
    "mesh-tolerance-not-met" within the budget: a solution with a larger stated error, not a failure.

    The approach-controlled solve has a budget of 30 000 unknowns (two levels, 5 616 and 15 822; measured: force
    1.5 % off against a stated 17 %, 7.5 s): a series on other meshes than the load-controlled one (three levels to
    48 435), so the invariant is checked across discretisations. With the default budget of 200 000 the series went
    on to about 145 000 unknowns for the same assertion (78 s CPU, issue 27).
    """
    geo = ContactGeometry.quadric(0.46, 0.15, approach_m=elliptic_result.approach_m)
    r = FeaModel().solve(geo, Creepage(), STEEL_210, options={"max_dofs": APPROACH_CONTROL_MAX_DOFS})
    assert r.success and r.status in ("ok", "mesh-tolerance-not-met"), r.message
    stated = (
        r.extra["discretisation_error"]["relative_error"]["normal_force"]
        + 1.5 * elliptic_result.extra["discretisation_error"]["relative_error"]["approach"]
    )
    assert abs(r.normal_force_N / FORCE_N - 1.0) <= stated


def test_circular_subsurface_max_shear_and_von_mises_match_johnson():
    geo = ContactGeometry.quadric(0.3, 0.3)
    r = FeaModel().solve(geo, Creepage(), STEEL_210, normal_force_N=FORCE_N)
    ref = hertz_elliptic(geo.curvature_long_1_per_m, geo.curvature_lat_1_per_m, FORCE_N, STEEL_210.combined_modulus_Pa)
    tau, depth = circular_axis_maximum(0.3)  # 0.310, 0.481 (Johnson 1985)
    p0, a = ref.max_pressure_Pa, ref.semi_axis_long_m
    e = r.extra
    assert e["axis_max_shear_Pa"] == pytest.approx(tau * p0, rel=0.05)
    assert e["axis_max_shear_depth_m"] == pytest.approx(depth * a, rel=0.10)
    assert e["axis_max_von_mises_Pa"] == pytest.approx(2 * tau * p0, rel=0.05)
    assert e["max_shear_Pa"] == pytest.approx(tau * p0, rel=0.05)
    assert e["max_von_mises_depth_m"] == pytest.approx(depth * a, rel=0.15)
    # most compressive principal stress: sigma_z = -p0 at the centre of the surface (Johnson eq 3.41)
    assert e["min_principal_Pa"] == pytest.approx(-p0, rel=0.08)
    assert e["min_principal_depth_m"] < 0.2 * a


TWO_BODY_SERIES = {"formulation": "two-body", "quick": True, "max_dofs": 20000}
"""The two-body refinement series of test_two_elastic_bodies_match_hertz: quick's mesh, two levels to 13 851
unknowns (measured 14 s CPU; the default series cost 50-117 s for the same assertions, issue 27)."""


def test_two_elastic_bodies_match_hertz():
    """Two elastic quadric bodies (E, nu each; curvature split equally) with node-to-surface pairing.

    Through the two-body refinement series (quick's mesh to 20 000 unknowns, two levels; it ends
    "mesh-tolerance-not-met" at that budget, a solution with its stated error): p0, a and b within 5 % of Hertz
    (measured +0.68 %, -0.50 %, -0.86 %), and the series' stated errors bracket those true errors (stated 1.6 %,
    1.4 %, 3.1 %).
    """
    r = FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=TWO_BODY_SERIES)
    ref = hertz_elliptic(
        ELLIPTIC.curvature_long_1_per_m, ELLIPTIC.curvature_lat_1_per_m, FORCE_N, STEEL_210.combined_modulus_Pa
    )
    assert r.success and "pairing converged" in r.message
    # the pairing iteration stops at its own tolerance: 3.5e-4 measured on the finest level of the default series
    assert r.normal_force_N == pytest.approx(FORCE_N, rel=1e-3)
    assert r.max_pressure_Pa == pytest.approx(ref.max_pressure_Pa, rel=0.05)
    assert r.semi_axis_long_m == pytest.approx(ref.semi_axis_long_m, rel=0.05)
    assert r.semi_axis_lat_m == pytest.approx(ref.semi_axis_lat_m, rel=0.05)
    assert r.extra["young_modulus_Pa"] == pytest.approx(210e9)
    error = r.extra["discretisation_error"]
    assert len(error["levels"]) >= 2  # a series, not one mesh
    stated = error["relative_error"]
    assert abs(r.max_pressure_Pa / ref.max_pressure_Pa - 1) <= stated["max_pressure"]
    assert abs(r.semi_axis_long_m / ref.semi_axis_long_m - 1) <= stated["semi_axis_long"]
    assert abs(r.semi_axis_lat_m / ref.semi_axis_lat_m - 1) <= stated["semi_axis_lat"]


def test_quadratic_elements_match_hertz():
    """P2 displacements (constraint at vertices and edge midpoints) on the quick mesh.

    Checks that the P2 path gives Hertz's patch: the force to 1e-6 (load control), p0 and the semi-axes within 5 %,
    on one quick mesh (measured: p0 -0.24 %, a and b -0.17 %; 17 500 unknowns, 2.7 s). The claim is the element, not
    the refinement series (the quick series to 200 000 unknowns took 14-74 s here for the same assertions); the P2
    series and its error estimate are checked against Hertz to 1 % in test_fea_refinement.py.
    """
    options = {"degree": 2, "quick": True, "mesh_tolerance": None}
    r = FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=options)
    ref = hertz_elliptic(
        ELLIPTIC.curvature_long_1_per_m, ELLIPTIC.curvature_lat_1_per_m, FORCE_N, STEEL_210.combined_modulus_Pa
    )
    assert r.success
    assert r.normal_force_N == pytest.approx(FORCE_N, rel=1e-6)
    assert r.max_pressure_Pa == pytest.approx(ref.max_pressure_Pa, rel=0.05)
    assert r.semi_axis_long_m == pytest.approx(ref.semi_axis_long_m, rel=0.05)
    assert r.semi_axis_lat_m == pytest.approx(ref.semi_axis_lat_m, rel=0.05)


def test_two_body_needs_quadric_geometry():
    x = np.linspace(-0.01, 0.01, 11)
    X, Y = np.meshgrid(x, x)
    geo = ContactGeometry(1.0, 1.0, approach_m=1e-5, undeformed=UndeformedDistance(x, x, X**2 + Y**2 - 1e-5))
    with pytest.raises(ValueError, match="two-body.*quadric"):
        FeaModel().solve(geo, Creepage(), STEEL_210, normal_force_N=FORCE_N, options={"formulation": "two-body"})


def test_profiles_formulation_needs_contact_points():
    options = {"formulation": "profiles", "wheel_profile": "MBench_S1002_v3", "rail_profile": "MBench_UIC60_v3"}
    with pytest.raises(ValueError, match="contact_point_rail_m"):
        FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=options)


def test_sampled_gap_full_block_agrees_with_quadric_hertz():
    """Second path: a sampled (off-centre) quadric gap on the full block gives Hertz's patch.

    Checks that the sampled gap is meshed and solved where it lies: p0 within 5 % and the area within 8 % of Hertz,
    the pressure's centroid within 0.2 mm of the gap's minimum, no elliptic fit. On one mesh of 6 elements per
    semi-axis in quick's block (measured: p0 +1.6 %, area -2.7 %, centroid 6 um off; 15 000 unknowns, 2.3 s):
    the claim is the sampled path, not the refinement series (whose accuracy the elliptic tests check); the
    quick series to 200 000 unknowns cost 84-139 s here for the same assertions.
    """
    A, B = ELLIPTIC.curvature_long_1_per_m, ELLIPTIC.curvature_lat_1_per_m
    x = np.linspace(-0.02, 0.02, 81)
    y = np.linspace(-0.01, 0.012, 45)
    X, Y = np.meshgrid(x, y)
    und = UndeformedDistance(x, y, A * (X - 1e-3) ** 2 + B * (Y - 2e-3) ** 2 - 1e-4)
    geo = ContactGeometry(A, B, approach_m=1e-4, undeformed=und, is_elliptic=False)
    options = {"quick": True, "elements_per_semi_axis": 6, "mesh_tolerance": None, "stresses": False}
    r = FeaModel().solve(geo, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=options)
    ref = hertz_elliptic(A, B, FORCE_N, STEEL_210.combined_modulus_Pa)
    assert r.success
    assert r.max_pressure_Pa == pytest.approx(ref.max_pressure_Pa, rel=0.05)
    assert r.contact_area_m2 == pytest.approx(math.pi * ref.semi_axis_long_m * ref.semi_axis_lat_m, rel=0.08)
    p = r.fields.pressure_Pa
    xc = (r.fields.x_m[None, :] * p).sum() / p.sum()
    yc = (r.fields.y_m[:, None] * p).sum() / p.sum()
    assert xc == pytest.approx(1e-3, abs=2e-4) and yc == pytest.approx(2e-3, abs=2e-4)
    assert r.semi_axis_long_m is None  # no elliptic fit for a sampled gap


def test_non_convergence_is_reported_not_raised():
    A, B = ELLIPTIC.curvature_long_1_per_m, ELLIPTIC.curvature_lat_1_per_m
    x = np.linspace(-0.02, 0.02, 41)
    X, Y = np.meshgrid(x, x)
    geo = ContactGeometry(A, B, approach_m=0.0, undeformed=UndeformedDistance(x, x, A * X**2 + B * Y**2))
    r = FeaModel().solve(
        geo,
        Creepage(),
        STEEL_210,
        normal_force_N=FORCE_N,
        options={"quick": True, "max_iterations": 1, "stresses": False},
    )
    assert not r.success and r.status == "not-converged" and "did not settle" in r.message


def test_no_contact_at_zero_approach():
    r = FeaModel().solve(ContactGeometry.quadric(0.46, 0.15), Creepage(), STEEL_210)
    assert r.success and r.status == "no-contact" and r.normal_force_N == 0.0


def test_mesh_quality_failure_is_an_error():
    from meshing.quality import MeshQualityError

    with pytest.raises(MeshQualityError, match="min quality"):
        FeaModel().solve(
            ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options={"quick": True, "min_mesh_quality": 0.99}
        )


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"mesh_sise": 1.0}, "unknown fea option.*mesh_sise"),
        ({"degree": 3}, "degree"),
        ({"degree": 2, "formulation": "two-body"}, "formulation 'rigid'"),
        ({"mesh_size_factor": 0.0}, "mesh_size_factor"),
        ({"linear_solver": "hypre"}, "linear_solver"),
        ({"formulation": "mortar"}, "formulation"),
        ({"formulation": "profiles", "wheel_profile": "MBench_S1002_v3"}, "wheel_profile and rail_profile"),
    ],
)
def test_bad_options_raise(options, match):
    with pytest.raises(ValueError, match=match):
        FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=options)


def test_bad_force_raises():
    with pytest.raises(ValueError, match="normal_force_N"):
        FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=-1.0)


def test_outputs_written(tmp_path):
    """The VTU grid and the PNG maps are written (of one quick mesh: the refinement series writes its final level
    through the same ``write``; its accuracy is checked by the tests above)."""
    options = {"quick": True, "output_dir": str(tmp_path), "mesh_tolerance": None}
    r = FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=options)
    for key in ("vtu", "pressure_png", "von_mises_cut_png"):
        assert Path(r.extra["files"][key]).is_file()


def _mpiexec():
    candidate = Path(sys.executable).parent / "mpiexec"
    return str(candidate) if candidate.exists() else shutil.which("mpiexec")


RANKS_RIGID = {"quick": True, "max_dofs": 20000}
"""The rigid solve compared on one and two ranks: the quick mesh's refinement series, with stresses, to a budget of
20 000 unknowns (two levels; the default series to 200 000 cost 140 s on two ranks for the same claim)."""
RANKS_TWO_BODY = {"formulation": "two-body", "quick": True, "stresses": False, "mesh_tolerance": None}
"""The two-body pairing compared on one and two ranks: one quick mesh."""


@pytest.mark.skipif(_mpiexec() is None, reason="mpiexec not found")
def test_two_ranks_agree_with_one_rank(mpi_lock):
    """Regression (our one-rank and two-rank runs of the same solves): forces, p0, semi-axes, approach, von Mises
    and the two-body pairing's p0 and approach agree to 1e-6."""
    script = (
        "import dolfinx_solver, json\n"
        "from mpi4py import MPI\n"
        "from fea.model import FeaModel\n"
        "from rigid_dynamics.contact.types import ContactGeometry, Creepage\n"
        "from rigid_dynamics.materials import Material\n"
        "r = FeaModel().solve(ContactGeometry.quadric(0.46, 0.15), Creepage(), Material.from_young(210e9, 0.3, 0.3),"
        f" normal_force_N=1e5, options={RANKS_RIGID!r})\n"
        "t = FeaModel().solve(ContactGeometry.quadric(0.46, 0.15), Creepage(), Material.from_young(210e9, 0.3, 0.3),"
        f" normal_force_N=1e5, options={RANKS_TWO_BODY!r})\n"
        "if MPI.COMM_WORLD.rank == 0:\n"
        "    print(json.dumps([r.normal_force_N, r.max_pressure_Pa, r.semi_axis_long_m, r.semi_axis_lat_m,"
        " r.approach_m, r.extra['max_von_mises_Pa'], t.max_pressure_Pa, t.approach_m, r.extra['mpi_ranks']]))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    out = subprocess.run(
        [_mpiexec(), "-n", "2", sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=240,
        env=env,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    values = json.loads(out.stdout.strip().splitlines()[-1])
    assert values[-1] == 2
    r = FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=RANKS_RIGID)
    t = FeaModel().solve(ELLIPTIC, Creepage(), STEEL_210, normal_force_N=FORCE_N, options=RANKS_TWO_BODY)
    assert r.extra["dofs"] > 10000  # a refined level, not the first mesh
    one = [
        r.normal_force_N,
        r.max_pressure_Pa,
        r.semi_axis_long_m,
        r.semi_axis_lat_m,
        r.approach_m,
        r.extra["max_von_mises_Pa"],
        t.max_pressure_Pa,
        t.approach_m,
    ]
    np.testing.assert_allclose(values[:-1], one, rtol=1e-6)


def test_pressure_field_converges_at_first_order():
    """Force-weighted L1 distance to Hertz's p0 sqrt(1 - x^2/a^2 - y^2/b^2) over three refinements.

    The contact edge is located to within about one element, so the L1 error of the pressure is
    O(h): the observed order fitted over h, h/2, h/4 must be about 1 (measured 1.18 and 1.00).
    """
    ref = hertz_elliptic(
        ELLIPTIC.curvature_long_1_per_m, ELLIPTIC.curvature_lat_1_per_m, FORCE_N, STEEL_210.combined_modulus_Pa
    )
    sizes, errors = [], []
    for n in (3, 6, 12):
        r = FeaModel().solve(
            ELLIPTIC,
            Creepage(),
            STEEL_210,
            normal_force_N=FORCE_N,
            options={"elements_per_semi_axis": n, "domain_factor": 12, "stresses": False, "mesh_tolerance": None},
        )
        f = r.fields
        X, Y = np.meshgrid(f.x_m, f.y_m)
        exact = ref.max_pressure_Pa * np.sqrt(
            np.clip(1 - (X / ref.semi_axis_long_m) ** 2 - (Y / ref.semi_axis_lat_m) ** 2, 0, None)
        )
        sizes.append(1.0 / n)
        errors.append(np.abs(f.pressure_Pa - exact).sum() / exact.sum())
    order = np.polyfit(np.log(sizes), np.log(errors), 1)[0]
    assert 0.7 < order < 2.0, f"observed order {order:.2f}, errors {errors}"
    assert errors[-1] < 0.04
