"""Tables and figure data: what every room of validation hands to the writers.

Table is the one table class: the report's tables (rows computed in memory) and the error map's
CSV file (rows read from it and replaced one key at a time) alike. FigureData is one figure's
table (its CSV, in column order) with the marks it draws besides. `fraction` and `fraction_label`
write the paper's ratios in tables, captions and figures ("1/20").
"""
from __future__ import annotations

import base64
import csv
import io
import math
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from ddg.output.io import atomic_write_text


def fraction(x: float) -> str:
    """1/d for the ratios the paper uses (0.05 -> "1/20"), else 4 significant digits."""
    for d in (2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20):
        if abs(x - 1 / d) < 1e-6:
            return f"1/{d:g}"
    return f"{x:.4g}"


def fraction_label(x: float) -> str:
    """A ratio as the nearest fraction with denominator <= 100 ("1/12", "1/4", "3")."""
    f = Fraction(float(x)).limit_denominator(100)
    return f"{f.numerator}/{f.denominator}" if f.denominator != 1 else str(f.numerator)


def csv_cell(value):
    """A value as a CSV cell: '' for None and for a non-finite float, a float at full precision
    (repr, as the csv module writes it), anything else as it is."""
    if value is None:
        return ""
    if isinstance(value, float):
        return "" if not math.isfinite(value) else repr(value)
    return value


def write_csv(path: Path, columns: list[str], rows: list[list]) -> None:
    """A header and rows of cells as a CSV file, written atomically: a non-finite float (and None)
    as an empty cell, the rest as the csv module writes it."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(columns)
    for row in rows:
        writer.writerow(["" if (isinstance(v, float) and not math.isfinite(v)) else v for v in row])
    atomic_write_text(Path(path), buf.getvalue())


@dataclass
class Table:
    """Rows of one table (dicts keyed by column), written in `columns` order.

    `csv`: the report writes it as DIR/<name>.csv (the other tables' numbers are in their figure's
    CSV); `shown`: the columns the report prints (default all). A table kept in a CSV file
    (`path`; Table.read) holds its cells as the file does, strings with '' for an empty cell:
    `put` replaces the row of its `key` (the values of the key columns) and rewrites the file.
    """
    name: str
    columns: list[str]
    rows: list[dict]
    csv: bool = False
    shown: list[str] | None = None
    path: Path | None = None
    key: tuple[str, ...] = ()

    @property
    def shown_columns(self) -> list[str]:
        return self.columns if self.shown is None else self.shown

    @classmethod
    def read(cls, path: Path, name: str | None = None, columns: list[str] | None = None,
             key: tuple[str, ...] = ()) -> Table:
        """The CSV file at `path` (its rows as strings, '' for an empty cell; none if the file does
        not exist); the columns are the file's header unless given."""
        path = Path(path)
        rows, header = [], []
        if path.exists():
            with open(path, newline="") as fh:
                reader = csv.DictReader(fh)
                rows = list(reader)
                header = list(reader.fieldnames or [])
        return cls(name or path.stem, list(columns) if columns is not None else header, rows, path=path,
                   key=tuple(key))

    def key_of(self, row: dict) -> tuple:
        """The values of the key columns of `row`, as strings (as a row read from the file has them)."""
        return tuple(str(row.get(c)) for c in self.key)

    def put(self, row: dict) -> None:
        """`row` (its cells as csv_cell writes them) in place of the row of its key: the other rows
        are kept in their order, the new one last; the file is rewritten atomically."""
        row = {c: csv_cell(row.get(c)) for c in self.columns}
        self.rows = [r for r in self.rows if self.key_of(r) != self.key_of(row)] + [row]
        self.write()

    def write(self, path: Path | None = None) -> None:
        """The rows in column order as a CSV file (default the table's own file), atomically."""
        write_csv(Path(path) if path is not None else self.path, self.columns,
                  [[r.get(c) for c in self.columns] for r in self.rows])


@dataclass
class FigureData:
    """One figure: `rows` (in `columns` order) are its CSV and every number it plots from data;
    `marks` the reference lines and layout it draws besides (analytic curves, paper values,
    threshold lines, panels); `kind` names its drawing function in validation/figures.
    `png` is set once drawn (the HTML embeds it)."""
    name: str
    kind: str
    caption: str
    columns: list[str]
    rows: list[list]
    marks: dict = field(default_factory=dict)
    png: bytes | None = None

    @property
    def files(self) -> dict[str, str]:
        return {ext: f"figures/{self.name}.{ext}" for ext in ("png", "pdf", "csv")}

    @property
    def png_base64(self) -> str:
        return base64.b64encode(self.png or b"").decode()

    @property
    def png_size(self) -> tuple[int, int] | None:
        """(width, height) in pixels of the drawn PNG (its IHDR chunk), None before it is drawn: the
        HTML gives its image this size so the page is laid out before the image loads."""
        if not self.png or self.png[:8] != b"\x89PNG\r\n\x1a\n" or len(self.png) < 24:
            return None
        return int.from_bytes(self.png[16:20], "big"), int.from_bytes(self.png[20:24], "big")

    def records(self) -> list[dict]:
        return [dict(zip(self.columns, row)) for row in self.rows]


def records_figure(name: str, kind: str, caption: str, data: list[dict], marks: dict | None = None) -> FigureData:
    """A figure whose CSV is a table's rows (dicts of the same keys, in order)."""
    return FigureData(name, kind, caption, list(data[0].keys()) if data else ["model"],
                      [list(d.values()) for d in data], marks or {})
