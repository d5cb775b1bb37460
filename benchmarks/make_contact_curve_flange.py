"""Write and run the CONTACT deck of the curve-flange state (tests/data/contact_curve_flange, SOURCE.md there).

The state: scene ``curve-flange`` (S1002 / UIC60 1:40, right curve R = 100 m, cant 0.15 m, 50 km/h, mu 0.3) started
on its settled flange-root contact (initial lateral_displacement_m = -0.00628, yaw_rad = -0.00455,
settling_distance_m = 0): the run's state at t = 0 (:data:`STATE`, recorded from ``simulate``; the vertical position
and roll are the run's initial equilibrium). CONTACT (E.A.H. Vollebregt, J.J. Kalker; Apache-2.0) is run on it with
the scene's own profiles: the built-in S1002 and UIC60 with wheelrail's 2 mm smoothing (the loop's geometry),
written every 0.05 mm (``*.prf``, plain two-column files in CONTACT's canonical form: y to the field side, z down,
mm) and read by CONTACT with SMOOTH = 0 (interpolated).

Cases, one deck each (``<name>.inp``, CONTACT's ``<name>.out`` beside it; a second case in the same deck is not
independent here: CONTACT then finds a 2 um smaller approach on the same pose and up to twice the max pressure),
all with Z_WS prescribed at the state's vertical position: CONTACT's Z_WS = (z + r0) in mm, checked on the
tread patch of the right wheel whose approach equals ours to 0.01 um):

1. left wheel, planar contact approach (D = 2, CONTACT's module 1 as the static wheelset case forms patches), the
   loop's kinematics: CURV = 1/R (right curve), VS = x', VYAW = 0 (the state's yaw rate relative to the curve),
   VPITCH = -(spin rate) + :data:`CANT_PITCH_CORRECTION` (below); DX = DS = 0.2 mm;
2. the same, conformal contact approach (D = 4: curved reference surface, varying normal);
3. right wheel as case 1;
4. left wheel, planar, straight track (CURV = 0) with the pitch rate :data:`STRAIGHT_VPITCH` for which CONTACT's
   CKSI equals case 1's: the kinematics of the static wheelset case (which has no yaw rate); DX = DS = 0.5 mm (the
   test's grid, tests/test_contact_curve_flange.py);
5. as 4 with DX = DS = 0.2 mm (benchmarks/results/curve_flange_contact.md).

CANT_PITCH_CORRECTION: the loop turns its track frame about the true vertical (the canted track's normal tilted by
the cant angle c = asin(0.15 / 1.5)), CONTACT about the track normal; at the flange root that changes the
longitudinal rigid slip by about kappa V ((1 - cos c) y + sin c z) = 6e-4 m/s. The pitch rate is changed by this
over the rolling radius (4e-5 of it) so that CONTACT's longitudinal slip equals the loop's (found by the secant in
:func:`tune_pitch`, recorded in the constant).

Run: ``python benchmarks/make_contact_curve_flange.py [--contact /work/contact-build/run_contact.sh]`` (CONTACT
built as /work/contact-build/READY says); writes the profiles, the decks and CONTACT's .out
files into tests/data/contact_curve_flange. Without CONTACT it writes the decks only.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT_DIR = ROOT / "tests" / "data" / "contact_curve_flange"
PROFILES = {"S1002": "s1002_smoothed.prf", "UIC60": "uic60_smoothed.prf"}
SMOOTHING_M = 0.002  # the scene's (wheelrail's default profile smoothing)
SPACING_M = 5.0e-5

STATE = {
    "y_m": -0.00628,
    "z_m": -0.4601900903898496,
    "yaw_rad": -0.00455,
    "roll_rad": 0.0007168608842980646,
    "x_velocity_m_per_s": 13.8889,
    "spin_rate_rad_per_s": 30.022146467392318,
}
"""The curve-flange state at t = 0 (simulate, main-branch commit of this file; the other rates are 0)."""
NOMINAL_RADIUS_M = 0.46
CURVATURE_1_PER_M = 0.01  # right curve, R = 100 m
RAIL_INCLINATION_RAD = 0.025
LOOP_LONGITUDINAL_SLIP_M_PER_S = -0.0025032242 * 13.8833763
"""xi V of the loop's formed patch (formed_patches.transported_creepage at the state): the wheel's slip along e_x."""
CANT_PITCH_CORRECTION = 0.0013152
"""VPITCH - (-spin rate) of cases 1-3, rad/s (module docstring; from :func:`tune_pitch`)."""
STRAIGHT_VPITCH = -29.805840
"""VPITCH of cases 4-5: CONTACT's CKSI on straight track equal to case 1's (from :func:`tune_pitch`)."""


def export_profiles(out_dir: Path) -> None:
    """The scene's S1002 and UIC60 curves (2 mm smoothing) every 0.05 mm as two-column files, mm."""
    from rigid_dynamics.geometry import load_profile
    from rigid_dynamics.geometry.profile import ProfileCurve

    for name, fname in PROFILES.items():
        curve = ProfileCurve(load_profile(name), SMOOTHING_M)
        y = np.arange(math.ceil(curve.y_min_m / SPACING_M) * SPACING_M, curve.y_max_m + 1e-12, SPACING_M)
        z = curve.z(y)
        ok = np.isfinite(z)
        text = "".join(f"{a:12.5f} {b:14.8f}\n" for a, b in zip(y[ok] * 1e3, z[ok] * 1e3, strict=True))
        (out_dir / fname).write_text(text)


def case_text(title, side, discretisation, element_mm, curvature_1_per_mm, vpitch, z_mm) -> str:
    """One module-1 case (Z_WS prescribed, steady rolling, Coulomb friction 0.3, half-space)."""
    config = 1 if side == "right" else 0
    s = STATE
    return "\n".join(
        [
            f"% {title}",
            "  1 MODULE",
            f" {config}203000    C-P-B-T-N-F-S   CONFIG, PVTIME, BOUND,  TANG,   NORM,   FORCE,  STRESS",
            f" 00{discretisation}2033    V-L-D-C-M-Z-E   VARFRC, FRCLAW, DISCNS, INFLCF, MATER,  ZTRACK, EWHEEL",
            " 0000321    H-G-I-A-O-W-R     HEAT, GAUSEI, IESTIM, MATFIL, OUTPUT, FLOW,   RETURN",
            "    999     100    30    1     1e-5         MAXGS , MAXIN , MAXNR , MAXOUT, EPS",
            "  0.300   0.300                                 FSTAT, FKIN",
            "  0.280   0.280   82000.  82000.                POISS 1,2,  GG 1,2",
            f"  {element_mm:.3f}   {element_mm:.3f}   1.000   90d   8.0   4.0"
            "       DX, DS, DQREL, A_SEP, D_SEP, D_COMB",
            f"   14.0     0    1435.0   {RAIL_INCLINATION_RAD}   {curvature_1_per_mm:g}"
            "        GAUGHT, GAUGSQ, GAUGWD, CANT, CURV",
            f"  '{PROFILES['UIC60']}'   0     1.0   0.0  -1    RFNAME, MIRRORY, SCALE, SMOOTH, MIRRORZ",
            "     0.0    0.0   0.000   0.0   0.0   0.000     DY, DZ, ROLL, VY, VZ, VROLL",
            "  1360.0  -70.0   460.0                         FBDIST, FBPOS, NOMRAD",
            f"  '{PROFILES['S1002']}'   0     1.0   0.0  -1    WFNAME, MIRRORY, SCALE, SMOOTH, MIRRORZ",
            f"  0.0  {s['y_m'] * 1e3:.6f}  {z_mm:.8f}  {s['roll_rad']!r}  {s['yaw_rad']!r}  0.0"
            "      S, Y, Z, ROLL, YAW, PITCH",
            f"  {s['x_velocity_m_per_s'] * 1e3:.4f}  0.0  0.0  0.0  0.0  {vpitch:.7f}"
            "      VS, VY, VZ, VROLL, VYAW, VPITCH",
            "",
        ]
    )


CASES = (
    ("left_planar_curve", "left wheel, planar, curve (the loop's kinematics)", "left", 2, 0.2, "curve"),
    ("left_conformal_curve", "left wheel, conformal, curve", "left", 4, 0.2, "curve"),
    ("right_planar_curve", "right wheel, planar, curve", "right", 2, 0.2, "curve"),
    ("left_planar_straight_05", "left wheel, planar, straight (the static case's kinematics), 0.5 mm", "left", 2, 0.5,
     "straight"),
    ("left_planar_straight", "left wheel, planar, straight, 0.2 mm", "left", 2, 0.2, "straight"),
)  # fmt: skip
"""(deck name, title, side, D digit, DX = DS in mm, kinematics) of the five cases (module docstring, in order)."""


def deck_text(case, correction=CANT_PITCH_CORRECTION, straight_vpitch=STRAIGHT_VPITCH) -> str:
    """The deck of one of :data:`CASES` (one case per deck: module docstring)."""
    name, title, side, discretisation, element_mm, kinematics = case
    z_mm = (STATE["z_m"] + NOMINAL_RADIUS_M) * 1e3
    if kinematics == "curve":
        curv, vpitch = CURVATURE_1_PER_M * 1e-3, -STATE["spin_rate_rad_per_s"] + correction
    else:
        curv, vpitch = 0.0, straight_vpitch
    head = (
        "% CONTACT deck of the wheelrail curve-flange state (benchmarks/make_contact_curve_flange.py;\n"
        "% tests/data/contact_curve_flange/SOURCE.md). Z_WS prescribed: the state's vertical position.\n"
    )
    return head + case_text(title, side, discretisation, element_mm, curv, vpitch, z_mm) + "  0 MODULE\n"


def run_contact(runner: str, deck: str, profiles_from: Path) -> list[dict]:
    """Run ``deck`` in a scratch folder with the profiles; the .out's cases (benchmarks/contact_out.read_out)."""
    sys.path.insert(0, str(Path(__file__).parent))
    from contact_out import read_out

    with tempfile.TemporaryDirectory() as tmp:
        for fname in PROFILES.values():
            shutil.copy(profiles_from / fname, tmp)
        (Path(tmp) / "deck.inp").write_text(deck)
        subprocess.run([runner, str(Path(tmp) / "deck.inp")], check=True, capture_output=True, env=os.environ)
        return read_out(Path(tmp) / "deck.out")


def tune_pitch(runner: str, profiles_from: Path) -> tuple[float, float]:
    """(CANT_PITCH_CORRECTION, STRAIGHT_VPITCH) by secant iterations on CONTACT's case 1 / case 4 alone."""
    z_mm = (STATE["z_m"] + NOMINAL_RADIUS_M) * 1e3

    def slip(vp, curv):
        text = case_text("tune", "left", 2, 0.2, curv, vp, z_mm) + "  0 MODULE\n"
        patch = run_contact(runner, text, profiles_from)[0]["patches"][0]
        return patch, -patch["CKSI"] * patch["VELOC"] * 1e-3  # the wheel's slip along e_x, m/s

    def secant(f, x0, x1, target, tolerance):
        # CONTACT prints 4 significant digits: stop at that resolution
        f0, f1 = f(x0), f(x1)
        for _ in range(8):
            if abs(f1 - target) <= tolerance or f1 == f0:
                break
            x0, x1, f0 = x1, x1 + (target - f1) * (x1 - x0) / (f1 - f0), f1
            f1 = f(x1)
        return x1

    base = -STATE["spin_rate_rad_per_s"]
    vp = secant(lambda v: slip(v, CURVATURE_1_PER_M * 1e-3)[1], base, base - 1e-3, LOOP_LONGITUDINAL_SLIP_M_PER_S, 2e-5)
    cksi = slip(vp, CURVATURE_1_PER_M * 1e-3)[0]["CKSI"]
    straight = secant(lambda v: slip(v, 0.0)[0]["CKSI"], vp, vp + 0.2, cksi, 1.5e-6)
    return vp - base, straight


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--contact", default="/work/contact-build/run_contact.sh", help="CONTACT's run script")
    parser.add_argument("--tune", action="store_true", help="find the pitch rates again (tune_pitch) and print them")
    args = parser.parse_args(argv)
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    export_profiles(OUT_DIR)
    correction, straight = CANT_PITCH_CORRECTION, STRAIGHT_VPITCH
    if args.tune:
        correction, straight = tune_pitch(args.contact, OUT_DIR)
        print(f"CANT_PITCH_CORRECTION = {correction:.7f}, STRAIGHT_VPITCH = {straight:.6f}")
    for case in CASES:
        name = case[0]
        (OUT_DIR / f"{name}.inp").write_text(deck_text(case, correction, straight))
        if not Path(args.contact).exists():
            continue
        with tempfile.TemporaryDirectory() as tmp:
            for fname in PROFILES.values():
                shutil.copy(OUT_DIR / fname, tmp)
            shutil.copy(OUT_DIR / f"{name}.inp", tmp)
            subprocess.run([args.contact, str(Path(tmp) / f"{name}.inp")], check=True, capture_output=True)
            shutil.copy(Path(tmp) / f"{name}.out", OUT_DIR / f"{name}.out")
    ran = "and CONTACT's .out files" if Path(args.contact).exists() else f"(CONTACT not found at {args.contact})"
    print(f"wrote {len(CASES)} decks into {OUT_DIR} {ran}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
