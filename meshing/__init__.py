"""gmsh models for the finite-element contact rung (gmsh is imported inside the functions).

* :mod:`meshing.hertz`: canonical Hertz bodies (block under a rigid quadric, block pair for two bodies).
* :mod:`meshing.profile_sections`: local rail and wheel sections from real profiles.
* :mod:`meshing.quality`: quality report and checks (:class:`MeshQualityError`).
* :mod:`meshing.session`: scoped gmsh model (no global state left behind).
"""
