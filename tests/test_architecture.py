"""The package's structure: no import circles, no private names used across modules, every
module says in its first docstring line what it is, and ruff is clean.

The import graph is read from the source (ast), lazy imports inside functions included: a
circle closed by a lazy import still means two modules that cannot be understood apart.
"""
from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("ddg", "fem_reference", "validation")


def modules() -> dict[str, Path]:
    found = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            found[".".join(parts)] = path
    return found


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def import_graph() -> tuple[dict[str, set[str]], dict[str, set[tuple[str, str]]]]:
    """module -> the project modules it imports; module -> (imported module, private name) pairs."""
    mods = modules()
    graph: dict[str, set[str]] = {m: set() for m in mods}
    private: dict[str, set[tuple[str, str]]] = {m: set() for m in mods}
    for module, path in mods.items():
        tree = ast.parse(path.read_text(), str(path))
        is_package = path.name == "__init__.py"
        for node in ast.walk(tree):
            targets: list[tuple[str, list[str]]] = []
            if isinstance(node, ast.Import):
                targets = [(alias.name, []) for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = _resolve(module, is_package, node)
                targets = [(base, [alias.name for alias in node.names])]
            for base, names in targets:
                for name in names:
                    if f"{base}.{name}" in mods:  # `from package import module`
                        graph[module].add(f"{base}.{name}")
                    elif name.startswith("_") and not name.startswith("__") and base in mods:
                        private[module].add((base, name))
                if base in mods:
                    if not (names and all(f"{base}.{n}" in mods for n in names)):
                        graph[module].add(base)
    for module in graph:
        graph[module].discard(module)
        # a package's own __init__ importing its submodules is not a circle through the package
    return graph, private


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10000))
    for v in graph:
        if v not in index:
            visit(v)
    return out


def _without_package_inits(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """Edges into a package __init__ that only names the package (the parent import every
    `from ddg.x import y` implies) are not dependencies on the __init__'s contents, except
    for the top-level packages whose __init__ re-exports the API."""
    mods = set(graph)
    packages = {m for m, p in modules().items() if p.name == "__init__.py"}
    return {m: {w for w in deps if w not in packages or w in PACKAGES} for m, deps in graph.items()
            if m in mods}


def test_no_import_circles():
    graph, _ = import_graph()
    found = cycles(_without_package_inits(graph))
    assert not found, f"import circles: {found}"


def folder_graph(graph: dict[str, set[str]]) -> tuple[dict[str, set[str]], dict[tuple[str, str], set[tuple[str, str]]]]:
    """ddg's rooms (its sub-packages and its top-level modules, ddg/__init__ and __main__ aside: they
    face the user) -> the rooms they import; (room, room) -> the module imports behind the edge."""
    def room(module: str) -> str | None:
        parts = module.split(".")
        if parts[0] != "ddg" or module in ("ddg", "ddg.__main__"):
            return None
        return parts[1]

    rooms: dict[str, set[str]] = {}
    behind: dict[tuple[str, str], set[tuple[str, str]]] = {}
    for module, targets in graph.items():
        a = room(module)
        if a is None:
            continue
        rooms.setdefault(a, set())
        for target in targets:
            b = room(target)
            if b is not None and b != a:
                rooms[a].add(b)
                behind.setdefault((a, b), set()).add((module, target))
    return rooms, behind


def test_no_import_circles_between_ddgs_folders():
    """The floors stand on each other one way: inputs (limits) below geometry, the assembly below
    the energies and the solvers, the solvers below the models, analysis below output, protocol and
    the api, the studies that run paths above the api. A loop between two folders, lazy imports
    included, means two floors that cannot be understood apart."""
    rooms, behind = folder_graph(import_graph()[0])
    loops = cycles(rooms)
    assert not loops, [(loop, sorted(edge for pair, edges in behind.items() if set(pair) <= set(loop)
                                     for edge in edges)) for loop in loops]


def test_no_private_names_imported_across_modules():
    _, private = import_graph()
    used = {m: sorted(p) for m, p in private.items() if p}
    assert not used, f"private names imported from other modules: {used}"


@pytest.mark.parametrize("module", sorted(modules()))
def test_module_docstring_says_what_it_is(module):
    path = modules()[module]
    doc = ast.get_docstring(ast.parse(path.read_text()))
    assert doc and doc.strip().splitlines()[0].strip(), f"{path.relative_to(ROOT)} has no docstring"


def test_every_module_imports_in_a_fresh_interpreter():
    """Each module imported alone (fem_reference only where dolfinx is installed): no module
    relies on another having been imported first."""
    names = [m for m in modules() if not m.startswith("fem_reference") or _has_dolfinx()]
    names = [m for m in names if not m.endswith("__main__")]
    code = ("import importlib, sys\nbad = []\nfor name in sys.argv[1:]:\n"
            "    for key in [k for k in sys.modules if k.split('.')[0] in ('ddg', 'fem_reference', 'validation')]:\n"
            "        del sys.modules[key]\n"
            "    try:\n        importlib.import_module(name)\n"
            "    except Exception as exc:\n        bad.append(f'{name}: {type(exc).__name__}: {exc}')\n"
            "print('\\n'.join(bad))\nsys.exit(1 if bad else 0)\n")
    done = subprocess.run([sys.executable, "-c", code, *names], cwd=ROOT, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr[-2000:]


def _has_dolfinx() -> bool:
    import importlib.util

    return importlib.util.find_spec("dolfinx") is not None


def test_ruff_is_clean():
    ruff = shutil.which("ruff") or str(Path(sys.executable).parent / "ruff")
    if not Path(ruff).exists():
        pytest.skip("ruff is not installed (requirements-dev.txt installs it)")
    done = subprocess.run([ruff, "check", *PACKAGES, "tests", "benchmarks"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:]


def validation_rooms(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """validation's rooms (its sub-packages and its top-level modules; the package itself and its
    __main__ face the user) -> the rooms they import."""
    def room(module: str) -> str | None:
        parts = module.split(".")
        if parts[0] != "validation" or module in ("validation", "validation.__main__"):
            return None
        return parts[1]

    rooms: dict[str, set[str]] = {}
    for module, targets in graph.items():
        a = room(module)
        if a is None:
            continue
        rooms.setdefault(a, set())
        rooms[a] |= {b for b in map(room, targets) if b is not None and b != a}
    return rooms


def test_no_import_circles_between_validations_rooms():
    """validation's rooms stand on each other one way: the table, the references and the estimates
    below the claims, the benchmark, the error map, the scorecard and the figures; the report's data
    above them; the command line (validation.cli) on top, imported by none of them."""
    rooms = validation_rooms(import_graph()[0])
    assert not cycles(rooms), cycles(rooms)
    assert not [r for r, targets in rooms.items() if "cli" in targets]
