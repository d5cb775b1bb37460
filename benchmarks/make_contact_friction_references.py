"""Write the CONTACT reference data for the friction work (issue 26) under tests/data/contact_friction.

Development tool, not part of the package or the tests: it runs CONTACT (E.A.H. Vollebregt, J.J. Kalker; Vtech
CMCC; Apache-2.0), built outside this repository by a helper (``/work/contact-build/run_contact.sh``; source:
repository eve70a/CONTACT, revision 2707 of 2025-07-23, snapshot commit d431cdb), on the decks of each reference
folder and tabulates what CONTACT prints (``benchmarks/contact_out.py``). No code of CONTACT is in this repository;
the decks written here are our own inputs to it, and the one example deck used (``mbench_a22_varfric``) is read from
CONTACT's example folder, with its published ``.ref_out`` tabulated next to this build's run.

Folders (each has a SOURCE.md with the inputs needed to reproduce the cases in wheelrail):
* ``varfric/``: CONTACT's friction-variation example (friction against the contact angle, two patches).
* ``falling/``: Hertzian creep cases under friction laws L = 0, 2, 3, 4 (deck ``falling_friction.inp``), and the
  example ``tractcurv`` (L = 4 with CONTACT's interfacial layer and FASTSIM variants).
* ``force_control/``: wheelset cases on the A-2.2 set-up with the total longitudinal force prescribed (F = 1).

Run: ``.venv/bin/python benchmarks/make_contact_friction_references.py [varfric|falling|force_control ...]``.
"""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

from contact_out import read_out  # noqa: E402

DATA = ROOT / "tests" / "data" / "contact_friction"
RUNNER = Path("/work/contact-build/run_contact.sh")
EXAMPLES = Path("/work/contact-src/examples")
PROFILES = ("MBench_S1002_v3.prw", "MBench_UIC60_v3.prr")


def run_deck(deck_text: str | None, name: str, example: bool = False) -> Path:
    """Run a deck in a fresh folder (with the A-2.2 profiles), return the path of its .out."""
    work = Path(tempfile.mkdtemp(prefix=f"contact-{name}-"))
    for prof in PROFILES:
        shutil.copy(EXAMPLES / prof, work / prof)
    if example:
        shutil.copy(EXAMPLES / f"{name}.inp", work / f"{name}.inp")
    else:
        (work / f"{name}.inp").write_text(deck_text)
    subprocess.run([str(RUNNER), str(work / f"{name}.inp")], check=True, capture_output=True, timeout=1800)
    return work / f"{name}.out"


def _g(d: dict, *names, default=""):
    for n in names:
        if d.get(n) is not None:
            return d[n]
    return default


def wheelrail_rows(out: Path, dx_mm: float = 0.2) -> list[dict]:
    """One row per contact patch of a module-1 (wheel-rail) output."""
    rows = []
    for case in read_out(out):
        for k, p in enumerate(case["patches"], start=1):
            ncon = _g(p, "NCON")
            mu_min, mu_max = p.get("FSTAT_MIN"), p.get("FSTAT_MAX")
            rows.append(
                {
                    "case": case["case"],
                    "s_ws_mm": _g(case, "S_WS"),
                    "y_ws_mm": _g(case, "Y_WS"),
                    "yaw_ws_rad": _g(case, "YAW_WS"),
                    "z_ws_mm": _g(case, "Z_WS"),
                    "roll_ws_rad": _g(case, "ROLL_WS"),
                    "vpitch_ws_rad_per_s": _g(case, "VPITCH_WS"),
                    "fx_tr_N": _g(case, "FX(TR)"),
                    "fy_tr_N": _g(case, "FY(TR)"),
                    "fz_tr_N": _g(case, "FZ(TR)"),
                    "fx_ws_N": _g(case, "FX(WS)"),
                    "patch": k,
                    "n_patches": case["n_patches"],
                    "ycp_rail_mm": _g(p, "YCP(R)"),
                    "zcp_rail_mm": _g(p, "ZCP(R)"),
                    "deltcp_tr_rad": _g(p, "DELTCP(TR)"),
                    "mu": "" if mu_min is not None else _g(p, "FSTAT"),
                    "mu_row_min": "" if mu_min is None else mu_min,
                    "mu_row_max": "" if mu_max is None else mu_max,
                    "cksi": _g(p, "CKSI"),
                    "ceta": _g(p, "CETA"),
                    "cphi_1_per_mm": _g(p, "CPHI"),
                    "fn_N": _g(p, "FN", "BAR_FN"),
                    "fx_N": _g(p, "FX", "BAR_FX"),
                    "fs_N": _g(p, "FS", "BAR_FS"),
                    "mn_N_mm": _g(p, "MN"),
                    "approach_mm": _g(p, "APPROACH"),
                    "pmax_N_per_mm2": _g(p, "PMAX"),
                    "ncon": ncon,
                    "nadh": _g(p, "NADH"),
                    "nslip": _g(p, "NSLIP"),
                    "dx_mm": dx_mm,
                    "contact_area_mm2": round(ncon * dx_mm * dx_mm, 4) if ncon != "" else "",
                }
            )
    return rows


def write_csv(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    with tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    tmp.replace(path)
    print(f"wrote {path.relative_to(ROOT)} ({len(rows)} rows)")


# ---------------------------------------------------------------------------------------------- (a) varfric


def make_varfric() -> None:
    published = wheelrail_rows(EXAMPLES / "mbench_a22_varfric.ref_out")
    write_csv(DATA / "varfric" / "mbench_a22_varfric.csv", published)
    ours = wheelrail_rows(run_deck(None, "mbench_a22_varfric", example=True))
    differ = [(a["case"], a["patch"], k) for a, b in zip(published, ours, strict=True) for k in a if a[k] != b[k]]
    print(f"this build against the published .ref_out: {len(differ)} values differ {differ[:10]}")


# ---------------------------------------------------------------------------------------------- (b) falling

FALLING_LAWS = {  # L -> (FKIN, F1, SABSH1 mm/s, F2, SABSH2 mm/s); L = 0: (FSTAT, FKIN)
    0: (0.33, 0.33),
    2: (0.14, 0.19, 1250.0, 0.0, 1250.0),
    3: (0.14, 0.19, 1250.0, 0.0, 1250.0),
    4: (0.14, 0.19, 1250.0, 0.0, 1250.0),
}
FALLING_CREEP = [  # (CKSI, CETA, CPHI 1/mm)
    (0.001, 0.0, 0.0),
    (0.002, 0.0, 0.0),
    (0.004, 0.0, 0.0),
    (0.01, 0.0, 0.0),
    (0.03, 0.0, 0.0),
    (0.1, 0.0, 0.0),
    (0.25, 0.0, 0.0),
    (0.003, 0.002, 0.0002),
    (0.05, 0.03, 0.0005),
]
FN_N, VELOC_MM_S = 106700.0, 10000.0


def falling_deck() -> str:
    lines = [
        "% Hertzian creep cases under CONTACT's friction laws L = 0, 2, 3, 4 (wheelrail reference deck).",
        "% Geometry and load of CONTACT's tractcurv example (Eurosprinter, Polach 2005): A1 = 0.0008 1/mm (R = 625",
        "% mm), a/b = 0.5, FN = 106.7 kN, V = 10 m/s, G = 82 GPa, nu = 0.28, 48 x 44 elements, scale 1.1;",
        "% elastic bodies (M = 0), no friction memory (MEMDST = 0).",
        "",
    ]
    for law, params in FALLING_LAWS.items():
        for cksi, ceta, cphi in FALLING_CREEP:
            lines += [
                " 3 MODULE",
                "  203100     P-B-T-N-F-S        PVTIME, BOUND , TANG  , NORM , FORCE, STRESS",
                f"  {law}22020     L-D-C-M-Z-E        FRCLAW, DISCNS, INFLCF, MATER, RZNORM, EXRHS",
                " 0000331   H-G-I-A-O-W-R  HEAT, GAUSEI, IESTIM, MATFIL, OUTPUT, FLOW, RETURN",
                "    80   200    5    1      1e-6    MAXGS , MAXIN , MAXNR , MAXOUT, EPS",
                f" {FN_N:.1f}   {cksi:.6g}   {ceta:.6g}   {cphi:.6g}        FN, CKSI, CETA, CPHI",
            ]
            if law == 0:
                lines.append(f"   {params[0]}   {params[1]}                      FSTAT, FKIN")
            else:
                lines.append("   " + "   ".join(f"{v:.6g}" for v in params) + "   FKIN, F1, SABSH1, F2, SABSH2")
                lines.append("   0.000   1.000                    MEMDST, MEM_S0")
            lines += [
                f"   0.000      0.500      {VELOC_MM_S:.1f}           CHI, DQ, VELOC",
                "   0.280      0.280      82000.     82000.          POISS 1,2,  GG 1,2",
                "   -2                                               IPOTCN",
                "   48   44    0.0008     0.500      1.100           MX,MY,A1,AOB,SCALE",
                "",
            ]
    lines.append(" 0 MODULE")
    return "\n".join(lines) + "\n"


def hertz_rows(out: Path, laws: list[tuple]) -> list[dict]:
    rows = []
    for case, law in zip(read_out(out), laws, strict=True):
        p = case["patches"][0]
        rows.append(
            {
                "case": case["case"],
                **law,
                "fn_N": _g(p, "FN"),
                "cksi": _g(p, "CKSI"),
                "ceta": _g(p, "CETA"),
                "cphi_1_per_mm": _g(p, "CPHI"),
                "veloc_mm_per_s": _g(p, "VELOC"),
                "fx_N": _g(p, "FX"),
                "fy_N": _g(p, "FY"),
                "mz_N_mm": _g(p, "MZ"),
                "fx_over_fstat_fn": _g(p, "FX/FSTAT/FN"),
                "fy_over_fstat_fn": _g(p, "FY/FSTAT/FN"),
                "approach_mm": _g(p, "APPROACH"),
                "pmax_N_per_mm2": _g(p, "PMAX"),
                "fric_power_as_printed": _g(p, "FRIC.POWER"),
                "npot": _g(p, "NPOT"),
                "ncon": _g(p, "NCON"),
                "nadh": _g(p, "NADH"),
                "nslip": _g(p, "NSLIP"),
            }
        )
    return rows


def make_falling() -> None:
    text = falling_deck()
    (DATA / "falling").mkdir(parents=True, exist_ok=True)
    (DATA / "falling" / "falling_friction.inp").write_text(text)
    out = run_deck(text, "falling_friction")
    laws = []
    for law, params in FALLING_LAWS.items():
        for _ in FALLING_CREEP:
            if law == 0:
                laws.append({"frclaw": 0, "mu_static": params[0], "mu_kin": params[1], "mu_1": 0.0,
                             "sabsh1_mm_per_s": "", "mu_2": 0.0, "sabsh2_mm_per_s": ""})  # fmt: skip
            else:
                fkin, f1, sh1, f2, sh2 = params
                laws.append({"frclaw": law, "mu_static": fkin + f1 + f2, "mu_kin": fkin, "mu_1": f1,
                             "sabsh1_mm_per_s": sh1, "mu_2": f2, "sabsh2_mm_per_s": sh2})  # fmt: skip
    write_csv(DATA / "falling" / "falling_friction.csv", hertz_rows(out, laws))
    # CONTACT's example tractcurv: 4 series of 30 cases (see SOURCE.md)
    out = run_deck(None, "tractcurv", example=True)
    series = (
        [{"series": 1, "model": "half-space Coulomb (L=0 M=0)", "frclaw": 0}] * 30
        + [{"series": 2, "model": "half-space with interfacial layer; exponential (L=4 M=4)", "frclaw": 4}] * 30
        + [{"series": 3, "model": "FASTSIM parabolic bound; Coulomb (L=0 M=3 B=3)", "frclaw": 0}] * 30
        + [{"series": 4, "model": "modified FASTSIM; exponential (L=4 M=3 B=3)", "frclaw": 4}] * 30
    )
    write_csv(DATA / "falling" / "tractcurv.csv", hertz_rows(out, series))


# ---------------------------------------------------------------------------------------------- (c) force control

FORCE_CASES = [  # (y_ws mm, yaw rad, roll rad, FX_WS N, D_SEP mm, D_COMB mm)
    (0.0, 0.0, 0.0, 1500.0, 8.0, 4.0),
    (0.0, 0.0, 0.0, -1500.0, 8.0, 4.0),
    (0.0, 0.0, 0.0, 2700.0, 8.0, 4.0),
    (5.0, 0.0120, -0.00035540, 1500.0, 8.0, 4.0),
    (5.0, 0.0120, -0.00035540, 1500.0, 6.0, 3.0),  # the patches kept apart: two patches
]


def force_deck() -> str:
    head = [
        "% A-2.2 right wheel (CONTACT's mbench_a22_right set-up) with the total longitudinal force FX_WS prescribed",
        "% (F = 1) instead of the pitch velocity, which CONTACT solves (wheelrail reference deck).",
        "",
    ]
    lines = list(head)
    for k, (y, yaw, roll, fx, dsep, dcomb) in enumerate(FORCE_CASES):
        new_sep = k > 0 and (dsep, dcomb) != FORCE_CASES[k - 1][4:]
        lines += [
            "  1 MODULE",
            " 1203110    C-P-B-T-N-F-S   CONFIG, PVTIME, BOUND,  TANG,   NORM,   FORCE,  STRESS",
        ]
        if k == 0:
            lines += [
                " 0022033    V-L-D-C-M-Z-E   VARFRC, FRCLAW, DISCNS, INFLCF, MATER,  ZTRACK, EWHEEL",
                " 0000321    H-G-I-A-O-W-R     HEAT, GAUSEI, IESTIM, MATFIL, OUTPUT, FLOW,   RETURN",
                "    999     100    30    1     1e-5         MAXGS , MAXIN , MAXNR , MAXOUT, EPS",
                "  0.300   0.300                                 FSTAT, FKIN",
                "  0.280   0.280   82000.  82000.                POISS 1,2,  GG 1,2",
                "  0.200   0.200   1.000   90d   8.0   4.0      DX, DS, DQREL, A_SEP, D_SEP, D_COMB",
                "   14.0     0    1435.0   0.000                GAUGHT, GAUGSQ, GAUGWD, CANT",
                "  'MBench_UIC60_v3.prr'   0     1.0   0.0       RFNAME, MIRRORY, SCALE, SMOOTH",
                "     0.0    0.0   0.000   0.0   0.0   0.000     DY, DZ, ROLL, VY, VZ, VROLL",
                "  1360.0  -70.0   460.0                         FBDIST, FBPOS, NOMRAD",
                "  'MBench_S1002_v3.prw'   0     1.0   0.0       WFNAME, MIRRORY, SCALE, SMOOTH",
            ]
        else:
            lines += [
                f" 01{2 if new_sep else 1}1002    V-L-D-C-M-Z-E  VARFRC, FRCLAW, DISCNS, INFLCF, MATER, ZTRACK, EWHEEL",
                " 0100321    H-G-I-A-O-W-R  HEAT, GAUSEI, IESTIM, MATFIL, OUTPUT, FLOW, RETURN",
            ]
            if new_sep:
                lines.append(
                    f"  0.200   0.200   1.000   90d   {dsep:.1f}   {dcomb:.1f}      DX, DS, DQREL, A_SEP, D_SEP, D_COMB"
                )
        lines += [
            f"  0.0  {y:.1f}  10000.  {roll:.8f}  {yaw:.4f}  0.0      S, Y, FZ, ROLL, YAW, PITCH",
            f" 2000. 0.0    0.0   0.0        0.0  {fx:.1f}     VS,VY,VZ, VROLL,VYAW, FX_WS",
            "",
        ]
    lines.append(" 0 MODULE")
    return "\n".join(lines) + "\n"


def make_force_control() -> None:
    text = force_deck()
    (DATA / "force_control").mkdir(parents=True, exist_ok=True)
    (DATA / "force_control" / "force_control.inp").write_text(text)
    out = run_deck(text, "force_control")
    rows = wheelrail_rows(out)
    for r in rows:
        r["fx_ws_prescribed_N"] = FORCE_CASES[r["case"] - 1][3]
        r["d_sep_mm"], r["d_comb_mm"] = FORCE_CASES[r["case"] - 1][4:]
    write_csv(DATA / "force_control" / "force_control.csv", rows)


if __name__ == "__main__":
    todo = sys.argv[1:] or ["varfric", "falling", "force_control"]
    for name in todo:
        {"varfric": make_varfric, "falling": make_falling, "force_control": make_force_control}[name]()
