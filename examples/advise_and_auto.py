"""Which model is enough for a scene, then the run of that choice.

ddg.advise reads the error map (data/error_map/error_map.csv: per model, resolution and scene,
the error of dW1/L, dW2/L and H_mid/L against the converged FEM shell, plus that reference's error
bar, and the wall time) and predicts, without running anything, each candidate's error on the
scene; its choice is the cheapest candidate predicted within the tolerance (`python -m ddg advise`).
`ddg.simulate(..., model="auto", tolerance=...)` makes the same choice and runs it; its summary
keeps the choice and the reasons under `auto` (summary.json too).

On the default scene (W/L = 1/20, dL/L = 1/2) at a tolerance of 0.02 L the choice is the ribbon
with a cross-section field at M = 201 nodes: the rod is cheaper but predicted about 0.05 L off on
dW2/L.

    .venv/bin/python examples/advise_and_auto.py [--out DIR]   # about 11 s
"""
import argparse
import json
import warnings
from pathlib import Path

import ddg
from ddg.advise import choose, format_choice

parser = argparse.ArgumentParser(description="ddg.advise on the default scene, then ddg.simulate(model='auto').")
parser.add_argument("--out", default="out/examples/advise_and_auto", help="run folder (default: %(default)s)")
out = Path(parser.parse_args().out)

WIDTH, COMPRESSION, TOLERANCE = 1 / 20, 1 / 2, 0.02

# The advice: instant, from the committed map (another map: choose(..., path=CSV)).
choice = choose(WIDTH, COMPRESSION, tolerance=TOLERANCE)
print(format_choice(choice))
print()

# The run of the choice. The model may warn on the way (the cross-section ribbon says where its
# strains start to vary over less than a width); the warnings are kept in summary["warnings"].
strip = ddg.Strip.from_ratios(width_ratio=WIDTH, compression_ratio=COMPRESSION)
with warnings.catch_warnings():
    warnings.simplefilter("ignore", ddg.ValidityWarning)
    result = ddg.simulate(strip, ddg.LoadingProtocol(compression_ratio=COMPRESSION), model="auto",
                          tolerance=TOLERANCE, out=out)
summary, auto = result.summary, result.summary["auto"]
print(f"ran {summary['model']} at resolution {summary['scene']['resolution']} in {summary['wall_time_s']:.1f} s: "
      f"dW1/L = {summary['dW1_over_L']:.4f}, dW2/L = {summary['dW2_over_L']:.4f} ({summary['status']})")
print(f"auto: {auto['chosen_model']} {auto['resolution_label']}, {auto['verdict']}")
for text in summary["warnings"]:
    print(f"  warning: {text[:110]}...")

# The run is the advised one, and says so: the same model and resolution, the same verdict.
assert auto["chosen_model"] == choice.model == summary["model"]
assert auto["resolution"] == choice.resolution == summary["scene"]["resolution"]
assert auto["within_tolerance"] == choice.within
assert auto["predicted_errors"] == choice.predicted_errors
# ...and summary.json on disk carries the same block.
assert json.loads((out / "summary.json").read_text())["auto"]["chosen_model"] == choice.model
assert summary["status"] == "complete", summary["message"]
print(f"ok: {out}")
