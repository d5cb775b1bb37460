"""The contact candidates of a pose (:class:`PatchSet`), the provider protocol, the side names."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from rigid_dynamics.wheelset.parameters import Irregularities

SIDES = ("left", "right")
SIDE_SIGNS = np.array([-1.0, 1.0])
MIN_LONGITUDINAL_CURVATURE_FRACTION = 0.1
"""Floor of the longitudinal relative curvature A, as a fraction of 1/(2 r0) (concave flat regions)."""


@dataclass(eq=False)
class PatchSet:
    """Contact candidates of both wheels of one pose; arrays of length n (one entry per candidate).

    Attributes:
        side: 0 = left, 1 = right.
        slot: candidate number on its side (0 tread, 1 flange or second patch).
        point_m: contact point on the wheel, main frame, (n, 3), m.
        normal: unit normal from the rail into the wheel, main frame, (n, 3).
        curvature_long_1_per_m, curvature_lat_1_per_m: A, B of h = A x^2 + B y^2 - q, (n,), 1/m.
        approach_m: q, (n,), m (> 0 in contact, < 0 a gap).
        rolling_radius_m: wheel radius at the contact, (n,), m.
        contact_angle_rad: angle of the normal to the vertical, positive towards the track centre, (n,).
        wheel_lateral_m: y_d of the contact point on the wheel (wheelset frame), (n,), m.
        geometries: optional ContactGeometry per candidate (a search gives sampled gap fields).
        merge_approach_m: optional, per candidate: overlap of the rise of the gap between this candidate and
            the deepest one of its side (-inf for the deepest); > 0 means both lie in one connected contact
            region and this candidate is not a separate patch (profile_section.ProfileSectionProvider).
    """

    side: np.ndarray
    slot: np.ndarray
    point_m: np.ndarray
    normal: np.ndarray
    curvature_long_1_per_m: np.ndarray
    curvature_lat_1_per_m: np.ndarray
    approach_m: np.ndarray
    rolling_radius_m: np.ndarray
    contact_angle_rad: np.ndarray
    wheel_lateral_m: np.ndarray
    geometries: list | None = None
    merge_approach_m: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.side)


def running_direction_only(irregularities: Irregularities | None, provider: str) -> Irregularities | None:
    """The irregularities an analytic provider evaluates (irregular.py), None if there are none.

    Raises:
        ValueError: harmonics or measured grids, which only the 3-D search evaluates.
    """
    if irregularities is None or not irregularities.any:
        return None
    if irregularities.needs_search:
        raise ValueError(
            f"contact_provider = {provider!r} with irregularities harmonics / wheel_grid_file / corrugation_file: "
            "expected contact_provider 'search' or 'auto' (only the 3-D search evaluates them)"
        )
    return irregularities


@runtime_checkable
class ContactProvider(Protocol):
    """What the equations of motion need from a contact-geometry source."""

    name: str

    def patches(self, centre_m: np.ndarray, yaw_rad: float, roll_rad: float, spin_rad: float) -> PatchSet: ...
