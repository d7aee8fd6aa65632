"""`python -m fem_reference` on bad input and on Ctrl-C (issue 13).

Every bad input is refused with one line on stderr (`error: ...` naming the value or option),
exit code 2, before any FEM work: the FEM modules (dolfinx, gmsh, PETSc, and fem_reference's
shell, solver, continuation) are made unimportable for those tests, so a case that reached them
would fail with another exit code. The interrupt tests run a real but tiny model (8 x 2
elements, a few recorded steps) with the load stepping replaced by a KeyboardInterrupt or a
ContinuationFailure after a few steps, and check what is on disk.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from ddg.geometry.strip import InputError, LoadingProtocol, Strip

SCENE = ["--width-ratio", "0.1667", "--compression-ratio", "0.5"]
FEM_MODULES = ("dolfinx", "dolfinx.io", "dolfinx.fem", "gmsh", "petsc4py", "slepc4py", "mpi4py", "basix", "ffcx",
               "ufl", "fem_reference.shell", "fem_reference.solver", "fem_reference.continuation")
GIB = 2.0**30


pytestmark = pytest.mark.usefixtures("restore_signal_handlers")  # tests/conftest.py


@pytest.fixture
def no_fem(monkeypatch):
    """Make every FEM module unimportable (an import raises ImportError): a rejection must come
    before any of them. Also a fixed memory budget (8 GiB of a 16 GiB machine) for determinism."""
    for name in FEM_MODULES:
        monkeypatch.setitem(sys.modules, name, None)
    import ddg.limits

    monkeypatch.setattr(ddg.limits, "available_memory_bytes", lambda: 16 * GIB)


def run_cli(argv, capsys):
    from fem_reference.cli import main

    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.err


def assert_refused(argv, capsys, *fragments):
    code, err = run_cli(argv, capsys)
    assert code == 2, (code, err)
    assert "Traceback" not in err
    assert err.endswith("\n") and err.count("\n") == 1, repr(err)
    assert err.startswith("error: "), repr(err)
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    return err


# --- scene and steps (ddg validates the scene; the step counts by ddg.limits.check_steps) -------------
@pytest.mark.parametrize("option, value, fragment", [
    ("--compression-steps", "0", "--compression-steps"),
    ("--compression-steps", "-3", "--compression-steps"),
    ("--compression-steps", "5001", "5001"),
    ("--shear-steps", "0", "--shear-steps"),
    ("--shear-steps", "100000", "100000"),
    ("--width-ratio", "0", "width_ratio"),
    ("--width-ratio", "nan", "width_ratio"),
    ("--width-ratio", "1.5", "width_ratio"),
    ("--compression-ratio", "1.5", "compression_ratio"),
    ("--compression-ratio", "inf", "compression_ratio"),
    ("--poisson-ratio", "0.5", "poisson_ratio"),
    ("--slenderness", "1e9", "slenderness"),
    ("--shear-ratio", "5", "5"),
])
def test_scene_and_steps_refused(no_fem, capsys, option, value, fragment):
    options = {"--width-ratio": "0.1667", "--compression-ratio": "0.5", option: value}
    assert_refused(["simulate", *[a for pair in options.items() for a in pair], "--quiet"], capsys, fragment)


# --- mesh bounds ------------------------------------------------------------------------------------
@pytest.mark.parametrize("value", ["100000000", "401", "3", "0", "-60"])
def test_resolution_bounds(no_fem, capsys, value):
    assert_refused(["simulate", *SCENE, "--resolution", value, "--quiet"], capsys, "--resolution", value, "[4, 400]")


@pytest.mark.parametrize("value", ["0", "1", "-2", "401", "100000000"])
def test_across_bounds(no_fem, capsys, value):
    err = assert_refused(["simulate", *SCENE, "--across", value, "--quiet"], capsys, "--across", value, "[2, 400]")
    assert "centre" in err  # why an even count at least 2


def test_mesh_refused_by_its_memory_estimate(no_fem, capsys):
    """400 x 400 elements (3.1M unknowns, ~40 GiB estimated) against a budget of 8 GiB."""
    err = assert_refused(["simulate", *SCENE, "--resolution", "400", "--across", "400", "--quiet"], capsys,
                         "--resolution", "--across", "GiB", "unknowns")
    assert "400 x 400" in err


def test_unknown_counts_and_estimates():
    """MeshSpec.n_dof is the Naghdi discretisation's count (as NaghdiStrip reports it: 24 x 10 in
    tests/fem_reference/test_fem_reference.py, 60 x 10 and 120 x 20 in fem_reference/README.md); the gold and
    default meshes fit a 8 GiB budget, the largest allowed mesh of the widest strip does not."""
    from fem_reference.mesh import MeshSpec

    assert MeshSpec(24, 10, 1 / 6).n_dof == 6585
    assert MeshSpec(60, 10, 1 / 6).n_dof == 16305
    assert MeshSpec(120, 20, 1 / 6).n_dof == 63805
    assert MeshSpec.from_resolution(120, 1 / 2).estimated_memory_bytes() < 3 * GIB  # 189k unknowns
    assert MeshSpec.from_resolution(400, 1.0).estimated_memory_bytes() > 8 * GIB


def test_default_and_gold_meshes_pass(monkeypatch):
    """Every mesh of every gold study fits a 16 GiB machine and is refined by exactly 1.5 in both
    directions from one level to the next (Richardson needs uniform refinement)."""
    import ddg.limits
    from fem_reference.gold import REFINEMENT, WIDTH_RATIOS, mesh_sequence
    from fem_reference.mesh import checked_spec

    monkeypatch.setattr(ddg.limits, "available_memory_bytes", lambda: 16 * GIB)
    for width in WIDTH_RATIOS:
        meshes = mesh_sequence(width)
        assert [along for along, _ in meshes] == [64, 96, 144]
        for (a0, c0), (a1, c1) in zip(meshes, meshes[1:]):
            assert a1 / a0 == c1 / c0 == REFINEMENT
        for along, across in meshes:
            spec = checked_spec(along, width, across)
            assert (spec.nx, spec.ny) == (along, across)
    assert checked_spec(5, 1 / 6, 3).nx == 6 and checked_spec(5, 1 / 6, 3).ny == 4  # odd rounded up to even


# --- branch-switch perturbation ------------------------------------------------------------------------
@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e300", "0", "-1e-3", "0.2", "1e-300"])
def test_perturbation_bounds(no_fem, capsys, value):
    assert_refused(["simulate", *SCENE, "--perturbation", value, "--quiet"], capsys, "--perturbation")


# --- argparse: one line, no usage block ----------------------------------------------------------------------
@pytest.mark.parametrize("argv, fragment", [
    (["simulate", *SCENE, "--resolution", "abc"], "--resolution"),
    (["simulate", *SCENE, "--resolution", "1e9"], "--resolution"),
    (["simulate", *SCENE, "--across", "2.5"], "--across"),
    (["simulate", "--width-ratio", "0.1667"], "--compression-ratio"),
    (["simulate", *SCENE, "--foo", "1"], "--foo"),
    (["simulate", *SCENE, "--shear-sign", "2"], "--shear-sign"),
    (["simulate", *SCENE, "--material", "steel"], "steel"),
    (["simulate", "--width-ratio", "x", "--compression-ratio", "0.5"], "--width-ratio"),
    (["simulat"], "simulat"),
    ([], "command"),
    (["gold"], "--out"),
    (["convergence", *SCENE, "--out", "x", "--resolutions"], "--resolutions"),
    (["convergence-table", "--out", "x"], "--runs"),
])
def test_argparse_errors_are_one_line(no_fem, capsys, argv, fragment):
    err = assert_refused(argv, capsys, fragment)
    assert "usage" not in err


# --- output directory (ddg.output.io.check_output_directory), every command ---------------------------------------
def _bad_out(kind: str, tmp_path: Path) -> str:
    file = tmp_path / "a_file"
    file.write_text("x")
    return {"existing file": str(file), "/dev/null": "/dev/null", "under a file": str(file / "sub"),
            "too long": str(tmp_path / ("x" * 300)), "empty": ""}[kind]


COMMANDS = {
    "simulate": ["simulate", *SCENE, "--resolution", "8", "--quiet", "--out"],
    "convergence": ["convergence", *SCENE, "--resolutions", "8", "12", "--quiet", "--out"],
    "gold": ["gold", "--only", "dL0.5_W0.1667", "--quiet", "--out"],
}


@pytest.mark.parametrize("kind", ["existing file", "/dev/null", "under a file", "too long", "empty"])
@pytest.mark.parametrize("command", sorted(COMMANDS) + ["convergence-table"])
def test_bad_output_directory(no_fem, capsys, tmp_path, command, kind):
    out = _bad_out(kind, tmp_path)
    if command == "convergence-table":
        runs = [_fake_run(tmp_path / f"N{n}", n) for n in (8, 12)]
        argv = ["convergence-table", "--runs", *runs, "--out", out]
    else:
        argv = [*COMMANDS[command], out]
    assert_refused(argv, capsys, "--out")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only directories")
def test_read_only_output_directory(no_fem, capsys, tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        assert_refused(["simulate", *SCENE, "--quiet", "--out", locked / "run"], capsys, "--out")
        assert_refused(["simulate", *SCENE, "--quiet", "--out", locked], capsys, "--out", "not writable")
    finally:
        locked.chmod(0o700)


@pytest.mark.skipif(not os.path.isdir("/sys/kernel"), reason="no /sys")
def test_unwritable_system_directory(no_fem, capsys):
    """/sys is read-only even for root (the case of a read-only directory when tests run as root)."""
    assert_refused(["simulate", *SCENE, "--quiet", "--out", "/sys/kernel"], capsys, "--out", "/sys/kernel")


# --- gold, convergence, convergence-table ------------------------------------------------------------------
def test_gold_unknown_scene_lists_the_known(no_fem, capsys, tmp_path):
    err = assert_refused(["gold", "--out", tmp_path, "--only", "dL0.5_W0.1667", "nope"], capsys, "'nope'",
                         "dL0.5_W0.1667", "dL0.25_W0.5")
    assert "dL0.5_W0.1667," in err  # the known names listed, the valid one not reported unknown
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("value", ["2", "100000", "-1"])
def test_gold_resolution_bounds(no_fem, capsys, tmp_path, value):
    assert_refused(["gold", "--out", tmp_path / "g", "--resolution", value], capsys, "--resolution", value)
    assert not (tmp_path / "g").exists()  # refused before the output folder is made


@pytest.mark.parametrize("values, fragment", [
    (["2", "60"], "[4, 400]"),
    (["60", "100000"], "100000"),
    (["60"], "2 to 6"),
    (["60", "60"], "same mesh"),
    (["59", "60"], "same mesh"),
    (["12", "16", "20", "24", "28", "32", "36"], "2 to 6"),
])
def test_convergence_resolutions(no_fem, capsys, tmp_path, values, fragment):
    assert_refused(["convergence", *SCENE, "--out", tmp_path / "c", "--resolutions", *values, "--quiet"], capsys,
                   "--resolutions", fragment)
    assert not (tmp_path / "c").exists()


def _fake_run(folder: Path, resolution: int, status: str = "complete", width: float = 1 / 6) -> str:
    """A run folder with the files and keys convergence-table reads."""
    folder.mkdir(parents=True, exist_ok=True)
    summary = {"model": "fem", "scene": {"width_ratio": width, "compression_ratio": 0.5, "slenderness": 1181.1,
                                         "resolution": resolution},
               "mesh": {"triangles": 2 * resolution * 2}, "n_dof": 100, "recorded_steps": 3, "dW1_over_L": 0.26,
               "dW2_over_L": 0.43, "wall_time_s": 1.0, "newton_iterations": 10, "converged": status == "complete",
               "status": status, "H_mid_over_L_compressed": 0.37}
    (folder / "summary.json").write_text(json.dumps(summary))
    (folder / "path.csv").write_text("stage,dL_over_L,dW_over_L,H_mid_over_L,phase\n"
                                     "compression,0.5,0.0,0.37,U\nshear,0.5,0.1,0.3,U\nshear,0.5,0.2,0.25,U\n")
    return str(folder)


@pytest.mark.parametrize("case, fragment", [
    ("missing", "is not a directory"),
    ("one run", "2 or more"),
    ("no summary", "no summary.json"),
    ("corrupt summary", "not a run folder"),
    ("running", "'running'"),
    ("no shear", "no shear steps"),
    ("two scenes", "different scenes"),
    ("same mesh", "repeat"),
])
def test_convergence_table_runs(no_fem, capsys, tmp_path, case, fragment):
    good = _fake_run(tmp_path / "N8", 8)
    other = tmp_path / "other"
    if case == "missing":
        runs = [good, str(tmp_path / "nonexistent")]
    elif case == "one run":
        runs = [good]
    elif case == "no summary":
        other.mkdir()
        (other / "path.csv").write_text("stage\n")
        runs = [good, str(other)]
    elif case == "corrupt summary":
        _fake_run(other, 12)
        (other / "summary.json").write_text("{not json")
        runs = [good, str(other)]
    elif case == "running":
        runs = [good, _fake_run(other, 12, status="running")]
    elif case == "no shear":
        _fake_run(other, 12)
        (other / "path.csv").write_text("stage,dL_over_L,dW_over_L,H_mid_over_L,phase\ncompression,0.5,0.0,0.37,U\n")
        runs = [good, str(other)]
    elif case == "two scenes":
        runs = [good, _fake_run(other, 12, width=1 / 20)]
    else:
        runs = [good, _fake_run(other, 8)]
    assert_refused(["convergence-table", "--runs", *runs, "--out", tmp_path / "table"], capsys, fragment)
    assert not (tmp_path / "table").exists()


# --- the Python API checks the same before any work ----------------------------------------------------------
@pytest.mark.parametrize("kwargs, fragment", [
    ({"resolution": 10**8}, "resolution"),
    ({"resolution": 2}, "resolution"),
    ({"resolution": True}, "resolution"),
    ({"resolution": 60.5}, "resolution"),
    ({"across": 0}, "across"),
    ({"material": "steel"}, "material"),
    ({"options": type("Options", (), {"perturbation": float("nan")})()}, "perturbation"),
    ({"out": "/dev/null"}, "out"),
    ({"out": ""}, "out"),
    ({"fields": "yes"}, "fields"),
])
def test_api_refuses_before_any_work(no_fem, tmp_path, kwargs, fragment):
    from fem_reference.api import simulate

    strip = Strip.from_ratios(1 / 6, 0.5)
    protocol = LoadingProtocol(0.5, compression_steps=2, shear_steps=2)
    kwargs = {"resolution": 8, **kwargs}
    resolution = kwargs.pop("resolution")
    with pytest.raises(InputError) as info:
        simulate(strip, protocol, resolution, **kwargs)
    assert fragment in str(info.value) and "\n" not in str(info.value)


def test_module_entry_point_one_line_and_no_fem_import(tmp_path):
    """The real command (`python -m fem_reference`): exit 2, one line, and the rejection did not
    import dolfinx or gmsh."""
    code = ("import sys; from fem_reference.cli import main; rc = main(sys.argv[1:]); "
            "print('dolfinx' in sys.modules, 'gmsh' in sys.modules); raise SystemExit(rc)")
    proc = subprocess.run([sys.executable, "-c", code, "simulate", *SCENE, "--resolution", "100000000"],
                          capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2], timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout.split() == ["False", "False"]
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("error: --resolution = 100000000")


# --- Ctrl-C, SIGTERM and a path that stops converging: nothing converged is lost ------------------------------
TINY = ["simulate", *SCENE, "--resolution", "8", "--across", "2", "--compression-steps", "3", "--shear-steps", "4",
        "--quiet"]


@pytest.fixture
def fem():
    pytest.importorskip("dolfinx", reason="fem_reference needs dolfinx")
    pytest.importorskip("slepc4py", reason="fem_reference needs slepc4py")
    from fem_reference import continuation

    return continuation


def _stop_advance_at(monkeypatch, continuation, call: int, exc_factory, out: Path | None = None, seen=None):
    """Stepper.advance raises exc_factory() at its `call`-th call (the earlier ones are real);
    before raising, what is on disk is recorded in `seen` (path.csv rows, summary status)."""
    original = continuation.Stepper.advance
    count = [0]

    def advance(self, target):
        count[0] += 1
        if count[0] == call:
            if out is not None and seen is not None:
                seen["rows"] = len((out / "path.csv").read_text().splitlines()) - 1
                seen["status"] = json.loads((out / "summary.json").read_text())["status"]
            raise exc_factory()
        return original(self, target)

    monkeypatch.setattr(continuation.Stepper, "advance", advance)


def _read(out: Path):
    rows = (out / "path.csv").read_text().splitlines()
    return rows[1:], json.loads((out / "summary.json").read_text())


def test_ctrl_c_keeps_every_converged_step(fem, monkeypatch, capsys, tmp_path):
    """SIGINT at the third compression step: the first two and the rest state are in path.csv (appended
    and flushed as they were recorded: on disk before the interrupt, summary then 'running'),
    summary.json says interrupted, not converged; exit 130 with one line naming the folder."""
    seen = {}
    _stop_advance_at(monkeypatch, fem, 3, KeyboardInterrupt, tmp_path, seen)
    code, err = run_cli([*TINY, "--out", tmp_path], capsys)
    assert code == 130, err
    assert seen == {"rows": 3, "status": "running"}
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("error: interrupted by SIGINT during the compression stage") and str(tmp_path) in err
    rows, summary = _read(tmp_path)
    assert len(rows) == 3 == summary["recorded_steps"]
    assert summary["status"] == "interrupted" and summary["converged"] is False
    assert summary["path_complete"] is False and summary["dW1_over_L"] is None
    assert "interrupted by SIGINT" in summary["message"]
    assert (tmp_path / "centerline.csv").exists() and (tmp_path / "fields.xdmf").exists()
    handler = signal.getsignal(signal.SIGINT)
    assert callable(handler), handler  # gmsh's SIG_DFL did not survive the meshing


def test_sigterm_during_threshold_location(fem, monkeypatch, capsys, tmp_path):
    """SIGTERM (as ddg.output.interrupts raises it) while dW1 is bisected, after the path (the
    thresholds are steps after it, ddg.protocol; on this 8 x 2 mesh the path stops where the
    switch from the first unstable U fails): every recorded step is written, including the
    unstable-U row the bisection's bracket ends at; no threshold reported; exit 143."""
    from ddg.output.interrupts import RunInterrupted

    def locate_dw1(*args, **kwargs):
        raise RunInterrupted("SIGTERM")

    monkeypatch.setattr(fem, "locate_dw1", locate_dw1)
    code, err = run_cli([*TINY, "--out", tmp_path, "--no-fields"], capsys)
    assert code == 143, err
    assert err.count("\n") == 1 and err.startswith("error: interrupted by SIGTERM during threshold location")
    rows, summary = _read(tmp_path)
    assert summary["status"] == "interrupted" and summary["converged"] is False
    assert summary["dW1_over_L"] is None and summary["dW2_over_L"] is None
    assert len(rows) == summary["recorded_steps"] == 1 + 3 + 2  # rest, 3 compression, 2 shear
    assert rows[-1].split(",")[0] == "shear" and rows[-1].split(",")[7] == "U"  # the unstable U state


def test_api_interrupt_attaches_the_result(fem, monkeypatch, tmp_path):
    from fem_reference.api import simulate

    _stop_advance_at(monkeypatch, fem, 2, KeyboardInterrupt)
    strip = Strip.from_ratios(1 / 6, 0.5)
    protocol = LoadingProtocol(0.5, compression_steps=3, shear_steps=4)
    with pytest.raises(KeyboardInterrupt) as info:
        simulate(strip, protocol, 8, across=2, out=tmp_path, fields=False)
    result = info.value.result
    assert result is not None and len(result.rows) == 2 and not result.converged
    assert result.summary["status"] == "interrupted"
    rows, summary = _read(tmp_path)
    assert len(rows) == 2 and summary["status"] == "interrupted"


def test_stopped_path_exit_3_and_no_threshold_claimed(fem, monkeypatch, capsys, tmp_path):
    """A path that stops converging: exit 3, one line saying where, the converged part written with
    status 'stopped', no threshold (none was located)."""
    _stop_advance_at(monkeypatch, fem, 3, lambda: fem.ContinuationFailure("load step below 1e-07 L"))
    code, err = run_cli([*TINY, "--out", tmp_path, "--no-fields"], capsys)
    assert code == 3, err
    assert err.count("\n") == 1 and err.startswith("error: run did not complete: stopped converging at dL/L")
    assert "no threshold located" in err and str(tmp_path) in err
    rows, summary = _read(tmp_path)
    assert len(rows) == 3 and summary["status"] == "stopped" and summary["converged"] is False
    assert summary["dW1_over_L"] is None and summary["dW2_over_L"] is None


def test_a_new_run_clears_the_old_results(fem, monkeypatch, capsys, tmp_path):
    """Files of an earlier run in the folder are removed at the start (RunFolder): an interrupted run
    leaves no stale centerline.csv or fields.xdmf from another scene."""
    for name in ("centerline.csv", "fields.xdmf", "fields.h5", "branches.csv"):
        (tmp_path / name).write_text("stale")
    _stop_advance_at(monkeypatch, fem, 1, KeyboardInterrupt)
    code, _ = run_cli([*TINY, "--out", tmp_path, "--no-fields"], capsys)
    assert code == 130
    assert not (tmp_path / "fields.xdmf").exists() and not (tmp_path / "branches.csv").exists()
    rows, summary = _read(tmp_path)
    assert len(rows) == 1 and summary["status"] == "interrupted"


def test_keep_python_sigint_undoes_gmsh_reset():
    from fem_reference.mesh import keep_python_sigint

    handler = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # what gmsh.py does on import
    keep_python_sigint(handler)
    assert signal.getsignal(signal.SIGINT) is (handler if callable(handler) else signal.default_int_handler)
