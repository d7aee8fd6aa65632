"""Sphinx helpers of the ddg-strips manual (docs/conf.py loads this as the extension `ddg_docs`).

- `.. command-help:: python -m ddg simulate`: the command's `--help`, run at build time with the
  building interpreter, as a literal block (the CLI pages never drift from the parsers);
- docstrings that are not valid reStructuredText (the project's docstrings are prose written for
  `help()`, not for Sphinx) are shown as preformatted text instead of making the build warn; the
  objects so shown are listed in BUILD/_docstrings_as_text.txt and in the build log (verbose);
- sphinx-gallery on examples/ as it is: the gallery's header comes from docs/gallery_intro.txt when
  examples/ has no README.txt or README.rst (it has README.md, which Sphinx cannot parse); each
  example's page gets its first docstring line as its title (the scripts' docstrings have none), and
  its indented command lines are shown as code;
- ExampleArguments and OutputPictures, the gallery's `reset_argv` and image scraper: every example
  runs with `--out` in a temporary folder, and the PNG files it writes there are its pictures.
"""
from __future__ import annotations

import io
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive, directives, roles

DOCS = Path(__file__).resolve().parents[1]
GALLERY_INTRO = DOCS / "gallery_intro.txt"
AS_TEXT_FILE = "_docstrings_as_text.txt"


# ------------------------------------------------------------------------------- command-help
class CommandHelp(Directive):
    """`.. command-help:: python -m PACKAGE [SUBCOMMAND]`: PACKAGE's --help as a literal block.

    Run from the documented checkout with the building interpreter and COLUMNS=100; a command that
    fails is a build warning (the page then says so)."""
    required_arguments = 1
    final_argument_whitespace = True
    has_content = False

    def run(self):
        env = self.state.document.settings.env
        words = shlex.split(self.arguments[0])
        if words[:2] != ["python", "-m"] or len(words) < 3:
            raise self.error(f"command-help expects 'python -m PACKAGE ...', got {self.arguments[0]!r}")
        root = env.config.ddg_docs_root or str(DOCS.parent)
        path = os.pathsep.join(filter(None, (root, os.environ.get("PYTHONPATH"))))
        done = subprocess.run([sys.executable, *words[1:], "--help"], cwd=root, capture_output=True, text=True,
                              timeout=120, env={**os.environ, "COLUMNS": "100", "PYTHONPATH": path})
        if done.returncode != 0:
            message = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
            return [self.state.document.reporter.warning(
                f"{self.arguments[0]} --help failed (exit {done.returncode}): {message[0]}", line=self.lineno)]
        text = done.stdout.rstrip()
        block = nodes.literal_block(text, text)
        block["language"] = "text"
        return [block]


# --------------------------------------------------------------------- tables from the data
def _root(env) -> Path:
    return Path(env.config.ddg_docs_root or DOCS.parent)


def _fraction(value: float) -> str:
    """0.0833 -> "1/12", 0.4 -> "2/5" (the benchmark's scenes are simple fractions)."""
    from fractions import Fraction

    fraction = Fraction(value).limit_denominator(40)
    return str(fraction) if abs(float(fraction) - value) < 1e-3 * value else f"{value:g}"


def _with_bar(value, bar) -> str:
    """A CSV cell pair as the benchmark writes it (validation.benchmark.with_bar: "0.3511 ± 0.0012")."""
    from validation.benchmark import with_bar

    def number(cell):
        return None if cell in (None, "") else float(cell)

    return with_bar(number(value), number(bar))


class _TableDirective(Directive):
    """A list-table made from the repository's data at build time (never a stale copy)."""
    has_content = False

    def table(self, title: str, header: list[str], rows: list[list[str]], widths: str | None = None):
        from docutils.statemachine import StringList

        lines = [f".. list-table:: {title}", "   :header-rows: 1"]
        lines += ([f"   :widths: {widths}"] if widths else []) + [""]
        for row in [header] + rows:
            lines.append(f"   * - {row[0]}")
            lines += [f"     - {cell}" for cell in row[1:]]
        container = nodes.container()
        self.state.nested_parse(StringList(lines, source="ddg_docs"), self.content_offset, container)
        return container.children

    def missing(self, what: str):
        return [self.state.document.reporter.warning(f"{what} not found: the table is left out", line=self.lineno)]


class BenchmarkScenes(_TableDirective):
    """`.. benchmark-scenes::`: every scene of the benchmark (validation.score.load_benchmark) with its
    converged thresholds and error bars, the benchmark's version and data digest."""

    def run(self):
        env = self.state.document.settings.env
        root = _root(env)
        if str(root) not in sys.path:
            sys.path.insert(0, str(root))
        from validation.score import BENCHMARK_VERSION, benchmark_digest, benchmark_rows, load_benchmark

        scenes = load_benchmark(root / "data" / "fem_gold")
        if not scenes:
            return self.missing("data/fem_gold (the FEM mesh studies)")
        rows = [[f"``{r['scene']}``", _fraction(r["compression_ratio"]), _fraction(r["width_ratio"]),
                 f"{r['slenderness']:.0f}", _with_bar(r["dW1_over_L"], r["dW1_error_bar"]),
                 _with_bar(r["dW2_over_L"], r["dW2_error_bar"]), str(r["H_mid_points"]),
                 (r["dW1_meshes"] or "\u2013").replace("/", ", ")] for r in benchmark_rows(scenes)]
        title = (f"Benchmark {BENCHMARK_VERSION}: {len(scenes)} scenes, data digest "
                 f"{benchmark_digest(scenes)} (read from data/fem_gold when this page was built)")
        return self.table(title, ["scene", "dL/L", "W/L", "L/b", "dW1/L", "dW2/L", "H_mid points",
                                  "meshes (dW1)"], rows, "16 7 7 7 17 17 9 20")


class ThresholdTable(_TableDirective):
    """`.. threshold-table:: dW1` (or dW2): the converged threshold of every model on the paper's ten
    scenes, from data/benchmark/benchmark.csv (python -m validation benchmark)."""
    required_arguments = 1
    MODELS = (("fem", "FEM shell"), ("plate", "plate"), ("midedge", "mid-edge plate"), ("rod", "rod"),
              ("cross_section", "cross-section"))

    def run(self):
        import csv

        key = self.arguments[0]
        if key not in ("dW1", "dW2"):
            raise self.error(f"threshold-table takes dW1 or dW2, not {key!r}")
        path = _root(self.state.document.settings.env) / "data" / "benchmark" / "benchmark.csv"
        if not path.is_file():
            return self.missing("data/benchmark/benchmark.csv")
        with path.open(newline="") as f:
            data = list(csv.DictReader(f))
        rows = []
        for r in data:
            cells = [_fraction(float(r["compression_ratio"])), _fraction(float(r["width_ratio"])),
                     f"{float(r['width_squared_over_thickness_length']):.1f}"]
            cells += [_with_bar(r.get(f"{m}_{key}"), r.get(f"{m}_{key}_error_bar")) for m, _ in self.MODELS]
            paper = r.get(f"paper_{key}")
            cells.append(f"{float(paper):.4g}" if paper else "\u2013")
            rows.append(cells)
        header = ["dL/L", "W/L", "W²/(bL)"] + [f"{name} {key}/L" for _, name in self.MODELS] + [f"paper {key}/L"]
        return self.table(f"{key}/L: converged values \u00b1 error bars (data/benchmark/benchmark.csv)", header,
                          rows)


# ------------------------------------------------------------------------- docstring fallback
_IGNORED = ("Unknown interpreted text role", "Unknown directive type", "No role entry", "No directive entry",
            'Trying "', "Problem retrieving role entry", "Problem retrieving directive entry")


def rst_problems(text: str) -> list[str]:
    """The docutils warnings and errors of `text` parsed as a reStructuredText fragment (Sphinx's own
    roles and directives, which plain docutils does not know, are not counted)."""
    from docutils.core import publish_doctree
    from docutils.utils import Reporter

    stream = io.StringIO()
    settings = {"report_level": Reporter.WARNING_LEVEL, "halt_level": Reporter.SEVERE_LEVEL + 1,
                "warning_stream": stream, "file_insertion_enabled": False, "raw_enabled": False,
                "doctitle_xform": False, "sectsubtitle_xform": False}
    # docutils drops the default role after parsing a document: Sphinx's (default_role) is kept
    default = roles._roles.get("")
    try:
        tree = publish_doctree(text, settings_overrides=settings)
    except Exception as exc:   # docutils gave up: certainly not clean
        return [f"{type(exc).__name__}: {exc}"]
    finally:
        if default is not None:
            roles._roles[""] = default
    problems = []
    for match in re.finditer(r"^[^\n]*?:(\d+|): \((WARNING|ERROR|SEVERE)/\d\) (.*(?:\n(?![^\n]*\(\w+/\d\)).*)*)",
                             stream.getvalue(), re.MULTILINE):
        body = " ".join(match.group(3).split())
        if not any(key in body for key in _IGNORED):
            problems.append(f"line {match.group(1) or '?'}: {body[:160]}")
    # a section title inside a docstring cannot be placed in the page (an error in Sphinx, not docutils)
    if tree.next_node(nodes.section) is not None:
        problems.append("a section title (a line underlined with -, = or ~) inside the docstring")
    return problems


_LITERAL = re.compile(r"(``.*?``|(?<![`\w])`[^`]+`(?![`_]))")
_BAR = re.compile(r"(?<!\\)\|")
_STAR = re.compile(r"(?<!\\)\*")
_TRAILING_UNDERSCORE = re.compile(r"(?<=\w)_(?!\w)")
_ITEM = re.compile(r"^(\s*)([-*+]|\d+\.) \S")
_UNDERLINE = re.compile(r"^\s*([-=~^])\1{2,}\s*$")


def _escape_inline(line: str) -> str:
    """|x| (an absolute value), * (a product or a wildcard) and name_ (a name) as text."""
    item = _ITEM.match(line)
    head, line = (line[:item.end(2)], line[item.end(2):]) if item else ("", line)
    parts = _LITERAL.split(line)
    return head + "".join(part if k % 2 else
                          _TRAILING_UNDERSCORE.sub(r"\\_", _STAR.sub(r"\\*", _BAR.sub(r"\\|", part)))
                          for k, part in enumerate(parts))


def escape_prose(lines: list[str]) -> list[str]:
    """The project's docstrings, prose written for help(), as reStructuredText that says the same:

    - |x|, * and name_ are text (_escape_inline), except in ``literals`` and literal blocks;
    - a list that starts or ends without a blank line gets one;
    - lines indented under a paragraph (formulas, commands), with or without a blank line between,
      become a literal block;
    - a heading underlined with ---, === or ~~~ becomes a rubric (a docstring cannot hold sections).
    """
    out: list[str] = []
    block_indent = None    # inside a literal block opened by a line at this indent
    list_indent = None     # inside a list whose items start at this indent
    para_indent = None     # indent of the paragraph the previous line belongs to
    last_paragraph = None  # (indent, index in out of its last line) of the paragraph before a blank line
    k = 0
    while k < len(lines):
        line = lines[k]
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        previous_blank = not out or not out[-1].strip()
        if block_indent is not None:
            if not stripped or indent > block_indent:
                out.append(line)
                k += 1
                continue
            block_indent = None
            if not previous_blank:
                out.append("")
                previous_blank = True
        if not stripped:
            if para_indent is not None and not previous_blank:
                last_paragraph = (para_indent, len(out) - 1)
            out.append(line)
            para_indent = None
            k += 1
            continue
        if previous_blank and list_indent is None and last_paragraph is not None \
                and indent > last_paragraph[0] and not _ITEM.match(line):
            # an indented block after a paragraph (formulas, commands): a literal block
            at = last_paragraph[1]
            if not out[at].rstrip().endswith("::"):
                out[at] = out[at].rstrip() + (":" if out[at].rstrip().endswith(":") else " ::")
            block_indent = last_paragraph[0]
            last_paragraph = None
            out.append(line)
            k += 1
            continue
        last_paragraph = None
        following = lines[k + 1] if k + 1 < len(lines) else ""
        if _UNDERLINE.match(following) and len(following.strip()) >= 3 and not _UNDERLINE.match(line):
            if not previous_blank:
                out.append("")
            out += [" " * indent + ".. rubric:: " + _escape_inline(stripped), ""]
            list_indent = para_indent = None
            k += 2
            continue
        item = _ITEM.match(line)
        if item:
            if not previous_blank and list_indent != indent:
                out.append("")
            list_indent, para_indent = indent, indent + len(item.group(2)) + 1
        elif list_indent is not None and indent <= list_indent:
            if not previous_blank:
                out.append("")
            list_indent = None
            para_indent = indent
        elif para_indent is not None and not previous_blank and indent > para_indent and list_indent is None:
            # indented under a paragraph line: a literal block
            out[-1] = out[-1].rstrip() + (":" if out[-1].rstrip().endswith(":") else " ::")
            out.append("")
            block_indent = para_indent
            out.append(line)
            k += 1
            continue
        elif para_indent is None:
            para_indent = indent
        out.append(_escape_inline(line))
        if stripped.endswith("::"):
            block_indent = indent
        k += 1
    return out


_NUMPYDOC_SECTIONS = ("Parameters", "Returns", "Yields", "Receives", "Raises", "Warns", "Other Parameters",
                      "Attributes", "Methods", "See Also", "Notes", "References", "Examples", "Warnings")


def is_numpydoc(lines: list[str]) -> bool:
    """Whether a docstring has a numpydoc section (a known heading underlined with dashes)."""
    return any(first.strip() in _NUMPYDOC_SECTIONS and second.strip().startswith("-" * len(first.strip()))
               for first, second in zip(lines, lines[1:]))


def _numpydoc_where_written(app, what, name, obj, options, lines):
    """numpydoc's docstring handler for numpydoc docstrings only: on prose it keeps the first paragraph
    and drops every underlined heading it does not know, with the text under it (validation.score)."""
    from numpydoc.numpydoc import mangle_docstrings

    if is_numpydoc(lines):
        mangle_docstrings(app, what, name, obj, options, lines)


def _route_numpydoc(app):
    """Replace numpydoc's autodoc-process-docstring listener by _numpydoc_where_written."""
    from numpydoc.numpydoc import mangle_docstrings

    listeners = app.events.listeners.get("autodoc-process-docstring", [])
    for listener in list(listeners):
        if listener.handler is mangle_docstrings:
            app.disconnect(listener.id)
            app.connect("autodoc-process-docstring", _numpydoc_where_written, priority=listener.priority)


_ORIGINALS: dict[tuple[str, str], list[str]] = {}


def _keep_original(app, what, name, obj, options, lines):
    """autodoc-process-docstring, before numpydoc: the docstring as written, for _as_text."""
    _ORIGINALS[(what, name)] = list(lines)


def _as_text(app, what, name, obj, options, lines):
    """autodoc-process-docstring, after numpydoc: |x| and name_ escaped (escape_prose); a docstring
    that would still make Sphinx warn is replaced by its original text in a literal block."""
    if not lines:
        _ORIGINALS.pop((what, name), None)
        return
    lines[:] = escape_prose(lines)
    problems = rst_problems("\n".join(lines))
    if not problems:
        _ORIGINALS.pop((what, name), None)
        return
    original = _ORIGINALS.pop((what, name), None) or lines
    text = "\n".join(original).expandtabs(4)
    lines[:] = ["::", ""] + ["    " + line if line.strip() else "" for line in text.split("\n")]
    lines.append("")
    app.env.ddg_docs_as_text = sorted(set(getattr(app.env, "ddg_docs_as_text", [])) | {f"{what} {name}: "
                                                                                       f"{problems[0]}"})


def _merge_as_text(app, env, docnames, other):
    env.ddg_docs_as_text = sorted(set(getattr(env, "ddg_docs_as_text", []))
                                  | set(getattr(other, "ddg_docs_as_text", [])))


def _write_as_text(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    listed = getattr(app.env, "ddg_docs_as_text", [])
    path = Path(app.outdir) / AS_TEXT_FILE
    path.write_text("".join(f"{line}\n" for line in listed)
                    or "(every docstring is valid reStructuredText)\n", encoding="utf-8")
    from sphinx.util import logging

    logging.getLogger(__name__).info(f"{len(listed)} docstrings shown as preformatted text: {path}")


# ------------------------------------------------------------------------------- the gallery
def _install_gallery_readme_fallback(app, config):
    """examples/ has README.md, sphinx-gallery 0.10 wants README.txt/.rst: fall back to GALLERY_INTRO for
    the examples folder itself (its subfolders still need their own README to be a gallery section)."""
    if "sphinx_gallery_conf" not in config:   # sphinx-gallery not loaded
        return
    from sphinx_gallery import gen_gallery, gen_rst

    original = gen_rst._get_readme
    if getattr(original, "ddg_docs", False):
        return
    examples = [Path(app.srcdir, d).resolve() for d in _as_list(config.sphinx_gallery_conf.get("examples_dirs"))]

    def get_readme(dir_, gallery_conf, raise_error=True):
        found = original(dir_, gallery_conf, raise_error=False)
        if found is None and Path(dir_).resolve() in examples and GALLERY_INTRO.is_file():
            return str(GALLERY_INTRO)
        return found if found is not None else original(dir_, gallery_conf, raise_error=raise_error)

    get_readme.ddg_docs = True
    gen_rst._get_readme = get_readme
    gen_gallery._get_readme = get_readme


def _as_list(value):
    return [value] if isinstance(value, str) else list(value or [])


_LABEL = re.compile(r"^\.\. _sphx_glr_auto_examples_(\w+)\.py:\s*$", re.MULTILINE)


def _gallery_page_title(app, docname, source):
    """source-read of auto_examples/NAME: the docstring's first paragraph becomes the page title, and
    the docstring's indented lines (commands) a literal block."""
    if not docname.startswith("auto_examples/") or docname.endswith("/index"):
        return
    text = source[0]
    label = _LABEL.search(text)
    if label is None:
        return
    head, rest = text[:label.end()], text[label.end():]
    # the docstring runs up to the first generated code block
    cut = rest.find(".. GENERATED FROM PYTHON SOURCE LINES")
    cut = len(rest) if cut < 0 else cut
    doc, code = rest[:cut], rest[cut:]
    paragraphs = doc.strip("\n").split("\n\n")
    if not paragraphs or paragraphs[0].startswith(".. ") or paragraphs[0].startswith("="):
        return
    title = " ".join(paragraphs[0].split()).rstrip(".")
    kept: list[str] = []
    for paragraph in paragraphs[1:]:
        if paragraph.startswith("    ") and not (kept and kept[-1].rstrip().endswith("::")):
            kept.append("::")
        kept.append(paragraph)
    body = "\n\n".join(kept)
    source[0] = f"{head}\n\n{title}\n{'=' * len(title)}\n\n{body}\n\n{code}"


class ExampleArguments:
    """reset_argv: `--out BASE/NAME` for example NAME.py, BASE a temporary folder made at the first
    run (or $DDG_DOCS_GALLERY_OUT); also gives the script its `__file__`."""

    def __init__(self, base: str | None = None):
        self.base = base
        self.made: str | None = None

    def folder(self) -> Path:
        if self.base:
            return Path(self.base)
        if self.made is None:
            self.made = tempfile.mkdtemp(prefix="ddg-docs-gallery-")
        return Path(self.made)

    def out(self, src_file: str) -> Path:
        return self.folder() / Path(src_file).stem

    def __call__(self, gallery_conf, script_vars):
        # sphinx-gallery runs a script without __file__ (compare_with_gold.py finds validation/ by it):
        # the script's globals are made before its arguments, so it is set here, as `python FILE` sets it
        example_globals = script_vars.get("example_globals")
        if isinstance(example_globals, dict):
            example_globals.setdefault("__file__", str(script_vars["src_file"]))
        return ["--out", str(self.out(script_vars["src_file"]))]

    def cleanup(self, app, exception):
        if self.made is not None:
            shutil.rmtree(self.made, ignore_errors=True)
            self.made = None

    def __repr__(self):   # sphinx-gallery and Sphinx compare the configuration by repr
        return "ExampleArguments()"


class OutputPictures:
    """Image scraper: the PNG files an example wrote into its --out folder, in name order."""

    def __init__(self):
        self.shown: set[str] = set()

    def __call__(self, block, block_vars, gallery_conf):
        from sphinx_gallery.scrapers import figure_rst

        arguments = gallery_conf["reset_argv"]
        if not isinstance(arguments, ExampleArguments):
            return ""
        out = arguments.out(block_vars["src_file"])
        pictures = [p for p in sorted(out.rglob("*.png")) if str(p) not in self.shown] if out.is_dir() else []
        written = []
        for picture, target in zip(pictures, block_vars["image_path_iterator"]):
            shutil.copyfile(picture, target)
            self.shown.add(str(picture))
            written.append(target)
        return figure_rst(written, gallery_conf["src_dir"])

    def __repr__(self):
        return "OutputPictures()"


# ------------------------------------------------------------------------------ local MathJax
def _link_mathjax(app, exception):
    """With ddg_docs_mathjax_source set (conf.py: a local MathJax 2), OUT/_static/mathjax is a link to it."""
    source = app.config.ddg_docs_mathjax_source
    if exception is not None or not source or app.builder.format != "html":
        return
    target = Path(app.outdir) / "_static" / "mathjax"
    if target.is_symlink() or target.exists():
        if target.is_symlink() and os.readlink(target) == source:
            return
        if target.is_symlink() or target.is_file():
            target.unlink()
        else:
            shutil.rmtree(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    target.symlink_to(source, target_is_directory=True)


# ---------------------------------------------------------------------------------- set-up
def setup(app):
    app.add_config_value("ddg_docs_root", os.environ.get("DDG_DOCS_ROOT", ""), "env")
    app.add_config_value("ddg_docs_mathjax_source", "", "html")
    app.connect("build-finished", _link_mathjax)
    directives.register_directive("command-help", CommandHelp)
    directives.register_directive("benchmark-scenes", BenchmarkScenes)
    directives.register_directive("threshold-table", ThresholdTable)
    if "numpydoc" in app.extensions:
        _route_numpydoc(app)
    # after numpydoc (priority 500): the final reStructuredText is checked
    if os.environ.get("DDG_DOCS_RAW_DOCSTRINGS", "0") != "1":   # =1: the docstrings as written (diagnosis)
        app.connect("autodoc-process-docstring", _keep_original, priority=100)
        app.connect("autodoc-process-docstring", _as_text, priority=900)
    app.connect("env-merge-info", _merge_as_text)
    app.connect("build-finished", _write_as_text)
    app.connect("config-inited", _install_gallery_readme_fallback)
    app.connect("source-read", _gallery_page_title)

    def cleanup(app_, exception):
        arguments = (app_.config.sphinx_gallery_conf or {}).get("reset_argv") \
            if "sphinx_gallery_conf" in app_.config else None
        if isinstance(arguments, ExampleArguments):
            arguments.cleanup(app_, exception)

    app.connect("build-finished", cleanup)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
