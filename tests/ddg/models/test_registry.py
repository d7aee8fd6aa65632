"""The model registry (ddg.models.registry): one table that every layer reads, and the only place
in ddg/ that spells a model's name (with the vocabulary module ddg.models.names and the command
line's help)."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

import ddg
from ddg.models import registry
from ddg.models.base import Model

DDG = Path(ddg.__file__).resolve().parent
#: The files allowed to spell a model's name in code: the registry's vocabulary and table, and the
#: command line (its help lists them). output/render.py says "plate" and "rod" as the kinds of
#: geometry a frame draws (a surface of triangles, a polyline), not as models.
SPELLERS = {"models/names.py", "models/registry.py", "cli.py", "output/render.py"}


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the docstring nodes of a module and of its classes and functions."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                found.add(id(first.value))
    return found


def spelled_names() -> dict[str, list[str]]:
    """file (relative to ddg/) -> 'line: name' of each string constant in code (docstrings aside)
    that is a model's name."""
    out: dict[str, list[str]] = {}
    for path in sorted(DDG.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        docs = _docstrings(tree)
        hits = [f"{node.lineno}: {node.value}" for node in ast.walk(tree)
                if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in registry.MODELS
                and id(node) not in docs]
        if hits:
            out[path.relative_to(DDG).as_posix()] = hits
    return out


def test_model_names_are_spelled_in_the_registry_only():
    offenders = {f: hits for f, hits in spelled_names().items() if f not in SPELLERS}
    assert not offenders, offenders


@pytest.mark.parametrize("name", registry.NAMES)
def test_every_entry_is_a_model_the_driver_can_run(name):
    """Each class is a Model (the protocol the driver, Newton and the continuation call), carries
    its registry name, and builds at its default resolution."""
    entry = registry.MODELS[name]
    strip = ddg.Strip.from_ratios(1 / 20, 1 / 3)
    model = entry.model_class(strip, 41 if not entry.resolves_width else 200)
    assert isinstance(model, Model)
    assert model.name == name
    assert entry.default_resolution == ddg.api.DEFAULT_RESOLUTION[name]
    assert (name in ddg.api.ROD_FAMILY) is not entry.resolves_width


def test_the_families_and_options_partition_the_models():
    assert set(registry.names_in(registry.ROD_FAMILY)) | set(registry.names_in(registry.PLATES)) == set(registry.NAMES)
    assert set(registry.accepting(registry.MESH_FILE)) <= set(registry.accepting(registry.MESH)) \
        <= set(registry.names_in(registry.PLATES))
    assert set(registry.accepting(registry.ZETA)) <= set(registry.names_in(registry.ROD_FAMILY))


def test_an_unknown_model_is_one_line_naming_the_choices():
    with pytest.raises(ddg.InputError, match="is not available; choose one of") as caught:
        registry.entry("shell")
    assert "\n" not in str(caught.value) and all(name in str(caught.value) for name in registry.NAMES)
