"""Masks → closed cubic paths (SAMVG stage 2): one path per connected component of each mask.

Each component's outer contour (``samvg.trace.contour``; holes filled) becomes one closed path
of cubic Béziers, each pinned to the joins it runs between (``samvg.trace.fit``), all
components of all masks fitted in one vectorized batch. The segment count is either fixed
(``segments_per_path``: the contour is cut at that many corners, ``samvg.trace.outline``; the
paper's setting) or, given a ``tolerance`` in pixels, the fewest found such that the curve
stays within the tolerance of the contour, with every real corner a join
(``samvg.trace.adaptive``); paths then have different segment counts.

Public API:

* ``trace_masks(masks, image, segments_per_path=4, min_area=16, tolerance=None,
  max_segments=32) -> Scene``: the paths, filled with the mean colour of the image under each
  component, in paint order.
* ``trace_masks_with_info(...) -> (Scene, list[TracedPath])``: the same scene and, for each of
  its paths (same order), the source mask index, component area and fitting error.
* ``trace_components(mask, segments=4, min_area=16, tolerance=None, max_segments=32)
  -> list[TracedPath]``: geometry only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from samvg.errors import InputError
from samvg.imaging import to_float_rgb
from samvg.scene import FlatPaint, Scene
from samvg.trace.adaptive import (
    DEFAULT_MAX_SEGMENTS,
    check_max_segments,
    check_tolerance,
    fit_adaptive,
)
from samvg.trace.contour import Components, find_components
from samvg.trace.outline import fit_fixed

#: Default smallest component kept, in pixels (a 4 × 4 block): smaller specks would cost a whole
#: path of 3K control points for almost no pixels, and a few-pixel contour cannot carry K cubics.
DEFAULT_MIN_AREA = 16


@dataclass(frozen=True)
class TracedPath:
    """One traced component.

    ``points`` (3K, 2): the closed path in :class:`~samvg.scene.Scene` layout, starting at a
    corner; K is ``segments_per_path`` for every path, or each path's own count when a
    tolerance chose it. ``mask_index``: index of the source mask. ``area``: pixel count of the
    component (holes not counted). ``max_error`` / ``rms_error``: max and RMS distance in pixels
    between the fitted contour points and the curve (each point to its Newton-refined
    parameter's point).
    """

    points: np.ndarray
    mask_index: int
    area: int
    max_error: float
    rms_error: float


def _check_count(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _check_min_area(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"min_area must be a number of pixels, got {value!r}")
    if not np.isfinite(value) or value < 0:
        raise InputError(f"min_area must be a finite number >= 0, got {value!r}")
    return float(value)


def _as_bool_mask(mask: object, index: int, shape: tuple[int, ...] | None) -> np.ndarray:
    """``mask`` as a boolean array, checked: two-dimensional, of ``shape``, values 0/1 only."""
    array = np.asarray(mask)
    if array.ndim != 2:
        raise InputError(f"mask {index} must be two-dimensional (H, W), got shape {array.shape}")
    if shape is not None and array.shape != shape:
        raise InputError(
            f"mask {index} has shape {array.shape}, but the image is {shape[0]}x{shape[1]} "
            "(masks and image must have the same height and width)"
        )
    if array.dtype == bool:
        return array
    if array.dtype.kind not in "iuf":
        raise InputError(f"mask {index} must be boolean, got dtype {array.dtype}")
    binary = array != 0
    if not np.all(binary | (array == 0)) or not np.all(array[binary] == 1):
        bad = array[(array != 0) & (array != 1)].flat[0]
        raise InputError(
            f"mask {index} must be boolean (or only 0 and 1), but contains {bad!r}; "
            "threshold soft masks first, e.g. mask > 0.5"
        )
    return binary


def _as_mask_list(masks: object, shape: tuple[int, ...] | None) -> list[np.ndarray]:
    expected = "masks must be a list of (H, W) masks or an (N, H, W) array"
    if isinstance(masks, np.ndarray):
        if masks.ndim != 3:
            hint = "; wrap a single mask in a list" if masks.ndim == 2 else ""
            raise InputError(f"{expected}, got an array of shape {masks.shape}{hint}")
        items: Sequence[object] = list(masks)
    elif isinstance(masks, (list, tuple)):
        items = masks
    else:
        raise InputError(f"{expected}, got {type(masks).__name__}")
    return [_as_bool_mask(mask, index, shape) for index, mask in enumerate(items)]


def _as_rgb(image: object) -> np.ndarray:
    """The image as float32 (H, W, 3) in [0, 1]."""
    array = np.asarray(image)
    if array.ndim != 3 or array.shape[2] != 3 or array.shape[0] < 1 or array.shape[1] < 1:
        raise InputError(f"image must be RGB with shape (H, W, 3), got shape {array.shape}")
    if array.dtype != np.uint8 and array.dtype.kind != "f":
        raise InputError(f"image must be uint8 or float in [0, 1], got dtype {array.dtype}")
    return to_float_rgb(array)


def _trace(
    masks: list[np.ndarray], segments: int, min_area: float, tolerance: float | None, cap: int
) -> tuple[list[TracedPath], list[Components]]:
    """Trace every kept component of every mask: ``segments`` cubics each, or as few as fit
    within ``tolerance`` (at most ``cap``); one batch of fits (per round) for all of them."""
    found = [find_components(mask, min_area) for mask in masks]
    contours, owners, areas = [], [], []
    for mask_index, components in enumerate(found):
        for contour, area in zip(components.contours, components.areas, strict=True):
            contours.append(contour)
            owners.append(mask_index)
            areas.append(int(area))
    if tolerance is None:
        fits = fit_fixed(contours, segments)
    else:
        fits = fit_adaptive(contours, tolerance, cap, sharpen=True)
    traced = [
        TracedPath(fit.points, mask_index, area, fit.max_error, fit.rms_error)
        for fit, mask_index, area in zip(fits, owners, areas, strict=True)
    ]
    return traced, found


def _mean_colours(components: Components, rgb: np.ndarray) -> list[np.ndarray]:
    """Mean colour of ``rgb`` (float32 (H, W, 3)) over each kept component (its pixels only)."""
    colours = []
    top, left = components.origin
    for label, area, (rows, cols) in zip(
        components.ids, components.areas, components.boxes, strict=True
    ):
        inside = (components.labels[rows, cols] == label).astype(np.float32)
        region = rgb[top + rows.start : top + rows.stop, left + cols.start : left + cols.stop]
        total = np.tensordot(inside, region, axes=([0, 1], [0, 1]))
        colours.append(np.clip(total.astype(np.float64) / area, 0.0, 1.0))
    return colours


def _check_options(
    min_area: object, tolerance: object, max_segments: object
) -> tuple[float, float | None, int]:
    return (
        _check_min_area(min_area),
        None if tolerance is None else check_tolerance(tolerance),
        check_max_segments(max_segments),
    )


def trace_components(
    mask: np.ndarray,
    segments: int = 4,
    min_area: float = DEFAULT_MIN_AREA,
    tolerance: float | None = None,
    max_segments: int = DEFAULT_MAX_SEGMENTS,
) -> list[TracedPath]:
    """Trace each connected component of a boolean (H, W) mask with at least ``min_area``
    pixels into a closed path of ``segments`` cubics (or, given ``tolerance``, as few as fit
    within it, at most ``max_segments``; see :func:`trace_masks`), holes filled; largest
    component first. An empty mask gives an empty list. ``mask_index`` of the results is 0."""
    segments = _check_count(segments, "segments")
    min_area, tolerance, cap = _check_options(min_area, tolerance, max_segments)
    traced, _ = _trace([_as_bool_mask(mask, 0, None)], segments, min_area, tolerance, cap)
    return traced


def trace_masks_with_info(
    masks: Sequence[np.ndarray] | np.ndarray,
    image: np.ndarray,
    segments_per_path: int = 4,
    min_area: float = DEFAULT_MIN_AREA,
    tolerance: float | None = None,
    max_segments: int = DEFAULT_MAX_SEGMENTS,
) -> tuple[Scene, list[TracedPath]]:
    """:func:`trace_masks`, plus one :class:`TracedPath` per path of the scene, in the same order
    (source mask index, component area, fitting error)."""
    segments = _check_count(segments_per_path, "segments_per_path")
    min_area, tolerance, cap = _check_options(min_area, tolerance, max_segments)
    rgb = _as_rgb(image)
    height, width = rgb.shape[:2]
    binary = _as_mask_list(masks, (height, width))
    traced, found = _trace(binary, segments, min_area, tolerance, cap)
    colours = [colour for components in found for colour in _mean_colours(components, rgb)]
    paths = [
        (path.points, FlatPaint((*colour, 1.0)))
        for path, colour in zip(traced, colours, strict=True)
    ]
    return Scene.from_paths(width, height, paths), traced


def trace_masks(
    masks: Sequence[np.ndarray] | np.ndarray,
    image: np.ndarray,
    segments_per_path: int = 4,
    min_area: float = DEFAULT_MIN_AREA,
    tolerance: float | None = None,
    max_segments: int = DEFAULT_MAX_SEGMENTS,
) -> Scene:
    """Trace boolean masks (a list of (H, W) arrays or an (N, H, W) array, in paint order) over
    an RGB ``image`` (H, W, 3; uint8, or float in [0, 1]) into a :class:`~samvg.scene.Scene`
    without a background.

    Every connected component (4-connected) of every mask with at least ``min_area`` pixels
    becomes one closed path with its holes filled (masks painted later cover them), filled
    opaque with the mean image colour under the component. With ``tolerance=None`` every path
    has ``segments_per_path`` cubic segments. With a ``tolerance`` in pixels (a positive
    number, like potrace's ``opttolerance``), ``segments_per_path`` is ignored: each path gets
    the fewest segments found, from 1 to ``max_segments``, such that every fitted contour point
    is within ``tolerance`` of the curve (``TracedPath.max_error``), with every sharp corner
    (a turn of 45° or more) a join; a path that needs more keeps ``max_segments``.

    Paths follow the mask order, the components of one mask largest first; empty masks and
    masks with only smaller components add nothing. Non-boolean masks (values other than 0/1),
    masks that are not (H, W) or differ in size from the image, and bad options raise
    :class:`InputError`.
    """
    return trace_masks_with_info(
        masks, image, segments_per_path, min_area, tolerance, max_segments
    )[0]
