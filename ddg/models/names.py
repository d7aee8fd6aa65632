"""The names of the models ddg offers: the vocabulary of the model registry (ddg.models.registry),
spelled here once. Code names a model by these constants; the registry says what each one is."""
from __future__ import annotations

#: The discrete elastic rod (paper section 3.1).
ROD = "rod"
#: The Sadowsky ribbon (paper Appendix A, Eq. A.5).
RIBBON = "ribbon"
#: The wide ribbons on the rod's centreline and frame (ddg.models.wide_ribbons).
SANO_WADA_RIBBON = "ribbon-sano-wada"
TRAPEZE_RIBBON = "ribbon-trapeze"
CROSS_SECTION_RIBBON = "ribbon-cross-section"
WUNDERLICH_RIBBON = "ribbon-wunderlich"
#: The paper's DDG plate (section 3.2) and the mid-edge plate.
PLATE = "plate"
MIDEDGE_PLATE = "plate-midedge"
