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


def _stored_rows():
    path = wide_check.ROOT_FEM.parent / "midedge_wide" / "summary.json"
    return {r["run"]: r for r in json.loads(path.read_text())["rows"]}


def test_stored_check_the_mid_edge_U_branch_stiffens_towards_the_shell_with_rows():
    """data/midedge_wide (docs/findings/benchmark.md, the W/L = 1/2 paragraph): the plate's clamp force at dW/L = 0.02
    rises with the rows across W and stays below the shell's finest mesh, and on 54 rows dW1 is
    nearer the FEM's than on 36: the mid-edge meshes are the unconverged side."""
    rows = _stored_rows()
    plate = [rows[f"plate-midedge psri {n} rows"]["F_shear_norm_at_0.02"] for n in (16, 24, 36, 54)]
    shell = rows["fem N144x54"]["F_shear_norm_at_0.02"]
    assert plate == sorted(plate) and plate[-1] < shell, (plate, shell)
    fem_dw1 = rows["fem N144x54"]["dW1_over_L"]
    assert (abs(rows["plate-midedge psri 54 rows"]["dW1_over_L"] - fem_dw1)
            < abs(rows["plate-midedge psri 36 rows"]["dW1_over_L"] - fem_dw1))
    # not the membrane: the constant-strain membrane moves the force far less than its distance to the shell
    for n in (16, 24, 36):
        full, psri = (rows[f"plate-midedge {m} {n} rows"]["F_shear_norm_at_0.02"] for m in ("full", "psri"))
        assert abs(full - psri) < 0.5 * (shell - psri), (n, full, psri, shell)
    # resolution across W matters more than along L: twice the columns on 16 rows gain less than 24 rows
    assert (rows["plate-midedge psri 16 rows x 72 columns"]["F_shear_norm_at_0.02"]
            < rows["plate-midedge psri 24 rows"]["F_shear_norm_at_0.02"])
