"""Optional extras (issue 18 item 6): a command that needs a missing one says so in one line naming
the extra, before any work, exit 2; and `pip install .` installs ddg and fem_reference but no
top-level module named plain `validation`."""
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Runs a module as __main__ with some modules made unimportable (sys.modules[name] = None).
BLOCK = ("import runpy, sys\n"
         "for m in sys.argv[1].split(','):\n"
         "    sys.modules[m] = None\n"
         "mod = sys.argv[2]\n"
         "sys.argv = [mod] + sys.argv[3:]\n"
         "runpy.run_module(mod, run_name='__main__', alter_sys=True)\n")


@pytest.mark.parametrize("blocked, argv, extra", [
    ("matplotlib", ["ddg", "curvatures", "--out", "{tmp}/c"], "plot"),
    ("meshio", ["ddg", "simulate", "--frames", "--out", "{tmp}/f"], "io"),
    ("jinja2", ["validation", "report", "--quick", "--out", "{tmp}/r"], "report"),
    ("matplotlib", ["validation", "report", "--quick", "--out", "{tmp}/r"], "report"),
])   # render (pyvista) and dask: tests/ddg/output/test_render.py and tests/ddg/sweep/test_sweep.py
def test_a_missing_extra_is_named_in_one_line_before_any_work(blocked, argv, extra, tmp_path):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    done = subprocess.run([sys.executable, "-c", BLOCK, blocked, *argv], cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    err = done.stderr.strip()
    assert done.returncode == 2, (done.returncode, err)
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert f"ddg-strips[{extra}]" in err, err
    assert not (tmp_path / "f" / "path.csv").exists() and not (tmp_path / "c" / "curvatures.csv").exists()


def test_the_wheel_has_no_top_level_validation(tmp_path):
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                           "-w", str(tmp_path), str(ROOT)], capture_output=True, text=True, timeout=300)
    if done.returncode != 0 and "No module named" in done.stderr:
        pytest.skip(f"cannot build a wheel here: {done.stderr.strip().splitlines()[-1]}")
    assert done.returncode == 0, done.stderr
    (wheel,) = tmp_path.glob("*.whl")
    tops = {name.split("/")[0] for name in zipfile.ZipFile(wheel).namelist()}
    packages = {t for t in tops if not t.endswith((".dist-info", ".data"))}
    assert packages == {"ddg", "fem_reference"}, packages
