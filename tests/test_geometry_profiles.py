"""Profiles, readers and profile curves (rigid_dynamics.geometry.profile / readers)."""

import math

import numpy as np
import pytest

from rigid_dynamics.geometry import (
    CircularArcCurve,
    Profile,
    ProfileCurve,
    builtin_profiles,
    load_profile,
    read_profile,
    write_profile_csv,
)
from rigid_dynamics.geometry.readers import BUILTIN_PROFILE_DIR

FILES = {
    "MBench_S1002_v3": "wheel",
    "MBench_UIC60_v3": "rail",
    "MBench_UIC60_v3_ban": "rail",
    "uic60_true": "rail",
    "worn_high_mileage": "wheel",
    "site_b_hr": "rail",
    "avg_wheel": "wheel",
    "Car7216_0001r": "wheel",
    "circ_r300": "rail",
    "circ_r100": "wheel",
}


@pytest.fixture(scope="module")
def profiles():
    return {name: load_profile(name) for name in FILES}


def test_every_shipped_file_is_listed_and_has_attribution():
    names = builtin_profiles()
    for name in FILES:
        assert name in names
    shipped = {p.name for p in BUILTIN_PROFILE_DIR.iterdir() if p.suffix in (".prw", ".prr", ".whl", ".ban")}
    assert len(shipped) == 10
    source = (BUILTIN_PROFILE_DIR / "SOURCE.md").read_text()
    assert "Apache" in source and "Vollebregt" in source


@pytest.mark.parametrize("name", list(FILES))
def test_reader_convention(profiles, name):
    """Each file ends up in the internal convention: kind, increasing y, origin, flange/gauge side."""
    p = profiles[name]
    assert p.kind == FILES[name]
    assert np.all(np.diff(p.y_m) > 0)
    assert p.outline_y_m.size >= p.y_m.size
    if p.kind == "wheel":
        # tape circle at y_p = 0 with z_p = 0; flange tip (max z) at negative y_p, 25..36 mm below
        assert abs(np.interp(0.0, p.y_m, p.z_m)) < 1e-9
        i = int(np.argmax(p.z_m))
        if name != "circ_r100":
            assert -0.060 < p.y_m[i] < -0.040
            assert 0.025 < p.z_m[i] < 0.037
            # flange back near y_p = -70 mm (wheel width beyond the flange back is not in the data)
            assert -0.0715 < p.y_min_m < -0.060
    else:
        assert p.z_m.min() == pytest.approx(0.0, abs=1e-15)
        assert p.z_m.max() > 0.010  # the head sides drop (z down)


def test_s1002_known_points(profiles):
    """MBench S1002: flange height 28 mm below the tape circle (EN 13715 nominal value)."""
    p = profiles["MBench_S1002_v3"]
    assert p.z_m.max() == pytest.approx(0.028, abs=2e-5)


def test_prr_and_ban_files_agree(profiles):
    """The MiniProf .ban copy of the MBench rail is mirrored in y: after reading both give the same points."""
    a, b = profiles["MBench_UIC60_v3"], profiles["MBench_UIC60_v3_ban"]
    np.testing.assert_allclose(a.y_m, b.y_m, atol=1e-12)
    np.testing.assert_allclose(a.z_m, b.z_m, atol=1e-12)


def test_uic60_true_vertical_sides_trimmed(profiles):
    """uic60_true.prr has vertical sides at |y| = 40.435889 mm below 15.53 mm: they are cut off."""
    p = profiles["uic60_true"]
    assert p.y_min_m == pytest.approx(-0.040435889, abs=1e-6) or p.y_min_m > -0.0405
    assert p.z_m.max() < 0.0156
    assert p.outline_z_m.max() == pytest.approx(0.031529605, abs=1e-9)


@pytest.mark.parametrize("name", list(FILES))
def test_csv_round_trip(profiles, name, tmp_path):
    p = profiles[name]
    path = write_profile_csv(tmp_path / f"{name}.csv", p)
    q = read_profile(path)
    assert q.kind == p.kind
    np.testing.assert_allclose(q.y_m, p.y_m, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q.z_m, p.z_m, rtol=0, atol=1e-12)


@pytest.mark.parametrize(("name", "radius_m", "sign"), [("circ_r100", 0.1, -1.0), ("circ_r300", 0.3, 1.0)])
def test_spline_curvature_of_circular_profiles(profiles, name, radius_m, sign):
    """Closed form: z = sign (R - sqrt(R^2 - y^2)), z' = sign y / sqrt(R^2 - y^2), curvature sign / R.

    The files are rounded to 1e-6 mm; circ_r100.prw moreover deviates from the circle by up to
    5e-5 mm within |y| <= 0.3 mm (its points there are off the circle), which costs 0.5 % of
    curvature at the apex after smoothing; away from it the smoothed spline (L_filt = 2 mm) has
    curvature 1/R to 1e-3 (the residue of the rounding noise, 6e-4 observed for circ_r300; 5e-5 with
    L_filt = 5 mm).
    """
    c = profiles[name].curve(0.002)
    y = np.linspace(c.y_min_m + 0.005, c.y_max_m - 0.005, 3001)
    if name == "circ_r300":
        y = y[np.abs(y) < 0.2]
    z, dz, d2z = c.evaluate(y)
    root = np.sqrt(radius_m**2 - y**2)
    np.testing.assert_allclose(z, sign * (radius_m - root), atol=1e-7)
    np.testing.assert_allclose(dz, sign * y / root, atol=2e-5)
    kappa = d2z / (1 + dz**2) ** 1.5
    away = np.abs(y) > 0.003
    assert np.max(np.abs(kappa[away] * radius_m * sign - 1)) < 1e-3
    assert np.max(np.abs(kappa * radius_m * sign - 1)) < 6e-3


def test_interpolating_spline_on_exact_circle_data():
    """Exact circle samples (0.1 mm): interpolating spline curvature 1/R to 1e-6, slope to 1e-9."""
    arc = CircularArcCurve(0.3, 0.05, "rail")
    c = ProfileCurve(arc.to_profile(1e-4), smoothing_wavelength_m=0.0)
    y = np.linspace(-0.045, 0.045, 1001)
    z, dz, d2z = c.evaluate(y)
    ze, dze, d2ze = arc.evaluate(y)
    np.testing.assert_allclose(z, ze, atol=1e-13)
    np.testing.assert_allclose(dz, dze, atol=1e-9)
    np.testing.assert_allclose(d2z, d2ze, rtol=1e-6)


def test_circular_arc_curve_derivatives_match_finite_differences():
    arc = CircularArcCurve(0.1, 0.06, "wheel", centre_y_m=0.01, apex_z_m=0.002)
    y = np.linspace(-0.04, 0.06, 11)
    h = 1e-6
    np.testing.assert_allclose(arc.z(y, 1), (arc.z(y + h) - arc.z(y - h)) / (2 * h), rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(arc.z(y, 2), (arc.z(y + h, 1) - arc.z(y - h, 1)) / (2 * h), rtol=1e-6)
    assert arc.z(0.01, 2) == pytest.approx(-1 / 0.1)
    assert math.isnan(arc.z(0.08))


def test_smoothing_suppresses_noise_on_measured_wheel(profiles):
    """Car7216 (raw MiniProf, 0.3 mm spacing): the tread curvature stays that of a tread, not of the noise.

    With interpolation the noise gives |z''| up to ~60 1/m on the tread; a new or worn tread has
    lateral radii above ~100 mm (|z''| < 10 1/m) except in the flange root.
    """
    c0 = profiles["avg_wheel"].curve(0.0)
    c2 = profiles["avg_wheel"].curve(0.002)
    y = np.linspace(-0.02, 0.04, 2001)
    assert np.abs(c0.z(y, 2)).max() > 100.0  # 0.01 mm rounding of the data -> ringing
    assert np.abs(c2.z(y, 2)).max() < 45.0
    # smoothing keeps the shape: 90 % of the points within 0.02 mm
    p = profiles["Car7216_0001r"]
    d = np.abs(p.curve(0.002).z(p.y_m) - p.z_m)
    assert np.nanpercentile(d, 90) < 2e-5


def test_curve_outside_range_is_nan(profiles):
    c = profiles["uic60_true"].curve()
    assert np.isnan(c.z(c.y_max_m + 1e-3))
    assert np.isfinite(c.z(0.0))


# ----------------------------------------------------------------------------------- bad input
def _pts(n=6):
    y = np.linspace(-0.01, 0.01, n)
    return y, y**2


def test_profile_validation_errors():
    y, z = _pts()
    with pytest.raises(ValueError, match="kind must be one of"):
        Profile(y, z, "axle")
    with pytest.raises(ValueError, match="at least 5 are needed"):
        Profile(y[:4], z[:4], "rail")
    z_bad = z.copy()
    z_bad[2] = np.nan
    with pytest.raises(ValueError, match="point 2 is not finite"):
        Profile(y, z_bad, "rail")
    y_dup = y.copy()
    y_dup[3] = y_dup[2]
    with pytest.raises(ValueError, match="duplicate abscissa"):
        Profile(y_dup, z, "rail")
    with pytest.raises(ValueError, match="not sorted"):
        Profile(y[::-1], z, "rail")
    with pytest.raises(ValueError, match="same length"):
        Profile(y, z[:-1], "rail")
    loop_y = np.array([0.0, 1.0, 1.0, 0.5, 0.5, 2.0])
    loop_z = np.array([0.0, 0.0, 1.0, 1.0, -1.0, -1.0])
    with pytest.raises(ValueError, match="intersects itself"):
        Profile(y, z, "rail", outline_y_m=loop_y, outline_z_m=loop_z)


def test_curve_argument_errors(profiles):
    c = profiles["circ_r300"].curve()
    with pytest.raises(ValueError, match="derivative must be 0, 1 or 2"):
        c.z(0.0, 3)
    with pytest.raises(ValueError, match="smoothing_wavelength_m must be"):
        ProfileCurve(profiles["circ_r300"], -1.0)
    with pytest.raises(ValueError, match="profile must be a Profile"):
        ProfileCurve("circ_r300")
    with pytest.raises(ValueError, match="radius_m must be"):
        CircularArcCurve(-1.0, 0.01, "rail")
    with pytest.raises(ValueError, match="half_width_m must be"):
        CircularArcCurve(0.1, 0.2, "rail")


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


SIMPACK = """header.begin
  version = 1
  type = {type}
header.end
spline.begin
  units.len.f = {unit}
  rotate = {rotate}
  point.begin
{points}
  point.end
spline.end
"""


def _simpack(tmp_path, name="t.prr", type_=0, unit="1000.", rotate="0", points=None):
    if points is None:
        y = np.linspace(-30, 30, 61)
        points = "\n".join(f"{a:.6f} {a * a / 600:.6f}" for a in y)
    return _write(tmp_path, name, SIMPACK.format(type=type_, unit=unit, rotate=rotate, points=points))


def test_reader_errors(tmp_path):
    with pytest.raises(ValueError, match="cannot be read"):
        read_profile(tmp_path / "missing.prr")
    with pytest.raises(ValueError, match="unknown extension"):
        read_profile(_write(tmp_path, "a.xyz", "1 2\n"))
    with pytest.raises(ValueError, match=r"line 10: expected two or three numbers"):
        read_profile(_simpack(tmp_path, points="1.0 2.0\n1.5 abc\n"))
    with pytest.raises(ValueError, match="holds a rail profile but kind='wheel'"):
        read_profile(_simpack(tmp_path), kind="wheel")
    with pytest.raises(ValueError, match="header 'type' 0 \\(rail\\) or 1"):
        read_profile(_simpack(tmp_path, type_=7))
    with pytest.raises(ValueError, match="'rotate' = 0.1 is not supported"):
        read_profile(_simpack(tmp_path, rotate="0.1"))
    with pytest.raises(ValueError, match="check the length unit"):
        read_profile(_simpack(tmp_path, unit="1."))
    with pytest.raises(ValueError, match="no 'point.begin'"):
        read_profile(_write(tmp_path, "b.prw", "header.begin\ntype = 1\nheader.end\n"))
    with pytest.raises(ValueError, match="at least 5 are needed"):
        read_profile(_simpack(tmp_path, points="1 1\n2 2\n3 3\n"))
    with pytest.raises(ValueError, match=r"line 3: expected two numbers"):
        read_profile(_write(tmp_path, "c.csv", "y,z\n1,2\n3;x\n"))
    with pytest.raises(ValueError, match="kind of profile is unknown"):
        read_profile(_write(tmp_path, "d.csv", "\n".join(f"{a},{a * a / 600}" for a in range(-20, 21)) + "\n"))
    with pytest.raises(ValueError, match="point 3 is not finite"):
        read_profile(_write(tmp_path, "e.csv", "# kind: rail\n" + "1,1\n2,2\n3,3\nnan,4\n5,5\n6,6\n"))
    loop = "# kind: rail\n0,0\n10,0\n10,10\n5,10\n5,-10\n20,-10\n"
    with pytest.raises(ValueError, match="intersects itself"):
        read_profile(_write(tmp_path, "f.csv", loop))
    with pytest.raises(ValueError, match="empty line between the MiniProf header"):
        read_profile(_write(tmp_path, "g.ban", "Filename=x\nColumnDef=X,Y\n"))
    with pytest.raises(ValueError, match=r"line 4: expected at least 2 numbers"):
        read_profile(_write(tmp_path, "h.whl", "MINIPROF\nx\n\n1.0\n"))
    with pytest.raises(ValueError, match="tape circle y_p = 0 lies outside"):
        read_profile(_write(tmp_path, "i.csv", "# kind: wheel\n" + "\n".join(f"{a},{-a / 40}" for a in range(10, 60))))
    with pytest.raises(ValueError, match="kind must be one of"):
        read_profile(_simpack(tmp_path), kind="axle")


def test_load_profile_errors(tmp_path):
    with pytest.raises(ValueError, match="neither a built-in profile"):
        load_profile("no_such_profile")
    with pytest.raises(ValueError, match="is a wheel profile, but kind='rail'"):
        load_profile("MBench_S1002_v3", "rail")
    with pytest.raises(ValueError, match="kind must be one of"):
        load_profile("MBench_S1002_v3", "axle")
    assert load_profile("mbench_s1002_V3").name == "MBench_S1002_v3"
    assert load_profile(_simpack(tmp_path)).kind == "rail"


def test_write_profile_csv_needs_profile(tmp_path):
    with pytest.raises(ValueError, match="profile must be a Profile"):
        write_profile_csv(tmp_path / "x.csv", "S1002")


@pytest.mark.parametrize(("mirror_y", "flip_z"), [(False, False), (True, False), (False, True), (True, True)])
def test_miniprof_wheel_conventions_detected(tmp_path, mirror_y, flip_z):
    """An S1002 wheel written MiniProf-style (y from the flange back, in either lateral direction, z up or down)
    is read back onto the analytic S1002 (tape circle 70 mm from the flange back) to 1e-8 m (the z origin is
    set by linear interpolation at y_p = 0 between points 0.1 mm apart: 4e-9 m)."""
    from rigid_dynamics.geometry import s1002_wheel

    s = s1002_wheel()
    y = np.linspace(-0.0699, 0.060, 1301)
    z = s.z(y)
    yf = (y + 0.070) * 1000  # from the flange back, mm
    zf = z * 1000
    if mirror_y:
        yf = -yf
    if flip_z:
        zf = -zf
    lines = ["MINIPROF test", "synthetic.whl", "32.50 28.00 10.8 (Sd/Sh/qR)", ""]
    lines += [f"{a:.9f} {b:.9f} 0.000" for a, b in zip(yf, zf, strict=True)]
    p = read_profile(_write(tmp_path, "synthetic.whl", "\n".join(lines) + "\n"))
    np.testing.assert_allclose(p.z_m, s.z(p.y_m), atol=1e-8)
    assert p.y_min_m == pytest.approx(-0.0699, abs=1e-9)


@pytest.mark.parametrize("flip_z", [False, True])
def test_miniprof_rail_conventions_detected(tmp_path, flip_z):
    """A canted UIC60 head written MiniProf-style (track centre at +y, z up or down) is read back
    with the gauge side at -y and the top at z = 0."""
    from rigid_dynamics.geometry import uic60_rail

    u = uic60_rail()
    t = np.linspace(-0.0365, 0.0365, 1461)
    b = math.atan(1 / 20)
    Y = math.cos(b) * t + math.sin(b) * u.z(t)
    Z = -math.sin(b) * t + math.cos(b) * u.z(t)
    yf, zf = -Y * 1000, (Z - Z.min()) * 1000 * (-1 if flip_z else 1)
    lines = ["Filename=x.ban", "ColumnDef=X,Y", ""] + [f"{a:.9f}\t{c:.9f}" for a, c in zip(yf, zf, strict=True)]
    p = read_profile(_write(tmp_path, "x.ban", "\n".join(lines) + "\n"))
    i = int(np.argmin(p.z_m))
    assert p.y_m[i] > 0.005  # a canted crown's top moves towards the field side (+y): 300 mm / 20 = 15 mm
    assert p.z_m.min() == pytest.approx(0.0, abs=1e-15)
