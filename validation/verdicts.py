"""The report's conclusions as data: each verdict a comparison of the numbers it is stated with.

A verdict here holds its numbers and computes every word-deciding outcome from them (a level, a
count, a list of exceptions); validation/templates/sentences.j2 only words these outcomes, so a
sentence cannot conclude anything its numbers do not. tests/validation/test_verdicts.py tests each outcome
on both sides of its boundaries.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

#: Relative difference from the paper's quoted threshold above which a row is listed as a disagreement.
PAPER_DISAGREEMENT = 0.10


@dataclass(frozen=True)
class ShareOfGap:
    """How much of the plate's gap to the nu = 0 shell the material's effect on the shell could
    explain. Both are largest absolute differences, so they do not add: the wording says "may"."""
    quantity: str   # "dW1/L" or "H_mid"
    unit: str       # "" or " L"
    effect: float   # the FEM shell with the plate's material against the nu = 0 shell
    gap: float      # the plate against the nu = 0 gold shell

    @property
    def share(self) -> float:
        return self.effect / self.gap if self.gap > 0 else math.inf

    @property
    def percent(self) -> float:
        return 100 * self.effect / self.gap if self.gap > 0 else math.inf

    @property
    def level(self) -> str:
        """"no gap" (gap 0), "small" (share < 1/3), "part" (< 2/3), "most" (<= 3/2) or "all"."""
        if not self.gap > 0:
            return "no gap"
        if self.share < 1 / 3:
            return "small"
        if self.share < 2 / 3:
            return "part"
        if self.share <= 1.5:
            return "most"
        return "all"


@dataclass(frozen=True)
class OwnMaterial:
    """The plate against the shell with its own material, set against the plate against the nu = 0 shell."""
    quantity: str
    unit: str
    to_own: float
    to_gold: float

    @property
    def closer(self) -> bool:
        return self.to_own < self.to_gold


@dataclass(frozen=True)
class MeshTrend:
    """The plate's dW1/L against its triangle count, and where its distance to `reference` does
    not fall with refinement. points: (triangles, dW1/L), any order."""
    points: list[tuple[int, float]]
    reference: float
    name: str = "the FEM gold shell's"

    def __post_init__(self):
        object.__setattr__(self, "points", sorted(tuple(p) for p in self.points))

    @property
    def rises(self) -> list[tuple[int, int]]:
        """(coarser, finer) triangle counts between which the distance does not fall."""
        distance = [abs(d - self.reference) for _, d in self.points]
        return [(self.points[i][0], self.points[i + 1][0]) for i in range(len(self.points) - 1)
                if distance[i + 1] >= distance[i]]


@dataclass(frozen=True)
class MaterialCheck:
    """Is the plate/FEM gap at W/L = 1/6, dL/L = 1/2 the plate's material (the DEP's membrane
    nu = 1/3 and bending nu_b = -1/3, against the shell's nu = 0)? Largest differences, in L."""
    fem_dep_vs_nu0_dW1: float
    fem_dep_vs_nu0_curve: float
    plate_vs_fem_gold_dW1: float
    plate_vs_fem_gold_curve: float
    plate_vs_fem_dep_dW1: float
    plate_vs_fem_dep_curve: float
    fem_dep_resolution: int
    plate_triangles: int
    mesh_trend: MeshTrend | None = None

    @property
    def shares(self) -> list[ShareOfGap]:
        return [ShareOfGap("dW1/L", "", self.fem_dep_vs_nu0_dW1, self.plate_vs_fem_gold_dW1),
                ShareOfGap("H_mid", " L", self.fem_dep_vs_nu0_curve, self.plate_vs_fem_gold_curve)]

    @property
    def own(self) -> list[OwnMaterial]:
        return [OwnMaterial("dW1/L", "", self.plate_vs_fem_dep_dW1, self.plate_vs_fem_gold_dW1),
                OwnMaterial("H_mid", " L", self.plate_vs_fem_dep_curve, self.plate_vs_fem_gold_curve)]


@dataclass(frozen=True)
class PaperReading:
    """Where the paper quotes dW1 and `label`'s run has one: how often the paper's value is above
    it. The paper reads its thresholds by eye from dynamic runs; a dynamic run leaves U late after
    a supercritical pitchfork, which would put a quoted dW1 above the onset of instability."""
    label: str
    rows: list[dict] = field(default_factory=list)  # threshold-table rows with paper_dW1 and dW1_over_L

    @classmethod
    def of(cls, table: list[dict], model: str = "fem") -> PaperReading:
        rows = [r for r in table if r["model"] == model and r.get("paper_dW1") is not None
                and r.get("dW1_over_L") is not None]
        return cls("FEM" if model == "fem" else model, rows)

    @property
    def differences(self) -> list[dict]:
        """paper / ours - 1 in percent, with the scene."""
        return [{"percent": 100 * (r["paper_dW1"] / r["dW1_over_L"] - 1), "width_ratio": r["width_ratio"],
                 "compression_ratio": r["compression_ratio"]} for r in self.rows]

    @property
    def above(self) -> int:
        return sum(1 for r in self.rows if r["paper_dW1"] > r["dW1_over_L"])

    @property
    def verdict(self) -> str:
        """"no data", "all" (every quoted dW1 above ours), "none" or "some"."""
        if not self.rows:
            return "no data"
        if self.above == len(self.rows):
            return "all"
        return "some" if self.above else "none"


@dataclass(frozen=True)
class ClaimLine:
    """One claim in one line (the report's summary): its outcome and the figure that decides it.
    A single-model claim: its measured |value| against the bound. A cross-model claim: the point
    that decides its outcome (validation.claims.Agreement.deciding), its difference against the bound
    and its combined error bar against the claim's error-bar limit, and where the reference stops
    short of the compared range. claim: a row of validation.claims.evaluate."""
    claim: dict

    @property
    def key(self) -> str:
        return self.claim["claim"]

    @property
    def outcome(self) -> str:
        return self.claim.get("outcome", "holds" if self.claim["holds"] else "fails")

    @property
    def cross_model(self) -> bool:
        return self.claim.get("error_bar_limit") is not None

    @property
    def value(self) -> float | None:
        """The figure set against the bound: the deciding point's difference, or the measured value;
        None without a measured value (no data)."""
        if self.claim.get("measured") is None:
            return None
        return self.claim.get("deciding_difference") if self.cross_model else self.claim["measured"]

    @property
    def bound(self) -> float:
        return self.claim["bound"]

    @property
    def within(self) -> bool:
        return self.value is not None and self.value <= self.bound

    @property
    def error_bar(self) -> float | None:
        return self.claim.get("deciding_error_bar") if self.value is not None else None

    @property
    def limit(self) -> float | None:
        return self.claim.get("error_bar_limit")

    @property
    def decidable(self) -> bool:
        """The combined error bar is within the claim's limit (the bars can decide the claim)."""
        return self.error_bar is not None and self.error_bar <= self.limit

    @property
    def stops_short(self) -> bool:
        return bool(self.claim.get("stops_short"))


@dataclass(frozen=True)
class ClaimsVerdict:
    """All claims hold, or which do not (claims: rows of validation.claims.evaluate)."""
    claims: list[dict]

    @property
    def lines(self) -> list[ClaimLine]:
        return [ClaimLine(c) for c in self.claims]

    @property
    def held(self) -> list[dict]:
        return [c for c in self.claims if c["holds"]]

    @property
    def failing(self) -> list[dict]:
        """The claims that do not hold: they fail or are undecided."""
        return [c for c in self.claims if not c["holds"]]

    @property
    def failed(self) -> list[dict]:
        return [c for c in self.claims if c.get("outcome", "holds" if c["holds"] else "fails") == "fails"]

    @property
    def undecided(self) -> list[dict]:
        return [c for c in self.claims if c.get("outcome") == "undecided"]

    @property
    def all_hold(self) -> bool:
        return not self.failing


def paper_disagreements(table: list[dict], limit: float = PAPER_DISAGREEMENT) -> list[dict]:
    """Threshold-table entries more than `limit` (relative) from the paper's quoted dW1 or dW2:
    {model, width_ratio, compression_ratio, key, ours, paper, rel_diff, percent}, in table order."""
    out = []
    for r in table:
        for key in ("dW1", "dW2"):
            diff = r.get(f"{key}_rel_diff_vs_paper")
            if diff is not None and abs(diff) > limit:
                out.append({"model": r["model"], "width_ratio": r["width_ratio"],
                            "compression_ratio": r["compression_ratio"], "key": key, "ours": r[f"{key}_over_L"],
                            "paper": r[f"paper_{key}"], "rel_diff": diff, "percent": 100 * diff})
    return out


def unusual_outcomes(smap: list[dict]) -> list[dict]:
    """Stability-map entries whose outcome is not plain "ok"."""
    return [e for e in smap if e["outcome"] != "ok"]
