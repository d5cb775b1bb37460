"""The Python side of the compiled code's one callback boundary (compiled_rhs._external): :class:`PatchCallback`
solves one patch of the loop with a contact model that is not compiled (bem, fea, user models; BEM for ``auto``)
and answers with a compiled_rhs.CallbackOutcome.
"""

from __future__ import annotations

import numpy as np

from rigid_dynamics.contact.types import ContactGeometry, Creepage
from rigid_dynamics.wheelset.compiled_rhs import CallbackOutcome
from rigid_dynamics.wheelset.layout import PATCH_ELLIPSE, PATCH_SAMPLED
from rigid_dynamics.wheelset.providers import SIDES


class PatchCallback:
    """The Python side of the compiled code's one callback boundary (compiled_rhs._external): a contact model that is
    not compiled (bem, fea, user models; BEM for ``auto``) solves one patch from its geometry and creepages.

    The geometry is the quadric of the compiled candidate (curvatures, approach, contact point and frame, rolling
    radius, contact angle) unless the provider gave a sampled one (``geometries``, candidate index -> ContactGeometry;
    set per right-hand side by WheelsetModel for providers evaluated in Python). ``calls`` and ``seconds`` count the
    solves; ``message`` holds the last failure.
    """

    def __init__(self, model, options, material):
        self.model = model
        self.options = options
        self.material = material
        self.geometries: dict = {}
        self.calls = 0
        self.seconds = 0.0
        self.message = ""

    def solve(self, patch):
        """N, T_x, T_y, M_z, a, b and a status (0 solved, 1 failed: :attr:`message`) of one patch of the loop
        (compiled_rhs.CallbackPatch) by the model.
        """
        import time

        start = time.perf_counter()
        self.calls += 1
        t = patch.t_s
        try:
            geometry = self.geometries.get(patch.candidate)
            if geometry is None:
                frame = np.array([patch.e_x, patch.e_y, patch.normal], float).T
                geometry = ContactGeometry(
                    curvature_long_1_per_m=float(patch.curvature_long_1_per_m),
                    curvature_lat_1_per_m=float(patch.curvature_lat_1_per_m),
                    approach_m=float(patch.approach_m),
                    side=SIDES[int(patch.side)],
                    point_m=np.array(patch.point_m, float),
                    frame=frame,
                    contact_angle_rad=float(patch.contact_angle_rad),
                    rolling_radius_m=float(patch.rolling_radius_m),
                )
            creepage = Creepage(
                float(patch.creepage_long),
                float(patch.creepage_lat),
                float(patch.spin_creepage_1_per_m),
                float(patch.rolling_speed_m_per_s),
            )
            result = self.model.solve(geometry, creepage, self.material, options=self.options)
        except Exception as exc:  # noqa: BLE001 (any failure of a user model is reported as the run's status)
            self.message = f"contact model {getattr(self.model, 'name', self.model)!r} raised at t = {t:.6g} s: {exc}"
            return _FAILED
        finally:
            self.seconds += time.perf_counter() - start
        if not result.success and result.status != "no-contact":
            self.message = f"contact model {result.method!r} failed at t = {t:.6g} s: {result.status}: {result.message}"
            return _FAILED
        sampled = geometry.undeformed is not None
        residual = np.nan
        if sampled:
            from rigid_dynamics.contact.search import ellipticity_error

            residual = ellipticity_error(
                geometry.undeformed, geometry.curvature_long_1_per_m, geometry.curvature_lat_1_per_m,
                geometry.ellipse_angle_rad, geometry.approach_m,
            )  # fmt: skip
        return CallbackOutcome(
            float(result.normal_force_N or 0.0),
            float(result.creep_force_long_N or 0.0),
            float(result.creep_force_lat_N or 0.0),
            float(result.spin_moment_Nm or 0.0),
            _number(result.semi_axis_long_m),
            _number(result.semi_axis_lat_m),
            _number(result.contact_area_m2),
            _number(result.max_pressure_Pa),
            PATCH_SAMPLED if sampled else PATCH_ELLIPSE,
            float(residual),
            0,
        )


_FAILED = CallbackOutcome(0.0, 0.0, 0.0, 0.0, np.nan, np.nan, np.nan, np.nan, PATCH_ELLIPSE, np.nan, 1)
"""The callback's answer for a patch whose contact model failed (its message kept in PatchCallback.message)."""


def _number(value) -> float:
    """A result's optional number as a float (NaN when the model gives none)."""
    return np.nan if value is None else float(value)
