"""Reader of CONTACT's wheel slices files (``.slcw``): an out-of-round wheel as profiles at angles round the wheel.

Format (CONTACT user guide, "Wheel slices-file"; E.A.H. Vollebregt, CONTACT, open source): ``%`` starts a comment
(whole line or trailing); then

    TH_OFFSET  TH_SCALE          theta_wc = TH_SCALE (TH_OFFSET + TH_SLC), rad
    NSLC                         number of slices
    NFEAT  NKINK  NACCEL         lateral features (only NFEAT = 0 is read here)
    TH_INTPOL                    1 interpolating, 2 approximating spline between slices
    TH_SLC  'file'               NSLC lines: slice angle and its profile file (relative to the slices file)

Each slice file holds a wheel profile (two columns y, z in mm, ``%`` comments) in one orientation for all slices.
The first slice is the *base*: it is read with the profile reader (rigid_dynamics.geometry.readers: orientation
detected, y_p from the tape circle, z_p down, z_p(0) = 0), and the same transform (mirrors, shifts) is applied to
every slice, so a flat keeps its depth at the tape circle (the reader would re-zero each profile on its own). The
radial deviation of slice k from the base is

    R_irr(theta_k, y_p) = z_p,k(y_p) - z_p,base(y_p)             (z_p down: a positive value adds material)

on the lateral range common to all slices, plus the base's own offset: a slice's z is the wheel's radius relative
to the nominal radius (CONTACT's wheel profile frame: its profile reader keeps the file's z, m_profile's
profile_finish_grid), while the profile reader re-zeroes the base at the tape circle, so the file's z_p,base(0)
(``origin_offset_m``; -0.041 mm in CONTACT's wheelflat example: its rolling radius at the tape circle is 0.041 mm
below r0) is kept in R_irr at every angle and the wheel is the file's. Angles: CONTACT's theta_wc is the wheel's
angle with the contact at
theta_wc = -PITCH; in this package the wheel's material angle at its lowest point is alpha = pi/2 - phi with
phi = -PITCH (wheelset_case: phi' = -pitch rate), so alpha = pi/2 - theta_wc. Along the angle the surface is
CONTACT's (its m_bspline_make, read to learn, not copied): TH_INTPOL 1 interpolates the slices; TH_INTPOL 2 takes
them as the *control points* of a cubic B-spline with knots at the slice angles (the ends extended by three
intervals, one phantom control point extrapolated linearly at each end), which smooths over about one slice
either side (on uniform spacing h the value at a slice is (c_{k-1} + 4 c_k + c_{k+1}) / 6: a quadratic c theta^2
reads c (theta^2 + h^2 / 3)). Both are stored as their values at the slice angles, through which the periodic
bicubic spline of MeasuredWheelIrregularity passes: a cubic spline with those knots is fixed by those values, so
away from the wrap-around it is CONTACT's spline. CONTACT's constant extrapolation outside the slices' angle
range is not reproduced (the spline is periodic).

The wheel profile of a case that uses such a file should be the base slice's file (R_irr is relative to it).

Status: verified on a parametric flat written as slices (tests/test_geometry_slices.py) and against CONTACT's
published solution of its examples/wheelflat.inp (tests/test_wheelflat_contact_reference.py, all 26 angles in
benchmarks/results/wheelflat_contact.md) once read as CONTACT reads it: TH_INTPOL 2, the base's file offset kept,
the wheel's SMOOTH taken as CONTACT's default ISMOOTH 0 parameter (:func:`contact_smoothing_wavelength_m`), the rail
unsmoothed.
"""

from __future__ import annotations

import math
import shlex
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .irregularities import MeasuredWheelIrregularity
from .profile import Profile
from .readers import read_profile

__all__ = ["WheelSlices", "contact_smoothing_wavelength_m", "read_wheel_slices"]


@dataclass(frozen=True, eq=False)
class WheelSlices:
    """A wheel slices file read: the base profile and the out-of-roundness.

    Attributes:
        base: the first slice as a Profile (internal convention).
        irregularity: R_irr(alpha, y_p) relative to the base (MeasuredWheelIrregularity).
        theta_rad: CONTACT's slice angles theta_wc, rad, shape (n,).
        source: the file.
        th_intpol: the file's TH_INTPOL: 1 interpolating, 2 approximating spline along the angle (module docstring).
        origin_offset_m: the base slice's z_p at the tape circle in the file (internal orientation, z down), m: the
            shift the profile reader removed from ``base``, kept in ``irregularity`` (module docstring).
    """

    base: Profile
    irregularity: MeasuredWheelIrregularity
    theta_rad: np.ndarray
    source: str
    th_intpol: int = 1
    origin_offset_m: float = 0.0


def _lines(path: Path):
    """Non-empty lines of a file with ``%`` comments removed (outside quotes)."""
    out = []
    for raw in path.read_text(errors="replace").splitlines():
        if "'" not in raw and '"' not in raw:  # no quotes: the comment starts at the first % (the loop's result)
            text = raw.split("%", 1)[0].strip()
            if text:
                out.append(text)
            continue
        line, quoted = [], None
        for ch in raw:
            if ch in "'\"":
                quoted = None if quoted == ch else (ch if quoted is None else quoted)
            if ch == "%" and quoted is None:
                break
            line.append(ch)
        text = "".join(line).strip()
        if text:
            out.append(text)
    return out


def _err(path, msg):
    return ValueError(f"{path}: {msg}")


def _numbers(path, line, count, what):
    try:
        values = [float(v) for v in line.replace(",", " ").split()[:count]]
    except ValueError:
        raise _err(path, f"expected {what}, got {line!r}") from None
    if len(values) < count or not all(math.isfinite(v) for v in values):
        raise _err(path, f"expected {what}, got {line!r}")
    return values


def _points(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The (y, z) columns of a slice file, mm."""
    rows = []
    for line in _lines(path):
        tokens = line.replace(",", " ").split()
        try:
            rows.append((float(tokens[0]), float(tokens[1])))
        except (ValueError, IndexError):
            continue  # a header line
    if len(rows) < 4:
        raise _err(path, f"expected at least 4 points (y, z in mm), found {len(rows)}")
    arr = np.array(rows, float)
    return arr[:, 0], arr[:, 1]


def _transform(base: Profile, y_mm, z_mm):
    """(s_y, s_z, y shift mm, z shift mm) with base.z(s_y y - shift) = s_z z - z0 (the reader's normalisation)."""
    best = None
    yb, zb = base.y_m * 1e3, base.z_m * 1e3
    for sy in (1.0, -1.0):
        for sz in (1.0, -1.0):
            for shift in (0.0, 70.0):
                y = sy * y_mm - shift
                inside = (y >= yb[0]) & (y <= yb[-1])
                if inside.sum() < 4:
                    continue
                d = sz * z_mm[inside] - np.interp(y[inside], yb, zb)
                z0 = float(np.median(d))
                residual = float(np.max(np.abs(d - z0)))
                if best is None or residual < best[0]:
                    best = (residual, sy, sz, shift, z0)
    if best is None or best[0] > 1e-3:
        raise ValueError("the base slice's orientation could not be matched to the profile reader's")
    return best[1:]


def read_wheel_slices(path, lateral_step_m: float = 5.0e-4, smoothing_wavelength_m: float = 0.0) -> WheelSlices:
    """Read a CONTACT wheel slices file (module docstring).

    Args:
        path: the ``.slcw`` file.
        lateral_step_m: spacing of the common lateral grid on which the slices are resampled, m.
        smoothing_wavelength_m: L_filt of a smoothing spline applied to each slice's deviation along y (the same
            filter as the profile splines, rigid_dynamics.geometry.profile; CONTACT's SMOOTH), m; 0: none.

    Raises:
        ValueError: unreadable file, bad header, fewer than 4 slices, angles not increasing by >= 0.001 rad or
            spanning 2 pi or more, NFEAT > 0 (lateral features are not read), a slice file missing.
    """
    path = Path(path)
    if not path.is_file():
        raise _err(path, "no such file")
    lines = _lines(path)
    if len(lines) < 4:
        raise _err(path, "expected the header TH_OFFSET TH_SCALE / NSLC / NFEAT NKINK NACCEL / TH_INTPOL")
    offset, scale = _numbers(path, lines[0], 2, "TH_OFFSET TH_SCALE")
    (count,) = _numbers(path, lines[1], 1, "NSLC")
    nfeat = _numbers(path, lines[2], 1, "NFEAT NKINK NACCEL")[0]
    if nfeat != 0:
        raise _err(path, f"NFEAT = {nfeat:g}: expected 0 (lateral features in slices files are not read here)")
    (th_intpol,) = _numbers(path, lines[3], 1, "TH_INTPOL")
    if th_intpol not in (1.0, 2.0):
        raise _err(path, f"TH_INTPOL = {th_intpol:g}: expected 1 (interpolating) or 2 (approximating spline)")
    count = int(count)
    if count < 4 or len(lines) < 4 + count:
        raise _err(path, f"NSLC = {count}: expected at least 4 slices, each on a line 'TH_SLC file'")
    theta, files = [], []
    for line in lines[4 : 4 + count]:
        parts = shlex.split(line)
        if len(parts) < 2:
            raise _err(path, f"expected 'TH_SLC file', got {line!r}")
        theta.append(_numbers(path, parts[0], 1, "TH_SLC")[0])
        files.append(path.parent / parts[1])
    theta = scale * (offset + np.array(theta))
    if np.any(np.diff(theta) < 1e-3) or theta[-1] - theta[0] >= 2 * math.pi:
        raise _err(path, "expected slice angles increasing by at least 0.001 rad and spanning less than 2 pi")
    missing = [str(f) for f in files if not f.is_file()]
    if missing:
        raise _err(path, f"slice file {missing[0]} not found")
    base = read_profile(files[0], "wheel")
    sy, sz, shift, z0 = _transform(base, *_points(files[0]))
    profiles = []
    lo, hi = -math.inf, math.inf
    for f in files:
        y_mm, z_mm = _points(f)
        y, z = (sy * y_mm - shift) / 1e3, (sz * z_mm - z0) / 1e3
        order = np.argsort(y)
        y, z = y[order], z[order]
        profiles.append((y, z))
        lo, hi = max(lo, y[0]), min(hi, y[-1])
    lo, hi = max(lo, base.y_m[0]), min(hi, base.y_m[-1])
    if not hi - lo > 4 * lateral_step_m:
        raise _err(path, "the slices have no common lateral range")
    grid = np.arange(lo, hi + 0.5 * lateral_step_m, lateral_step_m)
    grid = grid[grid <= hi]
    base_z = np.interp(grid, base.y_m, base.z_m)
    # the file's z relative to the reader's base: the base's removed offset z0 is kept (module docstring)
    deviation = np.array([np.interp(grid, y, z) - base_z for y, z in profiles]) + z0 / 1e3
    if smoothing_wavelength_m > 0:
        from scipy.interpolate import make_smoothing_spline

        step_mm = lateral_step_m * 1e3
        lam = (smoothing_wavelength_m * 1e3 / (2.0 * math.pi)) ** 4 / step_mm
        y_mm = grid * 1e3
        deviation = np.array([make_smoothing_spline(y_mm, row, lam=lam)(y_mm) for row in deviation])
    if th_intpol == 2.0:
        deviation = approximating_values(theta, deviation)
    alpha = 0.5 * math.pi - theta  # module docstring
    order = np.argsort(alpha)
    irregularity = MeasuredWheelIrregularity(alpha[order], grid, deviation[order])
    return WheelSlices(base, irregularity, theta, str(path), int(th_intpol), z0 / 1e3)


def contact_smoothing_wavelength_m(smooth: float, path) -> float:
    """L_filt (m) of this package's smoothing splines equivalent to CONTACT's profile SMOOTH with its default method
    (ISMOOTH 0: a non-weighted smoothing spline, sum over the file's points of (z_i - f(s_i))^2 + SMOOTH times the
    integral of f''^2 ds, s in mm; CONTACT's m_profile, read to learn). The weighted spline here minimises
    integral (z - f)^2 ds + (L_filt / 2 pi)^4 integral f''^2 ds; a sum over points spaced h is the integral / h, so
    L_filt = 2 pi (h SMOOTH)^(1/4) with h the mean spacing of the file's points (mm). Exact for uniform spacing;
    CONTACT's wheelflat slices (SMOOTH 5, h 0.87 mm) give 9.1 mm, not the 5 mm that reading SMOOTH as L_filt gives
    (ISMOOTH 1 and 2 take SMOOTH as L_filt: use it directly then).
    """
    y_mm, _ = _points(Path(path))
    spacing_mm = float(np.mean(np.abs(np.diff(y_mm))))
    return 2.0 * math.pi * (spacing_mm * float(smooth)) ** 0.25 / 1e3


def approximating_values(theta: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Values at the angles ``theta`` (increasing, n >= 4) of the cubic B-spline whose control points are ``rows``
    (n, m): CONTACT's approximating spline of TH_INTPOL 2 (module docstring): knots at the angles, the ends extended
    by three intervals, a phantom control point 2 c_1 - c_2 (2 c_n - c_(n-1)) at each end.
    """
    from scipy.interpolate import BSpline

    theta = np.asarray(theta, float)
    rows = np.asarray(rows, float)
    d0, d1 = theta[1] - theta[0], theta[-1] - theta[-2]
    knots = np.concatenate([theta[0] - d0 * np.arange(3, 0, -1), theta, theta[-1] + d1 * np.arange(1, 4)])
    control = np.concatenate([[2 * rows[0] - rows[1]], rows, [2 * rows[-1] - rows[-2]]])
    return BSpline(knots, control, 3)(theta)
