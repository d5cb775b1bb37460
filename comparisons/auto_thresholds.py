"""Derive ``auto``'s thresholds from a bench run, the named cases' features and a creep sweep.

Data (:func:`derive`): the rows of a bench run (``comparisons.bench`` CSV format, the tangential rungs linear,
vermeulen-johnson and fastsim at its grids) on the named cases, plus the rows of :func:`run_sweep`; the features
of every case (:func:`case_features`, :func:`rigid_dynamics.contact.auto.patch_features`); the boxes of
:func:`rigid_dynamics.contact.auto.derive_thresholds`.

Why a sweep: the named cases hold five creep points on one quadric (two with spin) and the wheelset cases; they
leave the saturation and spin-share axes with gaps of a factor 5-10 between measured points. The sweep adds
creep points on the same quadric (R_long 0.46 m, R_lat 0.30 m, 10 kN, steel, mu 0.3) over w' = 0.005 to 1.5
without spin and over spin shares 0.01 to 0.6 at four saturations (with translational creepage the share stays
below 1; the pure-spin cases creep-spin-only and large-spin have share 1). Its reference is BEM: the first-order
Richardson limit of 48 x 48 and 96 x 96 elements (BEM's creep forces converge as 1/n on these patches); the
reference's own error estimate is the difference to the limit from 32 x 32 and 64 x 64 (recorded per point).
The error of a rung on a sweep point is the bench's creep-force error (the normal problem is Hertz in every
tangential rung, exact on a quadric).
"""

from __future__ import annotations

import datetime
import hashlib
import math
import subprocess
import time
from pathlib import Path

import numpy as np

from rigid_dynamics.contact.auto import FEATURES, LEVELS, RUNG_MODELS, derive_thresholds, patch_features

SWEEP_RADII_M = (0.46, 0.30)
SWEEP_NORMAL_FORCE_N = 1.0e4
SWEEP_MATERIAL = (82.0e9, 0.28, 0.3)
SWEEP_SATURATIONS = (0.005, 0.01, 0.02, 0.035, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, 1.5)
SWEEP_SPIN_SHARES = (0.01, 0.03, 0.1, 0.15, 0.2, 0.3, 0.6)
SWEEP_SPIN_SATURATIONS = (0.02, 0.1, 0.3, 0.7)
SWEEP_REFERENCE = ((48, 96), (32, 64))
"""BEM grids of the reference (Richardson limit) and of its error estimate."""
SWEEP_DIRECTION = (1.0, 0.5)
"""Translational creepage direction (xi, eta) of the sweep, normalised."""


def _hertz_of(geometry, material, normal_force_N):
    from rigid_dynamics.contact.hertz import hertz_solve_batch

    return hertz_solve_batch(
        geometry.curvature_long_1_per_m,
        geometry.curvature_lat_1_per_m,
        normal_force_N=float(normal_force_N),
        shear_modulus_Pa=material.shear_modulus_Pa,
        poisson_ratio=material.poisson_ratio,
    )


def max_features(per_patch: list[dict]) -> dict:
    """The largest value of each feature over a side's patches (the worst patch decides)."""
    return {f: max(p[f] for p in per_patch) for f in FEATURES}


def case_features(named) -> dict | None:
    """Features of a named case's compared side: of its patch (quadric), or the largest over the side's patches of a
    wheelset case (solved with ``hertz`` for the geometry, creepages and normal forces). None without contact.
    """
    from comparisons.bench import solve_contact_case

    case = named.case
    if case.kind == "quadric":
        hz = _hertz_of(case.geometry, case.material, case.normal_force_N)
        return patch_features(case.geometry, case.creepage, case.material, hz)
    patches, success, _ = solve_contact_case(case, "hertz", {})
    on_side = [p for p in patches if p[0] == named.side and (p[3].normal_force_N or 0) > 0]
    if not success or not on_side:
        return None
    feats = [
        patch_features(g, c, case.material, _hertz_of(g, case.material, r.normal_force_N)) for _, g, c, r in on_side
    ]
    return max_features(feats)


def sweep_points() -> list[dict]:
    """The sweep's creep points: name, creepages; the quadric and load are the module's SWEEP_* constants."""
    from rigid_dynamics.contact.kalker import kalker_coefficients
    from rigid_dynamics.contact.linear import linear_creep_forces
    from rigid_dynamics.contact.types import ContactGeometry
    from rigid_dynamics.materials import Material

    material = Material(*SWEEP_MATERIAL)
    geometry = ContactGeometry.quadric(*SWEEP_RADII_M)
    hz = _hertz_of(geometry, material, SWEEP_NORMAL_FORCE_N)
    a, b = float(hz.semi_axis_long_m), float(hz.semi_axis_lat_m)
    coef = kalker_coefficients(a / b, material.poisson_ratio)
    mu_n = material.friction_coefficient * SWEEP_NORMAL_FORCE_N
    dx, dy = np.array(SWEEP_DIRECTION) / math.hypot(*SWEEP_DIRECTION)

    def t_lin(s, phi):
        tx, ty, _ = linear_creep_forces(
            a, b, s * dx, s * dy, phi, shear_modulus_Pa=material.shear_modulus_Pa,
            poisson_ratio=material.poisson_ratio, coefficients=coef,
        )  # fmt: skip
        return math.hypot(float(tx), float(ty))

    unit = t_lin(1.0, 0.0)
    spin_unit = material.shear_modulus_Pa * (a * b) ** 1.5 * float(coef.c23)
    points = []
    for w in SWEEP_SATURATIONS:
        points.append({"name": f"sweep-w{w:g}", "creepage": (w * 3 * mu_n / unit * dx, w * 3 * mu_n / unit * dy, 0.0)})
    for w in SWEEP_SPIN_SATURATIONS:
        s = w * 3 * mu_n / unit
        for share in SWEEP_SPIN_SHARES:
            # spin share = spin_unit |phi| / max(T_lin(s, phi), mu N): bisection on phi (monotone here)
            lo, hi = 0.0, 1.0
            while spin_unit * hi / max(t_lin(s, hi), mu_n) < share:
                hi *= 2.0
                if hi > 1e6:
                    raise ValueError(f"spin share {share} is not reached at w' = {w}")
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if spin_unit * mid / max(t_lin(s, mid), mu_n) < share:
                    lo = mid
                else:
                    hi = mid
            points.append({"name": f"sweep-w{w:g}-s{share:g}", "creepage": (s * dx, s * dy, 0.5 * (lo + hi))})
    return points


def _creep_error(fx, fy, ref, mu_n) -> float:
    scale = max(math.hypot(*ref), 0.01 * mu_n)
    return math.hypot(fx - ref[0], fy - ref[1]) / scale


def run_sweep(quick: bool = False, progress=None) -> tuple[list[dict], dict]:
    """Solve the sweep: BEM reference and every tangential rung at the bench's grids (``quick``: the quick bench's).

    Returns:
        (rows in the bench's CSV format, case name -> features).
    """
    from comparisons.bench import QUICK_RESOLUTIONS, RESOLUTIONS
    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.contact.types import ContactGeometry, Creepage
    from rigid_dynamics.materials import Material

    material = Material(*SWEEP_MATERIAL)
    geometry = ContactGeometry.quadric(*SWEEP_RADII_M)
    hz = _hertz_of(geometry, material, SWEEP_NORMAL_FORCE_N)
    mu_n = material.friction_coefficient * SWEEP_NORMAL_FORCE_N
    bem = get_model("bem")
    rows, features = [], {}
    points = sweep_points()
    for i, point in enumerate(points):
        creepage = Creepage(*point["creepage"], 10.0)
        features[point["name"]] = patch_features(geometry, creepage, material, hz)
        limits = []
        for coarse, fine in SWEEP_REFERENCE:
            f = []
            for n in (coarse, fine):
                r = bem.solve(
                    geometry, creepage, material, normal_force_N=SWEEP_NORMAL_FORCE_N, options={"nx": n, "ny": n}
                )
                if not r.success:
                    raise RuntimeError(f"sweep reference {point['name']} BEM {n}x{n}: {r.status}: {r.message}")
                f.append(np.array([r.creep_force_long_N, r.creep_force_lat_N]))
            # first order: F = F_inf + c / n  ->  F_inf = (n2 F2 - n1 F1) / (n2 - n1)
            limits.append((fine * f[1] - coarse * f[0]) / (fine - coarse))
        ref = limits[0]
        ref_error = _creep_error(*limits[1], ref, mu_n)
        for model in RUNG_MODELS:
            for label, options in RESOLUTIONS[model]:
                if quick and model in QUICK_RESOLUTIONS and label not in QUICK_RESOLUTIONS[model]:
                    continue
                start = time.perf_counter()
                r = get_model(model).solve(
                    geometry, creepage, material, normal_force_N=SWEEP_NORMAL_FORCE_N, options=options or None
                )
                wall = time.perf_counter() - start
                ok = r.success or r.status == "beyond-friction-limit"
                err = _creep_error(r.creep_force_long_N, r.creep_force_lat_N, ref, mu_n) if ok else None
                rows.append(
                    {
                        "case": point["name"],
                        "source": f"bem-richardson-48-96 (own error {ref_error:.2g})",
                        "model": model,
                        "resolution": label,
                        "status": "ok" if ok else r.status,
                        "wall_time_s": wall,
                        "n_patches": 1,
                        "normal_force_N": r.normal_force_N,
                        "creep_force_long_N": r.creep_force_long_N,
                        "creep_force_lat_N": r.creep_force_lat_N,
                        "err_creep_force": err,
                        "error": err,
                        "message": r.message,
                    }
                )
        if progress is not None:
            progress(i + 1, len(points), point["name"])
    return rows, features


def read_bench_csv(path) -> list[dict]:
    """Rows of a bench CSV (``comparisons.bench.write_bench``), numbers as strings ('' for None)."""
    import csv

    with open(path, encoding="utf-8", newline="") as handle:
        return list(csv.DictReader(handle))


def _git(*args) -> str:
    try:
        out = subprocess.run(["git", *args], capture_output=True, text=True, check=True, cwd=Path(__file__).parent)
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def bench_identity(csv_path, json_path=None) -> dict:
    """Identity of a bench run: the CSV's sha256, the commit and date that last changed it, its machine line."""
    import json

    csv_path = Path(csv_path)
    ident = {
        "csv": str(csv_path),
        "sha256": hashlib.sha256(csv_path.read_bytes()).hexdigest(),
        "commit": _git("log", "-1", "--format=%H", "--", str(csv_path.resolve())),
        "date": _git("log", "-1", "--format=%cI", "--", str(csv_path.resolve())),
    }
    json_path = Path(json_path) if json_path else csv_path.with_suffix(".json")
    if json_path.exists():
        summary = json.loads(json_path.read_text(encoding="utf-8"))
        ident["machine"] = summary.get("machine")
        ident["quick"] = summary.get("quick")
        ident["wall_time_s"] = summary.get("wall_time_s")
    ident["command"] = "wheelrail bench --quick" if ident.get("quick") else "wheelrail bench"
    return ident


def derive(bench_rows, named_features: dict, sweep_rows, sweep_features: dict, levels=LEVELS) -> dict:
    """Thresholds from bench rows and sweep rows with the features of their cases."""
    feats = {**named_features, **sweep_features}
    derived = derive_thresholds([*bench_rows, *sweep_rows], feats, levels)
    derived["features"] = list(FEATURES)
    derived["case_features"] = {k: feats[k] for k in sorted(feats)}
    return derived


def this_run_identity(command: str) -> dict:
    """Date, commit and machine of the current process (the sweep and the derivation)."""
    from comparisons.bench import machine

    dirty = _git("status", "--porcelain", "--untracked-files=no")
    return {
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "commit": _git("rev-parse", "HEAD") + (" (with uncommitted changes)" if dirty not in ("", "unknown") else ""),
        "machine": machine(),
        "command": command,
    }


def thresholds_document(bench_csv=None, quick: bool = False, progress=None, command: str = "") -> dict:
    """The thresholds file's content: from ``bench_csv`` (a bench run's CSV) or, when None, from a bench of the
    tangential rungs run now (``quick``: the quick bench's grids), plus the sweep run now.
    """
    from comparisons.bench import run_bench
    from wheelrail.named_cases import load_named_cases

    cases = load_named_cases()
    start = time.perf_counter()
    if bench_csv is not None:
        bench_rows = read_bench_csv(bench_csv)
        bench_source = bench_identity(bench_csv)
    else:
        runs = run_bench(cases, RUNG_MODELS, quick=quick)
        bench_rows = [r.row() for r in runs]
        bench_source = {
            **this_run_identity(f"comparisons.bench.run_bench(all named cases, {RUNG_MODELS}, quick={quick})"),
            "in_process": True,
        }
    with_rungs = {row["case"] for row in bench_rows if row["model"] in RUNG_MODELS}
    named_features = {}
    for named in cases:
        if named.name in with_rungs:
            feats = case_features(named)
            if feats is not None:
                named_features[named.name] = feats
    sweep_rows, sweep_features = run_sweep(quick=quick, progress=progress)
    doc = {
        "about": "auto's feature thresholds per tolerance level and rung (rigid_dynamics.contact.auto); "
        "regenerate with benchmarks/derive_auto_thresholds.py",
        "derived": {**this_run_identity(command), "wall_time_s": time.perf_counter() - start},
        "sources": {
            "bench": {**bench_source, "cases": sorted(with_rungs)},
            "sweep": {
                "what": "creep points on the quadric R_long 0.46 m, R_lat 0.30 m, 10 kN, G 82 GPa, nu 0.28, mu 0.3 "
                "(comparisons.auto_thresholds); reference BEM Richardson limit of 48x48 / 96x96",
                "cases": sorted(sweep_features),
                "quick": quick,
                "max_reference_error": max(
                    float(r["source"].split("own error ")[1].rstrip(")"))
                    for r in sweep_rows
                    if "own error" in r["source"]
                ),
            },
        },
    }
    doc.update(derive(bench_rows, named_features, sweep_rows, sweep_features))
    keep = ("case", "model", "resolution", "status", "error", "wall_time_s")
    doc["bench_rows"] = [{k: r[k] for k in keep} for r in bench_rows if r["model"] in RUNG_MODELS]
    doc["sweep_rows"] = [
        {k: r[k] for k in ("case", "model", "resolution", "status", "error", "wall_time_s")} for r in sweep_rows
    ]
    return doc
