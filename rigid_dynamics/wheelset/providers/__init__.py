"""Contact-geometry providers: where the patches of a wheelset pose come from.

The equations of motion ask a *provider* for the contact patches of a pose and do not care how they
were found. A provider has a ``name`` and one method::

    provider.patches(centre_m, yaw_rad, roll_rad, spin_rad) -> PatchSet

returning every contact *candidate* of both wheels (also those with a gap, approach < 0, so that
wheel lift can be detected). Providers here:

* :class:`ConicalProvider` — exact analytic contact of a conical wheel on a circular rail head
  (derivation below), with optional running-direction irregularities. Used for Klingel and
  stability verification.
* :class:`TableProvider` — contact-geometry tables over lateral shift and roll, precomputed from any
  section provider for ideal (irregularity-free) geometry; the usual practice of multibody codes.
* :class:`SearchProvider` — the 3-D contact search of rigid_dynamics.contact.search (real profiles,
  irregularities) when it is available.
* :class:`ProfileSectionProvider` — a 2-D profile section of real profiles, the section sampled by the tables.

Files: patches.py (PatchSet, the protocol, SIDES), conical.py, tables.py (both add the running-direction
irregularities by the compiled section of the dynamics, compiled_tables._irregularity), surfaces.py (wheel and rail
surfaces from the scene), profile_section.py, search.py.
"""

from rigid_dynamics.wheelset.providers.conical import ConicalProvider
from rigid_dynamics.wheelset.providers.patches import (
    MIN_LONGITUDINAL_CURVATURE_FRACTION,
    SIDE_SIGNS,
    SIDES,
    ContactProvider,
    PatchSet,
    running_direction_only,
)
from rigid_dynamics.wheelset.providers.profile_section import ProfileSectionProvider
from rigid_dynamics.wheelset.providers.search import SearchProvider
from rigid_dynamics.wheelset.providers.surfaces import (
    ABSENT_GAP_M,
    MIN_LATERAL_CURVATURE_1_PER_M,
    build_surfaces,
    conical_track,
    geometry_irregularities,
)
from rigid_dynamics.wheelset.providers.tables import TableProvider

__all__ = [
    "ABSENT_GAP_M",
    "MIN_LATERAL_CURVATURE_1_PER_M",
    "MIN_LONGITUDINAL_CURVATURE_FRACTION",
    "SIDES",
    "SIDE_SIGNS",
    "ConicalProvider",
    "ContactProvider",
    "PatchSet",
    "ProfileSectionProvider",
    "SearchProvider",
    "TableProvider",
    "build_surfaces",
    "conical_track",
    "geometry_irregularities",
    "running_direction_only",
]
