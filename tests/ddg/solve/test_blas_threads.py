"""BLAS threads during a run (ddg.solve.blas_threads, issue 31 item 3): one thread by default for
the band factorisations, the caller's setting back afterwards, DDG_BLAS_THREADS to choose, and a
one-line refusal of a bad value before any work."""
import os
import subprocess
import sys
import warnings

import pytest

import ddg
from ddg.geometry.strip import InputError
from ddg.solve.blas_threads import _control, blas_threads, requested_threads
from ddg.solve.probe import Probe

CONTROLLED = _control().kind != "none"


@pytest.mark.skipif(not CONTROLLED, reason="no BLAS this process can set the threads of")
def test_a_run_has_one_blas_thread_and_gives_the_callers_back(monkeypatch):
    monkeypatch.delenv("DDG_BLAS_THREADS", raising=False)
    control = _control()
    before = control.get()
    restore = control.limit(2)   # the caller's own setting
    try:
        seen = []

        class Spy(Probe):
            def solve(self, phase, iterations, converged):
                seen.append(control.get())

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = ddg.simulate(ddg.Strip.from_ratios(0.05, 0.5), ddg.LoadingProtocol(0.5), model="rod",
                                  resolution=30, branches=False, thresholds=False, probe=Spy())
        assert seen and all(threads == seen[0] for threads in seen)
        if control.kind == "openblas":
            assert seen[0] == [1] and control.get() == [2]
        assert result.summary["blas_threads"] == {"requested": 1, "control": control.kind}
    finally:
        restore()
    assert control.get() == before


@pytest.mark.skipif(not CONTROLLED, reason="no BLAS this process can set the threads of")
def test_the_environment_chooses_the_threads(monkeypatch):
    control = _control()
    before = control.get()
    monkeypatch.setenv("DDG_BLAS_THREADS", "keep")
    assert requested_threads() is None
    with blas_threads():
        assert control.get() == before
    if control.kind == "openblas":
        monkeypatch.setenv("DDG_BLAS_THREADS", "2")
        with blas_threads():
            assert control.get() == [2]
        assert control.get() == before


@pytest.mark.parametrize("value", ["0", "-1", "one", "1.5", ""])
def test_a_bad_thread_count_is_refused_in_one_line(monkeypatch, value, tmp_path):
    monkeypatch.setenv("DDG_BLAS_THREADS", value)
    with pytest.raises(InputError, match="DDG_BLAS_THREADS"):
        requested_threads()
    out = tmp_path / "run"
    done = subprocess.run([sys.executable, "-m", "ddg", "simulate", "--model", "rod", "--out", str(out)],
                          capture_output=True, text=True, env={**os.environ, "DDG_BLAS_THREADS": value},
                          timeout=120)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines()[-1].startswith("error: DDG_BLAS_THREADS")
    assert not out.exists()


@pytest.mark.parametrize("value", ["257", "1000000000", "9" * 400])
def test_a_thread_count_beyond_the_bound_is_refused_naming_value_and_range(monkeypatch, value):
    """Issue 47 item 3: DDG_BLAS_THREADS=1000000000 was accepted. At most MAX_THREADS (256); the command
    lines refuse it before any work (exit 2: tests/test_fuzz_inputs.py)."""
    from ddg.solve.blas_threads import MAX_THREADS

    monkeypatch.setenv("DDG_BLAS_THREADS", str(MAX_THREADS))
    assert requested_threads() == MAX_THREADS == 256
    monkeypatch.setenv("DDG_BLAS_THREADS", value)
    with pytest.raises(InputError) as refused:
        requested_threads()
    message = str(refused.value)
    assert value[:40] in message and "[1, 256]" in message and "\n" not in message and len(message) < 200


@pytest.mark.skipif(_control().kind != "openblas", reason="checks OpenBLAS's own setting")
def test_nested_runs_restore_once_the_outermost_ends(monkeypatch):
    monkeypatch.delenv("DDG_BLAS_THREADS", raising=False)
    control = _control()
    restore = control.limit(2)
    try:
        with blas_threads():
            with blas_threads():
                assert control.get() == [1]
            assert control.get() == [1]   # the outer run still has its one thread
        assert control.get() == [2]
    finally:
        restore()
