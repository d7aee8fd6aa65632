"""A plate run with ParaView frames, drawn off-screen with pyvista.

`frames=True` writes one VTU file per recorded step, DIR/frames/frame_NNNNN.vtu, and
DIR/frames/frames.pvd, which ParaView opens as a time series (its time is dW/L on the shear).
The points are the deformed shape; each triangle carries `turn_angle_deg` and
`bending_energy_density`. The frame's step number is the row of path.csv, which gives its phase.

Here the plate is coarse (about 1000 triangles at W/L = 1/12, dL/L = 1/2, sheared to dW/L = 0.55:
about 5 s), enough to pass U, US and S. Then ddg.output.render draws one state of each phase (the
middle of its stretch of the shear) with one camera and one colour scale, as `python -m ddg render
DIR` does. Rendering needs the 'render' extra (pyvista, vtk >= 9.4; off-screen through EGL, no
display needed); without it the script says so and stops after checking the frames.

    .venv/bin/python examples/plate_frames_render.py [--out DIR]   # about 7 s; needs meshio, pyvista optional
"""
import argparse
import importlib.util
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import ddg

if importlib.util.find_spec("meshio") is None:   # writes the VTU frames
    sys.exit("plate_frames_render.py needs meshio: pip install 'ddg-strips[io]' (or apt install python3-meshio)")

parser = argparse.ArgumentParser(description="A plate run with ParaView frames, rendered with pyvista.")
parser.add_argument("--out", default="out/examples/plate_frames_render", help="run folder (default: %(default)s)")
out = Path(parser.parse_args().out)

# The run: frames need an output folder.
strip = ddg.Strip.from_ratios(width_ratio=1 / 12, compression_ratio=0.5)
protocol = ddg.LoadingProtocol(compression_ratio=0.5, shear_ratio=0.55, compression_steps=20, shear_steps=60)
result = ddg.simulate(strip, protocol, model="plate", resolution=1000, out=out, frames=True)
summary = result.summary
print(f"plate, {summary['mesh']['triangles']} triangles: dW1/L = {summary['dW1_over_L']:.4f}, "
      f"dW2/L = {summary['dW2_over_L']:.4f}, {summary['wall_time_s']:.1f} s")
assert summary["status"] == "complete", summary["message"]

# One frame per row of path.csv, each listed in the .pvd collection with its time.
frames = sorted((out / "frames").glob("frame_*.vtu"))
assert len(frames) == len(result.rows) == summary["recorded_steps"], (len(frames), len(result.rows))
datasets = ET.parse(out / "frames" / "frames.pvd").getroot().iter("DataSet")
assert sorted(d.get("file") for d in datasets) == [f.name for f in frames]
phases = {row["phase"] for row in result.rows if row["stage"] == "shear"}
assert {"U", "US+", "S+"} <= phases, phases
print(f"{len(frames)} frames in {out / 'frames'}; open frames.pvd in ParaView")

# The pictures, if pyvista is installed.
if importlib.util.find_spec("pyvista") is None:
    print("pyvista is not installed: no pictures (pip install 'ddg-strips[render]')")
else:
    from ddg.output.render import default_steps, open_run, render_run

    run = open_run(out)
    steps = default_steps(run)                       # the middle of the U, US and S stretches
    pictures = render_run(out, out / "render", steps)
    for step, png in zip(steps, pictures):
        print(f"step {step} ({run.phase(step)}): {png}")
    assert [run.phase(s) for s in steps] == ["U", "US+", "S+"]
    assert all(p.stat().st_size > 10_000 and p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pictures)
print(f"ok: {out}")
