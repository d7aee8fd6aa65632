"""Independent mesh series of a gold scene beside its study: does the study's error bar hold?

Issue 28: at W/L = 1/6, dL/L = 1/2 the gold study (64 x 8, 96 x 12, 144 x 18: elements h_y/h_x =
4/3) gave dW1/L 0.2646 from differences of opposite sign, while an older series of near-isotropic
meshes (60 x 10, 90 x 16, 120 x 20, data/fem_convergence, made before the gold's bisection
tolerances and continuation settings) extrapolated to 0.2685. A series refines one mesh family
by a fixed ratio; each is estimated with the gold's rule (fem_reference.convergence.estimate,
refinement ratios from sqrt(along x across)), and the series are compared with each other and with
the two candidate values. `write_series(scene_folder)` writes OUT/<scene>/series.md and
series.json from the finished runs that exist; `python -m fem_reference gold --studies-only`
calls it for the scenes of SERIES.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ddg.output.io import atomic_write_text, read_json_object

#: Per scene: (name, description, run folders relative to the data folder, coarsest first).
SERIES = {
    "dL0.5_W0.1667": (
        ("gold", "the gold sequence, elements h_y/h_x = 4/3 (64 x 8 ... 216 x 28)",
         ("fem_gold/dL0.5_W0.1667/N64x8", "fem_gold/dL0.5_W0.1667/N96x12", "fem_gold/dL0.5_W0.1667/N144x18",
          "fem_gold/dL0.5_W0.1667/N216x28")),
        ("isotropic", "h_y = h_x, refined by 1.5 (96 x 16, 144 x 24, 216 x 36), the gold's tolerances",
         ("fem_gold/dL0.5_W0.1667/N96x16", "fem_gold/dL0.5_W0.1667/N144x24", "fem_gold/dL0.5_W0.1667/N216x36")),
        ("older isotropic", "near-isotropic runs of data/fem_convergence (60 x 10, 90 x 16, 120 x 20; earlier "
         "code, dW1 bisection bracket not recorded) and 180 x 30 with the gold's tolerances",
         ("fem_convergence/dL0.5_W0.1667/N60", "fem_convergence/dL0.5_W0.1667/N90",
          "fem_convergence/dL0.5_W0.1667/N120", "fem_gold/dL0.5_W0.1667/N180x30")),
    ),
}
#: The values the series are to decide between (issue 28): the gold's dW1/L before the fourth mesh
#: and the older isotropic series' extrapolation.
CANDIDATES = {"dL0.5_W0.1667": {"dW1": (0.2646, 0.2685)}}


def _run(folder: Path) -> dict | None:
    summary = read_json_object(folder / "summary.json")
    # runs before the status key (data/fem_convergence) count when they finished their path
    status = summary.get("status", "complete" if summary.get("converged") else None) if summary else None
    if status not in ("complete", "stopped"):
        return None
    mesh = summary.get("mesh") or {}
    along, across = mesh.get("elements_along_L"), mesh.get("elements_across_W")
    if along is None or across is None:
        return None
    return {"folder": folder, "along": int(along), "across": int(across), "status": status,
            "dW1_over_L": summary.get("dW1_over_L"), "dW2_over_L": summary.get("dW2_over_L"),
            "wall_time_s": summary.get("wall_time_s"), "newton_iterations": summary.get("newton_iterations"),
            "tolerances": summary.get("threshold_tolerances_over_L")}


def series_estimates(runs: list[dict]) -> dict:
    """estimate() of dW1 and dW2 over one series' finished runs (coarsest first), with its bisection
    brackets (none recorded: none added)."""
    from .convergence import estimate

    def bracket(key):
        return max(float((r["tolerances"] or {}).get(key) or 0.0) for r in runs) if runs else 0.0

    resolutions = [r["along"] for r in runs]
    sizes = [math.sqrt(r["along"] * r["across"]) for r in runs]
    return {key: estimate([r[f"{key}_over_L"] for r in runs], resolutions, share * bracket(key), sizes)
            for key, share in (("dW1", 0.5), ("dW2", 1.0))}


def write_series(scene_folder: Path) -> dict | None:
    """series.json and series.md of one scene of SERIES from the runs that exist; None otherwise."""
    scene_folder = Path(scene_folder)
    name = scene_folder.name
    if name not in SERIES:
        return None
    data_root = scene_folder.parent.parent
    study = read_json_object(scene_folder / "richardson.json") or {}
    out = {"scene": name, "series": [], "candidates": CANDIDATES.get(name, {})}
    for label, description, folders in SERIES[name]:
        runs = [r for r in (_run(data_root / f) for f in folders) if r is not None]
        estimates = series_estimates(runs)
        out["series"].append({"name": label, "description": description,
                              "runs": [{**{k: v for k, v in r.items() if k != "folder"},
                                        "folder": str(Path(r["folder"]).relative_to(data_root))} for r in runs],
                              **estimates})
    out["study"] = {key: study.get(key) for key in ("dW1", "dW2")}
    out["checks"] = _checks(out)
    atomic_write_text(scene_folder / "series.json", json.dumps(out, indent=2) + "\n")
    atomic_write_text(scene_folder / "series.md", _markdown(out))
    return out


def _checks(out: dict) -> list[dict]:
    """Each pair of series with estimates (the first, "gold", is the study's own sequence): do they
    agree within the sum of their error bars; each candidate value: inside which error bar."""
    checks = []
    named = [(s["name"], {k: s[k] for k in ("dW1", "dW2")}) for s in out["series"]]
    for key in ("dW1", "dW2"):
        have = [(n, e[key]) for n, e in named if e.get(key) and e[key].get("error_bar") is not None]
        for i, (na, ea) in enumerate(have):
            for nb, eb in have[i + 1:]:
                diff, bars = abs(ea["value"] - eb["value"]), ea["error_bar"] + eb["error_bar"]
                checks.append({"quantity": key, "a": na, "b": nb, "difference": diff, "combined_error_bar": bars,
                               "agree": diff <= bars})
        for candidate in out["candidates"].get(key, ()):
            inside = [n for n, e in have if abs(candidate - e["value"]) <= e["error_bar"]]
            checks.append({"quantity": key, "candidate": candidate, "inside": inside,
                           "outside": [n for n, _ in have if n not in inside]})
    return checks


def _fmt(v, spec="{:.4f}") -> str:
    return "-" if v is None else spec.format(v)


def _markdown(out: dict) -> str:
    lines = [f"# Independent mesh series at {out['scene']} (fem_reference/series.py)", "",
             "Each series estimated with the gold's error-bar rule (data/fem_gold/README.md); the study row is "
             "richardson.json. Written by `python -m fem_reference gold --studies-only`.", "",
             "| series | meshes | dW1/L per mesh | dW1/L | +- | basis | dW2/L per mesh | dW2/L | +- | basis |",
             "|---|---|---|---:|---:|---|---|---:|---:|---|"]
    for s in out["series"]:
        meshes = ", ".join(f"{r['along']}x{r['across']}" for r in s["runs"]) or "none yet"
        cells = [s["name"], meshes]
        for key in ("dW1", "dW2"):
            e = s[key] or {}
            cells += [" / ".join(_fmt(r[f"{key}_over_L"]) for r in s["runs"]), _fmt(e.get("value")),
                      _fmt(e.get("error_bar")), e.get("basis", "-")]
        lines.append("| " + " | ".join(cells) + " |")
    for key in ("dW1", "dW2"):
        e = out["study"].get(key) or {}
        lines.append(f"\nStudy {key}/L: {_fmt(e.get('value'))} +- {_fmt(e.get('error_bar'))} ({e.get('basis', '-')}).")
    lines += ["", "| quantity | compared | difference | combined error bar | agree |", "|---|---|---:|---:|---|"]
    for c in out["checks"]:
        if "candidate" in c:
            continue
        lines.append(f"| {c['quantity']} | {c['a']} / {c['b']} | {c['difference']:.4f} | "
                     f"{c['combined_error_bar']:.4f} | {'yes' if c['agree'] else 'no'} |")
    for c in out["checks"]:
        if "candidate" in c:
            lines.append(f"\n{c['quantity']}/L = {c['candidate']:.4f} lies within the error bar of: "
                         f"{', '.join(c['inside']) or 'none'}; outside: {', '.join(c['outside']) or 'none'}.")
    for s in out["series"]:
        lines.append(f"\n- {s['name']}: {s['description']}; wall time "
                     f"{sum(r['wall_time_s'] or 0 for r in s['runs']):.0f} s over {len(s['runs'])} run(s).")
    return "\n".join(lines) + "\n"
