"""Boundary-element contact (CONTACT-style NORM and TANG) on a regular grid of rectangular elements.

Modules:

* :mod:`.influence` - half-space influence coefficients of uniform tractions on rectangles
  (Love 1929; Cerruti counterparts; Kalker's difference parameter K) and their FFT convolution.
* :mod:`.norm` - the normal problem (pressure >= 0, gap >= 0, complementarity), approach or force control:
  FFT-preconditioned bound-constrained CG in the manner of Vollebregt's NormCG (default), or the
  Polonsky & Keer (1999) CG.
* :mod:`.tang` - the tangential problem: steady rolling and the shift (Cattaneo) problem with
  Coulomb friction (static and kinetic coefficients), by an active-set Newton method with GMRES on FFT
  influence sums.
* :mod:`.model` - :class:`BemModel`, the registered contact model ``"bem"`` (grid by counts or element
  size, Richardson extrapolation of steady rolling, the shift problem, static and kinetic friction).
"""
