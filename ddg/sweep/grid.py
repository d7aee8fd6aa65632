"""What a sweep runs: one run's specification (RunSpec), its content hash, and grids of them.

A run is one `ddg.simulate` call (the ribbon: `ddg.run_ribbon`, started from the flat strip) on
one scene. Its folder is named by `RunSpec.key(code_version())`: a hash of the run's inputs and
of the ddg sources, so a change of the solver invalidates every cached run and a
rerun computes only what is missing. The validation report's runs are RunSpecs too (its cache
CACHE/<key>/ is the same layout as a sweep's DIR/runs/<key>/).
"""
from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import asdict, dataclass
from pathlib import Path

from ..limits import InputError
from ..models import registry

PACKAGE = Path(__file__).resolve().parent.parent  # ddg/

MODELS = registry.NAMES

#: Modules of this package that schedule runs and present results but take no part in computing
#: one: editing them keeps every cached run (a new module is hashed until it is listed here).
ORCHESTRATION = ("sweep/cluster.py", "sweep/command.py", "sweep/run.py", "sweep/cache.py", "sweep/table.py",
                 "sweep/figure.py", "sweep/worker.py", "advise.py", "protocol/validity.py", "protocol/progress.py",
                 "cli.py", "__main__.py")   # the command line: runs go through ddg.api

#: Most runs one sweep may ask for (a rod path costs ~1 s, a 2000-triangle plate ~30-80 s).
MAX_RUNS = 10000


@dataclass(frozen=True)
class RunSpec:
    """One run: the model on the scene of `ddg.Strip.from_ratios(width_ratio, compression_ratio,
    slenderness, poisson_ratio=...)`, compressed then sheared to `shear_ratio` (None: dW_max/L)."""

    model: str                     # one of MODELS
    width_ratio: float
    compression_ratio: float
    resolution: int | None = None  # None: the model's default
    shear_ratio: float | None = None  # None: dW_max/L; 0: compression only
    compression_steps: int = 40
    shear_steps: int = 120
    poisson_ratio: float = 0.0
    slenderness: float | None = None
    thresholds: bool = True
    branches: bool = False
    frames: bool = False           # plate shapes per step (VTU) for the 3D snapshots

    @property
    def label(self) -> str:
        res = "" if self.resolution is None else f" N={self.resolution}"
        nu = f" nu={self.poisson_ratio:g}" if self.poisson_ratio else ""
        lb = "" if self.slenderness is None else f" L/b={self.slenderness:g}"
        return f"{self.model} W/L={self.width_ratio:.4g} dL/L={self.compression_ratio:.4g}{lb}{res}{nu}"

    def key(self, code: str) -> str:
        """16 hex digits of sha256 over the inputs and the code version (the cache folder's name)."""
        spec = asdict(self)
        if not spec["frames"]:  # added later: runs without frames keep their cache keys
            del spec["frames"]
        text = json.dumps({"spec": spec, "code": code}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def strip(self):
        from ..geometry.strip import Strip

        return Strip.from_ratios(self.width_ratio, self.compression_ratio, self.slenderness,
                                 poisson_ratio=self.poisson_ratio)

    def protocol(self):
        from ..geometry.strip import LoadingProtocol

        return LoadingProtocol(self.compression_ratio, self.shear_ratio, self.compression_steps, self.shear_steps)

    def check(self) -> int:
        """Validate every input as ddg.simulate would, before any work; the resolved resolution."""
        from ..api import check_resolution

        if self.model not in MODELS:
            raise InputError(f"model = {self.model!r} is not available; choose one of {', '.join(MODELS)}")
        strip = self.strip()
        self.protocol().resolved_shear_ratio(strip)
        return check_resolution(self.model, self.resolution, strip)


def code_version() -> str:
    """sha256 of the ddg package's sources (but ORCHESTRATION): a change of the solver
    invalidates the cache. Read afresh at each call: the files, not the modules loaded."""
    return _code_version(PACKAGE)


def _code_version(package: Path) -> str:
    digest = hashlib.sha256()
    skip = {package / name for name in ORCHESTRATION}
    for path in sorted(package.rglob("*.py")):
        if path in skip:
            continue
        digest.update(str(path.relative_to(package.parent)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def estimated_cost(spec: RunSpec) -> float:
    """Rough relative cost of a run, for ordering (the plate's path grows about linearly with its
    triangles, 2000 triangles ~ 20 rods of 100 nodes)."""
    if registry.MODELS[spec.model].resolves_width:
        return (spec.resolution or 2000) / 100.0
    return (spec.resolution or 100) / 100.0


def grid(models, width_ratios, compression_ratios, slendernesses=(None,), resolutions=(None,),
         compression_steps: int = 40, shear_steps: int = 120) -> list[RunSpec]:
    """Every combination as a RunSpec (thresholds located, branches not traced), each checked
    before any work: InputError naming the option and the value otherwise."""
    from ..limits import check_steps

    compression_steps = _named("--compression-steps", check_steps, "compression_steps", compression_steps)
    shear_steps = _named("--shear-steps", check_steps, "shear_steps", shear_steps)
    axes = [list(dict.fromkeys(a)) for a in (models, compression_ratios, width_ratios, slendernesses, resolutions)]
    count = 1
    for axis in axes:
        count *= len(axis)
    if count > MAX_RUNS:
        raise InputError(f"the grid has {count} runs; allowed 1 to {MAX_RUNS} (fewer values per option)")
    for model in axes[0]:
        if model not in MODELS:
            raise InputError(f"--model {model!r} is not available; choose from {', '.join(MODELS)}")
    specs = []
    for model, compression, width, slenderness, resolution in itertools.product(*axes):
        spec = RunSpec(model, width, compression, resolution, None, compression_steps, shear_steps,
                       slenderness=slenderness, thresholds=True, branches=False)
        resolved = _checked(spec)
        specs.append(RunSpec(model, width, compression, resolved, None, compression_steps, shear_steps,
                             slenderness=slenderness, thresholds=True, branches=False))
    return specs


#: The option of `python -m ddg sweep` that sets each input a check may name.
_OPTIONS = (("thickness b", "--width-ratios/--slenderness"), ("width W", "--width-ratios/--slenderness"),
            ("width_ratio", "--width-ratios"), ("compression_ratio", "--compression-ratios"),
            ("slenderness", "--slenderness"), ("resolution", "--resolutions"))


def _checked(spec: RunSpec) -> int:
    try:
        return spec.check()
    except InputError as exc:
        text = " ".join(str(exc).split())
        option = next((opt for word, opt in _OPTIONS if word in text), None)
        raise InputError(f"{option}: {text}" if option else text) from None


def _named(option: str, check, name: str, value):
    try:
        return check(name, value)
    except InputError as exc:
        raise InputError(f"{option}: {exc}") from None
