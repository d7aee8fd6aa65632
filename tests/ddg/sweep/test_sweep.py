"""`python -m ddg sweep`: runs as Dask tasks on a LocalCluster of 2 workers, cached by content hash,
one tidy table equal to direct runs, a worker killed mid-run costs that run only, Ctrl-C keeps what
finished, bad input and a missing dask install fail in one line before any work."""
import importlib.util
import json
import os
import signal
import sys
import threading
import time
from pathlib import Path

import pytest

import ddg
from ddg.cli import main
from ddg.sweep import cluster as C
from ddg.sweep.cache import run_cached
from ddg.sweep.grid import RunSpec, code_version, grid
from ddg.sweep.table import COLUMNS, read_table
from ddg.sweep.tasks import execute_one, is_finished

pytest.importorskip("distributed")

#: A cheap rod scene (about 1 s per run): M = 24, 10 + 30 recorded steps to dW_max, thresholds located.
M, COMPRESSION_STEPS, SHEAR_STEPS = 24, 10, 30
SMALL_GRID = ["sweep", "--model", "rod", "--width-ratios", "0.05,0.1", "--compression-ratios", "0.5",
              "--resolutions", str(M), "--compression-steps", str(COMPRESSION_STEPS), "--shear-steps", str(SHEAR_STEPS)]


def direct(width_ratio, compression_ratio=0.5, resolution=M):
    """The same scene by a direct ddg.simulate (as the sweep runs it: thresholds, no branches)."""
    strip = ddg.Strip.from_ratios(width_ratio, compression_ratio)
    protocol = ddg.LoadingProtocol(compression_ratio, None, COMPRESSION_STEPS, SHEAR_STEPS)
    return ddg.simulate(strip, protocol, model="rod", resolution=resolution, branches=False).summary


def small_specs(widths=(0.05, 0.1)):
    return grid(["rod"], list(widths), [0.5], [None], [M], COMPRESSION_STEPS, SHEAR_STEPS)


def no_cluster(*args, **kwargs):
    raise AssertionError("a cluster was started")


# ---------------------------------------------------------------------------- the command
def test_sweep_tables_every_run_as_a_direct_simulate_and_a_rerun_computes_nothing(tmp_path, capsys, monkeypatch):
    assert main(SMALL_GRID + ["--workers", "2", "--out", str(tmp_path), "--quiet"]) == 0
    rows = read_table(tmp_path / "sweep.csv")
    assert len(rows) == 2 and list(rows[0]) == list(COLUMNS)
    for row, width in zip(rows, (0.05, 0.1)):
        expected = direct(width)
        assert (row["model"], row["W_over_L"], row["dL_over_L"], row["resolution"]) == ("rod", width, 0.5, M)
        assert row["L_over_b"] == pytest.approx(150e-3 / 0.127e-3)
        for key in ("dW1_over_L", "dW2_over_L", "H_mid_over_L_compressed"):
            assert expected[key] is not None and row[key] == pytest.approx(expected[key], rel=1e-12, abs=1e-15), key
        assert row["newton_iterations"] == expected["newton_iterations"]
        assert (row["converged"], row["status"]) == (1, "complete") and row["wall_time_s"] > 0
        assert is_finished(tmp_path / row["run_dir"]) and (tmp_path / row["run_dir"] / "path.csv").exists()
    if importlib.util.find_spec("matplotlib") is not None:
        assert (tmp_path / "phase_diagram.png").stat().st_size > 10000 and (tmp_path / "phase_diagram.pdf").exists()
    capsys.readouterr()

    # the rerun finds both runs cached: no cluster, nothing computed, the same table
    before = (tmp_path / "sweep.csv").read_text()
    monkeypatch.setattr(C, "connect", no_cluster)
    t0 = time.perf_counter()
    assert main(SMALL_GRID + ["--workers", "2", "--out", str(tmp_path)]) == 0
    assert time.perf_counter() - t0 < 5.0
    out = capsys.readouterr().out
    assert "sweep: 2 runs: 0 computed, 2 cached, 0 failed" in out, out
    assert (tmp_path / "sweep.csv").read_text() == before


def test_without_matplotlib_the_table_is_written_and_one_line_says_the_figure_was_skipped(tmp_path, capsys,
                                                                                        monkeypatch):
    specs = small_specs((0.05,))
    run_cached(specs, tmp_path / "runs", in_process=True, progress=False)  # cached: the command computes nothing
    monkeypatch.setattr(C, "connect", no_cluster)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    args = SMALL_GRID[:4] + ["0.05"] + SMALL_GRID[5:] + ["--out", str(tmp_path), "--quiet"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert err == ("note: matplotlib is not installed: the phase diagram was skipped (install the 'plot' extra: "
                   "pip install ddg-strips[plot])\n")
    assert len(read_table(tmp_path / "sweep.csv")) == 1 and not (tmp_path / "phase_diagram.png").exists()


@pytest.mark.parametrize("argument, value, named", [
    ("--width-ratios", "1.5", "1.5"), ("--width-ratios", "0.05,nan", "nan"), ("--compression-ratios", "0.95", "0.95"),
    ("--slenderness", "5", "5"), ("--resolutions", "3", "3"), ("--resolutions", "many", "many"),
    ("--model", "spaghetti", "spaghetti"), ("--workers", "0", "0"), ("--retries", "11", "11"),
    ("--compression-steps", "0", "0"), ("--scheduler", "tcp://no where", "no where"),
    ("--width-ratios", ",".join(["0.1"] * 51), "51 values"),
])
def test_bad_input_exits_2_with_one_line_before_any_work(argument, value, named, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(C, "connect", no_cluster)
    args = list(SMALL_GRID)
    if argument in args:
        args[args.index(argument) + 1] = value
    else:
        args += [argument, value]
    out = tmp_path / "out"
    assert main(args + ["--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert argument in err and named in err, err
    assert not out.exists()


def test_missing_dask_names_the_extra_in_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    assert main(SMALL_GRID + ["--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err == "error: install the 'dask' extra: pip install ddg-strips[dask]\n"
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------------------- the Python API
def test_run_sweep_is_the_command_from_python_and_returns_its_table(tmp_path, scheduler, monkeypatch):
    """ddg.sweep.run_sweep: the same grid, the same sweep.csv the command writes, its rows returned;
    a second call takes every run from the cache without a cluster."""
    from ddg.sweep import run_sweep

    grid_args = dict(width_ratios=[0.05, 0.1], compression_ratios=[0.5], resolutions=[M],
                     compression_steps=COMPRESSION_STEPS, shear_steps=SHEAR_STEPS)
    result = run_sweep(["rod"], out=tmp_path / "api", scheduler=scheduler, figure=False, **grid_args)
    assert result.complete and result.runs == 2 and not result.incomplete and result.interrupted is None
    assert result.rows == read_table(tmp_path / "api" / "sweep.csv")
    assert [r["W_over_L"] for r in result.rows] == [0.05, 0.1]
    assert result.rows[0]["dW1_over_L"] == pytest.approx(direct(0.05)["dW1_over_L"], rel=1e-12)
    assert result.files[0] == tmp_path / "api" / "sweep.csv" and not (tmp_path / "api" / "phase_diagram.png").exists()
    assert main(SMALL_GRID + ["--scheduler", scheduler, "--out", str(tmp_path / "cli"), "--quiet"]) == 0
    columns = [c for c in COLUMNS if c not in ("wall_time_s", "run_dir")]
    assert [[r[c] for c in columns] for r in read_table(tmp_path / "cli" / "sweep.csv")] == \
        [[r[c] for c in columns] for r in result.rows]

    monkeypatch.setattr(C, "connect", no_cluster)
    again = run_sweep("rod", out=tmp_path / "api", figure=False, **grid_args)   # a string is a list of one
    assert len(again.outcome.cached) == 2 and not again.outcome.computed and again.outcome.where == ""
    if importlib.util.find_spec("pandas") is not None:
        frame = again.to_dataframe()
        assert list(frame.columns) == list(COLUMNS) and len(frame) == 2


@pytest.mark.parametrize("argument, value, named", [
    ("width_ratios", [0.05, 1.5], "width_ratios = 1.5"), ("compression_ratios", "0.5, nan", "nan"),
    ("models", ["rod", "spaghetti"], "models 'spaghetti'"), ("resolutions", [3], "3"),
    ("slendernesses", [5], "5"), ("width_ratios", [0.1] * 51, "width_ratios has 51 values"),
    ("workers", 0, "0"),
])
def test_run_sweep_refuses_bad_input_before_any_work(argument, value, named, tmp_path, monkeypatch):
    from ddg.geometry.strip import InputError
    from ddg.sweep import run_sweep

    monkeypatch.setattr(C, "connect", no_cluster)
    kwargs = dict(models=["rod"], width_ratios=[0.05], compression_ratios=[0.5], resolutions=[M],
                  out=tmp_path / "out")
    kwargs[argument] = value
    with pytest.raises(InputError) as error:
        run_sweep(**kwargs)
    assert named in str(error.value) and "\n" not in str(error.value)
    assert not (tmp_path / "out").exists()


# ---------------------------------------------------------------------------- cache and resume
def test_a_half_written_run_folder_is_not_finished_and_is_run_again(tmp_path):
    """What a killed attempt leaves (summary.json "running", part of path.csv, no spec.json)."""
    spec = small_specs((0.05,))[0]
    folder = tmp_path / "runs" / spec.key(code_version())
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text(json.dumps({"status": "running", "converged": False}))
    (folder / "path.csv").write_text("stage,dL_over_L\ncompression,0.0\n")
    assert not is_finished(folder)
    outcome = run_cached([spec], tmp_path / "runs", in_process=True, progress=False)
    assert outcome.computed == [spec] and outcome.retried == [spec] and is_finished(folder)
    assert outcome.results[spec].summary["status"] == "complete"


def test_the_validation_report_shares_the_specification_and_the_cache():
    """validation/runs.py takes its RunSpec, cache folders and runner from ddg.sweep (one implementation)."""
    from validation import runs as R

    assert R.RunSpec is RunSpec and R.execute_one is execute_one and R.code_version() == code_version()


# ---------------------------------------------------------------------------- workers on a cluster
@pytest.fixture(scope="module")
def scheduler():
    """An existing cluster (2 worker processes, one thread each), reached by its address as
    `--scheduler` would; closed after the module."""
    from distributed import LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None, silence_logs=40)
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def killed_once(spec, directory):
    """execute_one, but the first attempt at W/L = 0.1 SIGKILLs its own worker process once the
    run's path.csv has 5 rows (a marker file next to the run folder remembers it)."""
    marker = Path(directory).parent / "killed.json"
    if spec.width_ratio == 0.1 and not marker.exists():
        path = Path(directory) / "path.csv"

        def kill_when_half_written():
            while True:
                rows = len(path.read_text().splitlines()) - 1 if path.exists() else 0
                if rows >= 5 and not is_finished(directory):
                    marker.write_text(json.dumps({"rows": rows, "pid": os.getpid()}))
                    os.kill(os.getpid(), signal.SIGKILL)
                time.sleep(0.001)

        threading.Thread(target=kill_when_half_written, daemon=True).start()
    return execute_one(spec, directory)


def test_a_worker_killed_during_a_run_loses_that_run_only(tmp_path, scheduler):
    specs = small_specs()
    outcome = run_cached(specs, tmp_path / "runs", killed_once, scheduler=scheduler, retries=2, progress=False)
    assert not outcome.errors, outcome.errors
    killed = json.loads((tmp_path / "runs" / "killed.json").read_text())
    assert killed["rows"] >= 5 and killed["pid"] != os.getpid()
    assert outcome.interrupted is None and outcome.where.startswith("the scheduler at ")
    assert set(outcome.results) == set(specs) and outcome.retried == [specs[1]]
    for spec in specs:
        expected = direct(spec.width_ratio)
        summary = outcome.results[spec].summary
        for key in ("dW1_over_L", "dW2_over_L", "H_mid_over_L_compressed", "newton_iterations"):
            assert summary[key] == pytest.approx(expected[key], rel=1e-12), key
        assert len(outcome.results[spec].rows) == 1 + COMPRESSION_STEPS + SHEAR_STEPS


def test_ctrl_c_keeps_the_finished_runs_and_tables_them(tmp_path, scheduler, capsys):
    """SIGINT while a long run (M = 3000) is computing and a short one has finished: exit 130, the
    short run is in the table and cached, the long one is not tabled."""
    out = tmp_path / "out"
    args = ["sweep", "--model", "rod", "--width-ratios", "0.05", "--compression-ratios", "0.5", "--resolutions",
            f"{M},3000", "--compression-steps", str(COMPRESSION_STEPS), "--shear-steps", str(SHEAR_STEPS),
            "--scheduler", scheduler, "--out", str(out), "--quiet"]
    short = small_specs((0.05,))[0]
    finished = out / "runs" / short.key(code_version()) / "spec.json"

    def interrupt_when_the_short_run_is_done():
        deadline = time.monotonic() + 60
        while not finished.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt_when_the_short_run_is_done, daemon=True).start()
    assert main(args) == 130
    err = capsys.readouterr().err
    assert err.startswith("error: interrupted by SIGINT: 1 of 2 runs finished") and err.count("\n") == 1, err
    rows = read_table(out / "sweep.csv")
    assert [(r["resolution"], r["status"]) for r in rows] == [(M, "complete")]


def test_a_worker_that_does_not_see_the_folder_sends_the_files_back(tmp_path):
    """No shared file system (the probe file is not the client's): the run goes to a temporary
    folder on the worker, its files travel in the record, the client writes them, spec.json last."""
    from ddg.sweep.tasks import materialise, run_task

    spec = small_specs((0.05,))[0]
    probe = tmp_path / ".probe"
    probe.write_text("the client's token")
    folder = tmp_path / "runs" / spec.key(code_version())
    record = run_task(execute_one, spec, str(folder), (str(probe), "another machine's token"), code_version())
    assert not folder.exists() and {"path.csv", "summary.json", "centerline.csv"} <= set(record["files"])
    materialise(record, folder)
    assert is_finished(folder) and "files" not in json.loads((folder / "spec.json").read_text())
    assert json.loads((folder / "summary.json").read_text())["dW1_over_L"] == direct(0.05)["dW1_over_L"]
