"""A rod run written to a folder and read back as a pandas DataFrame.

The default scene: a strip with W/L = 1/20, compressed by dL/L = 1/2 so that it buckles into a U,
then sheared sideways up to dW_max. The rod (M = 100 nodes) writes its run folder as the output
contract says (docs/reference/output_contract.rst): path.csv, one row per recorded equilibrium, and summary.json.
Here path.csv is read with plain pandas, as any other tool would read it, and the run's story is
checked on the table: U up to dW1, then the asymmetric US, then S from dW2.

    .venv/bin/python examples/rod_dataframe.py [--out DIR]      # about 2 s; needs pandas
"""
import argparse
import json
import sys
from pathlib import Path

try:
    import pandas as pd
except ImportError:
    sys.exit("rod_dataframe.py needs pandas: pip install 'ddg-strips[dataframe]' (or apt install python3-pandas)")

import ddg

parser = argparse.ArgumentParser(description="A rod run read back as a pandas DataFrame.")
parser.add_argument("--out", default="out/examples/rod_dataframe", help="run folder (default: %(default)s)")
out = Path(parser.parse_args().out)

# The scene and the loading: Strip.from_ratios builds the paper's strip (clamps 75 mm apart after
# compression, b = 0.127 mm); the protocol compresses, then shears to dW_max/L (Eq. B.1).
strip = ddg.Strip.from_ratios(width_ratio=1 / 20, compression_ratio=1 / 2)
protocol = ddg.LoadingProtocol(compression_ratio=1 / 2)
ddg.simulate(strip, protocol, model="rod", resolution=100, out=out)

# Everything the run wrote is in the folder (the returned result holds the same rows and summary).
summary = json.loads((out / "summary.json").read_text())
df = pd.read_csv(out / "path.csv")
print(f"{len(df)} rows, columns: {', '.join(df.columns)}")
print(f"dW1/L = {summary['dW1_over_L']:.4f}, dW2/L = {summary['dW2_over_L']:.4f} "
      f"({summary['status']}, {summary['wall_time_s']:.1f} s)")

# The path is complete: every recorded step converged and the shear reached dW_max.
shear = df[df.stage == "shear"]
assert summary["status"] == "complete" and summary["path_complete"], summary["message"]
assert len(df) == summary["recorded_steps"]
assert abs(shear.dW_over_L.max() - summary["dW_max_over_L"]) < 1e-9
assert shear.stable.all()   # the static path follows the stable branch (it switches at the pitchfork)

# Both thresholds were found, and the phases of path.csv bracket them: the last U state lies
# below dW1, the first US above it; the last US below dW2, the first S above it.
dW1, dW2 = summary["dW1_over_L"], summary["dW2_over_L"]
assert dW1 is not None and dW2 is not None
u, us, s = (shear[shear.phase.isin(names)] for names in (["U"], ["US+", "US-"], ["S+", "S-"]))
assert u.dW_over_L.max() < dW1 < us.dW_over_L.min()
assert us.dW_over_L.max() < dW2 <= s.dW_over_L.min()

# The sign structure of H_mid/L (observed, and what the symmetries say): the U buckles up
# (H_mid > 0) and sinks monotonically as the shear grows; on US it keeps its sign and keeps
# sinking, to zero at S, which is point-symmetric about the midpoint (H_mid = 0 to 1e-4 L).
print(shear.groupby("phase", sort=False).agg(rows=("H_mid_over_L", "size"), dW_from=("dW_over_L", "min"),
                                              dW_to=("dW_over_L", "max"), H_mid_max=("H_mid_over_L", "max"),
                                              H_mid_min=("H_mid_over_L", "min")).to_string())
assert (u.H_mid_over_L > 0).all() and (u.H_mid_over_L.diff().dropna() < 0).all()
assert (us.H_mid_over_L > 0).all() and us.H_mid_over_L.max() < u.H_mid_over_L.min()
assert (us.H_mid_over_L.diff().dropna() < 0).all()
assert (s.H_mid_over_L.abs() < 1e-4).all()

# The same table without pandas-specific code: ddg.read_run(out).to_dataframe() (or .arrays()).
assert ddg.read_run(out).to_dataframe().shape == df.shape
print(f"ok: {out}")
