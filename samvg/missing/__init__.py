"""Stage 4: paths added where the optimized render still misses parts of the image."""

from samvg.missing.prompts import missing_component_map, missing_component_prompts
from samvg.missing.stage import MissingRound, MissingSettings, add_missing, missing_masks

__all__ = [
    "MissingRound",
    "MissingSettings",
    "add_missing",
    "missing_component_map",
    "missing_component_prompts",
    "missing_masks",
]
