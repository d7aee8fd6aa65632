"""The valid edge cases of the command lines (accepted up to the solver; a handful run for real on a
tiny scene) and the bad inputs also run as a subprocess (`python -m ddg|fem_reference|validation`)."""
from __future__ import annotations

from .case import ACCEPT, RUN, Case
from .command_lines import (DDG_CENTERLINE_ERROR, DDG_CURVATURES, DDG_SIMULATE, FEM_CONVERGENCE, FEM_GOLD,
                            FEM_SIMULATE, ddg_simulate)
from .validation_commands import ERROR_MAP, SCORE


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
