"""The sweep's phase diagram (ddg.sweep.figure) takes the FEM gold thresholds and their error bars
from each scene's mesh study in data/fem_gold/index.json, for every scene that has one."""
import json
from pathlib import Path

import pytest

from ddg.sweep.figure import DATA, gold_thresholds, phase_diagram_figure, write_phase_diagram

#: Two sweep rows (the rod at M = 24, thresholds as a sweep tables them).
ROWS = [{"model": "rod", "W_over_L": w, "dL_over_L": 0.5, "L_over_b": 1181.1, "resolution": 24,
         "dW1_over_L": d1, "dW2_over_L": d2} for w, d1, d2 in ((0.05, 0.351, 0.470), (0.1667, 0.350, 0.455))]


def study(dw1, bar1, dw2, bar2):
    return {"meshes": ["64x8", "96x12", "144x18"],
            "dW1": {"value": dw1, "error_bar": bar1, "basis": "Richardson"},
            "dW2": {"value": dw2, "error_bar": bar2, "basis": "the finest value"},
            "H_mid_compressed": {"value": 0.373, "error_bar": 1e-5}}


def entry(width, compression=0.5, converged=True, slenderness=None, dw1=0.3, dw2=0.45, with_study=None):
    out = {"compression_ratio": compression, "width_ratio": width, "slenderness": slenderness,
           "converged": converged, "resolution": 60, "dW1_over_L": dw1, "dW2_over_L": dw2}
    if with_study is not None:
        out["study"] = with_study
    return out


@pytest.fixture
def data(tmp_path):
    index = {
        "dL0.5_W0.05": entry(0.05, dw1=0.337, with_study=study(0.3523, 0.0048, 0.4754, 0.0008)),
        "dL0.5_W0.1667": entry(1 / 6, dw1=0.264, with_study=study(0.2646, 0.0011, 0.4310, 0.0042)),
        "dL0.25_W0.05": entry(0.05, 0.25, dw1=0.2123, dw2=0.3309),              # a single run, no study
        "dL0.25_W0.5": entry(0.5, 0.25, converged=False, dw1=None, dw2=None),  # unfinished, no study
        "dL0.5_W0.05_Lb300": entry(0.05, slenderness=300.0, with_study=study(0.3393, 0.0019, 0.511, 0.0003)),
    }
    (tmp_path / "fem_gold").mkdir()
    (tmp_path / "fem_gold" / "index.json").write_text(json.dumps(index))
    return tmp_path


def test_each_scene_with_a_study_gives_its_converged_values_and_error_bars(data):
    gold = {g["scene"]: g for g in gold_thresholds(data)}
    assert set(gold) == {"dL0.5_W0.05", "dL0.5_W0.1667", "dL0.25_W0.05"}   # not another strip, not unfinished
    w05 = gold["dL0.5_W0.05"]
    assert (w05["dW1_over_L"], w05["dW1_error"], w05["dW2_over_L"], w05["dW2_error"]) == \
        (0.3523, 0.0048, 0.4754, 0.0008)
    assert w05["basis"] == "study" and w05["W_over_L"] == 0.05 and w05["dL_over_L"] == 0.5
    assert gold["dL0.5_W0.1667"]["dW2_error"] == 0.0042
    single = gold["dL0.25_W0.05"]   # the finest run's thresholds, no error bar
    assert (single["basis"], single["dW1_over_L"], single["dW1_error"], single["dW2_error"]) == \
        ("single run", 0.2123, None, None)
    assert gold_thresholds(data / "nowhere") == []


def test_the_figure_draws_the_study_values_with_their_error_bars(data):
    pytest.importorskip("matplotlib")
    from matplotlib.container import ErrorbarContainer

    fig, caption = phase_diagram_figure(ROWS, gold_thresholds(data))
    (ax,) = fig.axes   # one panel: dL/L = 1/2
    bars = {}
    for container in ax.containers:
        if isinstance(container, ErrorbarContainer) and container.has_yerr:
            for (x, low), (_, high) in container.lines[2][0].get_segments():
                bars[(round(x, 4), round((low + high) / 2, 4))] = round((high - low) / 2, 6)
    assert bars == {(0.05, 0.3523): 0.0048, (0.1667, 0.2646): 0.0011,
                    (0.05, 0.4754): 0.0008, (0.1667, 0.431): 0.0042}
    assert "every scene the converged value of its mesh study with its error bar" in caption
    assert "largest dW1 +/-0.0048, dW2 +/-0.0042" in caption and "fem_convergence" not in caption


def test_a_scene_without_a_study_is_drawn_without_a_bar_and_the_caption_says_so(data):
    pytest.importorskip("matplotlib")
    rows = [dict(r, dL_over_L=0.25) for r in ROWS]
    _, caption = phase_diagram_figure(rows, gold_thresholds(data))
    assert "1 scene at the paper's thickness" in caption
    assert "has a single run, no mesh study and no error bar" in caption


def test_every_committed_gold_scene_with_a_study_gets_its_error_bars():
    """On the repository's own index: each scene of the paper's strip that has a study is drawn
    from it (value and error bar), not from its finest run."""
    index_path = DATA / "fem_gold" / "index.json"
    if not index_path.exists():
        pytest.skip("no data/fem_gold/index.json (an installed copy)")
    index = json.loads(index_path.read_text())
    with_study = {name for name, e in index.items() if e.get("slenderness") is None
                  and (e.get("study") or {}).get("dW1", {}).get("value") is not None}
    gold = {g["scene"]: g for g in gold_thresholds()}
    assert len(with_study) >= 10 and with_study <= set(gold)
    for name in with_study:
        assert gold[name]["basis"] == "study"
        assert gold[name]["dW1_over_L"] == index[name]["study"]["dW1"]["value"]
        assert gold[name]["dW1_error"] == index[name]["study"]["dW1"]["error_bar"] > 0


def test_the_phase_diagram_is_byte_stable(data, tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    first, _ = write_phase_diagram(tmp_path / "a", ROWS, data)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")
    second, _ = write_phase_diagram(tmp_path / "b", ROWS, data)
    assert [p.name for p in first] == ["phase_diagram.png", "phase_diagram.pdf"]
    for a, b in zip(first, second):
        assert Path(a).read_bytes() == Path(b).read_bytes(), a.name
