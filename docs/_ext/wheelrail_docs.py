"""Sphinx extension of wheelrail's documentation: the pages generated from the repository at build time.

- ``examples/*.py`` (jupytext light-format notebooks, run by ``tests/test_examples.py``) are converted into
  sphinx-gallery scripts in ``docs/_gallery_src/`` before sphinx-gallery reads them: the first Markdown cell
  becomes the docstring (title and introduction), every later Markdown cell a ``# %%`` text block, every code
  cell a code block. The code is copied unchanged; the Markdown is turned into the little reStructuredText that
  sphinx-gallery's text blocks take (headings, inline code, links). The examples are not executed here.
- ``benchmarks/results/*.md`` (and ``benchmarks/results/*/*.md``) are collected into ``docs/results.md``, one
  section per file, their headings moved one level down and image paths made relative to ``docs/``.
- The registered contact models and their declared options (what ``wheelrail models`` prints) are written to
  ``docs/_generated/models.md`` for the contact-models page, and ``wheelrail``'s public names (``wr.api()``)
  to ``docs/_generated/facade.rst`` for the API page.

Both run on ``builder-inited`` ahead of sphinx-gallery, so the generated files exist before any page is read.
The generated files are not part of the repository (``docs/.gitignore``).
"""

from __future__ import annotations

import re
from pathlib import Path

from rigid_dynamics.files import write_text

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent
EXAMPLES = ROOT / "examples"
GALLERY_SOURCE = DOCS / "_gallery_src"
RESULTS = ROOT / "benchmarks" / "results"
RESULTS_PAGE = DOCS / "results.md"
GENERATED = DOCS / "_generated"

GALLERY_HEADER = """\
Examples
========

Literate scripts from ``examples/`` (jupytext light format: open them as notebooks with jupytext, or run them
with python). Each asserts its own physics against a reference (Hertz's closed forms, saturation at mu N,
CONTACT's published A-2.2 solution, Johnson's subsurface shear, ...), and ``tests/test_examples.py`` runs every
one of them with small settings, so none can drift. They are shown here without being run.
"""

_UNDERLINE = {1: "=", 2: "-", 3: "~", 4: "^"}
_HEADING = re.compile(r"^(#{1,4})\s+(.*?)\s*#*\s*$")
_CODE_SPAN = re.compile(r"(?<!`)`([^`]+?)`(?!`)", flags=re.S)
_LINK = re.compile(r"(?<!!)\[([^\]]+)\]\(([^)\s]+)\)")


def markdown_to_rst(text: str) -> str:
    """The Markdown of the examples' text cells as reStructuredText: ATX headings, inline code, links.

    Paragraphs, lists, emphasis and strong emphasis read the same in both; anything else the build's
    warnings-as-errors reports, so a new construct in an example fails the docs test instead of rendering wrong.
    """
    text = _CODE_SPAN.sub(lambda m: "``" + m.group(1).replace("\n", " ") + "``", text)
    text = _LINK.sub(lambda m: f"`{m.group(1)} <{m.group(2)}>`__", text)
    lines = []
    for line in text.splitlines():
        match = _HEADING.match(line)
        if match:
            title = match.group(2)
            lines += [title, _UNDERLINE[len(match.group(1))] * max(len(title), 3), ""]
        else:
            lines.append(line)
    return "\n".join(lines)


def example_to_gallery_script(path: Path) -> str:
    """One jupytext light-format example as a sphinx-gallery script (module docstring)."""
    import jupytext

    notebook = jupytext.read(path, fmt="py:light")
    cells = list(notebook.cells)
    if not cells or cells[0].cell_type != "markdown":
        raise ValueError(f"{path}: the first cell must be Markdown with the example's title ('# Title')")
    docstring = markdown_to_rst(cells[0].source).strip()
    if '"""' in docstring:
        raise ValueError(f'{path}: the first Markdown cell must not contain """')
    parts = [f'r"""\n{docstring}\n"""\n']
    for cell in cells[1:]:
        source = cell.source.strip("\n")
        if not source.strip():
            continue
        if cell.cell_type == "markdown":
            text = markdown_to_rst(source)
            parts.append("# %%\n" + "\n".join(("# " + line).rstrip() for line in text.splitlines()) + "\n")
        else:
            parts.append("# %%\n" + source + "\n")
    return "\n".join(parts)


def write_gallery_sources(app=None) -> None:
    """Convert every ``examples/*.py`` into ``docs/_gallery_src/`` (stale files there are removed)."""
    GALLERY_SOURCE.mkdir(exist_ok=True)
    wanted = {}
    for path in sorted(EXAMPLES.glob("*.py")):
        wanted[path.name] = example_to_gallery_script(path)
    wanted["README.rst"] = GALLERY_HEADER
    for old in GALLERY_SOURCE.iterdir():
        if old.is_file() and old.name not in wanted:
            old.unlink()
    for name, text in wanted.items():
        _write_if_changed(GALLERY_SOURCE / name, text)


def _shift_headings(text: str, by: int) -> str:
    """Markdown ATX headings moved ``by`` levels down, outside fenced code."""
    out, fenced = [], False
    for line in text.splitlines():
        if line.lstrip().startswith(("```", "~~~")):
            fenced = not fenced
        if not fenced and re.match(r"^#{1,6}\s", line):
            line = "#" * by + line
        out.append(line)
    return "\n".join(out)


def _relink_images(text: str, source: Path) -> str:
    """Relative image paths of a results file, made relative to ``docs/``."""

    def relink(match):
        target = match.group(2)
        if re.match(r"^[a-z]+://", target) or target.startswith("/"):
            return match.group(0)
        resolved = (source.parent / target).resolve()
        return f"![{match.group(1)}](../{resolved.relative_to(ROOT).as_posix()})"

    return re.sub(r"!\[([^\]]*)\]\(([^)\s]+)\)", relink, text)


def results_files() -> list[Path]:
    """The recorded results: ``benchmarks/results/*.md`` then ``benchmarks/results/*/*.md``, sorted."""
    return sorted(RESULTS.glob("*.md")) + sorted(RESULTS.glob("*/*.md"))


def write_results_page(app=None) -> None:
    """Write ``docs/results.md`` from the recorded results (images relinked per file)."""
    _write_if_changed(
        RESULTS_PAGE, results_page([(path, path.read_text(encoding="utf-8")) for path in results_files()])
    )


def results_page(pieces: list[tuple[Path, str]]) -> str:
    """One Markdown page with one section per (path, text) of a results file: its text, headings one level down."""
    parts = [
        "# Recorded results",
        "",
        "Generated when the documentation is built, from every Markdown file in `benchmarks/results/`, one "
        "section per file, as the benchmark scripts in `benchmarks/` wrote them (each file names its script, "
        "its machine and its load). Rerun a script to update its section; nothing here is copied by hand.",
        "",
    ]
    for path, raw in pieces:
        name = path.relative_to(ROOT).as_posix()
        text = _relink_images(raw.strip(), path)
        first, _, rest = text.partition("\n")
        if first.startswith("# "):
            parts += ["#" + first, "", f"*From `{name}`.*", "", _shift_headings(rest.strip(), 1)]
        else:
            parts += [f"## {name}", "", _shift_headings(text, 1)]
        parts.append("")
    return "\n".join(parts)


def models_listing() -> str:
    """The registered contact models with their options, as ``wheelrail models`` lists them (Markdown)."""
    from rigid_dynamics.contact.registry import MODELS, model_options

    parts = []
    for name, (target, description) in MODELS.items():
        parts += [f"### `{name}`", "", f"{description} (`{target}`).", ""]
        options = model_options(name)
        if options:
            parts += ["Options:", ""] + [f"- {option.describe()}".replace("*", "\\*") for option in options.values()]
        else:
            parts.append("No options.")
        parts.append("")
    return "\n".join(parts)


def facade_listing() -> str:
    """``wheelrail``'s public names (``wr.api()``) as an rST list table, each linked to where it is defined."""
    import importlib

    import wheelrail

    rows = [
        ".. list-table::",
        "   :header-rows: 1",
        "   :widths: 25 45 30",
        "",
        "   * - name",
        "     - what",
        "     - defined in",
    ]
    for name, (module_name, attr, what) in wheelrail._API.items():
        obj = getattr(importlib.import_module(module_name), attr)
        home = getattr(obj, "__module__", None) if callable(obj) else None
        target = f":py:obj:`{home}.{obj.__qualname__}`" if home else f":py:mod:`{module_name}`"
        rows += [f"   * - ``wr.{name}``", f"     - {what}", f"     - {target}"]
    return "\n".join(rows) + "\n"


def write_generated_includes(app=None) -> None:
    """Write the listings that pages include from ``docs/_generated/`` (model registry, ``wheelrail``'s names)."""
    GENERATED.mkdir(exist_ok=True)
    _write_if_changed(GENERATED / "models.md", models_listing())
    _write_if_changed(GENERATED / "facade.rst", facade_listing())


def _write_if_changed(path: Path, text: str) -> None:
    """Write only when the text changed, so that Sphinx's incremental build sees unchanged files as unchanged."""
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        write_text(path, text)


# Docstrings written as plain text whose formula lines are not valid reStructuredText (indented continuation
# lines, |x| for a norm): their description is shown verbatim as a literal block instead of failing the build.
# Remove a name once its docstring reads as reStructuredText; a new docstring with such lines fails the docs test.
PLAIN_TEXT_DOCSTRINGS = frozenset(
    {
        "rigid_dynamics.geometry",
        "rigid_dynamics.geometry.irregularities.WheelFlat",
        "rigid_dynamics.geometry.measured",
        "rigid_dynamics.kinematics.euler_accelerations",
        "rigid_dynamics.wheelset.checks.check_scene",
        "rigid_dynamics.wheelset.equations",
        "rigid_dynamics.wheelset.equations.WheelsetModel.kinetic_energy_J",
    }
)
_GOOGLE_SECTION = re.compile(
    r"^\s*(Args|Arguments|Parameters|Keyword Args|Other Parameters|Returns?|Yields?|Raises|Attributes|Examples?"
    r"|Notes?|References|See Also|Warnings?|Todo|Methods):\s*$"
)


def plain_text_docstring(app, what, name, obj, options, lines):
    """Show the description of a :data:`PLAIN_TEXT_DOCSTRINGS` docstring verbatim (before napoleon reads it).

    The Google-style sections (``Args:``, ``Returns:``, ...) stay as they are for napoleon; the lines before
    the first of them become a literal block.
    """
    if name not in PLAIN_TEXT_DOCSTRINGS:
        return
    start = 0
    end = next((i for i, line in enumerate(lines) if _GOOGLE_SECTION.match(line)), len(lines))
    body = lines[start:end]
    while body and not body[-1].strip():
        body.pop()
    if body:
        lines[start:end] = ["::", ""] + [("    " + line).rstrip() for line in body] + [""]


def escape_bars(app, what, name, obj, options, lines):
    """``|x|`` in a docstring is a norm or an absolute value (plain-text formulas), never an rST substitution.

    Escapes every ``|`` outside literal blocks (a paragraph ending in ``::`` and the lines indented under it)
    and inline literals.
    """
    literal_indent = None
    expect_literal, base_indent = False, 0
    for i, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if not line.strip() or indent > literal_indent:
                continue
            literal_indent = None
        if expect_literal and line.strip():
            expect_literal = False
            if indent > base_indent:
                literal_indent = base_indent
                continue
        if line.rstrip().endswith("::"):
            expect_literal, base_indent = True, indent
        parts = re.split(r"(``.*?``)", line)
        lines[i] = "".join(part if part.startswith("``") else part.replace("|", "\\|") for part in parts)


def skip_tuple_fields(app, what, name, obj, skip, options):
    """Skip a NamedTuple's field accessors ("Alias for field number k"): the class docstring's Attributes say it."""
    if type(obj).__name__ == "_tuplegetter":
        return True
    return None


def setup(app):
    """Register the generators ahead of sphinx-gallery (priority below its default 500) and the docstring hooks."""
    app.connect("autodoc-process-docstring", plain_text_docstring, priority=400)
    app.connect("autodoc-process-docstring", escape_bars, priority=410)
    app.connect("autodoc-skip-member", skip_tuple_fields)
    app.connect("builder-inited", write_gallery_sources, priority=100)
    app.connect("builder-inited", write_results_page, priority=100)
    app.connect("builder-inited", write_generated_includes, priority=100)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
