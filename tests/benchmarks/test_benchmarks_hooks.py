"""Benchmarks measure through the library's public hooks (issue 15 item 5): the probe of
ddg.solve.probe, summary.json and cProfile; never by patching ddg objects or reading caller frames."""
from __future__ import annotations

import ast
import math
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCHMARKS = sorted((ROOT / "benchmarks").glob("*.py"))

#: text that only a patch or caller-name introspection needs
FORBIDDEN_TEXT = ("_getframe", "def _set(", "._set(", "mock.patch", "monkeypatch")


def _root(node):
    """The name at the root of an attribute/subscript chain (a.b[c].d -> "a"), or None."""
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def _imports_ddg(node) -> bool:
    """importlib.import_module("ddg...") or __import__("ddg...")."""
    return (isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str) and node.args[0].value.split(".")[0] == "ddg"
            and (getattr(node.func, "attr", None) == "import_module" or getattr(node.func, "id", None) == "__import__"))


def _ddg_names(tree) -> set[str]:
    """Names bound to ddg modules, classes or functions anywhere in the module (imports, and
    aliases such as `PF = continuation.PathFollower`); scopes are not told apart."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names if a.name.split(".")[0] == "ddg"}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "ddg":
            names |= {a.asname or a.name for a in node.names}
    grew = True
    while grew:
        grew = False
        for node in ast.walk(tree):
            if isinstance(node, ast.Assign) and (_root(node.value) in names or _imports_ddg(node.value)):
                for target in node.targets:
                    if isinstance(target, ast.Name) and target.id not in names:
                        names.add(target.id)
                        grew = True
    return names


def patches(source: str) -> list[str]:
    """Where `source` patches ddg objects or reads caller frames: "line N: what"."""
    found = [f"line {n}: {text!r}" for n, line in enumerate(source.splitlines(), 1)
             for text in FORBIDDEN_TEXT if text in line]
    tree = ast.parse(source)
    ddg = _ddg_names(tree)
    for node in ast.walk(tree):
        targets = (node.targets if isinstance(node, ast.Assign) else
                   [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else
                   node.targets if isinstance(node, ast.Delete) else [])
        for target in targets:
            if isinstance(target, ast.Attribute) and _root(target) in ddg:
                found.append(f"line {node.lineno}: assignment to {ast.unparse(target)}")
            elif isinstance(target, ast.Subscript) and (
                    getattr(target.value, "attr", None) == "__dict__"
                    or (isinstance(target.value, ast.Call) and getattr(target.value.func, "id", None) == "vars")):
                found.append(f"line {node.lineno}: assignment into a namespace, {ast.unparse(target)}")
        if isinstance(node, ast.Call):
            name = getattr(node.func, "id", None) or getattr(node.func, "attr", None)
            if name in ("setattr", "delattr", "__setattr__", "__delattr__") and node.args and (
                    _root(node.args[0]) in ddg or "sys.modules" in ast.unparse(node.args[0])):
                found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


@pytest.mark.parametrize("path", BENCHMARKS, ids=lambda p: p.name)
def test_benchmarks_do_not_patch_the_library(path):
    assert patches(path.read_text()) == [], f"{path.name} patches the library or reads caller frames"


@pytest.mark.parametrize("snippet", [
    """
    from ddg.solve import banded
    banded.SymmetricBanded.lowest_eigenpairs = timed
    """,
    """
    import ddg.api as api
    setattr(api, "fill_thresholds", marked)
    """,
    """
    import sys
    caller = sys._getframe(1).f_code.co_name
    """,
    """
    from ddg.solve import continuation
    PF = continuation.PathFollower
    PF.advance = wrapper
    """,
    """
    self._set(SymmetricBanded, "cholesky", wrapper)
    """,
    """
    import importlib
    api = importlib.import_module("ddg.api")
    api.simulate = wrapped
    """,
    """
    from ddg.models import plate
    vars(plate)["add_edge_terms"] = wrapper
    """,
])
def test_the_check_finds_the_patches_the_benchmarks_used_to_make(snippet):
    assert patches(textwrap.dedent(snippet))


def test_the_check_passes_measurement_through_public_hooks():
    clean = textwrap.dedent("""
        import cProfile
        import ddg
        from ddg.solve.probe import Probe

        class Counting(Probe):
            def __init__(self):
                self.steps = []

            def step(self, stage, row, wall_s):
                self.steps.append(wall_s)

        profile = cProfile.Profile()
        result = ddg.simulate(strip, protocol, probe=Counting())
        record = {"wall": result.summary["wall_time_s"]}
    """)
    assert patches(clean) == []


def test_the_rod_benchmark_measures_a_small_run_with_everything_its_report_needs(tmp_path):
    from benchmarks import rod_path
    from benchmarks.common import Provenance, finish_path_report
    from ddg.solve.continuation import PHASES

    rec = rod_path.measure(20, compression_steps=4, shear_steps=4)
    # the probe: every recorded step, the solves adding up to the summary's iterations
    assert rec["converged"]
    assert rec["probe_matches_summary"]
    assert len(rec["steps"]) == rec["recorded_steps"] == 4 + 4 + 1
    assert sum(st["iterations_all"] for st in rec["steps"]) == rec["newton_iterations"]
    assert all(st["time_s"] > 0 for st in rec["steps"])
    assert set(rec["newton_by_phase"]) == set(PHASES)
    assert rec["profiled_run_newton_iterations"] == rec["newton_iterations"]
    assert rec["stage"]["compression"]["iterations"] + rec["stage"]["shear"]["iterations"] == rec["newton_iterations"]
    # cProfile: the split adds up to the un-profiled wall time, every category measured
    assert rec["profiled_wall_time_s"] > 0 and rec["wall_time_s"] > 0
    assert set(rec["split_s"]) == {*rod_path.CATEGORIES, "other"}
    assert all(v >= 0 for v in rec["split_s"].values()), rec["split_s"]
    assert math.isclose(sum(rec["split_s"].values()), rec["wall_time_s"], rel_tol=1e-9)
    assert all(rec["split_s"][c] > 0 for c in rod_path.CATEGORIES), rec["split_s"]
    assert math.isclose(sum(rec["split_fraction_issue14_definition"].values()), 1.0, rel_tol=1e-9)
    # the Newton load steps evaluate inside their compiled loop (issue 31): the Python-level calls
    # are the recorded states' and the threshold descents' evaluations
    assert rec["evaluations"] > 0 and rec["newton_iterations"] > 0
    assert rec["calls"]["eigen_calls"] and rec["calls"]["cholesky_factorisations"] > 0
    for key in ("first_call_wall_s", "cpu_time_s", "time_per_evaluation_ms", "H_mid_rel_error",
                "threshold_newton_iterations", "branches_newton_iterations", "stability_changes_during_shear"):
        assert key in rec, key
    # the report renders from the record alone
    rec.update(status="ok", all_wall_times_s=[rec["wall_time_s"]])
    (row,) = rod_path.table_rows([rec])
    assert len(row) == len(rod_path.HEADER) and all(cell != "" for cell in row)
    report = rod_path.build_report([rec], 1, None)
    finish_path_report(report, Provenance(), rod_path.scaling, rod_path.observations, rod_path.markdown_report,
                       tmp_path)
    text = (tmp_path / "rod_path.md").read_text()
    assert "by phase: accepted steps" in text and "by caller" not in text
    assert "measured under cProfile" in text
    # issue 31's targets: each measured figure is the sum of the parts it is said to be made of
    as_m100 = dict(rec, nodes=100)
    process = rod_path.measure_process(100, 1, 300)
    assert process["process_wall_s"] > process["imports_wall_s"] > 0
    targets = rod_path.issue31_targets([as_m100], process)
    assert [t["unit"] for t in targets] == ["s", "s", "its/step"]
    solver, whole, per_step = targets
    parts = solver["made_of"]
    assert math.isclose(sum(v for k, v in parts.items() if not k.startswith("by kind")), solver["measured"])
    assert math.isclose(sum(v for k, v in parts.items() if k.startswith("by kind")), solver["measured"])
    assert math.isclose(sum(whole["made_of"].values()), whole["measured"])
    assert math.isclose(sum(per_step["made_of"].values()), per_step["measured"])
    report["issue31_targets"] = targets
    assert "## Targets (issue 31)" in rod_path.markdown_report(report)


def test_the_plate_benchmark_states_issue_31s_targets_with_what_each_figure_is_made_of():
    """On the stored benchmark record (benchmarks/results/plate_path.json): a wall-time target per
    size the issue names and an iterations target per run, each measured figure the sum of its
    parts (the path, thresholds, branches and rest; again by kind; iterations by phase)."""
    import json
    from pathlib import Path

    from benchmarks import plate_path

    report = json.loads((Path(__file__).parents[2] / "benchmarks/results/plate_path.json").read_text())
    targets = plate_path.issue31_targets(report["results"])
    walls = [t for t in targets if t["unit"] == "s"]
    assert sorted(t["bound"] for t in walls) == sorted(plate_path.ISSUE31_WALL_TARGET_S.values())
    for t in walls:
        parts = t["made_of"]
        assert math.isclose(sum(v for k, v in parts.items() if not k.startswith("by kind")), t["measured"])
        assert math.isclose(sum(v for k, v in parts.items() if k.startswith("by kind")), t["measured"])
    for t in targets:
        if t["unit"] == "its/step":
            assert math.isclose(sum(t["made_of"].values()), t["measured"])
    report["issue31_targets"] = targets
    assert "## Targets (issue 31)" in plate_path.markdown_report(report)
