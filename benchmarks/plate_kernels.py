"""The mid-edge plate's three compiled kernels timed one by one, and against another source tree.

    .venv/bin/python -m benchmarks.plate_kernels [--against DIR] [--rounds 5] [--rows 8 12 18 28]
        [--budget 0.25] [--out benchmarks/results]

Issue 50 item 2: the mid-edge plate's energy kernels at <= 0.4 us per triangle or hinge for energy,
gradient and Hessian. For each mesh (ddg.Strip.from_ratios(1/6, 0.5), MidedgePlateModel(strip,
rows=R)) it takes a deformed state: the buckled guess at dL = L/2 with a seeded random perturbation
of 1e-3 L of the nodes and random edge angles of 1e-2 (no term vanishes), and times

- each kernel alone, as the model's evaluate calls it, into accumulators allocated once (the
  kernels add into them; the values they accumulate do not change the work): the constant-strain
  membrane (ddg.energies.membrane), the smoothed membrane (ddg.energies.smoothed_membrane) and the
  mid-edge bending (ddg.energies.midedge_bending), each for the energy only, energy + gradient and
  energy + gradient + Hessian;
- the whole `model.evaluate` (gathers, zeroed accumulators, the three kernels, the Evaluation);
- (this tree's stencils only) the band additions alone: the lower band entries of each bending
  stencil and each patch added 0.0 with nothing computed, what the band storage costs by itself.

A measurement is `calls` calls (as many as fit in --budget seconds, 5 to 500), their median per
call; each round runs in a fresh child process whose working directory is the source tree (this
repository, or --against DIR, another checkout with its kernels compiled: `python -m ddg warmup
plate-midedge`), the trees alternating round by round so a change of load falls on both; the
figure is the minimum over the rounds of the medians. Reported per triangle (every kernel), per
hinge (the bending: interior edges) and per patch (the smoothed membrane: one per node).

Writes OUT/plate_kernels.json and .md atomically (with --against: the other tree's figures and the
speed-up other / this). Not part of the test run; nothing asserts on it.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from benchmarks.common import load_average, machine_info, markdown_table, source_fingerprint, write_report

REPO = Path(__file__).resolve().parents[1]

ROWS = (8, 12, 18, 28)
KERNELS = ("membrane", "smoothed membrane", "mid-edge bending")
MODES = (("energy", False, False), ("energy + gradient", True, False), ("energy + gradient + Hessian", True, True))
#: issue 50 item 2's target per triangle or hinge, energy + gradient + Hessian
TARGET_US = 0.4

CHILD = r"""
import json, statistics, sys, time
import numpy as np
from numba import njit
import ddg
from ddg.models.midedge_plate import MidedgePlateModel
from ddg.energies.membrane import add_membrane_terms
from ddg.energies.smoothed_membrane import add_smoothed_membrane_terms
from ddg.energies.midedge_bending import add_midedge_terms

rows, budget = json.loads(sys.argv[1]), float(sys.argv[2])
modes = ((False, False), (True, False), (True, True))


def kernels(model, x, theta, grad, band):
    '''The three kernel calls of model.evaluate, (gradient, hessian) -> energy, with either tree's
    arguments: this one's (the triangles in the model's order by x, model._by_x; the bending's
    stencils) or those before issue 50 item 2 (--against an older tree).'''
    n, alpha = model.n_dof, model.membrane_alpha
    if hasattr(model, "_by_x"):
        t = model._by_x
        return (
            lambda g, h: add_membrane_terms(x, t["triangles"], t["membrane"], t["abar"], model._node_dofs, n,
                                            grad, band, g, h),
            lambda g, h: add_smoothed_membrane_terms(x, model._triangles, model._strain_T, model._abar,
                                                     *model._patches, model._plane_stress, 1.0 - alpha,
                                                     model._node_dofs, n, grad, band, g, h),
            lambda g, h: add_midedge_terms(x, theta, t["stencil"], t["hinge_slots"], t["face_edges"], t["bending"],
                                           model._node_dofs, model._edge_dofs, n, grad, band, g, h))
    return (
        lambda g, h: add_membrane_terms(x, model._triangles, model._membrane_share, model._abar, model._node_dofs,
                                        n, grad, band, g, h),
        lambda g, h: add_smoothed_membrane_terms(x, model._triangles, model._strain_T, model._abar,
                                                 *model._patches, model._plane_stress, 1.0 - alpha,
                                                 model._node_dofs, n, grad, band, g, h),
        lambda g, h: add_midedge_terms(x, theta, model._triangles, model._face_edges, model._roles,
                                       model._hinge_of_edge, model._hinges, model._bending, model._node_dofs,
                                       model._edge_dofs, n, grad, band, g, h))


def timed(call):
    call()
    start = time.perf_counter()
    call()
    once = time.perf_counter() - start
    calls = int(min(500, max(5, budget / max(once, 1e-9))))
    times = []
    for _ in range(calls):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


@njit
def scatter_alone(stencil, face_edges, node_pointer, patch_nodes, vertex_dof, edge_dof, n, band, which):
    '''The band additions alone (0.0 added at each lower entry of each element, nothing computed):
    which = 0 the bending stencils (the model's triangle order), 1 the smoothed membrane's patches.'''
    dofs = np.empty(64, dtype=np.int64)
    count = stencil.shape[0] if which == 0 else node_pointer.shape[0] - 1
    for e in range(count):
        m = 0
        if which == 0:
            for s in range(6):
                if stencil[e, s] >= 0:
                    for k in range(3):
                        dofs[m] = vertex_dof[stencil[e, s], k]
                        m += 1
            for i in range(3):
                dofs[m] = edge_dof[face_edges[e, i]]
                m += 1
        else:
            for j in range(node_pointer[e], node_pointer[e + 1]):
                for k in range(3):
                    dofs[m] = vertex_dof[patch_nodes[j], k]
                    m += 1
        for a in range(m):
            for b in range(a + 1):
                band[abs(dofs[a] - dofs[b]) * n + min(dofs[a], dofs[b])] += 0.0


out = []
for R in rows:
    strip = ddg.Strip.from_ratios(1 / 6, 0.5)
    model = MidedgePlateModel(strip, rows=R)
    L = strip.length
    rng = np.random.default_rng(R)
    q = model.apply_clamps(model.buckled_guess(0.5 * L), 0.5 * L, 0.0)
    q[model.free] += 1e-3 * L * rng.standard_normal(model.free.stop - model.free.start)
    q[model.edge_dofs] = np.where(np.isin(model.edge_dofs, model.constrained), 0.0,
                                  1e-2 * rng.standard_normal(len(model.edge_dofs)))
    model.commit(q)
    x = np.ascontiguousarray(q[model.node_dofs])
    theta = np.ascontiguousarray(q[model.edge_dofs])
    grad = np.zeros(model.n_dof)
    band = np.zeros((model.bandwidth + 1) * model.n_dof)
    calls = kernels(model, x, theta, grad, band)
    row = {"triangles": int(len(model._triangles)), "hinges": int(len(model.mesh.hinges)),
           "patches": int(len(model._patches[0]) - 1), "n_dof": int(model.n_dof), "bandwidth": int(model.bandwidth),
           "kernels": [[timed(lambda: call(g, h)) for g, h in modes] for call in calls],
           "evaluate": [timed(lambda: model.evaluate(q, gradient=g, hessian=h)) for g, h in modes]}
    if hasattr(model, "_by_x"):
        t, patches = model._by_x, model._patches
        row["scatter_alone"] = [timed(lambda: scatter_alone(t["stencil"], t["face_edges"], patches[4], patches[5],
                                                            model._node_dofs, model._edge_dofs, model.n_dof, band,
                                                            which)) for which in (0, 1)]
    out.append(row)
print(json.dumps(out))
"""


def one_round(tree: Path, rows, budget: float, timeout: float) -> list[dict]:
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps(list(rows)), str(budget)], cwd=tree,
                          capture_output=True, text=True, timeout=timeout)
    if done.returncode:
        raise SystemExit(f"{tree}: {done.stderr.strip().splitlines()[-3:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _merge(best, new):
    if best is None:
        return new
    for b, r in zip(best, new):
        b["kernels"] = [[min(u, v) for u, v in zip(x, y)] for x, y in zip(b["kernels"], r["kernels"])]
        b["evaluate"] = [min(u, v) for u, v in zip(b["evaluate"], r["evaluate"])]
        if "scatter_alone" in b:
            b["scatter_alone"] = [min(u, v) for u, v in zip(b["scatter_alone"], r["scatter_alone"])]
    return best


def _cell(this: float, other: float | None, per: int) -> str:
    """us per element (the call's us in brackets); with the other tree: its us per element and other / this."""
    text = f"{1e6 * this / per:.3f}"
    if other is not None:
        text += f" (was {1e6 * other / per:.3f}, x{other / this:.1f})"
    return text


def markdown(report: dict) -> str:
    best, other = report["seconds"]["this"], report["seconds"].get("other")
    lines = ["# The mid-edge plate's kernels, one by one", "",
             "W/L = 1/6, dL/L = 1/2 (buckled guess, perturbed 1e-3 L, edge angles 1e-2). Minimum over rounds of the "
             "per-round median of one call" + (", this tree against the other (`was`) and the speed-up other / this"
                                               if other else "") + f". Issue 50's target: <= {TARGET_US} us per "
             "triangle or hinge for energy + gradient + Hessian.", ""]
    for k, kernel in enumerate(KERNELS):
        unit = {"membrane": ("triangle", "triangles"), "smoothed membrane": ("patch", "patches"),
                "mid-edge bending": ("hinge", "hinges")}[kernel]
        header = ["rows", "triangles", f"elements ({unit[1]})"] + [f"{m[0]}: us / triangle" for m in MODES] + [
            f"E+G+H us / {unit[0]}", "E+G+H call us"] + (["band additions alone: us / triangle"] if k > 0 else [])
        rows = []
        for i, r in enumerate(best):
            o = other[i] if other else None
            cells = [str(report["rows"][i]), str(r["triangles"]), str(r[unit[1]])]
            for j in range(len(MODES)):
                cells.append(_cell(r["kernels"][k][j], o["kernels"][k][j] if o else None, r["triangles"]))
            cells.append(_cell(r["kernels"][k][2], o["kernels"][k][2] if o else None, r[unit[1]]))
            cells.append(f"{1e6 * r['kernels'][k][2]:.1f}" + (f" (was {1e6 * o['kernels'][k][2]:.1f})" if o else ""))
            if k > 0:
                alone = r.get("scatter_alone")
                cells.append(f"{1e6 * alone[2 - k] / r['triangles']:.3f}" if alone else "")
            rows.append(cells)
        lines += [f"## {kernel}", "", markdown_table(header, rows), ""]
    lines += ["band additions alone: the same lower band entries of each element (the bending's stencils, the "
              "patches) added 0.0, with nothing computed: what the band storage costs these kernels by itself.", ""]
    header = ["rows", "n_dof", "bandwidth"] + [f"evaluate, {m[0]}: us" for m in MODES] + [
        "E+G+H us / triangle", "three kernels E+G+H us / triangle", "E+G+H outside the kernels us"]
    rows = []
    for i, r in enumerate(best):
        o = other[i] if other else None
        cells = [str(report["rows"][i]), str(r["n_dof"]), str(r["bandwidth"])]
        for j in range(len(MODES)):
            cells.append(f"{1e6 * r['evaluate'][j]:.1f}" + (
                f" (was {1e6 * o['evaluate'][j]:.1f}, x{o['evaluate'][j] / r['evaluate'][j]:.1f})" if o else ""))
        cells.append(_cell(r["evaluate"][2], o["evaluate"][2] if o else None, r["triangles"]))
        three = sum(r["kernels"][k][2] for k in range(3))
        cells.append(_cell(three, sum(o["kernels"][k][2] for k in range(3)) if o else None, r["triangles"]))
        cells.append(f"{1e6 * (r['evaluate'][2] - three):.0f}"
                     + (f" (was {1e6 * (o['evaluate'][2] - sum(o['kernels'][k][2] for k in range(3))):.0f})"
                        if o else ""))
        rows.append(cells)
    lines += ["## model.evaluate", "", markdown_table(header, rows), "",
              "evaluate includes what the kernels do not: the gather of q into positions and angles, the zeroed "
              "gradient and band ((bandwidth + 1) n doubles, 98 MB at 28 rows: a fresh allocation each call, whose "
              "pages the kernels then touch for the first time) and the Evaluation.", "",
              f"Trees: {report['trees']}; {report['rounds']} rounds, {report['budget_s']} s per measurement; load "
              f"average {report['load_before']} before, {report['load_after']} after; "
              f"{report['machine'].get('cpu_model', '?')}, {report['machine'].get('thread_env')}.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", type=Path, default=None, help="another source tree, its kernels compiled")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--rows", type=int, nargs="+", default=list(ROWS))
    parser.add_argument("--budget", type=float, default=0.25, help="seconds per measurement (5 to 500 calls)")
    parser.add_argument("--timeout", type=float, default=1800.0)
    parser.add_argument("--out", default="benchmarks/results")
    args = parser.parse_args(argv)
    trees = {"this": REPO} | ({"other": args.against.resolve()} if args.against else {})
    best = {label: None for label in trees}
    load_before = load_average()
    for _ in range(args.rounds):
        for label, tree in trees.items():
            best[label] = _merge(best[label], one_round(tree, args.rows, args.budget, args.timeout))
    report = {"machine": machine_info(), "source": source_fingerprint(), "date": time.strftime("%Y-%m-%d %H:%M"),
              "load_before": load_before, "load_after": load_average(), "rounds": args.rounds,
              "budget_s": args.budget, "trees": {k: str(v) for k, v in trees.items()}, "rows": args.rows,
              "kernels": KERNELS, "modes": [m[0] for m in MODES], "seconds": best}
    text = markdown(report)
    print(text)
    print(write_report(args.out, "plate_kernels", report, text))
    return 0


if __name__ == "__main__":
    sys.exit(main())
