"""Principal curvatures of parametric surfaces and the relative curvature of two bodies (seed eq 12-33).

A surface x_s(u1, u2) (eq 12) with tangents t_j = dx_s/du_j (eq 13), normal n = t1 x t2 / |t1 x t2|
(eq 14), first fundamental form G_ij = t_i . t_j (eq 15) and second fundamental form
H_ij = n . d2x_s/du_i du_j (eq 16). The principal curvatures C_v are the roots of det(H - C G) = 0,
which are the eigenvalues of H G^-1 (eq 17). Note on eq 20: the principal directions are t = w_j t_j with
w the solution of the generalised problem H w = C G w; the eigenvectors v of H G^-1 (eq 17-19) are
G w, which equal w only when G is a multiple of the identity. This module avoids the issue by expressing
the second fundamental form in an orthonormal tangent basis (e1, e2):

    K = A^-T H A^-1,   A_aj = e_a . t_j,

a symmetric 2x2 *curvature tensor*: the normal curvature along the unit tangent d = c1 e1 + c2 e2 is c^T K c,
positive when the surface bends towards n. Its eigenvalues are the principal curvatures and its eigenvectors
the principal directions (eq 17-21).

Relative curvature (eq 24, 32-33). With both tensors taken with respect to the SAME unit normal n pointing
from the rail into the wheel and in the same tangent basis, the wheel's surface near the contact point is
z_w = 1/2 x^T K_w x and the rail's z_r = 1/2 x^T K_r x (heights along n), so the undeformed distance is

    h(x) = z_w - z_r = x^T D x,   D = (K_w - K_r) / 2     (eq 33),

and the common principal frame (eq 31) is the eigen-frame of D. Eq 25 gives its angle from the wheel's
principal frame when both curvature pairs are taken with respect to the same normal (the minus sign in its
denominator belongs to that choice; with the rail's curvatures taken with respect to its own outward
normal the sign flips). :func:`common_principal_angle` implements eq 25 and tests check that the off-diagonal
term of D vanishes in the frame it gives. Units: curvatures 1/m; D in 1/m (h in m for x in m).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


@dataclass(frozen=True, eq=False)
class SurfaceCurvature:
    """Curvature of a parametric surface at a batch of points (batch shape S).

    Attributes:
        normal: unit normal (..., 3) the curvatures refer to.
        first_form: G (eq 15), S + (2, 2).
        second_form: H (eq 16) with respect to ``normal``, S + (2, 2).
        principal_curvatures_1_per_m: (C_1, C_2), C_1 >= C_2, S + (2,), 1/m, positive when bending towards n.
        principal_directions: unit tangents (t_p1, t_p2) (eq 20), S + (2, 3); (t_p1, t_p2, n) is right-handed
            (eq 21).
    """

    normal: np.ndarray
    first_form: np.ndarray
    second_form: np.ndarray
    principal_curvatures_1_per_m: np.ndarray
    principal_directions: np.ndarray

    @property
    def frame(self) -> np.ndarray:
        """Principal frame C_PS = [t_p1, t_p2, n] as columns (eq 21), S + (3, 3)."""
        return np.stack([self.principal_directions[..., 0, :], self.principal_directions[..., 1, :], self.normal], -1)


def symmetric_eigen(tensor) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closed-form eigen-decomposition of symmetric 2x2 matrices [[p, q], [q, s]] (..., 2, 2).

    Returns:
        (lambda_1, lambda_2, angle): lambda_1 >= lambda_2 and the angle (rad, in (-pi/2, pi/2]) of the
        eigenvector of lambda_1 from the first basis axis: tensor = R(angle) diag(l1, l2) R(angle)^T.
    """
    t = np.asarray(tensor, float)
    p, q, s = t[..., 0, 0], 0.5 * (t[..., 0, 1] + t[..., 1, 0]), t[..., 1, 1]
    mean = 0.5 * (p + s)
    radius = np.hypot(0.5 * (p - s), q)
    angle = 0.5 * np.arctan2(2.0 * q, p - s)
    return mean + radius, mean - radius, angle


def curvature_tensor(d_u, d_v, d_uu, d_uv, d_vv, normal, basis_1, basis_2) -> np.ndarray:
    """Curvature tensor K = A^-T H A^-1 of a parametric surface in an orthonormal tangent basis.

    Args:
        d_u, d_v: first partial derivatives dx_s/du1, dx_s/du2 (eq 13), (..., 3).
        d_uu, d_uv, d_vv: second partial derivatives, (..., 3).
        normal: unit normal the curvature refers to (either orientation), (..., 3).
        basis_1, basis_2: orthonormal tangent basis (e1, e2) at the point, (..., 3).

    Returns:
        K (..., 2, 2), 1/m: K[a, b] = e_a^T (shape operator) e_b; c^T K c is the normal curvature along
        c1 e1 + c2 e2 (positive when the surface bends towards ``normal``).
    """
    h11, h12, h22 = _dot(normal, d_uu), _dot(normal, d_uv), _dot(normal, d_vv)
    a11, a12, a21, a22 = _dot(basis_1, d_u), _dot(basis_1, d_v), _dot(basis_2, d_u), _dot(basis_2, d_v)
    det = a11 * a22 - a12 * a21
    # B = A^-1 = [[a22, -a12], [-a21, a11]] / det ; K = B^T H B
    b11, b12, b21, b22 = a22 / det, -a12 / det, -a21 / det, a11 / det
    k11 = b11 * (h11 * b11 + h12 * b21) + b21 * (h12 * b11 + h22 * b21)
    k12 = b11 * (h11 * b12 + h12 * b22) + b21 * (h12 * b12 + h22 * b22)
    k22 = b12 * (h11 * b12 + h12 * b22) + b22 * (h12 * b12 + h22 * b22)
    return np.stack([np.stack([k11, k12], -1), np.stack([k12, k22], -1)], -2)


def surface_curvature(d_u, d_v, d_uu, d_uv, d_vv, *, normal_towards=None) -> SurfaceCurvature:
    """Principal curvatures and directions from the fundamental forms (eq 12-21), vectorised.

    Args:
        d_u, d_v, d_uu, d_uv, d_vv: partial derivatives of x_s(u1, u2) (eq 12-13), each (..., 3), m.
        normal_towards: optional vector (..., 3); the normal is oriented so that n . normal_towards > 0.
            Default: n = t1 x t2 / |t1 x t2| (eq 14).

    Returns:
        :class:`SurfaceCurvature`.
    """
    d_u, d_v, d_uu, d_uv, d_vv = (np.asarray(a, float) for a in (d_u, d_v, d_uu, d_uv, d_vv))
    n = np.cross(d_u, d_v)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    if normal_towards is not None:
        n = np.where((_dot(n, np.asarray(normal_towards, float)) < 0)[..., None], -n, n)
    e1 = d_u / np.linalg.norm(d_u, axis=-1, keepdims=True)
    e2 = np.cross(n, e1)
    k = curvature_tensor(d_u, d_v, d_uu, d_uv, d_vv, n, e1, e2)
    c1, c2, angle = symmetric_eigen(k)
    ca, sa = np.cos(angle)[..., None], np.sin(angle)[..., None]
    t1 = ca * e1 + sa * e2
    t2 = np.cross(n, t1)
    first = np.stack(
        [np.stack([_dot(d_u, d_u), _dot(d_u, d_v)], -1), np.stack([_dot(d_u, d_v), _dot(d_v, d_v)], -1)], -2
    )
    second = np.stack([np.stack([_dot(n, d_uu), _dot(n, d_uv)], -1), np.stack([_dot(n, d_uv), _dot(n, d_vv)], -1)], -2)
    return SurfaceCurvature(
        normal=n,
        first_form=first,
        second_form=second,
        principal_curvatures_1_per_m=np.stack([c1, c2], -1),
        principal_directions=np.stack([t1, t2], -2),
    )


def relative_curvature(wheel_tensor, rail_tensor) -> np.ndarray:
    """D = (K_w - K_r)/2 (eq 33): both tensors in the same tangent basis, w.r.t. the normal rail -> wheel."""
    return 0.5 * (np.asarray(wheel_tensor, float) - np.asarray(rail_tensor, float))


def principal_relative_curvature(relative) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split D into h = A x'^2 + B y'^2 with x' the principal axis nearest to the basis' first axis.

    Args:
        relative: D (..., 2, 2) in a tangent basis (e1 = rolling direction, e2).

    Returns:
        (A, B, angle): A, B in 1/m (the eigenvalues of D; A belongs to the principal direction within
        +-pi/4 of e1), and angle (rad, in [-pi/4, pi/4]) from e1 to that direction, about the normal.
    """
    l1, l2, angle = symmetric_eigen(relative)
    swap = np.abs(angle) > 0.25 * np.pi
    a = np.where(swap, l2, l1)
    b = np.where(swap, l1, l2)
    angle = np.where(swap, angle - np.sign(angle) * 0.5 * np.pi, angle)
    return a, b, angle


def common_principal_angle(wheel_curvatures, rail_curvatures, angle_between_rad) -> np.ndarray:
    """Eq 25: rotation eps_w from the wheel's principal frame to the common principal frame.

    eps_w = 1/2 atan( sin 2eps / (cos 2eps - (C_w1 - C_w2)/(C_r1 - C_r2)) ), evaluated with atan2 and the
    sign of (C_r1 - C_r2) so that it is defined for equal rail curvatures too.

    Args:
        wheel_curvatures: (C_w1, C_w2) (..., 2) w.r.t. the normal rail -> wheel, 1/m.
        rail_curvatures: (C_r1, C_r2) (..., 2) w.r.t. the SAME normal, 1/m.
        angle_between_rad: eps, angle from the wheel's first principal direction to the rail's, rad.

    Returns:
        eps_w (...), rad; the rail's angle is eps_r = eps_w - eps (eq 26).
    """
    cw, cr = np.asarray(wheel_curvatures, float), np.asarray(rail_curvatures, float)
    eps = np.asarray(angle_between_rad, float)
    dw, dr = cw[..., 0] - cw[..., 1], cr[..., 0] - cr[..., 1]
    # tan(2 eps_w) = dr sin 2eps / (dr cos 2eps - dw), which is eq 25 multiplied through by dr.
    return 0.5 * np.arctan2(-dr * np.sin(2 * eps), -(dr * np.cos(2 * eps) - dw))
