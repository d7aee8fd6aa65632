"""Issue 47 item 3, every bad input answered: the command lines of validation (`python -m validation
<command>` and the modules with a main of their own), `ddg sweep` and run_sweep, a scheduler that
cannot be reached, DDG_BLAS_THREADS; each case names the refused value and leaves its folder as it was."""
from __future__ import annotations

from .case import ACCEPT, Case
from .command_lines import FEM_GOLD, ddg_simulate, value_label


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
        add(f"validation.error_map-{option.lstrip('-')}-{value_label(value)}", "validation.error_map",
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


def issue47_api_cases() -> list[Case]:
    """run_sweep refusing a scheduler that cannot be reached, and its base call accepted."""
    return [Case("api-run_sweep-scheduler-refused", "api", option="run_sweep", call=_sweep(scheduler=NO_SCHEDULER),
                 names=NO_SCHEDULER, untouched=True),
            Case("valid-api-run_sweep", "api", option="run_sweep", expect=ACCEPT, call=_sweep())]
