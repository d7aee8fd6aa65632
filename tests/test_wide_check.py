"""validation/wide_check.py: the W/L = 1/2 U-branch table (no run made here)."""
from __future__ import annotations

import json

import pytest

from validation import wide_check


@pytest.mark.parametrize("argv, word", [(["--rows", "15"], "--rows 15"), (["--rows", "0"], "--rows 0"),
                                        (["--membranes", "cst"], "'cst'")])
def test_bad_input_is_one_line_and_exit_2_before_any_run(tmp_path, capsys, argv, word):
    assert wide_check.main(["--out", str(tmp_path / "out"), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error:") and word in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_table_reads_the_fem_study_meshes_at_the_compared_loads(tmp_path):
    summary = wide_check.write_tables(tmp_path, wide_check.ROOT_FEM)
    fem = [r for r in summary["rows"] if r["run"].startswith("fem ")]
    assert [r["run"] for r in fem] == ["fem N64x24", "fem N96x36", "fem N144x54"]
    # the shell's U branch converges: its clamp force at dW/L = 0.02 falls mesh by mesh
    forces = [r["F_shear_norm_at_0.02"] for r in fem]
    assert forces[0] > forces[1] > forces[2] > 1.1
    assert abs(summary["elastica_H_mid_over_L_compressed"] - 0.29239) < 1e-5
    assert json.loads((tmp_path / "summary.json").read_text())["rows"] == summary["rows"]
    assert "| fem N144x54 | 15552 |" in (tmp_path / "wide_check.md").read_text()
