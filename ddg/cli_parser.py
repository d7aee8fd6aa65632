"""The argument parser of every command line of the project (ddg, fem_reference, validation): argparse
whose parse errors are one line on stderr, `error: <message>`, and exit code 2, never its usage block.

One implementation for all: ddg is the lowest layer, so fem_reference and validation import it from
here without an import circle.
"""
from __future__ import annotations

import argparse
import sys

#: The exit code of bad input on every command line (ddg.cli, fem_reference.cli, validation).
EXIT_BAD_INPUT = 2


class OneLineParser(argparse.ArgumentParser):
    """argparse.ArgumentParser whose errors (an unknown option, a value of the wrong type, a missing
    argument) are `error: <message>` on one line of stderr, then SystemExit(2). Its subcommand parsers
    (add_subparsers) are of the same class."""

    def error(self, message):
        sys.stderr.write(f"error: {' '.join(str(message).split())}\n")
        raise SystemExit(EXIT_BAD_INPUT)
