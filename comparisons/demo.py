"""The default demo: a dynamics run, then the contact at the instant of peak normal force through every rung.

:func:`peak_patch_case` takes a finished run (``SimulationResult`` of a scene with the 3-D contact search),
finds the output instant and patch of the largest normal force, re-runs the contact search at that state with
the sampled undeformed distance switched on, and returns that patch as a contact case (geometry, creepages of
the run, the run's normal force as the load) that :func:`comparisons.compare.run_compare` can take.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True, eq=False)
class PatchCase:
    """One patch as a force-controlled contact case (the attributes ``compare`` reads of a contact case).

    Attributes:
        geometry: ContactGeometry of the patch (sampled gap when the search gave one).
        creepage: Creepage of the run at that instant.
        material: Material of the scene.
        normal_force_N: the run's normal force on the patch, N (the load of the re-solve).
        time_s, side, slot: where in the run it comes from.
    """

    geometry: object
    creepage: object
    material: object
    normal_force_N: float
    time_s: float
    side: str
    slot: int
    kind: str = "quadric"
    solver_options: dict = field(default_factory=dict)


def peak_patch_case(result, skip_s: float | None = None) -> PatchCase:
    """The patch of the largest normal force of a finished run, as a :class:`PatchCase` (module docstring).

    Args:
        result: the finished run.
        skip_s: the start of the run left out, s (default: min(0.3 s, a quarter of the run)): the transient from
            the static equilibrium. In the polygonal-wheel scene it holds a one-sample spike of 218 kN at
            t = 0.079 s (neighbours 97 and 85 kN) at a flip of the S1002/UIC60 two-point contact, an artefact of
            the step (README, dynamics table), not the peak of the polygon's load.
    """
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.wheelset.simulate import build_provider
    from rigid_dynamics.wheelset.wheelset_model import WheelsetModel

    scene = result.scene
    normal = np.nan_to_num(np.asarray(result.patches["normal_force_N"], float), nan=-np.inf)
    t = np.asarray(result.t, float)
    skip = min(0.3, 0.25 * float(t[-1] - t[0])) if skip_s is None else float(skip_s)
    normal[t < t[0] + skip] = -np.inf
    k, side, slot = np.unravel_index(int(np.argmax(normal)), normal.shape)
    state = np.asarray(result.states[k], float)
    provider = build_provider(scene)
    if hasattr(provider, "options"):
        provider.options["field"] = True  # the search samples the undeformed distance of each patch
    model = WheelsetModel(scene, provider, get_model("fastsim"), {"fields": False})
    contact = model.contact(state, record=True)
    match = np.flatnonzero((contact.side == side) & (contact.slot == slot))
    if not len(match):
        raise ValueError(f"no patch on side {side}, slot {slot} at t = {result.t[k]:.4g} s when re-searched")
    i = int(match[0])
    values = contact.values
    patches = provider.patches(state[0:3], state[3], state[4], state[5])
    geometry = patches.geometries[i] if patches.geometries is not None else None
    if geometry is None:
        geometry = ContactGeometry(
            curvature_long_1_per_m=float(patches.curvature_long_1_per_m[i]),
            curvature_lat_1_per_m=float(patches.curvature_lat_1_per_m[i]),
            approach_m=float(patches.approach_m[i]),
        )
    creepage = Creepage(
        float(values["creepage_long"][i]),
        float(values["creepage_lat"][i]),
        float(values["spin_creepage_1_per_m"][i]),
        scene.speed_m_per_s,
    )
    return PatchCase(
        geometry=geometry,
        creepage=creepage,
        material=scene.material,
        normal_force_N=float(values["normal_force_N"][i]),
        time_s=float(result.t[k]),
        side=("left", "right")[int(side)],
        slot=int(slot),
    )
