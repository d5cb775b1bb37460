"""Creep-force tables for fast dynamics: a rung's creep forces tabulated once over the normalised creepages and the
patch shape, interpolated per patch (CONTACT's table generation; Kalker's USETAB idea).

Normalisation (Kalker 1990 sec. 3.3; CONTACT's, Vollebregt's user guide): on a Hertz ellipse with semi-axes a
(rolling direction) and b, normal force N, friction mu, combined shear modulus G and Kalker's C_ij(a/b, nu)::

    xi*  = G a b C11 xi / (3 mu N)       eta* = G a b C22 eta / (3 mu N)       phi* = G (ab)^1.5 C23 phi / (3 mu N)
    F_x = mu N f_x(c*, a/b),   F_y = mu N f_y(c*, a/b),   M_z = mu N sqrt(ab) m_z(c*, a/b)

so that for Coulomb friction the creep force of Kalker's theories depends on c* = (xi*, eta*, phi*), a/b and nu
only (G, mu, N and the patch size drop out; pure creepage saturates at |xi*| = 1 in the simplified theory). The
table's third axis scales phi* by a factor of a/b alone: phi^ = G a b (C11 b + C22 a) phi / (6 mu N), the spin's
rigid slip at the patch's edges (phi b along x, phi a across) normalised as xi and eta are. On slender patches phi*
weighs spin by C23 sqrt(ab), far below its effect on the saturated force (a/b = 0.14: 23 times): the same grid in
phi* missed FASTSIM by up to 6.1 % of mu N (500 random points, at a/b = 0.14), in phi^ by 1.8 %. The
table therefore serves every patch of a material's Poisson ratio and every Coulomb coefficient, also one that varies
in place (mu at the patch's place). Falling friction (mu of the slip velocity V |s|) adds the rolling speed and the
law's parameters as variables: it is not tabulated, and asking for it raises :class:`TableUnavailable`.

Grid (:data:`GRID`): c* in spherical form. The magnitude r = |(xi*, eta*, phi^)| is mapped to rho = r / (1 + r)
in [0, 1] (rho = 1: r -> infinity, full slip, evaluated at r = :data:`FULL_SLIP_R`) and the axis is uniform in
s = 1 - sqrt(1 - rho) (nodes closer towards full slip, where FASTSIM's force still turns towards the creepage up to
r ~ 1000; saturation at r ~ 1 sits at rho = 1/2, s = 0.29). The direction is given by its longitude
theta = atan2(eta*, xi*) in [-pi, pi] and latitude lam = asin(phi^/r) in [-pi/2, pi/2], the shape by ln(a/b) in
[-ln 20, ln 20]; uniform in each, interpolated multilinearly (16 corners). The table holds the forces divided by
rho (the face rho = 0 holds their limit, the linear theory's slopes, evaluated at r = :data:`SMALL_R`) and the
interpolation multiplies by rho: in the linear regime F = 3 r = 3 rho/(1 - rho) is convex in rho, and interpolating
F itself overshot by 1/(1 - rho_1) (2.5 % at the first node), while F/rho = 3/(1 - rho) is followed to 0.02 %. A
patch with a/b outside the table's range is solved by the source rung itself (:func:`tabulated_forces` says so by
its flag).

Source rung: ``fastsim`` (contact.fastsim._fastsim_one with contact.fastsim.flexibilities_one, the kernels the
compiled loop's FASTSIM runs) at the run's grid, traction bound and flexibility. The blended "three" flexibility
(contact.fastsim) weighs xi, eta and phi by one norm whose terms have different units, so with spin its forces are
not exactly invariant under the patch size: the table is built at a patch of :data:`REFERENCE_SIZE_M` (sqrt(ab));
the interpolation error stated by tests/test_creep_table.py and benchmarks/bench_creep_table.py is measured over
patch sizes 2-15 mm and includes that departure.

Cache: the table is built once per (Poisson ratio, source rung and its options, grid) and stored, as the contact
geometry tables are (wheelset/providers/table_cache.py), in ``$WHEELRAIL_CACHE_DIR/creep_tables`` (else
``$XDG_CACHE_HOME/wheelrail/creep_tables``, else ``~/.cache/wheelrail/creep_tables``), one ``creep-table-<key>.npz``
per key, written atomically (rigid_dynamics.files.atomic_write); the key is SHA-256 of those inputs and of the
source of the code that computes the table (this file, contact/fastsim.py, contact/kalker.py and its data). A file
that cannot be read or holds another key is rebuilt.
"""

from __future__ import annotations

import hashlib
import math
import os
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact.fastsim import (
    FastsimGrid,
    FastsimPatch,
    PatchFriction,
    StripFields,
    _fastsim_one,
    flexibilities_one,
)
from rigid_dynamics.contact.friction import FRICTION_COULOMB, VARIES_NOWHERE, FrictionRecord

_FORMAT = "wheelrail-creep-table-2"
_HERE = Path(__file__).resolve().parent
_SOURCES = (_HERE / "creep_table.py", _HERE / "fastsim.py", _HERE / "kalker.py", _HERE / "friction.py")

SOURCES = ("fastsim",)
"""The rungs a table can be built of. BEM is not among them: at ~20 ms a patch its table of GRID's 0.6 million nodes
would take hours to build (see docs/models.md, "Creep-force tables")."""

REFERENCE_SIZE_M = 6.0e-3
"""sqrt(ab) of the patches the table is built on (a wheel-rail tread patch); see the module docstring."""
REFERENCE_NORMAL_FORCE_N = 1.0e5
"""N of the patches the table is built on (N, mu and G drop out of the normalised forces)."""
REFERENCE_FRICTION = 0.3
"""mu of the patches the table is built on."""
FULL_SLIP_R = 1.0e4
"""|c*| at rho = 1 (full slip)."""
SMALL_R = 1.0e-6
"""|c*| at rho = 0 (the limit of F/rho: the linear regime)."""


class TableGrid(NamedTuple):
    """The table's uniform axes: points in s = 1 - sqrt(1 - rho), rho = r/(1 + r), longitude theta, latitude lam and
    ln(a/b) (module docstring), and the largest |ln(a/b)| tabulated.
    """

    magnitude_points: int
    longitude_points: int
    latitude_points: int
    shape_points: int
    max_log_ratio: float


GRID = TableGrid(41, 65, 33, 17, math.log(20.0))
"""The grid of the tables built here; its interpolation error is measured in benchmarks/results/creep_table.md."""

F_X, F_Y, M_Z = range(3)
"""The values per node: F_x/(mu N), F_y/(mu N), M_z/(mu N sqrt(ab)) (forces on the wheel, contact frame), each divided
by rho (module docstring)."""


class CreepTable(NamedTuple):
    """A creep-force table as compiled code reads it: ``values`` (float32; shape points, latitude points, longitude
    points, magnitude points, 3) with the rows :data:`F_X`, :data:`F_Y`, :data:`M_Z`, on the uniform grid of ln(a/b)
    from ``log_ratio_start`` by ``log_ratio_step`` and the spherical axes of :data:`GRID` (s in [0, 1], theta in
    [-pi, pi], lam in [-pi/2, pi/2]); ``source_code`` the source rung's index in :data:`SOURCES` (-1: an empty
    table, no run uses it).
    """

    log_ratio_start: float
    log_ratio_step: float
    values: np.ndarray
    source_code: int


def empty_table() -> CreepTable:
    """The table of a run that does not use one (same types, two points per axis, never read)."""
    return CreepTable(0.0, 1.0, np.zeros((2, 2, 2, 2, 3), np.float32), -1)


class TableUnavailable(ValueError):
    """A table asked for what it cannot serve (a falling friction law, an unknown source); the message says which."""


@dataclass(frozen=True)
class BuiltTable:
    """A table and how it was had: ``table`` (:class:`CreepTable`), ``status`` "hit" (loaded from the cache),
    "built" or "rebuilt" (a bad file replaced), ``path`` of its cache file (None: not written), ``build_time_s``
    (0 for a hit), ``note`` a sentence when something was wrong.
    """

    table: CreepTable
    status: str
    path: Path | None
    build_time_s: float
    note: str = ""

    @property
    def size_bytes(self) -> int:
        """The bytes of the tabulated values."""
        return int(self.table.values.nbytes)


class SourceOptions(NamedTuple):
    """The source rung and its options: FASTSIM's grid nx x ny, traction bound ("elliptic" or "parabolic") and
    flexibility (contact.fastsim.FLEXIBILITY_CODES' names).
    """

    source: str = "fastsim"
    nx: int = 20
    ny: int = 20
    traction_bound: str = "elliptic"
    flexibility: str = "three"


DEFAULT_SOURCE = SourceOptions()
"""FASTSIM at 20 x 20, elliptic bound, blended flexibilities (the scenes' default)."""


def check_friction(law) -> None:
    """Raise :class:`TableUnavailable` unless ``law`` (contact.friction.FrictionLaw, or None: Coulomb) is Coulomb's."""
    if law is not None and not law.is_coulomb:
        raise TableUnavailable(
            f"friction law = {law.laws[0].law!r} (falling with the slip velocity): a creep-force table is built for "
            "Coulomb friction only (falling friction adds the rolling speed and the law's parameters as variables, "
            "not tabulated); expected friction law 'coulomb', or the rung itself ('fastsim')"
        )


def _check_source(options: SourceOptions) -> None:
    if options.source not in SOURCES:
        raise TableUnavailable(f"source = {options.source!r}: expected one of {', '.join(SOURCES)}")


# --- the normalisation --------------------------------------------------------------------------------------------
@njit(cache=True, _nrt=False, inline="always")
def normalised_creepages(shear_modulus_Pa, patch, mu_n, creep):
    """The table's coordinates (xi*, eta*, phi^) of creep = (xi, eta, phi) on patch = (a, b, C11, C22, C23),
    mu_n = mu N (module docstring; phi^ = G a b (C11 b + C22 a) phi / (6 mu N)).
    """
    a, b, c11, c22, _ = patch
    xi, eta, phi = creep
    scale = shear_modulus_Pa * a * b / (3.0 * mu_n)
    return scale * c11 * xi, scale * c22 * eta, 0.5 * scale * (c11 * b + c22 * a) * phi


@njit(cache=True, _nrt=False, inline="always")
def uniform_cell(x, x0, step, n):
    """(cell, weight) of x on the uniform axis x0 + i step, i < n, clamped to its ends (the compiled Hertz and
    Kalker tables, wheelset.compiled_laws, look up their axes with it too).
    """
    f = (x - x0) / step
    if f < 0.0:
        f = 0.0
    if f > n - 1.0:
        f = n - 1.0
    i = min(int(f), n - 2)
    return i, f - i


@njit(cache=True, _nrt=False)
def tabulated_forces(table, log_ratio, star):
    """(f_x, f_y, m_z, inside) interpolated at ln(a/b) = log_ratio and c* = star (:func:`normalised_creepages`):
    the normalised forces (:data:`F_X`, ...); inside False (forces 0) when ln(a/b) is beyond the table's range.
    """
    v = table.values
    ns, nl, nt, nr = v.shape[0], v.shape[1], v.shape[2], v.shape[3]
    top = table.log_ratio_start + (ns - 1) * table.log_ratio_step
    if log_ratio < table.log_ratio_start - 1e-12 or log_ratio > top + 1e-12:
        return 0.0, 0.0, 0.0, False
    xs, ys, zs = star
    r = math.sqrt(xs * xs + ys * ys + zs * zs)
    if r == 0.0:
        return 0.0, 0.0, 0.0, True
    rho = r / (1.0 + r)
    spread = 1.0 - math.sqrt(1.0 - rho)  # the magnitude axis (module docstring)
    theta = math.atan2(ys, xs)
    lam = math.asin(max(-1.0, min(1.0, zs / r)))
    i0, w0 = uniform_cell(log_ratio, table.log_ratio_start, table.log_ratio_step, ns)
    i1, w1 = uniform_cell(lam, -0.5 * math.pi, math.pi / (nl - 1), nl)
    i2, w2 = uniform_cell(theta, -math.pi, 2.0 * math.pi / (nt - 1), nt)
    i3, w3 = uniform_cell(spread, 0.0, 1.0 / (nr - 1), nr)
    fx, fy, mz = 0.0, 0.0, 0.0  # the table holds F / rho
    for d0 in range(2):
        c0 = w0 if d0 else 1.0 - w0
        for d1 in range(2):
            c1 = c0 * (w1 if d1 else 1.0 - w1)
            for d2 in range(2):
                c2 = c1 * (w2 if d2 else 1.0 - w2)
                for d3 in range(2):
                    c3 = c2 * (w3 if d3 else 1.0 - w3)
                    node = v[i0 + d0, i1 + d1, i2 + d2, i3 + d3]
                    fx += c3 * node[F_X]
                    fy += c3 * node[F_Y]
                    mz += c3 * node[M_Z]
    return rho * fx, rho * fy, rho * mz, True


@njit(cache=True, _nrt=False, inline="always")
def table_creep_law(table, shear_modulus_Pa, patch, creep, mu_n):
    """(T_x, T_y, M_z, inside) of the table on a Hertz patch = (a, b, C11, C22, C23) with creep = (xi, eta, phi) and
    mu_n = mu N: the normalised forces scaled back (forces on the wheel, contact frame); inside False when a/b is
    beyond the table (then the caller solves the patch with the source rung).
    """
    a, b = patch[0], patch[1]
    if mu_n <= 0.0:
        return 0.0, 0.0, 0.0, True
    star = normalised_creepages(shear_modulus_Pa, patch, mu_n, creep)
    fx, fy, mz, inside = tabulated_forces(table, math.log(a / b), star)
    return mu_n * fx, mu_n * fy, mu_n * math.sqrt(a * b) * mz, inside


# --- building ----------------------------------------------------------------------------------------------------
def node_creepages(grid: TableGrid) -> tuple[np.ndarray, np.ndarray]:
    """The table's nodes: ln(a/b) (shape points,) and c* (latitude, longitude, magnitude, 3)."""
    log_ratio = np.linspace(-grid.max_log_ratio, grid.max_log_ratio, grid.shape_points)
    lam = np.linspace(-0.5 * math.pi, 0.5 * math.pi, grid.latitude_points)
    theta = np.linspace(-math.pi, math.pi, grid.longitude_points)
    rho = 1.0 - (1.0 - np.linspace(0.0, 1.0, grid.magnitude_points)) ** 2
    r = np.empty_like(rho)
    r[:-1] = rho[:-1] / (1.0 - rho[:-1])
    r[0] = SMALL_R
    r[-1] = FULL_SLIP_R
    lm, th, rr = np.meshgrid(lam, theta, r, indexing="ij")
    star = np.stack([rr * np.cos(lm) * np.cos(th), rr * np.cos(lm) * np.sin(th), rr * np.sin(lm)], axis=-1)
    return log_ratio, star


@njit(cache=True)
def _fastsim_nodes(star, coefficients, material, options, out):
    """FASTSIM at every node of one shape: star (..., 3) normalised creepages (none zero); coefficients (a, b, C11,
    C22, C23); material (G, mu, N); options (nx, ny, parabolic, flexibility code); out (..., 3) the normalised forces
    divided by rho.
    """
    a, b, c11, c22, c23 = coefficients
    g_mod, mu, fn = material
    nx, ny, parabolic, flex = options
    ab = a * b
    scale = 3.0 * mu * fn / (g_mod * ab)
    law = _coulomb_record(mu)
    friction = PatchFriction(law, 0.0, mu, 1.0)
    d = np.zeros((1, 1))
    fields = StripFields(d, d, d, d, False)
    grid = FastsimGrid(nx, ny, parabolic)
    flat = star.reshape(-1, 3)
    res = out.reshape(-1, 3)
    for k in range(flat.shape[0]):
        xi = scale * flat[k, 0] / c11
        eta = scale * flat[k, 1] / c22
        phi = 2.0 * scale * flat[k, 2] / (c11 * b + c22 * a)
        flexes = flexibilities_one(a, b, fn, xi, eta, phi, g_mod, mu, (c11, c22, c23), flex)
        fs = _fastsim_one(FastsimPatch(a, b, fn, xi, eta, phi), flexes, friction, grid, fields)
        r = math.sqrt(flat[k, 0] ** 2 + flat[k, 1] ** 2 + flat[k, 2] ** 2)
        rho = r / (1.0 + r)  # the table holds F / rho
        res[k, 0] = fs[0] / (mu * fn * rho)
        res[k, 1] = fs[1] / (mu * fn * rho)
        res[k, 2] = fs[2] / (mu * fn * math.sqrt(ab) * rho)


@njit(cache=True)
def _coulomb_record(mu):
    """The FrictionRecord of Coulomb's law with coefficient mu (contact.friction.uniform(mu).record())."""
    one = np.array([mu])
    return FrictionRecord(FRICTION_COULOMB, VARIES_NOWHERE, np.zeros(1), one, np.zeros(1), np.ones(1), np.zeros(1),
                          np.ones(1))  # fmt: skip


def build(poisson_ratio: float, options: SourceOptions = DEFAULT_SOURCE, grid: TableGrid = GRID) -> CreepTable:
    """Build the table of the source rung ``options`` for Poisson ratio ``poisson_ratio`` on ``grid`` (no cache)."""
    from rigid_dynamics.contact.fastsim import FLEXIBILITY_CODES
    from rigid_dynamics.contact.kalker import kalker_coefficients

    _check_source(options)
    log_ratio, star = node_creepages(grid)
    values = np.zeros((grid.shape_points, *star.shape))  # float32 when stored (interpolation error >> 1e-7)
    coef = kalker_coefficients(np.exp(log_ratio), poisson_ratio)
    shear = 1.0  # G drops out; any value serves (module docstring)
    settings = (int(options.nx), int(options.ny), options.traction_bound == "parabolic",
                int(FLEXIBILITY_CODES[options.flexibility]))  # fmt: skip
    for s, lr in enumerate(log_ratio):
        a = REFERENCE_SIZE_M * math.exp(0.5 * lr)
        b = REFERENCE_SIZE_M * math.exp(-0.5 * lr)
        patch = (a, b, float(coef.c11[s]), float(coef.c22[s]), float(coef.c23[s]))
        material = (shear, REFERENCE_FRICTION, REFERENCE_NORMAL_FORCE_N)
        _fastsim_nodes(star, patch, material, settings, values[s])
    step = float(log_ratio[1] - log_ratio[0])
    return CreepTable(float(log_ratio[0]), step, values.astype(np.float32), SOURCES.index(options.source))


# --- the cache ---------------------------------------------------------------------------------------------------
def cache_dir() -> Path:
    """The folder of the table files (module docstring)."""
    explicit = os.environ.get("WHEELRAIL_CACHE_DIR")
    if explicit:
        return Path(explicit) / "creep_tables"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "wheelrail" / "creep_tables"


def table_key(poisson_ratio: float, options: SourceOptions, grid: TableGrid) -> str:
    """The cache key of a table (module docstring)."""
    digest = hashlib.sha256()
    digest.update(_FORMAT.encode())
    digest.update(repr((float(poisson_ratio), tuple(options), tuple(grid))).encode())
    digest.update(repr((REFERENCE_SIZE_M, REFERENCE_NORMAL_FORCE_N, REFERENCE_FRICTION, FULL_SLIP_R)).encode())
    for path in (*_SOURCES, _HERE / "data" / "kalker_creep_coefficients.csv"):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _load(path: Path, key: str, shape: tuple) -> tuple[CreepTable | None, str]:
    if not path.exists():
        return None, ""
    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["key"]) != key:
                raise ValueError("it holds another key")
            values = np.ascontiguousarray(data["values"], dtype=np.float32)
            start, step, source = (float(v) for v in data["axis"])
        if values.shape != shape or not np.all(np.isfinite(values)):
            raise ValueError(f"values of shape {values.shape} (expected {shape}) or not finite")
    except Exception as exc:  # noqa: BLE001 -- any unreadable file is rebuilt, never trusted
        return None, f"creep-table cache file {path} unreadable ({type(exc).__name__}: {exc}): rebuilt"
    return CreepTable(start, step, values, int(source)), ""


def _save(path: Path, key: str, table: CreepTable) -> str:
    from rigid_dynamics.files import atomic_write

    def writer(tmp: Path) -> None:
        with open(tmp, "wb") as handle:
            axis = np.array([table.log_ratio_start, table.log_ratio_step, table.source_code], dtype=np.float64)
            np.savez(handle, key=np.array(key), values=table.values, axis=axis)

    try:
        atomic_write(path, writer)
    except OSError as exc:
        return f"creep table not cached ({path}: {exc})"
    return ""


def creep_table(poisson_ratio: float, options: SourceOptions = DEFAULT_SOURCE, grid: TableGrid = GRID) -> BuiltTable:
    """The table of ``options``' source rung for ``poisson_ratio``: from this process's memory, else the disk cache,
    else built and cached (module docstring). Raises :class:`TableUnavailable` for an unknown source.
    """
    _check_source(options)
    return _creep_table(float(poisson_ratio), SourceOptions(*options), grid)


@lru_cache(maxsize=8)
def _creep_table(poisson_ratio: float, options: SourceOptions, grid: TableGrid) -> BuiltTable:
    key = table_key(poisson_ratio, options, grid)
    path = cache_dir() / f"creep-table-{key[:32]}.npz"
    shape = (grid.shape_points, grid.latitude_points, grid.longitude_points, grid.magnitude_points, 3)
    table, note = _load(path, key, shape)
    if table is not None:
        return BuiltTable(table, "hit", path, 0.0)
    start = time.perf_counter()
    table = build(poisson_ratio, options, grid)
    elapsed = time.perf_counter() - start
    save_note = _save(path, key, table)
    notes = "; ".join(n for n in (note, save_note) if n)
    return BuiltTable(table, "rebuilt" if note else "built", None if save_note else path, elapsed, notes)


# --- the table against its source --------------------------------------------------------------------------------
class SampleErrors(NamedTuple):
    """The table against its source rung over a random sample: per point the creep-force vector's departure
    |F_table - F_source| / (mu N) and the spin moment's |M_table - M_source| / (mu N sqrt(ab)) (arrays), the max and
    rms of each, the points, and the source's and the table's evaluation time per point (s, one run); then the
    force's departure relative to the force itself, |F_table - F_source| / max(|F_source|, 0.01 mu N) (the bench's
    definition, contact_tolerance's), its max and rms.
    """

    force_error: np.ndarray
    moment_error: np.ndarray
    max_force_error: float
    rms_force_error: float
    max_moment_error: float
    rms_moment_error: float
    points: int
    source_time_s: float
    table_time_s: float
    relative_force_error: np.ndarray
    max_relative_force_error: float
    rms_relative_force_error: float


class SampleRanges(NamedTuple):
    """Where the random sample is drawn: |c*| log-uniform in [min, max] with its direction uniform on the sphere,
    a/b log-uniform within 1/max_ratio..max_ratio, the patch size sqrt(ab) uniform in m, N uniform in N, mu uniform,
    G in Pa.
    """

    min_star: float = 0.01
    max_star: float = 10.0
    max_ratio: float = 10.0
    size_m: tuple = (2.0e-3, 15.0e-3)
    normal_force_N: tuple = (1.0e4, 1.5e5)
    friction: tuple = (0.1, 0.6)
    shear_modulus_Pa: float = 8.2e10


def sample_patches(points: int, seed: int, poisson_ratio: float, ranges: SampleRanges | None = None) -> dict:
    """A seeded random sample of Hertz patches and creepages (:class:`SampleRanges`): arrays a, b, N, mu, C11, C22,
    C23, xi, eta, phi (dimensional) by name.
    """
    from rigid_dynamics.contact.kalker import kalker_coefficients

    ranges = ranges if ranges is not None else SampleRanges()
    rng = np.random.default_rng(seed)
    ratio = np.exp(rng.uniform(-math.log(ranges.max_ratio), math.log(ranges.max_ratio), points))
    size = rng.uniform(*ranges.size_m, points)
    a, b = size * np.sqrt(ratio), size / np.sqrt(ratio)
    fn = rng.uniform(*ranges.normal_force_N, points)
    mu = rng.uniform(*ranges.friction, points)
    direction = rng.normal(size=(points, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    star = direction * np.exp(rng.uniform(math.log(ranges.min_star), math.log(ranges.max_star), points))[:, None]
    coef = kalker_coefficients(ratio, poisson_ratio)
    scale = 3.0 * mu * fn / (ranges.shear_modulus_Pa * a * b)
    return {
        "a": a, "b": b, "normal_force_N": fn, "friction": mu, "c11": coef.c11, "c22": coef.c22, "c23": coef.c23,
        "xi": scale * star[:, 0] / coef.c11, "eta": scale * star[:, 1] / coef.c22,
        "phi": scale * star[:, 2] / (coef.c23 * np.sqrt(a * b)), "shear_modulus_Pa": ranges.shear_modulus_Pa,
    }  # fmt: skip


@njit(cache=True)
def _evaluate(table, sample, options, use_table, out):
    """Every sample point by the table (use_table) or by its source rung (FASTSIM, options as in
    :func:`_fastsim_nodes`); out (n, 3): F_x, F_y, M_z.
    """
    a_s, b_s, fn_s, mu_s, c11_s, c22_s, c23_s, xi_s, eta_s, phi_s, g_mod = sample
    nx, ny, parabolic, flex = options
    d = np.zeros((1, 1))
    fields = StripFields(d, d, d, d, False)
    grid = FastsimGrid(nx, ny, parabolic)
    for k in range(a_s.shape[0]):
        a, b, fn, mu = a_s[k], b_s[k], fn_s[k], mu_s[k]
        creep = (xi_s[k], eta_s[k], phi_s[k])
        c = (c11_s[k], c22_s[k], c23_s[k])
        if use_table:
            fx, fy, mz, inside = table_creep_law(table, g_mod, (a, b, c[0], c[1], c[2]), creep, mu * fn)
            if inside:
                out[k, 0], out[k, 1], out[k, 2] = fx, fy, mz
                continue
        flexes = flexibilities_one(a, b, fn, creep[0], creep[1], creep[2], g_mod, mu, c, flex)
        friction = PatchFriction(_coulomb_record(mu), 0.0, mu, 1.0)
        fs = _fastsim_one(FastsimPatch(a, b, fn, creep[0], creep[1], creep[2]), flexes, friction, grid, fields)
        out[k, 0], out[k, 1], out[k, 2] = fs[0], fs[1], fs[2]


def compare_with_source(table: CreepTable, options: SourceOptions, sample: dict, repeats: int = 3) -> SampleErrors:
    """The table against its source rung on ``sample`` (:func:`sample_patches`): :class:`SampleErrors`, times the
    best of ``repeats`` runs over the whole sample.
    """
    from rigid_dynamics.contact.fastsim import FLEXIBILITY_CODES

    names = ("a", "b", "normal_force_N", "friction", "c11", "c22", "c23", "xi", "eta", "phi")
    args = (*(np.ascontiguousarray(sample[n], dtype=np.float64) for n in names), float(sample["shear_modulus_Pa"]))
    settings = (int(options.nx), int(options.ny), options.traction_bound == "parabolic",
                int(FLEXIBILITY_CODES[options.flexibility]))  # fmt: skip
    n = len(args[0])
    out = {True: np.zeros((n, 3)), False: np.zeros((n, 3))}
    best = {True: math.inf, False: math.inf}
    for _ in range(max(1, repeats)):
        for use in (False, True):
            start = time.perf_counter()
            _evaluate(table, args, settings, use, out[use])
            best[use] = min(best[use], time.perf_counter() - start)
    mu_n = sample["friction"] * sample["normal_force_N"]
    diff = out[True] - out[False]
    force = np.hypot(diff[:, 0], diff[:, 1]) / mu_n
    moment = np.abs(diff[:, 2]) / (mu_n * np.sqrt(sample["a"] * sample["b"]))
    size = np.maximum(np.hypot(out[False][:, 0], out[False][:, 1]), 0.01 * mu_n)
    relative = np.hypot(diff[:, 0], diff[:, 1]) / size
    return SampleErrors(
        force, moment, float(force.max()), float(np.sqrt(np.mean(force**2))), float(moment.max()),
        float(np.sqrt(np.mean(moment**2))), n, best[False] / n, best[True] / n, relative, float(relative.max()),
        float(np.sqrt(np.mean(relative**2))),
    )  # fmt: skip


# --- the registry's model ----------------------------------------------------------------------------------------
def _table_model_class():
    from rigid_dynamics.contact.models import FastsimModel
    from rigid_dynamics.contact.options import Option, declare

    class TableModel(FastsimModel):
        """Hertz + the creep-force table of a rung (option ``source``; "fastsim", at FASTSIM's options nx, ny,
        traction_bound, flexibility), interpolated over the normalised creepages and a/b (module docstring).

        Registered as ``table``; the compiled dynamics loop runs the same interpolation (``compiled_law`` "table",
        wheelset.compiled_laws._table_law). The static solve also runs the source rung on the same patch and states
        the table's departure from it: ``extra["table_departure"]`` = |F_table - F_source| / (mu N) (creep-force
        vectors), with the source's discretisation estimate (FastsimModel's); ``extra["table_source"]``,
        ``extra["table_cache"]`` (hit / built / rebuilt). Falling friction raises :class:`TableUnavailable` (a
        ValueError).
        """

        name = "table"
        compiled_law = "table"
        description = "Hertz + FASTSIM's creep-force table (normalised creepages x a/b), for fast dynamics"
        OPTIONS: dict = declare(
            Option("source", str, "fastsim", "the rung tabulated", choices=SOURCES),
            *(option for key, option in FastsimModel.OPTIONS.items() if key != "fields"),
        )

        def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None):
            check_friction(material.friction)
            return super().solve(geometry, creepage, material, normal_force_N=normal_force_N, options=options)

        def tangential(self, hertz, creepage, material, opts):
            from rigid_dynamics.contact.kalker import kalker_coefficients

            forces, extra = super().tangential(hertz, creepage, material, {**opts, "fields": False})
            source = SourceOptions(opts["source"], int(opts["nx"]), int(opts["ny"]), opts["traction_bound"],
                                   opts["flexibility"])  # fmt: skip
            built = creep_table(material.poisson_ratio, source)
            a, b = float(hertz.semi_axis_long_m), float(hertz.semi_axis_lat_m)
            coef = kalker_coefficients(np.array([a / b]), material.poisson_ratio)
            mu_n = material.friction_coefficient * float(hertz.normal_force_N)
            fx, fy, mz, inside = table_creep_law(
                built.table, material.shear_modulus_Pa, (a, b, float(coef.c11[0]), float(coef.c22[0]),
                float(coef.c23[0])), (creepage.longitudinal, creepage.lateral, creepage.spin_1_per_m), mu_n,
            )  # fmt: skip
            if inside:
                departure = math.hypot(fx - forces["creep_force_long_N"], fy - forces["creep_force_lat_N"])
                extra["table_departure"] = departure / mu_n if mu_n > 0 else 0.0
                forces = {"creep_force_long_N": fx, "creep_force_lat_N": fy, "spin_moment_Nm": mz, "fields": None}
            else:
                extra["table_departure"] = 0.0
                extra["table_note"] = f"a/b = {a / b:.4g} beyond the table's range: solved by {source.source}"
            extra["table_source"] = f"{source.source} {source.nx}x{source.ny}"
            extra["table_cache"] = built.status
            return forces, extra

    return TableModel


def __getattr__(name):
    if name == "TableModel":
        cls = _table_model_class()
        globals()["TableModel"] = cls
        return cls
    raise AttributeError(name)
