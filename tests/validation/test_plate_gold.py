"""Plate mesh studies (validation/plate_gold.py, issue 16 item 2): uniform refinement by 1.5 on
exactly equilateral meshes, and a study written from stored runs with the FEM gold's estimates."""
import json

import pytest

import ddg
from ddg.geometry.plate_mesh import equilateral_mesh
from validation.plate_gold import REFINEMENT, rows_sequence, write_scene_study


@pytest.mark.parametrize("width", [1 / 20, 1 / 12, 1 / 6, 1 / 3, 1 / 2])
def test_every_level_divides_every_spacing_by_the_refinement_ratio(width):
    strip = ddg.Strip.from_ratios(width, 0.5)
    rows = rows_sequence(width)
    assert len(rows) == 3 and all(r % 2 == 0 for r in rows)
    spacings = []
    for r in rows:
        mesh = equilateral_mesh(strip.length, strip.width, r)
        x = sorted(set(round(v, 12) for v in mesh.nodes[:, 0]))
        spacings.append((strip.width / r, x[len(x) // 2 + 1] - x[len(x) // 2]))
    for (hy0, hx0), (hy1, hx1) in zip(spacings, spacings[1:]):
        # (the column positions are read back rounded to 1e-12 m: 3e-9 of a 3e-4 m spacing)
        assert hy0 / hy1 == pytest.approx(REFINEMENT, rel=1e-12) and hx0 / hx1 == pytest.approx(REFINEMENT, rel=1e-7)


def test_a_scene_study_from_three_short_plate_runs(tmp_path):
    """Three short runs (compression and a little shear) on 8, 12, 18 rows: the study lists them
    coarsest first and estimates H_mid after compression, which converges (order in the window
    or the finest value with its spread, never a missing error bar)."""
    strip = ddg.Strip.from_ratios(1 / 6, 0.5)
    protocol = ddg.LoadingProtocol(0.5, shear_ratio=0.03, compression_steps=4, shear_steps=2)
    scene = tmp_path / "dL0.5_W0.1667"
    for rows in rows_sequence(1 / 6):
        ddg.simulate(strip, protocol, model="plate", mesh=equilateral_mesh(strip.length, strip.width, rows),
                     out=scene / f"R{rows}", branches=False, thresholds=False)
    study = write_scene_study(scene, rows_sequence(1 / 6))
    stored = json.loads((scene / "richardson.json").read_text())
    assert [m["rows"] for m in stored["meshes"]] == [8, 12, 18] == [m["rows"] for m in study["meshes"]]
    h = stored["H_mid_compressed"]
    assert h["error_bar"] is not None and abs(h["value"] - h["finest"]) <= 3 * h["error_bar"]
    assert (scene / "convergence.md").read_text().startswith("# Plate mesh study")


@pytest.mark.parametrize("folder", ["plate_gold", "midedge_gold"])
def test_stored_study_readme_lists_each_scenes_agreement_with_the_shell(folder):
    """The README of each DDG study folder ends with the comparison against the shell's studies
    (validation.plate_gold.agreement_lines) computed from its stored studies: regenerated whenever a
    study changes (`--studies-only`), so the two cannot drift apart."""
    from pathlib import Path

    from validation.plate_gold import agreement_lines

    root = Path(__file__).resolve().parents[2] / "data" / folder
    index = json.loads((root / "index.json").read_text())
    text = (root / "README.md").read_text()
    lines = agreement_lines(root, "plate" if folder == "plate_gold" else "plate-midedge")
    assert "\n".join(lines) in text
    assert len(lines) == 4 + len(index)
