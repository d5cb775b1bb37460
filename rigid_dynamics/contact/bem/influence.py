"""Half-space influence coefficients for uniform tractions on rectangles, and their FFT convolution.

Two elastic half-spaces touch in the plane z = 0 of the contact frame (x rolling, y lateral,
z from the rail into the wheel). Body 1 is the wheel (material at z > 0), body 2 the rail.
The traction ``(t_x, t_y, p)`` acts on the wheel (``p`` > 0 presses the bodies apart), minus it
on the rail. The *displacement difference* ``u = u(wheel) - u(rail)`` at the surface is::

    u_i(x) = sum_j  integral  A_ij(x - x') t_j(x') dx'          (Kalker 1990, sec. 1.6 and 5.2)

with, for r = |x - x'|, (X, Y) = x - x' and the combined constants of the pair
(Kalker 1990, eq 1.6.9)::

    1/G = (1/G1 + 1/G2)/2,  nu/G = (nu1/G1 + nu2/G2)/2,  K = (G/4) [(1 - 2 nu1)/G1 - (1 - 2 nu2)/G2]

    A_zz = (1 - nu)/(pi G r)                    (Boussinesq; both bodies)
    A_xx = [(1 - nu)/r + nu X^2/r^3]/(pi G)     (Cerruti)
    A_yy = [(1 - nu)/r + nu Y^2/r^3]/(pi G)
    A_xy = A_yx = nu X Y/(pi G r^3)
    A_zx = K X/(pi G r^2),  A_xz = -A_zx         (normal displacement from t_x and vice versa)
    A_zy = K Y/(pi G r^2),  A_yz = -A_zy

These follow from the single-body surface displacements of a point force on a half-space
(Johnson 1985, eq 3.19 and 3.77; the sign of the Cerruti normal displacement fixed by Betti's
reciprocity with the Boussinesq radial displacement u_r = -(1 - 2 nu) P/(4 pi G r)).
Quasi-identical bodies have K = 0: the normal and tangential problems decouple.

The coefficient of a *uniform* traction on the rectangle |x'| <= dx/2, |y'| <= dy/2 is the
double integral of the kernel. With a primitive F (d^2 F/dX dY = kernel) it is::

    C(x, y) = F(x + dx/2, y + dy/2) - F(x - dx/2, y + dy/2) - F(x + dx/2, y - dy/2) + F(x - dx/2, y - dy/2)

    1/r     : F = X asinh(Y/|X|) + Y asinh(X/|Y|)      (Love 1929, uniform pressure on a rectangle)
    X^2/r^3 : F = Y asinh(X/|Y|)
    Y^2/r^3 : F = X asinh(Y/|X|)
    XY/r^3  : F = -r
    X/r^2   : F = X atan(Y/X) + Y ln r
    Y/r^2   : F = Y atan(X/Y) + X ln r

A 2-D (plane strain, long strip along y) variant uses line elements of width dx with the line-load
kernels A_zz = A_xx = -2 (1 - nu) ln|X|/(pi G), A_yy = -2 ln|X|/(pi G), A_xy = 0 (Johnson 1985, eq
2.19 and 2.24 for both bodies; valid up to a constant, which force control absorbs).

Symbols: G shear modulus (Pa), nu Poisson's ratio, K difference parameter (-), dx, dy element
sizes (m). Displacements per unit traction: m/Pa.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
import scipy.fft

try:  # scipy.fft's own transform functions, without its dispatch layer: the same code on the same data, same bits
    from scipy.fft._duccfft import pyduccfft as _DIRECT
except ImportError:  # pragma: no cover - older scipy (pocketfft, same signatures) or a layout without either
    try:
        from scipy.fft._pocketfft import pypocketfft as _DIRECT
    except ImportError:
        _DIRECT = None


def _direct_agrees(direct) -> bool:
    """Whether scipy's private transform functions ``direct`` (not a public API: a scipy release may change their
    signatures) give scipy.fft's public results on a small padded 2-D case, forward and back; any exception: no.
    """
    try:
        values = np.arange(12.0).reshape(3, 4) ** 1.5
        spectrum = scipy.fft.rfft2(values, s=(4, 6))
        padded = np.zeros((4, 6))
        padded[:3, :4] = values
        mine = direct.c2c(direct.r2c(padded, (1,), True, 0, None, 1), (0,), True, 0, None, 1)
        back = direct.c2r(direct.c2c(mine.copy(), (0,), False, 2, None, 1), (1,), 6, False, 2, None, 1)
        return bool(np.array_equal(mine, spectrum) and np.allclose(back, scipy.fft.irfft2(spectrum, s=(4, 6))))
    except Exception:  # noqa: BLE001 - a changed private signature means: use the public functions
        return False


if _DIRECT is not None and not _direct_agrees(_DIRECT):  # pragma: no cover - a scipy whose private layer moved
    _DIRECT = None

KERNELS = ("zz", "xx", "yy", "xy", "zx", "zy", "xz", "yz")
"""Names of the influence kernels A_ij: first index displacement, second traction component."""


def combined_elastic_constants(
    shear_modulus_1_Pa: float, poisson_ratio_1: float, shear_modulus_2_Pa: float, poisson_ratio_2: float
) -> tuple[float, float, float]:
    """Combined constants (G, nu, K) of two bodies (Kalker 1990, eq 1.6.9).

    Returns:
        G (Pa) with 1/G = (1/G1 + 1/G2)/2; nu with nu/G = (nu1/G1 + nu2/G2)/2; the difference
        parameter K = (G/4) [(1 - 2 nu1)/G1 - (1 - 2 nu2)/G2] (0 for quasi-identical bodies).
    """
    for name, value in (("shear_modulus_1_Pa", shear_modulus_1_Pa), ("shear_modulus_2_Pa", shear_modulus_2_Pa)):
        if not math.isfinite(value) or value <= 0:
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    for name, value in (("poisson_ratio_1", poisson_ratio_1), ("poisson_ratio_2", poisson_ratio_2)):
        if not -1.0 < value < 0.5:
            raise ValueError(f"{name} = {value!r}: expected a value in (-1, 0.5)")
    g = 2.0 / (1.0 / shear_modulus_1_Pa + 1.0 / shear_modulus_2_Pa)
    nu = 0.5 * g * (poisson_ratio_1 / shear_modulus_1_Pa + poisson_ratio_2 / shear_modulus_2_Pa)
    k = (
        0.25
        * g
        * ((1.0 - 2.0 * poisson_ratio_1) / shear_modulus_1_Pa - (1.0 - 2.0 * poisson_ratio_2) / shear_modulus_2_Pa)
    )
    return g, nu, k


def point_load_kernels(
    x_m: np.ndarray, y_m: np.ndarray, shear_modulus_Pa: float, poisson_ratio: float, difference_parameter: float = 0.0
) -> dict[str, np.ndarray]:
    """Displacement difference per unit point force, A_ij(X, Y) of the module docstring, m/N.

    Boussinesq (normal) and Cerruti (tangential) surface solutions of both bodies combined.
    ``x_m``, ``y_m``: offsets observation - load point (not both zero), m.
    """
    x, y = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    r = np.hypot(x, y)
    c = 1.0 / (math.pi * shear_modulus_Pa)
    nu, k = poisson_ratio, difference_parameter
    out = {
        "zz": c * (1.0 - nu) / r,
        "xx": c * ((1.0 - nu) / r + nu * x * x / r**3),
        "yy": c * ((1.0 - nu) / r + nu * y * y / r**3),
        "xy": c * nu * x * y / r**3,
        "zx": c * k * x / r**2,
        "zy": c * k * y / r**2,
    }
    out["xz"] = -out["zx"]
    out["yz"] = -out["zy"]
    return out


def _x_asinh_y_over_x(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """X asinh(Y/|X|), continuous with value 0 at X = 0."""
    ax = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        val = x * np.arcsinh(y / ax)
    return np.where(ax > 0, val, 0.0)


def _primitives(x: np.ndarray, y: np.ndarray) -> dict[str, np.ndarray]:
    """Primitives F of the kernel shapes (module docstring), at corner offsets (X, Y)."""
    r = np.hypot(x, y)
    xa = _x_asinh_y_over_x(x, y)
    ya = _x_asinh_y_over_x(y, x)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_r = np.where(r > 0, np.log(np.where(r > 0, r, 1.0)), 0.0)
        x_atan = np.where(x != 0, x * np.arctan(y / np.where(x != 0, x, 1.0)), 0.0)
        y_atan = np.where(y != 0, y * np.arctan(x / np.where(y != 0, y, 1.0)), 0.0)
    return {
        "inv_r": xa + ya,
        "xx_r3": ya,
        "yy_r3": xa,
        "xy_r3": -r,
        "x_r2": x_atan + y * log_r,
        "y_r2": y_atan + x * log_r,
    }


def rectangle_influence(
    x_m: np.ndarray,
    y_m: np.ndarray,
    dx_m: float,
    dy_m: float,
    shear_modulus_Pa: float,
    poisson_ratio: float,
    difference_parameter: float = 0.0,
) -> dict[str, np.ndarray]:
    """Displacement difference at (x, y) from unit uniform traction on the rectangle |x'| <= dx/2, |y'| <= dy/2.

    Love (1929) for the normal load, the Cerruti counterparts for the tangential loads
    (primitives in the module docstring). Returns a dict kernel name -> array of the broadcast
    shape of ``x_m``, ``y_m``, in m/Pa (displacement per unit traction).
    """
    x, y = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    hx, hy = 0.5 * dx_m, 0.5 * dy_m
    acc: dict[str, np.ndarray] = {}
    for sx, sy, sign in ((1, 1, 1.0), (-1, 1, -1.0), (1, -1, -1.0), (-1, -1, 1.0)):
        prim = _primitives(x + sx * hx, y + sy * hy)
        for key, val in prim.items():
            acc[key] = acc.get(key, 0.0) + sign * val
    return _kernels_from_primitives(acc, shear_modulus_Pa, poisson_ratio, difference_parameter)


def _kernels_from_primitives(acc, shear_modulus_Pa, poisson_ratio, difference_parameter) -> dict[str, np.ndarray]:
    """The eight influence kernels from the corner-differenced primitives ``acc`` of one rectangle."""
    c = 1.0 / (math.pi * shear_modulus_Pa)
    nu, k = poisson_ratio, difference_parameter
    out = {
        "zz": c * (1.0 - nu) * acc["inv_r"],
        "xx": c * ((1.0 - nu) * acc["inv_r"] + nu * acc["xx_r3"]),
        "yy": c * ((1.0 - nu) * acc["inv_r"] + nu * acc["yy_r3"]),
        "xy": c * nu * acc["xy_r3"],
        "zx": c * k * acc["x_r2"],
        "zy": c * k * acc["y_r2"],
    }
    out["xz"] = -out["zx"]
    out["yz"] = -out["zy"]
    return out


def _lattice_rectangle_influence(
    di: np.ndarray,
    dj: np.ndarray,
    dx_m: float,
    dy_m: float,
    shear_modulus_Pa: float,
    poisson_ratio: float,
    difference_parameter: float,
    only_normal: bool = False,
) -> dict[str, np.ndarray]:
    """:func:`rectangle_influence` on the regular offsets (dj[:, None] dy, di[None, :] dx), consecutive integers.

    The four corner terms of neighbouring offsets share corners, so the primitives are evaluated once on
    the corner lattice ((di - 1/2) dx, (dj - 1/2) dy) and differenced (a quarter of the evaluations).
    ``only_normal``: only the kernel zz (returned alone), from the 1/r primitive.
    """
    cx = (np.arange(di[0], di[-1] + 2) - 0.5) * dx_m
    cy = (np.arange(dj[0], dj[-1] + 2) - 0.5) * dy_m
    if only_normal:
        xg, yg = np.meshgrid(cx, cy)
        v = _x_asinh_y_over_x(xg, yg) + _x_asinh_y_over_x(yg, xg)
        acc = v[1:, 1:] - v[1:, :-1] - v[:-1, 1:] + v[:-1, :-1]
        return {"zz": (1.0 - poisson_ratio) / (math.pi * shear_modulus_Pa) * acc}
    prim = _primitives(*np.meshgrid(cx, cy))
    acc = {k: v[1:, 1:] - v[1:, :-1] - v[:-1, 1:] + v[:-1, :-1] for k, v in prim.items()}
    return _kernels_from_primitives(acc, shear_modulus_Pa, poisson_ratio, difference_parameter)


def strip_influence(
    x_m: np.ndarray, dx_m: float, shear_modulus_Pa: float, poisson_ratio: float
) -> dict[str, np.ndarray]:
    """2-D (plane strain) influence of unit uniform traction on the strip |x'| <= dx/2, -inf < y' < inf.

    Kernel -2 (1 - nu) ln|X|/(pi G) (normal and in-plane tangential), -2 ln|X|/(pi G) (antiplane);
    the integral uses the primitive X ln|X| - X. Defined up to an additive constant. m/Pa.
    """
    x = np.asarray(x_m, float)

    def prim(s: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(s != 0, s * np.log(np.abs(np.where(s != 0, s, 1.0))), 0.0) - s

    integral = prim(x + 0.5 * dx_m) - prim(x - 0.5 * dx_m)
    c = -2.0 / (math.pi * shear_modulus_Pa)
    zero = np.zeros_like(integral)
    return {
        "zz": c * (1.0 - poisson_ratio) * integral,
        "xx": c * (1.0 - poisson_ratio) * integral,
        "yy": c * integral,
        "xy": zero,
        "zx": zero,
        "zy": zero,
        "xz": zero,
        "yz": zero,
    }


def period_rfft2(values: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``scipy.fft.rfft2(values)`` (the last two axes; no padding), by scipy's transform function directly.

    ``out``: a complex (..., ny, nx/2 + 1) array to write the spectrum into (returned), or None (a new one).
    """
    if _DIRECT is None:
        return scipy.fft.rfft2(values)
    return _DIRECT.r2c(np.asarray(values, float), (values.ndim - 2, values.ndim - 1), True, 0, out, 1)


def period_irfft2(spectrum: np.ndarray, nx: int, out: np.ndarray | None = None) -> np.ndarray:
    """``scipy.fft.irfft2(spectrum, s=(ny, nx))`` with ny = spectrum.shape[-2], by scipy's function directly.

    ``out``: a float (..., ny, nx) array to write the result into (returned), or None (a new one).
    """
    if _DIRECT is None:
        return scipy.fft.irfft2(spectrum, s=(spectrum.shape[-2], nx))
    return _DIRECT.c2r(spectrum, (spectrum.ndim - 2, spectrum.ndim - 1), nx, False, 2, out, 1)


SHARED_CACHE_GRIDS = 16
"""Number of grids (by nx, ny, dx, dy and elastic constants) whose coefficients and spectra are kept for reuse."""
SHARED_CACHE_ELEMENTS = 100_000
"""Bound on the summed elements of the kept grids (about 0.7 kB each for all kernels; the newest grid is kept)."""

_SHARED_CACHES: OrderedDict = OrderedDict()


@dataclass(frozen=True, eq=False)
class InfluenceGrid:
    """Influence coefficients of a regular nx x ny grid of rectangular elements, applied by FFT.

    Element (i, j) has its centre at (x0 + i dx, y0 + j dy); arrays are indexed ``[j, i]``
    (y rows, x columns) as in :class:`~rigid_dynamics.contact.types.ContactFields`.

    Two operators per kernel (A_ij of the module docstring):

    * static: ``u[I] = sum_K C(I - K) t[K]`` (displacement difference, m), used by NORM and by the
      shift problem;
    * rolling: ``sum_K (C(I - K) - C(I - K + e_x)) t[K] / dx``, the upwind difference
      ``(u(x_I) - u(x_I + dx))/dx = -du/dx`` of steady rolling with the leading edge at +x
      (Kalker 1990, sec. 5.2: the previous position of a particle is dx ahead).

    The convolution is a zero-padded FFT (period >= 2n - 1 along each axis, so no wrap-around),
    O(N log N) time and O(N) memory; no dense N x N matrix is formed. Coefficients and spectra are computed
    lazily and shared by the grids of equal parameters (the last ``SHARED_CACHE_GRIDS`` distinct ones, within
    ``SHARED_CACHE_ELEMENTS`` elements in all), so that
    the repeated solves on one patch grid (e.g. a load equilibrium) compute them once.

    Attributes:
        nx, ny: number of elements along x and y.
        dx_m, dy_m: element size, m (dy_m is ignored in the 2-D mode).
        shear_modulus_Pa, poisson_ratio, difference_parameter: combined constants G, nu, K.
        plane: 2-D (plane strain) mode with ny = 1 line elements (forces per unit length).
    """

    nx: int
    ny: int
    dx_m: float
    dy_m: float
    shear_modulus_Pa: float
    poisson_ratio: float
    difference_parameter: float = 0.0
    plane: bool = False
    _cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        for name in ("nx", "ny"):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"{name} = {value!r}: expected an integer >= 1")
        for name in ("dx_m", "dy_m", "shear_modulus_Pa"):
            value = getattr(self, name)
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise ValueError(f"poisson_ratio = {self.poisson_ratio!r}: expected a value in (-1, 0.5)")
        if not math.isfinite(self.difference_parameter) or abs(self.difference_parameter) >= 0.5:
            raise ValueError(f"difference_parameter = {self.difference_parameter!r}: expected |K| < 0.5")
        if self.plane and self.ny != 1:
            raise ValueError(f"ny = {self.ny!r}: the 2-D (plane) mode expects ny = 1")
        if self.plane and self.difference_parameter != 0.0:
            raise ValueError(f"difference_parameter = {self.difference_parameter!r}: expected 0 in the 2-D mode")
        key = (
            int(self.nx),
            int(self.ny),
            float(self.dx_m),
            float(self.dy_m),
            float(self.shear_modulus_Pa),
            float(self.poisson_ratio),
            float(self.difference_parameter),
            bool(self.plane),
        )
        shared = _SHARED_CACHES.get(key)
        if shared is not None and not self._cache:
            # the coefficients are functions of the key alone: share them with the earlier grid of the same key
            _SHARED_CACHES.move_to_end(key)
            object.__setattr__(self, "_cache", shared)
            return
        shape = (
            scipy.fft.next_fast_len(2 * int(self.ny) - 1, real=True) if self.ny > 1 else 1,
            scipy.fft.next_fast_len(2 * int(self.nx) - 1, real=True),
        )
        self._cache["shape"] = shape
        self._cache["static"] = {}
        self._cache["rolling"] = {}
        self._cache["fft"] = {}
        _SHARED_CACHES[key] = self._cache
        while len(_SHARED_CACHES) > SHARED_CACHE_GRIDS or (
            len(_SHARED_CACHES) > 1 and sum(k[0] * k[1] for k in _SHARED_CACHES) > SHARED_CACHE_ELEMENTS
        ):
            _SHARED_CACHES.popitem(last=False)

    def _compute_kernels(self, names: tuple[str, ...]) -> None:
        """Fill the static and rolling coefficient caches for ``names`` (lazily: NORM needs only zz)."""
        nx, ny = int(self.nx), int(self.ny)
        di = np.arange(-(nx - 1), nx + 1)  # one extra offset for the rolling difference
        # one extra row (offset ny) too: with it the offsets span a whole 2 ny x 2 nx period (preconditioner)
        dj = np.arange(-(ny - 1), ny + (0 if self.plane else 1))
        if self.plane:
            xx, _ = np.meshgrid(di * self.dx_m, dj * self.dy_m)
            ext = strip_influence(xx, self.dx_m, self.shear_modulus_Pa, self.poisson_ratio)
        else:
            ext = _lattice_rectangle_influence(
                di,
                dj,
                self.dx_m,
                self.dy_m,
                self.shear_modulus_Pa,
                self.poisson_ratio,
                self.difference_parameter,
                only_normal=names == ("zz",),
            )
        self._cache["period"] = dict(ext)  # offsets -(ny - 1)..ny (0 in 2-D) x -(nx - 1)..nx
        for k, v in ext.items():
            v = v[: 2 * ny - 1]
            self._cache["static"][k] = v[:, : 2 * nx - 1]
            self._cache["rolling"][k] = (v[:, : 2 * nx - 1] - v[:, 1:]) / self.dx_m

    # --- kernels -----------------------------------------------------------------------------------
    def kernel(self, name: str, rolling: bool = False) -> np.ndarray:
        """Coefficients on offsets, shape (2 ny - 1, 2 nx - 1), entry [dj + ny - 1, di + nx - 1], m/Pa or 1/Pa."""
        if name not in KERNELS:
            raise ValueError(f"kernel = {name!r}: expected one of {', '.join(KERNELS)}")
        cache = self._cache["rolling" if rolling else "static"]
        if name not in cache:
            self._compute_kernels(("zz",) if name == "zz" else KERNELS)
        return cache[name]

    def self_coefficient(self, name: str, rolling: bool = False) -> float:
        """Coefficient of an element on itself (offset 0)."""
        return float(self.kernel(name, rolling)[self.ny - 1, self.nx - 1])

    def _kernel_fft(self, name: str, rolling: bool) -> np.ndarray:
        key = (name, rolling)
        cache = self._cache["fft"]
        if key not in cache:
            ly, lx = self._cache["shape"]
            pad = np.zeros((ly, lx))
            k = self.kernel(name, rolling)
            jj = np.arange(-(self.ny - 1), self.ny) % ly
            ii = np.arange(-(self.nx - 1), self.nx) % lx
            pad[np.ix_(jj, ii)] = k
            cache[key] = scipy.fft.rfft2(pad)
        return cache[key]

    # --- operators ---------------------------------------------------------------------------------
    def _forward(self, field_values: np.ndarray) -> np.ndarray:
        """rfft2 of (..., ny, nx) fields zero-padded to the period (ly, lx), shape (..., ly, lx/2 + 1).

        Done as two 1-D passes so that the padding rows are not transformed along x (about 30 % less work
        than ``rfft2`` of the padded array; same result to rounding). With scipy's transform functions called
        directly (:data:`_DIRECT`), the padded input and the spectrum live in buffers kept per grid, field
        shape and thread (no dispatch, no new zero-padded arrays: the same transforms of the same numbers, the
        same bits as ``scipy.fft.rfft``/``fft``): the returned spectrum is valid until the next call for that
        shape in the thread.
        """
        ly, lx = self._cache["shape"]
        values = np.asarray(field_values, float)
        if _DIRECT is None:
            spec = scipy.fft.rfft(values, n=lx, axis=-1)
            if ly == 1:
                return spec
            return scipy.fft.fft(spec, n=ly, axis=-2, overwrite_x=True)
        key = ("forward", values.shape, threading.get_ident())  # per thread: a grid's cache may be shared
        buffers = self._cache.get(key)
        if buffers is None:
            real = np.zeros((*values.shape[:-1], lx))
            spec = np.zeros((*values.shape[:-2], ly, lx // 2 + 1), complex) if ly > 1 else None
            buffers = self._cache[key] = (real, spec)
        real, spec = buffers
        last = values.ndim - 1
        real[..., : values.shape[-1]] = values
        if ly == 1:
            return _DIRECT.r2c(real, (last,), True, 0, None, 1)
        ny = values.shape[-2]
        spec[..., ny:, :] = 0.0
        _DIRECT.r2c(real, (last,), True, 0, spec[..., :ny, :], 1)
        return _DIRECT.c2c(spec, (last - 1,), True, 0, spec, 1)

    def _backward(self, spectrum: np.ndarray, reuse: bool = False) -> np.ndarray:
        """Inverse of :meth:`_forward`, cropped to (..., ny, nx); only the ny kept rows are transformed along x.

        ``spectrum`` (complex, C-contiguous, owned by the caller's computation) may be overwritten. ``reuse``: the
        result is written into a buffer kept per grid and shape, valid until the next such call (for a product
        consumed at once, as in the solvers' iterations).
        """
        ly, lx = self._cache["shape"]
        if _DIRECT is None:
            if ly > 1:
                spectrum = scipy.fft.ifft(spectrum, axis=-2)[..., : self.ny, :]
            return scipy.fft.irfft(spectrum, n=lx, axis=-1)[..., : self.nx]
        last = spectrum.ndim - 1
        if ly > 1:
            spectrum = _DIRECT.c2c(spectrum, (last - 1,), False, 2, spectrum, 1)[..., : self.ny, :]
        out = None
        if reuse:
            key = ("backward", spectrum.shape[:-1], threading.get_ident())
            out = self._cache.get(key)
            if out is None:
                out = self._cache[key] = np.empty((*spectrum.shape[:-1], lx))
        return _DIRECT.c2r(spectrum, (last,), lx, False, 2, out, 1)[..., : self.nx]

    def apply(self, name: str, field_values: np.ndarray, rolling: bool = False) -> np.ndarray:
        """Convolution ``sum_K C_name(I - K) t[K]`` of one kernel with a (ny, nx) field."""
        return self._backward(self._kernel_fft(name, rolling) * self._forward(field_values))

    def normal(
        self, pressure_Pa: np.ndarray, traction_x_Pa=None, traction_y_Pa=None, reuse: bool = False
    ) -> np.ndarray:
        """Normal displacement difference u_z (m) from the pressure (and, if K != 0, the tractions).

        ``reuse``: the result lives in a buffer of the grid, valid until the next ``reuse`` product (:meth:`_backward`).
        """
        spec = self._kernel_fft("zz", False) * self._forward(pressure_Pa)
        if self.difference_parameter != 0.0:
            if traction_x_Pa is not None:
                spec = spec + self._kernel_fft("zx", False) * self._forward(traction_x_Pa)
            if traction_y_Pa is not None:
                spec = spec + self._kernel_fft("zy", False) * self._forward(traction_y_Pa)
        return self._backward(spec, reuse)

    def normal_preconditioner(self, residual_m: np.ndarray, reuse: bool = False) -> np.ndarray:
        """Approximate inverse of the normal operator A_zz: pressure (Pa) for a displacement field (m).

        The inverse of the circulant on the period (ny, nx) of the grid itself (no padding: a quarter of the
        convolution's FFT size) whose coefficients are A_zz folded onto that period; its symbol is the
        2 ny x 2 nx circulant's (Vollebregt's FFT preconditioner, J. Comput. Phys. 257 (2014)) at every other
        frequency. Symbols below 1e-6 of the largest (the 2-D log kernel's) are raised to that floor.
        A preconditioner for :func:`~.norm.solve_norm`, not an exact inverse on the bounded grid.
        """
        if "prec" not in self._cache:
            self.kernel("zz")
            symbol = scipy.fft.rfft2(self._folded_period("zz")).real
            floor = 1e-6 * float(np.abs(symbol).max())
            self._cache["prec"] = 1.0 / np.maximum(symbol, floor)
        if not reuse:
            spec = period_rfft2(residual_m)
            spec *= self._cache["prec"]
            return period_irfft2(spec, self.nx)
        key = ("prec_work", threading.get_ident())
        if key not in self._cache:
            self._cache[key] = (np.empty((self.ny, self.nx // 2 + 1), complex), np.empty((self.ny, self.nx)))
        spec, out = self._cache[key]
        spec = period_rfft2(residual_m, spec)
        spec *= self._cache["prec"]
        return period_irfft2(spec, self.nx, out)

    def _folded_period(self, name: str) -> np.ndarray:
        """Kernel ``name`` (static) folded onto the grid's own period (ny, nx): the coefficients of the 2 ny x 2 nx
        period (offsets -(ny - 1)..ny x -(nx - 1)..nx) indexed by offset modulo (ny, nx) and summed.
        """
        ny, nx = int(self.ny), int(self.nx)
        k = self._cache["period"][name]
        folded = np.roll(k, (-(ny - 1) if k.shape[0] > 1 else 0, -(nx - 1)), axis=(0, 1))
        if folded.shape[0] > 1:
            folded = folded[:ny] + folded[ny:]
        return folded[:, :nx] + folded[:, nx:]

    def _forward_pair(self, first: np.ndarray, second: np.ndarray) -> np.ndarray:
        """Spectra of two (ny, nx) fields in one batched FFT call, shape (2, ly, lx/2 + 1)."""
        return self._forward(np.stack((first, second)))

    def _backward_pair(self, first: np.ndarray, second: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Inverse of two spectra in one batched FFT call, each cropped to (ny, nx)."""
        out = self._backward(np.stack((first, second)))
        return out[0], out[1]

    def tangential(
        self, traction_x_Pa: np.ndarray, traction_y_Pa: np.ndarray, rolling: bool = False, pressure_Pa=None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Tangential displacement differences (u_x, u_y) (static, m) or their rolling differences (-du/dx, -)."""
        fx, fy = self._forward_pair(traction_x_Pa, traction_y_Pa)
        kxy = self._kernel_fft("xy", rolling)
        sx = self._kernel_fft("xx", rolling) * fx + kxy * fy
        sy = kxy * fx + self._kernel_fft("yy", rolling) * fy
        if self.difference_parameter != 0.0 and pressure_Pa is not None:
            fz = self._forward(pressure_Pa)
            sx = sx + self._kernel_fft("xz", rolling) * fz
            sy = sy + self._kernel_fft("yz", rolling) * fz
        return self._backward_pair(sx, sy)

    @property
    def padded_shape(self) -> tuple[int, int]:
        """(ly, lx): the zero-padded FFT period along y and x (>= 2 ny - 1, 2 nx - 1)."""
        return self._cache["shape"]

    def tangential_spectra(self, rolling: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """rfft2 spectra (kxx, kxy, kyy) of the tangential kernels on the padded period, complex (ly, lx/2 + 1)."""
        return self._kernel_fft("xx", rolling), self._kernel_fft("xy", rolling), self._kernel_fft("yy", rolling)

    def inverse_static_spectra(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Spectra (ixx, ixy, iyy) of the padded circulant's inverse of the static tangential operator.

        The 2 x 2 symbol [[kxx, kxy], [kxy, kyy]] is inverted per frequency (real parts, floored at
        1e-3 max kxx against the near-zero symbols of the padding); a preconditioner only.
        """
        if "inv" not in self._cache:
            kxx = self._kernel_fft("xx", False).real
            kyy = self._kernel_fft("yy", False).real
            kxy = self._kernel_fft("xy", False).real
            floor = 1e-3 * float(np.abs(kxx).max())
            kxx = np.maximum(kxx, floor)
            kyy = np.maximum(kyy, floor)
            det = kxx * kyy - kxy * kxy
            det = np.where(det > floor * floor, det, floor * floor)
            self._cache["inv"] = tuple(
                np.ascontiguousarray(v, dtype=complex) for v in (kyy / det, -kxy / det, kxx / det)
            )
        return self._cache["inv"]

    def inverse_static_period_spectra(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Spectra (ixx, ixy, iyy), shape (ny, nx/2 + 1), of an approximate inverse of the static tangential operator
        on the grid's own period (no padding: a quarter of the convolution's FFT size).

        As :meth:`normal_preconditioner` for A_zz (Vollebregt's FFT preconditioner, J. Comput. Phys. 257 (2014)):
        the kernels xx, xy, yy folded onto the (ny, nx) period, the 2 x 2 symbol [[kxx, kxy], [kxy, kyy]] (real
        parts) inverted per frequency, kxx, kyy and the determinant floored at 1e-6 of the largest kxx (and its
        square). Apply with rfft2 / irfft2 on (ny, nx) fields; a preconditioner only.
        """
        if "inv_period" not in self._cache:
            self.kernel("xx")
            kxx, kxy, kyy = (scipy.fft.rfft2(self._folded_period(name)).real for name in ("xx", "xy", "yy"))
            floor = 1e-6 * float(np.abs(kxx).max())
            kxx = np.maximum(kxx, floor)
            kyy = np.maximum(kyy, floor)
            det = kxx * kyy - kxy * kxy
            det = np.where(det > floor * floor, det, floor * floor)
            self._cache["inv_period"] = tuple(
                np.ascontiguousarray(v, dtype=complex) for v in (kyy / det, -kxy / det, kxx / det)
            )
        return self._cache["inv_period"]

    def inverse_static(self, ux_m: np.ndarray, uy_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Approximate inverse of the static tangential operator: the padded circulant's inverse, by FFT.

        A preconditioner only (exact for the periodic extension, not for the bounded grid).
        """
        ixx, ixy, iyy = self.inverse_static_spectra()
        fx, fy = self._forward_pair(ux_m, uy_m)
        return self._backward_pair(ixx * fx + ixy * fy, ixy * fx + iyy * fy)

    def dense(self, name: str, rolling: bool = False) -> np.ndarray:
        """Dense N x N matrix of one kernel (N = nx ny, row-major over [j, i]); only for grids up to 64 x 64."""
        if self.nx * self.ny > 64 * 64:
            raise ValueError(f"grid {self.nx} x {self.ny}: a dense influence matrix is only built up to 64 x 64")
        k = self.kernel(name, rolling)
        j, i = np.divmod(np.arange(self.nx * self.ny), self.nx)
        return k[(j[:, None] - j[None, :]) + self.ny - 1, (i[:, None] - i[None, :]) + self.nx - 1]


class SubPatchInfluence:
    """An :class:`InfluenceGrid` whose normal products reduce the interaction between sub-patches.

    CONTACT's IPLAN = 4 (m_solvpn's matrix-vector product of NORM): the normal displacement at an element of
    sub-patch j due to the pressure on sub-patch i != j is scaled by f_ij; u = A p - sum_{i != j} (1 - f_ij)
    M_j A (M_i p) with M_k the mask of sub-patch k, one extra convolution per sub-patch with reduced
    interaction. The tangential products (and everything else) are the grid's own: CONTACT reduces the normal
    problem's interaction only.

    Args:
        grid: the influence grid.
        labels: sub-patch number (1..n) of each element, 0 outside every sub-patch, shape (ny, nx).
        factors: f_ij, shape (n, n), 1 on the diagonal.
    """

    reduced_interaction = True

    def __init__(self, grid: InfluenceGrid, labels: np.ndarray, factors: np.ndarray) -> None:
        self._grid = grid
        self.labels = np.asarray(labels)
        self.factors = np.asarray(factors, float)
        n = len(self.factors)
        if self.labels.shape != (grid.ny, grid.nx) or self.factors.shape != (n, n):
            raise ValueError(
                f"labels shape {self.labels.shape}, factors shape {self.factors.shape}: expected "
                f"{(grid.ny, grid.nx)} and (n, n)"
            )
        self._masks = [self.labels == k + 1 for k in range(n)]

    def __getattr__(self, name: str):
        return getattr(self._grid, name)

    def normal(
        self, pressure_Pa: np.ndarray, traction_x_Pa=None, traction_y_Pa=None, reuse: bool = False
    ) -> np.ndarray:
        """:meth:`InfluenceGrid.normal` with the sub-patches' reduced interaction (a new array; ``reuse`` ignored)."""
        u = np.array(self._grid.normal(pressure_Pa, traction_x_Pa, traction_y_Pa))
        p = np.asarray(pressure_Pa, float)
        for i, mask_i in enumerate(self._masks):
            reduced = [j for j in range(len(self._masks)) if j != i and self.factors[i, j] != 1.0]
            if not reduced:
                continue
            part = np.where(mask_i, p, 0.0)
            if not part.any():
                continue
            u_i = self._grid.normal(part)
            for j in reduced:
                mask_j = self._masks[j]
                u[mask_j] -= (1.0 - self.factors[i, j]) * u_i[mask_j]
        return u
