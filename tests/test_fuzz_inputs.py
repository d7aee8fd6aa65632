"""Issue 13, acceptance: no traceback on any input. A fuzz test of both command lines and the API.

The contract, for every BAD input (the package tests/fuzz_cases/ generates them):

- command line (`python -m ddg ...` = ddg.cli.main, `python -m fem_reference ...` =
  fem_reference.cli.main): exit code 2 (returned, or SystemExit(2) from argparse), stderr exactly
  one line starting with `error:`, no "Traceback" in stdout or stderr;
- API (ddg.Strip, Strip.from_ratios, LoadingProtocol, NewtonOptions, ContinuationOptions,
  DynamicOptions, ddg.simulate): ddg.InputError (a ValueError) with a one-line message, raised
  at construction or at the call;
- nothing computed: the refusal comes before any work. While a case runs, the solvers' entry
  points (path following, the models' energy evaluation, the dynamic stepper, gmsh meshing, the
  FEM mesh and shell) are replaced by a tripwire: reaching one means the input was accepted and
  work began, and the case fails with "not refused: computation started". Each case runs under a
  memory ceiling (3 GiB above the process's current address space) and a 30 s alarm, so an
  unbounded size fails fast (MemoryError, timeout) instead of loading the shared machine.
  A refused case takes milliseconds; the 30 s limit is the hard ceiling.

VALID edge cases (W/L = 1, dW/L = 0, the smallest resolutions, 5000 steps, ...) must NOT be
refused: they must reach a tripwire (validation passed, the solver was about to start) with
nothing on stderr. A handful of them run for real on a tiny rod scene (exit 0, or 3 if the run
stops converging, never 2, never a traceback). A few bad cases also run as subprocesses
(`python -m ddg|fem_reference`, cwd = the case's temporary directory, 30 s timeout) for the real
exit code and output.

Issue 47 item 3 ("every bad input answered") adds the validation command lines (`python -m
validation <command>` for every subcommand, and the old spellings validation.error_map,
validation.plate_gold and every other validation module with its own main; prog "validation" or the
module's name), `ddg sweep` and run_sweep, the
scheduler of fem_reference gold, and DDG_BLAS_THREADS (Case.env). Each of those cases must also name
the refused value in its one line (Case.names) and leave its temporary folder exactly as it was
(Case.untouched: no --out created, an existing --out unchanged, no runs/ or cache/); a read that
could block (a FIFO) runs under a shorter alarm (Case.limit_s). The validation commands' own work is
tripwired too (the scorecard, the template, the error map's rows, the report).

Cases are generated deterministically from tables (fuzz_cases.BAD_VALUES: option -> bad
values, crossed with every subcommand and model the option applies to; hand-written lists of
incompatible options, unknown options and missing arguments; API calls), with ids such as
`ddg-simulate-rod-resolution-100000000` or `api-NewtonOptions-max_iterations-0`.

Set DDG_FUZZ_RECORD=/path/file.jsonl to append one JSON record per case (id, outcome, cause,
exit code, first stderr line, seconds); `python tests/fuzz_cases/report.py /path/file.jsonl`
lists the failing cases grouped by cause.
"""
from __future__ import annotations

import contextlib
import json
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_cases  # noqa: E402
from fuzz_cases import ACCEPT, REFUSE, RUN, Case  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
HARD_LIMIT_S = 30.0
MEMORY_HEADROOM = 3 * 2**30

IN_PROCESS = fuzz_cases.all_in_process_cases()
RUNS = fuzz_cases.run_cases()
SUBPROCESS = fuzz_cases.subprocess_cases()

#: The whole file's budget (in-process cases take milliseconds; the subprocesses ~0.2-3 s each).
FILE_BUDGET_S = 60.0
_CLOCK = {"start": None, "cases": 0}


@pytest.fixture(autouse=True)
def _count_case():
    if _CLOCK["start"] is None:
        _CLOCK["start"] = time.perf_counter()
    yield
    _CLOCK["cases"] += 1


# ----------------------------------------------------------------------------------- tripwires
class WorkStarted(BaseException):
    """A solver entry point was reached: the input was accepted and work began."""


class CaseTimeout(BaseException):
    """The case ran past HARD_LIMIT_S."""


DDG_ENTRY_POINTS = (
    ("ddg.solve.continuation", "PathFollower", "rest"),
    ("ddg.solve.continuation", "PathFollower", "start_compression"),
    ("ddg.solve.continuation", "PathFollower", "advance"),
    ("ddg.models.rod", "RodModel", "evaluate"),
    ("ddg.models.ribbon", "RibbonModel", "evaluate"),
    ("ddg.models.plate", "PlateModel", "evaluate"),
    ("ddg.solve.dynamics", "ImplicitEuler", "__init__"),
    ("ddg.solve.dynamics", "ImplicitEuler", "advance"),
    # gmsh's import, initialisation and meshing: the pytest worker running the valid gmsh case under
    # the case's memory ceiling crashed once (1 of 7 clean-clone runs, in gmsh's initialise or
    # finalise, the only native code the case reached), so none of gmsh runs inside a case
    ("ddg.geometry.mesh_io", None, "_gmsh_session"),
    # the study generators and the sweep hand their runs to Dask workers here: past every check
    ("ddg.sweep.cluster", None, "run_all"),
)
#: Where the validation commands begin their work: the scorecard, the template, the error map's rows, the
#: report's runs (each looked up in its module at the call, so the tripwire is what the command calls).
VALIDATION_ENTRY_POINTS = (
    ("validation.score", None, "score_results"),
    ("validation.score", None, "write_template"),
    ("validation.error_map.command", None, "build"),
    ("validation.report", None, "build_report"),
)
FEM_ENTRY_POINTS = (
    ("fem_reference.mesh", None, "build_gmsh_model"),
    ("fem_reference.mesh", None, "create_mesh"),
    ("fem_reference.shell", "NaghdiStrip", "__init__"),
    ("fem_reference.solver", "Solver", "__init__"),
)


def _tripwire(name):
    def tripped(*args, **kwargs):
        raise WorkStarted(name)
    return tripped


#: Modules that bind an entry point by name when first imported (`from .mesh import create_mesh`):
#: imported before the tripwires go in, or the tripwire would stay bound in them after the case
#: (monkeypatch restores the entry point's own module only) and trip the tests that run later.
BIND_ENTRY_POINTS_BY_NAME = ("fem_reference.shell",)


def install_tripwires(monkeypatch, fem: bool, validation: bool = False) -> None:
    import importlib

    for module_name in BIND_ENTRY_POINTS_BY_NAME if fem else ():
        try:
            importlib.import_module(module_name)
        except ImportError:
            pass
    for module_name, owner, attribute in DDG_ENTRY_POINTS + (FEM_ENTRY_POINTS if fem else ()) + \
            (VALIDATION_ENTRY_POINTS if validation else ()):
        try:
            module = importlib.import_module(module_name)
        except ImportError:
            continue
        target = module if owner is None else getattr(module, owner, None)
        if target is None or not hasattr(target, attribute):
            continue  # the library is being refactored: skip entry points that moved
        if owner is not None and attribute not in vars(target):
            continue  # inherited: the base class's tripwire covers it
        monkeypatch.setattr(target, attribute, _tripwire(f"{owner + '.' if owner else ''}{attribute}"))


def _address_space() -> int:
    with open("/proc/self/status") as fh:
        match = re.search(r"VmSize:\s+(\d+)\s+kB", fh.read())
    return int(match.group(1)) * 1024 if match else 0


@contextlib.contextmanager
def guarded(limit_s: float = HARD_LIMIT_S):
    """A memory ceiling (current address space + MEMORY_HEADROOM) and an alarm at limit_s."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    ceiling = _address_space() + MEMORY_HEADROOM
    if hard != resource.RLIM_INFINITY:
        ceiling = min(ceiling, hard)

    resource.setrlimit(resource.RLIMIT_AS, (ceiling, hard))
    try:
        with fuzz_cases.at_most(limit_s, CaseTimeout):
            yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


# ----------------------------------------------------------------------------------- running a case
def prepare(tmp_path: Path, monkeypatch) -> None:
    (tmp_path / "file.txt").write_text("not a directory\n")
    (tmp_path / "empty.msh").write_text("")
    (tmp_path / "dir").mkdir()
    (tmp_path / "garbage.msh").write_bytes(bytes(range(256)) * 8)
    (tmp_path / "header.msh").write_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
    (tmp_path / "mesh.xyz").write_text("1 2 3\n")
    os.symlink(tmp_path / "loop", tmp_path / "loop")
    os.symlink(tmp_path / "nowhere" / "at-all", tmp_path / "dangling")
    for name, text in (("run-corrupt", "{not json"), ("run-keys", "{}")):
        (tmp_path / name).mkdir()
        (tmp_path / name / "summary.json").write_text(text)
        (tmp_path / name / "path.csv").write_text("stage,dL_over_L\ncompression,x\n")
    os.mkfifo(tmp_path / "fifo")   # opening it for reading blocks until a writer comes: never read it
    for name, text in fuzz_cases.RESULTS_FILES.items():
        (tmp_path / name).write_text(text)
    monkeypatch.chdir(tmp_path)  # a stray default ./out lands here, never in the repository


def tree(folder: Path) -> dict[str, tuple]:
    """Every entry under `folder` (symlinks not followed): relative path -> (mode, size, mtime)."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = Path(root) / name
            info = path.lstat()
            out[str(path.relative_to(folder))] = (info.st_mode, info.st_size, info.st_mtime_ns)
    return out


def changes(before: dict, after: dict) -> str:
    """What a case created, removed or changed in its folder, in words ('' if nothing)."""
    created = sorted(set(after) - set(before))
    removed = sorted(set(before) - set(after))
    changed = sorted(k for k in set(before) & set(after) if before[k] != after[k])
    return "; ".join(f"{what}: {', '.join(names[:4])}" for what, names in (("created", created), ("removed", removed),
                                                                           ("changed", changed)) if names)


def expand(argv, tmp_path: Path) -> list[str]:
    return [a.replace("{out}", str(tmp_path / "out")).replace("{tmp}", str(tmp_path)) for a in argv]


def _main(prog: str):
    if prog == "ddg":
        from ddg.cli import main
    elif prog == "fem":
        from fem_reference.cli import main
    else:   # "validation" (python -m validation) or a module of validation with its own main
        import importlib

        main = importlib.import_module("validation.__main__" if prog == "validation" else prog).main
    return main


def run_cli_in_process(case: Case, tmp_path: Path, capfd) -> dict:
    main = _main(case.prog)
    argv = expand(case.argv, tmp_path)
    outcome = {"code": None, "exception": None, "work": None, "timeout": None}
    t0 = time.perf_counter()
    try:
        with guarded(case.limit_s or HARD_LIMIT_S):
            outcome["code"] = main(argv)
    except SystemExit as exc:
        code = exc.code
        if isinstance(code, str):  # SystemExit("text"): Python prints it and exits 1
            sys.stderr.write(code + "\n")
            code = 1
        outcome["code"] = 0 if code is None else code
    except WorkStarted as exc:
        outcome["work"] = str(exc)
    except CaseTimeout as exc:
        outcome["timeout"] = str(exc)
    except BaseException as exc:  # noqa: BLE001 - escaping main() is a traceback
        outcome["exception"] = exc
    outcome["seconds"] = time.perf_counter() - t0
    captured = capfd.readouterr()
    outcome["out"], outcome["err"] = captured.out, captured.err
    return outcome


def run_api(case: Case, tmp_path: Path) -> dict:
    outcome = {"exception": None, "work": None, "timeout": None, "returned": False}
    t0 = time.perf_counter()
    try:
        with guarded(case.limit_s or HARD_LIMIT_S):
            case.call(tmp_path)
        outcome["returned"] = True
    except WorkStarted as exc:
        outcome["work"] = str(exc)
    except CaseTimeout as exc:
        outcome["timeout"] = str(exc)
    except BaseException as exc:  # noqa: BLE001
        outcome["exception"] = exc
    outcome["seconds"] = time.perf_counter() - t0
    return outcome


def first_line(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    return lines[0][:200] if lines else ""


def _exception_text(exc: BaseException) -> str:
    message = str(exc).splitlines()[0][:200] if str(exc) else ""
    return f"{type(exc).__name__}: {message}"


def cli_problem(outcome: dict) -> tuple[str, str] | None:
    """(cause, detail) of a bad command-line case that was not cleanly refused, else None."""
    err, out = outcome["err"], outcome["out"]
    if outcome["timeout"]:
        return f"timeout: {outcome['timeout']} (computing, or blocked on a read)", outcome["timeout"]
    if outcome["work"]:
        return "not refused: computation started", f"reached {outcome['work']}"
    exc = outcome["exception"]
    if exc is not None:
        if isinstance(exc, MemoryError):
            return "not refused: unbounded size, allocation failed (MemoryError traceback)", _exception_text(exc)
        return f"traceback: uncaught {type(exc).__name__}", _exception_text(exc)
    if "Traceback" in err or "Traceback" in out:
        return "traceback printed", first_line(err) or first_line(out)
    code = outcome["code"]
    if code == 1 and "out of memory" in err:
        return "exit 1: out of memory (size not bounded before work)", first_line(err)
    if code == 1 and "internal error" in err:
        return "exit 1: internal error (an exception after validation, not refused as input)", first_line(err)
    if code != 2:
        return f"exit code {code} instead of 2", first_line(err)
    lines = err.splitlines()
    if len(lines) != 1 or not err.endswith("\n"):
        if err.startswith("usage:"):
            return "stderr: usage dump (argparse's default error, not one line)", first_line(err)
        return f"stderr: {len(lines)} lines instead of one", first_line(err)
    if not lines[0].startswith("error:"):
        return "stderr: the line does not start with 'error:'", first_line(err)
    if outcome["seconds"] > HARD_LIMIT_S:
        return "slow refusal (> 30 s)", f"{outcome['seconds']:.1f} s"
    return None


def api_problem(outcome: dict) -> tuple[str, str] | None:
    if outcome["timeout"]:
        return "timeout: still running after 30 s (computing)", outcome["timeout"]
    if outcome["work"]:
        return "not refused: computation started", f"reached {outcome['work']}"
    if outcome["returned"]:
        return "not refused: the call returned", ""
    exc = outcome["exception"]
    import ddg

    if isinstance(exc, MemoryError):
        return "not refused: unbounded size, allocation failed (MemoryError)", _exception_text(exc)
    if not isinstance(exc, ddg.InputError):
        return f"wrong exception: {type(exc).__name__} instead of ddg.InputError", _exception_text(exc)
    if "\n" in str(exc).strip() or not str(exc).strip():
        return "InputError message not one line", repr(str(exc)[:200])
    if outcome["seconds"] > HARD_LIMIT_S:
        return "slow refusal (> 30 s)", f"{outcome['seconds']:.1f} s"
    return None


def record(case: Case, problem, code=None, line="", seconds=0.0) -> None:
    path = os.environ.get("DDG_FUZZ_RECORD")
    if not path:
        return
    entry = {"id": case.id, "prog": case.prog, "option": case.option, "expect": case.expect, "ok": problem is None,
             "cause": problem[0] if problem else "", "detail": problem[1] if problem else "", "code": code,
             "stderr": line, "seconds": round(seconds, 4)}
    with open(path, "a") as fh:
        fh.write(json.dumps(entry) + "\n")


def fail(case: Case, problem, code, line) -> None:
    cause, detail = problem
    pytest.fail(f"{case.id}: {cause} | exit {code} | {detail or line}", pytrace=False)


# ----------------------------------------------------------------------------------- the tests
@pytest.mark.parametrize("case", IN_PROCESS, ids=[c.id for c in IN_PROCESS])
def test_input(case: Case, tmp_path, monkeypatch, capfd):
    prepare(tmp_path, monkeypatch)
    install_tripwires(monkeypatch, fem=case.prog == "fem", validation=case.prog.startswith("validation"))
    for name, value in case.env:
        monkeypatch.setenv(name, value)
    before = tree(tmp_path) if case.untouched else None
    if case.prog == "api":
        outcome = run_api(case, tmp_path)
        code = None
        exc = outcome["exception"]
        line = _exception_text(exc) if exc is not None else ""
        if case.expect == REFUSE:
            problem = api_problem(outcome)
        elif outcome["work"]:
            problem = None
        else:
            import ddg

            exc = outcome["exception"]
            if isinstance(exc, ddg.InputError):
                problem = ("valid input refused (InputError)", line)
            elif exc is not None:
                problem = (f"valid input: uncaught {type(exc).__name__}", line)
            else:
                problem = ("valid input: did not reach the solver",
                           "the call returned" if outcome["returned"] else outcome["timeout"])
        capfd.readouterr()
    else:
        outcome = run_cli_in_process(case, tmp_path, capfd)
        code = outcome["code"]
        line = first_line(outcome["err"])
        if outcome["exception"] is not None:
            line = _exception_text(outcome["exception"])
        if case.expect == REFUSE:
            problem = cli_problem(outcome)
        elif outcome["work"] and not [x for x in outcome["err"].splitlines()
                                      if x.strip() and not x.startswith("warning:")]:
            problem = None  # validation passed (a `warning:` line is allowed), the solver was reached
        elif outcome["work"]:
            problem = ("valid input: stderr not empty before the solver", line)
        elif outcome["exception"] is not None:
            problem = (f"valid input: traceback: uncaught {type(outcome['exception']).__name__}", line)
        else:
            problem = (f"valid input refused (exit {code})" if code == 2 else
                       f"valid input: did not reach the solver (exit {code})", line or outcome["timeout"] or "")
    if problem is None and case.names and case.names not in line:
        problem = ("the error line does not name the value", f"{case.names!r} not in the line")
    if problem is None and before is not None:
        touched = changes(before, tree(tmp_path))
        if touched:
            problem = ("refused, but its folder changed (made or written before the refusal)", touched)
    record(case, problem, code, line, outcome["seconds"])
    if problem is not None:
        fail(case, problem, code, line)


@pytest.fixture(scope="module")
def kernels_loaded():
    """The compiled kernels the valid runs use, loaded from numba's cache before a case's memory
    ceiling is set: loading them maps the JIT's code, which under the ceiling aborted LLVM (seen
    when this file was the first of its pytest-xdist worker to run the rod). The ceiling is for
    what a run allocates, not for loading the library."""
    from ddg.models.names import PLATE, RIBBON, ROD
    from ddg.warmup import compile_kernels

    compile_kernels([ROD, RIBBON, PLATE])


@pytest.mark.parametrize("case", RUNS, ids=[c.id for c in RUNS])
def test_valid_edge_case_runs(case: Case, tmp_path, monkeypatch, capfd, kernels_loaded):
    """A valid edge case on a tiny scene, run for real: exit 0 (or 3: stopped converging), not 2."""
    prepare(tmp_path, monkeypatch)
    outcome = run_cli_in_process(case, tmp_path, capfd)
    code, err = outcome["code"], outcome["err"]
    line = first_line(err) if outcome["exception"] is None else _exception_text(outcome["exception"])
    problem = None
    if outcome["timeout"]:
        problem = ("valid run: timeout", outcome["timeout"])
    elif outcome["exception"] is not None:
        problem = (f"valid run: traceback: uncaught {type(outcome['exception']).__name__}", line)
    elif "Traceback" in err or "Traceback" in outcome["out"]:
        problem = ("valid run: traceback printed", line)
    elif code not in (0, 3):
        problem = (f"valid run: exit {code}" + (" (refused)" if code == 2 else ""), line)
    elif code == 0 and "error:" in err:
        problem = ("valid run: exit 0 with an error line", line)
    elif code == 0 and not all((tmp_path / "out" / name).is_file() for name in ("path.csv", "summary.json")):
        problem = ("valid run: exit 0 without path.csv and summary.json", line)
    record(case, problem, code, line, outcome["seconds"])
    if problem is not None:
        fail(case, problem, code, line)


def _limit_memory():  # subprocess preexec: the same ceiling as in-process, absolute
    resource.setrlimit(resource.RLIMIT_AS, (4 * 2**30, resource.RLIM_INFINITY))


@pytest.mark.parametrize("case", SUBPROCESS, ids=[c.id for c in SUBPROCESS])
def test_bad_input_in_a_subprocess(case: Case, tmp_path, monkeypatch):
    """The real program: exit 2, one `error:` line on stderr, no traceback, within 30 s."""
    prepare(tmp_path, monkeypatch)
    module = {"ddg": "ddg", "fem": "fem_reference"}.get(case.prog, case.prog)   # or validation[.module]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH",
                                                                                  "")]).rstrip(os.pathsep),
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg", **dict(case.env)}
    t0 = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, "-m", module, *expand(case.argv, tmp_path)], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=HARD_LIMIT_S, preexec_fn=_limit_memory)
    except subprocess.TimeoutExpired:
        problem = ("timeout: still running after 30 s (computing)", "")
        record(case, problem, None, "", time.perf_counter() - t0)
        fail(case, problem, None, "")
    seconds = time.perf_counter() - t0
    err, out, code = proc.stderr, proc.stdout, proc.returncode
    line = first_line(err)
    problem = None
    if "Traceback" in err or "Traceback" in out:
        tail = [x for x in err.splitlines() if x.strip()]
        problem = ("traceback printed", tail[-1][:200] if tail else line)
    elif code != 2:
        problem = (f"exit code {code} instead of 2", line)
    elif len(err.splitlines()) != 1 or not err.startswith("error:"):
        problem = ("stderr: usage dump (argparse's default error, not one line)" if err.startswith("usage:")
                   else f"stderr: {len(err.splitlines())} lines, not one 'error:' line", line)
    record(case, problem, code, line, seconds)
    if problem is not None:
        fail(case, problem, code, line)


def test_case_counts():
    """The generator yields a few hundred cases, every one with a unique id (also a guard against an
    empty table after an edit)."""
    bad = [c for c in IN_PROCESS if c.expect == REFUSE]
    valid = [c for c in IN_PROCESS if c.expect == ACCEPT]
    assert len(bad) >= 300 and len(valid) >= 30 and 5 <= len(RUNS) <= 10 and 10 <= len(SUBPROCESS) <= 16
    issue47 = [c for c in bad if c.untouched]   # issue 47 item 3: each names its value and leaves its folder
    assert len(issue47) >= 40 and all(c.names for c in issue47)
    assert all(c.expect == RUN for c in RUNS)
    assert len({c.id for c in IN_PROCESS + RUNS + SUBPROCESS}) == len(IN_PROCESS) + len(RUNS) + len(SUBPROCESS)


def test_input_error_is_a_one_line_value_error():
    import ddg

    assert issubclass(ddg.InputError, ValueError)


def test_whole_file_within_budget():
    """Runs last (pytest keeps file order): the file took under FILE_BUDGET_S when every case ran."""
    total = len(IN_PROCESS) + len(RUNS) + len(SUBPROCESS) + 2  # + test_case_counts, the InputError check
    if _CLOCK["cases"] < total:
        pytest.skip(f"only {_CLOCK['cases']} of {total} cases ran")
    elapsed = time.perf_counter() - _CLOCK["start"]
    assert elapsed < FILE_BUDGET_S, f"the fuzz file took {elapsed:.1f} s (budget {FILE_BUDGET_S:g} s)"
