"""Named benchmark cases: ``comparisons/cases/<name>/`` (one source of truth for bench, compare and tests).

Each folder holds

* ``case.toml``: a contact-case file (the format of ``wheelrail contact``; :mod:`wheelrail.cases`);
* ``reference.toml``: ``source`` (``closed-form``, ``contact-published``, ``contact-converged`` or
  ``bem-richardson``), ``side`` (the patch side compared: ``"single"`` for a quadric, ``"right"`` for a wheelset
  case), ``note``, and a table
  ``[reference]`` of numbers on the wheel in the contact frame (SI: ``normal_force_N``,
  ``creep_force_long_N``, ``creep_force_lat_N``, ``max_pressure_Pa``, ``contact_area_m2``; a closed-form
  Hertz case also ``semi_axis_long_m``, ``semi_axis_lat_m``), and ``[uncertainty]`` (the reference's own
  relative error estimate per quantity, where known);
* ``contact_reference.csv`` (``contact-published`` and ``contact-converged`` cases): the row(s) of CONTACT's
  published solution, copied unchanged; for ``contact-published`` the numbers of ``[reference]`` are derived
  from it here (:func:`contact_row_reference`);
* ``contact_grid.csv`` (``contact-converged`` cases): CONTACT's solution of the same deck run here at element
  sizes DX = DS halved down from the deck's 0.2 mm (benchmarks/contact_grid_study.py); the reference is the
  finest row and its own error estimate per quantity the change over the last halving
  (:func:`contact_grid_reference`): CONTACT's max pressure and area (NCON dx ds) depend on the element size, so
  the published 0.2 mm numbers are no grid-converged reference (on the flange, 3-4 elements across the patch);
* ``reference_field.npz`` (``bem-richardson`` cases): the pressure field of the finest BEM run
  (``x_m``, ``y_m``, ``pressure_Pa``), for the field norm;
* ``SOURCE.md``: where the numbers come from.

The files are read by :func:`wheelrail.named_cases.load_named_case` (TOML is read only in wheelrail).
For a wheelset case the compared quantities are those of the wheel's patches together: N, Fx, Fy summed over
the patches of ``side`` (each in its own contact frame; CONTACT combines close patches into one), the largest
max pressure and the summed area.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

CASES_ROOT = Path(__file__).parent / "cases"
QUANTITIES = ("normal_force_N", "creep_force_long_N", "creep_force_lat_N", "max_pressure_Pa", "contact_area_m2")
SOURCES = ("closed-form", "contact-published", "contact-converged", "bem-richardson")
CONTACT_PRINT_RESOLUTION = 5e-4
"""CONTACT prints FN, FX, FS and PMAX with 4 significant digits: half a unit of the last one, relative (at most)."""


@dataclass(frozen=True, eq=False)
class NamedCase:
    """One named case: its folder, the validated contact case and its reference numbers.

    Attributes:
        name: folder name.
        folder: the case folder.
        source: where the reference comes from (one of :data:`SOURCES`).
        side: patch side compared ("single" or "right"/"left").
        reference: quantity -> value (SI; forces on the wheel, contact frame); quantities without a reference
            are absent.
        uncertainty: quantity -> relative error estimate of the reference itself (absent: not known).
        note: one line on the case.
        tags: labels used by the research claims ("hertz", "creep", "spin", "flange", "irregular", ...).
        case: the validated contact case of ``case.toml`` (``wheelrail.cases.ContactCase``; read by
            ``wheelrail.named_cases``, since TOML is read only in wheelrail).
        case_file: the case's TOML file where it is not ``folder/case.toml`` (the cases of ``wheelrail/cases``).
    """

    name: str
    folder: Path
    source: str
    side: str
    reference: dict
    uncertainty: dict = field(default_factory=dict)
    note: str = ""
    tags: tuple = ()
    case: object = None
    case_file: Path | None = None

    @property
    def case_path(self) -> Path:
        """The case file: ``case_file`` when given (a case without a reference folder), else ``folder/case.toml``."""
        return self.case_file if self.case_file is not None else self.folder / "case.toml"

    def reference_grid(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Points (x_m, y_m) on which the reference pressure field is compared, or None (no reference field).

        Closed-form Hertz cases: 121 x 121 points over 1.15 times the ellipse's bounding box; BEM references: the
        stored field's grid.
        """
        ref = self.reference
        if self.source == "closed-form" and "semi_axis_long_m" in ref:
            return (
                np.linspace(-1.15, 1.15, 121) * ref["semi_axis_long_m"],
                np.linspace(-1.15, 1.15, 121) * ref["semi_axis_lat_m"],
            )
        path = self.folder / "reference_field.npz"
        if not path.exists():
            return None
        with np.load(path) as data:
            return np.array(data["x_m"]), np.array(data["y_m"])

    def reference_pressure(self, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray | None:
        """Reference pressure at points (x, y) of the contact plane (Pa), or None when there is none.

        Closed-form Hertz cases: p0 sqrt(1 - x^2/a^2 - y^2/b^2) (0 outside). BEM references: the stored field of
        the finest run, bilinear, 0 outside its grid. Published CONTACT cases: None (no field published).
        """
        ref = self.reference
        if self.source == "closed-form" and "semi_axis_long_m" in ref:
            r2 = (np.asarray(x_m) / ref["semi_axis_long_m"]) ** 2 + (np.asarray(y_m) / ref["semi_axis_lat_m"]) ** 2
            return ref["max_pressure_Pa"] * np.sqrt(np.clip(1.0 - r2, 0.0, None))
        path = self.folder / "reference_field.npz"
        if not path.exists():
            return None
        with np.load(path) as data:
            x, y, p = data["x_m"], data["y_m"], data["pressure_Pa"].astype(float)
        return grid_interpolate(x, y, p, x_m, y_m)


def grid_interpolate(x: np.ndarray, y: np.ndarray, values: np.ndarray, x_m, y_m) -> np.ndarray:
    """Bilinear interpolation of ``values[j, i]`` given at (x[i], y[j]) to points (x_m, y_m); 0 outside the grid."""
    from scipy.interpolate import RegularGridInterpolator

    interp = RegularGridInterpolator((np.asarray(y), np.asarray(x)), values, bounds_error=False, fill_value=0.0)
    xx, yy = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float))
    return interp(np.stack([yy.ravel(), xx.ravel()], axis=-1)).reshape(xx.shape)


def contact_row_reference(row: dict) -> dict:
    """CONTACT's printed patch numbers (forces on the rail, mm, N/mm^2) -> our reference (on the wheel, SI).

    Mapping from the data's SOURCE.md: F_N = fn; Fx_wheel = -fx; Fy_wheel = +fs (the patch's lateral axis);
    max pressure pmax N/mm^2 -> Pa; area mm^2 -> m^2.
    """
    return {
        "normal_force_N": float(row["fn_N"]),
        "creep_force_long_N": -float(row["fx_N"]),
        "creep_force_lat_N": float(row["fs_N"]),
        "max_pressure_Pa": float(row["pmax_N_per_mm2"]) * 1e6,
        "contact_area_m2": float(row["contact_area_mm2"]) * 1e-6,
    }


def contact_grid_reference(rows: list[dict]) -> tuple[dict, dict]:
    """Reference and its own relative error estimate from CONTACT rows at several element sizes (one patch sum).

    ``rows``: dicts with ``dx_mm``, ``ds_mm`` and the columns of :func:`contact_row_reference`. The reference is
    the row of the smallest element; the uncertainty of each quantity is the relative change from the row with
    twice its DX and DS (for the first-order convergence of the area and the max pressure, the remaining error of
    the finest grid is about that change), at least CONTACT's print resolution
    (:data:`CONTACT_PRINT_RESOLUTION`); for the creep forces the change of the vector (Fx, Fy) over |F|.
    """
    by_size = sorted(rows, key=lambda r: float(r["dx_mm"]) * float(r["ds_mm"]))
    finest = by_size[0]
    coarser = [
        r
        for r in by_size[1:]
        if math.isclose(float(r["dx_mm"]), 2 * float(finest["dx_mm"]))
        and math.isclose(float(r["ds_mm"]), 2 * float(finest["ds_mm"]))
    ]
    if not coarser:
        raise ValueError(f"CONTACT grid rows {[(r['dx_mm'], r['ds_mm']) for r in rows]}: expected the finest "
                         "element and one of twice its size")  # fmt: skip
    fine, coarse = contact_row_reference(finest), contact_row_reference(coarser[0])
    uncertainty = {}
    for key in ("normal_force_N", "max_pressure_Pa", "contact_area_m2"):
        uncertainty[key] = max(abs(coarse[key] / fine[key] - 1.0), CONTACT_PRINT_RESOLUTION)
    force = math.hypot(fine["creep_force_long_N"], fine["creep_force_lat_N"])
    change = math.hypot(
        coarse["creep_force_long_N"] - fine["creep_force_long_N"],
        coarse["creep_force_lat_N"] - fine["creep_force_lat_N"],
    )
    for key in ("creep_force_long_N", "creep_force_lat_N"):
        uncertainty[key] = max(change / force, CONTACT_PRINT_RESOLUTION)
    return fine, uncertainty


def named_case_names() -> list[str]:
    """Names of the named cases (folders with a reference.toml), sorted."""
    return sorted(p.parent.name for p in CASES_ROOT.glob("*/reference.toml"))
