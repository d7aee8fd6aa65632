"""The effect of the Wunderlich ribbon's regularisation (ddg.energies.wunderlich) on its thresholds,
`python -m validation ribbon-regularisation --out data/ribbon_regularisation` (old spelling
`python -m validation.ribbon_regularisation`).

Eq. (A.2) is singular at inflection points (eta = tau / k2 diverges where k2 = 0). The model
regularises the ruling slope as Eq. (A.5) regularises Sadowsky's quartic term, eta = tau k2 /
(k2^2 + 1/zeta^2), with zeta = zeta_SW = sqrt((1 - nu) / 60) W^2 / b (Sano and Wada) by default.
This study runs the Wunderlich ribbon (M = 101, the static continuation with thresholds, no
branches) at zeta / zeta_SW in FACTORS on the scenes SCENES, and the Sano-Wada and plain Sadowsky
ribbons (ribbon-sano-wada, ribbon with zeta = 1e4 L) and the rod beside them, and writes

    OUT/regularisation.csv  one row per run: scene, model, zeta/zeta_SW, zeta/L, status, dW1/L,
                            dW2/L, the last dW/L reached, the largest |W eta'| on the path, message
    OUT/README.md           the same as a table, with the generator command

Resumable row by row: a row whose key (scene, model, factor) is in the CSV is not rerun. Each run
has TIMEOUT_S of wall time; one that needs more is reported with status "timeout" and what it reached.
"""
from __future__ import annotations

import csv
import math
import sys
from pathlib import Path

SCENES = ((0.5, 1 / 20), (0.5, 1 / 6), (0.25, 1 / 20), (0.25, 1 / 6))
FACTORS = (1 / 16, 1 / 4, 1.0, 4.0)
NODES = 101
#: Wall-time limit per run (s): past it the run is stopped and its converged part reported
#: (status "timeout"); Wunderlich runs that creep along the ruling factor's barrier can take hours.
TIMEOUT_S = 300
COLUMNS = ("compression_ratio", "width_ratio", "model", "zeta_over_zeta_sw", "zeta_over_L", "status",
           "dW1_over_L", "dW2_over_L", "last_dW_over_L", "max_ruling_rate", "message")


def cases():
    for dL, W in SCENES:
        yield dL, W, "rod", None
        yield dL, W, "ribbon", None
        yield dL, W, "ribbon-sano-wada", 1.0
        for factor in FACTORS:
            yield dL, W, "ribbon-wunderlich", factor


def key(dL, W, model, factor) -> tuple:
    return (f"{dL:.4g}", f"{W:.4g}", model, "" if factor is None else f"{factor:.4g}")


class _TimeUp(KeyboardInterrupt):
    """Raised by the alarm: ddg.simulate treats it as an interruption and keeps every converged step."""


def _time_up(signum, frame):
    raise _TimeUp()


def run_case(dL: float, W: float, model: str, factor: float | None, timeout: int = TIMEOUT_S) -> dict:
    import signal

    import ddg
    from ddg.models.wide_ribbons import sano_wada_zeta

    strip = ddg.Strip.from_ratios(W, dL)
    zeta = None if model != "ribbon-wunderlich" else factor * sano_wada_zeta(strip)
    previous = signal.signal(signal.SIGALRM, _time_up)
    signal.alarm(timeout)
    try:
        result = ddg.simulate(strip, ddg.LoadingProtocol(dL), model=model, resolution=NODES, branches=False,
                              zeta=zeta)
        timed_out = False
    except _TimeUp as stop:
        result, timed_out = getattr(stop, "result", None), True
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    if result is None:
        raise RuntimeError(f"{model} at dL/L = {dL:g}, W/L = {W:.4g}: no result after the time limit")
    s = result.summary
    if timed_out:
        s = {**s, "status": "timeout", "message": f"stopped after {timeout} s: {s.get('message', '')}"}
    rates = []
    if model == "ribbon-wunderlich":
        rates = [result.model.resolution_indicators(result.final_state.q)["max_ruling_rate"]]
    shear = [row["dW_over_L"] for row in result.rows if row["stage"] == "shear"]
    used = s.get("zeta")
    return {"compression_ratio": f"{dL:.4g}", "width_ratio": f"{W:.4g}", "model": model,
            "zeta_over_zeta_sw": "" if factor is None else f"{factor:.4g}",
            "zeta_over_L": "" if used is None else f"{used / strip.length:.4g}", "status": s["status"],
            "dW1_over_L": _number(s.get("dW1_over_L")), "dW2_over_L": _number(s.get("dW2_over_L")),
            "last_dW_over_L": _number(max(shear) if shear else None),
            "max_ruling_rate": _number(max(rates) if rates else None), "message": s.get("message", "")}


def _number(value) -> str:
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.4f}"


def read_rows(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def write_rows(path: Path, rows: list[dict]) -> None:
    from ddg.output.io import atomic_write_text

    lines = [",".join(COLUMNS)]
    for row in rows:
        lines.append(",".join(_csv_cell(row.get(c, "")) for c in COLUMNS))
    atomic_write_text(path, "\n".join(lines) + "\n")


def _csv_cell(value) -> str:
    text = str(value)
    return '"' + text.replace('"', '""') + '"' if any(ch in text for ch in ',"\n') else text


def write_readme(out: Path, rows: list[dict]) -> None:
    from ddg.output.io import atomic_write_text

    head = ["# The Wunderlich ribbon's regularisation (validation/ribbon_regularisation.py)", "",
            "Regenerate (resumable row by row, a few minutes on one core):", "",
            "    .venv/bin/python -m validation.ribbon_regularisation --out data/ribbon_regularisation", "",
            "M = 101, L/b = 1181, static continuation with thresholds. zeta_SW = sqrt((1 - nu) / 60) W^2 / b;",
            "the ribbon's zeta is 1e4 L (Sadowsky). max |W eta'| is on the last state (the pole is at 2).", "",
            "| dL/L | W/L | model | zeta/zeta_SW | zeta/L | status | dW1/L | dW2/L | last dW/L | max W eta' |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    body = [f"| {r['compression_ratio']} | {r['width_ratio']} | {r['model']} | {r['zeta_over_zeta_sw'] or '-'} | "
            f"{r['zeta_over_L'] or '-'} | {r['status']} | {r['dW1_over_L'] or '-'} | {r['dW2_over_L'] or '-'} | "
            f"{r['last_dW_over_L'] or '-'} | {r['max_ruling_rate'] or '-'} |" for r in rows]
    atomic_write_text(out / "README.md", "\n".join(head + body) + "\n")


def add_arguments(parser) -> None:
    """The options of `python -m validation ribbon-regularisation`."""
    parser.description = __doc__.split("\n")[0]
    parser.add_argument("--out", default="data/ribbon_regularisation")


def run(args) -> int:
    """Every case not yet in OUT's CSV run, the CSV rewritten after each, then the README."""
    from ddg.geometry.strip import InputError
    from ddg.output.io import check_output_directory

    try:
        check_output_directory(args.out, "--out")
    except InputError as error:
        sys.stderr.write(f"error: {error}\n")
        return 2
    out = Path(args.out)
    path = out / "regularisation.csv"
    rows = read_rows(path)
    done = {(r["compression_ratio"], r["width_ratio"], r["model"], r["zeta_over_zeta_sw"]) for r in rows}
    for case in cases():
        if key(*case) in done:
            continue
        rows.append(run_case(*case))
        write_rows(path, rows)
        print(",".join(str(rows[-1][c]) for c in COLUMNS[:9]), flush=True)
    write_readme(out, rows)
    return 0


def main(argv=None) -> int:
    """`python -m validation.ribbon_regularisation [options]`: the same as `python -m validation
    ribbon-regularisation [options]`."""
    from .command_line import standalone

    return standalone("ribbon-regularisation", add_arguments, run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
