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
