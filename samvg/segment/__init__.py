"""Stage 1: which SAM masks become paths (automatic masks, filter by impact, re-prompts)."""

from samvg.segment.impact import ImpactCanvas, filter_by_impact, keep_all, offer_best
from samvg.segment.prompts import circular_kernel, disc_sum, uncovered_prompts
from samvg.segment.segmenter import Segmenter
from samvg.segment.select import MaskSelection, SegmentSettings, select_masks

__all__ = [
    "ImpactCanvas",
    "MaskSelection",
    "SegmentSettings",
    "Segmenter",
    "circular_kernel",
    "disc_sum",
    "filter_by_impact",
    "keep_all",
    "offer_best",
    "select_masks",
    "uncovered_prompts",
]
