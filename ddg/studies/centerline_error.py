"""Fig. 10's study: the centerline approximation's error delta (Eq. 13, ddg.analysis.centerline_approx)
against L/W at each dW/L, one plate run per width along its stable path."""
from __future__ import annotations

from ..analysis.centerline_approx import (PAPER_SHEAR_RATIOS, PAPER_WIDTH_RATIOS, centerline_error_field,
                                          edge_reconstruction)
from ..geometry.strip import Strip
from ..models.names import PLATE
from ..solve.continuation import ContinuationFailure
from ..solve.state import phase_label
from .curvature_studies import states_at_shears


def centerline_error_study(width_ratios=PAPER_WIDTH_RATIOS, shear_ratios=PAPER_SHEAR_RATIOS, compression_ratio=0.5,
                           triangles: int = 800, slenderness: float | None = None, max_step: float = 0.05,
                           options=None, progress=None) -> list[dict]:
    """Fig. 10: mean and max of delta (Eq. 13) against L/W at each dW/L, one plate run per width
    along its stable path (branch switching on). A run that stops converging records NaN for the
    shears it did not reach, with the message. progress(text) is called after each (width, shear)
    state is measured (e.g. ddg.protocol.progress.ProgressBar.update)."""
    rows = []
    for ratio in width_ratios:
        strip = Strip.from_ratios(ratio, compression_ratio, slenderness)
        L = strip.length
        limit = strip.shear_limit(compression_ratio * L) / L
        wanted = [r for r in shear_ratios if r <= limit]
        done = set()
        message = ""
        try:
            for model, state in states_at_shears(PLATE, strip, compression_ratio, wanted, triangles,
                                                 max_step=max_step, options=options):
                field = centerline_error_field(model, state.q)
                edges = edge_reconstruction(model, state.q)
                shear = state.shear / L
                done.add(round(shear, 9))
                rows.append({"L_over_W": 1.0 / ratio, "W_over_L": ratio, "dW_over_L": shear,
                             "mean_error": field["mean"], "max_error": field["max"],
                             "rod_edge_mean_error": edges["rod_mean"], "ribbon_edge_mean_error": edges["ribbon_mean"],
                             "phase": phase_label(model, state.q, state.compression, state.shear),
                             "triangles": model.mesh.triangle_count, "message": ""})
                if progress is not None:
                    progress(f"W/L = {ratio:.4g}, dW/L = {shear:.3g}: mean delta {field['mean']:.2e}")
        except ContinuationFailure as exc:
            message = str(exc)
        for r in shear_ratios:
            if round(r, 9) not in done:
                rows.append({"L_over_W": 1.0 / ratio, "W_over_L": ratio, "dW_over_L": r, "mean_error": float("nan"),
                             "max_error": float("nan"), "rod_edge_mean_error": float("nan"),
                             "ribbon_edge_mean_error": float("nan"), "phase": "", "triangles": None,
                             "message": message or f"beyond the shear limit dW_max/L = {limit:.4g} (Eq. B.1)"})
    return rows
