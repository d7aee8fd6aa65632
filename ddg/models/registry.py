"""The model registry: one table of the models ddg offers (name, class, family, default resolution,
the options each accepts, its validity indicators). The api, the command line, the sweep, the
adviser, the warm-up and validation read it; adding a model is one entry here and one class
(ddg.models.base.Model).

Families: the rod family lives on the rod's centreline and frame (resolution: the node count M;
no resolved width, so its results carry the width-validity indicator of ddg.protocol.validity),
the plates on a triangulated mid-surface (resolution: a target triangle count; their results
carry the mesh-resolution indicators).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..limits import InputError
from .midedge_plate import MidedgePlateModel
from .names import (CROSS_SECTION_RIBBON, MIDEDGE_PLATE, PLATE, RIBBON, ROD, SANO_WADA_RIBBON, TRAPEZE_RIBBON,
                    WUNDERLICH_RIBBON)
from .plate import PlateModel
from .ribbon import RibbonModel
from .rod import RodModel
from .wide_ribbons import CrossSectionRibbon, SanoWadaRibbon, TrapezeRibbon, WunderlichRibbon

#: The families.
ROD_FAMILY, PLATES = "rod family", "plates"

#: The options a model may accept beyond the strip and the resolution: ZETA the regularisation
#: length zeta (m); MESH a PlateMesh; MESH_FILE a mesh file or "gmsh"; MEMBRANE the mid-edge
#: plate's membrane formulation.
ZETA, MESH, MESH_FILE, MEMBRANE = "zeta", "mesh", "mesh file", "membrane"

#: The validity indicators a family's results carry (ddg.protocol.validity).
WIDTH_INDICATOR, MESH_INDICATORS = ("width",), ("mesh resolution", "thresholds")


@dataclass(frozen=True)
class ModelEntry:
    """One model: its name, class, family, default resolution (rod family: nodes M, not a
    multiple of 4 for the ribbons, see ddg.models.ribbon; plates: target triangles), the options
    it accepts and the validity indicators its results carry."""

    name: str
    model_class: type
    family: str
    default_resolution: int
    options: frozenset = frozenset()
    summary: str = ""

    @property
    def resolves_width(self) -> bool:
        """True for the plates (a triangulated width), False for the rod family."""
        return self.family == PLATES

    @property
    def validity_indicators(self) -> tuple[str, ...]:
        return MESH_INDICATORS if self.resolves_width else WIDTH_INDICATOR

    @property
    def resolution_name(self) -> str:
        return "target triangle count" if self.resolves_width else "node count M"

    def accepts(self, option: str) -> bool:
        return option in self.options


#: The table, in the order the command line lists the models.
MODELS: dict[str, ModelEntry] = {entry.name: entry for entry in (
    ModelEntry(ROD, RodModel, ROD_FAMILY, 100, frozenset(), "discrete elastic rod"),
    ModelEntry(PLATE, PlateModel, PLATES, 2000, frozenset({MESH, MESH_FILE}), "the paper's DDG plate"),
    ModelEntry(MIDEDGE_PLATE, MidedgePlateModel, PLATES, 2000, frozenset({MESH, MEMBRANE}), "mid-edge plate"),
    ModelEntry(RIBBON, RibbonModel, ROD_FAMILY, 101, frozenset({ZETA}), "Sadowsky ribbon"),
    ModelEntry(SANO_WADA_RIBBON, SanoWadaRibbon, ROD_FAMILY, 101, frozenset(), "Sano-Wada wide ribbon"),
    ModelEntry(TRAPEZE_RIBBON, TrapezeRibbon, ROD_FAMILY, 101, frozenset(), "trapeze wide ribbon"),
    ModelEntry(CROSS_SECTION_RIBBON, CrossSectionRibbon, ROD_FAMILY, 101, frozenset(), "cross-section ribbon"),
    ModelEntry(WUNDERLICH_RIBBON, WunderlichRibbon, ROD_FAMILY, 101, frozenset({ZETA}), "Wunderlich ribbon"),
)}

#: Every model's name, in the table's order.
NAMES = tuple(MODELS)


def names_in(family: str) -> tuple[str, ...]:
    """The names of one family's models, in the table's order."""
    return tuple(name for name, entry in MODELS.items() if entry.family == family)


def entry(name) -> ModelEntry:
    """The registry's entry of `name` (a one-line InputError naming the available models otherwise)."""
    if not isinstance(name, str) or name not in MODELS:
        raise InputError(f"model = {name!r} is not available; choose one of {sorted(MODELS)}")
    return MODELS[name]


def accepting(option: str) -> tuple[str, ...]:
    """The names of the models that accept `option`."""
    return tuple(name for name, e in MODELS.items() if e.accepts(option))
