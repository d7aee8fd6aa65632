"""3D output with pyvista (ddg/output/render.py, `python -m ddg render`): a small rod run and a
small plate run are drawn off-screen and the pictures checked for content (strip pixels in the
expected amount, shading, the U arch standing taller than the S state under the fixed camera);
bad inputs give one line and exit code 2 before any drawing; a missing pyvista names the extra."""
from __future__ import annotations

import base64
import io
import json
import re
import sys
import zipfile

import numpy as np
import pytest

import ddg
from ddg.cli import main
from ddg.geometry.strip import InputError
from ddg.output import render

EXTRA_MESSAGE = "error: install the 'render' extra: pip install ddg-strips[render]\n"


@pytest.fixture(scope="module")
def rod_run(tmp_path_factory):
    """Rod, 30 nodes, W/L = 1/20: U, US+ and S in 16 shear steps (about 1 s)."""
    out = tmp_path_factory.mktemp("rod")
    strip = ddg.Strip.from_ratios(width_ratio=1 / 20, compression_ratio=1 / 2)
    result = ddg.simulate(strip, ddg.LoadingProtocol(1 / 2, compression_steps=4, shear_steps=16), model="rod",
                          resolution=30, frames=True, out=out, branches=False)
    assert result.converged, result.summary["message"]
    return out


@pytest.fixture(scope="module")
def plate_run(tmp_path_factory):
    """Plate, 200 triangles, W/L = 1/6, 12 shear steps (about 1 s)."""
    out = tmp_path_factory.mktemp("plate")
    strip = ddg.Strip.from_ratios(width_ratio=1 / 6, compression_ratio=1 / 2)
    result = ddg.simulate(strip, ddg.LoadingProtocol(1 / 2, compression_steps=4, shear_steps=12), model="plate",
                          resolution=200, frames=True, out=out, thresholds=False)
    assert result.converged, result.summary["message"]
    return out


def strip_pixels(png) -> np.ndarray:
    """Mask of the picture's coloured pixels above the colour bar and the axes triad (the lowest
    22 % of the rows): the strip, whose viridis colours are saturated, while the white background,
    the black title and the grey clamps are not."""
    from PIL import Image

    image = np.asarray(Image.open(png).convert("RGB")).astype(int)
    body = image[: int(0.78 * image.shape[0])]
    saturation = body.max(axis=2) - body.min(axis=2)
    return saturation > 40


def assert_drawn(png, low=0.01, high=0.6) -> np.ndarray:
    """The picture is not blank: background white in the corners, the strip covering between `low`
    and `high` of the pixels, shaded (many distinct colours), and grey clamps present."""
    from PIL import Image

    image = np.asarray(Image.open(png).convert("RGB"))
    assert image.shape[0] >= 300 and image.shape[1] >= 300
    for corner in (image[-1, -1], image[0, -1]):
        assert tuple(corner) == (255, 255, 255)
    mask = strip_pixels(png)
    fraction = mask.mean()
    assert low < fraction < high, f"strip covers {fraction:.3f} of the picture"
    colours = np.unique(image.reshape(-1, 3), axis=0)
    assert len(colours) > 500, f"only {len(colours)} colours: flat or empty picture"
    grey = (np.ptp(image, axis=2) < 8) & (image.max(axis=2) > 40) & (image.max(axis=2) < 140)
    assert grey.mean() > 0.002, "no clamp drawn"
    return mask


def vertical_extent(mask: np.ndarray) -> int:
    rows = np.flatnonzero(mask.any(axis=1))
    return int(rows[-1] - rows[0]) if len(rows) else 0


# --------------------------------------------------------------------------- drawing
def test_rod_run_draws_u_us_s_under_one_camera(rod_run, tmp_path):
    pytest.importorskip("pyvista")
    run = render.open_run(rod_run)
    steps = render.default_steps(run)
    assert [run.phase(s).rstrip("+-") for s in steps] == ["U", "US", "S"]
    assert all(run.row(s)["stage"] == "shear" for s in steps)
    files = render.render_run(rod_run, tmp_path / "pictures")
    assert [f.name for f in files] == [f"step_{s:05d}.png" for s in steps]
    masks = [assert_drawn(f) for f in files]
    # one camera and scale for the three: the U arch (0.36 L high) stands well above the lower US
    # and the S, whose picture is mostly the shear offset seen in depth (measured 345, 170, 218 rows)
    u, us, s = (vertical_extent(m) for m in masks)
    assert u > 1.6 * us and u > 1.35 * s


def test_plate_run_draws_its_surface(plate_run, tmp_path):
    pytest.importorskip("pyvista")
    run = render.open_run(plate_run)
    files = render.render_run(plate_run, tmp_path, steps=[run.steps[-1], run.steps[len(run.steps) // 2]])
    assert len(files) == 2
    for f in files:
        assert_drawn(f)
    # a plate is wider than the rod's tube: coloured by displacement it fills more of the picture
    single = render.render_frame(run.files[run.steps[-1]], tmp_path / "one.png", color_by="displacement")
    assert_drawn(single)


def test_render_frame_title_has_the_phase_from_path_csv(rod_run, tmp_path):
    pytest.importorskip("pyvista")
    run = render.open_run(rod_run)
    step = render.default_steps(run)[1]
    frame = render.read_frame(run.files[step], strip_width=run.strip_width)
    title = render.title_of(frame, run.phase(step), "rod")
    assert f"step {step} (shear)" in title and run.phase(step) in title and "dW/L = " in title
    assert frame.width == pytest.approx(1 / 20)
    # the rod's clamped end edges, drawn as a ribbon: two nodes, each with both sides of the strip
    assert frame.clamped[0].sum() == 4 and frame.clamped[1].sum() == 4 and frame.kind == "plate"
    assert render.render_frame(run.files[step], tmp_path / "f.png") == tmp_path / "f.png"
    assert_drawn(tmp_path / "f.png")


def test_grid_of_panels_for_the_report(rod_run, plate_run, tmp_path):
    pytest.importorskip("pyvista")
    rod, plate = render.open_run(rod_run), render.open_run(plate_run)
    panels = [(rod.files[s], f"rod {rod.phase(s)}") for s in render.default_steps(rod)]
    panels += [None, (plate.files[plate.steps[-1]], None)]  # an empty panel keeps the rows aligned
    image = render.render_grid(panels, None, columns=3, strip_widths=[rod.strip_width] * 3 + [None, None])
    assert image.shape == (2 * 420, 3 * 560, 3)
    for row in range(2):
        for col in range(3):
            panel = image[row * 420: (row + 1) * 420, col * 560: (col + 1) * 560].astype(int)
            coloured = (panel.max(axis=2) - panel.min(axis=2) > 40).mean()
            if (row, col) in ((1, 0), (1, 2)):
                assert coloured == 0  # the None panel, and the cell after the last panel
            else:
                assert coloured > 0.01, (row, col, coloured)


def test_html_scene(plate_run, tmp_path):
    pytest.importorskip("pyvista")
    if render.html_unavailable():
        pytest.skip(render.html_unavailable())
    run = render.open_run(plate_run)
    files = render.render_run(plate_run, tmp_path, steps=[run.steps[-1]], html=True)
    html = [f for f in files if f.suffix == ".html"]
    assert len(html) == 1
    text = html[0].read_text()
    data = re.search(r'const base64Str = "([^"]+)"', text)
    assert data, "no embedded scene"
    scene = json.loads(zipfile.ZipFile(io.BytesIO(base64.b64decode(data.group(1)))).read("index.json"))
    assert any(h.get("vtk") == "vtkPoints" for h in scene["hashes"].values())


# --------------------------------------------------------------------------- command line
def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    return err


def test_cli_renders_a_run(rod_run, tmp_path, capsys):
    pytest.importorskip("pyvista")
    assert main(["render", str(rod_run), "--out", str(tmp_path), "--steps", "0,5"]) == 0
    assert capsys.readouterr().out.split() == [str(tmp_path / "step_00000.png"), str(tmp_path / "step_00005.png")]
    assert_drawn(tmp_path / "step_00005.png", low=0.0005)


@pytest.mark.parametrize("args, fragments", [
    (["{missing}"], ["does not exist"]),
    (["{empty}"], ["is not a run folder"]),
    (["{no_frames}"], ["has no frames/ folder"]),
    (["{rod}", "--steps", "999"], ["999", "out of range", "steps 0 to 20"]),
    (["{rod}", "--steps", "-1"], ["-1", "out of range", "steps 0 to 20"]),
    (["{rod}", "--steps", "2,x"], ["'x'", "steps 0 to 20"]),
    (["{rod}", "--out", "/dev/null"], ["/dev/null"]),
])
def test_cli_bad_input_is_one_line_and_exit_2(args, fragments, rod_run, tmp_path, capsys, monkeypatch):
    if "--out" in args:  # checked after the pyvista import (no folder is made for a command that cannot draw)
        pytest.importorskip("pyvista")
    (tmp_path / "empty").mkdir()
    (tmp_path / "no_frames").mkdir()
    (tmp_path / "no_frames" / "summary.json").write_text("{}")
    names = {"missing": tmp_path / "missing", "empty": tmp_path / "empty", "no_frames": tmp_path / "no_frames",
             "rod": rod_run}
    drawn = []
    monkeypatch.setattr(render, "render_run", lambda *a, **k: drawn.append(a))
    assert main(["render", *[a.format(**names) for a in args]]) == 2
    err = _one_line_error(capsys)
    for fragment in fragments:
        assert fragment in err
    assert not drawn  # refused before any work


def test_missing_pyvista_names_the_extra(rod_run, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyvista", None)
    assert main(["render", str(rod_run), "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err == EXTRA_MESSAGE
    assert not list(tmp_path.iterdir())
    with pytest.raises(InputError, match=r"pip install ddg-strips\[render\]"):
        render.render_run(rod_run, tmp_path)


def test_html_without_trame_names_the_packages(rod_run, tmp_path, capsys, monkeypatch):
    pytest.importorskip("pyvista")
    monkeypatch.setitem(sys.modules, "trame_pyvista", None)
    assert main(["render", str(rod_run), "--out", str(tmp_path), "--html"]) == 2
    assert "pip install trame-pyvista nest_asyncio2" in _one_line_error(capsys)
    assert not list(tmp_path.glob("*.png"))
