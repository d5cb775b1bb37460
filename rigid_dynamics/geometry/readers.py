"""Profile file readers (SIMPACK .prw/.prr, MiniProf .whl/.ban, two-column CSV) and built-in profiles.

Every reader converts millimetres to metres and brings the points into the internal profile
convention of `rigid_dynamics.geometry.profile` (y_p towards the field side, z_p down; wheel
origin at the tape circle, rail z_p = 0 at the top). What each file format says, and what is
detected from the points themselves:

SIMPACK (.prw wheel, .prr rail). Blocks ``header.begin/end``, ``spline.begin/end``,
``point.begin/end``; ``!`` starts a comment anywhere on a line, ``%`` comments a whole line (as in
CONTACT's files). ``type`` 0 = rail, 1 = wheel. The processing options are applied in the order
numbered in the files: 1 ``point.dist.min`` (drop points closer than this to the previous one),
2 ``shift.y``/``shift.z``, 3 ``rotate`` (only 0 is supported), 4 ``bound.y.min/max``,
``bound.z.min/max`` (active when min < max), 5 ``mirror.y``/``mirror.z`` (1: y -> -y / z -> -z),
6 ``inversion`` (reverse the point order), 7 ``units.len.f`` = length unit per metre (1000 for
mm; default 1). After these, SIMPACK/CONTACT profiles have y positive towards the field side
("right-side profile") and z down (CONTACT user guide, section "Wheel and rail profiles", and
its MBench example: "prw-file has flange-back at -70 mm", "rail ... inner side (y < 0)").

MiniProf (.whl wheel, .ban rail). A header (free text lines, or ``Key=Value`` lines for .ban)
ends at the first empty line; then one point per line, columns separated by blanks or tabs,
values in mm; a leading ``"`` marker on a point line is ignored. For .ban the ``ColumnDef`` key
names the columns (X = lateral, Y = vertical). MiniProf draws the track centre / flange on the
right-hand side, so rail profiles are mirrored in y (CONTACT user guide: MiniProf files
"usually need mirror_y = 1"); the direction of z is detected (below). MiniProf wheel profiles
measure y from the flange back (back face of the flange, y = 0).

CSV (.csv, .txt). Two (or more) columns y, z in mm separated by commas, semicolons, tabs or
blanks; lines starting with ``#`` are comments (``# kind: wheel`` sets the kind); an optional
non-numeric header line before the data. Written by `write_profile_csv` in the internal
convention.

Detection and normalisation (all formats), recorded in ``Profile.source``:

1. Zig-zags (a point pair that reverses the direction twice, from stitched measurements) are
   replaced by their mean and points closer than 1 um to the previous one dropped (as CONTACT's
   profile curation); then the outline must not intersect itself.
2. Function part: the longest run of points whose y is strictly monotonic is kept; vertical or
   overhanging sides (uic60_true.prr has vertical sides; flange backs and rim faces are vertical)
   are trimmed away, and each end is cut back past the last segment steeper than
   ``MAX_PROFILE_SLOPE`` (|dz/dy| > 50, within 1.15 deg of vertical) lying within 5 mm of that end,
   where z(y) is not a usable function. The full outline is kept
   in ``Profile.outline_*``.
3. z direction: a rail head is convex, its top is an interior minimum of z (z down); a wheel's
   flange tip is an interior maximum of z. The orientation is chosen so that the more prominent
   interior extremum has that type (prominence = the smaller of the drops to either side).
4. Wheel y direction: the flange tip must be nearer the low-y end of the profile than the
   high-y end (the flange is on the track-centre side); otherwise y is mirrored.
5. Wheel origin: the flange tip lies between the flange back and the tape circle. If it is at
   y > 0 the file measures y from the flange back (MiniProf; worn_high_mileage.prw) and the tape
   circle is taken ``TAPE_CIRCLE_FROM_FLANGE_BACK_M`` = 70 mm from the flange back (EN 13715,
   standard for 1435 mm gauge wheelsets): y_p = y - 70 mm. Then z is shifted so that
   z_p(0) = 0 (linear interpolation between the points).
6. Rail origin: z is shifted so that the highest point has z_p = 0; y keeps the file's origin
   (SIMPACK rails use the head centre line; placement on the track uses the gauge faces, not
   this origin).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .profile import MIN_PROFILE_POINTS, PROFILE_KINDS, Profile, find_self_intersection

__all__ = [
    "MAX_PROFILE_SLOPE",
    "TAPE_CIRCLE_FROM_FLANGE_BACK_M",
    "builtin_profiles",
    "load_profile",
    "read_profile",
    "write_profile_csv",
    "BUILTIN_PROFILE_DIR",
]

MAX_PROFILE_SLOPE = 50.0
END_ZONE_MM = 5.0
TAPE_CIRCLE_FROM_FLANGE_BACK_M = 0.070
MIN_POINT_DISTANCE_MM = 1e-3
ZIGZAG_ANGLE_RAD = 5.0 * np.pi / 6.0
MIN_PROFILE_LENGTH_MM, MAX_PROFILE_LENGTH_MM = 5.0, 500.0

BUILTIN_PROFILE_DIR = Path(__file__).resolve().parent / "data" / "profiles"

# built-in measured/reference files: name -> (file name, description); attribution in data/profiles/SOURCE.md
_BUILTIN_FILES = {
    "MBench_S1002_v3": ("MBench_S1002_v3.prw", "new S1002 wheel, Manchester Contact Benchmark v3 (SIMPACK)"),
    "MBench_UIC60_v3": (
        "MBench_UIC60_v3.prr",
        "new UIC60 rail, Manchester Contact Benchmark v3, canted 1:40 (SIMPACK)",
    ),
    "MBench_UIC60_v3_ban": ("MBench_UIC60_v3.ban", "the same rail as MBench_UIC60_v3, MiniProf format"),
    "uic60_true": ("uic60_true.prr", "UIC60 rail with vertical sides, not canted (SIMPACK)"),
    "worn_high_mileage": ("worn_high_mileage.prw", "worn heavy-haul wheel, measured and smoothed (SIMPACK)"),
    "site_b_hr": ("site_b_hr.prr", "worn high rail, heavy-haul railway, measured and smoothed (SIMPACK)"),
    "avg_wheel": ("avg_wheel.whl", "averaged measured wheel (MiniProf)"),
    "Car7216_0001r": ("Car7216_0001r.whl", "measured wheel (MiniProf)"),
    "circ_r300": ("circ_r300.prr", "circular rail head, radius 300 mm (SIMPACK)"),
    "circ_r100": ("circ_r100.prw", "circular wheel profile, radius 100 mm (SIMPACK)"),
}

BUILTIN_CANT_RAD = {"MBench_UIC60_v3": math.atan(1.0 / 40.0), "MBench_UIC60_v3_ban": math.atan(1.0 / 40.0)}
"""Cant of the rail already contained in a built-in profile's points, rad (as each file's header states; the
profile's ``cant_rad``). A profile read from a path has cant 0 unless its user states it (the case key
``rail_profile_cant_rad``): the cant of a file is data about that file, never inferred from its name."""

_EXT_KIND = {".prw": "wheel", ".prr": "rail", ".whl": "wheel", ".ban": "rail"}
_NUMBER_SPLIT = re.compile(r"[,;\s]+")


@dataclass
class _Raw:
    """Points as read, in mm, in the file's own lateral direction; plus provenance."""

    y_mm: np.ndarray
    z_mm: np.ndarray
    kind: str | None
    fmt: str
    notes: list[str] = field(default_factory=list)
    name: str = ""


def _err(path, msg, line=None):
    where = f"{path}" if line is None else f"{path}, line {line}"
    return ValueError(f"profile file {where}: {msg}")


def _floats(tokens):
    try:
        return [float(t) for t in tokens]
    except ValueError:
        return None


# --------------------------------------------------------------------------------------------- SIMPACK
def _strip_bang_comment(line):
    out, quote = [], None
    for ch in line:
        if quote:
            out.append(ch)
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
            out.append(ch)
        elif ch == "!":
            break
        else:
            out.append(ch)
    return "".join(out).strip()


def _read_simpack(path, text):
    opts: dict[str, tuple[str, int]] = {}
    pts, block = [], None
    seen_points = False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if not s or s.startswith("%") or s.startswith("!"):
            continue
        s = _strip_bang_comment(s)
        if not s:
            continue
        low = s.lower()
        if low.endswith(".begin") and " " not in low:
            block = low[: -len(".begin")]
            if block == "point":
                seen_points = True
            continue
        if low.endswith(".end") and " " not in low:
            block = None if block == low[: -len(".end")] else block
            continue
        if block == "point":
            vals = _floats(s.split())
            if vals is None or len(vals) not in (2, 3):
                raise _err(path, f"expected two or three numbers (y z [weight]) in the point block, got {s!r}", lineno)
            pts.append(vals[:2])
            continue
        if "=" in s:
            key, _, val = s.partition("=")
            key = key.strip().lower()
            if block == "header":
                key = "header." + key
            opts[key] = (val.strip().strip("'\"").strip(), lineno)
            continue
        raise _err(path, f"expected 'key = value', a '.begin'/'.end' line or a comment, got {s!r}", lineno)
    if not seen_points:
        raise _err(path, "no 'point.begin' ... 'point.end' block found (is this a SIMPACK profile?)")
    if len(pts) < MIN_PROFILE_POINTS:
        raise _err(path, f"the point block has {len(pts)} points; at least {MIN_PROFILE_POINTS} are needed")

    def num(key, default):
        if key not in opts:
            return default
        val, lineno = opts[key]
        try:
            return float(val)
        except ValueError:
            raise _err(path, f"expected a number for {key!r}, got {val!r}", lineno) from None

    notes = []
    kind = None
    if "header.type" in opts:
        t = num("header.type", None)
        if t not in (0.0, 1.0):
            val, lineno = opts["header.type"]
            raise _err(path, f"expected header 'type' 0 (rail) or 1 (wheel), got {val!r}", lineno)
        kind = "wheel" if t == 1.0 else "rail"
    p = np.asarray(pts, float)
    y, z = p[:, 0].copy(), p[:, 1].copy()
    dmin = num("point.dist.min", 0.0)
    if dmin > 0:
        keep = [0]
        for i in range(1, len(y)):
            if np.hypot(y[i] - y[keep[-1]], z[i] - z[keep[-1]]) >= dmin:
                keep.append(i)
        y, z = y[keep], z[keep]
        notes.append(f"point.dist.min={dmin:g}")
    sy, sz = num("shift.y", 0.0), num("shift.z", 0.0)
    y, z = y + sy, z + sz
    if sy or sz:
        notes.append(f"shift=({sy:g}, {sz:g})")
    rot = num("rotate", 0.0)
    if rot != 0.0:
        raise _err(
            path, f"'rotate' = {rot:g} is not supported (only 0); rotate the points before reading", opts["rotate"][1]
        )
    for ax, arr in (("y", "y"), ("z", "z")):
        lo, hi = num(f"bound.{ax}.min", 1.0), num(f"bound.{ax}.max", 0.0)
        if lo < hi:
            v = y if arr == "y" else z
            keep = (v >= lo) & (v <= hi)
            y, z = y[keep], z[keep]
            notes.append(f"bound.{ax}=[{lo:g}, {hi:g}]")
    if num("mirror.y", 0.0) == 1.0:
        y = -y
        notes.append("mirror.y")
    if num("mirror.z", 0.0) == 1.0:
        z = -z
        notes.append("mirror.z")
    if num("inversion", 0.0) == 1.0:
        y, z = y[::-1], z[::-1]
    f = num("units.len.f", 1.0)
    if not (np.isfinite(f) and f > 0):
        raise _err(path, f"expected 'units.len.f' > 0 (length unit per metre), got {f!r}", opts["units.len.f"][1])
    to_mm = 1000.0 / f
    return _Raw(y * to_mm, z * to_mm, kind, "simpack", notes)


# --------------------------------------------------------------------------------------------- MiniProf
def _read_miniprof(path, text, ext):
    lines = text.splitlines()
    try:
        blank = next(i for i, ln in enumerate(lines) if not ln.strip())
    except StopIteration:
        raise _err(path, "expected an empty line between the MiniProf header and the points") from None
    header = {}
    for ln in lines[:blank]:
        if "=" in ln:
            k, _, v = ln.partition("=")
            header[k.strip().lower()] = v.strip()
    ix, iz = 0, 1
    if "columndef" in header:
        cols = [c.strip().upper() for c in header["columndef"].split(",")]
        if "X" not in cols or "Y" not in cols:
            raise _err(path, f"expected columns X and Y in 'ColumnDef', got {header['columndef']!r}")
        ix, iz = cols.index("X"), cols.index("Y")
    pts = []
    for lineno in range(blank + 1, len(lines)):
        s = lines[lineno].strip()
        if not s:
            continue
        s = s.lstrip('"').strip()
        vals = _floats(s.split())
        if vals is None or len(vals) <= max(ix, iz):
            raise _err(
                path,
                f"expected at least {max(ix, iz) + 1} numbers (lateral, vertical) per point, got {s!r}",
                lineno + 1,
            )
        pts.append((vals[ix], vals[iz]))
    if len(pts) < MIN_PROFILE_POINTS:
        raise _err(path, f"found {len(pts)} points after the header; at least {MIN_PROFILE_POINTS} are needed")
    p = np.asarray(pts, float)
    kind = _EXT_KIND[ext]
    notes = []
    y = p[:, 0]
    if kind == "rail":
        y = -y
        notes.append("mirrored y (MiniProf rail: track centre at +y)")
    for key in ("xoffset", "yoffset"):
        if header.get(key) and _floats([header[key]]) not in (None, [0.0]):
            notes.append(f"{key}={header[key]} not applied")
    return _Raw(y, p[:, 1].copy(), kind, "miniprof", notes)


# --------------------------------------------------------------------------------------------- CSV
def _read_csv(path, text):
    kind, pts, header_seen = None, [], False
    for lineno, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if not s:
            continue
        if s.startswith("#"):
            m = re.match(r"#\s*kind\s*[:=]\s*(\w+)", s, re.IGNORECASE)
            if m:
                kind = m.group(1).lower()
                if kind not in PROFILE_KINDS:
                    raise _err(path, f"expected '# kind: wheel' or '# kind: rail', got {s!r}", lineno)
            continue
        tokens = [t for t in _NUMBER_SPLIT.split(s) if t]
        vals = _floats(tokens)
        if vals is None:
            if not pts and not header_seen:
                header_seen = True
                continue
            raise _err(path, f"expected two numbers (y_mm, z_mm), got {s!r}", lineno)
        if len(vals) < 2:
            raise _err(path, f"expected two numbers (y_mm, z_mm), got {s!r}", lineno)
        pts.append(vals[:2])
    if len(pts) < MIN_PROFILE_POINTS:
        raise _err(path, f"found {len(pts)} points; at least {MIN_PROFILE_POINTS} are needed")
    p = np.asarray(pts, float)
    return _Raw(p[:, 0].copy(), p[:, 1].copy(), kind, "csv", [])


# --------------------------------------------------------------------------------------------- normalisation
def _remove_zigzags(y, z):
    changed = True
    count = 0
    while changed and len(y) > 3:
        changed = False
        d = np.column_stack([np.diff(y), np.diff(z)])
        nrm = np.hypot(d[:, 0], d[:, 1])
        nrm[nrm == 0] = 1.0
        u = d / nrm[:, None]
        cosang = np.clip(np.sum(u[:-1] * u[1:], axis=1), -1, 1)
        turn = np.arccos(cosang)  # turn angle at interior points 1..n-2
        big = turn > ZIGZAG_ANGLE_RAD
        pair = np.nonzero(big[:-1] & big[1:])[0]
        if pair.size:
            i = pair[0] + 1  # points i, i+1 form the zig-zag
            ym, zm = 0.5 * (y[i] + y[i + 1]), 0.5 * (z[i] + z[i + 1])
            y = np.concatenate([y[:i], [ym], y[i + 2 :]])
            z = np.concatenate([z[:i], [zm], z[i + 2 :]])
            changed = True
            count += 1
    return y, z, count


def _thin(y, z, dmin):
    keep = [0]
    for i in range(1, len(y)):
        if np.hypot(y[i] - y[keep[-1]], z[i] - z[keep[-1]]) >= dmin:
            keep.append(i)
    return y[keep], z[keep], len(y) - len(keep)


def _function_part(y, z):
    """Part of the outline where z is a function of y, in ascending y.

    The outline is cut between its leftmost and its rightmost point (for ties, e.g. a vertical side,
    the pair closest along the outline): what lies beyond them is a vertical or overhanging side.
    Along the remaining path a point that steps back in y (a measurement glitch, e.g. at the flange
    tip of a measured wheel) removes the earlier points it overlaps, so that y increases strictly.
    """
    lo = np.flatnonzero(y == y.min())
    hi = np.flatnonzero(y == y.max())
    d = np.abs(lo[:, None] - hi[None, :])
    k = np.unravel_index(np.argmin(d), d.shape)
    i_lo, i_hi = int(lo[k[0]]), int(hi[k[1]])
    if i_lo <= i_hi:
        py, pz = y[i_lo : i_hi + 1], z[i_lo : i_hi + 1]
    else:
        py, pz = y[i_hi : i_lo + 1][::-1], z[i_hi : i_lo + 1][::-1]
    ky, kz = [py[0]], [pz[0]]
    for yi, zi in zip(py[1:], pz[1:], strict=True):
        while ky and ky[-1] >= yi:
            ky.pop()
            kz.pop()
        ky.append(yi)
        kz.append(zi)
    return np.asarray(ky), np.asarray(kz)


def _trim_steep_ends(y, z):
    """Cut each end back past the last segment steeper than MAX_PROFILE_SLOPE within END_ZONE_MM of that end."""
    slope = np.abs(np.diff(z) / np.diff(y))
    steep = slope > MAX_PROFILE_SLOPE
    a, b = 0, len(y) - 1
    left = np.nonzero(steep & (y[1:] <= y[0] + END_ZONE_MM))[0]
    if left.size:
        a = int(left[-1]) + 1
    right = np.nonzero(steep & (y[:-1] >= y[-1] - END_ZONE_MM))[0]
    if right.size:
        b = int(right[0])
    if b <= a:
        return y[:0], z[:0], len(y)
    return y[a : b + 1], z[a : b + 1], len(y) - (b + 1 - a)


def _prominence_max(z):
    i = int(np.argmax(z))
    if i == 0 or i == len(z) - 1:
        return 0.0, i
    return float(min(z[i] - z[:i].min(), z[i] - z[i + 1 :].min())), i


def _normalise(raw: _Raw, kind: str, path) -> Profile:
    notes = list(raw.notes)
    y, z = np.asarray(raw.y_mm, float), np.asarray(raw.z_mm, float)
    if not (np.isfinite(y).all() and np.isfinite(z).all()):
        i = int(np.argmax(~(np.isfinite(y) & np.isfinite(z))))
        raise _err(path, f"point {i} is not finite (y={y[i]!r}, z={z[i]!r}); expected finite numbers")
    y, z, nzig = _remove_zigzags(y, z)
    if nzig:
        notes.append(f"{nzig} zig-zag(s) merged")
    y, z, nthin = _thin(y, z, MIN_POINT_DISTANCE_MM)
    if nthin:
        notes.append(f"{nthin} point(s) closer than {MIN_POINT_DISTANCE_MM * 1000:g} um dropped")
    length = float(np.sum(np.hypot(np.diff(y), np.diff(z))))
    if not (MIN_PROFILE_LENGTH_MM <= length <= MAX_PROFILE_LENGTH_MM):
        raise _err(
            path,
            f"profile length {length:.6g} mm is outside [{MIN_PROFILE_LENGTH_MM:g}, {MAX_PROFILE_LENGTH_MM:g}] mm "
            "expected of a wheel or rail profile; check the length unit (units.len.f)",
        )
    hit = find_self_intersection(y, z)
    if hit is not None:
        raise _err(
            path,
            f"the profile intersects itself (segments {hit[0]} and {hit[1]} near y={y[hit[0]]:.4f} mm, "
            f"z={z[hit[0]]:.4f} mm); expected a simple curve",
        )
    fy, fz = _function_part(y, z)
    if len(fy) < len(y):
        notes.append(
            f"trimmed to the part where z is a function of y "
            f"({len(y) - len(fy)} points of vertical/overhanging sides removed)"
        )
    fy, fz, nsteep = _trim_steep_ends(fy, fz)
    if nsteep:
        notes.append(f"{nsteep} end point(s) steeper than |dz/dy| = {MAX_PROFILE_SLOPE:g} removed")
    if len(fy) < MIN_PROFILE_POINTS:
        raise _err(
            path, f"only {len(fy)} points remain where z is a function of y; at least {MIN_PROFILE_POINTS} are needed"
        )
    # z direction
    pmax, imax = _prominence_max(fz)
    pmin, imin = _prominence_max(-fz)
    want_max = kind == "wheel"
    if (want_max and pmin > pmax) or (not want_max and pmax > pmin):
        z, fz = -z, -fz
        notes.append("z mirrored (detected: z pointed up)")
        imax, imin = imin, imax
        pmax, pmin = pmin, pmax
    if kind == "wheel":
        if pmax > 0:
            y_tip = fy[imax]
            if (y_tip - fy[0]) > (fy[-1] - y_tip):
                y, fy, fz = -y, -fy[::-1], fz[::-1]
                notes.append("y mirrored (detected: flange at +y)")
                y_tip = -y_tip
            if y_tip > 0:
                shift = TAPE_CIRCLE_FROM_FLANGE_BACK_M * 1000.0
                y, fy = y - shift, fy - shift
                notes.append(f"y origin moved to the tape circle {shift:g} mm from the flange back")
        if not (fy[0] <= 0.0 <= fy[-1]):
            raise _err(path, f"the tape circle y_p = 0 lies outside the profile [{fy[0]:.3f}, {fy[-1]:.3f}] mm")
        z0 = float(np.interp(0.0, fy, fz))
    else:
        z0 = float(fz.min())
    z, fz = z - z0, fz - z0
    if z0 != 0.0:
        notes.append(f"z shifted by {-z0:.6g} mm")
    src = f"{path} ({raw.fmt}, mm -> m" + ("; " + "; ".join(notes) if notes else "") + ")"
    return Profile(fy / 1000.0, fz / 1000.0, kind, raw.name, src, y / 1000.0, z / 1000.0)


# --------------------------------------------------------------------------------------------- public API
def read_profile(path, kind: str | None = None) -> Profile:
    """Read a wheel or rail profile file into a `Profile` in the internal convention (module docstring).

    Args:
        path: file path; the format is chosen by the extension: .prw/.prr (SIMPACK), .whl/.ban
            (MiniProf), .csv/.txt (two columns y, z in mm).
        kind: "wheel" or "rail"; None takes it from the file (SIMPACK ``type``, the extension, or a
            ``# kind:`` line in a CSV file).

    Raises:
        ValueError: missing or unreadable file, unknown extension, malformed content (naming the
            file, the line and what was expected), kind mismatch, invalid points.
    """
    p = Path(path)
    if kind is not None and kind not in PROFILE_KINDS:
        raise ValueError(f"kind must be one of {PROFILE_KINDS} or None, got {kind!r}")
    ext = p.suffix.lower()
    if ext not in (".prw", ".prr", ".whl", ".ban", ".csv", ".txt"):
        raise _err(p, f"unknown extension {p.suffix!r}; expected .prw, .prr, .whl, .ban, .csv or .txt")
    try:
        text = p.read_text(encoding="utf-8-sig", errors="replace")  # -sig: a UTF-8 byte-order mark is dropped
    except OSError as exc:
        raise _err(p, f"cannot be read ({exc.strerror or exc})") from None
    if ext in (".prw", ".prr"):
        raw = _read_simpack(p, text)
        if raw.kind is None:
            raw.kind = _EXT_KIND[ext]
    elif ext in (".whl", ".ban"):
        raw = _read_miniprof(p, text, ext)
    else:
        raw = _read_csv(p, text)
    if kind is not None and raw.kind is not None and kind != raw.kind:
        raise _err(p, f"the file holds a {raw.kind} profile but kind={kind!r} was requested")
    kind = kind or raw.kind
    if kind is None:
        raise _err(p, "the kind of profile is unknown; pass kind='wheel' or kind='rail' (or add '# kind: ...')")
    raw.name = p.stem
    return _normalise(raw, kind, p)


def write_profile_csv(path, profile: Profile) -> Path:
    """Write ``profile`` as CSV in mm (internal convention), readable by `read_profile`.

    The file holds ``# name:``, ``# kind:`` and ``# source:`` comment lines, a header ``y_mm,z_mm``
    and one point per line with 10 decimals (1e-13 m). Written to a temporary name and renamed.
    """
    if not isinstance(profile, Profile):
        raise ValueError(f"profile must be a Profile, got {type(profile).__name__}")
    from rigid_dynamics.files import write_text

    p = Path(path)
    lines = [
        f"# name: {profile.name}",
        f"# kind: {profile.kind}",
        f"# source: {profile.source}".replace("\n", " "),
        "y_mm,z_mm",
    ]
    lines += [f"{y * 1000.0:.10f},{z * 1000.0:.10f}" for y, z in zip(profile.y_m, profile.z_m, strict=True)]
    return write_text(p, "\n".join(lines) + "\n")


def builtin_profiles() -> dict[str, str]:
    """Built-in profile names and one-line descriptions (files under data/profiles, see SOURCE.md there)."""
    out = {name: desc for name, (_, desc) in _BUILTIN_FILES.items()}
    try:
        from .standard_profiles import ANALYTIC_PROFILES
    except ImportError:  # stage without analytic profiles
        return out
    out.update({name: desc for name, (desc, _) in ANALYTIC_PROFILES.items()})
    return out


def load_profile(name_or_path, kind: str | None = None) -> Profile:
    """A built-in profile by name (see `builtin_profiles`, case-insensitive) or a profile file by path.

    Raises:
        ValueError: unknown name that is not an existing file (lists the built-in names), kind mismatch,
            or any error of `read_profile`.
    """
    if kind is not None and kind not in PROFILE_KINDS:
        raise ValueError(f"kind must be one of {PROFILE_KINDS} or None, got {kind!r}")
    key = str(name_or_path)
    lookup = {n.lower(): n for n in builtin_profiles()}
    if key.lower() in lookup:
        name = lookup[key.lower()]
        if name in _BUILTIN_FILES:
            prof = read_profile(BUILTIN_PROFILE_DIR / _BUILTIN_FILES[name][0])
            prof = Profile(
                prof.y_m, prof.z_m, prof.kind, name, prof.source, prof.outline_y_m, prof.outline_z_m,
                cant_rad=BUILTIN_CANT_RAD.get(name, 0.0),
            )  # fmt: skip
        else:
            from .standard_profiles import ANALYTIC_PROFILES

            prof = ANALYTIC_PROFILES[name][1]()
        if kind is not None and prof.kind != kind:
            raise ValueError(f"built-in profile {name!r} is a {prof.kind} profile, but kind={kind!r} was requested")
        return prof
    p = Path(key)
    if not p.exists():
        raise ValueError(
            f"profile {key!r} is neither a built-in profile "
            f"({', '.join(sorted(builtin_profiles()))}) nor an existing file"
        )
    return read_profile(p, kind)
