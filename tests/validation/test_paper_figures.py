"""The paper's figures (validation/paper_figures.py writes their data, validation.figures draws
them): Figs. 10 and A.12-14 from their data files, the Fig. 9 generator's refusal of a bad --out and
its skipping of finished widths, and Fig. 9a's deformed plate with its centreline."""
import pytest

PNG = b"\x89PNG\r\n\x1a\n"


def test_the_paper_figures_draw_from_their_data(tmp_path):
    """Figs. 10 and A.12-14 from the files data/paper_figures/generate.sh writes (tiny hand-made ones
    here): the centreline error on a log L/W axis, the curvature profiles per dW/L."""
    pytest.importorskip("matplotlib")
    from validation import figures
    from validation.report_data import paper_figures

    (tmp_path / "centerline_error").mkdir()
    (tmp_path / "centerline_error" / "centerline_error.csv").write_text(
        "L_over_W,W_over_L,dW_over_L,mean_error,max_error,rod_edge_mean_error,ribbon_edge_mean_error,phase,"
        "triangles,message\n2,0.5,0.1,0.01,0.02,0,0,U,2000,\n20,0.05,0.1,0.0001,0.0003,0,0,U,2000,\n")
    for model in ("rod", "plate"):
        (tmp_path / f"curvatures_{model}").mkdir()
        (tmp_path / f"curvatures_{model}" / "curvatures.csv").write_text(
            "model,step,dL_over_L,dW_over_L,s_over_L,k1_L,k2_L,tau_L\n"
            + "".join(f"{model},0,0.5,0.2,{s},0.0,{s * 3},{-s}\n" for s in (0.1, 0.5, 0.9)))
    for name in ("rod", "ribbon_rod"):
        run = tmp_path / "a11" / "W0.05" / name
        run.mkdir(parents=True)
        (run / "path.csv").write_text("stage,dL_over_L,dW_over_L,H_mid_over_L,phase\ncompression,0.5,0,0.37,U\n"
                                      "shear,0.5,0.1,0.36,U\nshear,0.5,0.4,0.2,US+\n")
    (tmp_path / "fig9").mkdir()
    (tmp_path / "fig9" / "W0.05.csv").write_text(
        "W_over_L,dW_over_L,s_over_L,w_over_L,delta_percent\n"
        + "".join(f"0.05,0.3,{s},{w},{0.01 + s * abs(w)}\n" for s in (0.0, 0.5, 1.0) for w in (-0.025, 0.0, 0.025)))
    found = {f.name: f for f in paper_figures(tmp_path)}
    assert set(found) == {"centerline_error", "curvature_profiles", "sadowsky_a11", "centerline_error_field"}
    figures.draw(found["centerline_error_field"])
    assert len(found["sadowsky_a11"].rows) == 4          # the shear rows only
    figures.draw(found["sadowsky_a11"])
    fig = figures.draw(found["centerline_error"])
    assert fig.axes[0].get_xscale() == "log"
    png = figures.save(figures.draw(found["curvature_profiles"]), tmp_path / "out", "curvature_profiles")
    assert png[:8] == PNG and (tmp_path / "out" / "curvature_profiles.pdf").exists()
    assert paper_figures(tmp_path / "none") == []


def test_the_fig9_generator_refuses_a_bad_out_and_skips_finished_widths(tmp_path, capsys, monkeypatch):
    from validation import paper_figures as pf

    (tmp_path / "file").write_text("x")
    assert pf.main(["--out", str(tmp_path / "file"), "--quiet"]) == 2
    assert capsys.readouterr().err.startswith("error: ") and not (tmp_path / "file" / "fig9").exists()
    for width in pf.FIG9_WIDTHS:                     # every width finished: nothing is run
        pf.field_file(tmp_path / "out", width).parent.mkdir(parents=True, exist_ok=True)
        pf.field_file(tmp_path / "out", width).write_text("W_over_L\n")
    import ddg.studies.curvature_studies as curvatures
    monkeypatch.setattr(curvatures, "states_at_shears", lambda *a, **k: 1 / 0)
    assert pf.write_fields(tmp_path / "out", quiet=True) == []
    for width in pf.FIG9_WIDTHS:                     # Fig. 9a: a width with its centreline file is finished
        pf.shape_files(tmp_path / "out", width)["centerline"].parent.mkdir(parents=True, exist_ok=True)
        pf.shape_files(tmp_path / "out", width)["centerline"].write_text("dW_over_L\n")
    assert pf.write_shapes(tmp_path / "out", quiet=True) == []


def test_fig9a_draws_the_deformed_plate_and_its_centreline_rendering(tmp_path):
    """A coarse plate (W/L = 1/6, 300 triangles) sheared to dW/L = 0.1: the shape files hold every
    node of the mesh, the centreline runs through both clamps with its m2 at every station, and
    the figure draws the mesh and the Eq. (12) lines from them (Fig. 9a)."""
    pytest.importorskip("matplotlib")
    import csv

    import numpy as np

    from validation import figures
    from validation import paper_figures as pf
    from validation.report_data import fig9a_figure

    written = pf.write_shapes(tmp_path, widths=(1 / 6,), shears=(0.1,), triangles=300, quiet=True)
    files = pf.shape_files(tmp_path, 1 / 6)
    assert written == [files["centerline"]]
    tri = np.loadtxt(files["triangles"], delimiter=",", skiprows=1, dtype=int)
    with open(files["nodes"]) as f:
        nodes = list(csv.DictReader(f))
    assert len(nodes) == tri.max() + 1 and {n["dW_over_L"] for n in nodes} == {"0.1"}
    with open(files["centerline"]) as f:
        line = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    assert line[0]["s_over_L"] <= 1e-9 and line[-1]["s_over_L"] >= 1 - 1e-9   # the clamped rows included
    # m2 at a station is the mean of its two edges' unit m2 (Eq. 12): unit to within their turn
    # (|m2| in [0.9953, 1] on the committed W/L = 1/3 shapes, 2000 triangles)
    assert all(0.99 < np.hypot(np.hypot(r["m2_x"], r["m2_y"]), r["m2_z"]) <= 1 + 1e-6 for r in line)
    figure = fig9a_figure(tmp_path)
    assert {r[0] for r in figure.rows} == {"plate node", "centreline"} and len(figure.rows) == len(nodes) + len(line)
    fig = figures.draw(figure)
    assert len(fig.axes) == 1 and fig.axes[0].get_title() == "W/L = 1/6, dW/L = 0.1"
    assert fig9a_figure(tmp_path / "none") is None
