"""Small marks on flat areas, for stage 4: the dashes, dots and tiny glyphs of a texture (a
wallpaper's pattern, a field of symbols) that SAM's prompts do not segment and that no single
one of them fixes enough error to pass the filter by impact.

A mark is a connected region of at least ``min_pixels`` pixels (VTracer's speckle filter:
4 × 4 by default) whose colour differs visibly from the render while the render around it is
flat. A misplaced edge is not a mark: the render changes colour there. Regions one or two
pixels wide along the render's edges are the common false alarm, so the wrong pixels are first
opened with a 2 × 2 square, which keeps strokes two pixels wide (a path budget's last rounds
drop the opening, for a star's one-pixel arms: `samvg.missing.stage.smaller_marks`). Marks of
one colour (within ``contrast`` ΔE in CIELAB) form one group, offered to the filter as one
mask: a texture passes or fails as a whole, and each of its components becomes a path of its
own colour, traced closely and kept as traced: Adam's steps are about a pixel whatever the
gradient, which tears a two-pixel dash into a streak, so fits move only a mark's paint.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage

from samvg.imaging import error_map
from samvg.trace.stage import TraceSettings

_OPENING = np.ones((2, 2), dtype=bool)
_RING = np.ones((3, 3), dtype=bool)


@dataclass(frozen=True)
class MarkSettings:
    """What counts as a mark (working pixels)."""

    min_pixels: float = 16.0
    """Smaller regions are speckle (VTracer's ``filter_speckle`` of 4: 4 × 4 pixels)."""
    pixel_error: float = 0.15
    """A pixel is off when its error (sum over RGB of |I − I′|, in [0, 3]) reaches this."""
    flatness: float = 0.1
    """The render's largest colour range around a mark (sum over RGB of max − min)."""
    contrast: float = 10.0
    """ΔE (CIELAB) within which marks share a group's colour."""
    opening: bool = True
    """Open the off pixels with a 2 × 2 square first (drops strokes one pixel wide)."""
    max_marks: int = 1024
    """The largest marks kept; the rest wait for a later round."""
    tolerance: float = 0.75
    """Pixels: marks are traced this closely (or as the stage's tolerance, if closer): a small
    mark keeps its traced outline through every fit (`Scene.fixed`)."""

    def trace_settings(self, trace: TraceSettings) -> TraceSettings:
        """``trace`` for marks: their smallest size and, with per-path segments, the closer
        tolerance."""
        tolerance = trace.tolerance
        if tolerance is not None:
            tolerance = min(tolerance, self.tolerance)
        return replace(trace, min_pixels=self.min_pixels, tolerance=tolerance)


def mark_groups(
    target: np.ndarray, render: np.ndarray, lab: np.ndarray, settings: MarkSettings
) -> list[np.ndarray]:
    """The marks of ``target`` (float RGB) that ``render`` misses, as one boolean mask per colour
    group (``lab``: the target in CIELAB), the group of largest area first."""
    off = error_map(target, render) >= settings.pixel_error
    if settings.opening:
        off = ndimage.binary_opening(off, _OPENING)
    labels, count = ndimage.label(off)
    if count == 0:
        return []
    index = np.arange(1, count + 1)
    areas = ndimage.sum_labels(off, labels, index)
    candidates = index[areas >= settings.min_pixels]
    if len(candidates) == 0:
        return []
    flat = candidates[_render_ranges(render, labels, candidates) <= settings.flatness]
    flat = flat[np.argsort(-areas[flat - 1], kind="stable")][: settings.max_marks]
    if len(flat) == 0:
        return []
    colours = np.stack([ndimage.mean(lab[..., c], labels, flat) for c in range(3)], axis=1)
    group_of = _colour_groups(colours, settings.contrast)
    lookup = np.zeros(count + 1, dtype=np.int32)
    lookup[flat] = group_of + 1
    grouped = lookup[labels]
    masks = [grouped == group + 1 for group in range(int(group_of.max()) + 1)]
    return sorted(masks, key=lambda mask: -int(np.count_nonzero(mask)))


def _render_ranges(render: np.ndarray, labels: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Per labelled region: the render's colour range (sum over RGB of max − min) over the
    region and a one-pixel ring around it."""
    grown = ndimage.grey_dilation(labels, footprint=_RING)
    ranges = np.zeros(len(index))
    for channel in range(3):
        values = render[..., channel]
        highest = np.asarray(ndimage.maximum(values, grown, index))
        lowest = np.asarray(ndimage.minimum(values, grown, index))
        ranges += highest - lowest
    return ranges


def _colour_groups(colours: np.ndarray, contrast: float) -> np.ndarray:
    """Greedy grouping of colours (n, 3) in CIELAB, given largest mark first: each joins the
    first group whose founding colour lies within ``contrast``, or founds one."""
    founders: list[np.ndarray] = []
    group_of = np.zeros(len(colours), dtype=np.int32)
    for position, colour in enumerate(colours):
        gaps = [float(np.linalg.norm(colour - founder)) for founder in founders]
        if gaps and min(gaps) < contrast:
            group_of[position] = int(np.argmin(gaps))
        else:
            group_of[position] = len(founders)
            founders.append(colour)
    return group_of
