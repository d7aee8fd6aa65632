"""The bad command lines of `python -m ddg` and `python -m fem_reference`: a tiny valid base command per
(program, subcommand, model) with one option overridden by a bad value (`--option=value`, appended
after the base: argparse keeps the last occurrence, and the `=` form lets values such as "-1", "-0"
or "" through as values). The bad values come from a table option -> values (BAD_VALUES) crossed
with every subcommand and model the option applies to; hand-written lists add the incompatible
combinations, unknown options, unknown subcommands and missing required arguments."""
from __future__ import annotations

from .case import Case


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


def value_label(value: str) -> str:
    if value == "":
        return "empty"
    return value.replace("/", "_").replace(" ", "_")


def _pairs(option: str):
    for value in BAD_VALUES[option]:
        yield (value if isinstance(value, tuple) else (value_label(value), value))


def _cases_for(prefix: str, prog: str, base: tuple, options, extra_values: dict | None = None) -> list[Case]:
    out = []
    for option in options:
        pairs = list(_pairs(option)) + [(value_label(v), v) for v in (extra_values or {}).get(option, ())]
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
            cases.append(Case(f"ddg-simulate-{option.lstrip('-')}-{value_label(value)}", "ddg",
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
