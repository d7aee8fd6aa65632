"""Gold data: the FEM reference on the paper's scenes (section 4: dL/L in {1/2, 1/4} x W/L in
{1/20, 1/12, 1/6, 1/3, 1/2}) with error bars from a mesh study,
`python -m fem_reference gold --out data/fem_gold [--only NAME ...] [--resolution N] [--levels K]
[--workers N | --scheduler ADDRESS] [--retries 2]`.

Every scene is run on LEVELS meshes refined uniformly by REFINEMENT = 1.5 in both directions
(along L: 64, 96, 144 elements; across W: BASE_ACROSS[W/L] times 1, 1.5, 2.25), each the whole
path with dW1 and dW2 bisected to GOLD_TOLERANCES, into OUT/<name>/N<along>x<across>/ (path.csv,
summary.json; no centerline.csv or XDMF, which no study reads, to keep the data small), name =
dL<dL/L>_W<W/L> e.g. dL0.5_W0.1667. After each run the scene's mesh study is rewritten from the runs that exist
(OUT/<name>/richardson.json, convergence.md, convergence.csv, thresholds.csv: Richardson
extrapolation with error bars, fem_reference.convergence.estimate), then OUT/index.json and
OUT/README.md. Resumable run by run: a finished run (status complete or stopped) on the same
mesh and tolerances is kept; Ctrl-C loses only the runs in progress (exit 130).

The runs are Dask tasks, as `python -m ddg sweep`'s (ddg.sweep.cluster): by default on a
LocalCluster of one single-threaded worker process per core (--workers N), with --scheduler on an
existing cluster whose workers share OUT and the checkout; each worker writes its run's folder and
imports dolfinx, the client rewrites the studies and the index as each run ends. A worker killed
mid-run costs that run, which is retried (--retries).
"""
from __future__ import annotations

import hashlib
import json
import math
import time
from pathlib import Path

from ddg.output.io import atomic_write_text, read_json_object

WIDTH_RATIOS = (1 / 20, 1 / 12, 1 / 6, 1 / 3, 1 / 2)
COMPRESSION_RATIOS = (1 / 2, 1 / 4)
#: The mesh study: LEVELS meshes, each REFINEMENT times finer than the last in both directions.
REFINEMENT = 1.5
LEVELS = 3
#: The most levels a study has (a fourth mesh, 216 elements along L, where the first three are not
#: asymptotic: issue 28).
MAX_LEVELS = 4
#: Elements along L of the coarsest mesh (64, 96, 144 with the defaults; a multiple of 8 keeps
#: the ratios exact). 40 is not in the asymptotic range of the thresholds: at W/L = 1/6, dL/L = 1/2
#: the meshes 40 x 8, 60 x 12, 90 x 18 gave dW1/L 0.2585, 0.2570, 0.2615 and dW2/L 0.4851,
#: 0.4195, 0.4360, neither monotone (those runs are kept in data/fem_gold/dL0.5_W0.1667).
BASE_RESOLUTION = 64
#: Elements across W of the coarsest mesh: multiples of 8, so that 1.5 and 2.25 times them are
#: even (the mesh must be symmetric); h_y = W/8 .. W/24 (at 64 along L: 0.4 to 1.3 times h_x,
#: at least 8 across, 4 of them on either side of y = 0).
BASE_ACROSS = {1 / 20: 8, 1 / 12: 8, 1 / 10: 8, 1 / 8: 8, 1 / 6: 8, 1 / 4: 16, 1 / 3: 16, 1 / 2: 24}
#: Scenes beyond the paper's ten that the error map (validation/error_map/, issue 17) needs as
#: references, as (dL/L, W/L, L/b or None for the paper's strip): held out of the map's fitting set
#: to check its predictions (W/L = 1/8 and 1/4 lie between the paper's widths), and other L/b.
#: Run with --only NAME; the default run is the paper's ten.
MAP_SCENES = ((1 / 2, 1 / 8, None), (1 / 4, 1 / 8, None), (1 / 2, 1 / 4, None), (1 / 2, 1 / 20, 300.0),
              (1 / 2, 1 / 6, 300.0),
              # Second held-out set, added after the first set had been checked (issue 17): scenes
              # whose references did not exist when the prediction rule's margin was fixed.
              (1 / 4, 1 / 4, None), (1 / 2, 1 / 10, None), (1 / 4, 1 / 10, None),
              # the thinnest strip of issue 17 (W^2/(bL) = 10): a fold of US the stable path snaps at
              (1 / 2, 1 / 20, 4000.0))
#: Issue 32's fitting scenes for the map over dL/L and L/b: a third compression between the paper's
#: two, and W/L = 1/6 at L/b = 4000 (the map has 1/6 at 300 and 1181 only; run with --only NAME
#: like MAP_SCENES). The error map (validation/error_map/) reads them as fitting scenes.
NEW_MAP_SCENES = ((1 / 3, 1 / 20, None), (1 / 3, 1 / 6, None), (1 / 3, 1 / 10, None), (1 / 3, 1 / 3, None),
                  (1 / 2, 1 / 6, 4000.0))
#: Issue 32's held-out scenes, named with ddg.advise's rule v3 and committed before their
#: references were computed (run with --only NAME): one per direction the rule interpolates in, each
#: inside the map's range by that rule: a dL/L between the map's (0.4 between 1/3 and 1/2, and 0.3
#: between 1/4 and 1/3 at a width between the map's), a W/L between the map's at the new dL/L = 1/3
#: (1/8 between 1/10 and 1/6), an L/b between 1181 and 4000 (2000 at W/L = 1/20, dL/L = 1/2).
HELD_OUT_SCENES = ((0.4, 1 / 20, None), (1 / 3, 1 / 8, None), (1 / 2, 1 / 20, 2000.0), (0.3, 1 / 4, None))
#: dW1 and dW2 bisection brackets of the gold runs (units of L), a tenth of the smallest change
#: between meshes of the earlier W/L = 1/6 study (dW2: 0.4336 to 0.4306 from 90 to 120 elements).
GOLD_TOLERANCES = (1e-4, 1e-4)


def mesh_sequence(width_ratio: float, base: int = BASE_RESOLUTION, levels: int = LEVELS) -> list[tuple[int, int]]:
    """(elements along L, elements across W) of each mesh of a scene's study, coarsest first
    (counts rounded up to even; exact 1.5 ratios for base a multiple of 8)."""
    across = next(v for w, v in BASE_ACROSS.items() if abs(w - width_ratio) < 1e-9)
    return refined_sequence(base, across, levels)


def refined_sequence(along: int, across: int, levels: int) -> list[tuple[int, int]]:
    """`levels` meshes from (along, across), each REFINEMENT times finer (counts rounded up to even)."""
    def even(x: float) -> int:
        n = int(round(x)) if abs(x - round(x)) < 1e-9 else int(x) + 1
        return n + (n % 2)

    return [(even(along * REFINEMENT**k), even(across * REFINEMENT**k)) for k in range(levels)]


def run_folder_name(along: int, across: int) -> str:
    return f"N{along}x{across}"


def scene_name(compression_ratio: float, width_ratio: float, slenderness: float | None = None) -> str:
    """dL<dL/L>_W<W/L>, with _Lb<L/b> for a strip other than the paper's (e.g. dL0.5_W0.05_Lb300)."""
    name = f"dL{compression_ratio:.4g}_W{width_ratio:.4g}"
    return name if slenderness is None else f"{name}_Lb{slenderness:.4g}"


def scenes() -> list[tuple[str, float, float]]:
    """All ten scenes, the ones the tests need first."""
    first = [(1 / 2, 1 / 6), (1 / 2, 1 / 20), (1 / 2, 1 / 2)]
    rest = [(c, w) for c in COMPRESSION_RATIOS for w in WIDTH_RATIOS if (c, w) not in first]
    return [(scene_name(c, w), c, w) for c, w in first + rest]


def all_scenes() -> list[tuple[str, float, float, float | None]]:
    """The paper's ten, MAP_SCENES, NEW_MAP_SCENES and HELD_OUT_SCENES as (name, dL/L, W/L, L/b or None)."""
    return [(name, c, w, None) for name, c, w in scenes()] + \
        [(scene_name(c, w, lb), c, w, lb) for c, w, lb in MAP_SCENES + NEW_MAP_SCENES + HELD_OUT_SCENES]


def _read_summary(path: Path) -> dict | None:
    """summary.json of a scene folder, None if missing or unreadable (an unreadable one is rerun)."""
    return read_json_object(path)


def check_gold_inputs(args) -> list[tuple[str, float, float, list[tuple[int, int]]]]:
    """The scenes to run as (name, dL/L, W/L, meshes), every input checked before any work:
    --only names known, --levels in 1..4, every mesh of every selected scene within the mesh
    bounds and memory (mesh.checked_spec), the cluster options (cluster_inputs: dask importable
    unless --studies-only), --out writable. One-line InputError otherwise."""
    from ddg.geometry.strip import InputError
    from ddg.limits import check_integer
    from ddg.output.io import check_output_directory

    from .mesh import checked_spec

    known = [name for name, _, _, _ in all_scenes()]
    only = args.only or None
    if only:
        unknown = [name for name in dict.fromkeys(only) if name not in known]
        if unknown:
            raise InputError(f"--only: unknown gold scene(s) {', '.join(map(repr, unknown))}; "
                             f"choose from {', '.join(known)}")
    levels = check_integer("--levels", LEVELS if args.levels is None else args.levels, 1, MAX_LEVELS,
                           "meshes per scene (3 for Richardson extrapolation with an observed order)")
    base = BASE_RESOLUTION if args.resolution is None else args.resolution
    selected = []
    paper = {name for name, _, _ in scenes()}
    for name, dL, W, slenderness in all_scenes():
        if (only and name not in only) or (not only and name not in paper):
            continue
        checked_spec(base, W, None, "--resolution")  # the base count's own bounds first
        meshes = mesh_sequence(W, int(base), levels)
        for along, across in meshes:
            checked_spec(along, W, across, f"--resolution (mesh {along} x {across} of the study)")
        selected.append((name, dL, W, slenderness, meshes))
    cluster_inputs(args)
    check_output_directory(args.out, "--out")
    return selected


def _finished(summary: dict | None, along: int, across: int) -> bool:
    """A stored run that needs no rerun: finished (complete, or stopped: a rerun stops again), on
    this mesh, with the gold tolerances."""
    if not summary or summary.get("status") not in ("complete", "stopped"):
        return False
    mesh = summary.get("mesh") or {}
    tolerances = summary.get("threshold_tolerances_over_L") or {}
    return (mesh.get("elements_along_L"), mesh.get("elements_across_W")) == (along, across) and \
        (tolerances.get("dW1"), tolerances.get("dW2")) == GOLD_TOLERANCES


def cluster_inputs(args, check: bool = True) -> tuple[str | None, int | None, int]:
    """(scheduler, workers, retries) of --scheduler, --workers, --retries, checked
    (ddg.sweep.cluster.checked_options), and dask importable unless --studies-only: the scheduler
    to use, None for a LocalCluster. With `check`, a scheduler is connected to once
    (ddg.sweep.cluster.ready), before check_gold_inputs creates --out. One-line InputError otherwise."""
    from ddg.sweep.cluster import checked_options, ready

    scheduler, workers, retries = checked_options(getattr(args, "scheduler", None), getattr(args, "workers", None),
                                                  getattr(args, "retries", 2))
    if not getattr(args, "studies_only", False):
        scheduler = ready(scheduler, workers, check)
    return scheduler, workers, retries


def run_mesh(compression_ratio: float, width_ratio: float, slenderness: float | None, along: int, across: int,
             target: str) -> dict:
    """One run of a study, in a Dask worker (dolfinx is imported here): the whole path on `along` x
    `across` elements, dW1 and dW2 bisected to GOLD_TOLERANCES, into `target` (path.csv,
    summary.json). Returns its status, dW1_over_L, dW2_over_L, converged and wall_time_s; a run
    an earlier attempt finished is returned as stored; a run that raised gives {"error": one line}
    (not retried: it would fail again), its converged part written with status "error"."""
    from ddg.geometry.strip import LoadingProtocol, Strip

    t0 = time.perf_counter()
    summary = _read_summary(Path(target) / "summary.json")
    if not _finished(summary, along, across):
        from .api import simulate
        from .continuation import ContinuationOptions

        options = ContinuationOptions(dw1_tolerance=GOLD_TOLERANCES[0], dw2_tolerance=GOLD_TOLERANCES[1])
        strip = Strip.from_ratios(width_ratio, compression_ratio, slenderness)
        try:
            summary = simulate(strip, LoadingProtocol(compression_ratio), along, out=target, across=across,
                               fields=False, options=options, progress=False, centerline=False).summary
        except Exception as exc:  # noqa: BLE001  (reported by the client, one line)
            need = "the FEM reference needs dolfinx 0.5, petsc4py, slepc4py, mpi4py and gmsh: " \
                if isinstance(exc, ImportError) else ""
            return {"error": f"{need}{type(exc).__name__}: {' '.join(str(exc).split())}",
                    "wall_time_s": time.perf_counter() - t0}
    return {**{k: summary.get(k) for k in ("status", "dW1_over_L", "dW2_over_L")},
            "converged": bool(summary.get("converged")), "wall_time_s": time.perf_counter() - t0}


def run_gold(args) -> int:
    """The gold command: each unfinished run of the selected scenes a Dask task (ddg.sweep.cluster:
    a LocalCluster of --workers processes, or the cluster at --scheduler), written by its worker
    into OUT/<scene>/N<along>x<across>/; here, as each one ends, its scene's study and the index.
    Exit 0, 3 if a run stopped short, 1 if one failed; Ctrl-C keeps the finished runs."""
    from ddg.output.interrupts import deferred_signals, signal_name_of
    from ddg.sweep.cluster import StudyLog, Task, run_all
    from ddg.sweep.grid import code_version

    selected = check_gold_inputs(args)  # before any FEM import and any work

    out = Path(args.out)
    if getattr(args, "studies_only", False):   # no FEM import: the studies read the stored runs
        for name, _, _, _, meshes in selected:
            if (out / name).is_dir():
                write_scene_study(out / name, meshes)
        write_index(out)
        return 0

    scheduler, workers, retries = cluster_inputs(args, check=False)   # check_gold_inputs connected to it
    where = hashlib.sha256(str(out.resolve()).encode()).hexdigest()[:8]
    tasks = []
    for name, dL, W, slenderness, meshes in selected:
        for along, across in meshes:
            target = out.resolve() / name / run_folder_name(along, across)
            if _finished(_read_summary(target / "summary.json"), along, across):
                continue
            tasks.append(Task(f"fem-gold-{name}-{run_folder_name(along, across)}-{where}", run_mesh,
                              (dL, W, slenderness, along, across, str(target)), along * across,
                              (name, along, across, meshes)))

    def after(task):
        write_scene_study(out / task.tag[0], task.tag[3])
        write_index(out)

    log = StudyLog(lambda task, _: f"{task.tag[0]} {task.tag[1]} x {task.tag[2]}", after, args.quiet)
    ran = run_all(tasks, log, scheduler=scheduler, workers=workers, retries=retries, code=code_version(),
                  shared=out)
    with deferred_signals():  # the index lists what is finished, also after Ctrl-C
        if ran.interrupted is not None:  # runs that ended while the client was stopping
            for name, meshes in {task.tag[0]: task.tag[3] for task in tasks}.items():
                write_scene_study(out / name, meshes)
        write_index(out)
    if ran.interrupted is not None:
        done = sum(_finished(_read_summary(Path(t.args[5]) / "summary.json"), t.args[3], t.args[4]) for t in tasks)
        ran.interrupted.run_message = (f"interrupted by {signal_name_of(ran.interrupted)}: {done} of {len(tasks)} "
                                       f"runs finished and kept in {out}; a rerun computes only the other "
                                       f"{len(tasks) - done}")
        raise ran.interrupted
    return log.exit_code


def scene_runs(folder: Path, meshes=None) -> list[tuple[int, int, Path]]:
    """The finished runs of one scene folder, coarsest first: (along, across, run folder); only
    those of `meshes` if given."""
    found = []
    for run in sorted(folder.glob("N*x*")):
        summary = _read_summary(run / "summary.json")
        mesh = (summary or {}).get("mesh") or {}
        key = (mesh.get("elements_along_L"), mesh.get("elements_across_W"))
        if summary and summary.get("status") in ("complete", "stopped") and None not in key:
            if meshes is None or key in meshes:
                found.append((int(key[0]), int(key[1]), run))
    return sorted(found)


def write_scene_study(folder: Path, meshes=None) -> dict | None:
    """The scene's mesh study from its finished runs (fem_reference.convergence): convergence.md,
    convergence.csv, thresholds.csv and richardson.json in the scene folder; None with no run.
    With `meshes` (a gold sequence), the runs of every level of that sequence up to MAX_LEVELS
    that exist: a fourth mesh run with --levels 4 stays in the study when it is rewritten with the
    default three. The refinement ratios are those of sqrt(along x across) (Celik's N^(1/2)):
    the fourth level's across-count is rounded up to even (8 x 3.375 = 27 -> 28)."""
    from ddg.geometry.strip import LoadingProtocol, Strip
    from ddg.output.io import StoredRun

    from .convergence import study_estimates, summarise, write_outputs

    if meshes:  # every level of the scene's sequence that has a run, not only those asked for
        meshes = list(dict.fromkeys(list(meshes) + refined_sequence(*meshes[0], MAX_LEVELS)))
    found = scene_runs(folder, meshes)
    if not found:
        return None
    runs = [StoredRun(str(path)) for _, _, path in found]
    resolutions = [along for along, _, _ in found]
    sizes = [math.sqrt(along * across) for along, across, _ in found]
    scene = runs[-1].summary["scene"]
    estimates = study_estimates(runs, resolutions, sizes=sizes)
    sheared = [(n, r) for n, r in zip(resolutions, runs) if any(row["stage"] == "shear" for row in r.rows)]
    if len(sheared) >= 2:
        rows, table = summarise([r for _, r in sheared], [n for n, _ in sheared])
        write_outputs(folder, rows, table, [r for _, r in sheared], [n for n, _ in sheared],
                      Strip.from_ratios(scene["width_ratio"], scene["compression_ratio"], scene["slenderness"]),
                      LoadingProtocol(scene["compression_ratio"]))
    study = {"scene": {k: scene[k] for k in ("width_ratio", "compression_ratio", "slenderness")},
             "meshes": [{"along": a, "across": c, "folder": p.name, "status": r.summary["status"],
                         "n_dof": r.summary["n_dof"], "wall_time_s": r.summary["wall_time_s"],
                         "newton_iterations": r.summary["newton_iterations"],
                         "dW1_over_L": r.summary["dW1_over_L"], "dW2_over_L": r.summary["dW2_over_L"],
                         "H_mid_over_L_compressed": r.summary["H_mid_over_L_compressed"],
                         "linear_resolution": h}
                        for (a, c, p), r, h in zip(found, runs, sizes)],
             "refinement_ratio": REFINEMENT, "threshold_tolerances_over_L": list(GOLD_TOLERANCES),
             **estimates}
    atomic_write_text(folder / "richardson.json", json.dumps(study, indent=2) + "\n")
    from .series import write_series

    write_series(folder)  # the scene's independent mesh series, where it has some (fem_reference.series.SERIES)
    return study


def finest_run(folder: Path) -> Path | None:
    """The scene's reference run for the report's H_mid figures: the single run at the folder's top
    level where there is one (the layout before the mesh studies), else the finest finished run of
    the study (N<along>x<across>), else None. The claims and the benchmark use the studies'
    converged values instead (validation.estimates)."""
    if (folder / "summary.json").exists():
        return folder
    found = scene_runs(folder)
    return found[-1][2] if found else None


def write_index(out: Path) -> None:
    """OUT/index.json: every scene with its study (richardson.json) or its single run (the layout
    before the studies), then OUT/README.md."""
    index = {}
    for name, dL, W, slenderness in all_scenes():
        folder = out / name
        study = _read_summary(folder / "richardson.json")
        finest = finest_run(folder)
        s = _read_summary(finest / "summary.json") if finest is not None else None
        if s is None:
            continue
        scene, mesh = s.get("scene") or {}, s.get("mesh") or {}
        entry = {"compression_ratio": dL, "width_ratio": W, "slenderness": slenderness,
                 "converged": bool(s.get("converged")),
                 "status": s.get("status"), "message": s.get("message", ""),
                 "finest_run": str(finest.relative_to(out)), "resolution": scene.get("resolution"),
                 "triangles": mesh.get("triangles"), "n_dof": s.get("n_dof"), "wall_time_s": s.get("wall_time_s"),
                 "H_mid_over_L_compressed": s.get("H_mid_over_L_compressed"),
                 "dW1_over_L": s.get("dW1_over_L"), "dW2_over_L": s.get("dW2_over_L"),
                 "dW_max_over_L": s.get("dW_max_over_L"),
                 "resolved_up_to_dW_over_L": s.get("resolved_up_to_dW_over_L")}
        if study is not None:
            entry["study"] = {"meshes": [f"{m['along']}x{m['across']}" for m in study["meshes"]],
                              "wall_time_s": sum(m["wall_time_s"] or 0.0 for m in study["meshes"]),
                              **{key: study[key] for key in ("dW1", "dW2", "H_mid_compressed") if key in study}}
        index[name] = entry
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "index.json", json.dumps(index, indent=2) + "\n")
    write_readme(out, index)


README_HEAD = """# FEM gold data (fem_reference, nonlinear Naghdi shell)

Regenerate (run by run, finished runs are kept; a few hours on one core):

    .venv/bin/python -m fem_reference gold --out data/fem_gold [--only dL0.5_W0.1667 ...]

Each scene (names dL<dL/L>_W<W/L>: dL0.5_W0.05, dL0.5_W0.08333, dL0.5_W0.1667, dL0.5_W0.3333,
dL0.5_W0.5, dL0.25_W0.05, ...) is run on three meshes refined by 1.5 in both directions (64, 96,
144 elements along L; across W 8/12/18 for W/L <= 1/6, 16/24/36 for 1/3, 24/36/54 for 1/2), and a
fourth (216 x 28, 216 x 54, 216 x 82; `--levels 4`) where the first three are not asymptotic, stop
short or converge at an order below 1.5; dW1 and dW2 bisected to 1e-4 L. Each run folder
N<along>x<across>/ holds path.csv and summary.json (no centerline.csv: no study reads it); the
scene folder holds the study: richardson.json, convergence.md. A scene folder with a single run at
its top level is from before the studies (60 elements, dW2 to 1e-3 L); the report's H_mid figures
still draw it, while the claims and the benchmark use the studies' converged values
(validation/estimates.py). Runs of other meshes in a scene folder are kept as evidence and are not
part of its study (W/L = 1/6: 40 x 8, 60 x 12, 90 x 18, not asymptotic: convergence_40_60_90.md;
the independent series of fem_reference/series.py, compared in series.md). Below the paper's ten, the error map's
scenes (fem_reference.gold.MAP_SCENES, `--only NAME`, names with _Lb<L/b> for another strip) are
listed as far as they have been run; the error map (validation/error_map/) uses one from two meshes.
Issue 32's dL/L = 1/3 scenes (NEW_MAP_SCENES) are listed too; the map reads them once their plate
studies exist.

## The error-bar rule (fem_reference.convergence.estimate, rule 2, issue 28)

Of the finest three meshes of a study with a value, f1, f2, f3 (coarse to fine), d1 = f2 - f1,
d2 = f3 - f2, refinement ratios from sqrt(along x across) (1.5, and 1.53 to the fourth mesh whose
across-count is rounded up to even), observed order p from the error model f* + C h^p (Celik et
al. 2008; ln|d1/d2| / ln 1.5 for equal ratios):

- asymptotic (d1, d2 of one sign, p in [1, 4]): the value is the Richardson extrapolation
  f3 + d2/(r^p - 1), the error bar Fs |d2|/(r^p - 1) (Roache's grid convergence index of the finest
  mesh) with Fs = 1.25 for p >= 1.5 and Fs = 3 for p < 1.5 (a low order is not a confirmed one);
- not asymptotic (differences of opposite sign, not shrinking, or p outside [1, 4]): the value is
  the finest mesh's, the error bar 3 max(|d1|, |d2|), and where p < 1 with both differences beyond
  the bisection bracket at least |d2|/(r^p - 1), the distance to the limit at the observed order
  (p counted as at least 0.5: a slower sequence has not begun to converge);
- two meshes: the finest value, 3 |f2 - f1|; one mesh: no error bar (the benchmark asks three);
- a threshold's bisection bracket (dW1: half of 1e-4, dW2: 1e-4) is added to its error bar.

The same estimate is made at every recorded dW for H_mid/L (richardson.json `H_mid_curve`) and
the clamp force F_shear L/(E b^3) (`F_shear_curve`), from the meshes that reached that dW (a
curve ends where fewer than two go on). Until issue 28 (rule 1) a non-asymptotic sequence whose
differences shrank got |d2| alone and every order 1.25; at W/L = 1/6, dL/L = 1/2 that bar (0.0010)
was 3.5 times smaller than the distance to an independent isotropic mesh series' extrapolation.
Tested on constructed sequences in tests/fem_reference/test_fem_gold_study.py.
`--studies-only` rewrites the studies and this file from the stored runs without running any.

## What exists (written by the gold command)

| scene | meshes | dW1/L | +- | order | dW2/L | +- | order | finest run | complete | wall time s (all meshes) |
|---|---|---:|---:|---:|---:|---:|---:|---|---|---:|
"""


def write_readme(out: Path, index: dict) -> None:
    """OUT/README.md: how to regenerate, and the table of the scenes that exist."""
    missing = [name for name, _, _ in scenes() if name not in index]

    def fmt(v, spec="{:.4f}"):
        return "-" if not isinstance(v, (int, float)) or isinstance(v, bool) else spec.format(v)

    def complete(e):
        if e["converged"]:
            return "yes"
        return f"no ({e['status']}): {e['message']}" if e.get("status") else f"no: {e['message']}"

    rows = []
    for name, e in index.items():
        study = e.get("study") or {}
        cells = []
        for key, single in (("dW1", "dW1_over_L"), ("dW2", "dW2_over_L")):
            est = study.get(key)
            if est:
                flag = "" if est["asymptotic"] else \
                    f" ({len(est['meshes'])} meshes)" if len(est["meshes"]) < 3 else " (not asymptotic)"
                cells += [fmt(est["value"]), fmt(est["error_bar"]), fmt(est["order"], "{:.2f}") + flag]
            else:
                cells += [fmt(e[single]), "-", "-"]
        meshes = ", ".join(study.get("meshes", [])) or f"{e['resolution']} (single run)"
        wall = study.get("wall_time_s", e["wall_time_s"])
        rows.append(f"| {name} | {meshes} | {' | '.join(cells)} | {e['finest_run']} | {complete(e)} | "
                    f"{fmt(wall, '{:.0f}')} |")
    text = README_HEAD + "\n".join(rows) + "\n"
    if missing:
        text += f"\nNot yet run (one command away, see above): {', '.join(missing)}.\n"
    atomic_write_text(out / "README.md", text)
