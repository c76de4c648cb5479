"""SAMVG stage 2 as a pipeline stage: masks in paint order → a `Scene` of traced paths."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from samvg.config import Config
from samvg.scene import RGB, Scene
from samvg.trace.adaptive import DEFAULT_MAX_SEGMENTS
from samvg.trace.tracer import trace_masks


@dataclass(frozen=True)
class TraceSettings:
    """Stage 2 in working pixels (derived once from `Config` for one canvas).

    ``segments``: cubics per path, used when ``tolerance`` is None; ``tolerance`` (pixels):
    each path gets the fewest segments (at most ``max_segments``) that fit within it."""

    segments: int
    min_pixels: float
    tolerance: float | None = None
    max_segments: int = DEFAULT_MAX_SEGMENTS

    @classmethod
    def from_config(cls, config: Config, width: int, height: int) -> TraceSettings:
        options = config.trace
        return cls(
            segments=options.segments if options.segments is not None else 5,
            min_pixels=config.segment.min_pixels(width, height),
            tolerance=options.tolerance if options.adaptive else None,
            max_segments=options.max_segments,
        )


def uncovered_background(masks: list[np.ndarray], target: np.ndarray) -> RGB:
    """The mean colour of the pixels no mask covers (all pixels when every one is covered)."""
    covered = np.zeros(target.shape[:2], dtype=bool)
    for mask in masks:
        covered |= mask
    if (~covered).any():
        mean = target[~covered].mean(axis=0)
    else:
        mean = target.reshape(-1, 3).mean(axis=0, dtype=np.float64)
    return (float(mean[0]), float(mean[1]), float(mean[2]))


def drop_transparent(masks: list[np.ndarray], alpha: np.ndarray | None) -> list[np.ndarray]:
    """The masks that lie mostly (at least half their area) where the input is opaque
    (alpha >= 0.5); all of them for an opaque input (``alpha`` None). A transparent region stays
    transparent instead of becoming a path of the colour behind it."""
    if alpha is None:
        return masks
    opaque = alpha >= 0.5
    return [mask for mask in masks if 2 * np.count_nonzero(mask & opaque) >= mask.sum()]


def trace_scene(masks: list[np.ndarray], target: np.ndarray, settings: TraceSettings) -> Scene:
    """Every component of every mask as a path filled with its mean colour (no background)."""
    return trace_masks(
        masks,
        target,
        segments_per_path=settings.segments,
        min_area=settings.min_pixels,
        tolerance=settings.tolerance,
        max_segments=settings.max_segments,
    )
