"""Command line: `python -m validation <command> ...`, one subcommand per report, table and study.

Each command lives in its room: its module declares the options (`add_arguments(parser)`) and does
the work (`run(args)`, the subcommand's one function, returning the exit code). Every command
checks its inputs before any work; a bad one is one line on stderr, `error: <message>`, and exit 2
(ddg.cli_parser.OneLineParser, as `python -m ddg` and `python -m fem_reference`). The old spelling
`python -m validation.<module>` of a command stays as an alias (validation.command_line.standalone).
"""
from __future__ import annotations

from ddg.cli_parser import OneLineParser


def commands() -> dict[str, tuple[object, str]]:
    """Subcommand -> (the module that declares and runs it, its one-line help), in the order
    `python -m validation --help` lists them."""
    from . import (benchmark, locking, midedge_convergence, narrow_limit, paper_figures, plate_gold, plate_mesh_scan,
                   plate_modes, report, ribbon_reconciliation,
                   ribbon_regularisation, score, wide_check)
    from .error_map import command as error_map

    return {
        "report": (report, "run the models on the paper's scenes and write DIR/index.html, report.md"),
        "score": (score, "score another code's thresholds and H_mid curves (a CSV file) against the FEM benchmark: "
                         "DIR/score.csv, score.md, score.png"),
        "benchmark": (benchmark, "the converged thresholds of the paper's ten scenes, FEM shell against the plates, "
                                 "the rod and the paper (data/benchmark)"),
        "error-map": (error_map, "every model's error and wall time on every scene with a FEM reference "
                                 "(data/error_map, read by python -m ddg advise)"),
        "plate-gold": (plate_gold, "the DDG plates' mesh studies on the benchmark scenes (data/plate_gold, "
                                   "data/midedge_gold)"),
        "narrow-limit": (narrow_limit, "the narrow strip at several L/b: FEM shell, plate, rod and cross-section "
                                       "(data/narrow_limit)"),
        "wide-check": (wide_check, "the mid-edge plate's U branch against the shell's at W/L = 1/2 "
                                   "(data/midedge_wide)"),
        "midedge-convergence": (midedge_convergence, "the mid-edge plate's dW1 over meshes refined across W and "
                                                     "along L apart (data/midedge_convergence)"),
        "locking": (locking, "membrane locking of the mid-edge plate at three slendernesses (data/midedge_locking)"),
        "plate-modes": (plate_modes, "the plate's energies on exact smooth deformations, mode by mode "
                                     "(data/plate_modes)"),
        "plate-mesh-scan": (plate_mesh_scan, "the plate's dW1 over every structured mesh in a range of sizes "
                                             "(data/plate_modes)"),
        "paper-figures": (paper_figures, "the data of the paper's Fig. 9: deformed plates and the centreline "
                                         "approximation's error (data/paper_figures)"),
        "ribbon-reconciliation": (ribbon_reconciliation, "our ribbons on Panda and Jawed's scene beside the shell "
                                                         "(data/ribbon_reconciliation)"),
        "ribbon-regularisation": (ribbon_regularisation, "the Wunderlich ribbon's thresholds against its "
                                                         "regularisation (data/ribbon_regularisation)"),
    }


def build_parser() -> OneLineParser:
    """The parser of every subcommand (commands), each with its module's options and its run."""
    parser = OneLineParser(prog="python -m validation",
                           description="Validation of the DDG models: the report, the benchmark and its scorecard, "
                                       "the error map and the studies behind the committed data.")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, (module, help_text) in commands().items():
        command = sub.add_parser(name, help=help_text)
        module.add_arguments(command)
        command.set_defaults(work=module.run)
    return parser


def main(argv=None) -> int:
    """`python -m validation <command> [options]`; returns the command's exit code (2: bad input,
    one line on stderr, before any work)."""
    args = build_parser().parse_args(argv)
    return args.work(args)
