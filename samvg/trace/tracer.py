"""Masks → closed cubic paths (SAMVG stage 2): one path per connected component of each mask.

Each component's outer contour (``samvg.trace.contour``; holes filled) is cut at a fixed number
of corners (``samvg.trace.corners``) and every stretch between two corners becomes one cubic
Bézier, fitted by least squares with Newton reparameterization and pinned to the corners
(``samvg.trace.fit``). All stretches of all masks are fitted in one vectorized batch.

Public API:

* ``trace_masks(masks, image, segments_per_path=4, min_area=16) -> Scene``: the paths, filled
  with the mean colour of the image under each component, in paint order.
* ``trace_masks_with_info(...) -> (Scene, list[TracedPath])``: the same scene and, for each of
  its paths (same order), the source mask index, component area and fitting error.
* ``trace_components(mask, segments=4, min_area=16) -> list[TracedPath]``: geometry only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from samvg.errors import InputError
from samvg.imaging import to_float_rgb
from samvg.scene import FlatPaint, Scene
from samvg.trace.contour import Components, find_components
from samvg.trace.corners import select_corners
from samvg.trace.fit import fit_cubics

#: Default smallest component kept, in pixels (a 4 × 4 block): smaller specks would cost a whole
#: path of 3K control points for almost no pixels, and a few-pixel contour cannot carry K cubics.
DEFAULT_MIN_AREA = 16
#: Most contour points a stretch contributes to its cubic's fit (evenly spread along it); the
#: fitting error is measured on the same points.
MAX_FIT_POINTS = 64


@dataclass(frozen=True)
class TracedPath:
    """One traced component.

    ``points`` (3K, 2): the closed path in :class:`~samvg.scene.Scene` layout, starting at a
    corner. ``mask_index``: index of the source mask. ``area``: pixel count of the component
    (holes not counted). ``max_error`` / ``rms_error``: max and RMS distance in pixels between the
    contour points and the fitted curve (each point to its Newton-refined parameter's point).
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


def _densify(contour: np.ndarray, minimum: int) -> np.ndarray:
    """Insert evenly spaced points on every edge until the contour has ``minimum`` points."""
    if len(contour) >= minimum:
        return contour
    pieces = -(-minimum // len(contour))
    following = np.roll(contour, -1, axis=0)
    fractions = np.arange(pieces) / pieces
    dense = contour[:, None, :] + fractions[None, :, None] * (following - contour)[:, None, :]
    return dense.reshape(-1, 2)


def _stretches(contour: np.ndarray, segments: int) -> tuple[np.ndarray, np.ndarray]:
    """The contour cut at ``segments`` corners: for each stretch from a corner to the next (both
    included) the contour indices of at most ``MAX_FIT_POINTS`` points evenly spread along it,
    concatenated, and the number of points of each stretch."""
    total = len(contour)
    corners = select_corners(contour, segments)
    while len(corners) < segments:  # cannot happen after _densify; keeps K exact regardless
        corners = np.append(corners, corners[-1])
    lengths = (np.append(corners[1:], corners[0]) - corners) % total
    if segments == 1:
        lengths[:] = total
    sizes = np.clip(lengths + 1, 2, MAX_FIT_POINTS)  # a repeated corner: a point cubic
    first = np.cumsum(sizes) - sizes
    step = np.arange(int(sizes.sum())) - np.repeat(first, sizes)
    scale = np.repeat(lengths / np.maximum(sizes - 1, 1), sizes)
    indices = np.repeat(corners, sizes) + np.rint(step * scale).astype(np.int64)
    return indices % total, sizes


def _trace(
    masks: list[np.ndarray], segments: int, min_area: float
) -> tuple[list[TracedPath], list[Components]]:
    """Trace every kept component of every mask; one batched fit for all stretches."""
    found = [find_components(mask, min_area) for mask in masks]
    runs, sizes, owners, areas = [], [], [], []
    for mask_index, components in enumerate(found):
        for contour, area in zip(components.contours, components.areas, strict=True):
            contour = _densify(contour, 4 * segments)
            indices, stretch_sizes = _stretches(contour, segments)
            runs.append(contour[indices])
            sizes.append(stretch_sizes)
            owners.append(mask_index)
            areas.append(int(area))
    if not runs:
        return [], found
    offsets = np.concatenate([[0], np.cumsum(np.concatenate(sizes))])
    fits = fit_cubics(np.concatenate(runs), offsets)
    controls = fits.controls.reshape(len(runs), segments, 4, 2)
    bounds = np.concatenate([[0], np.cumsum([len(run) for run in runs])])
    traced = []
    for path, (mask_index, area) in enumerate(zip(owners, areas, strict=True)):
        distances = fits.distances[bounds[path] : bounds[path + 1]]
        traced.append(
            TracedPath(
                points=controls[path, :, :3, :].reshape(3 * segments, 2),
                mask_index=mask_index,
                area=area,
                max_error=float(distances.max()),
                rms_error=float(np.sqrt(np.mean(distances**2))),
            )
        )
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


def trace_components(
    mask: np.ndarray, segments: int = 4, min_area: float = DEFAULT_MIN_AREA
) -> list[TracedPath]:
    """Trace each connected component of a boolean (H, W) mask with at least ``min_area``
    pixels into a closed path of ``segments`` cubics, holes filled; largest component first.
    An empty mask gives an empty list. ``mask_index`` of the results is 0."""
    segments = _check_count(segments, "segments")
    min_area = _check_min_area(min_area)
    traced, _ = _trace([_as_bool_mask(mask, 0, None)], segments, min_area)
    return traced


def trace_masks_with_info(
    masks: Sequence[np.ndarray] | np.ndarray,
    image: np.ndarray,
    segments_per_path: int = 4,
    min_area: float = DEFAULT_MIN_AREA,
) -> tuple[Scene, list[TracedPath]]:
    """:func:`trace_masks`, plus one :class:`TracedPath` per path of the scene, in the same order
    (source mask index, component area, fitting error)."""
    segments = _check_count(segments_per_path, "segments_per_path")
    min_area = _check_min_area(min_area)
    rgb = _as_rgb(image)
    height, width = rgb.shape[:2]
    binary = _as_mask_list(masks, (height, width))
    traced, found = _trace(binary, segments, min_area)
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
) -> Scene:
    """Trace boolean masks (a list of (H, W) arrays or an (N, H, W) array, in paint order) over
    an RGB ``image`` (H, W, 3; uint8, or float in [0, 1]) into a :class:`~samvg.scene.Scene`
    without a background.

    Every connected component (4-connected) of every mask with at least ``min_area`` pixels
    becomes one closed path of ``segments_per_path`` cubic segments with its holes filled (masks
    painted later cover them), filled opaque with the mean image colour under the component.
    Paths follow the mask order, the components of one mask largest first; empty masks and
    masks with only smaller components add nothing. Non-boolean masks (values other than 0/1),
    masks that are not (H, W) or differ in size from the image raise :class:`InputError`.
    """
    return trace_masks_with_info(masks, image, segments_per_path, min_area)[0]
