"""Write the named cases of comparisons/cases/: case.toml, reference.toml, SOURCE.md (and reference fields).

References by kind:

* Hertz ellipses (a/b = 0.1, 1, 10): closed form. The semi-axes a, b and the load N are chosen; the relative
  curvatures follow from Hertz's relations (Johnson 1985 sec. 4.2; Kalker 1990, as quoted in
  rigid_dynamics/contact/hertz.py) written here again with scipy's complete elliptic integrals:
  with p = (b_minor/a_major)^2, m = 1 - p, D = (K - E)/m, B = (E - p K)/m,
  min(A, B) = 3 N D / (2 pi E* a_major^3), max(A, B) = 3 N B / (2 pi E* a_major b_minor^2), p0 = 3N/(2 pi a b).
* Creep cases, large spin, wheel flat, corrugation, worn profiles: the more exact rung, the BEM (CONTACT-style
  NORM + TANG), at n = 40, 80, 160 elements per side (quadric cases; 30, 60, 120 for the worn wheelset case),
  extrapolated per quantity by Richardson with the observed order when the three differences are monotone
  (order between 0.5 and 4); otherwise the finest value. The reference's own error estimate is |R - finest| / |R|.
* Manchester A-2.2 positions: CONTACT's solution on refined elements (contact_grid.csv, written by
  benchmarks/contact_grid_study.py); the published rows of mbench_a22_right.csv copied unchanged for the record.

Run from the repository root: .venv/bin/python benchmarks/make_case_references.py [NAME ...]
It reads /work/shared/data/contact_reference/mbench_a22_right.csv only to copy the three rows (a development
step; nothing at run time reads outside the repository).
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.special import ellipe, ellipk

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CASES = ROOT / "comparisons" / "cases"
CONTACT_CSV = Path("/work/shared/data/contact_reference/mbench_a22_right.csv")
G, NU, MU = 82.0e9, 0.28, 0.3
E_STAR = G / (1.0 - NU)
MATERIAL = f"""[material]
shear_modulus_Pa = {G!r}
poisson_ratio = {NU!r}
friction_coefficient = {MU!r}
"""


def hertz_curvatures(a_x: float, b_y: float, force: float) -> tuple[float, float, float]:
    """(A, B, p0) of the Hertz ellipse with semi-axes a_x along x, b_y along y under ``force``."""
    p0 = 3.0 * force / (2.0 * math.pi * a_x * b_y)
    major, minor = max(a_x, b_y), min(a_x, b_y)
    if major == minor:
        a_c = 3.0 * force / (8.0 * E_STAR * major**3)
        return a_c, a_c, p0
    p = (minor / major) ** 2
    m = 1.0 - p
    k, e = ellipk(m), ellipe(m)
    d_fun, b_fun = (k - e) / m, (e - p * k) / m
    small = 3.0 * force * d_fun / (2.0 * math.pi * E_STAR * major**3)
    large = 3.0 * force * b_fun / (2.0 * math.pi * E_STAR * major * minor**2)
    # the smaller curvature lies along the major axis
    return (small, large, p0) if a_x > b_y else (large, small, p0)


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def toml_table(name: str, values: dict) -> str:
    lines = [f"[{name}]"]
    lines += [f"{k} = {float(v)!r}" for k, v in values.items() if v is not None]
    return "\n".join(lines) + "\n"


def quadric_case(name, description, radius_long, radius_lat, force, creep=(0.0, 0.0, 0.0), extra_geometry=""):
    xi, eta, phi = (float(v) for v in creep)
    radius_long, radius_lat, force = float(radius_long), float(radius_lat), float(force)
    return (
        f'name = "{name}"\ndescription = "{description}"\n\n{MATERIAL}\n[geometry]\nkind = "quadric"\n'
        f"radius_long_m = {radius_long!r}\nradius_lat_m = {radius_lat!r}\n{extra_geometry}\n"
        f"[loading]\nnormal_force_N = {force!r}\n\n[kinematics]\ncreepage_long = {xi!r}\ncreepage_lat = {eta!r}\n"
        f"spin_creepage_1_per_m = {phi!r}\nrolling_speed_m_per_s = 10.0\n\n[solver]\n"
    )


def wheelset_case(name, description, wheel, rail, shift, yaw, inclination):
    return (
        f'name = "{name}"\ndescription = "{description}"\n\n{MATERIAL}\n[geometry]\nkind = "wheelset"\n'
        f'wheel_profile = "{wheel}"\nrail_profile = "{rail}"\nlateral_shift_m = {shift!r}\nyaw_rad = {yaw!r}\n'
        "gauge_m = 1.435\ngauge_height_m = 0.014\nflange_back_distance_m = 1.36\nnominal_radius_m = 0.46\n"
        f"rail_inclination_rad = {inclination!r}\n\n[loading]\nwheel_load_N = 10000.0\n\n"
        "[kinematics]\nrolling_speed_m_per_s = 2.0\n\n[solver]\n"
    )


def reference_toml(source, side, note, tags, reference, uncertainty=None) -> str:
    text = f"source = {json.dumps(source)}\nside = {json.dumps(side)}\nnote = {json.dumps(note)}\n"
    text += f"tags = {json.dumps(list(tags))}\n\n"
    if reference:
        # creep forces that vanish by symmetry come out of the solvers as round-off: write them as exact zeros
        scale = MU * abs(reference.get("normal_force_N", 0.0))
        for key in ("creep_force_long_N", "creep_force_lat_N"):
            if key in reference and abs(reference[key]) < 1e-6 * scale:
                reference = {**reference, key: 0.0}
                if uncertainty:
                    uncertainty = {k: v for k, v in uncertainty.items() if k != key}
    if reference:
        text += toml_table("reference", reference) + "\n"
    if uncertainty:
        text += toml_table("uncertainty", uncertainty)
    return text


# --- Hertz ellipses ---------------------------------------------------------------------------

HERTZ = {"hertz-ab-0.1": 0.1, "hertz-ab-1": 1.0, "hertz-ab-10": 10.0}


def make_hertz(name: str, ratio: float) -> None:
    force, mean = 10_000.0, 4.0e-3
    a_x, b_y = mean * math.sqrt(ratio), mean / math.sqrt(ratio)
    a_c, b_c, p0 = hertz_curvatures(a_x, b_y, force)
    folder = CASES / name
    write(
        folder / "case.toml",
        f"# Hertz ellipse with a/b = {ratio:g}: the relative radii are chosen so that a = {a_x * 1e3:.4g} mm\n"
        f"# along x and b = {b_y * 1e3:.4g} mm along y at 10 kN (see SOURCE.md). Normal contact only.\n"
        + quadric_case(name, f"Hertz ellipse a/b = {ratio:g}, 10 kN, steel", 0.5 / a_c, 0.5 / b_c, force),
    )
    ref = {
        "normal_force_N": force,
        "max_pressure_Pa": p0,
        "contact_area_m2": math.pi * a_x * b_y,
        "semi_axis_long_m": a_x,
        "semi_axis_lat_m": b_y,
    }
    note = f"Hertz ellipse a/b = {ratio:g} under 10 kN: closed form"
    write(folder / "reference.toml", reference_toml("closed-form", "single", note, ("hertz", "normal"), ref))
    write(
        folder / "SOURCE.md",
        f"# {name}\n\nClosed form (Hertz 1882; Johnson 1985 sec. 4.2). The semi-axes a = {a_x!r} m (x) and "
        f"b = {b_y!r} m (y) and the load N = 10 kN are chosen; the relative curvatures A = 1/(2 R_long), "
        "B = 1/(2 R_lat) written in case.toml follow from Hertz's relations with the complete elliptic integrals "
        "(benchmarks/make_case_references.py::hertz_curvatures), p0 = 3N/(2 pi a b), area pi a b. "
        "The reference pressure field is p0 sqrt(1 - x^2/a^2 - y^2/b^2).\n"
        "tests/test_named_cases.py re-derives a, b, p0 from the radii by an independent route (quadrature of "
        "Hertz's potential integrals).\n",
    )


# --- BEM-referenced quadric cases ---------------------------------------------------------------

# name: (description, R_long, R_lat, force, (xi, eta, phi), extra geometry, tags, note)
BASE_R = (0.46, 0.30)
CREEP = {
    "creep-long-small": ("small longitudinal creepage (linear range)", (1.0e-5, 0.0, 0.0), ("creep",)),
    "creep-long-mid": ("longitudinal creepage, half saturated", (4.0e-4, 0.0, 0.0), ("creep",)),
    "creep-long-saturated": ("longitudinal creepage beyond saturation", (5.0e-3, 0.0, 0.0), ("creep", "saturated")),
    "creep-lat-spin": ("lateral creepage with spin", (0.0, -3.0e-4, 0.3), ("creep", "spin")),
    "creep-spin-only": ("pure spin", (0.0, 0.0, 0.8), ("creep", "spin")),
}


def bem_reference(geometry, creepage, force, sizes=(40, 80, 160)):
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.materials import Material

    model = get_model("bem")
    runs = []
    for n in sizes:
        t = time.perf_counter()
        r = model.solve(geometry, creepage, Material(G, NU, MU), normal_force_N=force, options={"nx": n, "ny": n})
        if not r.success:
            raise RuntimeError(f"BEM {n}x{n} failed: {r.message}")
        print(f"    bem {n}x{n}: {time.perf_counter() - t:.2f} s", flush=True)
        runs.append(r)
    return richardson(runs), runs[-1]


def richardson(runs) -> tuple[dict, dict]:
    values = {
        k: [getattr(r, k) for r in runs]
        for k in ("normal_force_N", "creep_force_long_N", "creep_force_lat_N", "max_pressure_Pa", "contact_area_m2")
    }
    return richardson_values(values)


def richardson_values(values: dict) -> tuple[dict, dict]:
    ref, unc = {}, {}
    for key, (f1, f2, f3) in values.items():
        d1, d2 = f2 - f1, f3 - f2
        scale = max(abs(f3), 1e-30)
        if abs(d2) <= 1e-12 * scale:
            ref[key], unc[key] = f3, 1e-12
            continue
        order = math.log2(d1 / d2) if d1 * d2 > 0 else math.nan
        if math.isfinite(order) and 0.5 <= order <= 4.0:
            extrapolated = f3 + d2 / (2.0**order - 1.0)
            ref[key], unc[key] = extrapolated, abs(extrapolated - f3) / max(abs(extrapolated), 1e-30)
        else:
            ref[key], unc[key] = f3, abs(d2) / scale
    return ref, unc


def save_field(folder: Path, result) -> None:
    f = result.fields
    tmp = folder / "reference_field.tmp.npz"
    np.savez_compressed(tmp, x_m=f.x_m, y_m=f.y_m, pressure_Pa=f.pressure_Pa.astype(np.float32))
    tmp.replace(folder / "reference_field.npz")


def make_bem_quadric(name, description, r_long, r_lat, force, creep, tags, extra="", source_note=""):
    from wheelrail.cases import load_case

    folder = CASES / name
    write(folder / "case.toml", quadric_case(name, description, r_long, r_lat, force, creep, extra))
    case = load_case(folder / "case.toml")
    print(f"  {name}", flush=True)
    (ref, unc), finest = bem_reference(case.geometry, case.creepage, force)
    note = f"{description}: BEM Richardson limit of 40/80/160"
    write(folder / "reference.toml", reference_toml("bem-richardson", "single", note, tags, ref, unc))
    save_field(folder, finest)
    write(
        folder / "SOURCE.md",
        f"# {name}\n\n{description}.\n\nReference: the more exact rung, the boundary-element solution "
        "(rigid_dynamics/contact/bem, Kalker's exact theory discretised as in CONTACT) on 40x40, 80x80 and "
        "160x160 elements over the potential contact area, extrapolated per quantity by Richardson with the observed "
        "order (finest value where the three are not monotone); `[uncertainty]` is |limit - 160x160| / |limit|. "
        "reference_field.npz is the 160x160 pressure field. Written by benchmarks/make_case_references.py; "
        "the numbers move if the BEM changes (rerun the script).\n" + source_note,
    )


def kalker_note(creep, force, r_long, r_lat) -> str:
    from rigid_dynamics.contact.hertz import hertz_solve_batch
    from rigid_dynamics.contact.kalker import kalker_coefficients

    h = hertz_solve_batch(
        np.array([0.5 / r_long]),
        np.array([0.5 / r_lat]),
        normal_force_N=np.array([force]),
        shear_modulus_Pa=G,
        poisson_ratio=NU,
    )
    a, b = float(h.semi_axis_long_m[0]), float(h.semi_axis_lat_m[0])
    c = kalker_coefficients(np.array([a / b]), NU)
    fx = -G * a * b * float(c.c11[0]) * creep[0]
    return (
        f"\nCheck against Kalker's linear theory (Table E.3, Kalker 1990): Fx = -G a b C11 xi = {fx:.6g} N "
        f"(a = {a:.6g} m, b = {b:.6g} m, C11 = {float(c.c11[0]):.5g}); at this creepage the exact theory lies "
        "below the linear one by about F/(3 mu N) (Vermeulen-Johnson's initial curvature), i.e. ~0.4 %.\n"
    )


def make_quadric_bem_cases(selected):
    for name, (description, creep, tags) in CREEP.items():
        if selected and name not in selected:
            continue
        note = kalker_note(creep, 10_000.0, *BASE_R) if name == "creep-long-small" else ""
        desc = f"Quadric R_long 0.46 m, R_lat 0.30 m, 10 kN, steel, {description}"
        make_bem_quadric(name, desc, *BASE_R, 10_000.0, creep, tags, source_note=note)
    if not selected or "large-spin" in selected:
        a_c, b_c, _ = hertz_curvatures(8e-3, 4e-3, 82_000.0)
        make_bem_quadric(
            "large-spin",
            "CONTACT's large-spin case: Hertz ellipse a = 8 mm, b = 4 mm, 82 kN, eta = -6.25e-4, phi = 0.625 1/m",
            0.5 / a_c,
            0.5 / b_c,
            82_000.0,
            (0.0, -6.25e-4, 0.625),
            ("creep", "spin", "large-spin"),
            source_note="\nCONTACT's own value for this case, Fy/(mu N) = -0.6074, is quoted for a 40x40 grid; "
            "benchmarks/results/bem.md shows the grid convergence (observed order ~1.1).\n",
        )
    if not selected or "wheel-flat" in selected:
        make_bem_quadric(
            "wheel-flat",
            "Wheel (r 0.46 m) with a rounded 50 mm flat centred at the contact on a rail crown R_lat 0.30 m, 10 kN",
            0.46,
            0.30,
            10_000.0,
            (1.0e-3, 0.0, 0.0),
            ("irregular", "flat", "creep"),
            extra='wheel_flat_length_m = 0.05\nwheel_flat_shape = "rounded"\n',
            source_note="\nGeometry: rigid_dynamics/contact/irregular_patch.py (the flat's exact rigid shape). The "
            "rounded flat of default depth L^2/(16 r) = 0.34 mm is concave at its centre: the wheel stands on the "
            "flat's two shoulders (two contact regions in one potential area). The analytic rungs see the local "
            "curvature at one shoulder (the deepest point), as a rigid-body contact search would give them.\n",
        )
    if not selected or "corrugation" in selected:
        make_bem_quadric(
            "corrugation",
            "Wheel r 0.46 m on a rail crown R_lat 0.30 m with 20 mm corrugation of 10 um amplitude, trough, 10 kN",
            0.46,
            0.30,
            10_000.0,
            (1.0e-3, 0.0, 0.0),
            ("irregular", "corrugation", "creep"),
            extra="corrugation_wavelength_m = 0.02\ncorrugation_amplitude_m = 1e-05\ncorrugation_phase_rad = 0.0\n",
            source_note="\nGeometry: rigid_dynamics/contact/irregular_patch.py (cosine corrugation added to the gap; "
            "phase 0 puts a trough of the rail at the wheel's lowest point). The analytic rungs see the local "
            "curvature at the deepest point.\n",
        )


# --- Manchester A-2.2 (CONTACT on refined elements) ---------------------------------------------

A22 = {
    "a22-tread": (6, "tread contact", ("wheelset", "tread")),
    "a22-flange-root": (
        11,
        "flange root: two interpenetration regions, one patch of two sub-patches in both codes",
        ("wheelset", "flange-root", "two-patch"),
    ),
    "a22-flange": (17, "flange contact", ("wheelset", "flange")),
}


A22_NOTES = {
    11: "\nThe case's inputs are the deck's: its profiles interpolated (SMOOTH = 0: `profile_smoothing_m = 0`) and "
    "its prescribed roll angle and pitch rate of case 11 (added 2026-11-29; before, the 2 mm default smoothing and a "
    "free roll moved the flange-root region's gap by about 1 um and the patch with it). The two interpenetration "
    "regions (6.75 mm apart, between D_COMB = 4 and D_SEP = 8 mm) form one patch of two sub-patches in both codes, "
    "whose normal interaction CONTACT scales by ((D_SEP - d)/(D_SEP - D_COMB))^0.8 (0.391; its m_wr_locatecp, "
    "m_solvpn) and our `bem` by default too (option `subpatch_interaction`, 0.395; "
    "tests/test_wheelset_case_contact_reference.py). With both, our BEM at the default grid (320 x 320) gives N "
    "9618.6 N, Fx 759.9 N, Fy -2738.5 N, max pressure 1573.3 MPa, area 14.94 mm^2 on the wheel: within 0.1 % of "
    "this reference in max pressure and area, 0.1 % of mu N in the forces. Joining the regions fully "
    '(`subpatch_interaction = "full"`, the behaviour before) gives max pressure +1.0 %, area -4.8 %, Fx +1.1 % of '
    "mu N; before the inputs were the deck's, the bench's BEM measured max pressure -3.3 % and area +1.6 % here, "
    "which an earlier note here took for a difference of models (CONTACT's sub-patch interaction and these inputs "
    "together).\n",
    17: "\nThe case's inputs are the deck's: its profiles interpolated (SMOOTH = 0: `profile_smoothing_m = 0`) and "
    "its prescribed roll angle and pitch rate of case 17 (added 2026-11-29, as for a22-flange-root; before, the 2 mm "
    "default smoothing and a free roll). On the same deck with square elements of CONTACT's size our BEM agrees with "
    "CONTACT within 0.16 % in max pressure and area at every size from 0.2 to 0.025 mm "
    "(benchmarks/results/contact_grid.md). At its default grid (refined to 80 x 80) our BEM gives N 12726.3 N, Fx "
    "2073.5 N, Fy -3193.6 N, max pressure 2594.2 MPa, area 7.443 mm^2 on the wheel: max pressure -0.11 %, area "
    "+0.20 %, forces within 0.01 % of mu N of this reference (before: -0.11 %, +0.19 %, Fx -0.04 % of mu N). "
    "Vermeulen-Johnson is 11.3 % off here (Fx -10.4 % of mu N), FASTSIM 20 x 20 1.2 %; with the free roll VJ was "
    "4.1 % off at a longitudinal creepage 19 % above CONTACT's (0.0253 against its CKSI 0.02127; now 0.02127): the "
    "wrong creepage offset part of its error.\n",
    6: "\nThe case's inputs are the deck's: its profiles interpolated (SMOOTH = 0: `profile_smoothing_m = 0`) and "
    "its prescribed roll angle and pitch rate of case 6 (added 2026-11-29, as for a22-flange-root; before, the 2 mm "
    "default smoothing and a free roll). On the same deck with square elements of CONTACT's size our BEM agrees with "
    "CONTACT within 0.01 % in max pressure and area at 0.2, 0.1 and 0.05 mm (benchmarks/results/contact_grid.md). "
    "At its default grid (refined to 80 x 80, stated grid error 1.7 %) our BEM gives N 9786.7 N, Fx 456.5 N, Fy "
    "-2900.1 N, max pressure 730.5 MPa, area 20.34 mm^2 on the wheel: max pressure -0.01 %, area +0.52 % (the "
    "reference's own 0.47 %), forces within 0.01 % of mu N (before: +0.22 %, +0.18 %, 0.00 % of mu N). "
    "Vermeulen-Johnson and FASTSIM 20 x 20 are within 0.7 % here (VJ 1.1 % with the free roll).\n",
}
"""Per A-2.2 case: how our BEM compares with CONTACT at the same element size (SOURCE.md)."""

A22_DECK_INPUTS = {6: (-0.0001457, -4.3455627), 11: (-0.0003554, -4.3353637), 17: (-0.008606, -4.2534857)}
"""Per A-2.2 case whose case.toml takes the deck's inputs: (roll angle, pitch rate) of mbench_a22_right.inp."""


def make_a22(name, case_no, what, tags):
    lines = CONTACT_CSV.read_text().splitlines()
    header, rows = lines[0], [row for row in lines[1:] if row.split(",")[0] == str(case_no)]
    shift = 0.5e-3 * (case_no - 1)
    yaw = 1.2e-3 * (case_no - 1)
    folder = CASES / name
    case_text = wheelset_case(
        name,
        f"Manchester A-2.2 case {case_no}, {what}",
        "MBench_S1002_v3",
        "MBench_UIC60_v3",
        shift,
        yaw,
        math.atan(1 / 40),
    )
    if case_no in A22_DECK_INPUTS:  # the deck's interpolated profiles and prescribed roll and pitch rate
        roll, pitch_rate = A22_DECK_INPUTS[case_no]
        case_text = case_text.replace(
            "rail_inclination_rad = 0.02499479361892016\n",
            "rail_inclination_rad = 0.02499479361892016\nprofile_smoothing_m = 0.0  # the deck's SMOOTH = 0 "
            "(CONTACT interpolates the profiles)\n",
        ).replace(
            "rolling_speed_m_per_s = 2.0\n",
            f"rolling_speed_m_per_s = 2.0\nroll_rad = {roll!r}  # the deck's prescribed roll angle and pitch rate of "
            f"case {case_no}\npitch_rate_rad_per_s = {pitch_rate!r}\n",
        )
    write(
        folder / "case.toml",
        f"# Manchester Contact Benchmark A-2.2, case {case_no} ({what}): shift {shift * 1e3:g} mm, yaw "
        f"{yaw * 1e3:g} mrad.\n# MBench_UIC60_v3 is already canted 1:40 (see wheelrail/cases/manchester-a22.toml).\n"
        + case_text,
    )
    write(
        folder / "contact_reference.csv",
        "# From CONTACT's examples/mbench_a22_right.ref_out (E.A.H. Vollebregt, J.J. Kalker; Apache-2.0; revision "
        "2707), as tabulated in /work/shared/data/contact_reference/mbench_a22_right.csv; units mm, N, N/mm^2, "
        "forces on the rail.\n" + header + "\n" + "\n".join(rows) + "\n",
    )
    note = (
        f"Manchester A-2.2 case {case_no} ({what}), right wheel: CONTACT's solution on its finest element run here "
        "(contact_grid.csv)"
    )
    write(folder / "reference.toml", reference_toml("contact-converged", "right", note, tags, {}))
    write(
        folder / "SOURCE.md",
        f"# {name}\n\nManchester Contact Benchmark (Shackleton & Iwnicki, Vehicle System Dynamics 46 (2008) "
        f"129-149), case A-2.2 step {case_no}: lateral shift {shift * 1e3:g} mm, yaw {yaw * 1e3:g} mrad, 10 kN per "
        "wheel, 2 m/s.\n\nReference: CONTACT's solution for the right wheel on the finest element size run here "
        "(`contact_grid.csv`), with its own error estimate per quantity: the change over the last halving of the "
        "element (at least CONTACT's 4-digit print resolution; comparisons/named_cases.py, "
        "`contact_grid_reference`). CONTACT is the open-source program by E.A.H. Vollebregt and J.J. Kalker "
        "(Vtech CMCC, Apache-2.0, revision 2707 of 2025-07-23), run here by benchmarks/contact_grid_study.py on "
        "its example deck examples/mbench_a22_right.inp (this case alone; only DX and DS changed; its numbers are "
        "used as reference data with this attribution; CONTACT's code is not part of this repository). Its 0.2 mm "
        "row equals the published solution (`contact_reference.csv`, the row of examples/mbench_a22_right.ref_out, "
        "kept for the record).\n\nWhy not the published numbers: CONTACT's max pressure (an element's mean) and "
        "area (NCON dx ds) depend on the element size, and the deck's 0.2 mm elements are coarse for these patches "
        "(3-4 elements across the flange patch): against the published row the bench's BEM error grew as its grid "
        "was refined. The forces change by 0.1 % or less with the element size.\n\nCONTACT prescribes the roll "
        "angle and pitch rate of each case; forces on the rail. comparisons/named_cases.py maps them to the wheel "
        "(Fx = -fx, Fy = +fs). Where our search finds two patches on the right wheel, their N, Fx, Fy are summed "
        "and compared with CONTACT's one combined patch.\n" + A22_NOTES.get(case_no, ""),
    )


def make_worn(selected):
    name = "worn-wheel-worn-rail"
    if selected and name not in selected:
        return
    from wheelrail.cases import load_case, solve_case

    folder = CASES / name
    write(
        folder / "case.toml",
        "# A measured worn wheel on a measured worn high rail (North American heavy haul, profiles from the\n"
        "# CONTACT program; rigid_dynamics/geometry/data/profiles/SOURCE.md), rail canted 1:40.\n"
        + wheelset_case(
            name,
            "worn wheel (worn_high_mileage) on worn rail (site_b_hr), shift 2 mm, yaw 2 mrad",
            "worn_high_mileage",
            "site_b_hr",
            0.002,
            0.002,
            math.atan(1 / 40),
        ),
    )
    case = load_case(folder / "case.toml")
    runs = []
    import dataclasses

    for n in (30, 60, 120):
        t = time.perf_counter()
        sol = solve_case(dataclasses.replace(case, solver_options={"model": {"nx": n, "ny": n}}), "bem")
        print(f"    bem {n}x{n}: {time.perf_counter() - t:.2f} s ({sol.message})", flush=True)
        if not sol.success:
            raise RuntimeError(sol.message)
        runs.append([p for p in sol.patches if p[0] == "right"])
    values = {
        "normal_force_N": [sum(p[3].normal_force_N for p in r) for r in runs],
        "creep_force_long_N": [sum(p[3].creep_force_long_N for p in r) for r in runs],
        "creep_force_lat_N": [sum(p[3].creep_force_lat_N for p in r) for r in runs],
        "max_pressure_Pa": [max(p[3].max_pressure_Pa for p in r) for r in runs],
        "contact_area_m2": [sum(p[3].contact_area_m2 for p in r) for r in runs],
    }
    ref, unc = richardson_values(values)
    note = "worn wheel on worn rail, right wheel: BEM Richardson limit of 30/60/120"
    write(
        folder / "reference.toml",
        reference_toml("bem-richardson", "right", note, ("wheelset", "worn", "non-elliptic"), ref, unc),
    )
    if len(runs[-1]) == 1:
        save_field(folder, runs[-1][0][3])
    write(
        folder / "SOURCE.md",
        f"# {name}\n\nMeasured worn wheel `worn_high_mileage.prw` on the measured worn high rail `site_b_hr.prr` "
        "(North American heavy-haul railway, smoothed; from the CONTACT program, Apache-2.0, see "
        "rigid_dynamics/geometry/data/profiles/SOURCE.md), rail canted 1:40, gauge 1435 mm, flange-back 1360 mm, "
        "r0 460 mm, 10 kN per wheel, shift 2 mm, yaw 2 mrad.\n\nReference: the more exact rung, the BEM through the "
        "whole wheelset case (wheelrail.cases.solve_case, load sharing 'model') with 30x30, 60x60 and 120x120 "
        "elements per patch, extrapolated per quantity by Richardson (finest value where not monotone); "
        "`[uncertainty]` is |limit - 120x120| / |limit|. Right wheel. Rerun benchmarks/make_case_references.py when "
        "the search, the wheelset case or the BEM change.\n",
    )


def main(argv: list[str]) -> None:
    selected = set(argv)
    for name, ratio in HERTZ.items():
        if not selected or name in selected:
            make_hertz(name, ratio)
    for name, (case_no, what, tags) in A22.items():
        if not selected or name in selected:
            make_a22(name, case_no, what, tags)
    make_quadric_bem_cases(selected)
    make_worn(selected)


if __name__ == "__main__":
    main(sys.argv[1:])
