"""path.csv names each column once, whichever writer made it: a model's own trailing columns
that repeat an extra (the shell's negative_eigenvalues) are written once, with the extras."""
import csv

from ddg.analysis.observables import EXTRA_COLUMNS, PATH_COLUMNS
from ddg.output.io import RunFolder, write_path_csv

TRAILING = ("negative_eigenvalues", "wall_time_s")


def _row():
    row = {c: 0.0 for c in PATH_COLUMNS}
    row.update({"stage": "shear", "phase": "U", "negative_eigenvalues": 2, "stable": 0, "wall_time_s": 1.5})
    return row


def _header_and_row(path):
    with open(path, newline="") as handle:
        reader = csv.reader(handle)
        return next(reader), next(reader)


def test_the_whole_file_writer_names_a_repeated_trailing_column_once(tmp_path):
    write_path_csv(tmp_path / "path.csv", [_row()], trailing=TRAILING)
    header, values = _header_and_row(tmp_path / "path.csv")
    assert len(header) == len(set(header))
    assert header[:len(PATH_COLUMNS)] == list(PATH_COLUMNS)
    assert header.index("negative_eigenvalues") < header.index("wall_time_s") == len(header) - 1
    assert values[header.index("negative_eigenvalues")] == "2"


def test_the_streaming_writer_names_a_repeated_trailing_column_once(tmp_path):
    folder = RunFolder(tmp_path / "run", trailing=TRAILING)
    folder.append(_row())
    folder.close()
    header, _ = _header_and_row(tmp_path / "run" / "path.csv")
    assert len(header) == len(set(header))
    assert [c for c in header if c in EXTRA_COLUMNS] == ["stable", "negative_eigenvalues"]
