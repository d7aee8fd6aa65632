"""Our ribbons on the scene of Panda and Jawed's ribbon comparison ("Discrete Elastic Ribbons",
arXiv 2605.05529), beside the shell: why their Sano model has a pitchfork at W/L = 1/6 and ours not.

`python -m validation ribbon-reconciliation [--only NAME ...] [--out data/ribbon_reconciliation]`
runs each run of RUNS not yet in OUT/runs.csv (resumable) and writes OUT/reconciliation.md, which
also reads the shell's runs OUT/fem/W<w>_N<along>x<across>/summary.json (their generator:
FEM_COMMAND, two meshes per width; the difference between the two is the shell's error bar here).

Their code (StructuresComp/discrete-elastic-ribbon, read, not run) has our Sano-Wada energy term
for term (E = 1/2 [EI_n k_n^2 + EI_g k_g^2 + GJ tau^2 + EI_n tau^4 / (k_n^2 + 1/zeta^2)], zeta^2 =
(1 - nu) W^4 / (60 b^2)), with nu = 0.5, on a strip 0.1 m long and 1 mm thick (L/b = 100),
compressed by 0.025 m (dL/L = 1/4), clamped over 10 mm at each end (free span about 0.081 m),
W/L = W / 0.1 m. The scenes here:

- "PJ": their nominal scene as our Strip takes it: L/b = 100, dL/L = 1/4, nu = 0.499 (our Strip
  takes nu < 0.5; zeta and GJ then differ from nu = 0.5 by 0.07 %), W/L as theirs;
- "PJ-span": the same strip measured on its free span (0.0807 m at their 63 nodes):
  L/b = 80.7, dL/L = 0.31, W/L times 1.239;
- "ours": the benchmark scene (L/b = 1181 at dL/L = 1/2, nu = 0).

zeta / L = sqrt((1 - nu) / 60) (W/L)^2 (L/b) sets how far the Sano-Wada ribbon is from the rod
(zeta -> 0) towards Sadowsky's ribbon (zeta -> infinity): "zeta" runs sweep it on one strip with
RibbonModel (the rod's GJ plus the quartic term) at a given zeta / L.
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

from ddg.output.io import atomic_write_text

from .command_line import check_run_names, output_folder, resumable_runs

#: Their strip: free span over nominal length (0.0807 m of 0.1 m at 63 nodes), their compression 0.025 m.
SPAN_FRACTION = 0.0807 / 0.1
SCENES = {"PJ": dict(compression=0.25, slenderness=100.0, poisson=0.499, width_scale=1.0),
          "PJ-span": dict(compression=0.025 / 0.0807, slenderness=80.7, poisson=0.499, width_scale=1 / SPAN_FRACTION),
          "ours": dict(compression=0.5, slenderness=None, poisson=0.0, width_scale=1.0)}
WIDTHS = (1 / 20, 1 / 12, 1 / 6)
MODELS = ("rod", "ribbon", "ribbon-sano-wada", "ribbon-trapeze", "ribbon-cross-section", "ribbon-wunderlich")
FEM_MESHES = ((64, 8), (96, 12))
FEM_COMMAND = ("python -m fem_reference simulate --width-ratio W --compression-ratio 0.25 --slenderness 100 "
               "--poisson-ratio 0.499 --resolution N --across A --no-fields --no-centerline "
               "--out data/ribbon_reconciliation/fem/W<W>_N<N>x<A>")


@dataclass(frozen=True)
class Run:
    """One 1D run: a scene of SCENES, W/L as the scene names it, a model of ddg's registry (or
    "zeta": RibbonModel at zeta_over_L), its node count M."""

    scene: str
    width_ratio: float
    model: str
    nodes: int = 101
    zeta_over_L: float | None = None
    modes: int | None = None
    curvature_gradient: float = 0.0

    @property
    def name(self) -> str:
        parts = [self.scene, f"W{round(1 / self.width_ratio)}", self.model, f"M{self.nodes}"]
        if self.zeta_over_L is not None:
            parts.append(f"z{self.zeta_over_L:g}")
        if self.modes is not None:
            parts.append(f"n{self.modes}")
        if self.curvature_gradient:
            parts.append(f"l{self.curvature_gradient:g}")
        return "_".join(parts)


#: Fixed before the runs: every 1D model on their scene at both node counts; Sano-Wada and the rod on
#: the free-span scene and ours; zeta / L swept on their W/L = 1/6 strip and ours across the values
#: both scenes' Sano-Wada zeta spans (0.023 .. 4.2).
ZETAS = (0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0)
#: What limits the cross-section model on our scene (added after the runs above, before its own):
#: the node count (101 / 201 / 401), a third mode, and a gradient energy of the normal curvature
#: B_k / 2 int kappa_n'^2, B_k = EI2 (l W)^2 (CrossSectionRibbon's curvature_gradient l), which would
#: give an inflection squeezed against a clamp a width of order l W.
GRADIENT_LENGTHS = (0.05, 0.1, 0.2, 0.4)
CROSS_SECTION_WIDTHS = (1 / 12, 1 / 6)
CROSS_SECTION_RUNS = ([Run("ours", w, "ribbon-cross-section", n) for w in CROSS_SECTION_WIDTHS for n in (101, 201, 401)]
                      + [Run("ours", w, "ribbon-cross-section", n, modes=3)
                         for w in CROSS_SECTION_WIDTHS for n in (101, 201)]
                      + [Run("ours", w, "ribbon-cross-section", n, curvature_gradient=g)
                         for w in CROSS_SECTION_WIDTHS for g in GRADIENT_LENGTHS for n in (101, 201)])
RUNS = ([Run("PJ", w, m, n) for n in (101, 201) for w in WIDTHS for m in MODELS]
        + [Run("PJ-span", w, m, n) for n in (101, 201) for w in WIDTHS for m in ("rod", "ribbon-sano-wada")]
        + [Run("ours", w, m, 101) for w in WIDTHS for m in ("rod", "ribbon-sano-wada")]
        + [Run(s, 1 / 6, "zeta", 101, z) for s in ("PJ", "ours") for z in ZETAS]
        + CROSS_SECTION_RUNS)

COLUMNS = ["name", "scene", "width_ratio_nominal", "width_ratio", "compression_ratio", "slenderness", "poisson_ratio",
           "model", "nodes", "zeta_over_L", "modes", "curvature_gradient", "status", "dW1_over_L", "dW2_over_L",
           "newton_iterations", "wall_time_s"]


def strip_of(scene: str, width_ratio: float):
    """The Strip of a scene (module docstring) at the scene's own W/L."""
    import ddg

    s = SCENES[scene]
    return ddg.Strip.from_ratios(width_ratio * s["width_scale"], s["compression"], s["slenderness"],
                                 poisson_ratio=s["poisson"])


def zeta_over_length(strip) -> float:
    """The Sano-Wada zeta / L of a strip."""
    return math.sqrt((1.0 - strip.poisson_ratio) / 60.0) * strip.width**2 / strip.thickness / strip.length


def run_one(run: Run) -> dict:
    """dW1 and dW2 of one run: the default protocol of ddg.simulate (thresholds from stability)."""
    import ddg
    from ddg.api import simulate_model
    from ddg.models.registry import entry
    from ddg.models.ribbon import RibbonModel
    from ddg.models.wide_ribbons import CrossSectionRibbon

    strip = strip_of(run.scene, run.width_ratio)
    if run.model == "zeta":
        model = RibbonModel(strip, run.nodes, zeta=run.zeta_over_L * strip.length)
    elif run.modes is not None or run.curvature_gradient:
        model = CrossSectionRibbon(strip, run.nodes, modes=run.modes, curvature_gradient=run.curvature_gradient)
    else:
        model = entry(run.model).model_class(strip, run.nodes)
    zeta = run.zeta_over_L if run.zeta_over_L is not None else zeta_over_length(strip)
    t0 = time.perf_counter()
    summary = simulate_model(model, ddg.LoadingProtocol(strip.design_compression_ratio), centerline=False).summary
    return {"name": run.name, "scene": run.scene, "width_ratio_nominal": run.width_ratio,
            "width_ratio": strip.width / strip.length, "compression_ratio": strip.design_compression_ratio,
            "slenderness": strip.length / strip.thickness, "poisson_ratio": strip.poisson_ratio, "model": run.model,
            "nodes": run.nodes, "zeta_over_L": zeta, "modes": run.modes or "",
            "curvature_gradient": run.curvature_gradient, "status": summary["status"],
            "dW1_over_L": summary["dW1_over_L"], "dW2_over_L": summary["dW2_over_L"],
            "newton_iterations": summary["newton_iterations"], "wall_time_s": round(time.perf_counter() - t0, 2)}


def _value(row, key):
    v = row.get(key) if row else None
    return float(v) if v not in (None, "", "None") else None


def fem_rows(folder: Path) -> dict:
    """The shell's runs under folder: {(W/L, (along, across)): summary}."""
    out = {}
    for w in WIDTHS:
        for along, across in FEM_MESHES:
            path = folder / f"W{_width_label(w)}_N{along}x{across}" / "summary.json"
            if path.exists():
                out[(w, (along, across))] = json.loads(path.read_text())
    return out


def _width_label(w: float) -> str:
    return {1 / 20: "0.05", 1 / 12: "0.08333", 1 / 6: "0.16667"}[w]


def _fmt(v, digits=4):
    return "none" if v is None else f"{v:.{digits}f}"


def report(rows: list[dict], fem: dict) -> str:
    """reconciliation.md: the shell and every 1D model on their scene, Sano-Wada on the three scenes,
    dW1 against zeta / L."""
    by = {r["name"]: r for r in rows}
    lines = ["# Our ribbons on Panda and Jawed's scene, beside the shell", "",
             "Generated by `python -m validation ribbon-reconciliation` (validation/ribbon_reconciliation.py, whose "
             "docstring gives the scenes and the runs). dW1/L, dW2/L from the static path's stability (\"none\": the "
             "path has no such threshold up to dW_max); the shell's runs: `" + FEM_COMMAND + "`.", "",
             "## Their scene (PJ: L/b = 100, dL/L = 1/4, nu = 0.499)", ""]
    header = "| W/L | zeta/L (Sano-Wada) | shell 64x8 dW1 | shell 96x12 dW1 | shell 96x12 dW2 |"
    for m in MODELS:
        header += f" {m} dW1 M101 / M201 |"
    lines += [header, "|" + "---:|" * (5 + len(MODELS))]
    for w in WIDTHS:
        coarse, fine = fem.get((w, FEM_MESHES[0])), fem.get((w, FEM_MESHES[1]))
        sano = by.get(Run("PJ", w, "ribbon-sano-wada").name)
        cells = [f"1/{round(1 / w)}", _fmt(_value(sano, "zeta_over_L"), 3),
                 _fmt(coarse and coarse.get("dW1_over_L")), _fmt(fine and fine.get("dW1_over_L")),
                 _fmt(fine and fine.get("dW2_over_L"))]
        for m in MODELS:
            a, b = (by.get(Run("PJ", w, m, n).name) for n in (101, 201))
            cells.append(f"{_fmt(_value(a, 'dW1_over_L'))} / {_fmt(_value(b, 'dW1_over_L'))}")
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", "dW2 on the same scene (M = 101 / 201; the shell's dW2 is a recorded step of its path, not "
              "bisected: one step is dW_max / 120 = 0.0051 L):", "",
              "| W/L | shell 64x8 dW2 | shell 96x12 dW2 |" + "".join(f" {m} dW2 |" for m in MODELS),
              "|" + "---:|" * (3 + len(MODELS))]
    for w in WIDTHS:
        coarse, fine = fem.get((w, FEM_MESHES[0])), fem.get((w, FEM_MESHES[1]))
        cells = [f"1/{round(1 / w)}", _fmt(coarse and coarse.get("dW2_over_L")), _fmt(fine and fine.get("dW2_over_L"))]
        for m in MODELS:
            a, b = (by.get(Run("PJ", w, m, n).name) for n in (101, 201))
            cells.append(f"{_fmt(_value(a, 'dW2_over_L'))} / {_fmt(_value(b, 'dW2_over_L'))}")
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", "## Sano-Wada and the rod on the three scenes (M = 101 / 201)", "",
              "| scene | W/L (nominal) | W/L | L/b | dL/L | nu | zeta/L | rod dW1 | Sano-Wada dW1 | Sano-Wada dW2 |",
              "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for scene in SCENES:
        for w in WIDTHS:
            runs = {(m, n): by.get(Run(scene, w, m, n).name) for m in ("rod", "ribbon-sano-wada") for n in (101, 201)}
            s = runs[("ribbon-sano-wada", 101)]
            if s is None:
                continue

            def pair(model, key):
                return " / ".join(_fmt(_value(runs[(model, n)], key)) for n in (101, 201) if runs[(model, n)])

            lines.append(f"| {scene} | 1/{round(1 / w)} | {float(s['width_ratio']):.4f} | "
                         f"{float(s['slenderness']):.1f} | "
                         f"{float(s['compression_ratio']):.3f} | {float(s['poisson_ratio']):g} | "
                         f"{float(s['zeta_over_L']):.3f} | {pair('rod', 'dW1_over_L')} | "
                         f"{pair('ribbon-sano-wada', 'dW1_over_L')} | {pair('ribbon-sano-wada', 'dW2_over_L')} |")
    lines += ["", "## dW1 against zeta / L (RibbonModel: the rod's GJ plus the quartic term, W/L = 1/6, M = 101)", "",
              "| zeta/L | PJ dW1 | PJ dW2 | ours dW1 | ours dW2 |", "|---:|---:|---:|---:|---:|"]
    for z in ZETAS:
        a, b = (by.get(Run(s, 1 / 6, "zeta", 101, z).name) for s in ("PJ", "ours"))
        lines.append(f"| {z:g} | {_fmt(_value(a, 'dW1_over_L'))} | {_fmt(_value(a, 'dW2_over_L'))} | "
                     f"{_fmt(_value(b, 'dW1_over_L'))} | {_fmt(_value(b, 'dW2_over_L'))} |")
    lines += cross_section_section(by)
    return "\n".join(lines) + "\n"


def cross_section_section(by: dict) -> list[str]:
    """The cross-section model on our scene against the shell's gold (data/fem_gold): node count,
    a third mode, the curvature gradient."""
    from .estimates import load_study

    lines = ["", "## The cross-section model on our scene (dL/L = 1/2, L/b = 1181, nu = 0)", "",
             "Gold: the shell's mesh study (data/fem_gold, value +- error bar). Status: c complete, s stopped.", "",
             "| W/L | variant | M | status | dW1 | dW1 - gold | dW2 | Newton its | wall s |",
             "|---:|---|---:|---|---:|---:|---:|---:|---:|"]
    for w in CROSS_SECTION_WIDTHS:
        study = load_study("fem", 0.5, w)
        gold1 = study.dW1 if study else None
        gold2 = study.dW2 if study else None
        lines.append(f"| 1/{round(1 / w)} | shell gold | | | {_fmt(gold1 and gold1.value)} +- "
                     f"{_fmt(gold1 and gold1.error_bar)} | | {_fmt(gold2 and gold2.value)} +- "
                     f"{_fmt(gold2 and gold2.error_bar)} | | |")
        for r in CROSS_SECTION_RUNS:
            if r.width_ratio != w or r.name not in by:
                continue
            row = by[r.name]
            variant = (f"{r.modes} modes" if r.modes else f"l = {r.curvature_gradient:g} W" if r.curvature_gradient
                       else "default (2 modes)")
            dw1 = _value(row, "dW1_over_L")
            error = None if dw1 is None or gold1 is None else dw1 - gold1.value
            lines.append(f"| 1/{round(1 / w)} | {variant} | {r.nodes} | {row['status'][0]} | {_fmt(dw1)} | "
                         f"{'' if error is None else f'{error:+.4f}'} | {_fmt(_value(row, 'dW2_over_L'))} | "
                         f"{row['newton_iterations']} | {float(row['wall_time_s']):.1f} |")
    return lines


def add_arguments(parser) -> None:
    """The options of `python -m validation ribbon-reconciliation`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--only", nargs="+", default=None, help="run names (e.g. PJ_W6_ribbon-sano-wada_M101)")
    parser.add_argument("--out", default="data/ribbon_reconciliation")


def run(args) -> int:
    """The runs not yet in OUT/runs.csv, the CSV and reconciliation.md rewritten after each."""
    check_run_names(RUNS, args.only)
    out = output_folder(args.out)
    if out is None:
        return 2
    rows = resumable_runs(RUNS, args.only, out, COLUMNS, run_one)
    atomic_write_text(out / "reconciliation.md", report(rows, fem_rows(out / "fem")))
    return 0


def main(argv=None) -> int:
    from .command_line import standalone

    return standalone("ribbon-reconciliation", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
