"""Stage 2: tracing segmentation masks into closed cubic Bézier paths."""

from samvg.trace.tracer import mask_contour, select_corners, trace_mask

__all__ = ["mask_contour", "select_corners", "trace_mask"]
