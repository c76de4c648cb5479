"""Stage 2: tracing segmentation masks into closed cubic Bézier paths (see ``tracer``)."""

from samvg.trace.contour import find_components, mask_contour
from samvg.trace.corners import select_corners
from samvg.trace.fit import fit_cubics
from samvg.trace.tracer import (
    DEFAULT_MIN_AREA,
    TracedPath,
    trace_components,
    trace_masks,
    trace_masks_with_info,
)

__all__ = [
    "DEFAULT_MIN_AREA",
    "TracedPath",
    "find_components",
    "fit_cubics",
    "mask_contour",
    "select_corners",
    "trace_components",
    "trace_masks",
    "trace_masks_with_info",
]
