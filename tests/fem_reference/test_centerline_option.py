"""centerline.csv stays part of a normal run's output (docs/reference/output_contract.rst); the mesh studies, which
read only path.csv and summary.json, leave it out with centerline=False (`--no-centerline`), and
nothing else of the run changes (issue 28, item 5)."""
import json

import pytest

import ddg
from ddg.cli import main
from ddg.geometry.strip import InputError

SMALL = dict(model="rod", resolution=20, branches=False)
PROTOCOL = ddg.LoadingProtocol(0.5, 0.1, 5, 4)
STRIP = ddg.Strip.from_ratios(0.05, 0.5)


def without_times(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if "wall_time" not in k}


def test_a_study_run_writes_path_and_summary_without_the_centerline(tmp_path):
    normal = ddg.simulate(STRIP, PROTOCOL, out=tmp_path / "normal", **SMALL)
    lean = ddg.simulate(STRIP, PROTOCOL, out=tmp_path / "lean", centerline=False, **SMALL)
    assert sorted(p.name for p in (tmp_path / "normal").iterdir()) == ["centerline.csv", "path.csv", "summary.json"]
    assert sorted(p.name for p in (tmp_path / "lean").iterdir()) == ["path.csv", "summary.json"]
    assert len(normal.centerlines) == len(normal.rows) == 10 and lean.centerlines == []
    assert (tmp_path / "lean" / "path.csv").read_text() == (tmp_path / "normal" / "path.csv").read_text()
    assert without_times(json.loads((tmp_path / "lean" / "summary.json").read_text())) == \
        without_times(json.loads((tmp_path / "normal" / "summary.json").read_text()))


def test_a_rerun_without_the_centerline_leaves_no_stale_one(tmp_path):
    ddg.simulate(STRIP, PROTOCOL, out=tmp_path, **SMALL)
    assert (tmp_path / "centerline.csv").exists()
    ddg.simulate(STRIP, PROTOCOL, out=tmp_path, centerline=False, **SMALL)
    assert not (tmp_path / "centerline.csv").exists()


def test_frames_are_numbered_by_row_without_the_centerline(tmp_path):
    pytest.importorskip("meshio")
    ddg.simulate(STRIP, PROTOCOL, out=tmp_path, frames=True, centerline=False, **SMALL)
    names = sorted(p.name for p in (tmp_path / "frames").glob("frame_*.vtu"))
    assert names == [f"frame_{k:05d}.vtu" for k in range(10)]


def test_the_ribbon_and_the_command_line_take_the_option(tmp_path):
    ddg.run_ribbon(STRIP, PROTOCOL, resolution=21, out=tmp_path / "ribbon", centerline=False, thresholds=False)
    assert (tmp_path / "ribbon" / "path.csv").exists() and not (tmp_path / "ribbon" / "centerline.csv").exists()
    args = ["simulate", "--model", "rod", "--resolution", "20", "--shear-ratio", "0.1", "--compression-steps", "5",
            "--shear-steps", "4", "--no-branches", "--quiet", "--no-centerline", "--out", str(tmp_path / "cli")]
    assert main(args) == 0
    assert (tmp_path / "cli" / "path.csv").exists() and not (tmp_path / "cli" / "centerline.csv").exists()


@pytest.mark.parametrize("call", ["simulate", "run_ribbon"])
def test_a_non_boolean_is_refused_before_any_work(call, tmp_path):
    from ddg import api

    with pytest.raises(InputError, match="centerline"):
        getattr(api, call)(STRIP, PROTOCOL, out=tmp_path / "x", centerline="no")
    assert not (tmp_path / "x").exists()


def test_the_fem_command_passes_no_centerline_to_the_run(monkeypatch, tmp_path):
    """`python -m fem_reference simulate --no-centerline` (the narrow-limit study's FEM runs) asks
    fem_reference.api.simulate for centerline=False; checked without running the FEM."""
    pytest.importorskip("dolfinx", reason="fem_reference needs dolfinx")
    import fem_reference.api as fem_api
    from fem_reference.cli import main as fem_main

    seen = {}

    def fake(*args, **kwargs):
        seen.update(kwargs)
        raise RuntimeError("stop here")

    monkeypatch.setattr(fem_api, "simulate", fake)
    argv = ["simulate", "--width-ratio", "0.1667", "--compression-ratio", "0.5", "--resolution", "8", "--across", "2",
            "--no-fields", "--no-centerline", "--quiet", "--out", str(tmp_path)]
    assert fem_main(argv) == 1   # the fake's error, after the arguments reached it
    assert seen["centerline"] is False and seen["fields"] is False
    monkeypatch.undo()
    with pytest.raises(InputError, match="centerline"):   # checked before any FEM work
        fem_api.simulate(STRIP, ddg.LoadingProtocol(0.5, compression_steps=2, shear_steps=2), 8, centerline=1)
