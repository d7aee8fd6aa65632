"""The repository stays lean (issue 28, item 5): a git-tracked file over 1 MB is there only if the
manifest tests/large_files.txt names it with the code or test that reads it, and every file the
manifest names is tracked, over the limit and referenced by its reader."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: The manifest of needed large files (path, reader, texts the reader must contain).
MANIFEST = ROOT / "tests" / "large_files.txt"
#: Largest tracked file that needs no manifest entry (bytes).
LIMIT = 1_000_000


def tracked_files() -> list[str]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout (an sdist or an installed copy): nothing tracked to check")
    done = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, timeout=60)
    if done.returncode != 0:
        pytest.skip(f"git ls-files failed: {done.stderr.decode(errors='replace').strip()}")
    return [name for name in done.stdout.decode().split("\0") if name]


def manifest() -> dict[str, tuple[str, list[str]]]:
    """{path: (reader, texts)} from the manifest; the texts default to the file's name."""
    entries: dict[str, tuple[str, list[str]]] = {}
    for number, line in enumerate(MANIFEST.read_text().splitlines(), 1):
        fields = line.split("#", 1)[0].split()
        if not fields:
            continue
        assert len(fields) >= 2, f"{MANIFEST.name}:{number}: '<path> <reader> [<text> ...]', not {line!r}"
        path, reader, texts = fields[0], fields[1], fields[2:] or [Path(fields[0]).name]
        assert path not in entries, f"{MANIFEST.name}:{number}: {path} listed twice"
        entries[path] = (reader, texts)
    return entries


def size(path: str) -> int:
    file = ROOT / path
    return file.stat().st_size if file.is_file() else 0


def test_every_tracked_file_over_1_MB_is_in_the_manifest():
    listed = manifest()
    large = sorted(p for p in tracked_files() if size(p) > LIMIT)
    unlisted = [f"{p} ({size(p) / 1e6:.1f} MB)" for p in large if p not in listed]
    assert not unlisted, (f"tracked files over {LIMIT / 1e6:g} MB that tests/large_files.txt does not list with "
                          f"their reader (keep such data out of git, or list it): {unlisted}")


def test_every_manifest_entry_is_a_large_tracked_file_its_reader_reads():
    tracked = set(tracked_files())
    for path, (reader, texts) in manifest().items():
        assert path in tracked, f"{path} is listed but not tracked (remove its line)"
        assert size(path) > LIMIT, f"{path} is {size(path)} bytes, within the limit: remove its line"
        assert reader in tracked and reader != path, f"{path}: its reader {reader} is not a tracked file"
        text = (ROOT / reader).read_text(errors="replace")
        missing = [t for t in texts if t not in text]
        assert not missing, f"{path}: {reader} does not mention {missing}, so it does not read it"


def test_the_manifest_check_has_teeth(tmp_path, monkeypatch):
    """A stale or unreferenced entry fails: the checks above are not vacuous."""
    fake = tmp_path / "large_files.txt"
    monkeypatch.setattr(sys.modules[__name__], "MANIFEST", fake)
    fake.write_text("validation/results/quick/index.html  tests/validation/test_report_html.py  no-such-text\n")
    with pytest.raises(AssertionError, match="does not mention"):
        test_every_manifest_entry_is_a_large_tracked_file_its_reader_reads()
    fake.write_text("README.md  -\n")
    with pytest.raises(AssertionError, match="within the limit"):
        test_every_manifest_entry_is_a_large_tracked_file_its_reader_reads()
    fake.write_text("# nothing listed\n")
    if any(size(p) > LIMIT for p in tracked_files()):
        with pytest.raises(AssertionError, match="does not list"):
            test_every_tracked_file_over_1_MB_is_in_the_manifest()
