"""`python -m validation <command>` (validation/cli.py): every command of validation is a subcommand,
and its old spelling `python -m validation.<module>` parses the same options (the same --help) and
refuses a bad one in the same single line."""
from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

from validation import cli

ROOT = Path(__file__).resolve().parents[2]
COMMANDS = cli.commands()
#: The old spelling of each subcommand: the module `python -m` ran.
OLD_SPELLING = {"report": "validation.report", "score": "validation.score", "benchmark": "validation.benchmark",
                "error-map": "validation.error_map", "plate-gold": "validation.plate_gold",
                "narrow-limit": "validation.narrow_limit", "wide-check": "validation.wide_check",
                "locking": "validation.locking", "plate-modes": "validation.plate_modes",
                "plate-mesh-scan": "validation.plate_mesh_scan", "paper-figures": "validation.paper_figures",
                "ribbon-regularisation": "validation.ribbon_regularisation",
                "midedge-convergence": "validation.midedge_convergence",
                "ribbon-reconciliation": "validation.ribbon_reconciliation"}


def test_every_command_of_validation_is_a_subcommand():
    """A module of validation with a command-line `main` (outside cli and __main__) is the alias of a
    subcommand whose module declares its options and runs it."""
    with_main = set()
    for path in sorted((ROOT / "validation").rglob("*.py")):
        tree = ast.parse(path.read_text())
        if any(isinstance(node, ast.FunctionDef) and node.name == "main" for node in tree.body):
            module = ".".join(path.relative_to(ROOT).with_suffix("").parts)
            with_main.add(module)
    with_main -= {"validation.cli", "validation.__main__"}
    assert with_main == {OLD_SPELLING[c].replace("validation.error_map", "validation.error_map.command")
                         for c in COMMANDS}
    assert set(COMMANDS) == set(OLD_SPELLING)
    for name, (module, help_text) in COMMANDS.items():
        assert callable(module.add_arguments) and callable(module.run) and help_text, name


@pytest.mark.parametrize("command", sorted(OLD_SPELLING))
def test_the_old_spelling_parses_as_the_subcommand(command, capsys):
    """The same --help (usage `python -m validation <command>`), and an unknown option refused in the
    same one line with exit 2."""
    old = importlib.import_module(OLD_SPELLING[command]).main
    with pytest.raises(SystemExit) as done:
        cli.main([command, "--help"])
    new_help = capsys.readouterr().out
    assert done.value.code == 0 and new_help.startswith(f"usage: python -m validation {command}")
    with pytest.raises(SystemExit) as done:
        old(["--help"])
    assert done.value.code == 0 and capsys.readouterr().out == new_help
    outcomes = []
    for call in (lambda: cli.main([command, "--spaghetti"]), lambda: old(["--spaghetti"])):
        with pytest.raises(SystemExit) as done:
            call()
        outcomes.append((done.value.code, capsys.readouterr().err))
    assert outcomes[0] == outcomes[1] == (2, "error: unrecognized arguments: --spaghetti\n")
