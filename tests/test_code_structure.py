"""The floor plan of the numeric core, checked statically (regression of the code's structure, not physics).

* No import loop inside ``rigid_dynamics``: every ``import`` and ``from ... import`` statement, at module level or
  inside a function, is an edge (``from pkg import name`` to ``pkg.name`` when that is a module, else to ``pkg``;
  the implicit import of a package's ``__init__`` by its submodules is not an edge); the graph has no cycle.
* No function in ``rigid_dynamics`` with more than 12 parameters (records instead of positionals; ``self`` and
  ``cls`` not counted), and no file in ``rigid_dynamics/wheelset`` over 700 lines.
* No numbered row access in the compiled kernels (:func:`_numbered_access`'s rule).
* The named rows, columns and codes of ``wheelset/layout.py`` follow their tuples of names (the state.py pattern).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "rigid_dynamics"
MAX_PARAMETERS = 12
MAX_LINES = 700


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The rigid_dynamics modules that ``name`` imports anywhere in its file."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            targets = []
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                targets.append(sub if sub in modules else base)
        else:
            continue
        found.update(t for t in targets if t in modules and t != name)
    return found


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_loop_in_rigid_dynamics():
    modules = _modules()
    graph = {name: _imports(name, path, modules) for name, path in modules.items()}
    assert _cycles(graph) == []


def test_the_loop_detector_finds_a_loop():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


LONG_SIGNATURES_ALLOWED: dict[str, set[str]] = {}
"""Functions allowed more than MAX_PARAMETERS parameters, by file: none."""


def _parameter_count(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = node.args
    n = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) + (a.kwarg is not None)
    first = (a.posonlyargs + a.args)[:1]
    return n - 1 if first and first[0].arg in ("self", "cls") else n


def _long_signatures(path: Path):
    allowed = LONG_SIGNATURES_ALLOWED.get(str(path.relative_to(ROOT)), set())
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name not in allowed:
            n = _parameter_count(node)
            if n > MAX_PARAMETERS:
                yield f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({n} parameters)"


def test_rigid_dynamics_functions_take_at_most_12_parameters():
    found = [hit for path in sorted(PACKAGE.rglob("*.py")) for hit in _long_signatures(path)]
    assert found == []


def test_the_signature_check_counts_parameters():
    tree = ast.parse("def f(a, b, *c, d, **e): pass\nclass K:\n    def m(self, a): pass\n")
    counts = {n.name: _parameter_count(n) for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)}
    assert counts == {"f": 5, "m": 1}


KERNEL_FILES = (
    *sorted((PACKAGE / "wheelset").glob("compiled_*.py")),
    PACKAGE / "wheelset" / "auto_reuse.py",
    *sorted((PACKAGE / "contact").glob("_*_kernels.py")),
    PACKAGE / "contact" / "fastrip.py",
    PACKAGE / "contact" / "kpec.py",
)
"""The files of the compiled kernels whose indexing :func:`_numbered_access` checks."""

NAMED_ARRAYS = frozenset(
    {"y", "y_new", "states", "rec", "recs", "cg", "g", "sc", "work", "table", "geo", "cand", "mem", "sp",
     "f3", "f4", "box"}
)  # fmt: skip
"""Arrays of the wheelset's compiled files whose every row or column has a name (the state vector, layout.py's
patch record, candidate geometry, scratch and table rows, compiled_search's candidates, memory and parameters, the
side forces, a grid's box): no integer literal indexes them."""


def _literal_indices(node: ast.Subscript) -> list[int]:
    """The integer literals among a subscript's indices and slice bounds (-1 for a negative literal)."""
    parts = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
    bounds = []
    for part in parts:
        bounds.extend((part.lower, part.upper, part.step) if isinstance(part, ast.Slice) else (part,))
    found = []
    for b in bounds:
        if isinstance(b, ast.UnaryOp) and isinstance(b.op, ast.USub):
            b, sign = b.operand, -1
        else:
            sign = 1
        if isinstance(b, ast.Constant) and type(b.value) is int:
            found.append(sign * b.value)
    return found


def _compiled(node) -> bool:
    return any("jit" in ast.unparse(d) for d in node.decorator_list)


def _numbered_access(source: str, wheelset: bool) -> list[str]:
    """Numbered row access in the compiled functions of ``source``.

    The rule: inside a numba-compiled function an integer literal may index only

    * a vector's x, y, z, a 3 x 3 matrix's rows and columns, a range's (low, high), a first row: the literals 0, 1
      and 2, and -1 for the last element; a larger literal is a position with a meaning that has a name (a
      layout.py constant, a record field, a row named where the array is made);
    * and in the wheelset's compiled files, none of the :data:`NAMED_ARRAYS` (the state vector and the layout's
      records), whose every position is named however small.

    ``.shape[k]`` is the array's k-th dimension, not a row, and is left alone.
    """
    hits = []
    for func in ast.walk(ast.parse(source)):
        if not (isinstance(func, ast.FunctionDef) and _compiled(func)):
            continue
        for node in ast.walk(func):
            if not isinstance(node, ast.Subscript):
                continue
            if isinstance(node.value, ast.Attribute) and node.value.attr == "shape":
                continue
            literals = _literal_indices(node)
            named = wheelset and isinstance(node.value, ast.Name) and node.value.id in NAMED_ARRAYS
            if any(k > 2 or k < -1 for k in literals) or (literals and named):
                hits.append(f"{func.name}:{node.lineno} {ast.unparse(node)}")
    return hits


def test_no_numbered_row_access_in_the_kernels():
    found = {
        str(path.relative_to(ROOT)): hits
        for path in KERNEL_FILES
        if (hits := _numbered_access(path.read_text(), path.parent.name == "wheelset"))
    }
    assert found == {}


def test_the_numbered_access_rule_finds_numbered_rows():
    source = (
        "from numba import njit\n"
        "@njit\n"
        "def k(rec, g, sc, v, w, c):\n"
        "    a = rec[c, 7] + g[10] + sc[16] + w[3:5] + v[-2]\n"
        "    b = v[0] + v[2] + w[-1] + rec[c, NORMAL_FORCE] + g[G_LEVER + 1] + v.shape[3]\n"
        "    return a + b + g[0]\n"
        "def python_side(rec):\n"
        "    return rec[0, 7]\n"
    )
    numbered = {"rec[c, 7]", "g[10]", "sc[16]", "w[3:5]", "v[-2]"}
    assert {h.split(" ", 1)[1] for h in _numbered_access(source, wheelset=True)} == numbered | {"g[0]"}
    assert {h.split(" ", 1)[1] for h in _numbered_access(source, wheelset=False)} == numbered


def test_wheelset_files_at_most_700_lines():
    long = {
        str(p.relative_to(ROOT)): n
        for p in sorted((PACKAGE / "wheelset").rglob("*.py"))
        if (n := len(p.read_text().splitlines())) > MAX_LINES
    }
    assert long == {}


def _stem(name: str) -> str:
    """A field's name without its unit, upper case: the name of its constant."""
    upper = name.upper()
    for unit in ("_1_PER_M", "_NM", "_RAD", "_M2", "_PA", "_CODE", "_M", "_N"):
        if upper.endswith(unit):
            return upper.removesuffix(unit)
    return upper


def test_layout_constants_follow_their_names():
    from rigid_dynamics.wheelset import compiled_laws, layout

    for k, name in enumerate(layout.PATCH_FIELDS):
        assert getattr(layout, _stem(name)) == k, name
    assert layout.N_PATCH == len(layout.PATCH_FIELDS)
    for k, name in enumerate(layout.AUTO_PATCH_FIELDS[:4]):
        assert getattr(layout, name.upper()) == layout.N_PATCH + k, name
    assert layout.AUTO_FEATURES == layout.N_PATCH + 4
    assert layout.AUTO_PATCH_FIELDS[4:] == tuple(f"auto_{f}" for f in layout.AUTO_FEATURE_NAMES)
    assert layout.FORMED == len(layout.PATCH_FIELDS) + len(layout.AUTO_PATCH_FIELDS)
    assert layout.FORMED_PATCH_FIELDS == tuple(f"formed_{n}" for n in layout.PATCH_FIELDS[: layout.N_FORMED])
    assert layout.N_FIELDS == layout.FORMED + layout.N_FORMED
    assert layout.N_FORMED == 12  # compiled_rhs._external's objmode type UniTuple(float64, 12) spells it out

    geometry = {
        "approach_m": "G_APPROACH", "lever_x_m": "G_LEVER", "normal_x": "G_NORMAL",
        "curvature_long_1_per_m": "G_CURVATURE_LONG", "curvature_lat_1_per_m": "G_CURVATURE_LAT",
        "rolling_radius_m": "G_ROLLING_RADIUS", "wheel_lateral_m": "G_WHEEL_LATERAL",
        "contact_angle_rad": "G_CONTACT_ANGLE",
    }  # fmt: skip
    for name, const in geometry.items():
        assert getattr(layout, const) == layout.GEOMETRY_FIELDS.index(name), name
    for axis, k in (("y", 1), ("z", 2)):
        assert layout.GEOMETRY_FIELDS.index(f"lever_{axis}_m") == layout.G_LEVER + k
        assert layout.GEOMETRY_FIELDS.index(f"normal_{axis}") == layout.G_NORMAL + k
    assert layout.N_GEO == len(layout.GEOMETRY_FIELDS)

    for k, name in enumerate(layout.TABLE_FIELDS):
        assert getattr(layout, "T_" + _stem(name)) == k, name
    assert layout.N_TABLE_ROWS == len(layout.TABLE_FIELDS)

    for k, name in enumerate(layout.SECTION_FIELDS):
        assert getattr(layout, "I_" + _stem(name)) == k, name
    assert layout.N_SECTION == len(layout.SECTION_FIELDS)

    single = [n for n in layout.SCRATCH_ROWS if not n.startswith(("side_force_", "rotation_row_"))]
    for name in single:
        assert getattr(layout, "S_" + name.upper()) == layout.SCRATCH_ROWS.index(name), name
    assert layout.SCRATCH_ROWS.index("side_force_left") == layout.S_SIDE_FORCE
    assert layout.SCRATCH_ROWS.index("rotation_row_0") == layout.S_ROTATION
    assert layout.N_SCRATCH == len(layout.SCRATCH_ROWS)

    for name, code in compiled_laws.LAW_CODES.items():
        assert getattr(compiled_laws, "LAW_" + name.upper().replace("-", "_")) == code
    assert len(set(compiled_laws.LAW_CODES.values()) | {compiled_laws.LAW_CALLBACK}) == len(compiled_laws.LAW_CODES) + 1
    assert sorted(layout.STATUS) == list(range(len(layout.STATUS)))
    assert layout.status_name(layout.OK) == "ok" and layout.status_name(layout.UNDERFLOW) == "step-size-underflow"
    assert layout.AUTO_RUNG_NAMES == ("linear", "vermeulen_johnson", "fastsim")
    assert (layout.AUTO_LINEAR, layout.AUTO_VERMEULEN_JOHNSON, layout.AUTO_FASTSIM) == (0, 1, 2)
    # auto's rung r runs the law LAW_LINEAR + r (compiled_laws._law)
    assert compiled_laws.LAW_LINEAR + layout.AUTO_FASTSIM == compiled_laws.LAW_FASTSIM


def test_contact_package_auto_rungs_match_the_compiled_order():
    from rigid_dynamics.contact.auto import AUTO_RUNGS, FEATURES
    from rigid_dynamics.wheelset import layout

    assert [r.replace("-", "_") for r in AUTO_RUNGS[: len(layout.AUTO_RUNG_NAMES)]] == list(layout.AUTO_RUNG_NAMES)
    assert tuple(FEATURES) == layout.AUTO_FEATURE_NAMES


WALK_HEADER = "The walk from a scene's `contact_model` to the compiled law"


def _readme_walk() -> tuple[str, list[list[str]]]:
    """The README's walk: its header line and, per numbered item, the backticked names in it (first: its file)."""
    text = (ROOT / "README.md").read_text()
    assert WALK_HEADER in text, "README.md's development section lost the walk"
    header, rest = text.split(WALK_HEADER, 1)[1].split("\n", 1)
    block = rest.strip("\n").split("\n\n", 1)[0]
    items = re.split(r"^\d+\. ", block, flags=re.M)[1:]
    return header, [re.findall(r"`([^`]+)`", " ".join(item.split())) for item in items]


def test_readme_walk_names_files_that_exist():
    """Regression of the README against the code: the walk from a scene's ``contact_model`` to the compiled law
    names at most 8 files (its header says how many), one per step, each a file of ``rigid_dynamics``; every
    identifier in the code it quotes (``law_code(model)``, ``compiled_laws._kpec_law``) is defined or used in one of
    the files it names (or in the scene reader it names)."""
    header, items = _readme_walk()
    files = [names[0] for names in items]
    assert all(f.endswith(".py") for f in files), files
    assert len(set(files)) == len(files) <= 8
    assert f"{len(files)} files" in header
    sources = {f: (PACKAGE / f).read_text() for f in files if (PACKAGE / f).is_file()}
    assert sorted(sources) == sorted(files), "a file the walk names does not exist"
    quoted = {n for names in items for n in names[1:] if n.endswith(".py")}
    for path in quoted:
        assert (PACKAGE / path).is_file() or (ROOT / path).is_file(), path
    text = "\n".join(sources.values()) + (ROOT / "wheelrail" / "scenes.py").read_text()
    quoted_code = [re.sub(r'"[^"]*"', "", n) for names in items for n in names[1:] if not n.endswith(".py")]
    identifiers = {word for code in quoted_code for word in re.findall(r"[A-Za-z_]\w*", code)}
    assert len(identifiers) > 20
    missing = sorted(n for n in identifiers if not re.search(rf"\b{n}\b", text))
    assert missing == []


def test_every_scene_contact_model_resolves_through_the_walk():
    """Regression of the README against the code: each shipped scene's ``contact_model`` resolves through the files
    of the walk: its class lives in a walk file, it declares a compiled law (not the callback), and the law's scalar
    kernel (contact/<law>.py, which compiled_laws.py imports) is among the kernels the walk's last step names."""
    import inspect
    import tomllib

    from rigid_dynamics.contact.registry import get_model
    from rigid_dynamics.wheelset.compiled_laws import LAW_CALLBACK, LAW_CODES
    from rigid_dynamics.wheelset.compiled_records import law_code

    _, items = _readme_walk()
    files = {names[0] for names in items}
    kernels = {n for n in items[-1] if n.endswith(".py")}
    laws_source = (PACKAGE / "wheelset" / "compiled_laws.py").read_text()
    scenes = sorted((ROOT / "wheelrail" / "scenes").glob("*.toml"))
    assert scenes
    for path in scenes:
        name = tomllib.loads(path.read_text())["contact_model"]
        model = get_model(name)
        module_file = Path(inspect.getsourcefile(type(model))).resolve().relative_to(PACKAGE).as_posix()
        assert module_file in files, (path.name, name, module_file)
        code = law_code(model)
        assert code != LAW_CALLBACK and LAW_CODES[model.compiled_law] == code, (path.name, name)
        if model.compiled_law != "hertz":  # hertz has no creep force: the walk ends in compiled_laws.py
            kernel = f"contact/{model.compiled_law.replace('-', '_')}.py"
            assert kernel in kernels, (path.name, kernel)
            assert f"from rigid_dynamics.{kernel[:-3].replace('/', '.')} import" in laws_source, kernel
