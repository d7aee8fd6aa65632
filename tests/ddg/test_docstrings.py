"""ddg's docstrings say what is computed, in which units, by which equation of the paper, and what
a function promises; measured figures, run results, issue numbers and history live in
docs/findings and benchmarks/results, beside the script that measures them, where they are kept
current (issue 48 item 3).

Every docstring under ddg/ (module, class, function, method; read with `ast`, nothing imported)
is searched, and each match of a rule below is one mention, reported at its file and line:

- issue: ``issue 47``, ``issues 29 and 31`` (one mention per number), ``issue #47``, ``#47``,
  ``PR 12``, ``pull request 12``; and a commit hash (7 to 40 hex digits with a letter and a
  digit: ``0c61dc0``), which dates a figure as an issue number does.
- time or memory: a number (or a range such as ``0.42-0.81``) followed by a unit of time (``s``,
  ``sec``, ``ms``, ``us``, ``µs``, ``ns``, ``microseconds``, ``milliseconds``, ``seconds``,
  ``1 second``, ``min``, ``minutes``, ``hrs``, ``hours``) or of memory (``kB``, ``MB``, ``GB``,
  ``TB``, ``KiB`` .. ``TiB``, ``bytes``). ``h`` is not a unit here: it is the mesh spacing.
- speed-up: a number followed by ``x``, ``×`` or ``times`` that is not a product of two numbers
  (``60 x 10`` is a mesh, ``12 x 12`` a block), as in ``2.0x``, ``4x``, ``1.445 times the
  rod's``; ``x1.018``; ``faster``, ``slower``, ``quicker``, ``cheaper`` or ``speed-up`` within
  a few words of a number.
- percentage: a number with ``%`` or ``percent``.
- measured count: a count of iterations, runs, calls, evaluations, steps, solves, states, tasks
  or triangles after a verb of measuring (``took 698 iterations``, ``spent ~5000 iterations``).
- comparison: two numbers set against each other in one sentence, ``A against B``, ``A vs B``,
  ``A -> B`` (a before and after), ``A instead of B``.
- result value: a threshold, height or eigenvalue with its value (``dW1/L 0.3088``,
  ``dW2 = 0.52``, ``H_mid/L 0.272``, ``lambda_min ~ -3e11``): a result of a run.
- measured: a sentence with ``measured``, ``timed``, ``benchmarked``, ``best of N``,
  ``load average`` or ``N cores`` (``2-core``) that holds a number, once per sentence
  (``measured along m2``, ``measured from the clamp`` are geometry, and ``measured in tests/...``
  names the test that asserts a property, docs/findings/measured.md the page that has the
  figures: not figures).

Outside the result values, a number after ``=`` or ``default`` is a parameter, not a figure
(``dt = 0.01 s``, ``default 0.01 s``), and so are numbers in exponents (``L^2 times``,
``A^-1 x``). Equation, figure, section and year numbers (``Eq. (6b)``, ``Fig. 8``, ``Sano and
Wada 2019``), fractions (``3/2 times``), limits (``b -> 0``, ``lambda_min = 0``), counts of a
formula (``6M - 3 against 4M - 1``), tolerances of the contract (``1e-4 L``), orders
(``O(h^2)``) and the paper's constants match no rule.

The rules err on the side of catching more: a false alarm is a sentence to rephrase, a missed
figure is one that goes stale in a docstring. At most MAX_MENTIONS mentions are allowed in ddg
(issue 48's acceptance), each printed with its file:line on failure; no module docstring is longer
than MAX_MODULE_LINES lines: a newcomer reads a module's docstring in under a minute.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

# the repository root: the first folder above this file that holds the ddg package (wherever tests/ nests it)
ROOT = next(p for p in Path(__file__).resolve().parents if (p / "ddg" / "__init__.py").is_file())
PACKAGE = ROOT / "ddg"
MAX_MENTIONS = 10
MAX_MODULE_LINES = 40

# a number not inside a word, an exponent (L^2, A^-1) or a decimal; not after "=" or "default"
_NOT_PARAMETER = r"(?<![\w.^/])(?<!\^-)(?<!=)(?<!= )(?<!=  )(?<!default )(?<!default of )"
RAW_NUM = r"(?<![\w.^/])[-+~]?\d+(?:[.,]\d+)?(?:e[-+]?\d+)?"
NUM = _NOT_PARAMETER + RAW_NUM
NONZERO = r"(?!0(?![.\d]))" + NUM + r"(?![A-Za-z])"          # a limit "-> 0" and "4M - 1" are not figures
RANGE = rf"{NUM}(?:\s*(?:-|–|to|and)\s*\d+(?:\.\d+)?(?:e[-+]?\d+)?)*"
TIME = (r"(?:s|sec|secs|ms|us|µs|μs|ns|microseconds?|milliseconds?|seconds|min|mins|minutes?"
        r"|hrs?|hours?)")
MEMORY = r"(?:[kKMGT]i?B|bytes)"
COUNTED = r"(?:newton\s+)?(?:iterations?|runs?|calls?|evaluations?|steps?|solves?|states?|tasks?|triangles?)"
MEASURING = r"(?:took|takes|taking|needed|needs|used|ran|cost|costs|spent|spends|lasted|made)"
SENTENCE_END = r"(?:[.;](?=\s)|\n\s*\n)"

RULES: dict[str, re.Pattern] = {
    "issue": re.compile(
        r"\b(?:issues?|PRs?|pull\s+requests?)\s*#?\s*\d+(?:\s*(?:,|and|or|&)\s*#?\d+)*"
        r"|(?<![\w&])#\d+\b"
        r"|\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b", re.I),
    "time or memory": re.compile(rf"{RANGE}\s*(?:{TIME}|{MEMORY})(?![\w/^])|(?<![\w.])1\s+second\b(?!\s+\w*deriv)"),
    "speed-up": re.compile(
        rf"{NUM}\s*(?:x|×|times)(?!\s*[-+]?\d)(?![\w^])|(?<![\w.])[x×]\d+\.\d+\b"
        rf"|\bspeed-?ups?\b[^.;]{{0,40}}?\d|{NUM}[^.;\n]{{0,30}}?\b(?:faster|slower|quicker|cheaper)\b"
        rf"|\b(?:faster|slower|quicker|cheaper)\b[^.;\n]{{0,30}}?{NUM}", re.I),
    "percentage": re.compile(rf"{NUM}\s*(?:%|percent\b)", re.I),
    "measured count": re.compile(
        rf"\b{MEASURING}\s+(?:about\s+|~\s*|only\s+|just\s+)?{RANGE}\s+{COUNTED}\b", re.I),
    "comparison": re.compile(
        rf"{NONZERO}(?:(?!{SENTENCE_END})[^\n]|\n(?!\s*\n))*?(?:\bagainst|\bvs\.?|\bversus|->|→|\binstead\s+of)\s+"
        rf"(?:about\s+|~\s*|only\s+)?{NONZERO}", re.I),
    "result value": re.compile(
        rf"\b(?:dW[12](?:_\w+)?|H_mid|lambda_min)(?:/L)?\s*(?:=|~|of|:|is)?\s*(?!0(?![.\d])){RAW_NUM}", re.I),
}
MEASURING_WORD = re.compile(r"(?<![/\w])(?:measured|timed|benchmarked)\b(?!\.md)"
                            r"(?!\s+(?:along|from|relative|with\s+respect|(?:in|by)\s+tests/))"
                            r"|\bbest\s+of\s+\d|\bload\s+average\b|\b\d+[- ]cores?\b", re.I)
SENTENCE_NUMBER = re.compile(NUM + r"(?![\w)])")
NOT_FIGURE_NUMBER = re.compile(r"(?:Eqs?\.|Figs?\.|sections?|Appendix|App\.)\s*\(?\s*[A-Z]?\.?\d"
                               r"|[A-Z][a-z]+(?: et al\.)? (?:19|20)\d\d\b")


def docstrings(path: Path):
    """(first line number, text) of every docstring of the module at `path`."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                yield body[0].lineno, body[0].value.value


def _measured_sentences(text: str):
    """(offset, sentence) of each sentence with a measuring word and a number that is no equation,
    figure, section or year."""
    start = 0
    for end in [m.end() for m in re.finditer(SENTENCE_END, text)] + [len(text)]:
        sentence = text[start:end]
        word = MEASURING_WORD.search(sentence)
        if word:
            cleaned = NOT_FIGURE_NUMBER.sub(" ", sentence)
            if SENTENCE_NUMBER.search(cleaned):
                yield start + word.start(), sentence
        start = end


def mentions(text: str) -> list[tuple[int, str, str]]:
    """(line offset within `text`, rule, matched text) of every mention in a docstring's text."""
    found = []
    for rule, pattern in RULES.items():
        for match in pattern.finditer(text):
            line = text.count("\n", 0, match.start())
            matched = " ".join(match.group(0).split())
            copies = len(re.findall(r"\d+", matched)) if rule == "issue" and not matched.startswith("#") \
                and re.match(r"(?:issue|pr|pull)", matched, re.I) else 1
            found += [(line, rule, matched)] * copies
    for offset, sentence in _measured_sentences(text):
        found.append((text.count("\n", 0, offset), "measured", " ".join(sentence.split())[:100]))
    return sorted(found)


def all_mentions(package: Path = PACKAGE) -> list[str]:
    """Every mention under `package` as 'file:line: [rule] matched | the docstring's line'."""
    out = []
    for path in sorted(package.rglob("*.py")):
        for lineno, text in docstrings(path):
            lines = text.splitlines()
            for offset, rule, matched in mentions(text):
                out.append(f"{path.relative_to(package.parent)}:{lineno + offset}: [{rule}] {matched!r} | "
                           f"{lines[offset].strip() if offset < len(lines) else ''}")
    return out


def test_docstrings_carry_no_measured_figures_or_issue_numbers():
    found = all_mentions()
    assert len(found) <= MAX_MENTIONS, (f"{len(found)} docstring mentions of measured figures or issue numbers "
                                        f"in ddg (at most {MAX_MENTIONS}; they belong in docs/findings or "
                                        "benchmarks/results):\n" + "\n".join(found))


def module_docstring_lines(path: Path) -> int:
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")), clean=False)
    return len(doc.splitlines()) if doc else 0


def test_module_docstrings_read_in_under_a_minute():
    long = [f"{path.relative_to(ROOT)}: {module_docstring_lines(path)} lines" for path in sorted(PACKAGE.rglob("*.py"))
            if module_docstring_lines(path) > MAX_MODULE_LINES]
    assert not long, f"module docstrings longer than {MAX_MODULE_LINES} lines:\n" + "\n".join(long)


CAUGHT = ["see issue 47", "issues 29 and 31", "fixed in #47", "(issue 31)", "at 0c61dc0", "0.41 s at M = 100",
          "57.9 us", "3 ms", "40 µs", "10 microseconds", "1029 seconds", "4.1 GB resident", "522 MB", "8 GiB",
          "2.0x faster", "x1.018", "1.25 times faster", "1.445 times the rod's", "3-4 times cheaper", "2.0 %",
          "17 percent", "took 698 iterations", "spent ~5000 iterations", "measured at M = 100: 0.41",
          "Measured on the rod: 3 points 1067, 4 points 792", "best of 3", "load average 1.5", "an idle 2-core machine",
          "1.9-20 s", "0.42-0.81 s", "1556 Newton iterations against 968",
          "225 iterations past the pitchfork (M = 100) "
          "against ~30 here", "M = 100: 110 -> 95", "dW1/L 0.3088, 0.3345", "dW2 = 0.52", "H_mid/L 0.272",
          "lambda_min ~ -3e11", "over two\nlines: 440 s"]
LEFT_ALONE = ["Eq. (6b)", "Eqs. (11a) and (11b)", "O(h^2)", "tolerance 1e-4 L", "zeta = 1e4 L", "a 60 x 10 mesh",
              "k^4 = 3 (1 - nu^2) kappa^2 W^4 / b^2", "6M - 3 DOFs", "GJ = E W b^3 / (6 (1 + nu))",
              "at most 50 iterations", "the 3 x 3 block", "no per-hinge 12 x 12 second derivatives", "dW/L = 0.05",
              "h/L = (W/L)/rows", "W^2/(b L)", "EI2 / L^2 times the node's share", "x becomes A^-1 x",
              "a mesh of [x0, x1] x [-W/2, W/2]", "shortens the free rod by 2h", "sqrt(3)/4 h", "dt = 0.01 s",
              "time_step (s): default 0.01 s", "1 mm/s", "damping 20 1/s", "w is measured along m2 at rest: "
              "m1 = +z", "arclength measured from the clamp point at s = 0",
              "Continuum limit (Seung and Nelson 1988; measured in tests/ddg/energies/test_plate_energies.py)",
              "the 75 mm between the clamps", "b = 0.127 mm", "(Sano and Wada 2019)", "Figs. 9-10",
              "the angle is 3/2 times larger",
              "W^2 kappa / b -> 0 or W^2 tau / b -> 0", "(lambda_min = 0 on its U branch)", "(6M - 3 against 4M - 1)",
              "bending Poisson ratio -1/3 (measured in tests/ddg/energies/test_plate_energies.py)",
              "bandwidth 10-200 (what that costs: docs/findings/measured.md)"]


def test_the_rules_catch_what_they_are_for():
    """Each rule on sentences it must catch, and physics and contracts it must leave alone."""
    for sentence in CAUGHT:
        assert mentions(sentence), sentence
    assert len(mentions("issues 29 and 31")) == 2
    for sentence in LEFT_ALONE:
        assert not mentions(sentence), (sentence, mentions(sentence))
