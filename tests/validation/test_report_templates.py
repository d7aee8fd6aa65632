"""The report's templates (validation/templates/, rendered by validation.report) on a ReportData
built by hand: every table row and claim in the Markdown and the HTML, a failing claim shown as
failing, the sections on ribbons and on the error map rendered from a map, and a missing jinja2
stopping the report before any run (_hand_made_report serves test_report_html.py too)."""
import re

import pytest

from validation import claims as C


def _hand_made_report(claims=None):
    """A ReportData built by hand (no model run): two claims, a row in every table, one figure."""
    from validation.report_data import FigureData, Provenance, ReportData, Snapshots, Table, Timings

    claims = claims if claims is not None else [C.evaluate("rod_elastica", 2e-4), C.evaluate("fem_elastica", 1e-4)]
    claims[0] = {**claims[0], "statement": "a <b> & c | d"}  # escaped in HTML, '|' kept out of the Markdown table
    thresholds = [{"model": "rod", "compression_ratio": 0.5, "width_ratio": 0.05, "dW1_over_L": 0.3516,
                   "paper_dW1": 0.36, "dW1_rel_diff_vs_paper": 0.3516 / 0.36 - 1, "dW2_over_L": 0.4598,
                   "paper_dW2": 0.52, "dW2_rel_diff_vs_paper": 0.4598 / 0.52 - 1, "dW2_S_stable_over_L": None,
                   "dW1_drop_vs_W_1_20_percent": 0.0, "paper_drop_percent": None, "dW_max_over_L": 0.8175}]
    speed = [{"model": "plate", "resolution": 1000, "wall_time_s": 15.33, "curve_error": 0.08721,
              "dW1_error": 0.01084, "converged": True}]
    conv = [{"model": "rod", "resolution": 50, "width_ratio": 0.05, "elastica_rel_error": -0.002527,
             "curve_error_vs_finest": None, "dW1_over_L": 0.351, "dW2_over_L": 0.5228, "wall_time_s": 2.2}]
    smap = [{"model": "ribbon", "compression_ratio": 0.5, "width_ratio": 0.05, "resolution": 101, "poisson_ratio": 0.0,
             "outcome": "missed pitchfork", "reached_dW_over_L": 0.8175, "dW_max_over_L": 0.8175,
             "reached_percent_of_dW_max": 100.0, "resolved_up_to_dW_over_L": 0.8175,
             "rod_dW1_minus_reference": None, "message": "path complete"}]
    tables = {"claims": Table("claims", list(claims[0]), claims, csv=True),
              "thresholds": Table("thresholds", list(thresholds[0]), thresholds, csv=True),
              "speed_accuracy": Table("speed_accuracy", list(speed[0]), speed),
              "convergence": Table("convergence", list(conv[0]), conv),
              "stability_map": Table("stability_map", list(smap[0]), smap, csv=True,
                                     shown=[c for c in smap[0] if c != "message"])}
    figure = FigureData("poisson", "poisson", "Rod, nu against nu = 0.", ["poisson_ratio", "dW_over_L", "H_mid_over_L"],
                        [[0.0, 0.0, 0.1], [0.0, 0.1, 0.2]], png=b"not really a PNG")
    return ReportData(Provenance("hand", 3, 3, 4, [(0.5, 0.05)], [(0.5, 1 / 6)]), claims, tables, "FEM gold",
                      {0.25: {"max_H_difference_over_L": 0.0101, "dW1_difference": 0.0078}}, None,
                      Snapshots(skipped="no plate runs"), [figure],
                      Timings(model_wall_time_s=3.4, report_wall_time_s=12.0))


def _shown(text: str) -> str:
    """A cell's whole text as a pattern: as it is, or folded in <details> behind its beginning
    (a long cell, validation.report.FOLD)."""
    return f"(?:{re.escape(text)}|<details><summary>[^<]*</summary>{re.escape(text)}</details>)"


def _in_md(row: dict, columns: list[str], md: str) -> bool:
    """The row is a line of the Markdown, each cell whole (folded or not)."""
    from validation.report import cell

    pattern = re.compile(r"\| " + " \\| ".join(_shown(cell(row.get(c)).replace("|", "/")) for c in columns) + r" \|")
    return any(pattern.fullmatch(line) for line in md.splitlines())


def _in_html(row: dict, columns: list[str], page: str) -> bool:
    """The row's cells are consecutive cells of the page, each whole (folded or not)."""
    import html

    from validation.report import cell

    return re.search("".join(f"<td>{_shown(html.escape(cell(row.get(c))))}</td>" for c in columns), page) is not None


def test_templates_render_every_table_row_and_claim_from_the_data():
    pytest.importorskip("jinja2")
    from validation.report import render_html, render_markdown

    data = _hand_made_report()
    md, page = render_markdown(data), render_html(data)
    for table in data.tables.values():
        for row in table.rows:
            assert _in_md(row, table.shown_columns, md), (table.name, row)
            assert _in_html(row, table.shown_columns, page), (table.name, row)
    for claim in data.claims:
        assert claim["claim"] in md and claim["reason"] in md and claim["claim"] in page
    assert "a <b> & c / d" in md and "a &lt;b&gt; &amp; c | d" in page and "<b>" not in page  # HTML autoescaped
    assert "message" not in md and "path complete" not in md  # the stability map's hidden column
    assert "3 model runs (3 requested), FEM gold scenes used: 1; no FEM gold data for dL/L=1/2 W/L=1/6" in md
    assert "- ribbon W/L = 1/20, dL/L = 1/2 (resolution 101): missed pitchfork; reached 0.8175 of dW_max 0.8175" in md
    assert "- rod at W/L = 1/20, dL/L = 1/2: dW2/L = 0.4598 against the paper's 0.52 (-11.6 %)." in md
    assert "dW1/L = 0.3516" not in md  # -2.3 % from the paper: within the 10 % the list states
    assert "- nu = 0.25 vs nu = 0: max |H_mid difference| = 0.0101 L, dW1 difference = 0.0078" in md
    assert "![poisson](figures/poisson.png)" in md and "*Rod, nu against nu = 0.*" in md
    assert page.count("data:image/png;base64,") == 1 and data.figures[0].png_base64 in page
    assert "Report built in 12 s" in md and "Report built in 12 s" in page
    assert "Skipped: no plate run of this profile kept its frames" in md


def test_a_failing_claim_renders_as_failing():
    """The verdict word follows the numbers: above its bound a claim is listed as not holding, in
    bold, its row flagged in the HTML; at or below its bound every claim holds."""
    pytest.importorskip("jinja2")
    from validation.report import render_html, render_markdown

    bound = C.CLAIMS["fem_elastica"].bound
    failing = _hand_made_report([C.evaluate("rod_elastica", 2e-4), C.evaluate("fem_elastica", 1.01 * bound)])
    md, page = render_markdown(failing), render_html(failing)
    assert (f"**1 of 2 claims do not hold (1 fail, 0 undecided): fem_elastica (fails: measured {1.01 * bound:.4g} > "
            f"bound {bound:g}).**") in md
    assert "All 2 claims hold" not in md and "All 2 claims hold" not in page
    fem_row = next(line for line in md.splitlines() if line.startswith("| fem_elastica |"))
    assert "| False |" in fem_row
    assert page.count('class="fails"') == 1 and "<strong>1 of 2 claims do not hold" in page
    holding = _hand_made_report([C.evaluate("rod_elastica", 2e-4), C.evaluate("fem_elastica", bound)])
    md, page = render_markdown(holding), render_html(holding)
    assert "All 2 claims hold: each measured value is at or below its bound." in md and "do not hold" not in md
    assert 'class="fails"' not in page and "All 2 claims hold" in page


def test_a_missing_jinja2_stops_the_report_before_any_run_with_one_line(monkeypatch, tmp_path, capsys):
    import sys

    from validation import report
    from validation.__main__ import main

    def refuse(*args, **kwargs):
        raise AssertionError("a run started without the report's extras")

    monkeypatch.setitem(sys.modules, "jinja2", None)  # `import jinja2` raises ImportError
    monkeypatch.setattr(report, "run_all", refuse)
    with pytest.raises(report.MissingExtra) as error:
        report.build_report("smoke", tmp_path / "out")
    message = str(error.value)
    assert "\n" not in message and "jinja2" in message and "pip install 'ddg-strips[report]'" in message
    assert not (tmp_path / "out").exists()
    with pytest.raises(report.MissingExtra):
        report.render_markdown(_hand_made_report())
    assert main(["report", "--smoke", "--out", str(tmp_path / "cli"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err == f"error: {message}\n"


# ---------------------------------------------------------------------------- the error map's sections
def _map_row(compression, width, model, label, bounds, wall, slenderness=None, dW1=0.3, dW2=0.5):
    """One error-map row (the columns of validation/error_map/ that the report uses) with the given
    dW1/dW2/H_mid error-plus-bar bounds."""
    from ddg import Strip

    lb = slenderness or Strip.from_ratios(width, compression).slenderness
    row = {"compression_ratio": str(compression), "width_ratio": str(width), "slenderness": str(lb),
           "model": model, "resolution": label[1:], "resolution_label": label, "dW1": str(dW1), "dW2": str(dW2),
           "ref_dW1": "0.31", "ref_dW2": "0.49", "wall_time_s": str(wall), "reason": ""}
    for q, b in zip(("dW1", "dW2", "H_mid"), bounds):
        row[f"{q}_bound"] = "" if b is None else str(b)
        row[f"{q}_error"] = "" if b is None else str(b / 2)
    return row


def test_the_ribbon_and_error_map_sections_render_from_the_map():
    """The '1D models with width' and 'which model is enough' sections: every row of the tables
    built from an error map (validation.report_data.wide_ribbon_table, enough_table) is rendered,
    and the counting sentence is computed from the table (1 of 2 scenes within 0.01 on all three,
    2 on dW1 alone)."""
    pytest.importorskip("jinja2")
    from validation.report import render_html, render_markdown
    from validation.report_data import ENOUGH_COLUMNS, WIDE_COLUMNS, Table, enough_table, wide_ribbon_table

    rows = [_map_row(0.5, 0.05, "rod", "M100", (0.005, 0.05, 0.09), 0.8),
            _map_row(0.5, 0.05, "ribbon-trapeze", "M101", (0.04, 0.02, 0.05), 1.5),
            _map_row(0.5, 0.05, "fem", "N64x8", (0.004, 0.003, 0.004), 80.0),
            _map_row(0.25, 1 / 3, "plate", "R16", (0.009, 0.008, 0.0097), 62.0),
            _map_row(0.25, 1 / 3, "plate", "R24", (0.007, 0.003, 0.005), 120.0)]
    wide, enough = wide_ribbon_table(rows), enough_table(rows)
    assert [(r["model"], r["resolution"]) for r in wide] == [("rod", "M100"), ("ribbon-trapeze", "M101"),
                                                              ("plate", "R24")]
    assert [(r["on_dW1"], r["on_all_three"]) for r in enough] == [("rod M100", "none"), ("plate R16", "plate R16")]
    # the map per tolerance (issue 32): nothing on the narrow scene before 0.09 (the rod's H_mid)
    assert [(r["on_all_three_0_02"], r["on_all_three_0_05"]) for r in enough] == [
        ("none", "ribbon-trapeze M101 (1.5 s)"), ("plate R16 (62 s)", "plate R16 (62 s)")]
    data = _hand_made_report()
    data.tables["wide_ribbons"] = Table("wide_ribbons", WIDE_COLUMNS, wide, csv=True)
    data.tables["enough"] = Table("enough", ENOUGH_COLUMNS, enough, csv=True)
    md, page = render_markdown(data), render_html(data)
    for table in (data.tables["wide_ribbons"], data.tables["enough"]):
        for row in table.rows:
            assert _in_md(row, table.shown_columns, md), (table.name, row)
            assert _in_html(row, table.shown_columns, page), (table.name, row)
    assert "## 1D models with width" in md and "## Which model is enough (error map)" in md
    assert "1 of 2 scenes have a model within 0.01 L on all three; 2 on dW1 alone." in md
    assert "within 0.02 L and 0.05 L on all three (1 and 2 scenes have one)" in md
