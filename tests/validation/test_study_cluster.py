"""The mesh-study generators on Dask (issue 28 item 3): `python -m fem_reference gold`,
`python -m validation.plate_gold` and `python -m validation.error_map` run their runs as tasks
(ddg.sweep.cluster.run_all) on a LocalCluster of two workers or on an existing cluster, write
what they wrote before, resume (a rerun starts no cluster and computes nothing), lose only the run
of a killed worker, keep every finished run on Ctrl-C (exit 130), and refuse bad cluster options
in one line (exit 2) before any work and before dask or dolfinx is imported.

Tiny inputs: the FEM on one 8 x 8 mesh (about 40 s on a busy core), the plate on 4 and 6 rows of
triangles at W/L = 1/2 (BASE_ROWS patched on the client, which sends the rows to the workers), the
rod at M = 24 to 40 against the stored FEM reference of dL/L = 1/4, W/L = 1/20 (read, not written).
"""
from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from ddg.output.io import finished_run_summary
from ddg.sweep import cluster as C

pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[2]
DASK_EXTRA = "error: install the 'dask' extra: pip install ddg-strips[dask]\n"
#: The plate's scenes here: W/L = 1/2 at both compressions, 4 (then 6) rows of triangles (90 and 182).
PLATE_SCENES = ["dL0.5_W0.5", "dL0.25_W0.5"]
#: A FEM reference scene no background job of the repository rewrites while the tests read it.
MAP_SCENE, MAP_ROW_SCENE = "dL0.25_W0.05", "dL0.25_W0.05_Lb787"


pytestmark = pytest.mark.usefixtures("restore_signal_handlers")  # tests/conftest.py


@pytest.fixture(scope="module")
def release(tmp_path_factory):
    """A file whose existence lets the held test tasks return ($STUDY_CLUSTER_RELEASE in the workers)."""
    return tmp_path_factory.mktemp("held") / "release"


@pytest.fixture(scope="module")
def scheduler(release):
    """An existing cluster (2 worker processes, one thread each), reached by its address as
    `--scheduler` would; closed after the module."""
    from distributed import LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None, silence_logs=40, env={"STUDY_CLUSTER_RELEASE": str(release)})
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


@pytest.fixture
def tiny_plates(monkeypatch):
    from validation import plate_gold

    monkeypatch.setitem(plate_gold.BASE_ROWS, 1 / 2, 4)
    return plate_gold


def no_cluster(*args, **kwargs):
    raise AssertionError("a cluster was started")


def snapshot(folder: Path) -> dict[str, tuple[int, bytes]]:
    """Every file under `folder` (but the probe files): its modification time and content."""
    return {str(p.relative_to(folder)): (p.stat().st_mtime_ns, p.read_bytes()) for p in sorted(folder.rglob("*"))
            if p.is_file() and not p.name.startswith(".")}


def gold(args) -> int:
    from fem_reference.cli import main

    return main(["gold"] + args)


# ---------------------------------------------------------------------------- the FEM gold
def test_gold_runs_on_two_local_workers_and_a_rerun_computes_nothing(tmp_path, capsys, monkeypatch):
    out = tmp_path / "gold"
    args = ["--out", str(out), "--only", "dL0.5_W0.05", "--resolution", "8", "--levels", "1"]
    assert gold(args + ["--workers", "2"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("dL0.5_W0.05 8 x 8: complete, ") and printed.count("\n") == 1, printed
    run = out / "dL0.5_W0.05" / "N8x8"
    summary = json.loads((run / "summary.json").read_text())
    assert (summary["status"], summary["converged"]) == ("complete", True)
    assert (summary["mesh"]["elements_along_L"], summary["mesh"]["elements_across_W"]) == (8, 8)
    assert len((run / "path.csv").read_text().splitlines()) > 100
    study = json.loads((out / "dL0.5_W0.05" / "richardson.json").read_text())
    assert [(m["along"], m["across"], m["folder"]) for m in study["meshes"]] == [(8, 8, "N8x8")]
    index = json.loads((out / "index.json").read_text())
    assert index["dL0.5_W0.05"]["finest_run"] == "dL0.5_W0.05/N8x8"
    assert index["dL0.5_W0.05"]["dW1_over_L"] == summary["dW1_over_L"] is not None
    assert "dL0.5_W0.05" in (out / "README.md").read_text()
    assert not list(out.glob(".probe-*"))

    # the rerun finds the run finished: no cluster, the same files (index and README rewritten alike)
    before = snapshot(out)
    monkeypatch.setattr(C, "connect", no_cluster)
    assert gold(args + ["--workers", "2"]) == 0
    after = snapshot(out)
    assert {k: v[1] for k, v in after.items()} == {k: v[1] for k, v in before.items()}
    assert after[f"{run.relative_to(out)}/summary.json"] == before[f"{run.relative_to(out)}/summary.json"]
    # --studies-only rewrites the same study without dask (the client's files are the command's own)
    monkeypatch.setitem(sys.modules, "distributed", None)
    assert gold(args + ["--studies-only"]) == 0
    assert {k: v[1] for k, v in snapshot(out).items()} == {k: v[1] for k, v in before.items()}


@pytest.mark.slow
def test_gold_on_an_existing_scheduler_runs_a_two_mesh_study(tmp_path, scheduler, capsys):
    """Two meshes (8 x 8, 12 x 12) of W/L = 1/20 run side by side on the cluster at --scheduler:
    the study holds both with its estimates, a rerun computes nothing (about 70 s on 2 busy cores)."""
    out = tmp_path / "gold"
    args = ["--out", str(out), "--only", "dL0.5_W0.05", "--resolution", "8", "--scheduler", scheduler]
    assert gold(args + ["--levels", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert sorted(line.split(":")[0] for line in lines) == ["dL0.5_W0.05 12 x 12", "dL0.5_W0.05 8 x 8"]
    study = json.loads((out / "dL0.5_W0.05" / "richardson.json").read_text())
    assert [m["folder"] for m in study["meshes"]] == ["N8x8", "N12x12"]
    assert study["dW1"]["value"] is not None and study["dW1"]["error_bar"] is not None
    before = snapshot(out)
    assert gold(args + ["--levels", "2", "--quiet"]) == 0
    assert {k: v[1] for k, v in snapshot(out).items()} == {k: v[1] for k, v in before.items()}


# ---------------------------------------------------------------------------- the plate studies
def test_plate_studies_on_two_local_workers_then_on_an_existing_scheduler(tmp_path, tiny_plates, scheduler,
                                                                           capsys, monkeypatch):
    """Level 1 of two scenes on a LocalCluster of two workers; level 2 on the cluster at
    --scheduler computes the finer meshes only; the studies are those --studies-only writes from
    the same runs; a third call starts no cluster and changes nothing."""
    out = tmp_path / "plate"
    args = ["--out", str(out), "--only", *PLATE_SCENES]
    assert tiny_plates.main(args + ["--levels", "1", "--workers", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert sorted(line.split(" (")[0] for line in lines) == [f"{name} R4" for name in sorted(PLATE_SCENES)]
    first = {name: (out / name / "R4" / "summary.json").read_bytes() for name in PLATE_SCENES}

    assert tiny_plates.main(args + ["--levels", "2", "--scheduler", scheduler]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert sorted(line.split(" (")[0] for line in lines) == [f"{name} R6" for name in sorted(PLATE_SCENES)]
    for name in PLATE_SCENES:
        assert (out / name / "R4" / "summary.json").read_bytes() == first[name]   # kept, not rerun
        for rows in (4, 6):
            summary = finished_run_summary(out / name / f"R{rows}")
            assert summary["status"] == "complete" and (out / name / f"R{rows}" / "path.csv").exists()
        study = json.loads((out / name / "richardson.json").read_text())
        assert [m["rows"] for m in study["meshes"]] == [4, 6] and [m["triangles"] for m in study["meshes"]] == [90, 182]
        assert (out / name / "convergence.md").read_text().startswith("# Plate mesh study")
    index = json.loads((out / "index.json").read_text())
    assert sorted(index) == sorted(PLATE_SCENES) and all(e["meshes"] == [4, 6] for e in index.values())
    assert not list(out.glob(".probe-*"))

    before = snapshot(out)
    monkeypatch.setattr(C, "connect", no_cluster)
    assert tiny_plates.main(args + ["--levels", "2", "--quiet"]) == 0
    assert tiny_plates.main(args + ["--levels", "2", "--studies-only"]) == 0
    assert {k: v[1] for k, v in snapshot(out).items()} == {k: v[1] for k, v in before.items()}
    assert capsys.readouterr().out == ""


def plate_killed_once(name, compression, width, slenderness, rows, model, target):
    """validation.plate_gold.run_mesh, but the first attempt at 6 rows SIGKILLs its own worker
    process once the run's path.csv has 5 rows (a marker file in OUT remembers it)."""
    from validation.plate_gold import run_mesh

    marker = Path(target).parents[1] / "killed.json"
    if rows == 6 and not marker.exists():
        path = Path(target) / "path.csv"

        def kill_when_half_written():
            while True:
                written = len(path.read_text().splitlines()) - 1 if path.exists() else 0
                if written >= 5:
                    marker.write_text(json.dumps({"rows": written, "pid": os.getpid()}))
                    os.kill(os.getpid(), signal.SIGKILL)
                time.sleep(0.001)

        threading.Thread(target=kill_when_half_written, daemon=True).start()
    return run_mesh(name, compression, width, slenderness, rows, model, target)


def test_a_worker_killed_during_a_plate_run_costs_that_run_only(tmp_path, tiny_plates, scheduler, capsys,
                                                                monkeypatch):
    out = tmp_path / "plate"
    monkeypatch.setattr(tiny_plates, "run_mesh", plate_killed_once)
    assert tiny_plates.main(["--out", str(out), "--only", "dL0.5_W0.5", "--levels", "2", "--scheduler", scheduler,
                             "--quiet"]) == 0
    killed = json.loads((out / "killed.json").read_text())
    assert killed["rows"] >= 5 and killed["pid"] != os.getpid()
    for rows in (4, 6):
        assert finished_run_summary(out / "dL0.5_W0.5" / f"R{rows}")["status"] == "complete"
    assert [m["rows"] for m in json.loads((out / "dL0.5_W0.5" / "richardson.json").read_text())["meshes"]] == [4, 6]
    assert "error" not in capsys.readouterr().err


def plate_held(name, compression, width, slenderness, rows, model, target):
    """run_mesh at 4 rows; at 6 rows a run that waits (up to 60 s) for OUT/release."""
    from validation.plate_gold import run_mesh

    if rows == 4:
        return run_mesh(name, compression, width, slenderness, rows, model, target)
    release = Path(target).parents[1] / "release"
    deadline = time.monotonic() + 60
    while not release.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    return {"error": "released"}


def test_ctrl_c_keeps_the_finished_runs_and_their_studies(tmp_path, tiny_plates, scheduler, capsys, monkeypatch):
    """SIGINT once the 4-row run is finished and filed, while the 6-row one is running: exit 130,
    one line, the finished run and its study kept; the rerun computes the other run only."""
    out = tmp_path / "plate"
    scene = out / "dL0.5_W0.5"
    monkeypatch.setattr(tiny_plates, "run_mesh", plate_held)

    def interrupt_when_the_study_is_written():
        deadline = time.monotonic() + 60
        while not (scene / "richardson.json").exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt_when_the_study_is_written, daemon=True).start()
    try:
        code = tiny_plates.main(["--out", str(out), "--only", "dL0.5_W0.5", "--levels", "2", "--scheduler",
                                 scheduler, "--quiet"])
    finally:
        (out / "release").write_text("")  # the held task returns: the worker is free for the next test
    err = capsys.readouterr().err
    assert code == 130
    assert err == f"error: interrupted by SIGINT: 1 of 2 runs finished and kept in {out}; a rerun computes only " \
                  "the other 1\n"
    assert finished_run_summary(scene / "R4")["status"] == "complete" and not (scene / "R6" / "summary.json").exists()
    assert [m["rows"] for m in json.loads((scene / "richardson.json").read_text())["meshes"]] == [4]
    assert list(json.loads((out / "index.json").read_text())) == ["dL0.5_W0.5"]


def gold_held(compression, width, slenderness, along, across, target):
    """Instead of fem_reference.gold.run_mesh: the 8 x 8 run returns at once (a stopped run, nothing
    written), the 12 x 12 one waits (up to 60 s) for OUT/release."""
    if along == 8:
        return {"status": "stopped", "dW1_over_L": None, "dW2_over_L": None, "converged": False, "wall_time_s": 0.0}
    release = Path(target).parents[1] / "release"
    deadline = time.monotonic() + 60
    while not release.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    return {"error": "released"}


def map_held(scene, model, resolution, timeout):
    """Instead of validation.error_map.run_row: M = 24 returns a row at once, M = 32 waits (up to
    60 s) for the file named by $STUDY_CLUSTER_RELEASE."""
    if resolution == 24:
        return {"scene": scene.name, "model": model, "resolution": resolution, "resolution_label": f"M{resolution}",
                "status": "complete", "reference_hash": scene.reference_hash}
    release = Path(os.environ["STUDY_CLUSTER_RELEASE"])
    deadline = time.monotonic() + 60
    while not release.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    raise RuntimeError("released")


def interrupt_once(path: Path) -> None:
    """SIGINT to this process as soon as `path` exists (at most 60 s from now)."""
    def wait():
        deadline = time.monotonic() + 60
        while not path.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=wait, daemon=True).start()


def test_ctrl_c_stops_the_gold_command_in_one_line_with_exit_130(tmp_path, scheduler, capsys, monkeypatch):
    """The interrupt goes through fem_reference.cli's handler: one line counting the runs kept."""
    from fem_reference import gold as fem_gold

    out = tmp_path / "gold"
    monkeypatch.setattr(fem_gold, "run_mesh", gold_held)
    interrupt_once(out / "index.json")   # written when the first run has been filed
    try:
        code = gold(["--out", str(out), "--only", "dL0.5_W0.05", "--resolution", "8", "--levels", "2", "--scheduler",
                     scheduler, "--quiet"])
    finally:
        (out / "release").write_text("")
    err = capsys.readouterr().err
    assert code == 130 and err == f"error: interrupted by SIGINT: 0 of 2 runs finished and kept in {out}; a rerun " \
                                  "computes only the other 2\n", err


# ---------------------------------------------------------------------------- the error map
def test_error_map_runs_on_two_local_workers_then_on_an_existing_scheduler(tmp_path, scheduler, capsys,
                                                                            monkeypatch):
    """The rod at M = 24 and 32 on a LocalCluster of two workers, then M = 40 added on the cluster at
    --scheduler (the other rows kept as they are), then a rerun without any cluster."""
    from validation import error_map as em
    from validation.runs import code_version

    if not (em.FEM_GOLD / MAP_SCENE / "richardson.json").exists():
        pytest.skip("the repository's FEM gold data (data/fem_gold) is not here")
    out = tmp_path / "map"
    args = ["--out", str(out), "--only", MAP_SCENE, "--models", "rod"]
    monkeypatch.setattr(em.compute, "rod_family", lambda: [("rod", (24, 32))])
    assert em.main(args + ["--workers", "2"]) == 0
    err = capsys.readouterr().err
    assert sorted(line.split(":")[0] for line in err.splitlines() if line.startswith(MAP_ROW_SCENE)) == \
        [f"{MAP_ROW_SCENE} rod M24", f"{MAP_ROW_SCENE} rod M32"], err
    with open(out / em.CSV_NAME, newline="") as fh:
        first = list(csv.DictReader(fh))
    assert sorted((r["scene"], r["model"], r["resolution_label"]) for r in first) == \
        [(MAP_ROW_SCENE, "rod", "M24"), (MAP_ROW_SCENE, "rod", "M32")]   # in the order they finished
    assert {r["source_hash"] for r in first} == {code_version()} and {r["status"] for r in first} == {"complete"}
    assert all(float(r["dW1_bound"]) > 0 for r in first) and (out / "README.md").exists()

    monkeypatch.setattr(em.compute, "rod_family", lambda: [("rod", (24, 32, 40))])
    assert em.main(args + ["--scheduler", scheduler]) == 0
    err = capsys.readouterr().err
    assert [line.split(":")[0] for line in err.splitlines() if line.startswith(MAP_ROW_SCENE)] == \
        [f"{MAP_ROW_SCENE} rod M40"], err
    with open(out / em.CSV_NAME, newline="") as fh:
        second = list(csv.DictReader(fh))
    assert second[:2] == first and second[2]["resolution_label"] == "M40"

    before = snapshot(out)
    monkeypatch.setattr(C, "connect", no_cluster)
    assert em.main(args) == 0
    assert snapshot(out)[em.CSV_NAME] == before[em.CSV_NAME]


def test_ctrl_c_keeps_the_map_rows_written_with_exit_130(tmp_path, scheduler, release, capsys, monkeypatch):
    from validation import error_map as em

    if not (em.FEM_GOLD / MAP_SCENE / "richardson.json").exists():
        pytest.skip("the repository's FEM gold data (data/fem_gold) is not here")
    out = tmp_path / "map"
    monkeypatch.setattr(em.compute, "rod_family", lambda: [("rod", (24, 32))])
    monkeypatch.setattr(em.compute, "run_row", map_held)
    interrupt_once(out / em.CSV_NAME)   # written when the first row has been filed
    try:
        code = em.main(["--out", str(out), "--only", MAP_SCENE, "--models", "rod", "--scheduler", scheduler])
    finally:
        release.write_text("")
    err = capsys.readouterr().err.splitlines()
    assert code == 130 and err[-1] == f"error: interrupted by SIGINT: 1 of 2 runs finished and written to " \
                                      f"{out / em.CSV_NAME}; a rerun computes only the other 1", err
    assert [r["resolution_label"] for r in em.read_table(out / em.CSV_NAME)] == ["M24"]


def test_the_time_limit_of_a_map_run_works_outside_the_main_thread():
    """--timeout is a probe checked at each Newton solve (a Dask worker runs tasks in a thread,
    where SIGALRM cannot be set): a run past its limit is a row with its reason."""
    from validation import error_map as em

    if not (em.FEM_GOLD / MAP_SCENE / "richardson.json").exists():
        pytest.skip("the repository's FEM gold data (data/fem_gold) is not here")
    scene = next(s for s in em.reference_scenes() if s.name == MAP_ROW_SCENE)
    rows = []
    worker = threading.Thread(target=lambda: rows.append(em.run_row(scene, "rod", 24, timeout=1e-9)))
    worker.start()
    worker.join(60)
    assert rows and "the run took more than 1e-09 s" in rows[0]["reason"], rows


# ---------------------------------------------------------------------------- bad input
def plate(args) -> int:
    from validation.plate_gold import main

    return main(args)


def error_map(args) -> int:
    from validation.error_map import main

    return main(args)


GENERATORS = {"gold": (gold, ["--only", "dL0.5_W0.05", "--resolution", "8", "--levels", "1"]),
              "plate_gold": (plate, ["--only", "dL0.5_W0.5", "--levels", "1"]),
              "error_map": (error_map, ["--only", MAP_SCENE, "--models", "rod"])}


@pytest.mark.parametrize("generator", sorted(GENERATORS))
@pytest.mark.parametrize("options, named", [
    (["--workers", "0"], "--workers = 0"), (["--workers", "many"], "--workers 'many'"),
    (["--retries", "11"], "--retries = 11"), (["--scheduler", "tcp://no where"], "'tcp://no where'"),
    (["--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"], "--workers applies to the LocalCluster only"),
])
def test_bad_cluster_options_exit_2_with_one_line_before_any_work(generator, options, named, tmp_path, capsys,
                                                                 monkeypatch):
    monkeypatch.setattr(C, "connect", no_cluster)
    main, args = GENERATORS[generator]
    out = tmp_path / "out"
    assert main(["--out", str(out)] + args + options) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith("error: ") and captured.err.count("\n") == 1, captured
    assert named in captured.err and "Traceback" not in captured.err
    assert not out.exists()


@pytest.mark.parametrize("generator", sorted(GENERATORS))
def test_a_scheduler_that_does_not_answer_is_one_line_and_exit_2(generator, tmp_path, capsys, monkeypatch):
    """A well-formed address where no scheduler listens (port 9, discard): refused when the first
    run is to be submitted, nothing run (the connection timeout shortened to 1 s here)."""
    from validation import error_map as em

    monkeypatch.setattr(C, "CONNECT_TIMEOUT_S", 1)
    monkeypatch.setattr(em.compute, "rod_family", lambda: [("rod", (24,))])
    main, args = GENERATORS[generator]
    out = tmp_path / "out"
    assert main(["--out", str(out)] + args + ["--scheduler", "tcp://127.0.0.1:9"]) == 2
    captured = capsys.readouterr()
    assert captured.err.startswith("error: --scheduler 'tcp://127.0.0.1:9': cannot connect within 1 s") and \
        captured.err.count("\n") == 1, captured.err
    assert not [p for p in out.rglob("*") if p.is_file()]


@pytest.mark.parametrize("generator", sorted(GENERATORS))
def test_missing_dask_names_the_extra_in_one_line(generator, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    main, args = GENERATORS[generator]
    assert main(["--out", str(tmp_path / "out")] + args) == 2
    assert capsys.readouterr().err == DASK_EXTRA
    assert not (tmp_path / "out").exists()


def test_studies_only_needs_no_dask(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    assert gold(["--out", str(tmp_path / "gold"), "--studies-only"]) == 0
    assert plate(["--out", str(tmp_path / "plate"), "--studies-only"]) == 0
    assert json.loads((tmp_path / "gold" / "index.json").read_text()) == {}
    assert json.loads((tmp_path / "plate" / "index.json").read_text()) == {}


def test_bad_input_is_refused_before_dask_or_dolfinx_is_imported(tmp_path):
    """In a fresh interpreter: the three commands refuse their bad options with dask, distributed
    and dolfinx never imported."""
    code = ("import sys\n"
            "from fem_reference.cli import main as gold\n"
            "from validation.plate_gold import main as plate\n"
            "from validation.error_map import main as error_map\n"
            "out = sys.argv[1]\n"
            "codes = [gold(['gold', '--out', out, '--workers', '0']), plate(['--out', out, '--retries', '-1']),\n"
            "         error_map(['--out', out, '--scheduler', 'tcp://no where'])]\n"
            "print(codes, sorted(m for m in ('dask', 'distributed', 'dolfinx') if m in sys.modules))\n")
    done = subprocess.run([sys.executable, "-c", code, str(tmp_path / "out")], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert done.stdout == "[2, 2, 2] []\n", done.stdout + done.stderr[-2000:]
    assert len(done.stderr.splitlines()) == 3 and not (tmp_path / "out").exists()
