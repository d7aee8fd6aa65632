"""The report's HTML and its committed snapshot (issue 18 item 8): every link resolves, every image
loads, no Markdown shows as source, wide tables scroll; a headless browser draws the page where
chromium is installed (CI installs it: scripts/setup.sh)."""
import base64
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from validation.report import inline_markdown

ROOT = Path(__file__).resolve().parents[1]
SNAPSHOT = ROOT / "validation" / "results" / "quick"
PNG = b"\x89PNG\r\n\x1a\n"


class Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.images, self.text, self.tables, self.wrapped = [], [], [], 0, 0
        self._stack = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
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
        if href.startswith(("http://", "https://", "#", "mailto:")):
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


def _browser():
    return next((shutil.which(name) for name in ("chromium", "chromium-browser", "google-chrome")
                 if shutil.which(name)), None)


def test_a_headless_browser_draws_the_snapshot(tmp_path):
    browser = _browser()
    if browser is None:
        pytest.skip("no chromium here (scripts/setup.sh installs Debian's chromium)")
    shot = tmp_path / "page.png"
    done = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                           f"--screenshot={shot}", "--window-size=1200,3000", (SNAPSHOT / "index.html").as_uri()],
                          capture_output=True, text=True, timeout=180)
    assert shot.exists() and shot.read_bytes()[:8] == PNG, done.stderr[-2000:]
    assert shot.stat().st_size > 50_000   # a drawn page, not a blank one (measured: 0.5-1 MB)


def test_stability_map_colours_the_mesh_unresolved_outcome_as_its_own():
    """The map's "ok (mesh unresolved near dW_max)" used to take plain "ok"'s colour (a startswith
    test that matched the shorter category first)."""
    from validation.figures import STABILITY_CATEGORIES, stability_category

    assert STABILITY_CATEGORIES[stability_category("ok (mesh unresolved near dW_max)")] == \
        "ok (mesh unresolved near dW_max)"
    assert STABILITY_CATEGORIES[stability_category("ok")] == "ok"
    assert STABILITY_CATEGORIES[stability_category("missed pitchfork (rod width error 0.2)")] == "rod width error"


def test_the_paper_figures_draw_from_their_data(tmp_path):
    """Figs. 10 and A.12-14 from the files data/paper_figures/generate.sh writes (tiny hand-made ones
    here): the centreline error on a log L/W axis, the curvature profiles per dW/L."""
    pytest.importorskip("matplotlib")
    from validation import figures
    from validation.report_data import paper_figures

    (tmp_path / "centerline_error").mkdir()
    (tmp_path / "centerline_error" / "centerline_error.csv").write_text(
        "L_over_W,W_over_L,dW_over_L,mean_error,max_error,rod_edge_mean_error,ribbon_edge_mean_error,phase,"
        "triangles,message\n2,0.5,0.1,0.01,0.02,0,0,U,2000,\n20,0.05,0.1,0.0001,0.0003,0,0,U,2000,\n")
    for model in ("rod", "plate"):
        (tmp_path / f"curvatures_{model}").mkdir()
        (tmp_path / f"curvatures_{model}" / "curvatures.csv").write_text(
            "model,step,dL_over_L,dW_over_L,s_over_L,k1_L,k2_L,tau_L\n"
            + "".join(f"{model},0,0.5,0.2,{s},0.0,{s * 3},{-s}\n" for s in (0.1, 0.5, 0.9)))
    for name in ("rod", "ribbon_rod"):
        run = tmp_path / "a11" / "W0.05" / name
        run.mkdir(parents=True)
        (run / "path.csv").write_text("stage,dL_over_L,dW_over_L,H_mid_over_L,phase\ncompression,0.5,0,0.37,U\n"
                                      "shear,0.5,0.1,0.36,U\nshear,0.5,0.4,0.2,US+\n")
    (tmp_path / "fig9").mkdir()
    (tmp_path / "fig9" / "W0.05.csv").write_text(
        "W_over_L,dW_over_L,s_over_L,w_over_L,delta_percent\n"
        + "".join(f"0.05,0.3,{s},{w},{0.01 + s * abs(w)}\n" for s in (0.0, 0.5, 1.0) for w in (-0.025, 0.0, 0.025)))
    found = {f.name: f for f in paper_figures(tmp_path)}
    assert set(found) == {"centerline_error", "curvature_profiles", "sadowsky_a11", "centerline_error_field"}
    figures.draw(found["centerline_error_field"])
    assert len(found["sadowsky_a11"].rows) == 4          # the shear rows only
    figures.draw(found["sadowsky_a11"])
    fig = figures.draw(found["centerline_error"])
    assert fig.axes[0].get_xscale() == "log"
    png = figures.save(figures.draw(found["curvature_profiles"]), tmp_path / "out", "curvature_profiles")
    assert png[:8] == PNG and (tmp_path / "out" / "curvature_profiles.pdf").exists()
    assert paper_figures(tmp_path / "none") == []


def test_the_fig9_generator_refuses_a_bad_out_and_skips_finished_widths(tmp_path, capsys, monkeypatch):
    from validation import paper_figures as pf

    (tmp_path / "file").write_text("x")
    assert pf.main(["--out", str(tmp_path / "file"), "--quiet"]) == 2
    assert capsys.readouterr().err.startswith("error: ") and not (tmp_path / "file" / "fig9").exists()
    for width in pf.FIG9_WIDTHS:                     # every width finished: nothing is run
        pf.field_file(tmp_path / "out", width).parent.mkdir(parents=True, exist_ok=True)
        pf.field_file(tmp_path / "out", width).write_text("W_over_L\n")
    import ddg.analysis.curvatures as curvatures
    monkeypatch.setattr(curvatures, "states_at_shears", lambda *a, **k: 1 / 0)
    assert pf.write_fields(tmp_path / "out", quiet=True) == []
    for width in pf.FIG9_WIDTHS:                     # Fig. 9a: a width with its centreline file is finished
        pf.shape_files(tmp_path / "out", width)["centerline"].parent.mkdir(parents=True, exist_ok=True)
        pf.shape_files(tmp_path / "out", width)["centerline"].write_text("dW_over_L\n")
    assert pf.write_shapes(tmp_path / "out", quiet=True) == []


def test_fig9a_draws_the_deformed_plate_and_its_centreline_rendering(tmp_path):
    """A coarse plate (W/L = 1/6, 300 triangles) sheared to dW/L = 0.1: the shape files hold every
    node of the mesh, the centreline runs through both clamps with its m2 at every station, and
    the figure draws the mesh and the Eq. (12) lines from them (Fig. 9a)."""
    pytest.importorskip("matplotlib")
    import csv

    import numpy as np

    from validation import figures
    from validation import paper_figures as pf
    from validation.report_data import fig9a_figure

    written = pf.write_shapes(tmp_path, widths=(1 / 6,), shears=(0.1,), triangles=300, quiet=True)
    files = pf.shape_files(tmp_path, 1 / 6)
    assert written == [files["centerline"]]
    tri = np.loadtxt(files["triangles"], delimiter=",", skiprows=1, dtype=int)
    with open(files["nodes"]) as f:
        nodes = list(csv.DictReader(f))
    assert len(nodes) == tri.max() + 1 and {n["dW_over_L"] for n in nodes} == {"0.1"}
    with open(files["centerline"]) as f:
        line = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    assert line[0]["s_over_L"] <= 1e-9 and line[-1]["s_over_L"] >= 1 - 1e-9   # the clamped rows included
    # m2 at a station is the mean of its two edges' unit m2 (Eq. 12): unit to within their turn
    # (|m2| in [0.9953, 1] on the committed W/L = 1/3 shapes, 2000 triangles)
    assert all(0.99 < np.hypot(np.hypot(r["m2_x"], r["m2_y"]), r["m2_z"]) <= 1 + 1e-6 for r in line)
    figure = fig9a_figure(tmp_path)
    assert {r[0] for r in figure.rows} == {"plate node", "centreline"} and len(figure.rows) == len(nodes) + len(line)
    fig = figures.draw(figure)
    assert len(fig.axes) == 1 and fig.axes[0].get_title() == "W/L = 1/6, dW/L = 0.1"
    assert fig9a_figure(tmp_path / "none") is None
