"""The rod's thresholds against the FEM gold study of the same scene, in units of its error bar.

data/fem_gold holds, per scene, a mesh study of the finite-element shell (fem_reference: a
nonlinear Naghdi shell in FEniCSx, three or four meshes refined by 1.5): the converged value of
each threshold, extrapolated from the sequence, with an error bar (Richardson with the observed
order and Roache's grid convergence index; data/fem_gold/README.md). validation.estimates reads
it. Here the rod runs the default scene (W/L = 1/20, dL/L = 1/2) at M = 100 and 200 nodes, and
each threshold's difference from the shell is printed in error bars.

What it shows: the rod's dW1/L (the pitchfork) is the shell's to within the shell's own error bar,
while its dW2/L (where the stable path reaches S) lies about 0.048 L, some 50 error bars, beyond
the shell's, the same at both M: a model error of the rod, which resolves no width (the error map
records it: `python -m ddg advise` predicts the rod about 0.05 L off on dW2 at this scene), not a
discretisation error.

    .venv/bin/python examples/compare_with_gold.py [--out DIR]   # about 3 s
"""
import argparse
import sys
from pathlib import Path

import ddg

# validation/ (the report package, which reads the gold data) is not installed with ddg: it stays
# at the top of the repository, the folder above this one.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from validation.estimates import load_study  # noqa: E402

parser = argparse.ArgumentParser(description="The rod's dW1/L and dW2/L against the FEM gold study.")
parser.add_argument("--out", default="out/examples/compare_with_gold",
                    help="folder for the rod runs, one per M (default: %(default)s)")
out = Path(parser.parse_args().out)

# The study: "fem" at dL/L = 0.5, W/L = 0.05 (None where a scene has none).
study = load_study("fem", 0.5, 0.05)
assert study is not None and study.dW1 is not None and study.dW2 is not None
print(study.describe())
for key in ("dW1", "dW2"):
    estimate = study.threshold(key)
    print(f"  {key}/L = {estimate.value:.4f} +- {estimate.error_bar:.4f} ({estimate.basis})")

# The rod on the same scene (the study's strip: the paper's, L/b = 1181).
strip = ddg.Strip.from_ratios(width_ratio=0.05, compression_ratio=0.5)
difference, in_bars = {}, {}    # (M, "dW1" or "dW2") -> rod - FEM, in L and in the FEM's error bars
print(f"{'M':>4s} {'quantity':>8s} {'rod':>7s} {'FEM':>7s} {'rod - FEM':>10s} {'in bars':>8s}")
for M in (100, 200):
    summary = ddg.simulate(strip, ddg.LoadingProtocol(compression_ratio=0.5), model="rod", resolution=M,
                           out=out / f"rod_M{M}").summary
    assert summary["status"] == "complete", summary["message"]
    for key in ("dW1", "dW2"):
        rod, gold = summary[f"{key}_over_L"], study.threshold(key)
        difference[M, key] = rod - gold.value
        in_bars[M, key] = difference[M, key] / gold.error_bar
        print(f"{M:4d} {key + '/L':>8s} {rod:7.4f} {gold.value:7.4f} {difference[M, key]:+10.4f} "
              f"{in_bars[M, key]:+8.1f}")

# The relations, true at both resolutions (measured: dW1 +0.4 and +0.5 bars; dW2 +0.048 L, +52
# bars, at both).
for M in (100, 200):
    assert abs(in_bars[M, "dW1"]) < 1.0, in_bars                       # dW1: within one error bar
    assert difference[M, "dW2"] > 0.04 and in_bars[M, "dW2"] > 20, in_bars  # dW2: 0.04 L, 20 bars beyond
# The rod's own mesh error is small beside that: M = 100 and 200 differ by less than 0.001 L.
assert abs(difference[200, "dW2"] - difference[100, "dW2"]) < 1e-3
assert abs(difference[200, "dW1"] - difference[100, "dW1"]) < 1e-3
print(f"ok: {out}")
