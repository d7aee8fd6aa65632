"""The documented API (issue 18 item 4): real signatures and docstrings, the result's rows as
numpy arrays always and as a pandas DataFrame when pandas is there, and a stored run read back."""
import inspect
import sys

import numpy as np
import pytest

import ddg


def test_public_names_have_signatures_and_docstrings():
    params = inspect.signature(ddg.simulate).parameters
    assert list(params)[:4] == ["strip", "protocol", "model", "resolution"]
    assert ddg.api.simulate is ddg.simulate and ddg.io.StoredRun is ddg.StoredRun
    for obj in (ddg.simulate, ddg.SimulationResult, ddg.SimulationResult.column, ddg.SimulationResult.to_dataframe,
                ddg.StoredRun, ddg.read_run, ddg.Strip, ddg.LoadingProtocol, ddg.ValidityWarning):
        assert obj.__doc__ and len(obj.__doc__.split()) >= 8, obj


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    result = ddg.simulate(strip, ddg.LoadingProtocol(0.5, shear_ratio=0.2, compression_steps=5, shear_steps=5),
                          model="rod", resolution=30, out=out, branches=False, thresholds=False)
    return result, out


def test_rows_as_arrays_and_dataframe(run):
    result, _ = run
    arrays = result.arrays("shear")
    assert set(arrays) >= {"dW_over_L", "H_mid_over_L", "phase"} and len(arrays["dW_over_L"]) == 5
    assert np.array_equal(arrays["H_mid_over_L"], result.column("H_mid_over_L", "shear"))
    frame = result.to_dataframe()
    assert len(frame) == len(result.rows) and list(frame.columns)[:3] == ["stage", "dL_over_L", "dW_over_L"]
    with pytest.raises(KeyError, match="the columns are stage"):
        result.column("H_max")


def test_to_dataframe_without_pandas_names_the_extra(run, monkeypatch):
    result, _ = run
    monkeypatch.setitem(sys.modules, "pandas", None)       # import pandas now fails
    with pytest.raises(ImportError) as info:
        result.to_dataframe()
    assert "ddg-strips[dataframe]" in str(info.value) and "\n" not in str(info.value)
    assert len(result.arrays()["stage"]) == len(result.rows)   # numpy arrays need nothing


def test_a_stored_run_reads_back_what_was_computed(run):
    result, out = run
    stored = ddg.read_run(out)
    assert stored.summary["model"] == "rod" and stored.converged == result.converged
    assert np.allclose(stored.column("H_mid_over_L", "shear"), result.column("H_mid_over_L", "shear"), rtol=1e-12)
    assert list(stored.column("phase")) == list(result.column("phase"))
    assert stored.branch_rows == [] and "rod" in repr(stored)
    assert len(stored.to_dataframe("shear")) == 5
