"""What every command of validation shares: one parser class (ddg.cli_parser.OneLineParser: a bad
option is one line on stderr, `error: <message>`, and exit 2, never a usage block or a traceback),
and the old spelling `python -m validation.<module>` of a command as an alias of
`python -m validation <command>`: the same options, the same checks, the same work.

A command's module declares its options (`add_arguments(parser)`) and does its work (`run(args)`,
returning the exit code); validation.cli gathers them as subcommands.
"""
from __future__ import annotations

import sys

from ddg.cli_parser import EXIT_BAD_INPUT, OneLineParser


def standalone(command: str, add_arguments, run, argv=None) -> int:
    """`python -m validation <command>` run from the command module's own `main(argv)`."""
    parser = OneLineParser(prog=f"python -m validation {command}")
    add_arguments(parser)
    return run(parser.parse_args(argv))


def refuse(message: str):
    """A bad option found after parsing, refused as a parse error is: one line on stderr, SystemExit(2)."""
    sys.stderr.write(f"error: {' '.join(str(message).split())}\n")
    raise SystemExit(EXIT_BAD_INPUT)


def output_folder(path):
    """The command's --out folder (ddg.output.io.check_output_directory), or None after one line on
    stderr where it is a file or cannot be written: the caller returns exit 2 before any work."""
    from ddg.limits import InputError
    from ddg.output.io import check_output_directory

    try:
        return check_output_directory(path, "--out")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return None


def check_run_names(runs, only) -> None:
    """--only's names refused in one line (exit 2) where one is not a run of the study."""
    unknown = [n for n in (only or ()) if n not in {r.name for r in runs}]
    if unknown:
        refuse(f"--only {unknown[0]!r} is not a run; the runs are {', '.join(r.name for r in runs)}")


def resumable_runs(runs, only, out, columns, run_one, table: str = "runs.csv") -> list[dict]:
    """A study's fixed list of runs (each with a `name`), resumable: the runs not yet in OUT/table
    (and in `only`, where given: check_run_names first) computed one by one by run_one(run) -> row,
    the table rewritten after each so an interrupted study keeps every finished run. Returns the
    rows in the list's order."""
    import csv

    from ddg.output.io import write_table_csv

    path = out / table
    done = {}
    if path.exists():
        with open(path, newline="") as fh:
            done = {r["name"]: r for r in csv.DictReader(fh)}
    for r in runs:
        if r.name in done or (only and r.name not in only):
            continue
        done[r.name] = run_one(r)
        write_table_csv(path, [done[x.name] for x in runs if x.name in done], columns)
        row = done[r.name]
        print(f"{r.name}: dW1/L = {row.get('dW1_over_L')}, dW2/L = {row.get('dW2_over_L', '-')}, "
              f"{row.get('wall_time_s')} s", flush=True)
    return [done[x.name] for x in runs if x.name in done]
