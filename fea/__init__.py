"""FEniCSx elastic contact (imported lazily: ``import fea.model`` does not load DOLFINx).

* :mod:`fea.model`: :class:`FeaModel`, the registered ``fea`` contact model.
* :mod:`fea.solver`: elastic block vs rigid indenter (primal-dual active set).
* :mod:`fea.two_body`: two elastic bodies with node-to-surface pairing.
* :mod:`fea.postprocess`, :mod:`fea.output`: pressure field, stresses, VTU grid and PNG.
* :mod:`fea.hertz_reference`: closed-form Hertz solutions for sizing and verification.
* :mod:`fea.friction`: Coulomb friction (Cattaneo-Mindlin shift, steady rolling); :mod:`fea.rolling_series`: the
  steady-rolling creep force with a stated error from a mesh series on the rolling block.
"""
