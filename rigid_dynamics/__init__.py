"""Rigid wheelset on two rails: geometry, kinematics, contact models, equations of motion.

The numeric core of wheelrail. Imports numpy, scipy and numba only; meshing, FEA and
plotting live in other packages and are imported lazily where they are needed.
"""
