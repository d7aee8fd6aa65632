"""Nothing computed is lost and nothing stale is mistaken for a result (issue 13, items 7-8).

A real `python -m ddg simulate` runs in a subprocess and is stopped by SIGINT, SIGTERM or
SIGKILL at a chosen stage (read from the folder itself: path.csv grows by a row per recorded
step, summary.json says what the run is doing). Then what is on disk is checked: every converged
step in path.csv, summary.json saying why the run ended, the exit code 128 + the signal and one
line on stderr.
"""
import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

# a rod fine enough that the path takes several seconds (M = 400: ~11 s), so there is time to
# stop it where the test wants
RUN = [sys.executable, "-m", "ddg", "simulate", "--model", "rod", "--resolution", "400", "--quiet"]
REPO = Path(__file__).resolve().parents[3]


def _start(out: Path, *extra: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(REPO))
    return subprocess.Popen(RUN + ["--out", str(out), *extra], cwd=out.parent, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _rows(out: Path) -> list[dict]:
    path = out / "path.csv"
    if not path.exists():
        return []
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _summary(out: Path) -> dict:
    try:
        return json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return {}


def _wait_for(condition, process: subprocess.Popen, timeout: float = 120.0) -> None:
    start = time.monotonic()
    while not condition():
        assert process.poll() is None, f"the run ended before the test could stop it: {process.communicate()}"
        assert time.monotonic() - start < timeout, "the run never reached the stage to stop it at"
        time.sleep(0.02)


def _stop(process: subprocess.Popen, sig: int) -> tuple[int, str]:
    process.send_signal(sig)
    _, err = process.communicate(timeout=60)
    return process.returncode, err


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_a_signal_during_the_path_keeps_every_converged_step(tmp_path, sig, code):
    out = tmp_path / "run"
    process = _start(out)
    _wait_for(lambda: len(_rows(out)) >= 8, process)
    returncode, err = _stop(process, sig)
    assert returncode == code
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: interrupted by {sig.name}") and "Traceback" not in err
    summary, rows = _summary(out), _rows(out)
    assert summary["status"] == "interrupted" and summary["converged"] is False
    assert summary["path_complete"] is False
    assert summary["message"].startswith(f"interrupted by {sig.name} during ")
    assert len(rows) == summary["recorded_steps"] >= 8
    # every row written is a converged equilibrium with all its columns
    assert all(r["H_mid_over_L"] != "" and r["phase"] is not None for r in rows)


def test_sigterm_during_threshold_location_keeps_the_complete_path(tmp_path):
    out = tmp_path / "run"
    process = _start(out, "--compression-steps", "10", "--shear-steps", "30", "--no-branches")
    _wait_for(lambda: "locating thresholds" in _summary(out).get("message", ""), process)
    returncode, err = _stop(process, signal.SIGTERM)
    assert returncode == 143 and err.count("\n") == 1 and "Traceback" not in err
    summary, rows = _summary(out), _rows(out)
    assert summary["status"] == "interrupted" and summary["converged"] is False
    assert summary["path_complete"] is True
    assert "during threshold location" in summary["message"] and "the path is complete" in summary["message"]
    assert len(rows) == 1 + 10 + 30 == summary["recorded_steps"]
    assert summary["dW1_over_L"] is None and summary["dW2_over_L"] is None  # not located, not guessed


def test_sigkill_leaves_the_steps_so_far_and_a_folder_marked_running(tmp_path):
    """A killed run cannot write its summary: the folder must say from the start that it is in
    progress, so that an earlier finished run in the same folder is never mistaken for this one."""
    out = tmp_path / "run"
    env = dict(os.environ, PYTHONPATH=str(REPO))
    earlier = subprocess.run([sys.executable, "-m", "ddg", "simulate", "--model", "rod", "--resolution", "20",
                              "--compression-steps", "3", "--shear-steps", "3", "--shear-ratio", "0.05", "--quiet",
                              "--no-thresholds", "--out", str(out)], cwd=tmp_path, env=env, capture_output=True)
    assert earlier.returncode == 0 and _summary(out)["converged"] is True and len(_rows(out)) == 7
    (out / "branches.csv").write_text("stale\n")
    process = _start(out, "--width-ratio", "0.1")
    _wait_for(lambda: _summary(out).get("status") == "running" and len(_rows(out)) >= 5, process)
    returncode, _ = _stop(process, signal.SIGKILL)
    assert returncode == -signal.SIGKILL
    summary, rows = _summary(out), _rows(out)
    assert summary["status"] == "running" and summary["converged"] is False
    assert summary["scene"]["width_ratio"] == pytest.approx(0.1) and summary["scene"]["resolution"] == 400
    assert len(rows) >= 5 and all(r["energy"] != "" for r in rows)  # whole rows: flushed one at a time
    assert not (out / "branches.csv").exists()  # nothing of the earlier run is left


def test_a_signal_inside_compiled_code_is_an_interrupt_not_an_internal_error():
    """A signal handler that raises while a numba dispatcher is on the stack surfaces as
    SystemError('... returned a result with an exception set') with the interrupt as its context
    (seen in CI: exit 1 instead of 143 during threshold location)."""
    from ddg.output.interrupts import RunInterrupted, interrupt_behind

    signal_raised = RunInterrupted("SIGTERM")
    try:
        try:
            raise signal_raised
        except KeyboardInterrupt:
            raise SystemError("CPUDispatcher(<function rod_frames>) returned a result with an exception set")
    except SystemError as wrapped:
        assert interrupt_behind(wrapped) is signal_raised
    assert interrupt_behind(ValueError("a real error")) is None
    assert interrupt_behind(SystemError("no interrupt behind it")) is None
    try:
        try:
            raise signal_raised
        except KeyboardInterrupt:
            raise ImportError("initialization failed")  # Ctrl-C during an extension module's import
    except ImportError as wrapped:
        assert interrupt_behind(wrapped) is signal_raised
