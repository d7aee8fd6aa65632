"""The cases of tests/test_fuzz_inputs.py (issue 13, "no traceback on any input"), generated from tables.

Command-line cases: a tiny valid base command per (program, subcommand, model), with one option
overridden by a bad value (`--option=value`, appended after the base: argparse keeps the last
occurrence, and the `=` form lets values such as "-1", "-0" or "" through as values). The bad
values come from a table option -> values (BAD_VALUES) crossed with every subcommand and model the
option applies to (APPLIES); hand-written lists add the incompatible combinations, unknown options,
unknown subcommands and missing required arguments. API cases are small functions (ApiCase.call)
that build the objects and, if construction passes, call ddg.simulate with a tiny scene.

Placeholders in argv: {tmp} is the case's temporary directory (cwd of the case), {out} a fresh
output directory inside it. Every case's {tmp} holds file.txt (a regular file), empty.msh (an
empty file), dir/ (an empty directory), garbage.msh (binary noise), header.msh (a gmsh header
without nodes), mesh.xyz (an unknown format), loop (a symlink to itself), dangling (a symlink to
nothing), run-corrupt/ (summary.json not JSON), run-keys/ (summary.json without the keys), fifo (a
named pipe: opening it for reading blocks) and the results files of `validation score` (RESULTS_FILES).

Everything is deterministic: no random numbers, the same cases in the same order on every run.
"""
from __future__ import annotations

import contextlib
import math
import signal
from dataclasses import dataclass, field
from typing import Callable

# ----------------------------------------------------------------------------------- the case record
REFUSE = "refuse"   # bad input: exit 2 / InputError, one line, nothing computed
ACCEPT = "accept"   # valid edge case: validation passes (the solver is reached, then stopped)
RUN = "run"         # valid edge case, run for real on a tiny scene (about 1 s each)


@dataclass(frozen=True)
class Case:
    id: str
    prog: str                     # "ddg", "fem", "validation" or a validation module (the command lines), or "api"
    argv: tuple = ()
    option: str = ""              # the option or object under test, for grouping the failures
    expect: str = REFUSE
    call: Callable | None = field(default=None, compare=False)  # api: call(tmp_path)
    env: tuple = ()               # (name, value) environment variables set for the case
    names: str = ""               # the error line must contain it (the value refused)
    untouched: bool = False       # the case's folder must be as it was: nothing created, nothing changed
    limit_s: float = 0.0          # a hard time limit below the file's 30 s (a read that could block)


# ----------------------------------------------------------------------------------- base commands
#: Tiny valid scenes: every case below is one of these with one change.
DDG_SIMULATE = {
    "rod": ("simulate", "--model=rod", "--resolution=20"),
    "plate": ("simulate", "--model=plate", "--resolution=200"),
    "ribbon": ("simulate", "--model=ribbon", "--resolution=21"),
}
DDG_SIMULATE_TAIL = ("--compression-steps=2", "--shear-steps=2", "--shear-ratio=0.05", "--no-thresholds",
                     "--no-branches", "--quiet", "--out={out}")
DDG_CURVATURES = {
    "rod": ("curvatures", "--model=rod", "--resolution=20", "--shear-ratios=0,0.05", "--out={out}"),
    "plate": ("curvatures", "--model=plate", "--resolution=200", "--shear-ratios=0,0.05", "--out={out}"),
    "ribbon": ("curvatures", "--model=ribbon", "--resolution=21", "--shear-ratios=0,0.05", "--out={out}"),
}
DDG_CENTERLINE_ERROR = ("centerline-error", "--width-ratios=0.2", "--shear-ratios=0.1", "--resolution=200",
                        "--out={out}")
FEM_SCENE = ("--width-ratio=0.1667", "--compression-ratio=0.5", "--shear-ratio=0.05", "--compression-steps=2",
             "--shear-steps=2")
FEM_SIMULATE = ("simulate",) + FEM_SCENE + ("--resolution=8", "--no-thresholds", "--no-fields", "--quiet",
                                             "--out={out}")
FEM_CONVERGENCE = ("convergence",) + FEM_SCENE + ("--resolutions", "8", "10", "--quiet", "--out={out}")
FEM_GOLD = ("gold", "--only", "dL0.5_W0.1667", "--resolution=8", "--quiet", "--out={out}")


def ddg_simulate(model: str, *extra: str) -> tuple:
    return DDG_SIMULATE[model] + DDG_SIMULATE_TAIL + extra


# ----------------------------------------------------------------------------------- bad values
SIZE_BAD = ("0", "-1", "2.5", "nan", "inf", "", "abc", "1e5", "1e9", "100000000", ("400-digits", "9" * 400))
STEPS_BAD = ("0", "-1", "2.5", "nan", "", "1e9", "5001", "100000", "100000000")
OUT_BAD = (("existing-file", "{tmp}/file.txt"), ("dev-null", "/dev/null"), ("under-file", "{tmp}/file.txt/sub"),
           ("proc", "/proc/fuzz-out"), ("name-300-chars", "{tmp}/" + "x" * 300), ("empty", ""),
           ("nul-byte", "{tmp}/a\x00b"), ("symlink-loop", "{tmp}/loop"), ("dangling-symlink", "{tmp}/dangling"))

#: option -> bad values (or (label, value) pairs). Every value must be refused wherever the option applies.
BAD_VALUES: dict[str, tuple] = {
    "--width-ratio": ("nan", "inf", "-0", "0", "1e-300", "1.5", "-0.1", ""),
    "--compression-ratio": ("0.999999", "0.95", "1", "0", "1e-300", "5e-324", "-0.1", "nan", "inf", ""),
    "--shear-ratio": ("0.9", "-0.1", "nan", "inf", "1e300"),     # 0.9: beyond dW_max/L (Eq. B.1)
    "--slenderness": ("1e12", "1e300", "5e-324", "0", "-1", "nan", "inf"),
    "--poisson-ratio": ("0.5", "-0.1", "nan", "inf"),
    "--young-modulus": ("5e-324", "1e-300", "1e300", "0", "-1", "nan", "inf"),
    "--resolution": SIZE_BAD,
    "--compression-steps": STEPS_BAD,
    "--shear-steps": STEPS_BAD,
    "--max-newton-iterations": ("0", "-1", "2.5", "nan", "", "100000000"),
    "--out": OUT_BAD,
    "--zeta": ("0", "-1", "nan", "inf", "-inf", "", "1e300", "5e-324"),
    "--stations": SIZE_BAD + ("1",),
    "--clamp-speed": ("5e-324", "1e300", "1e-9", "0", "-1", "nan", "inf"),
    "--perturbation": ("nan", "inf", "1e300", "0", "-1"),
    "--across": SIZE_BAD,
    "--shear-ratios": ("nan", "inf", "-0.1", "0.9", "2", "", ",", "a,b", "0.1,,x", "1e300"),
    "--width-ratios": ("0", "-0.1", "1.5", "nan", "inf", "", "abc", "1e-300"),
}

#: Sizes below each model's smallest allowed value (rod/ribbon: 7 nodes; plate: 16 triangles; FEM: 4 elements).
BELOW_MINIMUM = {"rod": "6", "ribbon": "6", "plate": "15", "fem": "3"}

SCENE_OPTIONS = ("--width-ratio", "--compression-ratio", "--shear-ratio", "--slenderness", "--poisson-ratio",
                 "--young-modulus")


def _label(value: str) -> str:
    if value == "":
        return "empty"
    return value.replace("/", "_").replace(" ", "_")


def _pairs(option: str):
    for value in BAD_VALUES[option]:
        yield (value if isinstance(value, tuple) else (_label(value), value))


def _cases_for(prefix: str, prog: str, base: tuple, options, extra_values: dict | None = None) -> list[Case]:
    out = []
    for option in options:
        pairs = list(_pairs(option)) + [(_label(v), v) for v in (extra_values or {}).get(option, ())]
        for label, value in pairs:
            out.append(Case(f"{prefix}-{option.lstrip('-')}-{label}", prog, base + (f"{option}={value}",), option))
    return out


# ----------------------------------------------------------------------------------- command-line cases
def ddg_bad_cases() -> list[Case]:
    cases: list[Case] = []
    # simulate: every scene, size and output option on every model
    for model in ("rod", "plate", "ribbon"):
        options = SCENE_OPTIONS + ("--resolution", "--compression-steps", "--shear-steps", "--max-newton-iterations",
                                   "--out")
        cases += _cases_for(f"ddg-simulate-{model}", "ddg", ddg_simulate(model), options,
                            {"--resolution": (BELOW_MINIMUM[model],)})
    cases += _cases_for("ddg-simulate-ribbon", "ddg", ddg_simulate("ribbon"), ("--zeta",))
    # the dynamic solver (rod only): its own speed, and the sizes it allocates from
    dynamic = ddg_simulate("rod", "--solver=dynamic")
    cases += _cases_for("ddg-simulate-rod-dynamic", "ddg", dynamic, ("--clamp-speed",))
    for option in ("--resolution", "--compression-steps", "--shear-steps", "--max-newton-iterations"):
        cases.append(Case(f"ddg-simulate-rod-dynamic-{option.lstrip('-')}-100000000", "ddg",
                          dynamic + (f"{option}=100000000",), option))
    cases.append(Case("ddg-simulate-rod-dynamic-shear-steps-5001", "ddg", dynamic + ("--shear-steps=5001",),
                      "--shear-steps"))
    # choices
    for option, values in (("--model", ("spaghetti", "", "ROD")), ("--solver", ("x", "")), ("--branch", ("x", "++")),
                           ("--shear-direction", ("0", "2", "x")), ("--ribbon-init", ("x",))):
        for value in values:
            cases.append(Case(f"ddg-simulate-{option.lstrip('-')}-{_label(value)}", "ddg",
                              ddg_simulate("ribbon" if option == "--ribbon-init" else "rod", f"{option}={value}"),
                              option))
    # plate meshes
    for label, extra in (("missing-file", ("--mesh={tmp}/missing.msh",)), ("directory", ("--mesh={tmp}/dir",)),
                         ("empty-file", ("--mesh={tmp}/empty.msh",)), ("dev-null", ("--mesh=/dev/null",)),
                         ("text-file", ("--mesh={tmp}/file.txt",)), ("empty", ("--mesh=",)),
                         ("nul-byte", ("--mesh={tmp}/a\x00b.msh",)), ("garbage", ("--mesh={tmp}/garbage.msh",)),
                         ("header-only", ("--mesh={tmp}/header.msh",)), ("unknown-format", ("--mesh={tmp}/mesh.xyz",)),
                         ("symlink-loop", ("--mesh={tmp}/loop",)),
                         ("gmsh-resolution-100000000", ("--mesh=gmsh", "--resolution=100000000")),
                         ("gmsh-resolution-15", ("--mesh=gmsh", "--resolution=15")),
                         ("gmsh-resolution-0", ("--mesh=gmsh", "--resolution=0"))):
        cases.append(Case(f"ddg-simulate-plate-mesh-{label}", "ddg", ddg_simulate("plate", *extra), "--mesh"))
    # incompatible options
    for label, model, extra in (
            ("zeta-with-rod", "rod", ("--zeta=1",)), ("zeta-with-plate", "plate", ("--zeta=1",)),
            ("ribbon-init-with-rod", "rod", ("--ribbon-init=rod",)),
            ("ribbon-init-with-plate", "plate", ("--ribbon-init=direct",)),
            ("mesh-with-rod", "rod", ("--mesh=gmsh",)), ("mesh-file-with-rod", "rod", ("--mesh={tmp}/empty.msh",)),
            ("mesh-with-ribbon", "ribbon", ("--mesh=gmsh",)),
            ("dynamic-with-plate", "plate", ("--solver=dynamic",)),
            ("dynamic-with-ribbon", "ribbon", ("--solver=dynamic",)),
            ("frames-with-ribbon", "ribbon", ("--frames",)),
            ("dynamic-with-mesh", "rod", ("--solver=dynamic", "--mesh=gmsh")),
            ("dynamic-with-frames", "rod", ("--solver=dynamic", "--frames")),
            ("clamp-speed-with-static", "rod", ("--clamp-speed=0.001",)),
            ("stations-with-simulate", "plate", ("--stations=5",)),
            ("branches-and-no-branches", "rod", ("--branches",)),
    ):
        cases.append(Case(f"ddg-simulate-incompatible-{label}", "ddg", ddg_simulate(model, *extra), "incompatible"))
    # curvatures: scene, sizes, shear list, output on every model
    for model in ("rod", "plate", "ribbon"):
        options = ("--width-ratio", "--compression-ratio", "--slenderness", "--resolution", "--shear-ratios", "--out")
        cases += _cases_for(f"ddg-curvatures-{model}", "ddg", DDG_CURVATURES[model], options,
                            {"--resolution": (BELOW_MINIMUM[model],)})
    many = ",".join(f"{i / 20000:.5f}" for i in range(10001))  # 10001 distinct dW/L in [0, 0.5]
    for model in ("rod", "plate", "ribbon"):
        cases.append(Case(f"ddg-curvatures-{model}-shear-ratios-10001-values", "ddg",
                          DDG_CURVATURES[model] + (f"--shear-ratios={many}",), "--shear-ratios"))
    widths = ",".join(f"{0.05 + i / 40000:.6f}" for i in range(10001))  # 10001 plate runs
    cases.append(Case("ddg-centerline-error-width-ratios-10001-values", "ddg",
                      DDG_CENTERLINE_ERROR + (f"--width-ratios={widths}",), "--width-ratios"))
    cases += _cases_for("ddg-curvatures-plate", "ddg", DDG_CURVATURES["plate"], ("--stations",))
    cases += _cases_for("ddg-curvatures-ribbon", "ddg", DDG_CURVATURES["ribbon"], ("--zeta",))
    for label, model, extra in (("zeta-with-rod", "rod", "--zeta=1"), ("zeta-with-plate", "plate", "--zeta=1"),
                                ("stations-with-rod", "rod", "--stations=5"),
                                ("stations-with-ribbon", "ribbon", "--stations=5"),
                                ("ribbon-init-x", "ribbon", "--ribbon-init=x")):
        cases.append(Case(f"ddg-curvatures-incompatible-{label}", "ddg", DDG_CURVATURES[model] + (extra,),
                          "incompatible"))
    # centerline-error (plate triangles)
    cases += _cases_for("ddg-centerline-error", "ddg", DDG_CENTERLINE_ERROR,
                        ("--width-ratios", "--shear-ratios", "--compression-ratio", "--slenderness", "--resolution",
                         "--out"),
                        {"--resolution": (BELOW_MINIMUM["plate"],), "--shear-ratios": ("0",)})
    # unknown options, unknown subcommands, missing arguments
    for label, argv in (
            ("no-arguments", ()), ("unknown-subcommand", ("spaghetti",)),
            ("option-before-subcommand", ("--out=x", "simulate")),
            ("simulate-unknown-option", ddg_simulate("rod", "--spaghetti")),
            ("simulate-unknown-option-value", ddg_simulate("rod", "--spaghetti=1")),
            ("simulate-positional", ddg_simulate("rod", "extra")),
            ("simulate-missing-value", ddg_simulate("rod", "--resolution")),
            ("simulate-abbreviated-ambiguous", ddg_simulate("rod", "--shear=0.1")),
            ("curvatures-option-of-simulate", DDG_CURVATURES["rod"] + ("--compression-steps=2",)),
            ("centerline-error-option-of-simulate", DDG_CENTERLINE_ERROR + ("--model=rod",)),
    ):
        cases.append(Case(f"ddg-cli-{label}", "ddg", argv, "arguments"))
    return cases


def fem_bad_cases() -> list[Case]:
    cases: list[Case] = []
    options = ("--width-ratio", "--compression-ratio", "--shear-ratio", "--slenderness", "--poisson-ratio",
               "--compression-steps", "--shear-steps", "--resolution", "--across", "--perturbation", "--out")
    cases += _cases_for("fem-simulate", "fem", FEM_SIMULATE, options, {"--resolution": (BELOW_MINIMUM["fem"],)})
    for option, value in (("--material", "x"), ("--shear-sign", "0"), ("--shear-sign", "x")):
        cases.append(Case(f"fem-simulate-{option.lstrip('-')}-{value}", "fem", FEM_SIMULATE + (f"{option}={value}",),
                          option))
    cases.append(Case("fem-simulate-incompatible-dep-with-poisson-ratio", "fem",
                      FEM_SIMULATE + ("--material=dep", "--poisson-ratio=0.3"), "incompatible"))
    # convergence: its list of resolutions, its scene, its output
    for label, values in (("0", ("0", "8")), ("3", ("3", "8")), ("100000000", ("8", "100000000")),
                          ("nan", ("nan",)), ("2.5", ("2.5", "8")), ("repeated", ("8", "8"))):
        argv = ("convergence",) + FEM_SCENE + ("--resolutions",) + values + ("--quiet", "--out={out}")
        cases.append(Case(f"fem-convergence-resolutions-{label}", "fem", argv, "--resolutions"))
    cases += _cases_for("fem-convergence", "fem", FEM_CONVERGENCE, ("--width-ratio", "--compression-steps", "--out"))
    # gold
    cases.append(Case("fem-gold-only-unknown-scene", "fem", ("gold", "--only", "spaghetti", "--out={out}"), "--only"))
    for value in ("0", "-1", "3", "2.5", "100000000"):
        cases.append(Case(f"fem-gold-resolution-{value}", "fem", FEM_GOLD + (f"--resolution={value}",),
                          "--resolution"))
    cases += _cases_for("fem-gold", "fem", FEM_GOLD, ("--out",))
    # convergence-table over folders that are not runs
    for label, runs in (("missing", ("{tmp}/missing", "{tmp}/missing2")), ("empty-dir", ("{tmp}/dir", "{tmp}/dir")),
                        ("corrupt-json", ("{tmp}/run-corrupt", "{tmp}/run-corrupt")),
                        ("json-without-keys", ("{tmp}/run-keys", "{tmp}/run-keys")),
                        ("file", ("{tmp}/file.txt",)), ("dev-null", ("/dev/null",))):
        cases.append(Case(f"fem-convergence-table-runs-{label}", "fem",
                          ("convergence-table", "--runs") + runs + ("--out={out}",), "--runs"))
    # unknown options, missing arguments
    for label, argv in (
            ("no-arguments", ()), ("unknown-subcommand", ("spaghetti",)),
            ("simulate-missing-required", ("simulate",)),
            ("simulate-missing-compression-ratio", ("simulate", "--width-ratio=0.1")),
            ("simulate-unknown-option", FEM_SIMULATE + ("--spaghetti",)),
            ("simulate-option-of-ddg", FEM_SIMULATE + ("--model=plate",)),
            ("convergence-missing-out", ("convergence",) + FEM_SCENE + ("--resolutions", "8", "10")),
            ("convergence-table-missing-runs", ("convergence-table", "--out={out}")),
            ("gold-missing-out", ("gold",)),
    ):
        cases.append(Case(f"fem-cli-{label}", "fem", argv, "arguments"))
    return cases


# ----------------------------------------------------------------------------------- valid edge cases
def valid_cases() -> list[Case]:
    """Inputs at the edge of the allowed ranges that must pass validation (checked up to the solver).

    The base commands come first: every bad case is one of them with one change, so each must be
    accepted as it is (else a bad case could pass for the wrong reason)."""
    out = [Case(f"valid-base-{label}", prog, argv, "base", ACCEPT) for label, prog, argv in (
        ("ddg-simulate-rod", "ddg", ddg_simulate("rod")), ("ddg-simulate-plate", "ddg", ddg_simulate("plate")),
        ("ddg-simulate-ribbon", "ddg", ddg_simulate("ribbon")),
        ("ddg-simulate-rod-dynamic", "ddg", ddg_simulate("rod", "--solver=dynamic")),
        ("ddg-curvatures-rod", "ddg", DDG_CURVATURES["rod"]), ("ddg-curvatures-plate", "ddg", DDG_CURVATURES["plate"]),
        ("ddg-curvatures-ribbon", "ddg", DDG_CURVATURES["ribbon"]),
        ("ddg-centerline-error", "ddg", DDG_CENTERLINE_ERROR),
        ("fem-simulate", "fem", FEM_SIMULATE), ("fem-convergence", "fem", FEM_CONVERGENCE), ("fem-gold", "fem",
                                                                                             FEM_GOLD),
    )]
    for label, model, extra in (
            ("width-ratio-1", "rod", ("--width-ratio=1",)), ("width-ratio-1", "plate", ("--width-ratio=1",)),
            ("width-ratio-1", "ribbon", ("--width-ratio=1",)),
            ("shear-ratio-0", "rod", ("--shear-ratio=0",)), ("shear-ratio-0", "plate", ("--shear-ratio=0",)),
            ("resolution-7", "rod", ("--resolution=7",)), ("resolution-7", "ribbon", ("--resolution=7",)),
            ("resolution-16", "plate", ("--resolution=16",)), ("resolution-2000", "plate", ("--resolution=2000",)),
            ("resolution-100", "rod", ("--resolution=100",)),
            ("compression-steps-1", "rod", ("--compression-steps=1",)),
            ("shear-steps-1", "rod", ("--shear-steps=1",)),
            ("compression-steps-5000", "rod", ("--compression-steps=5000",)),
            ("shear-steps-5000", "rod", ("--shear-steps=5000",)),
            ("max-newton-iterations-1", "rod", ("--max-newton-iterations=1",)),
            ("poisson-ratio-0.49", "rod", ("--poisson-ratio=0.49",)),
            ("poisson-ratio-0.3", "plate", ("--poisson-ratio=0.3",)),
            ("slenderness-100", "rod", ("--slenderness=100",)),
            ("slenderness-1e4", "plate", ("--slenderness=1e4",)),
            ("young-modulus-1e6", "rod", ("--young-modulus=1e6",)),
            ("compression-ratio-0.05", "rod", ("--compression-ratio=0.05",)),
            ("compression-ratio-0.9", "rod", ("--compression-ratio=0.9",)),
            ("shear-direction-minus-branch-minus", "rod", ("--shear-direction=-1", "--branch=-")),
            ("dynamic-clamp-speed-0.02", "rod", ("--solver=dynamic", "--clamp-speed=0.02")),
            ("zeta-1", "ribbon", ("--zeta=1",)), ("ribbon-init-rod", "ribbon", ("--ribbon-init=rod",)),
            ("mesh-gmsh", "plate", ("--mesh=gmsh",)), ("frames", "plate", ("--frames",)),
            ("out-new-nested", "rod", ("--out={tmp}/new/nested/dir",)), ("out-existing-dir", "rod",
                                                                         ("--out={tmp}/dir",)),
            ("out-relative", "rod", ("--out=relative-out",)),
    ):
        out.append(Case(f"valid-ddg-simulate-{model}-{label}", "ddg", ddg_simulate(model, *extra), label, ACCEPT))
    out.append(Case("valid-ddg-simulate-rod-default-shear-ratio", "ddg",
                    DDG_SIMULATE["rod"] + ("--compression-steps=2", "--shear-steps=2", "--quiet", "--out={out}"),
                    "defaults", ACCEPT))
    for label, argv in (
            ("curvatures-plate-stations-5", DDG_CURVATURES["plate"] + ("--stations=5",)),
            ("curvatures-rod-shear-ratios-0", DDG_CURVATURES["rod"] + ("--shear-ratios=0",)),
            ("curvatures-ribbon-ribbon-init-rod", DDG_CURVATURES["ribbon"] + ("--ribbon-init=rod",)),
            ("curvatures-rod-width-ratio-1", DDG_CURVATURES["rod"] + ("--width-ratio=1",)),
            ("centerline-error-width-ratios-1", DDG_CENTERLINE_ERROR + ("--width-ratios=1",)),
    ):
        out.append(Case(f"valid-ddg-{label}", "ddg", argv, label, ACCEPT))
    for label, argv in (("simulate-resolution-4", FEM_SIMULATE + ("--resolution=4",)),
                        ("simulate-dep", FEM_SIMULATE + ("--material=dep",)),
                        ("simulate-no-out", tuple(a for a in FEM_SIMULATE if not a.startswith("--out"))),
                        ("simulate-across-2", FEM_SIMULATE + ("--across=2",)),
                        ("simulate-perturbation-1e-2", FEM_SIMULATE + ("--perturbation=1e-2",))):
        out.append(Case(f"valid-fem-{label}", "fem", argv, label, ACCEPT))
    return out


#: A handful of valid edge cases run for real (tiny scenes, about 1 s each): exit 0 (or 3, a run that
#: stops converging, which is not a refusal), never 2, never a traceback.
def run_cases() -> list[Case]:
    return [Case(f"run-ddg-simulate-{model}-{label}", "ddg", ddg_simulate(model, *extra), label, RUN)
            for model, label, extra in (
                ("rod", "base", ()), ("rod", "width-ratio-1", ("--width-ratio=1",)),
                ("rod", "shear-ratio-0", ("--shear-ratio=0",)), ("rod", "resolution-7", ("--resolution=7",)),
                ("rod", "steps-1", ("--compression-steps=1", "--shear-steps=1")),
                ("rod", "dynamic-clamp-speed-0.02", ("--solver=dynamic", "--clamp-speed=0.02",
                                                     "--compression-ratio=0.25")),
                ("ribbon", "resolution-7", ("--resolution=7",)),
                ("plate", "resolution-16", ("--resolution=16",)))]


#: Bad inputs also run as `python -m ddg|fem_reference` in a subprocess: real exit code, nothing printed
#: but the one error line (no traceback). The fem_reference ones import dolfinx (a few seconds each).
def subprocess_cases() -> list[Case]:
    ddg_cases = (
        ("resolution-100000000", ddg_simulate("rod", "--resolution=100000000")),
        ("out-dev-null", ddg_simulate("rod", "--out=/dev/null")),
        ("width-ratio-nan", ddg_simulate("rod", "--width-ratio=nan")),
        ("unknown-option", ddg_simulate("rod", "--spaghetti")),
        ("dynamic-clamp-speed-1e-9", ddg_simulate("rod", "--solver=dynamic", "--clamp-speed=1e-9")),
        ("compression-steps-100000000", ddg_simulate("rod", "--compression-steps=100000000")),
        ("plate-mesh-empty-file", ddg_simulate("plate", "--mesh={tmp}/empty.msh")),
        ("curvatures-plate-stations-100000000", DDG_CURVATURES["plate"] + ("--stations=100000000",)),
        ("centerline-error-width-ratios-abc", DDG_CENTERLINE_ERROR + ("--width-ratios=abc",)),
        ("no-arguments", ()),
    )
    fem_cases = (
        ("simulate-perturbation-nan", FEM_SIMULATE + ("--perturbation=nan",)),
        ("simulate-resolution-100000000", FEM_SIMULATE + ("--resolution=100000000",)),
        ("convergence-table-runs-missing", ("convergence-table", "--runs", "{tmp}/missing", "--out={out}")),
    )
    validation_cases = (   # issue 47 item 3: python -m validation[.module], the real program
        ("validation", "score-unknown-option", SCORE + ("--spaghetti",)),
        ("validation", "score-results-fifo", ("score", "{tmp}/fifo", "--out={out}")),
        ("validation.error_map", "only-spaghetti", ERROR_MAP + ("--only=spaghetti",)),
    )
    return ([Case(f"subprocess-ddg-{label}", "ddg", argv, label) for label, argv in ddg_cases]
            + [Case(f"subprocess-fem-{label}", "fem", argv, label) for label, argv in fem_cases]
            + [Case(f"subprocess-{prog}-{label}", prog, argv, label) for prog, label, argv in validation_cases])


# ----------------------------------------------------------------------------------- API cases
_DEFAULT = object()


def _simulate(tmp, strip=_DEFAULT, protocol=_DEFAULT, **kwargs):
    """ddg.simulate on a tiny rod scene, with the given pieces replaced."""
    import ddg

    if strip is _DEFAULT:
        strip = ddg.Strip.from_ratios(0.05, 0.5)
    if protocol is _DEFAULT:
        protocol = ddg.LoadingProtocol(0.5, 0.05, compression_steps=2, shear_steps=2)
    kwargs.setdefault("out", str(tmp / "out"))
    kwargs.setdefault("resolution", 20)
    kwargs.setdefault("thresholds", False)
    kwargs.setdefault("branches", False)
    return ddg.simulate(strip, protocol, **kwargs)


def _strip(**kwargs):
    def call(tmp):
        import ddg

        base = {"length": 0.15, "width": 0.0075, "thickness": 0.127e-3}
        _simulate(tmp, strip=ddg.Strip(**{**base, **kwargs}))
    return call


def _from_ratios(**kwargs):
    def call(tmp):
        import ddg

        base = {"width_ratio": 0.05, "compression_ratio": 0.5}
        _simulate(tmp, strip=ddg.Strip.from_ratios(**{**base, **kwargs}))
    return call


def _protocol(**kwargs):
    def call(tmp):
        import ddg

        base = {"compression_ratio": 0.5, "shear_ratio": 0.05, "compression_steps": 2, "shear_steps": 2}
        _simulate(tmp, protocol=ddg.LoadingProtocol(**{**base, **kwargs}))
    return call


def _newton(**kwargs):
    def call(tmp):
        import ddg

        _simulate(tmp, options=ddg.ContinuationOptions(newton=ddg.NewtonOptions(**kwargs)))
    return call


def _continuation(**kwargs):
    def call(tmp):
        import ddg

        _simulate(tmp, options=ddg.ContinuationOptions(**kwargs))
    return call


def _call(**kwargs):
    def call(tmp):
        resolved = {k: (v(tmp) if callable(v) else v) for k, v in kwargs.items()}
        _simulate(tmp, **resolved)
    return call


def _dynamic(**kwargs):
    def call(tmp):
        from ddg.solve.dynamics import DynamicOptions

        _simulate(tmp, solver="dynamic", dynamic_options=DynamicOptions(**kwargs))
    return call


def _mutated(kind: str, name: str, value):
    """Build a valid options object, then set one field to a bad value (the dataclasses are mutable)."""
    def call(tmp):
        import ddg
        from ddg.solve.dynamics import DynamicOptions

        if kind == "dynamic":
            options = DynamicOptions()
            setattr(options, name, value)
            _simulate(tmp, solver="dynamic", dynamic_options=options)
            return
        options = ddg.ContinuationOptions()
        setattr(options.newton if kind == "newton" else options, name, value)
        _simulate(tmp, options=options)
    return call


NAN, INF = math.nan, math.inf


def _api_table() -> list[tuple[str, str, Callable]]:
    """(id, object, call) of the bad API inputs."""
    rows: list[tuple[str, str, Callable]] = []

    def add(obj, label, call):
        rows.append((f"api-{obj}-{label}", obj, call))

    # Strip: float range (1e300, 1e-300), non-finite, bools
    add("Strip", "length-1e300", _strip(length=1e300, width=0.01, thickness=1e-4))
    add("Strip", "length-1e300-scaled", _strip(length=1e300, width=5e298, thickness=1e297))
    add("Strip", "length-1e-300-scaled", _strip(length=1e-300, width=5e-302, thickness=1e-304))
    add("Strip", "thickness-1e-300", _strip(thickness=1e-300))
    add("Strip", "width-1e-300", _strip(width=1e-300, thickness=1e-301))
    for value in (NAN, INF, -1.0, 0.0, True, None, "abc"):
        add("Strip", f"length-{value!r}", _strip(length=value))
    for value in (5e-324, 1e-300, 1e300, NAN, INF, 0.0, True):
        add("Strip", f"young_modulus-{value!r}", _strip(young_modulus=value))
    for value in (0.5, -0.1, NAN, False, True):
        add("Strip", f"poisson_ratio-{value!r}", _strip(poisson_ratio=value))
    for value in (NAN, 0.0, -1.0):
        add("Strip", f"density-{value!r}", _strip(density=value))
    # Strip.from_ratios
    for value in (True, False, NAN, None, 1e-300, 1.5, "abc"):
        add("Strip.from_ratios", f"width_ratio-{value!r}", _from_ratios(width_ratio=value))
    for value in (True, 0.999999, 1.0, 0.0, NAN):
        add("Strip.from_ratios", f"compression_ratio-{value!r}", _from_ratios(compression_ratio=value))
    for value in (True, 1e12, 1e300, 5e-324, 0.0, NAN, INF):
        add("Strip.from_ratios", f"slenderness-{value!r}", _from_ratios(slenderness=value))
    # LoadingProtocol
    for value in (10**6, 5001, 0, -1, 2.5, True, None, NAN):
        add("LoadingProtocol", f"compression_steps-{value!r}", _protocol(compression_steps=value))
    for value in (10**6, 0, True):
        add("LoadingProtocol", f"shear_steps-{value!r}", _protocol(shear_steps=value))
    for value in (NAN, True, 0.0, 1.0):
        add("LoadingProtocol", f"compression_ratio-{value!r}", _protocol(compression_ratio=value))
    for value in (NAN, -0.1, "abc", 1e300, 0.9, True):
        add("LoadingProtocol", f"shear_ratio-{value!r}", _protocol(shear_ratio=value))
    for value in (0, 2, True, -1.5):
        add("LoadingProtocol", f"shear_sign-{value!r}", _protocol(shear_sign=value))
    # NewtonOptions
    for value in (0, -1, 2.5, True, 10**9, None):
        add("NewtonOptions", f"max_iterations-{value!r}", _newton(max_iterations=value))
    for value in (NAN, -1.0, INF):
        add("NewtonOptions", f"residual_tol-{value!r}", _newton(residual_tol=value))
    for value in (NAN, -1.0):
        add("NewtonOptions", f"step_tol-{value!r}", _newton(step_tol=value))
    for value in (0, 10**9):
        add("NewtonOptions", f"max_line_search-{value!r}", _newton(max_line_search=value))
    for value in (0, -1):
        add("NewtonOptions", f"give_up_after-{value!r}", _newton(give_up_after=value))
    for value in (NAN, -1.0, 1.5):
        add("NewtonOptions", f"give_up_ratio-{value!r}", _newton(give_up_ratio=value))
    for value in (NAN, 0.0, -0.5, 1.5, True, "x"):
        add("NewtonOptions", f"contraction_limit-{value!r}", _newton(contraction_limit=value))
    # ContinuationOptions
    for value in (0.0, -1.0, NAN, 2.0):
        add("ContinuationOptions", f"min_substep-{value!r}", _continuation(min_substep=value))
    for value in ("x", None):
        add("ContinuationOptions", f"predictor-{value!r}", _continuation(predictor=value))
    for value in (0, 2, True):
        add("ContinuationOptions", f"branch_sign-{value!r}", _continuation(branch_sign=value))
    add("ContinuationOptions", "newton-'x'", _continuation(newton="x"))
    add("ContinuationOptions", "easy_iterations--1", _continuation(easy_iterations=-1))
    for value in (NAN, 0.0, 1e300):
        add("ContinuationOptions", f"kick-{value!r}", _continuation(kick=value))
    add("ContinuationOptions", "jump_substep-nan", _continuation(jump_substep=NAN))
    add("ContinuationOptions", "grow_after-0", _continuation(grow_after=0))
    # simulate(...)
    for value in (["rod"], "spaghetti", None, ""):
        add("simulate", f"model-{value!r}", _call(model=value))
    add("simulate", "out-123", _call(out=123))
    add("simulate", "out-empty", _call(out=""))
    add("simulate", "out-existing-file", _call(out=lambda tmp: str(tmp / "file.txt")))
    add("simulate", "out-dev-null", _call(out="/dev/null"))
    add("simulate", "out-under-file", _call(out=lambda tmp: str(tmp / "file.txt" / "sub")))
    add("simulate", "out-name-300-chars", _call(out=lambda tmp: str(tmp / ("x" * 300))))
    for value in (10**9, 10**8, 0, -1, 2.5, True, "20", NAN):
        add("simulate", f"resolution-{value!r}", _call(resolution=value))
    add("simulate", "plate-resolution-100000000", _call(model="plate", resolution=10**8))
    add("simulate", "ribbon-resolution-100000000", _call(model="ribbon", resolution=10**8))
    for value in ("x", None):
        add("simulate", f"solver-{value!r}", _call(solver=value))
    add("simulate", "mesh-with-rod", _call(mesh="gmsh"))
    add("simulate", "frames-without-out", _call(frames=True, out=None))
    add("simulate", "dynamic-with-plate", _call(solver="dynamic", model="plate", resolution=200))
    add("simulate", "options-'x'", _call(options="x"))
    add("simulate", "strip-'x'", _call(strip="x"))
    add("simulate", "protocol-'x'", _call(protocol="x"))
    add("simulate", "dynamic-strip-'x'", _call(strip="x", solver="dynamic"))
    add("simulate", "dynamic-options-'x'", _call(solver="dynamic", dynamic_options="x"))
    add("simulate", "dynamic-resolution-1e9", _call(solver="dynamic", resolution=10**9))
    add("simulate", "dynamic-compression-steps-1e6",
        lambda tmp: _simulate(tmp, solver="dynamic",
                              protocol=__import__("ddg").LoadingProtocol(0.5, 0.05, compression_steps=10**6)))
    add("simulate", "options-NewtonOptions", lambda tmp: _simulate(tmp, options=__import__("ddg").NewtonOptions()))
    add("simulate", "plate-mesh-123", _call(model="plate", resolution=200, mesh=123))
    add("simulate", "plate-mesh-empty-file", _call(model="plate", resolution=200,
                                                   mesh=lambda tmp: str(tmp / "empty.msh")))
    # numpy bools and integers too large for a float
    import numpy as np

    add("Strip.from_ratios", "width_ratio-np.True_", _from_ratios(width_ratio=np.True_))
    add("Strip.from_ratios", "slenderness-np.True_", _from_ratios(slenderness=np.True_))
    add("Strip.from_ratios", "width_ratio-10**400", _from_ratios(width_ratio=10**400))
    add("Strip.from_ratios", "slenderness-10**400", _from_ratios(slenderness=10**400))
    add("Strip", "length-np.True_", _strip(length=np.True_))
    add("LoadingProtocol", "shear_ratio-np.True_", _protocol(shear_ratio=np.True_))
    add("LoadingProtocol", "compression_steps-np.True_", _protocol(compression_steps=np.True_))
    add("simulate", "resolution-np.True_", _call(resolution=np.True_))
    add("simulate", "resolution-10**400", _call(resolution=10**400))
    add("NewtonOptions", "max_iterations-np.True_", _newton(max_iterations=np.True_))
    # option objects are mutable dataclasses: a value set after construction must be refused at the call
    add("NewtonOptions", "mutated-max_iterations-0", _mutated("newton", "max_iterations", 0))
    add("NewtonOptions", "mutated-residual_tol-nan", _mutated("newton", "residual_tol", NAN))
    add("ContinuationOptions", "mutated-min_substep-0", _mutated("continuation", "min_substep", 0.0))
    add("ContinuationOptions", "mutated-predictor-x", _mutated("continuation", "predictor", "x"))
    add("DynamicOptions", "mutated-clamp_speed-0", _mutated("dynamic", "clamp_speed", 0.0))
    add("DynamicOptions", "mutated-time_step-nan", _mutated("dynamic", "time_step", NAN))
    # DynamicOptions (ddg.solve.dynamics)
    for value in (5e-324, 1e-9, 1e300, NAN, True):
        add("DynamicOptions", f"clamp_speed-{value!r}", _dynamic(clamp_speed=value))
    for value in (5e-324, NAN, 0.0):
        add("DynamicOptions", f"time_step-{value!r}", _dynamic(time_step=value))
    add("DynamicOptions", "damping-nan", _dynamic(damping=NAN))
    add("DynamicOptions", "max_halvings--1", _dynamic(max_halvings=-1))
    return rows


def api_bad_cases() -> list[Case]:
    return [Case(case_id, "api", option=obj, call=call) for case_id, obj, call in _api_table()]


def api_valid_cases() -> list[Case]:
    import numpy as np

    rows = (
        ("Strip.from_ratios-width_ratio-1", "Strip.from_ratios", _from_ratios(width_ratio=1)),
        ("Strip.from_ratios-slenderness-100", "Strip.from_ratios", _from_ratios(slenderness=100)),
        ("Strip-paper", "Strip", _strip()),
        ("Strip-poisson_ratio-0.49", "Strip", _strip(poisson_ratio=0.49)),
        ("LoadingProtocol-shear_ratio-0", "LoadingProtocol", _protocol(shear_ratio=0.0)),
        ("LoadingProtocol-shear_ratio-None", "LoadingProtocol", _protocol(shear_ratio=None)),
        ("LoadingProtocol-steps-1", "LoadingProtocol", _protocol(compression_steps=1, shear_steps=1)),
        ("LoadingProtocol-steps-5000", "LoadingProtocol", _protocol(compression_steps=5000, shear_steps=5000)),
        ("LoadingProtocol-shear_sign--1", "LoadingProtocol", _protocol(shear_sign=-1)),
        ("NewtonOptions-max_iterations-1", "NewtonOptions", _newton(max_iterations=1)),
        ("NewtonOptions-give_up_after-None", "NewtonOptions", _newton(give_up_after=None)),
        ("ContinuationOptions-predictor-tangent", "ContinuationOptions", _continuation(predictor="tangent")),
        ("ContinuationOptions-predictor-both", "ContinuationOptions", _continuation(predictor="both")),
        ("ContinuationOptions-branch_sign--1", "ContinuationOptions", _continuation(branch_sign=-1)),
        ("simulate-resolution-7", "simulate", _call(resolution=7)),
        ("simulate-resolution-numpy-int", "simulate", _call(resolution=np.int64(20))),
        ("simulate-plate-resolution-16", "simulate", _call(model="plate", resolution=16)),
        ("simulate-ribbon-resolution-7", "simulate", _call(model="ribbon", resolution=7)),
        ("simulate-out-None", "simulate", _call(out=None)),
        ("simulate-out-pathlib", "simulate", _call(out=lambda tmp: tmp / "pathlib-out")),
        ("simulate-dynamic", "simulate", _call(solver="dynamic")),
    )
    return [Case(f"valid-api-{case_id}", "api", option=obj, expect=ACCEPT, call=call) for case_id, obj, call in rows]


# ----------------------------------------------------------------------------------- issue 47 item 3
#: Every bad input answered (issue 47 item 3): the command lines of validation and the sweep. Each case
#: must exit 2 with one `error:` line naming the value, before any work, and leave its folder as it was
#: (untouched: no --out, no runs/ or cache/, an existing --out unchanged).
#: A scheduler address where nothing listens: refused at once (connection refused), not after 10 s.
NO_SCHEDULER = "tcp://127.0.0.1:1"
SWEEP = ("sweep", "--model=rod", "--width-ratios=0.05", "--compression-ratios=0.5", "--resolutions=20",
         "--compression-steps=2", "--shear-steps=2", "--quiet", "--out={out}")
SCORE = ("score", "{tmp}/results-ok.csv", "--out={out}")
ERROR_MAP = ("--out={out}", "--only=dL0.5_W0.05", "--models=rod")
PLATE_GOLD = ("--out={out}", "--only=dL0.5_W0.5", "--levels=1", "--quiet")
REPORT = ("report", "--quick", "--quiet", "--out={out}")
#: Each validation command with its own argparse main (validation/*.py) and a bad option value of its own.
VALIDATION_MAINS = (("validation.benchmark", "--out"), ("validation.error_map", "--timeout=x"),
                    ("validation.locking", "--out"), ("validation.narrow_limit", "--slenderness=x"),
                    ("validation.paper_figures", "--out"), ("validation.plate_gold", "--levels=x"),
                    ("validation.plate_mesh_scan", "--triangles=1"), ("validation.plate_modes", "--out"),
                    ("validation.ribbon_regularisation", "--out"), ("validation.wide_check", "--rows=x"))
#: The subcommand of `python -m validation` each module of VALIDATION_MAINS is (validation/cli.py).
SUBCOMMANDS = {"validation.benchmark": "benchmark", "validation.error_map": "error-map",
               "validation.locking": "locking", "validation.narrow_limit": "narrow-limit",
               "validation.paper_figures": "paper-figures", "validation.plate_gold": "plate-gold",
               "validation.plate_mesh_scan": "plate-mesh-scan", "validation.plate_modes": "plate-modes",
               "validation.ribbon_regularisation": "ribbon-regularisation", "validation.wide_check": "wide-check"}
#: A results file for `score` (validation/score.py's format): header and one scene.
RESULTS_HEADER = ("kind,compression_ratio,width_ratio,slenderness,poisson_ratio,dW1_over_L,dW2_over_L,dW_over_L,"
                  "H_mid_over_L\n")
RESULTS_FILES = {
    "results-ok.csv": RESULTS_HEADER + "thresholds,0.5,0.05,1181.1,0,0.35,0.47,,\n",
    "results-1e308.csv": RESULTS_HEADER + "thresholds,0.5,0.05,1181.1,0,1e308,1.7e308,,\n",
    "results-slenderness-1e308.csv": RESULTS_HEADER + "thresholds,0.5,0.05,1e308,0,0.35,0.47,,\n",
    "results-H_mid-1e308.csv": RESULTS_HEADER + "H_mid,0.5,0.05,1181.1,0,,,0.1,-1e308\n",
}


def issue47_bad_cases() -> list[Case]:
    cases: list[Case] = []

    def add(case_id, prog, argv, option, names, **extra):
        cases.append(Case(case_id, prog, tuple(argv), option, names=names, untouched=True, **extra))

    # 1. score: values near the float range (crashed in the figure after writing score.csv), a FIFO (hung),
    #    /dev/zero (read until MemoryError); and a template onto a FIFO (would be replaced by a file)
    for name, value in (("results-1e308.csv", "1e+308"), ("results-slenderness-1e308.csv", "1e+308"),
                        ("results-H_mid-1e308.csv", "-1e+308")):
        add(f"validation-score-{name.removesuffix('.csv')}", "validation",
            ("score", f"{{tmp}}/{name}", "--out={out}"), "RESULTS", value)
    add("validation-score-results-fifo", "validation", ("score", "{tmp}/fifo", "--out={out}"), "RESULTS", "fifo",
        limit_s=5.0)
    add("validation-score-results-dev-zero", "validation", ("score", "/dev/zero", "--out={out}"), "RESULTS",
        "/dev/zero", limit_s=10.0)
    add("validation-score-template-fifo", "validation", ("score", "--template={tmp}/fifo"), "--template", "fifo",
        limit_s=5.0)
    # 2. DDG_BLAS_THREADS without a bound
    for value in ("1000000000", "257"):
        add(f"ddg-simulate-rod-env-DDG_BLAS_THREADS-{value}", "ddg", ddg_simulate("rod"), "DDG_BLAS_THREADS", value,
            env=(("DDG_BLAS_THREADS", value),))
    add("ddg-sweep-env-DDG_BLAS_THREADS-1000000000", "ddg", SWEEP, "DDG_BLAS_THREADS", "1000000000",
        env=(("DDG_BLAS_THREADS", "1000000000"),))
    # 3. a scheduler that cannot be reached: refused before any folder is made; an existing --out stays as it was
    scheduler = f"--scheduler={NO_SCHEDULER}"
    for label, prog, argv in (("ddg-sweep", "ddg", SWEEP), ("fem-gold", "fem", FEM_GOLD),
                              ("validation.plate_gold", "validation.plate_gold", PLATE_GOLD),
                              ("validation.error_map", "validation.error_map", ERROR_MAP),
                              ("validation-report-quick", "validation", REPORT)):
        add(f"{label}-scheduler-refused", prog, argv + (scheduler,), "--scheduler", NO_SCHEDULER)
        existing = tuple("--out={tmp}/dir" if a == "--out={out}" else a for a in argv)
        add(f"{label}-scheduler-refused-existing-out", prog, existing + (scheduler,), "--scheduler", NO_SCHEDULER)
    # 4. the error map's own arguments
    for option, value in (("--only", "spaghetti"), ("--models", "spaghetti"), ("--timeout", "-5"), ("--timeout", "0"),
                          ("--timeout", "100000000"), ("--timeout", "2.5")):
        add(f"validation.error_map-{option.lstrip('-')}-{_label(value)}", "validation.error_map",
            ERROR_MAP + (f"{option}={value}",), option, value)
    add("validation.error_map-only-known-and-unknown", "validation.error_map",
        ERROR_MAP + ("--only", "dL0.5_W0.05", "spaghetti"), "--only", "spaghetti")
    # 5. parse errors: one line, as the ddg commands give, from every command with its own argparse main
    add("validation-score-unknown-option", "validation", SCORE + ("--spaghetti",), "arguments", "--spaghetti")
    add("validation-report-jobs-x", "validation", REPORT + ("--jobs=x",), "arguments", "'x'")
    add("validation-report-jobs-100000000", "validation", REPORT + ("--jobs=100000000",), "--jobs", "100000000")
    add("validation-unknown-subcommand", "validation", ("spaghetti",), "arguments", "spaghetti")
    for module, option in VALIDATION_MAINS:
        short = module.split(".")[1]
        add(f"{module}-unknown-option", module, ("--out={out}", "--spaghetti"), "arguments", "--spaghetti")
        if option != "--out":
            value = option.split("=")[1]
            add(f"{module}-{option.split('=')[0].lstrip('-')}-{value}", module, ("--out={out}", option), "arguments",
                f"'{value}'" if short != "plate_mesh_scan" else "--triangles")
    add("validation.narrow_limit-slenderness-5", "validation.narrow_limit", ("--out={out}", "--slenderness=5"),
        "--slenderness", "5")
    # 6. the same commands spelt as subcommands (python -m validation <command>): one bad value each, the
    #    commands without a bad value of their own given a regular file as --out
    for module, option in VALIDATION_MAINS:
        command = SUBCOMMANDS[module]
        if option == "--out":
            add(f"validation-{command}-out-file", "validation", (command, "--out={tmp}/file.txt"), "--out",
                "file.txt")
        else:
            name, value = option.split("=")
            add(f"validation-{command}-{name.lstrip('-')}-{value}", "validation", (command, "--out={out}", option),
                "arguments", f"'{value}'" if command != "plate-mesh-scan" else "--triangles")
    add("validation-error-map-only-spaghetti", "validation", ("error-map",) + ERROR_MAP + ("--only=spaghetti",),
        "--only", "spaghetti")
    add("validation-narrow-limit-slenderness-5", "validation", ("narrow-limit", "--out={out}", "--slenderness=5"),
        "--slenderness", "5")
    return cases


def issue47_valid_cases() -> list[Case]:
    """The base commands of issue47_bad_cases, accepted up to their work (a tripwire); DDG_BLAS_THREADS at
    its bound."""
    cases = [Case(f"valid-{label}", prog, argv, "base", ACCEPT) for label, prog, argv in (
        ("ddg-sweep", "ddg", SWEEP), ("validation-score", "validation", SCORE),
        ("validation.error_map", "validation.error_map", ERROR_MAP),
        ("validation.plate_gold", "validation.plate_gold", PLATE_GOLD), ("validation-report", "validation", REPORT),
        ("validation-error-map", "validation", ("error-map",) + ERROR_MAP),
        ("validation-plate-gold", "validation", ("plate-gold",) + PLATE_GOLD))]
    cases.append(Case("valid-ddg-simulate-rod-env-DDG_BLAS_THREADS-256", "ddg", ddg_simulate("rod"),
                      "DDG_BLAS_THREADS", ACCEPT, env=(("DDG_BLAS_THREADS", "256"),)))
    return cases


def _sweep(**kwargs):
    def call(tmp):
        from ddg.sweep import run_sweep

        run_sweep(["rod"], width_ratios=[0.05], compression_ratios=[0.5], resolutions=[20], compression_steps=2,
                  shear_steps=2, out=str(tmp / "out"), **kwargs)
    return call


def all_in_process_cases() -> list[Case]:
    cases = ddg_bad_cases() + fem_bad_cases() + api_bad_cases() + valid_cases() + api_valid_cases()
    cases += issue47_bad_cases() + issue47_valid_cases()
    cases += [Case("api-run_sweep-scheduler-refused", "api", option="run_sweep", call=_sweep(scheduler=NO_SCHEDULER),
                   names=NO_SCHEDULER, untouched=True),
              Case("valid-api-run_sweep", "api", option="run_sweep", expect=ACCEPT, call=_sweep())]
    ids = [c.id for c in cases]
    duplicates = sorted({i for i in ids if ids.count(i) > 1})
    assert not duplicates, f"duplicate case ids: {duplicates}"
    return cases


# ----------------------------------------------------------------------------------- the report
def report(record_path: str) -> str:
    """The failing cases of a DDG_FUZZ_RECORD file grouped by cause (case id, exit code, first
    line of stderr or the exception), then the counts and the slowest cases."""
    import json
    from collections import defaultdict

    entries = {}
    for line in open(record_path):
        if line.strip():
            entry = json.loads(line)
            entries[entry["id"]] = entry  # the last run of a case wins
    rows = list(entries.values())
    failing = [e for e in rows if not e["ok"]]
    groups = defaultdict(list)
    for e in failing:
        groups[e["cause"]].append(e)
    kinds = defaultdict(int)
    for e in rows:
        kinds[("subprocess" if e["id"].startswith("subprocess-") else e["expect"])] += 1
    lines = [f"fuzz cases recorded: {len(rows)} ({', '.join(f'{k} {v}' for k, v in sorted(kinds.items()))}); "
             f"failing: {len(failing)} in {len(groups)} causes", ""]
    for cause, members in sorted(groups.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        lines.append(f"== {cause} ({len(members)})")
        for e in sorted(members, key=lambda e: e["id"]):
            text = e["detail"] if e["detail"] and e["detail"] != e["stderr"] else e["stderr"]
            if e["stderr"] and e["detail"] and e["detail"] != e["stderr"]:
                text = f"{e['detail']} || stderr: {e['stderr']}"
            lines.append(f"  {e['id']}  exit={e['code']}  {text[:220]}")
        lines.append("")
    slow = sorted((e for e in rows if e["seconds"] > 1.0 and not e["id"].startswith(("run-", "subprocess-"))),
                  key=lambda e: -e["seconds"])
    lines.append(f"in-process cases slower than 1 s: {len(slow)}")
    lines += [f"  {e['id']}  {e['seconds']:.2f} s" for e in slow[:20]]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import sys

    if len(sys.argv) != 3 or sys.argv[1] != "report":
        sys.exit("usage: python tests/fuzz_cases.py report RECORD.jsonl")
    sys.stdout.write(report(sys.argv[2]))


@contextlib.contextmanager
def at_most(seconds: float, error: type = TimeoutError):
    """SIGALRM after `seconds` raises `error`: a call that blocks (a read from a FIFO) fails the test
    instead of hanging it."""
    def alarm(signum, frame):
        raise error(f"still running after {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
