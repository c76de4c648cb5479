"""Stage 2: tracing segmentation masks into closed cubic Bézier paths (see ``tracer``)."""

from samvg.trace.adaptive import (
    DEFAULT_MAX_SEGMENTS,
    fit_adaptive,
    refit_outline,
    refit_outlines,
)
from samvg.trace.contour import find_components, mask_contour
from samvg.trace.corners import find_corners, select_corners
from samvg.trace.fit import fit_cubics
from samvg.trace.tracer import (
    DEFAULT_MIN_AREA,
    TracedPath,
    trace_components,
    trace_masks,
    trace_masks_with_info,
)

__all__ = [
    "DEFAULT_MAX_SEGMENTS",
    "DEFAULT_MIN_AREA",
    "TracedPath",
    "find_components",
    "find_corners",
    "fit_adaptive",
    "fit_cubics",
    "mask_contour",
    "refit_outline",
    "refit_outlines",
    "select_corners",
    "trace_components",
    "trace_masks",
    "trace_masks_with_info",
]
