"""Mask boundaries: the connected components of a mask and the ordered outer contour of each.

Conventions: pixel (row r, column c) is the square [c, c+1] × [r, r+1]; points are (x, y).
Components are 4-connected (``scipy.ndimage.label``'s default), so pixels touching only at a
corner are separate components. The contour of a component is its *outer* boundary only (holes
are ignored, i.e. filled) and is the polygon through the midpoints of the pixel edges between the
component and everything else: the 0.5 iso-line of marching squares on the binary mask. It is
closed (first point not repeated), has one point per boundary pixel edge, and runs clockwise on
screen (positive shoelace area in x-right, y-down coordinates). The boundary is followed on a
copy of the mask padded by one background pixel, so components touching the image border get a
closed contour lying on the border (x = 0, x = W, y = 0 or y = H).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from samvg.errors import InputError
from samvg.imaging import label_components

# Directions E, S, W, N as (dx, dy) with y pointing down; turning right is d + 1 (mod 4).
_DX = np.array([1, 0, -1, 0], dtype=np.int64)
_DY = np.array([0, 1, 0, -1], dtype=np.int64)
# (row, col) offsets, from the vertex just reached, of the pixel ahead on the right (inside side)
# and ahead on the left (outside side) of the direction of travel.
_AHEAD_RIGHT = np.array([[0, 0], [0, -1], [-1, -1], [-1, 0]], dtype=np.int64)
_AHEAD_LEFT = np.array([[-1, 0], [0, 0], [0, -1], [-1, -1]], dtype=np.int64)


@njit(cache=True, nogil=True)
def _follow_boundary(
    labels: np.ndarray,
    label: int,
    row: int,
    col: int,
    capacity: int,
    dx: np.ndarray,
    dy: np.ndarray,
    ahead_right: np.ndarray,
    ahead_left: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """Edge midpoints of the outer boundary of component ``label``, from the top edge of its
    first pixel in raster order (``row``, ``col``), keeping the component on the right.

    At each lattice vertex: turn right if the pixel ahead-right is outside, turn left if both
    pixels ahead are inside, else go straight. Turning right first keeps diagonal-only contacts
    apart, matching the 4-connected labelling.
    """
    out = np.empty((capacity, 2), dtype=np.float64)
    x, y, d = col, row, 0
    n = 0
    while n < capacity:
        out[n, 0] = x + 0.5 * dx[d]
        out[n, 1] = y + 0.5 * dy[d]
        n += 1
        x += dx[d]
        y += dy[d]
        inside_right = labels[y + ahead_right[d, 0], x + ahead_right[d, 1]] == label
        inside_left = labels[y + ahead_left[d, 0], x + ahead_left[d, 1]] == label
        if not inside_right:
            d = (d + 1) % 4
        elif inside_left:
            d = (d + 3) % 4
        if x == col and y == row and d == 0:
            break
    return out[:n]


@dataclass(frozen=True)
class Components:
    """The connected components of one mask, cropped to the mask's bounding box.

    ``labels`` is the ``scipy.ndimage.label`` image of the crop padded by one background pixel
    on every side, so ``labels[i, j]`` is mask pixel (``origin[0] + i``, ``origin[1] + j``) with
    ``origin`` = (crop top - 1, crop left - 1). ``ids`` are the labels of the kept components,
    largest first; ``areas`` their pixel counts (holes not counted), ``boxes`` their bounding
    boxes as slices of ``labels`` and ``contours`` their outer contours in mask coordinates
    (see the module docstring).
    """

    labels: np.ndarray
    origin: tuple[int, int]
    ids: np.ndarray
    areas: np.ndarray
    boxes: list[tuple[slice, slice]]
    contours: list[np.ndarray]


def find_components(mask: np.ndarray, min_area: float = 1) -> Components:
    """Components of a boolean (H, W) mask with at least ``min_area`` pixels, largest first."""
    found = label_components(mask, min_area)
    labels, origin, ids = found.labels, found.origin, found.ids
    if len(ids) == 0:
        return Components(labels, origin, ids, found.areas, [], [])
    contours = []
    for label, area, (rows_slice, cols_slice) in zip(ids, found.areas, found.boxes, strict=True):
        # The top edge of the component's first pixel in raster order is on its outer boundary.
        row = rows_slice.start
        col = cols_slice.start + int(np.argmax(labels[row, cols_slice] == label))
        contour = _follow_boundary(
            labels, int(label), row, col, 4 * int(area) + 4,
            _DX, _DY, _AHEAD_RIGHT, _AHEAD_LEFT,
        )  # fmt: skip
        contour[:, 0] += origin[1]
        contour[:, 1] += origin[0]
        contours.append(contour)
    return Components(labels, origin, ids, found.areas, found.boxes, contours)


def mask_contour(mask: np.ndarray) -> np.ndarray:
    """Outer contour (N, 2) of the mask's largest component (see the module docstring)."""
    components = find_components(mask)
    if not components.contours:
        raise InputError("mask is empty: nothing to trace")
    return components.contours[0]
