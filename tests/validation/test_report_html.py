"""The report's HTML and its committed snapshot (issue 18 item 8): every link resolves, every image
loads, no Markdown shows as source, wide tables scroll; the page opens with a summary that fits a
laptop's first screen and folds its long texts (issue 33 item 5); a headless browser draws the page
where chromium is installed (CI installs it: scripts/setup.sh)."""
import base64
import csv
import html
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from validation.report import FOLD, inline_markdown

ROOT = Path(__file__).resolve().parents[2]
SNAPSHOT = ROOT / "validation" / "results" / "quick"
PNG = b"\x89PNG\r\n\x1a\n"


class Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.images, self.text, self.tables, self.wrapped = [], [], [], 0, 0
        self.ids = set()
        self._stack = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            assert attrs["id"] not in self.ids, f"id {attrs['id']!r} twice"
            self.ids.add(attrs["id"])
        if tag == "a" and "href" in attrs:
            self.links.append(attrs["href"])
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        if tag == "table":
            self.tables += 1
            self.wrapped += bool(self._stack and self._stack[-1] == "wide")
        if tag == "div":
            self._stack.append(attrs.get("class", ""))

    def handle_endtag(self, tag):
        if tag == "div" and self._stack:
            self._stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def check_page(folder: Path) -> Page:
    page = Page()
    page.feed((folder / "index.html").read_text())
    for href in page.links:
        if href.startswith("#"):
            assert href[1:] in page.ids, f"link {href!r} has no target in the page"
            continue
        if href.startswith(("http://", "https://", "mailto:")):
            continue
        target = (folder / href.split("#")[0]).resolve()
        assert target.exists() or (ROOT / href.split("#")[0]).exists(), f"link {href!r} does not resolve"
    assert page.images, "no image"
    for src in page.images:
        assert src.startswith("data:image/png;base64,"), src[:40]
        assert base64.b64decode(src.split(",", 1)[1])[:8] == PNG
    text = " ".join(page.text)
    assert "`" not in text and "**" not in text and not re.search(r"\]\([^)]+\)", text), "Markdown as source"
    assert page.tables > 0 and page.wrapped == page.tables, "a table without its scrolling wrapper"
    return page


def test_inline_markdown_is_rendered_and_text_escaped():
    html = str(inline_markdown("run `python -m ddg` and **see** [the map](data/error_map/README.md) <b>&"))
    assert "<code>python -m ddg</code>" in html and "<strong>see</strong>" in html
    assert '<a href="data/error_map/README.md">the map</a>' in html and "&lt;b&gt;&amp;" in html


def test_the_committed_snapshot_has_its_html_figures_and_pdfs():
    if not (SNAPSHOT / "index.html").exists():
        pytest.fail("validation/results/quick lacks index.html (regenerate the quick report and copy it)")
    check_page(SNAPSHOT)
    md = (SNAPSHOT / "report.md").read_text()
    for target in re.findall(r"\]\(([^)\s]+)\)", md):
        if target.startswith(("http://", "https://", "#")):
            continue
        assert (SNAPSHOT / target).exists() or (ROOT / target).exists(), f"report.md links {target!r}"
    for png in (SNAPSHOT / "figures").glob("*.png"):
        assert png.with_suffix(".pdf").exists(), f"{png.name} without its PDF"


# ---------------------------------------------------------------------------- the summary first
VOID = {"img", "meta", "br", "hr", "link", "input", "source", "wbr"}


class Node:
    """An element of a parsed page: tag, attributes, children (nodes and text)."""

    def __init__(self, tag: str, attrs: dict, parent=None):
        self.tag, self.attrs, self.parent, self.children = tag, attrs, parent, []

    def iter(self, tag: str | None = None):
        if tag in (None, self.tag):
            yield self
        for child in self.children:
            if isinstance(child, Node):
                yield from child.iter(tag)

    def find(self, tag: str, **attrs):
        return next((n for n in self.iter(tag) if all(n.attrs.get(k) == v for k, v in attrs.items())), None)

    @property
    def elements(self) -> list:
        return [c for c in self.children if isinstance(c, Node)]

    @property
    def text(self) -> str:
        return "".join(c if isinstance(c, str) else c.text for c in self.children)

    def inside(self, tag: str) -> bool:
        node = self.parent
        while node is not None and node.tag != tag:
            node = node.parent
        return node is not None


class Tree(HTMLParser):
    """The page as a tree of Nodes (the report's HTML closes every element it opens)."""

    def __init__(self, text: str):
        super().__init__()
        self.root = self._open = Node("#document", {})
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        node = Node(tag, dict(attrs), self._open)
        self._open.children.append(node)
        if tag not in VOID:
            self._open = node

    def handle_endtag(self, tag):
        node = self._open
        while node is not None and node.tag != tag:
            node = node.parent
        if node is not None:
            self._open = node.parent

    def handle_data(self, data):
        self._open.children.append(data)


def _csv_rows(name: str) -> list[dict]:
    with open(SNAPSHOT / name, newline="") as f:
        return list(csv.DictReader(f))


def _with_bar(value: str, bar: str) -> str:
    """The benchmark's value +- error bar as the summary prints it (4 decimals; the value alone without
    a bar, an en dash without a value)."""
    if not value:
        return "\u2013"
    return f"{float(value):.4f}" + (f" \u00b1 {float(bar):.4f}" if bar else "")


def _claim_figures(claim: dict) -> list[str]:
    """The numbers a claim's summary line states, from summary.json's claim (the details' data)."""
    if claim["measured"] is None:
        return ["no measured value"]
    if claim.get("error_bar_limit") is None:
        return [f"measured {claim['measured']:.4g}", f"bound {claim['bound']:g}"]
    return [f"difference {claim['deciding_difference']:.4g}", f"bound {claim['bound']:g}",
            f"combined error bar {claim['deciding_error_bar']:.4g}"]


def test_the_snapshot_opens_with_its_summary():
    """The page's first section is the summary: the benchmark table (every scene of benchmark.csv, FEM
    and plate dW1/L and dW2/L with their error bars), the thresholds-against-width figure (the PNG of
    figures/, embedded once in the page) and one line per claim of claims.csv with its outcome and
    the figure that decides it (summary.json), linked to the claim's entry below."""
    page = (SNAPSHOT / "index.html").read_text()
    tree = Tree(page)
    body = tree.root.find("body")
    summary = body.elements[0]
    assert (summary.tag, summary.attrs.get("id")) == ("section", "summary"), "the page does not open with the summary"
    assert summary.find("h1") is not None and "Validation report" in summary.find("h1").text

    bench = _csv_rows("benchmark.csv")
    table = next(t for t in summary.iter("table") if t.attrs.get("id") != "claim-lines")
    rows = [[td.text for td in tr.elements] for tr in table.iter("tr")]
    assert rows[0] == ["dL/L", "W/L", "FEM dW1/L", "FEM dW2/L", "plate dW1/L", "plate dW2/L"]
    assert len(rows) - 1 == len(bench) > 0
    for shown, r in zip(rows[1:], bench):
        assert shown[2:] == [_with_bar(r[f"{m}_{k}"], r[f"{m}_{k}_error_bar"]) for m in ("fem", "plate")
                             for k in ("dW1", "dW2")], shown

    figure = summary.find("figure", id="figure-thresholds_vs_width")
    assert figure is not None, "no thresholds-against-width figure in the summary"
    src = figure.find("img").attrs["src"]
    png = (SNAPSHOT / "figures" / "thresholds_vs_width.png").read_bytes()
    assert base64.b64decode(src.split(",", 1)[1]) == png
    assert page.count(src) == 1, "the summary's figure is embedded twice"

    claims = json.loads((SNAPSHOT / "summary.json").read_text())["claims"]
    assert [c["claim"] for c in claims] == [r["claim"] for r in _csv_rows("claims.csv")]
    lines = list(summary.find("table", id="claim-lines").iter("tr"))
    assert len(lines) == len(claims)
    for line, claim, row in zip(lines, claims, _csv_rows("claims.csv")):
        name, outcome, figures = line.elements
        assert name.text == claim["claim"] and name.find("a").attrs["href"] == f"#claims-{claim['claim']}"
        assert tree.root.find("tr", id=f"claims-{claim['claim']}") is not None
        assert outcome.text == row["outcome"] == claim["outcome"]
        assert outcome.attrs["class"] == f"outcome {row['outcome']}"
        for figure_text in _claim_figures(claim):
            assert figure_text in html.unescape(figures.text), (claim["claim"], figures.text)


def test_a_claims_line_states_the_figure_that_decides_it():
    """The summary's line of a claim: the measured value against the bound (single-model), the deciding
    point's difference against the bound and its combined error bar against the limit (cross-model),
    on both sides of each; "no measured value" without data."""
    from validation import claims as C
    from validation.report import sentence
    from validation.verdicts import ClaimLine

    def line(key, measured):
        return sentence("claim_figure", ClaimLine(C.evaluate(key, measured)))

    bound = C.CLAIMS["rod_elastica"].bound
    assert line("rod_elastica", 0.5 * bound) == f"measured {0.5 * bound:.4g} <= bound {bound:g}"
    assert line("rod_elastica", 2 * bound) == f"measured {2 * bound:.4g} > bound {bound:g}"
    assert line("rod_elastica", None) == "no measured value (no data)"
    claim = C.CLAIMS["plate_vs_fem_dW1"]
    b, lim = claim.bound, claim.error_bar_limit
    # the deciding point, not the largest difference: a decidable failure beside an undecidable larger one
    points = ((0.5 * b, 0.5 * lim, "a"), (1.5 * b, 0.5 * lim, "b"), (3 * b, 5 * lim, "c"))
    fails = C.Agreement(3 * b, 5 * lim, 0.0, 3, pairs=points)
    assert C.evaluate("plate_vs_fem_dW1", fails)["outcome"] == "fails"
    assert line("plate_vs_fem_dW1", fails) == (f"difference {1.5 * b:.4g} > bound {b:g}, combined error bar "
                                               f"{0.5 * lim:.4g} <= {lim:g}")
    undecided = C.Agreement(0.5 * b, 2 * lim, 0.0, pairs=((0.5 * b, 2 * lim, "a"),))
    assert line("plate_vs_fem_dW1", undecided) == (f"difference {0.5 * b:.4g} <= bound {b:g}, combined error bar "
                                                   f"{2 * lim:.4g} > {lim:g}")
    short = C.Agreement(0.5 * b, 0.5 * lim, 0.0, pairs=((0.5 * b, 0.5 * lim, "a"),), short="ends early")
    assert C.evaluate("plate_vs_fem_dW1", short)["outcome"] == "fails"
    assert line("plate_vs_fem_dW1", short).endswith("; the reference stops short of the compared range")


def test_the_summary_says_what_a_report_lacks_and_shows_what_it_has():
    """A report without a benchmark or the thresholds figure says so in its summary; given them, its
    summary shows their rows (dL/L, W/L as fractions, value +- bar) and the figure, not twice."""
    pytest.importorskip("jinja2")
    from test_report_templates import _hand_made_report

    from validation.report import render_html, render_markdown
    from validation.report_data import FigureData, Table

    data = _hand_made_report()
    page, md = render_html(data), render_markdown(data)
    for text in (page, md):
        assert "No benchmark in this report." in text and "No thresholds-against-width figure in this report." in text
    check = Tree(page).root.find("section", id="summary")
    assert len(list(check.find("table", id="claim-lines").iter("tr"))) == len(data.claims)

    row = {"compression_ratio": 0.25, "width_ratio": 1 / 12, "fem_dW1": 0.20842, "fem_dW1_error_bar": 0.00173,
           "fem_dW2": 0.30291, "fem_dW2_error_bar": None, "plate_dW1": None, "plate_dW1_error_bar": None,
           "plate_dW2": 0.29440, "plate_dW2_error_bar": 0.00138}
    data.tables["benchmark"] = Table("benchmark", list(row), [row], csv=True)
    png = (SNAPSHOT / "figures" / "thresholds_vs_width.png").read_bytes()
    data.figures.append(FigureData("thresholds_vs_width", "thresholds", "Thresholds.", ["model"], [], png=png))
    page, md = render_html(data), render_markdown(data)
    summary = Tree(page).root.find("section", id="summary")
    cells = [td.text for td in summary.find("table").iter("td")]
    assert cells == ["1/4", "1/12", "0.2084 \u00b1 0.0017", "0.3029", "\u2013", "0.2944 \u00b1 0.0014"]
    assert "| 1/4 | 1/12 | 0.2084 \u00b1 0.0017 | 0.3029 | \u2013 | 0.2944 \u00b1 0.0014 |" in md.splitlines()
    img = summary.find("figure", id="figure-thresholds_vs_width").find("img")
    assert (img.attrs["width"], img.attrs["height"]) == (str(int.from_bytes(png[16:20], "big")),
                                                         str(int.from_bytes(png[20:24], "big")))
    assert page.count("data:image/png;base64,") == len(data.figures)
    assert md.count("![thresholds_vs_width](figures/thresholds_vs_width.png)") == 1


def test_the_markdown_report_opens_with_the_same_summary():
    """report.md in the page's order: the benchmark table, the figure, a line per claim with its
    outcome (bold where it does not hold), then the claims' details."""
    md = (SNAPSHOT / "report.md").read_text()
    order = [md.index(mark) for mark in ("# Validation report", "| dL/L | W/L | FEM dW1/L |",
                                         "![thresholds_vs_width](figures/thresholds_vs_width.png)", "**[Claims]",
                                         "\n## Claims\n")]
    assert order == sorted(order)
    claims = json.loads((SNAPSHOT / "summary.json").read_text())["claims"]
    for claim in claims:
        outcome = claim["outcome"] if claim["outcome"] == "holds" else f"**{claim['outcome']}**"
        line = next(x for x in md.splitlines() if x.startswith(f"- {claim['claim']}: "))
        assert line.startswith(f"- {claim['claim']}: {outcome}; ") and md.index(line) < order[-1]
        assert all(figure in line for figure in _claim_figures(claim)), line
    for r in _csv_rows("benchmark.csv"):
        assert _with_bar(r["fem_dW1"], r["fem_dW1_error_bar"]) in md[:order[3]]


def test_the_snapshot_folds_its_long_texts_and_loses_none():
    """Every table cell longer than FOLD['cell'] characters is folded in <details> (the claims'
    statements, reasons and needs among them) and keeps its whole text there; every table or list of
    more than FOLD['rows'] entries outside the summary and the claims is folded whole."""
    page = (SNAPSHOT / "index.html").read_text()
    tree = Tree(page)
    folded = 0
    for td in tree.root.iter("td"):
        details = td.find("details")
        if details is None:
            assert len(td.text) <= FOLD["cell"], td.text[:80]
        else:   # the beginning shown, the whole text folded behind it
            folded += 1
            preview = details.find("summary").text
            assert details.text[len(preview):].startswith(preview.rstrip("\u2026").rstrip())
            assert len(preview) <= FOLD["preview"] < len(details.text) - len(preview)
    assert folded > 0
    for row in _csv_rows("claims.csv"):
        tr = tree.root.find("tr", id=f"claims-{row['claim']}")
        for column in ("statement", "reason", "needs"):
            if not row[column]:
                continue
            cells = [td for td in tr.elements if row[column] in td.text]
            assert cells, (row["claim"], column)
            if len(row[column]) > FOLD["cell"]:
                assert cells[0].find("details") is not None, (row["claim"], column)
    summary = tree.root.find("section", id="summary")
    claims_table = tree.root.find("tr", id=f"claims-{_csv_rows('claims.csv')[0]['claim']}").parent
    for table in tree.root.iter("table"):
        if len(list(table.iter("tr"))) - 1 > FOLD["rows"] and table is not claims_table and not table.inside("section"):
            assert table.inside("details"), [tr.text[:60] for tr in table.iter("tr")][:2]
    for ul in tree.root.iter("ul"):
        if len(ul.elements) > FOLD["rows"]:
            assert ul.inside("details")
    assert summary is not None and not any(n.tag == "details" for n in summary.iter())


def _browser():
    return next((shutil.which(name) for name in ("chromium", "chromium-browser", "google-chrome")
                 if shutil.which(name)), None)


def _chromium(*args: str) -> subprocess.CompletedProcess:
    browser = _browser()
    if browser is None:
        pytest.skip("no chromium here (scripts/setup.sh installs Debian's chromium)")
    return subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", *args],
                          capture_output=True, text=True, timeout=180)


def test_a_headless_browser_draws_the_snapshot(tmp_path):
    """At a laptop's window size (1366 x 768)."""
    shot = tmp_path / "page.png"
    done = _chromium(f"--screenshot={shot}", "--window-size=1366,768", (SNAPSHOT / "index.html").as_uri())
    assert shot.exists() and shot.read_bytes()[:8] == PNG, done.stderr[-2000:]
    header = shot.read_bytes()[16:24]
    assert (int.from_bytes(header[:4], "big"), int.from_bytes(header[4:], "big")) == (1366, 768)
    assert shot.stat().st_size > 50_000   # a drawn page, not a blank one (measured: 156 kB; blank: 5 kB)


#: Appended to a copy of the page: where the summary's parts are drawn, written into the page for --dump-dom.
LAYOUT_PROBE = """<script>
window.addEventListener("load", function () {
  function box(el) {
    var r = el.getBoundingClientRect();
    return {top: r.top, bottom: r.bottom, left: r.left, right: r.right};
  }
  var summary = document.getElementById("summary");
  var layout = {width: window.innerWidth, height: window.innerHeight,
                scroll_width: document.documentElement.scrollWidth, first: document.body.firstElementChild.id,
                benchmark: box(summary.querySelector(".columns table")),
                figure: box(summary.querySelector(".columns figure img")),
                claims: box(document.getElementById("claim-lines"))};
  var pre = document.createElement("pre");
  pre.id = "layout";
  pre.textContent = JSON.stringify(layout);
  document.body.appendChild(pre);
});
</script>
"""


def _layout(tmp_path: Path, width: int, height: int) -> dict:
    probe = tmp_path / "index.html"
    probe.write_text((SNAPSHOT / "index.html").read_text().replace("</body>", LAYOUT_PROBE + "</body>"))
    done = _chromium(f"--window-size={width},{height}", "--virtual-time-budget=5000", "--dump-dom", probe.as_uri())
    found = re.search(r'<pre id="layout">(.*?)</pre>', done.stdout)
    assert found, done.stderr[-2000:]
    return json.loads(html.unescape(found.group(1)))


@pytest.mark.parametrize("width, height", [(1366, 768), (1280, 800)])
def test_the_first_screen_at_a_laptop_size_holds_the_summary(tmp_path, width, height):
    """Drawn at a laptop's window size, the page's viewport (the window less the browser's bars) shows
    the benchmark table and the thresholds figure whole, side by side, and the claims' lines begin
    on it; nothing is wider than the window. Measured at 1366 x 768 (viewport 681 px high): table
    bottom 334 px, figure bottom 329 px, claims' lines 397-650 px."""
    layout = _layout(tmp_path, width, height)
    assert layout["first"] == "summary" and layout["width"] == width
    assert layout["scroll_width"] <= width, layout
    for part in ("benchmark", "figure"):
        assert 0 <= layout[part]["top"] and layout[part]["bottom"] <= layout["height"], (part, layout)
    assert layout["figure"]["left"] >= layout["benchmark"]["right"], layout   # beside the table
    assert layout["claims"]["top"] < layout["height"], layout


def test_on_a_narrow_window_the_summary_wraps_without_overflow(tmp_path):
    """At 800 px the figure goes below the table and nothing is wider than the window."""
    layout = _layout(tmp_path, 800, 1000)
    assert layout["scroll_width"] <= 800, layout
    assert layout["figure"]["top"] >= layout["benchmark"]["bottom"], layout
