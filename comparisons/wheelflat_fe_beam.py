"""A second method for the wheel-flat impact on a discretely supported rail: the vertical half-wheelset of
:mod:`comparisons.wheelflat_vertical` on an Euler-Bernoulli rail of finite elements, written apart from the
wheelset code and from its modal beam (rigid_dynamics.wheelset.track, model "beam").

The rail: cubic Hermite beam elements (deflection and slope at each node, consistent mass; the textbook element
matrices, e.g. Przemieniecki, Theory of Matrix Structural Analysis, 1968), ``elements_per_span`` per sleeper
spacing a, simply supported at both ends x = 0 and x = (n_seats + 1) a like the modal beam, a rail seat at every
node x = j a (j = 1 .. n_seats): pad (spring and damper) from the rail node to a sleeper mass on the ballast
(spring and damper). No damping in the rail itself. The wheel: the unsprung mass m_w with the static load P0 and
the primary suspension to the frame, on a Hertz spring N = C_H delta^1.5 whose approach is
delta = z_w - w_rail(x) - e(x), e the wheel-centre drop over the flat (wheelflat_vertical.centre_drop_m) and
w_rail(x) the rail's deflection under the wheel from the element's shape functions, which also spread the contact
force onto the element's nodes (the moving load).

Time integration: Newmark's average-acceleration rule (trapezoidal, second order, unconditionally stable) on the
whole linear system, with the contact force solved at each step from its scalar equation
F = C_H max(delta* - phi F, 0)^1.5 (phi the step's flexibility of wheel and rail at the contact point), one sparse
LU factorisation for the run. So the space discretisation (finite elements against modes), the integrator
(Newmark against RK4) and the contact (a point Hertz spring against the 3-D wheelset contact) all differ from the
wheelset model's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import splu

from comparisons.wheelflat_vertical import VerticalModel, centre_drop_m


@dataclass(frozen=True)
class FeBeamTrack:
    """An Euler-Bernoulli rail on discrete seats (per rail; SI units, the names of track.TrackDynamics)."""

    rail_mass_per_length_kg_per_m: float
    rail_bending_stiffness_N_m2: float
    sleeper_spacing_m: float
    seat_pad_stiffness_N_per_m: float
    seat_pad_damping_N_s_per_m: float
    seat_sleeper_mass_kg: float
    seat_ballast_stiffness_N_per_m: float
    seat_ballast_damping_N_s_per_m: float
    n_seats: int
    elements_per_span: int = 6

    @property
    def length_m(self) -> float:
        return (self.n_seats + 1) * self.sleeper_spacing_m


def _element_matrices(ei: float, rho_a: float, h: float):
    k = (ei / h**3) * np.array(
        [[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
         [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]]
    )  # fmt: skip
    m = (rho_a * h / 420.0) * np.array(
        [[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
         [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]]
    )  # fmt: skip
    return k, m


class FeBeam:
    """The assembled rail and seats: M, C, K (sparse) over the free degrees of freedom, and the shape functions."""

    def __init__(self, track: FeBeamTrack):
        self.track = track
        n_el = (track.n_seats + 1) * track.elements_per_span
        self.h = track.sleeper_spacing_m / track.elements_per_span
        n_nodes = n_el + 1
        n_rail = 2 * n_nodes
        n = n_rail + track.n_seats  # rail (w, slope) per node, then the sleepers
        ke, me = _element_matrices(track.rail_bending_stiffness_N_m2, track.rail_mass_per_length_kg_per_m, self.h)
        rows, cols, kv, mv, cv = [], [], [], [], []
        for e in range(n_el):
            dofs = [2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3]
            for i in range(4):
                for j in range(4):
                    rows.append(dofs[i])
                    cols.append(dofs[j])
                    kv.append(ke[i, j])
                    mv.append(me[i, j])
                    cv.append(0.0)
        for s in range(track.n_seats):
            node = (s + 1) * track.elements_per_span
            w, z = 2 * node, n_rail + s
            for (i, j), sign in (((w, w), 1.0), ((w, z), -1.0), ((z, w), -1.0), ((z, z), 1.0)):
                rows.append(i)
                cols.append(j)
                kv.append(sign * track.seat_pad_stiffness_N_per_m)
                cv.append(sign * track.seat_pad_damping_N_s_per_m)
                mv.append(0.0)
            rows.append(z)
            cols.append(z)
            kv.append(track.seat_ballast_stiffness_N_per_m)
            cv.append(track.seat_ballast_damping_N_s_per_m)
            mv.append(track.seat_sleeper_mass_kg)
        shape = (n, n)
        fixed = {0, 2 * (n_nodes - 1)}  # w = 0 at both ends (simply supported)
        self.free = np.array([d for d in range(n) if d not in fixed])
        index = np.full(n, -1)
        index[self.free] = np.arange(len(self.free))
        self.index = index

        def assemble(values):
            a = coo_matrix((values, (rows, cols)), shape=shape).tocsr()
            return a[self.free][:, self.free].tocsc()

        self.K, self.M, self.C = assemble(kv), assemble(mv), assemble(cv)
        self.n = len(self.free)

    def shape_vector(self, x_m: float) -> np.ndarray:
        """N(x) over the free dofs: the rail's deflection at x is N . u, a unit force at x loads the dofs by N."""
        h = self.h
        e = min(max(int(x_m // h), 0), int(round(self.track.length_m / h)) - 1)
        xi = (x_m - e * h) / h
        values = (1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3, h * (xi**3 - xi**2))
        out = np.zeros(self.n)
        for dof, v in zip((2 * e, 2 * e + 1, 2 * e + 2, 2 * e + 3), values, strict=True):
            if self.index[dof] >= 0:
                out[self.index[dof]] = v
        return out


def simulate_passage_fe(
    wheel: VerticalModel,
    track: FeBeamTrack,
    speed_m_per_s: float,
    start_m: float,
    distance_m: float,
    step_s: float = 1.0e-5,
):
    """Contact force history of the vertical model rolling from x = start_m (along the beam) over distance_m, the
    flat's centre at wheel.flat_centre_m of travel (from the start), on the finite-element rail.

    Returns:
        (t, travel, contact force N).
    """
    beam = FeBeam(track)
    m_w, p0 = wheel.wheel_mass_kg, wheel.static_load_N
    k_s, c_s, c_h = (
        wheel.suspension_stiffness_N_per_m,
        wheel.suspension_damping_N_s_per_m,
        wheel.hertz_constant_N_per_m15,
    )
    h = step_s
    k_eff = (beam.K + (4.0 / h**2) * beam.M + (2.0 / h) * beam.C).tocsc()
    solve = splu(k_eff).solve
    static = splu(beam.K.tocsc()).solve
    n0 = beam.shape_vector(start_m)
    u = static(n0 * p0)
    v = np.zeros(beam.n)
    a = np.zeros(beam.n)
    delta0 = (p0 / c_h) ** (2.0 / 3.0)
    z_rest = float(n0 @ u) + delta0  # the suspension's zero-force position: the wheel at rest
    z, zv, za = z_rest, 0.0, 0.0
    kw_eff = k_s + 4.0 * m_w / h**2 + 2.0 * c_s / h
    n_steps = int(math.ceil(distance_m / speed_m_per_s / h))
    travel = speed_m_per_s * h * np.arange(n_steps + 1)
    drop = centre_drop_m(wheel, travel)
    forces = np.zeros(n_steps + 1)
    forces[0] = p0
    mu, cu = beam.M, beam.C
    for i in range(1, n_steps + 1):
        nx = beam.shape_vector(start_m + travel[i])
        rhs = mu @ ((4.0 / h**2) * u + (4.0 / h) * v + a) + cu @ ((2.0 / h) * u + v)
        u_star = solve(rhs)
        g = solve(nx)
        z_star = (
            p0 + k_s * z_rest + m_w * ((4.0 / h**2) * z + (4.0 / h) * zv + za) + c_s * ((2.0 / h) * z + zv)
        ) / kw_eff
        delta_star = z_star - float(nx @ u_star) - drop[i]
        phi = 1.0 / kw_eff + float(nx @ g)
        force = 0.0
        if delta_star > 0.0:
            force = brentq(lambda f, ds=delta_star, p=phi: f - c_h * max(ds - p * f, 0.0) ** 1.5, 0.0, delta_star / phi)
        u_new = u_star + force * g
        z_new = z_star - force / kw_eff
        a_new = (4.0 / h**2) * (u_new - u) - (4.0 / h) * v - a
        v = v + 0.5 * h * (a + a_new)
        u, a = u_new, a_new
        za_new = (4.0 / h**2) * (z_new - z) - (4.0 / h) * zv - za
        zv = zv + 0.5 * h * (za + za_new)
        z, za = z_new, za_new
        forces[i] = force
    return h * np.arange(n_steps + 1), travel, forces


def fe_track_from_scene(track_dynamics, n_seats: int, elements_per_span: int = 6) -> FeBeamTrack:
    """The FE rail of a scene's beam track (its rail and seat data; Euler-Bernoulli, no rail damping)."""
    t = track_dynamics
    return FeBeamTrack(
        rail_mass_per_length_kg_per_m=t.rail_mass_per_length_kg_per_m,
        rail_bending_stiffness_N_m2=t.rail_bending_stiffness_N_m2,
        sleeper_spacing_m=t.sleeper_spacing_m,
        seat_pad_stiffness_N_per_m=t.seat_pad_stiffness_N_per_m,
        seat_pad_damping_N_s_per_m=t.seat_pad_damping_N_s_per_m,
        seat_sleeper_mass_kg=t.seat_sleeper_mass_kg,
        seat_ballast_stiffness_N_per_m=t.seat_ballast_stiffness_N_per_m,
        seat_ballast_damping_N_s_per_m=t.seat_ballast_damping_N_s_per_m,
        n_seats=n_seats,
        elements_per_span=elements_per_span,
    )
