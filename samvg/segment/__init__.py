"""Stage 1 and the SAM half of stage 4: which masks become paths."""

from samvg.segment.components import all_components, split_components
from samvg.segment.impact import ImpactCanvas, filter_by_impact, keep_all
from samvg.segment.masks import (
    MaskSelection,
    Segmenter,
    min_component_pixels,
    missing_masks,
    select_masks,
)
from samvg.segment.prompts import (
    circular_kernel,
    error_map,
    missing_component_map,
    missing_component_prompts,
    uncovered_prompts,
)

__all__ = [
    "all_components",
    "min_component_pixels",
    "split_components",
    "ImpactCanvas",
    "MaskSelection",
    "Segmenter",
    "circular_kernel",
    "error_map",
    "filter_by_impact",
    "keep_all",
    "missing_component_map",
    "missing_component_prompts",
    "missing_masks",
    "select_masks",
    "uncovered_prompts",
]
