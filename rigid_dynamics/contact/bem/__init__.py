"""Boundary-element contact (CONTACT-style NORM and TANG) on a regular grid of rectangular elements.

Modules:

* :mod:`.influence` - half-space influence coefficients of uniform tractions on rectangles
  (Love 1929; Cerruti counterparts; Kalker's difference parameter K) and their FFT convolution.
* :mod:`.norm` - the normal problem (pressure >= 0, gap >= 0, complementarity), CG active set
  (Polonsky & Keer 1999), approach or force control.
* :mod:`.tang` - the tangential problem: steady rolling and the shift (Cattaneo) problem with
  Coulomb friction, by Gauss-Seidel sweeps with FFT influence sums.
* :mod:`.model` - :class:`BemModel`, the registered contact model ``"bem"``.
"""
