"""One interface and one registry for the contact models.

Every model solves one patch::

    model.solve(geometry, creepage, material, normal_force_N=None, options=None) -> ContactResult

``normal_force_N=None`` means approach control (``geometry.approach_m`` is imposed); a number
means force control. ``options`` is a mapping of model-specific settings (grid size, ...), declared
by each model class as ``OPTIONS`` (:mod:`rigid_dynamics.contact.options`; :func:`model_options`); an
unknown option or a bad value raises ``OptionError`` (a ``ValueError``) naming it.

Models are registered by name as ``"module:Class"`` strings and imported only when asked
for, so asking for ``hertz`` never imports the BEM, and nothing of FEniCSx is imported unless
``fea`` is used. (``fea`` lives in the top-level ``fea`` package, above rigid_dynamics; the
registry names it but never imports it on its own.)
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from typing import Protocol, runtime_checkable

from rigid_dynamics.contact.types import ContactGeometry, ContactResult, Creepage
from rigid_dynamics.materials import Material


@runtime_checkable
class ContactModel(Protocol):
    """What every contact model provides.

    A model may also declare ``compiled_law``: the name of the law the compiled dynamics loop runs in its place
    (wheelset.layout.LAW_CODES; the registry's hertz, linear, vermeulen-johnson, fastsim and auto do); a model
    without it (bem, fea, user models) gets each patch of the loop through the callback.
    """

    name: str
    description: str

    def solve(
        self,
        geometry: ContactGeometry,
        creepage: Creepage,
        material: Material,
        *,
        normal_force_N: float | None = None,
        options: Mapping | None = None,
    ) -> ContactResult: ...


MODELS: dict[str, tuple[str, str]] = {
    "hertz": ("rigid_dynamics.contact.models:HertzModel", "Hertz normal contact only; creep forces 0"),
    "linear": ("rigid_dynamics.contact.models:LinearModel", "Hertz + Kalker's linear theory (full adhesion)"),
    "vermeulen-johnson": (
        "rigid_dynamics.contact.models:VermeulenJohnsonModel",
        "Hertz + Vermeulen-Johnson saturation (no spin)",
    ),
    "fastsim": ("rigid_dynamics.contact.models:FastsimModel", "Hertz + Kalker's FASTSIM (simplified theory)"),
    "fastrip": ("rigid_dynamics.contact.fastrip:FastripModel", "Hertz + FaStrip (strip theory with spin)"),
    "kpec": ("rigid_dynamics.contact.semi_hertzian:KpecModel", "CONTACT's KPEC semi-Hertzian normal + FASTSIM"),
    "analyn": ("rigid_dynamics.contact.semi_hertzian:AnalynModel", "CONTACT's ANALYN semi-Hertzian normal + FASTSIM"),
    "bem": ("rigid_dynamics.contact.bem.model:BemModel", "boundary elements: CONTACT-style NORM + TANG"),
    "fea": ("fea.model:FeaModel", "finite elements (FEniCSx): normal contact, subsurface stresses"),
    "table": (
        "rigid_dynamics.contact.creep_table:TableModel",
        "Hertz + FASTSIM's creep-force table (normalised creepages x a/b), for fast dynamics",
    ),
    "auto": ("rigid_dynamics.contact.models:AutoModel", "cheapest model meeting the tolerance for the patch"),
}
"""name -> ("module:Class", one-line description)."""


def model_names() -> list[str]:
    """Registered model names, in order of rising cost."""
    return list(MODELS)


def model_class(name: str) -> type:
    """The class registered as ``name`` (imports its module, not its heavy dependencies).

    Raises:
        ValueError: unknown name (the message lists the choices).
    """
    try:
        target, _ = MODELS[name]
    except KeyError:
        raise ValueError(f"contact model = {name!r}: expected one of {', '.join(MODELS)}") from None
    module_name, class_name = target.split(":")
    return getattr(importlib.import_module(module_name), class_name)


def model_options(name: str) -> dict:
    """The declared options of the model ``name``: option name -> :class:`~rigid_dynamics.contact.options.Option`.

    Every model class declares them as its ``OPTIONS`` (see :mod:`rigid_dynamics.contact.options`).
    """
    return dict(model_class(name).OPTIONS)


def get_model(name: str | ContactModel, **kwargs) -> ContactModel:
    """Return an instance of the model registered as ``name`` (or ``name`` itself if it is a model).

    Raises:
        ValueError: unknown name (the message lists the choices).
        ImportError: the model's optional dependencies are missing (the message names them).
    """
    if not isinstance(name, str):
        if isinstance(name, ContactModel):
            return name
        raise ValueError(f"contact model = {name!r}: expected a name or a ContactModel")
    return model_class(name)(**kwargs)
