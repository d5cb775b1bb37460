"""Mesh quality checks for gmsh models.

A mesh that fails the checks is an error (:class:`MeshQualityError`), never a silent bad result.
Quality measure: gmsh's ``minSICN`` (minimum signed inverse condition number of the element's
Jacobian, 1 for a regular tetrahedron, <= 0 for an inverted one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


class MeshQualityError(ValueError):
    """A generated mesh failed its quality checks (too distorted, empty or too large)."""


@dataclass(frozen=True)
class QualityLimits:
    """Acceptance limits of a volume mesh.

    Attributes:
        min_quality: smallest acceptable minSICN of any element, in (0, 1].
        max_elements: largest acceptable number of volume elements (> 0).
    """

    min_quality: float = 0.05
    max_elements: int = 2_000_000

    def __post_init__(self) -> None:
        if not (math.isfinite(self.min_quality) and 0.0 < self.min_quality <= 1.0):
            raise ValueError(f"min_quality = {self.min_quality!r}: expected a number in (0, 1]")
        if int(self.max_elements) != self.max_elements or self.max_elements <= 0:
            raise ValueError(f"max_elements = {self.max_elements!r}: expected an integer > 0")


@dataclass(frozen=True)
class MeshQuality:
    """Quality report of a volume mesh.

    Attributes:
        element_count: number of volume elements.
        node_count: number of mesh nodes.
        min_quality: smallest minSICN over the elements.
        mean_quality: mean minSICN.
    """

    element_count: int
    node_count: int
    min_quality: float
    mean_quality: float

    def as_dict(self) -> dict:
        """JSON-serialisable copy."""
        return {
            "element_count": self.element_count,
            "node_count": self.node_count,
            "min_quality": self.min_quality,
            "mean_quality": self.mean_quality,
        }


def mesh_quality(model) -> MeshQuality:
    """Measure the 3-D elements of the current mesh of a gmsh model (``gmsh.model``)."""
    import numpy as np

    element_count = 0
    qualities = []
    for _, tags, _ in zip(*model.mesh.getElements(3), strict=True):
        element_count += len(tags)
        if len(tags):
            qualities.append(np.asarray(model.mesh.getElementQualities(tags, "minSICN")))
    node_tags, _, _ = model.mesh.getNodes()
    if element_count == 0:
        return MeshQuality(0, len(node_tags), math.nan, math.nan)
    q = np.concatenate(qualities)
    return MeshQuality(element_count, len(node_tags), float(q.min()), float(q.mean()))


def check_quality(quality: MeshQuality, limits: QualityLimits) -> MeshQuality:
    """Return ``quality`` if it meets ``limits``.

    Raises:
        MeshQualityError: no elements, an element below ``limits.min_quality`` or more than
            ``limits.max_elements`` elements (the message gives the numbers).
    """
    if quality.element_count == 0:
        raise MeshQualityError("mesh has no volume elements: the geometry or the size field is invalid")
    if not quality.min_quality >= limits.min_quality:
        raise MeshQualityError(
            f"mesh min quality (minSICN) = {quality.min_quality:.3g}: expected >= {limits.min_quality:.3g} "
            f"({quality.element_count} elements); refine the size field or relax the grading"
        )
    if quality.element_count > limits.max_elements:
        raise MeshQualityError(
            f"mesh has {quality.element_count} elements: expected <= {limits.max_elements} "
            "(raise max_elements or coarsen the mesh size factor)"
        )
    return quality
