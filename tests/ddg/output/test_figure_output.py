"""Regenerated figures are byte-identical (issue 28, item 5): ddg.output.io.save_figure leaves out
matplotlib's date and software stamps and fixes the SVG ids, for every format the project writes
(PNG, PDF; SVG too), and it is the one place the project saves a figure."""
import re
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")

from ddg.output.io import FIGURE_METADATA, figure_bytes, save_figure  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
FORMATS = tuple(FIGURE_METADATA)


def drawing():
    """A small figure with what the project's figures have: lines, a filled area, mathtext, a legend."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3.0, 2.0))
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    ax.fill_between([0.0, 1.0], 0.0, [0.2, 0.5], color="#dbe9f6")
    ax.errorbar([0.3, 0.6], [0.4, 0.7], yerr=[0.05, 0.02], fmt="^", color="black", capsize=3, label="gold")
    ax.plot([0.0, 1.0], [0.1, 0.9], "o-", label=r"$\Delta W_1/L$")
    ax.legend(fontsize=6)
    ax.set_title("dL/L = 1/2")
    return fig


@pytest.mark.parametrize("fmt", FORMATS)
def test_the_same_figure_saved_twice_gives_the_same_bytes(fmt, tmp_path, monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)   # matplotlib stamps today's date
    first = save_figure(drawing(), tmp_path / "a" / f"figure.{fmt}", dpi=80).read_bytes()
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")              # ... or 1970's: a date would differ
    second = save_figure(drawing(), tmp_path / "b" / f"figure.{fmt}", dpi=80).read_bytes()
    assert first == second
    assert figure_bytes(drawing(), fmt, dpi=80) == first
    assert len(first) > 1000 and first[:4] == {"png": b"\x89PNG", "pdf": b"%PDF", "svg": b"<?xm"}[fmt]
    # no date and no software version inside (they change with the day and with matplotlib)
    import matplotlib

    assert matplotlib.__version__.encode() not in first
    assert not re.search(rb"CreationDate|<dc:date>|Software|Producer|Creator", first)
    assert not list(tmp_path.glob("*/.figure*")), "a temporary file was left"


@pytest.mark.parametrize("fmt", ("pdf", "svg"))
def test_matplotlib_alone_would_not_be_stable(fmt, monkeypatch):
    """Why the helper exists: savefig's defaults stamp the date (PDF, SVG) and salt SVG ids at random."""
    import io

    def plain():
        buf = io.BytesIO()
        drawing().savefig(buf, format=fmt, dpi=80)
        return buf.getvalue()

    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    first = plain()
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")
    assert plain() != first


def test_an_unknown_format_is_refused():
    with pytest.raises(ValueError, match="eps"):
        figure_bytes(drawing(), "eps")


def test_save_figure_is_the_only_savefig_of_the_project():
    """Every figure goes through ddg.output.io.save_figure (no copies of its stamps elsewhere)."""
    found = []
    for package in ("ddg", "validation", "fem_reference", "benchmarks"):
        for path in sorted((ROOT / package).rglob("*.py")):
            if path == ROOT / "ddg" / "output" / "io.py":
                continue
            for number, line in enumerate(path.read_text().splitlines(), 1):
                if ".savefig(" in line or "print_figure(" in line:
                    found.append(f"{path.relative_to(ROOT)}:{number}")
    assert not found, f"figures saved without ddg.output.io.save_figure: {found}"
