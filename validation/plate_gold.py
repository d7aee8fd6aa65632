"""Mesh studies of the DDG plate on the benchmark scenes:
`python -m validation plate-gold --out data/plate_gold [--only NAME ...] [--levels K]
[--model plate|plate-midedge] [--workers N | --scheduler ADDRESS] [--retries 2]` (the mid-edge
plate on ghost-clamp meshes of the same rows, e.g. into data/midedge_gold; old spelling
`python -m validation.plate_gold`).

Each of the ten scenes of fem_reference.gold (dL/L in {1/2, 1/4} x W/L in {1/20, 1/12, 1/6, 1/3,
1/2}, L/b = 1181; with --only also the error map's scenes, fem_reference.gold.MAP_SCENES) is run
with the plate on LEVELS exactly equilateral meshes (ddg.geometry.plate_mesh.equilateral_mesh)
refined uniformly by 1.5: BASE_ROWS[W/L] rows of triangles across W, then 1.5 and 2.25 times as
many (every spacing divided by 1.5 each time;
the default structured mesh cannot refine uniformly, its column count must stay odd). Each run
is the default path (docs/guide/run_a_scene.rst: 40 compression and 120 shear steps to dW_max, thresholds located, no
branch tracing) into OUT/<scene>/R<rows>/ (path.csv, summary.json; no centerline.csv, which no
study reads); after each run the scene's study is rewritten with the same estimates as the FEM gold
(fem_reference.convergence.study_estimates: Richardson with the observed order and a grid
convergence index where asymptotic, else the finest value with its spread, flagged):
OUT/<scene>/richardson.json and convergence.md, then OUT/index.json and OUT/README.md.
Resumable run by run (a finished run on the same mesh is kept).

The runs are Dask tasks, as `python -m ddg sweep`'s (ddg.sweep.cluster): by default on a
LocalCluster of one single-threaded worker process per core (--workers N), with --scheduler on an
existing cluster whose workers share OUT and the checkout; each worker writes its run's folder,
the client rewrites the studies and the index as each run ends. A worker killed mid-run costs that
run, which is retried (--retries); Ctrl-C keeps every finished run (exit 130). Exit 3 if a run
stopped short, 1 if one failed (one line each on stderr).
"""
from __future__ import annotations

import hashlib
import json
import sys
import time
from pathlib import Path

from ddg.output.io import atomic_write_text, finished_run_summary, read_json_object

from .command_line import standalone
from .estimates import DDG_TOLERANCES, load_study  # DDG_TOLERANCES: also read from here by benchmarks/

#: Rows of triangles across W on the coarsest mesh (a multiple of 8: 1.5 and 2.25 times it stay even).
BASE_ROWS = {1 / 20: 8, 1 / 12: 8, 1 / 10: 8, 1 / 8: 8, 1 / 6: 8, 1 / 4: 16, 1 / 3: 16, 1 / 2: 16}
REFINEMENT = 1.5
LEVELS = 3


def rows_sequence(width_ratio: float, levels: int = LEVELS) -> list[int]:
    base = next(v for w, v in BASE_ROWS.items() if abs(w - width_ratio) < 1e-9)
    return [int(round(base * REFINEMENT**k)) for k in range(levels)]


def _finished(folder: Path) -> bool:
    return finished_run_summary(folder) is not None


#: The plate models a study can run, with the mesh each needs (rows of triangles across W given).
MODELS = {"plate": "equilateral structured (ddg.geometry.plate_mesh.equilateral_mesh)",
          "plate-midedge": "ghost-clamp structured (ddg.geometry.plate_mesh.ghost_clamp_mesh)"}
TITLES = {"plate": "Plate", "plate-midedge": "Mid-edge plate"}


def model_mesh(model: str, length: float, width: float, rows: int):
    """The study mesh of `model` with `rows` rows of triangles across W."""
    from ddg.geometry.plate_mesh import equilateral_mesh, ghost_clamp_mesh

    if model == "plate-midedge":
        return ghost_clamp_mesh(length, width, rows=rows)
    return equilateral_mesh(length, width, rows)


def run_mesh(name: str, compression: float, width: float, slenderness: float | None, rows: int, model: str,
             target: str) -> dict:
    """One run of a study, in a Dask worker: `model` on `rows` rows of triangles across W into
    `target` (path.csv, summary.json). Returns its triangles, status, dW1_over_L, dW2_over_L,
    converged and wall_time_s; a run an earlier attempt finished is returned as stored, a run
    that raised gives {"error": one line} (not retried: it would fail again)."""
    import ddg

    t0 = time.perf_counter()
    summary = finished_run_summary(target)
    if summary is None:
        strip = ddg.Strip.from_ratios(width, compression, slenderness)
        try:
            summary = ddg.simulate(strip, ddg.LoadingProtocol(compression), model=model,
                                   mesh=model_mesh(model, strip.length, strip.width, rows), out=target,
                                   branches=False, centerline=False).summary
        except Exception as exc:  # noqa: BLE001  (reported by the client, one line)
            return {"error": f"{type(exc).__name__}: {' '.join(str(exc).split())}",
                    "wall_time_s": time.perf_counter() - t0}
    return {"triangles": (summary.get("mesh") or {}).get("triangles"),
            **{k: summary.get(k) for k in ("status", "dW1_over_L", "dW2_over_L")},
            "converged": bool(summary.get("converged")), "wall_time_s": time.perf_counter() - t0}


def study_tasks(out: Path, selected, levels: int, model: str) -> list:
    """The unfinished runs of the selected scenes ((name, dL/L, W/L, L/b)) as Dask tasks
    (ddg.sweep.cluster.Task, tagged (name, rows, sequence)), the largest meshes first (a priority
    proportional to the triangle count: the workers end together)."""
    from ddg.sweep.cluster import Task

    root = Path(out).resolve()
    where = hashlib.sha256(str(root).encode()).hexdigest()[:8]
    tasks = []
    for name, compression, width, slenderness in selected:
        sequence = rows_sequence(width, levels)
        for rows in sequence:
            target = root / name / f"R{rows}"
            if not _finished(target):
                tasks.append(Task(f"plate-gold-{model}-{name}-R{rows}-{where}", run_mesh,
                                  (name, compression, width, slenderness, rows, model, str(target)),
                                  int(rows * rows / width), (name, rows, sequence)))
    return tasks


def write_scene_study(folder: Path, sequence: list[int], model: str = "plate") -> dict | None:
    """richardson.json and convergence.md of one scene from its finished runs of `sequence`."""
    from ddg.output.io import StoredRun
    from fem_reference.convergence import study_estimates

    found = [(rows, folder / f"R{rows}") for rows in sequence if _finished(folder / f"R{rows}")]
    if not found:
        return None
    runs = [StoredRun(str(path)) for _, path in found]
    resolutions = [rows for rows, _ in found]
    estimates = study_estimates(runs, resolutions, default_tolerances=DDG_TOLERANCES)
    scene = runs[-1].summary["scene"]
    study = {"model": model, "mesh": MODELS[model],
             "scene": {k: scene[k] for k in ("width_ratio", "compression_ratio", "slenderness")},
             "meshes": [{"rows": rows, "folder": path.name, "status": run.summary["status"],
                         "triangles": run.summary["mesh"]["triangles"], "wall_time_s": run.summary["wall_time_s"],
                         "newton_iterations": run.summary["newton_iterations"],
                         "dW1_over_L": run.summary["dW1_over_L"], "dW2_over_L": run.summary["dW2_over_L"],
                         "H_mid_over_L_compressed": run.summary["H_mid_over_L_compressed"]}
                        for (rows, path), run in zip(found, runs)],
             "refinement_ratio": REFINEMENT, **estimates}
    atomic_write_text(folder / "richardson.json", json.dumps(study, indent=2) + "\n")
    title = f"# {TITLES[model]} mesh study: W/L = {scene['width_ratio']:.4g}, dL/L = {scene['compression_ratio']:g}"
    lines = [title, "",
             "| rows across W | triangles | status | dW1/L | dW2/L | H_mid/L compressed | wall s | Newton its |",
             "|---:|---:|---|---:|---:|---:|---:|---:|"]
    for m in study["meshes"]:
        lines.append(f"| {m['rows']} | {m['triangles']} | {m['status']} | {_fmt(m['dW1_over_L'])} | "
                     f"{_fmt(m['dW2_over_L'])} | {_fmt(m['H_mid_over_L_compressed'], '{:.6f}')} | "
                     f"{m['wall_time_s']:.0f} | {m['newton_iterations']} |")
    lines.append("")
    for key in ("dW1", "dW2", "H_mid_compressed"):
        e = estimates.get(key)
        if e:
            lines.append(f"- {key}: {_fmt(e['value'], '{:.5f}')} +- {_fmt(e['error_bar'], '{:.5f}')} "
                         f"(order {_fmt(e['order'], '{:.2f}')}; {e['basis']})")
    atomic_write_text(folder / "convergence.md", "\n".join(lines) + "\n")
    return study


def _fmt(value, spec="{:.4f}"):
    return "-" if not isinstance(value, (int, float)) or isinstance(value, bool) else spec.format(value)


def write_index(out: Path, model: str = "plate") -> None:
    from fem_reference.gold import all_scenes

    index = {}
    for name, _, _, _ in all_scenes():
        study = read_json_object(out / name / "richardson.json")
        if study is not None:
            index[name] = {"meshes": [m["rows"] for m in study["meshes"]],
                           "triangles": [m["triangles"] for m in study["meshes"]],
                           "wall_time_s": sum(m["wall_time_s"] for m in study["meshes"]),
                           **{k: study.get(k) for k in ("dW1", "dW2", "H_mid_compressed")}}
    atomic_write_text(out / "index.json", json.dumps(index, indent=2) + "\n")
    lines = [f"# DDG {TITLES[model].lower()} mesh studies (validation/plate_gold.py)", "",
             f"Regenerate (run by run, finished runs kept): `.venv/bin/python -m validation.plate_gold --model {model} "
             f"--out {out}`. Meshes: {MODELS[model]}, rows across W 8/12/18 (W/L <= 1/6) or 16/24/36; "
             "error bars as the FEM gold's (data/fem_gold/README.md).", "",
             "| scene | rows | triangles | dW1/L | +- | order | dW2/L | +- | order | wall s |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for name, e in index.items():
        cells = []
        for key in ("dW1", "dW2"):
            est = e.get(key)
            cells += ([_fmt(est["value"]), _fmt(est["error_bar"]),
                       _fmt(est["order"], "{:.2f}") + ("" if est["asymptotic"] else " (not asymptotic)")]
                      if est else ["-", "-", "-"])
        lines.append(f"| {name} | {', '.join(map(str, e['meshes']))} | {', '.join(map(str, e['triangles']))} | "
                     f"{' | '.join(cells)} | {e['wall_time_s']:.0f} |")
    lines += ["", *agreement_lines(out, model)]
    atomic_write_text(out / "README.md", "\n".join(lines) + "\n")


def agreement_lines(out: Path, model: str) -> list[str]:
    """Markdown lines comparing each stored study in `out` with the shell's (data/fem_gold) by the
    gold's rule (validation.claims.threshold_agreement): |DDG - FEM| against the sum of the bars."""
    from fem_reference.gold import all_scenes

    from .claims import threshold_agreement

    def cell(estimate):
        return "-" if estimate is None else f"{estimate.value:.4f} +- {_fmt(estimate.error_bar)}"

    lines = ["Against the shell's studies (data/fem_gold; the same error-bar rule): |diff|/combined is |DDG - FEM| "
             "over the sum of the two error bars, at most 1 where they agree.", "",
             "| scene | DDG dW1/L | FEM dW1/L | \\|diff\\|/combined | DDG dW2/L | FEM dW2/L | \\|diff\\|/combined |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, compression, width, _ in all_scenes():
        mine = load_study(model, compression, width, root=out, name=name)
        if mine is None:
            continue
        fem = load_study("fem", compression, width, name=name)
        cells = []
        for key in ("dW1", "dW2"):
            agreement = threshold_agreement(mine, fem, key) if fem is not None else None
            cells += [cell(mine.threshold(key)), cell(fem.threshold(key) if fem is not None else None),
                      "-" if agreement is None else f"{agreement.difference / agreement.combined_error_bar:.2f}"]
        lines.append(f"| {name} | {' | '.join(cells)} |")
    return lines


def add_arguments(parser) -> None:
    """The options of `python -m validation plate-gold`."""
    from ddg.sweep import cluster

    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--out", default="data/plate_gold")
    parser.add_argument("--only", nargs="*", default=None)
    parser.add_argument("--levels", type=int, default=LEVELS)
    parser.add_argument("--quiet", action="store_true")
    parser.add_argument("--model", choices=sorted(MODELS), default="plate")
    parser.add_argument("--studies-only", action="store_true",
                        help="no run: rewrite each selected scene's study and the index from its finished runs")
    cluster.add_options(parser)  # --workers, --scheduler, --retries: the runs are Dask tasks, as the sweep's


def run(args) -> int:
    """Every option checked before any folder is made, then the selected scenes' runs as Dask tasks
    (module docstring), each scene's study and the index rewritten as each run ends."""
    from ddg.geometry.strip import InputError
    from ddg.output.interrupts import deferred_signals, exit_code_of, signal_name_of, terminate_as_interrupt
    from ddg.output.io import check_output_directory
    from ddg.solve.blas_threads import requested_threads
    from ddg.sweep import cluster
    from ddg.sweep.grid import code_version
    from fem_reference.gold import all_scenes, scenes

    terminate_as_interrupt()  # SIGTERM too keeps the finished runs
    known = [name for name, _, _, _ in all_scenes()]
    paper = {name for name, _, _ in scenes()}
    try:
        unknown = [n for n in (args.only or []) if n not in known]
        if unknown:
            raise InputError(f"--only: unknown scene(s) {unknown}; choose from {', '.join(known)}")
        if not 1 <= args.levels <= 4:
            raise InputError(f"--levels = {args.levels} outside 1..4")
        scheduler, workers, retries = cluster.checked_options(args.scheduler, args.workers, args.retries)
        if not args.studies_only:
            requested_threads()   # a bad DDG_BLAS_THREADS would fail every run on its worker
            scheduler = cluster.ready(scheduler, workers)   # connected to first: then --out is made
        out = check_output_directory(args.out, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    # the error map's scenes (fem_reference.gold.MAP_SCENES) run only when named
    selected = [(name, compression, width, slenderness) for name, compression, width, slenderness in all_scenes()
                if (name in args.only if args.only else name in paper)]
    if args.studies_only:
        for name, _, width, _ in selected:
            if (out / name).is_dir():
                write_scene_study(out / name, rows_sequence(width, args.levels), args.model)
        write_index(out, args.model)
        return 0
    tasks = study_tasks(out, selected, args.levels, args.model)

    def label(task, result):
        name, rows, _ = task.tag
        return f"{name} R{rows}" + ("" if result is None else f" ({result['triangles']} triangles)")

    def after(task):
        write_scene_study(out / task.tag[0], task.tag[2], args.model)
        write_index(out, args.model)

    log = cluster.StudyLog(label, after, args.quiet)

    try:
        ran = cluster.run_all(tasks, log, scheduler=scheduler, workers=workers, retries=retries,
                              code=code_version(), shared=out)
    except InputError as exc:  # the scheduler at --scheduler does not answer
        print(f"error: {exc}", file=sys.stderr)
        return 2
    with deferred_signals():  # the index lists what is finished, also after Ctrl-C
        if ran.interrupted is not None:  # runs that ended while the client was stopping
            for name, sequence in {t.tag[0]: t.tag[2] for t in tasks}.items():
                write_scene_study(out / name, sequence, args.model)
        write_index(out, args.model)
    if ran.interrupted is not None:
        done = sum(_finished(Path(t.args[6])) for t in tasks)
        print(f"error: interrupted by {signal_name_of(ran.interrupted)}: {done} of {len(tasks)} runs finished and "
              f"kept in {out}; a rerun computes only the other {len(tasks) - done}", file=sys.stderr)
        return exit_code_of(ran.interrupted)
    return log.exit_code


def main(argv=None) -> int:
    """`python -m validation.plate_gold [options]`: the same as `python -m validation plate-gold [options]`."""
    return standalone("plate-gold", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
