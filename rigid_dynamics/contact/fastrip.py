"""FaStrip: strip theory with spin for the tangential problem on an elliptic patch (beside FASTSIM).

M. Sh. Sichani, R. Enblom, M. Berg, "An alternative to FASTSIM for tangential solution of the wheel-rail
contact", Vehicle System Dynamics 54 (2016) 748-764 (the "FaStrip" method); strip theory: J.J. Kalker,
"A strip theory for rolling with slip and spin", Proc. KNAW B70 (1967) 10-62. The formulas below are those
of the paper as the open-source CONTACT program documents them (eve70a/CONTACT); the code is written from the
formulas. With the slip-zone directions below it is CONTACT's modified FaStrip (``M = 5``, K0_MF = ALFAMF = BETAMF
= 1), not its original (``M = 6``): against CONTACT's M = 5 run on 91 strips, F_y within 0.05 % on the named case
creep-lat-spin and 0.9 % on the large-spin case (tests/data/contact_fastrip, tests/test_fastrip.py).

Hertz ellipse with semi-axes a (rolling direction x, leading edge at +x) and b, maximum pressure
p0 = 3 F_N/(2 pi a b), friction mu, combined G, nu, Kalker's C11, C22, C23 for a/b. Non-dimensional
creepages of strip theory (chosen so that small creepages reproduce Kalker's linear theory exactly)::

    xi' = -4 G (1 - nu) C11 xi/(2 pi^2 mu p0),   eta' = -4 G (1 - nu) C22 eta/(2 pi^2 mu p0),
    phi' = -3 G sqrt(ab) C23 phi/(2 pi mu p0)

Each strip at y has half-length a_y = a sqrt(1 - y^2/b^2); its slip zone is -a_y <= x < -a_y + 2 d_y with::

    d_y = [sqrt(eta'^2 + (1 - phi'^2) k^2) + eta' phi'] / (1 - phi'^2) * a/(1 - nu),   k = xi' - phi' y/a

evaluated as (eta'^2 + k^2)/(sqrt(eta'^2 + (1 - phi'^2) k^2) - eta' phi') * a/(1 - nu), the same positive root of
the strip theory's quadratic but regular at phi'^2 = 1 (the large-spin case has phi' = -1.002); full slip where
that root does not exist or d_y >= a_y. With k = xi' - phi' y/a, l = eta' + phi' d_y/a,
kappa = k/|(k, l)|, lambda = l/|(k, l)|, lambda' = lambda - phi', the adhesion-zone traction is::

    t_x = mu p0/a kappa [sqrt(a_y^2 - x^2) - sqrt((a_y - d_y)^2 - (x - d_y)^2)]
    t_y = mu p0/a [lambda sqrt(a_y^2 - x^2) - lambda' sqrt((a_y - d_y)^2 - (x - d_y)^2)]

(Carter's two-dimensional solution per strip when phi = 0). In the slip zone the traction is mu p (Hertz
pressure) in the direction of the traction of a FASTSIM pass over the same strip (three flexibilities L1, L2, L3
blended towards one as the creepage grows, as :mod:`.fastsim`'s default: with Kalker's unblended three the
full-slip traction would not oppose the rigid slip); here that pass uses the elliptic traction bound mu p, where
the original uses Kalker's flexibilities and a parabolic bound with a heuristic normal-force factor.
The square roots are integrated in closed form over each element of Kalker's strip layout (ny strips at the
midpoints y_j, nx elements per strip of length 2 a_y/nx), split at the adhesion/slip boundary, so the forces are
exact along x (only the strips and the slip directions are discretised). Forces on the wheel, contact frame,
opposing the creepage (F_x = -G ab C11 xi at small creepage).

Rolling direction: ``rolling_direction_rad`` 0 (leading edge at +x, the module convention) or pi (rolling
towards -x): the problem is mirrored in x (xi -> -xi, phi -> -phi, F_x -> -F_x, M_z -> -M_z).

Symbols: a, b semi-axes (m), p0 (Pa), xi, eta (-), phi (1/m), mu (-), G (Pa), t tractions (Pa).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rigid_dynamics.contact.fastsim import effective_flexibilities
from rigid_dynamics.contact.kalker import kalker_coefficients
from rigid_dynamics.contact.models import HertzianModel, grid_warning
from rigid_dynamics.contact.options import Option, declare


class StripTheory(NamedTuple):
    """The strip theory's data of one patch (module docstring): the semi-axis a along rolling (m; KPEC's patch: its
    equivalent ellipse's), p0 = 3 F_N/(2 pi a b) (Pa), Poisson's ratio nu and the non-dimensional creepages xi',
    eta', phi' (:func:`strip_creepages`).
    """

    semi_axis_long_m: float
    max_pressure_Pa: float
    poisson_ratio: float
    xi_s: float
    eta_s: float
    phi_s: float


@njit(cache=True, inline="always")
def _circle_integral(radius, centre, x1, x2):
    """Integral of sqrt(max(0, radius^2 - (x - centre)^2)) over [x1, x2] (closed form)."""
    if radius <= 0.0:
        return 0.0
    lo = max(x1, centre - radius) - centre
    hi = min(x2, centre + radius) - centre
    if hi <= lo:
        return 0.0
    r2 = radius * radius

    def prim(u):
        v = min(1.0, max(-1.0, u / radius))
        return 0.5 * (u * math.sqrt(max(0.0, r2 - u * u)) + r2 * math.asin(v))

    return prim(hi) - prim(lo)


@njit(cache=True)
def _fastrip_strips(strip, b, creep, flexibilities, traction):
    """FaStrip on Kalker's strip layout (module docstring); returns (Fx, Fy, Mz, slip fraction).

    ``strip``: the :class:`StripTheory` (a, p0, nu and the non-dimensional creepages xi_s, eta_s, phi_s); ``b``:
    the lateral semi-axis, m; ``creep`` = (mu, xi, eta, phi): friction and the creepages (FASTSIM pass with
    ``flexibilities`` = (l1, l2, l3) in m/Pa; the tuples of kpec.fastsim_strips). The tractions are integrated
    exactly over each element (closed form of the square roots, split at the adhesion/slip boundary), so the
    element values are element means. Fills ``traction`` = (px_out, py_out (Pa), slip_out (element mostly in the
    slip zone)) of shape (ny, nx), element k of strip j at x = a_y - (k + 1/2) 2 a_y/nx.
    """
    a, p0, nu, xi_s, eta_s, phi_s = strip
    mu, xi, eta, phi = creep
    l1, l2, l3 = flexibilities
    px_out, py_out, slip_out = traction
    ny, nx = px_out.shape
    fx = 0.0
    fy = 0.0
    mz = 0.0
    slip_length = 0.0
    dy = 2.0 * b / ny
    one_m = 1.0 - phi_s * phi_s
    scale = mu * p0 / a
    for j in range(ny):
        y = -b + (j + 0.5) * dy
        ay = a * math.sqrt(max(0.0, 1.0 - (y / b) ** 2))
        if ay <= 0.0:
            continue
        dx = 2.0 * ay / nx
        k_s = xi_s - phi_s * y / a
        # half-length of the slip zone: the positive root of (1 - phi'^2) D^2 - 2 eta' phi' D - (eta'^2 + k^2) = 0,
        # D = d (1 - nu)/a, written in the form regular at phi'^2 = 1; none: full slip
        radicand = eta_s * eta_s + one_m * k_s * k_s
        d = 2.0 * ay
        if radicand >= 0.0:
            denom = math.sqrt(radicand) - eta_s * phi_s
            if denom > 0.0:
                d = min(2.0 * ay, (eta_s * eta_s + k_s * k_s) / denom * a / (1.0 - nu))
        x_b = -ay + 2.0 * d  # adhesion for x > x_b
        l_s = eta_s + phi_s * d / a
        norm = math.sqrt(max(k_s * k_s + l_s * l_s, 1e-40))
        kappa = k_s / norm
        lam = l_s / norm
        lam_p = lam - phi_s
        # FASTSIM pass from the leading edge for the slip-zone directions
        ux = 0.0
        uy = 0.0
        x_prev = ay
        wx = xi / l1 - phi / l3 * y
        for k in range(nx):
            x = ay - (k + 0.5) * dx
            step = x_prev - x
            xm = 0.5 * (x + x_prev)
            tx = ux - wx * step
            ty = uy - (eta / l2 + phi / l3 * xm) * step
            rho = max(0.0, 1.0 - (x / a) ** 2 - (y / b) ** 2)
            g = mu * p0 * math.sqrt(rho)
            tn = math.sqrt(tx * tx + ty * ty)
            if tn > g:
                tx *= g / tn
                ty *= g / tn
            ux = tx
            uy = ty
            x_prev = x
            xl = x - 0.5 * dx
            xr = x + 0.5 * dx
            qx = 0.0
            qy = 0.0
            if xr > x_b:  # adhesion part of the element
                lo = max(xl, x_b)
                c_int = _circle_integral(ay, 0.0, lo, xr)
                a_int = _circle_integral(ay - d, d, lo, xr)
                qx += scale * kappa * (c_int - a_int)
                qy += scale * (lam * c_int - lam_p * a_int)
            if xl < x_b:  # slip part: mu p in the FASTSIM direction
                hi = min(xr, x_b)
                g_int = scale * _circle_integral(ay, 0.0, xl, hi)
                tn = math.sqrt(tx * tx + ty * ty)
                if tn > 0.0:
                    qx += g_int * tx / tn
                    qy += g_int * ty / tn
                else:
                    qx += g_int * kappa
                    qy += g_int * lam
                slip_length += hi - xl
            px_out[j, k] = qx / dx
            py_out[j, k] = qy / dx
            slip_out[j, k] = x < x_b
            fx += qx * dy
            fy += qy * dy
            mz += (x * qy - y * qx) * dy
    area_strips = 0.0
    for j in range(ny):
        y = -b + (j + 0.5) * dy
        area_strips += 2.0 * a * math.sqrt(max(0.0, 1.0 - (y / b) ** 2))
    return fx, fy, mz, slip_length / max(area_strips, 1e-300)


def strip_creepages(a, b, normal_force_N, xi, eta, phi, *, shear_modulus_Pa, poisson_ratio, friction_coefficient):
    """(xi', eta', phi', p0, C11, C22, C23) of the module docstring for one elliptic patch."""
    coef = kalker_coefficients(a / b, poisson_ratio)
    c11, c22, c23 = float(coef.c11), float(coef.c22), float(coef.c23)
    p0 = 3.0 * normal_force_N / (2.0 * math.pi * a * b)
    g, nu, mu_p0 = shear_modulus_Pa, poisson_ratio, friction_coefficient * p0
    xi_s = -4.0 * g * (1.0 - nu) * c11 * xi / (2.0 * math.pi**2 * mu_p0)
    eta_s = -4.0 * g * (1.0 - nu) * c22 * eta / (2.0 * math.pi**2 * mu_p0)
    phi_s = -3.0 * g * math.sqrt(a * b) * c23 * phi / (2.0 * math.pi * mu_p0)
    return xi_s, eta_s, phi_s, p0, c11, c22, c23


def fastrip(
    semi_axis_long_m: float,
    semi_axis_lat_m: float,
    normal_force_N: float,
    longitudinal: float,
    lateral: float,
    spin_1_per_m: float,
    *,
    shear_modulus_Pa: float,
    poisson_ratio: float,
    friction_coefficient: float,
    nx: int = 40,
    ny: int = 40,
    rolling_direction_rad: float = 0.0,
) -> tuple[tuple[float, float, float, float], np.ndarray, np.ndarray, np.ndarray]:
    """FaStrip for one Hertzian patch (module docstring).

    Args:
        semi_axis_long_m, semi_axis_lat_m: a (along x), b, m (> 0).
        normal_force_N: F_N > 0, N.
        longitudinal, lateral, spin_1_per_m: xi, eta (-), phi (1/m).
        shear_modulus_Pa, poisson_ratio, friction_coefficient: G, nu, mu (mu > 0).
        nx, ny: elements per strip, strips.
        rolling_direction_rad: 0 or pi (module docstring).

    Returns:
        ((F_x, F_y, M_z, slip fraction), t_x, t_y, in_slip): forces on the wheel (N, N m) and the strip-layout
        fields (ny, nx) of the rolling frame (element k of strip j at x = a_y - (k + 1/2) 2 a_y/nx, mirrored for
        rolling towards -x).
    """
    a, b, fn = float(semi_axis_long_m), float(semi_axis_lat_m), float(normal_force_N)
    for name, value in (("semi_axis_long_m", a), ("semi_axis_lat_m", b), ("normal_force_N", fn)):
        if not math.isfinite(value) or value <= 0:
            raise ValueError(f"{name} = {value!r}: expected a finite number > 0")
    if not math.isfinite(friction_coefficient) or friction_coefficient <= 0:
        raise ValueError(f"friction_coefficient = {friction_coefficient!r}: expected a finite number > 0")
    for name, value in (("nx", nx), ("ny", ny)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise ValueError(f"{name} = {value!r}: expected an integer >= 1")
    sign = _rolling_sign(rolling_direction_rad)
    xi, eta, phi = sign * float(longitudinal), float(lateral), sign * float(spin_1_per_m)
    xi_s, eta_s, phi_s, p0, c11, c22, c23 = strip_creepages(
        a,
        b,
        fn,
        xi,
        eta,
        phi,
        shear_modulus_Pa=shear_modulus_Pa,
        poisson_ratio=poisson_ratio,
        friction_coefficient=friction_coefficient,
    )
    coef = kalker_coefficients(a / b, poisson_ratio)
    l1, l2, l3 = effective_flexibilities(
        a,
        b,
        fn,
        xi,
        eta,
        phi,
        shear_modulus_Pa=shear_modulus_Pa,
        friction_coefficient=friction_coefficient,
        coefficients=coef,
        flexibility="three",
    )
    px = np.zeros((ny, nx))
    py = np.zeros((ny, nx))
    slip = np.zeros((ny, nx), dtype=np.bool_)
    strip = StripTheory(a, float(p0), float(poisson_ratio), float(xi_s), float(eta_s), float(phi_s))
    fx, fy, mz, frac = _fastrip_strips(
        strip, b, (float(friction_coefficient), xi, eta, phi), (float(l1), float(l2), float(l3)), (px, py, slip)
    )
    return (sign * fx, fy, sign * mz, frac), sign * px, py, slip


def _rolling_sign(rolling_direction_rad: float) -> float:
    """+1 for rolling towards +x (angle 0), -1 towards -x (angle pi); ValueError otherwise."""
    value = float(rolling_direction_rad)
    if not math.isfinite(value):
        raise ValueError(f"rolling_direction_rad = {rolling_direction_rad!r}: expected 0 or pi")
    c = math.cos(value)
    if abs(math.sin(value)) > 1e-9:
        raise ValueError(
            f"rolling_direction_rad = {rolling_direction_rad!r}: expected 0 or pi (FaStrip's strips run along the "
            "rolling direction, which must be a semi-axis of the ellipse)"
        )
    return 1.0 if c > 0 else -1.0


class FastripModel(HertzianModel):
    """Hertz + FaStrip (module docstring): the registered model ``fastrip``.

    Options (``OPTIONS``): ``nx`` (elements per strip, int >= 1), ``ny`` (strips, int >= 1),
    ``rolling_direction_rad`` (0 or pi: the direction of rolling in the contact frame), ``tolerance`` (accepted
    relative creep-force error of the grid). No surface fields are returned (the strip layout has a different x
    grid per strip); ``extra["slip_fraction"]`` is the slip zones' share of the strips' length.

    Discretisation error (``extra["discretisation_error_estimate"]``, relative to |F|, creep-force vectors): every
    solve is repeated on nx/2 x ny/2 and nx/4 x ny/4 (together 31 % of the cost), and the estimate is
    2 max(|F(n) - F(n/2)|, |F(n/2) - F(n/4)|/2): the strips converge at first order but not monotonically (on
    creep-lat-spin the half-grid difference alone was 3.5 times below the true error at 30 x 30). Measured against
    640 x 640 on the named quadric creep cases and four more (a/b 0.2 to 5, pure spin, combined creepages; grids
    8 to 100, tests/test_fastrip.py): true error / estimate at most 0.77; at the default 40 x 40 the true errors are
    0.03-0.7 %. A result whose estimate exceeds ``tolerance`` has status ``warning``.
    """

    name = "fastrip"
    description = "Hertz + FaStrip (strip theory with spin; Sichani et al. 2016)"
    SATURATING = True
    OPTIONS = declare(
        Option("nx", int, 40, "elements per strip (along x)", minimum=1, maximum=4096),
        Option("ny", int, 40, "strips (along y)", minimum=1, maximum=4096),
        Option("rolling_direction_rad", float, 0.0, "direction of rolling in the contact frame: 0 or pi, rad"),
        Option("tolerance", float, 0.05, "accepted relative creep-force error of the strips (estimated on the "
               "grids of half and a quarter of the elements)", minimum=0, exclusive_minimum=True),
    )  # fmt: skip

    def solve(self, geometry, creepage, material, *, normal_force_N=None, options=None):
        result = super().solve(geometry, creepage, material, normal_force_N=normal_force_N, options=options)
        return grid_warning(result, "FaStrip's strips", "against the grids of half and a quarter of the elements")

    def tangential(self, hertz, creepage, material, opts):
        """FaStrip on one Hertz ellipse; forces on the wheel in the contact frame (models.HertzianModel)."""
        _rolling_sign(opts["rolling_direction_rad"])

        def solve(divisor):
            return fastrip(
                float(hertz.semi_axis_long_m),
                float(hertz.semi_axis_lat_m),
                float(hertz.normal_force_N),
                creepage.longitudinal,
                creepage.lateral,
                creepage.spin_1_per_m,
                shear_modulus_Pa=material.shear_modulus_Pa,
                poisson_ratio=material.poisson_ratio,
                friction_coefficient=material.friction_coefficient,
                nx=max(1, opts["nx"] // divisor),
                ny=max(1, opts["ny"] // divisor),
                rolling_direction_rad=opts["rolling_direction_rad"],
            )[0]

        (fx, fy, mz, slip_fraction), half, quarter = solve(1), solve(2), solve(4)
        size = math.hypot(fx, fy)
        change = math.hypot(fx - half[0], fy - half[1])
        change_coarse = math.hypot(half[0] - quarter[0], half[1] - quarter[1])
        estimate = 2.0 * max(change, 0.5 * change_coarse) / size if size > 0 else 0.0
        forces = {"creep_force_long_N": fx, "creep_force_lat_N": fy, "spin_moment_Nm": mz}
        extra = {
            "discretisation_error_estimate": estimate if math.isfinite(estimate) else None,
            "tolerance": opts["tolerance"],
            "slip_fraction": slip_fraction,
            "nx": int(opts["nx"]),
            "ny": int(opts["ny"]),
            "rolling_direction_rad": float(opts["rolling_direction_rad"]),
        }
        return forces, extra
