"""The narrow-limit study (validation/narrow_limit.py): its run layout, table and input checks."""
import json

import pytest

from validation import narrow_limit as N


def test_every_model_runs_at_every_slenderness():
    """The rod too: its in-plane bending stiffness is (W/b)^2 times its out-of-plane one; and the 1D
    model with its cross-section (issue 30)."""
    for s in (N.PAPER_SLENDERNESS, 300.0):
        runs = N.runs(s)
        assert {m for m, *_ in runs} == {"fem", "plate", "rod", "ribbon-cross-section"}
        assert len(runs) == (len(N.FEM_MESHES) + len(N.PLATE_ROWS) + len(N.ROD_RESOLUTIONS)
                             + len(N.CROSS_SECTION_RESOLUTIONS))


def test_at_the_papers_slenderness_the_runs_are_those_of_the_mesh_studies(tmp_path):
    folder = N.run_folder(tmp_path, N.PAPER_SLENDERNESS, "plate", "plate_R8")
    assert folder.parts[-3:] == ("plate_gold", "dL0.5_W0.05", "R8")
    assert N.run_folder(tmp_path, 300.0, "plate", "plate_R8") == tmp_path / "Lb300" / "plate_R8"


def test_the_table_lists_finished_runs_with_w2_over_bl(tmp_path):
    run = tmp_path / "Lb300" / "plate_R8"
    run.mkdir(parents=True)
    (run / "summary.json").write_text(json.dumps({"status": "complete", "dW1_over_L": 0.35, "dW2_over_L": 0.5,
                                                  "wall_time_s": 1.0}))
    (tmp_path / "Lb300" / "fem_N64x8").mkdir()
    (tmp_path / "Lb300" / "fem_N64x8" / "summary.json").write_text(json.dumps({"status": "running"}))
    rows = N.table(tmp_path, [300.0])
    assert [(r["model"], r["mesh"]) for r in rows] == [("plate", "R8")]
    assert rows[0]["width_squared_over_thickness_length"] == pytest.approx(300 / 400)
    N.write_table(tmp_path, rows)
    assert "| 300 | 0.750 | plate | R8 | 0.3500 | 0.5000 | complete |" in (tmp_path / "narrow_limit.md").read_text()


def test_a_slenderness_out_of_range_exits_2_with_one_line(capsys):
    with pytest.raises(SystemExit) as stop:
        N.main(["--slenderness", "5", "--out", "unused"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err == "error: --slenderness 5 is outside [20, 1e5]"   # one line, as every command (ddg.cli_parser)
