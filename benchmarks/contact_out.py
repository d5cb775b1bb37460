"""Read the printed results of CONTACT's ``.out`` files (module 1 wheel-rail and module 3 basic cases) into rows.

CONTACT (E.A.H. Vollebregt, J.J. Kalker; Vtech CMCC; Apache-2.0) prints each case as blocks of a header line of
column names followed by a line of values (``TOTAL FORCES ON RAIL``, ``KINEMATIC CONSTANTS``, ...). This reader,
written for wheelrail, pairs such lines by their names; it holds no code of CONTACT. Used by
``benchmarks/make_contact_friction_references.py`` (which writes the CSV reference data under
``tests/data/contact_friction``) and ``benchmarks/bench_vs_contact.py``; nothing in the package imports it.

A case is a dict of its wheelset values (module 1) or its single patch (module 3); ``patches`` holds one dict per
contact patch with its reference point, friction, creepages, forces, approach, max pressure and element counts.
Names are CONTACT's upper-case column names (``FN``, ``FX``, ``FS`` or ``FY``, ``PMAX``, ``CKSI``, ...).
"""

from __future__ import annotations

import re
from pathlib import Path

_NUM = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+|[-+]\d{2,3})?$")


def _number(token: str) -> float | None:
    """A Fortran-printed number (``1.000E+04``, ``10000.``, ``-0.2480``, ``-0.1783+268``) or None."""
    if not _NUM.match(token):
        return None
    if re.search(r"\d[-+]\d{2,3}$", token) and "E" not in token.upper():
        token = re.sub(r"([-+]\d{2,3})$", r"E\1", token)
    return float(token)


def _pairs(lines: list[str]) -> dict[str, float]:
    """Every header line of names followed by a line of as many numbers, as name -> value."""
    out: dict[str, float] = {}
    for head, vals in zip(lines, lines[1:], strict=False):
        names = head.split()
        values = [_number(t) for t in vals.split()]
        if not names or len(names) != len(values) or any(v is None for v in values):
            continue
        if any(_number(n) is not None for n in names):
            continue
        for name, value in zip(names, values, strict=True):
            out.setdefault(name, value)
    return out


def read_out(path: str | Path) -> list[dict]:
    """The cases of a CONTACT ``.out`` file, in order, each with its ``case`` number and ``patches``."""
    text = Path(path).read_text(errors="replace")
    cases = re.split(r"^ Case +(\d+)\s*$", text, flags=re.M)[1:]
    numbers = cases[0::2]
    bodies = cases[1::2]
    rows = []
    for num, body in zip(numbers, bodies, strict=True):
        if "DATA FOR CONTACT PATCH" in body:
            head, *patch_texts = re.split(r"----- DATA FOR CONTACT PATCH +\d+ -----", body)
        else:
            head, patch_texts = body, [body]
        case = _pairs(head.splitlines())
        case["case"] = int(num)
        m = re.search(r"(\d+) CONTACT PATCH", head)
        case["n_patches"] = int(m.group(1)) if m else len(patch_texts)
        patches = []
        for pt in patch_texts:
            lines = pt.split("\n CURVED REFERENCE SURFACE")[0].splitlines()
            p = _pairs(lines)
            fric = re.search(r"FRICTION LAW PARAMETERS\n(.*?)\n\n", pt, flags=re.S)
            if fric:
                body_lines = fric.group(1).splitlines()
                names = body_lines[0].split()
                rows_f = [ln.split() for ln in body_lines[1:] if ln.split() and _number(ln.split()[0]) is not None]
                if names and names[0] == "IY" and rows_f:  # per-row friction (conformal patches): keep range
                    vals = [float(r[1]) for r in rows_f]
                    p["FSTAT_MIN"], p["FSTAT_MAX"] = min(vals), max(vals)
            patches.append(p)
        case["patches"] = patches
        rows.append(case)
    return rows
