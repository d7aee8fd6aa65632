"""`python -m ddg render DIR`: draw a run's recorded frames with pyvista (ddg.output.render):
a PNG per chosen step in OUT (default DIR/render), and interactive HTML scenes with --html.

Every input is checked before any drawing: DIR must be a run folder with frames (simulate
--frames), the steps recorded frames, OUT writable, pyvista installed (the 'render' extra) and,
for --html, trame-pyvista; otherwise a one-line error and exit code 2 (ddg/cli.py prints it).
"""
from __future__ import annotations

import sys

#: Most steps a comma-separated --steps list takes ('all' draws every frame).
MAX_STEPS = 50


def add_arguments(parser) -> None:
    """The render command's options."""
    parser.add_argument("dir", metavar="DIR", help="a run folder written with frames (python -m ddg simulate ... "
                                                   "--frames --out DIR)")
    parser.add_argument("--out", default=None, help="folder for step_NNNNN.png (and .html) (default DIR/render)")
    parser.add_argument("--steps", default=None,
                        help="comma-separated frame steps (the rows of DIR/path.csv, from 0), or 'all' (default: one "
                             "state per phase of the shear stage, U, US and S, each the middle of its stretch)")
    parser.add_argument("--color", default="z", choices=("z", "displacement"),
                        help="colour by the height z/L (default) or the displacement's length from the flat strip")
    parser.add_argument("--edges", action="store_true", help="draw the plate's triangle edges")
    parser.add_argument("--html", action="store_true",
                        help="also write interactive vtk.js scenes step_NNNNN.html (needs trame-pyvista and "
                             "nest_asyncio2)")
    parser.add_argument("--quiet", action="store_true", help="do not list the files written")


def parse_steps(text, run) -> list[int] | None:
    """--steps as frame steps of `run` (None: the default choice); a one-line InputError naming the
    value and the recorded range otherwise."""
    from ..limits import InputError
    from .render import check_steps

    if text is None:
        return None
    if text.strip().lower() == "all":
        return run.steps
    parts = [p.strip() for p in text.split(",")]
    allowed = f"this run's frames hold steps {run.describe_steps()}"
    if len(parts) > MAX_STEPS:
        raise InputError(f"--steps has {len(parts)} values; give 1 to {MAX_STEPS} steps or 'all' ({allowed})")
    steps = []
    for part in parts:
        try:
            steps.append(int(part))
        except ValueError:
            raise InputError(f"--steps = {text!r}: {part!r} is not an integer step; {allowed}") from None
    for step in steps:
        if step not in run.files:
            raise InputError(f"--steps = {text!r}: step {step} is out of range; {allowed}")
    return check_steps(run, steps)


def main(args) -> int:
    """Render; returns the exit code (0 drawn; 2 bad input, raised as InputError before any drawing)."""
    from ..limits import InputError
    from .io import check_output_directory
    from .render import html_unavailable, import_pyvista, open_run, render_run

    run = open_run(args.dir)
    steps = parse_steps(args.steps, run)
    import_pyvista()
    if args.html and (reason := html_unavailable()) is not None:
        raise InputError(reason)
    out = check_output_directory(args.out if args.out is not None else run.directory / "render", "--out")
    written = render_run(run.directory, out, steps, color_by=args.color, html=args.html, show_edges=args.edges)
    if not args.quiet:
        for path in written:
            sys.stdout.write(f"{path}\n")
    return 0
