"""The command line writes the output contract and fails cleanly on bad input."""
import csv
import json
import re

import pytest

from ddg.cli import main

CONTRACT_COLUMNS = ["stage", "dL_over_L", "dW_over_L", "H_mid_over_L", "F_shear_norm", "energy", "lambda_min", "phase"]
CONTRACT_KEYS = {"model", "scene", "H_mid_over_L_compressed", "dW_max_over_L", "dW1_over_L", "dW2_over_L", "n_dof",
                 "newton_iterations", "wall_time_s", "converged", "versions"}
SMALL_RUN = ["simulate", "--model", "rod", "--width-ratio", "0.05", "--compression-ratio", "0.5", "--shear-ratio",
             "0.1",
             "--resolution", "20", "--compression-steps", "5", "--shear-steps", "4", "--quiet"]


def test_simulate_writes_path_and_summary(tmp_path):
    assert main(SMALL_RUN + ["--out", str(tmp_path)]) == 0
    with open(tmp_path / "path.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][: len(CONTRACT_COLUMNS)] == CONTRACT_COLUMNS
    assert len(rows) == 1 + 1 + 5 + 4  # header, rest state, compression, shear
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert CONTRACT_KEYS <= set(summary)
    assert summary["model"] == "rod" and summary["converged"] is True
    assert summary["scene"]["resolution"] == 20 and summary["scene"]["shear_ratio"] == 0.1
    assert summary["scene"]["slenderness"] == pytest.approx(150e-3 / 0.127e-3)
    assert summary["n_dof"] == 4 * 20 - 1
    assert set(summary["versions"]) >= {"numpy", "scipy", "python", "ddg"}
    last = dict(zip(rows[0], rows[-1]))
    assert float(last["dW_over_L"]) == pytest.approx(0.1)


def test_the_final_line_lists_every_file_written(tmp_path, capsys):
    assert main([a for a in SMALL_RUN if a != "--quiet"] + ["--frames", "--out", str(tmp_path)]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("wrote ")
    for name in ("path.csv", "summary.json", "centerline.csv"):
        assert str(tmp_path / name) in last and (tmp_path / name).is_file()
    frames = len(list((tmp_path / "frames").glob("*.vtu")))
    assert f"{tmp_path / 'frames'}/ ({frames} frames, frames.pvd)" in last and frames > 0
    assert "branches.csv" not in last or (tmp_path / "branches.csv").is_file()


@pytest.mark.parametrize("argument, value", [
    ("--width-ratio", "1.5"), ("--compression-ratio", "1.0"), ("--compression-ratio", "-0.1"),
    ("--shear-ratio", "0.95"), ("--resolution", "3"), ("--poisson-ratio", "0.5"), ("--slenderness", "0"),
    ("--model", "spaghetti"), ("--resolution", "many"),
])
def test_bad_input_exits_2_with_one_line(argument, value, tmp_path, capsys):
    """Exit code 2 and one line naming the offending option and value: argparse's own errors
    (a value of the wrong type or not among the choices) raise SystemExit(2) and name the flag
    and the value as typed; ddg's checks return 2 and name the parameter and the value read."""
    args = [a for a in SMALL_RUN]
    if argument in args:
        i = args.index(argument)
        args[i + 1] = value
    else:
        args += [argument, value]
    args += ["--out", str(tmp_path)]
    if value in ("many", "spaghetti"):
        with pytest.raises(SystemExit) as exited:
            main(args)
        code = exited.value.code
    else:
        code = main(args)
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1 and "Traceback" not in err
    if value in ("many", "spaghetti"):
        assert f"argument {argument}:" in err and f"'{value}'" in err, err
    else:  # the parameter's name and its value as read (0 -> 0.0 for a float option)
        name = argument.lstrip("-").replace("-", "_")
        assert name in err, err
        assert re.search(rf"= ({re.escape(value)}|{re.escape(str(float(value)))})(?!\.?\d)", err), err


def test_run_that_stops_converging_exits_3_and_keeps_the_converged_part(tmp_path, capsys, monkeypatch):
    """Newton is made to fail from its 8th call on: the run must stop, say where, keep what converged."""
    import ddg.solve.continuation as continuation

    real_newton, calls = continuation.newton, []

    def failing_newton(model, q, *args, **kwargs):
        calls.append(1)
        result = real_newton(model, q, *args, **kwargs)
        if len(calls) >= 8:
            result.converged = False
        return result

    monkeypatch.setattr(continuation, "newton", failing_newton)
    code = main(SMALL_RUN + ["--out", str(tmp_path)])
    assert code == 3
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["converged"] is False and "dL/L" in summary["message"] and "dW/L" in summary["message"]
    assert summary["status"] == "stopped" and summary["path_complete"] is False
    with open(tmp_path / "path.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert 2 <= len(rows) < 1 + 5 + 4 and rows[0]["stage"] == "compression"
    assert len(rows) == summary["recorded_steps"]
    lines = capsys.readouterr().err.splitlines()
    # one error line, last; before it only the run's warnings (M = 20 turns its edges by 30 degrees
    # under this compression: the mesh warning, ddg.protocol.validity)
    assert lines[-1].startswith("error: run did not complete") and len(lines) == 1 + len(summary["warnings"])
    assert all(line.startswith("warning: ") for line in lines[:-1])


def test_run_that_stops_during_shear_says_how_close_to_dw_max_it_got(tmp_path, monkeypatch):
    """Newton is made to fail once the moving clamp passes dW/L = 0.05 (of 0.1 asked): the message
    gives the last converged dW/L and its share of dW_max (Eq. B.1)."""
    import ddg.solve.continuation as continuation

    real_newton = continuation.newton

    def failing_newton(model, q, *args, **kwargs):
        result = real_newton(model, q, *args, **kwargs)
        if q[model.node_dofs[-1, 1]] > 0.05 * model.strip.length:
            result.converged = False
        return result

    monkeypatch.setattr(continuation, "newton", failing_newton)
    assert main(SMALL_RUN + ["--out", str(tmp_path)]) == 3
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "dW/L = 0.05 " in summary["message"] or "dW/L = 0.05;" in summary["message"]
    share = 100 * 0.05 / summary["dW_max_over_L"]
    assert f"{share:.2f} % of dW_max/L" in summary["message"], summary["message"]


def test_dynamic_solver_writes_the_same_contract(tmp_path):
    args = ["simulate", "--solver", "dynamic", "--clamp-speed", "0.02", "--resolution", "20", "--compression-ratio",
            "0.25", "--shear-ratio", "0.05", "--compression-steps", "4", "--shear-steps", "2", "--quiet",
            "--out", str(tmp_path)]
    assert main(args) == 0
    with open(tmp_path / "path.csv") as fh:
        header = next(csv.reader(fh))
    assert header[: len(CONTRACT_COLUMNS)] == CONTRACT_COLUMNS
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert CONTRACT_KEYS <= set(summary) and summary["solver"] == "implicit-euler" and summary["converged"]


PLATE_RUN = ["simulate", "--model", "plate", "--width-ratio", "0.1667", "--compression-ratio", "0.5",
             "--shear-ratio", "0.05", "--resolution", "200", "--compression-steps", "4", "--shear-steps", "2",
             "--quiet"]


def test_plate_run_writes_the_same_contract_and_frames(tmp_path):
    pytest.importorskip("meshio")
    assert main(PLATE_RUN + ["--frames", "--out", str(tmp_path)]) == 0
    with open(tmp_path / "path.csv") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][: len(CONTRACT_COLUMNS)] == CONTRACT_COLUMNS and len(rows) == 1 + 1 + 4 + 2
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert CONTRACT_KEYS <= set(summary) and summary["model"] == "plate"
    assert summary["mesh"]["triangles"] > 0 and summary["n_dof"] == 3 * summary["mesh"]["nodes"]
    frames = sorted((tmp_path / "frames").glob("frame_*.vtu"))
    assert len(frames) == 7 and (tmp_path / "frames" / "frames.pvd").is_file()
    with open(tmp_path / "centerline.csv") as fh:
        centerline = list(csv.DictReader(fh))
    assert len(centerline) == 7 * 101
    last = [r for r in centerline if r["row"] == "6"]
    assert float(last[0]["x_over_L"]) == pytest.approx(0.0, abs=1e-12)  # the fixed clamp point
    assert float(last[-1]["y_over_L"]) == pytest.approx(0.05, abs=1e-12)  # the moving one, sheared


def test_plate_reads_a_mesh_file(tmp_path):
    meshio = pytest.importorskip("meshio")
    from ddg.geometry.plate_mesh import structured_mesh

    L, W = 150e-3, 0.1667 * 150e-3
    mesh = structured_mesh(L, W, 200)
    points = mesh.nodes + [3.0, 1.0]  # any offset: read_mesh moves the clamp lines to x = 0 and L
    meshio.write(tmp_path / "strip.msh", meshio.Mesh(points, [("triangle", mesh.triangles)]), file_format="gmsh22")
    assert main(PLATE_RUN + ["--mesh", str(tmp_path / "strip.msh"), "--out", str(tmp_path / "out")]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["mesh"]["triangles"] == mesh.triangle_count


def test_plate_mesh_of_the_wrong_width_is_a_one_line_error(tmp_path, capsys):
    meshio = pytest.importorskip("meshio")
    from ddg.geometry.plate_mesh import structured_mesh

    mesh = structured_mesh(150e-3, 10e-3, 200)
    meshio.write(tmp_path / "narrow.msh", meshio.Mesh(mesh.nodes, [("triangle", mesh.triangles)]), file_format="gmsh22")
    capsys.readouterr()  # meshio's own warnings while writing the test file
    assert main(PLATE_RUN + ["--mesh", str(tmp_path / "narrow.msh"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "width" in err


def test_rod_frames_are_the_ribbon_the_rod_stands_for(tmp_path):
    """Two triangles per edge over two points per node (ddg.output.frame_fields), so rods render
    like plates in ParaView; the centreline is the mid-line of the ribbon."""
    meshio = pytest.importorskip("meshio")
    assert main(SMALL_RUN + ["--frames", "--out", str(tmp_path)]) == 0
    frames = sorted((tmp_path / "frames").glob("frame_*.vtu"))
    assert len(frames) == 1 + 5 + 4
    last = meshio.read(frames[-1])
    assert last.cells[0].type == "triangle" and len(last.points) == 2 * 20 and len(last.cells[0].data) == 2 * 19
    with open(tmp_path / "centerline.csv") as fh:
        rows = [r for r in csv.DictReader(fh) if r["row"] == "9"]
    assert float(rows[-1]["y_over_L"]) == pytest.approx(0.1, abs=1e-12)  # the sheared clamp point
