"""Warnings for results that lie outside their model's or mesh's validity.

Three cases, each a line of summary.json's `warnings` (the CLI prints them, the API raises each as
a ValidityWarning):

* Width (1D models: the rod and the ribbons, which carry no width or only a width term). The
  error map (data/error_map/error_map.csv, ddg.advise) predicts each model's dW1/L error plus the
  reference's error bar on the scene; where even the model's best resolution there is predicted
  above WIDTH_TOLERANCE (0.01 L, the tolerance of "which model is enough"), or the map has no dW1
  of that model there, or the scene is wider than the map or at a dL/L or L/b it does not cover,
  the warning says so with the figures and the basis. dW1 is the quantity: it is the pitchfork
  whose width dependence is Fig. 8 (where the rod meets the tolerance: docs/findings/model_choice.md).
  A scene narrower than the map's narrowest strip is not flagged. Without a map file, no width check.
* Mesh: the recorded path went past the last state the discretisation resolves (neighbouring
  elements turning by more than RESOLVED_TURN_ANGLE_DEG, or a strain above RESOLVED_STRAIN;
  ddg.analysis.observables), with the shear where it happened; for the 1D model with its
  cross-section, past the last state its long-wavelength expansion holds (the path column
  curvature_change_per_width above LONG_WAVELENGTH_LIMIT, ddg.models.wide_ribbons).
* Thresholds: dW1 or dW2 null although the path went to its end (and the thresholds were
  sought), with why (the phases the path passed, the folds it met), unless the threshold was
  already reported unresolved.
"""
from __future__ import annotations

import warnings

from ..analysis.observables import RESOLVED_STRAIN, RESOLVED_TURN_ANGLE_DEG
from ..models import registry
from ..models.wide_ribbons import LONG_WAVELENGTH_LIMIT

#: dW1/L error + reference error bar (units of L) above which the map does not show a 1D model good enough.
WIDTH_TOLERANCE = 0.01
#: The models without a resolved width (ddg.api.ROD_FAMILY).
ONE_D_MODELS = registry.names_in(registry.ROD_FAMILY)


class ValidityWarning(UserWarning):
    """A result outside its model's or mesh's validity (the text says which and why)."""


def validity_warnings(summary: dict, rows: list[dict], error_map=None) -> list[str]:
    """The warnings of a finished run (module docstring), in the order mesh, thresholds, width."""
    return mesh_warnings(summary, rows) + threshold_warnings(summary, rows) + width_warnings(summary, error_map)


def add_validity_warnings(summary: dict, rows: list[dict], error_map=None) -> None:
    """validity_warnings appended to summary["warnings"] (each once)."""
    found = summary.setdefault("warnings", [])
    for text in validity_warnings(summary, rows, error_map):
        if text not in found:
            found.append(text)


def raise_warnings(summary: dict, stacklevel: int = 3) -> None:
    """Each line of summary["warnings"] as a ValidityWarning (the API's way of saying them)."""
    for text in summary.get("warnings") or ():
        warnings.warn(text, ValidityWarning, stacklevel=stacklevel)


def _shear_rows(rows):
    return [r for r in rows if r.get("stage") == "shear"]


def mesh_warnings(summary: dict, rows: list[dict]) -> list[str]:
    """The path went past the discretisation's last resolved state: where, and by how much."""
    shear = _shear_rows(rows)
    if not shear:
        return []
    model = summary.get("model", "model")
    out = []
    turned = next((r for r in shear if (r.get("max_turn_angle_deg") or 0.0) > RESOLVED_TURN_ANGLE_DEG), None)
    if turned is not None:
        worst = max((r.get("max_turn_angle_deg") or 0.0) for r in shear)
        resolved = summary.get("resolved_up_to_dW_over_L")
        upto = "no shear state" if resolved is None else f"dW/L <= {resolved:.4f}"
        out.append(f"the {model}'s discretisation stops resolving the shape at dW/L = {turned['dW_over_L']:.4f} "
                   f"(neighbouring elements turn by {turned['max_turn_angle_deg']:.0f} deg > "
                   f"{RESOLVED_TURN_ANGLE_DEG:.0f}, up to {worst:.0f} deg by dW/L = {shear[-1]['dW_over_L']:.4f}): "
                   f"only {upto} is resolved (resolved_up_to_dW_over_L); refine the mesh for the rest")
    varied = next((r for r in shear if (r.get("curvature_change_per_width") or 0.0) > LONG_WAVELENGTH_LIMIT), None)
    if varied is not None:
        worst = max((r.get("curvature_change_per_width") or 0.0) for r in shear)
        out.append(f"the {model} leaves the range of its long-wavelength expansion at dW/L = "
                   f"{varied['dW_over_L']:.4f}: the centreline's normal curvature changes by "
                   f"{varied['curvature_change_per_width']:.2g} times its largest value within one width (limit "
                   f"{LONG_WAVELENGTH_LIMIT:g}; up to {worst:.2g} by dW/L = {shear[-1]['dW_over_L']:.4f}); the states "
                   "past it are outside what the model covers; a plate model resolves them")
    strained = next((r for r in shear if (r.get("max_strain") or 0.0) > RESOLVED_STRAIN), None)
    if strained is not None:
        out.append(f"the {model} stretches by {strained['max_strain']:.3g} > {RESOLVED_STRAIN:g} at dW/L = "
                   f"{strained['dW_over_L']:.4f}: beyond the small-strain elasticity of the energies, or too few "
                   "elements for the shape")
    return out


def threshold_warnings(summary: dict, rows: list[dict]) -> list[str]:
    """dW1 / dW2 null at the end of a complete path, and why (not for a stopped run: its message
    says why already; not for a threshold reported unresolved: that has its own warning)."""
    if not summary.get("path_complete") or summary.get("threshold_wall_time_s") is None:
        return []
    shear = _shear_rows(rows)
    if not shear:
        return []
    unresolved = summary.get("unresolved_thresholds") or {}
    last = shear[-1]["dW_over_L"]
    limit = summary.get("dW_max_over_L")
    went = f"the path went to dW/L = {last:.4f}" + ("" if limit is None else f" (dW_max/L = {limit:.4f})")
    phases = list(dict.fromkeys(r.get("phase") or "" for r in shear))
    folds = summary.get("folds_dW_over_L") or []
    fold_text = f"; it passed {len(folds)} fold{'s' if len(folds) != 1 else ''}" if folds else ""
    out = []
    if summary.get("dW1_over_L") is None and "dW1_over_L" not in unresolved:
        if not any(p.startswith("US") or p.startswith("S") for p in phases):
            out.append(f"dW1 not reached: {went} and stayed on U (lambda_min never changed sign)")
        else:
            out.append(f"dW1 not located: {went} through {', '.join(p for p in phases if p)}, but the U -> US "
                       "bracket gave no sign change of lambda_min on U")
    if summary.get("dW2_over_L") is None and "dW2_over_L" not in unresolved:
        seen_s = next((r for r in shear if (r.get("phase") or "").startswith("S")), None)
        if seen_s is None:
            out.append(f"dW2 not reached: {went} and never reached S (phases {', '.join(p for p in phases if p)})"
                       f"{fold_text}")
        else:
            out.append(f"dW2 not located: the path reached S at dW/L = {seen_s['dW_over_L']:.4f}, but the US -> S "
                       f"bracket did not give the threshold{fold_text}")
    return out


def _short(reason: str, limit: int = 160) -> str:
    """The first clause of a map row's reason (they list every missing quantity), at most `limit` characters."""
    first = reason.split("; ")[0].split(" (")[0]
    return first if len(first) <= limit else first[: limit - 3] + "..."


def width_warnings(summary: dict, error_map=None) -> list[str]:
    """A 1D model on a scene where the error map says it misses the width (module docstring)."""
    model = summary.get("model")
    scene = summary.get("scene") or {}
    if model not in ONE_D_MODELS or not scene:
        return []
    from ..advise import (Scene, basis_scenes, cross_validated_margin, fitting, load_map, map_file, map_scenes,
                          predictions)
    from ..limits import InputError

    try:
        path, _ = map_file(error_map)
        rows = fitting(load_map(path))
    except InputError:
        return []
    if not rows:
        return []
    here = Scene(float(scene["compression_ratio"]), float(scene["width_ratio"]), float(scene["slenderness"]))
    where = (f"{model} at W/L = {here.width_ratio:.4g}, dL/L = {here.compression_ratio:g}, L/b = "
             f"{here.slenderness:.0f} (W^2/(bL) = {here.width_ratio**2 * here.slenderness:.3g})")
    basis, why = basis_scenes(rows, here)
    if not basis:
        same = [s for s in map_scenes(rows) if abs(s.compression_ratio - here.compression_ratio)
                <= 1e-3 * here.compression_ratio]
        if same and here.width_ratio < min(s.width_ratio for s in same):
            return []   # narrower than any map scene: the 1D models' home
        return [f"{where}: outside the error map ({why}); the error of a 1D model, which misses what the "
                "width adds, is not measured here: check against --model plate"]
    margin = cross_validated_margin(rows) if len(basis) > 1 else None
    found = [p for p in predictions(rows, basis, here, {model}, 1.0 if margin is None else margin.value)
             if p.model == model]
    names = ", ".join(s.name for s in basis)
    values = [(p.errors["dW1"], p.label) for p in found if p.errors.get("dW1") is not None]
    if not values:
        reasons = "; ".join(dict.fromkeys(_short(p.why.get("dW1", "no row")) for p in found)) or f"no row of {model}"
        return [f"{where}: the error map has no dW1 bound of this model on the scene(s) {names} ({reasons}), where "
                "the shell has a dW1: its width error is not measured here; use --model plate or --model auto "
                "--tolerance"]
    best, label = min(values)
    if best <= WIDTH_TOLERANCE:
        return []
    basis_text = names if margin is None else f"{names}, times the {margin.text()}"
    return [f"{where}: the error map predicts its dW1/L off the shell's by {best:.3f} (error + reference error "
            f"bar, its best resolution {label}; from {basis_text}) > {WIDTH_TOLERANCE:g}: the map does not show this "
            "1D model, which carries no resolved width, within the tolerance here; use --model plate or --model auto "
            "--tolerance"]
