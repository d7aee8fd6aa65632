"""The studies of the validation report and the runs each needs, for the --quick and --full
profiles (and a tiny "smoke" profile for the tests of the report machinery itself)."""
from __future__ import annotations

from dataclasses import dataclass, field

from .runs import RunSpec

WIDTHS_PAPER = (1 / 20, 1 / 12, 1 / 6, 1 / 2)      # Figs. 6, 7
WIDTHS_GOLD = (1 / 20, 1 / 12, 1 / 6, 1 / 3, 1 / 2)  # FEM gold scenes
COMPRESSIONS = (1 / 2, 1 / 4)
#: Fig. 8: L/W from 2 to 20
WIDTHS_PHASE_DIAGRAM = (1 / 20, 1 / 16, 1 / 12, 1 / 10, 1 / 8, 1 / 6, 1 / 5, 1 / 4, 1 / 3, 1 / 2.5, 1 / 2)
#: (dL/L, W/L) of the 3D snapshots (paper Fig. 1): a narrow and a wide plate; their plate runs keep frames
SNAPSHOT_SCENES = ((1 / 2, 1 / 20), (1 / 2, 1 / 6))
#: (dL/L, W/L) of the speed-accuracy chart (the FEM gold scene of the cross-model test)
SPEED_SCENE = (1 / 2, 1 / 6)
#: The 1D models with width (ddg.models.wide_ribbons), run like the rod at M = 101 on `wide_ribbon_scenes`.
WIDE_RIBBONS = ("ribbon-sano-wada", "ribbon-trapeze", "ribbon-wunderlich")


@dataclass
class Profile:
    name: str
    shear_curves: list[tuple[float, float]]          # (dL/L, W/L) scenes of the H_mid(dW) figures
    models: dict[str, int | None]                     # model -> resolution for the shear curves
    plate_scenes: list[tuple[float, float]]           # scenes the plate runs on (it is the costly one)
    ribbon_scenes: list[tuple[float, float]]
    phase_widths: tuple[float, ...]                   # thresholds vs W/L (plate)
    convergence: dict[str, tuple[int, ...]]           # model -> resolutions (scene SPEED_SCENE / narrow)
    speed: dict[str, tuple[int, ...]]                 # model -> resolutions on SPEED_SCENE
    poisson: tuple[float, ...] = (0.0, 0.25, 0.49)
    shear_steps: int = 120
    wide_ribbon_scenes: list[tuple[float, float]] = field(default_factory=list)
    extra: dict = field(default_factory=dict)


def quick() -> Profile:
    """A few minutes on 2 cores: the rod and the plate on every scene of Figs. 6 and 7."""
    return Profile(
        name="quick",
        shear_curves=[(c, w) for c in COMPRESSIONS for w in WIDTHS_PAPER],
        # the plate at its default 2000 triangles: at 1000 its W/L = 1/6 strip never reaches S
        # (US with H_mid/L ~ 0.03-0.06 to dW_max), against S from dW/L = 0.443 at 2000
        models={"rod": 100, "plate": 2000, "ribbon": 101, **{m: 101 for m in WIDE_RIBBONS}},
        plate_scenes=[(c, w) for c in COMPRESSIONS for w in WIDTHS_PAPER],
        ribbon_scenes=[(1 / 2, 1 / 20)],
        phase_widths=(),
        convergence={"rod": (50, 100, 200)},
        speed={"rod": (50, 100, 200), "plate": (500, 1000, 2000)},
        shear_steps=60,
        wide_ribbon_scenes=[(1 / 2, 1 / 20), (1 / 2, 1 / 6)],
    )


def full() -> Profile:
    """Every study (about 1-2 hours on 2 cores)."""
    return Profile(
        name="full",
        shear_curves=[(c, w) for c in COMPRESSIONS for w in WIDTHS_GOLD],
        models={"rod": 100, "plate": 2000, "ribbon": 101, **{m: 101 for m in WIDE_RIBBONS}},
        plate_scenes=[(c, w) for c in COMPRESSIONS for w in WIDTHS_GOLD],
        ribbon_scenes=[(c, 1 / 20) for c in COMPRESSIONS],
        phase_widths=WIDTHS_PHASE_DIAGRAM,
        convergence={"rod": (25, 50, 100, 200, 400), "plate": (500, 1000, 2000, 4000, 6000)},
        speed={"rod": (25, 50, 100, 200, 400), "plate": (250, 500, 1000, 2000, 4000, 6000),
               "ribbon": (51, 101, 201)},
        shear_steps=120,
        wide_ribbon_scenes=[(c, w) for c in COMPRESSIONS for w in WIDTHS_GOLD],
    )


def smoke() -> Profile:
    """Seconds: exercises every figure and table on coarse rods (tests of the report machinery)."""
    return Profile(
        name="smoke",
        shear_curves=[(1 / 2, 1 / 20), (1 / 2, 1 / 6)],
        models={"rod": 40},
        plate_scenes=[],
        ribbon_scenes=[],
        phase_widths=(),
        convergence={"rod": (30, 40)},
        speed={"rod": (30, 40)},
        poisson=(0.0, 0.49),
        shear_steps=30,
    )


PROFILES = {"quick": quick, "full": full, "smoke": smoke}


def shear_spec(model: str, compression: float, width: float, resolution, profile: Profile, **kw) -> RunSpec:
    """The run of one shear curve; the plate's runs on SNAPSHOT_SCENES at the profile's resolution
    keep their frames (one spec, shared by every study that needs that run)."""
    if (model == "plate" and (compression, width) in SNAPSHOT_SCENES and resolution == profile.models.get("plate")
            and not kw.get("poisson_ratio")):
        kw.setdefault("frames", True)
    return RunSpec(model, width, compression, resolution, None, 40, profile.shear_steps, **kw)


def specs(profile: Profile) -> dict[str, list[RunSpec]]:
    """Runs per study (a run shared by studies is computed once)."""
    out: dict[str, list[RunSpec]] = {"shear": [], "phase": [], "convergence": [], "speed": [], "poisson": []}
    for c, w in profile.shear_curves:
        out["shear"].append(shear_spec("rod", c, w, profile.models["rod"], profile))
        if "plate" in profile.models and (c, w) in profile.plate_scenes:
            out["shear"].append(shear_spec("plate", c, w, profile.models["plate"], profile))
        if "ribbon" in profile.models and (c, w) in profile.ribbon_scenes:
            out["shear"].append(shear_spec("ribbon", c, w, profile.models["ribbon"], profile))
        if (c, w) in profile.wide_ribbon_scenes:
            out["shear"] += [shear_spec(m, c, w, profile.models[m], profile) for m in WIDE_RIBBONS]
    for c in COMPRESSIONS:  # Fig. 8: the plate and the rod (cheap) at every width
        for w in profile.phase_widths:
            out["phase"].append(shear_spec("plate", c, w, profile.models["plate"], profile))
            out["phase"].append(shear_spec("rod", c, w, profile.models["rod"], profile))
    conv_scene = (1 / 2, 1 / 20)
    for model, resolutions in profile.convergence.items():
        scene = conv_scene if model == "rod" else SPEED_SCENE
        for n in resolutions:
            out["convergence"].append(shear_spec(model, *scene, n, profile))
    for model, resolutions in profile.speed.items():
        for n in resolutions:
            out["speed"].append(shear_spec(model, *SPEED_SCENE, n, profile))
    for nu in profile.poisson:
        out["poisson"].append(shear_spec("rod", 1 / 2, 1 / 20, profile.models["rod"], profile, poisson_ratio=nu))
    return out
