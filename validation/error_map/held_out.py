"""The held-out check of ddg.advise's prediction on the error map: each held-out scene (never used
by the prediction) and, leave-one-out, each fitting scene predicted from the other fitting scenes,
every prediction compared with what the scene measured.

Tolerances of the README's tables and of the check: TOLERANCES (units of L). The held-out scenes
of the rules before v3 (HELD_OUT_FIRST, checked with rule v1; HELD_OUT_SECOND, referenced after
rule v2 was fixed on the fitting scenes alone) fit the prediction from rule v3 on; rule v3's own
held-out scenes are fem_reference.gold.HELD_OUT_SCENES (role "held-out" in the rows).
"""
from __future__ import annotations

from ddg.advise import (NOT_RUN, QUANTITIES, RULE_V1_MARGIN, at_scene, basis_scenes, choose, compared_at,
                        cross_validated_margin, fitting, map_scenes, measured_error, parse_rows)

#: Tolerances of the README's tables and of the held-out check (units of L).
TOLERANCES = (0.01, 0.02, 0.05)
#: The held-out scenes of rules v1 and v2 (module docstring).
HELD_OUT_FIRST = ("dL0.5_W0.125_Lb1181", "dL0.25_W0.125_Lb787", "dL0.5_W0.25_Lb1181")
HELD_OUT_SECOND = ("dL0.25_W0.25_Lb787", "dL0.5_W0.1_Lb1181", "dL0.25_W0.1_Lb787")


def held_out_check(rows: list[dict], tolerance: float = 0.01, quantities=QUANTITIES, rule: str = "v3") -> list[dict]:
    """Check of ddg.advise's prediction on scenes it did not use: each held-out scene (role
    "held-out": never in the fitting set) and, leave-one-out, each fitting scene S with S removed
    from the fitting set. If the fitting scenes bracket it, every candidate predicted there (the
    plates at the rows measured at S too) is compared on each of `quantities` with its measured error
    |q - reference| at S (ddg.advise.measured_error; it holds where measured <= predicted), and
    advise's choice at `tolerance` is recorded: its verdict, predicted error and cost, and, where S
    has a row of it, its measured error and wall time. One dict per scene; scenes not bracketed without themselves say
    so. `rule` "v3": the cross-validated margin measured on the fitting scenes that remain (for a
    fitting scene S, nested: without S); "v1": margin 1."""
    parsed = load_rows(rows)
    fit = fitting(parsed)
    runnable = {r["model"] for r in parsed if r["model"] not in NOT_RUN}
    out = []
    for scene in map_scenes(parsed):
        same = [r for r in parsed if at_scene(r, scene)]
        role = "held-out" if same and same[0].get("role") == "held-out" else "fit"
        reduced = [r for r in fit if not at_scene(r, scene)]
        basis, why = basis_scenes(reduced, scene)
        entry = {"scene": scene.name, "role": role, "held_out": bool(basis), "why": why,
                 "basis": [s.name for s in basis], "compared": 0, "held": 0, "violations": [], "choice": None,
                 "choice_within": None, "choice_predicted": None, "choice_predicted_wall": None,
                 "choice_measured": None, "choice_measured_wall": None, "choice_holds": None}
        if not basis:
            out.append(entry)
            continue
        margin = RULE_V1_MARGIN if rule == "v1" else cross_validated_margin(reduced, runnable)
        entry["margin"] = margin.value
        for p, q, predicted, measured in compared_at(reduced + same, scene, basis, runnable, margin.value,
                                                     quantities):
            entry["compared"] += 1
            if measured <= predicted + 1e-12:
                entry["held"] += 1
            else:
                entry["violations"].append(f"{p.model} {p.label} {q}: measured {measured:.4f} > predicted "
                                           f"{predicted:.4f}")
        choice = choose(scene.width_ratio, scene.compression_ratio, scene.slenderness, tolerance, quantities,
                        rows=reduced, runnable=runnable, margin=margin)
        judged = [q for q in quantities if q not in choice.unknown]
        entry.update(choice=f"{choice.model} {choice.label}", choice_within=choice.within,
                     choice_predicted=choice.worst(), choice_predicted_wall=choice.wall_time_s,
                     choice_unknown=sorted(choice.unknown))
        mine = [r for r in same if r["model"] == choice.model and r["resolution_label"] == choice.label]
        if mine:
            entry["choice_measured_wall"] = mine[-1].get("wall_time_s")
            measured = [measured_error(mine[-1], q) for q in judged]
            if judged and None not in measured:
                entry["choice_measured"] = max(measured)
                entry["choice_holds"] = bool(max(measured) <= tolerance) if choice.within else None
        out.append(entry)
    return out


def held_out_targets(entries: list[dict], tolerance: float) -> dict:
    """The targets of the prediction on the held-out scenes of one tolerance's held_out_check: scenes
    inside the map, those with a choice predicted within the tolerance, the median wall time of those
    choices (measured where the scene has the chosen run, else predicted), and the (candidate,
    quantity) predictions that hold."""
    inside = [e for e in entries if e["role"] == "held-out" and e["held_out"]]
    within = [e for e in inside if e["choice_within"]]
    walls = sorted(e["choice_measured_wall"] if e["choice_measured_wall"] is not None else e["choice_predicted_wall"]
                   for e in within if (e["choice_measured_wall"] or e["choice_predicted_wall"]) is not None)
    median = None if not walls else (walls[len(walls) // 2] if len(walls) % 2 else
                                     0.5 * (walls[len(walls) // 2 - 1] + walls[len(walls) // 2]))
    return {"tolerance": tolerance, "held_out": sum(e["role"] == "held-out" for e in entries),
            "inside": len(inside), "within": len(within), "median_wall_s": median,
            "held": sum(e["held"] for e in inside), "compared": sum(e["compared"] for e in inside),
            "choices_measured": sum(e["choice_holds"] is not None for e in within),
            "choices_holding": sum(bool(e["choice_holds"]) for e in within)}


def load_rows(rows: list[dict]) -> list[dict]:
    """Rows of the CSV (strings) parsed as ddg.advise.load_map parses the file."""
    return parse_rows(rows)

