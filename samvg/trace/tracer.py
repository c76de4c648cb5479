"""Mask → closed cubic path: outer contour, a fixed number of corners chosen greedily by global
maximum of a turning score (SAMVG's variant of Sarfraz's corner detection), one least-squares
cubic per stretch between corners.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from skimage import measure

from samvg.errors import InputError


def mask_contour(mask: np.ndarray) -> np.ndarray:
    """Outer contour (N, 2) in pixel coordinates (x, y) of the mask's largest component.

    Pixel (row r, column c) covers [c, c+1] × [r, r+1]; the contour is the 0.5 iso-line
    through pixel centres, closed (first point not repeated), counter-clockwise on screen.
    """
    binary = np.asarray(mask, dtype=bool)
    if binary.ndim != 2:
        raise InputError(f"mask must be two-dimensional, got shape {binary.shape}")
    labels, count = ndimage.label(binary)
    if count == 0:
        raise InputError("mask is empty: nothing to trace")
    sizes = ndimage.sum_labels(binary, labels, index=np.arange(1, count + 1))
    largest = ndimage.binary_fill_holes(labels == (int(np.argmax(sizes)) + 1))
    padded = np.pad(largest.astype(np.float64), 1)
    contours = measure.find_contours(padded, 0.5)
    contour = max(contours, key=len)
    if np.allclose(contour[0], contour[-1]):
        contour = contour[:-1]
    xy = np.stack([contour[:, 1] - 0.5, contour[:, 0] - 0.5], axis=1)
    return xy


def _turning_score(contour: np.ndarray, reach: int) -> np.ndarray:
    """Angle the contour turns through at each point, measured over ``reach`` points each way."""
    forward = np.roll(contour, -reach, axis=0) - contour
    backward = contour - np.roll(contour, reach, axis=0)
    cross = backward[:, 0] * forward[:, 1] - backward[:, 1] * forward[:, 0]
    dot = np.einsum("ij,ij->i", backward, forward)
    return np.abs(np.arctan2(cross, dot))


def select_corners(contour: np.ndarray, count: int) -> np.ndarray:
    """Indices of ``count`` corners, in contour order: repeatedly the global maximum of the
    turning score, suppressing its neighbours; arclength-spaced points fill in on smooth shapes.
    """
    total = len(contour)
    if total <= count:
        return np.arange(total)
    reach = max(1, min(total // (4 * count), 4))
    score = _turning_score(contour, reach)
    suppression = max(1, total // (2 * count))
    available = np.ones(total, dtype=bool)
    chosen: list[int] = []
    significant = np.deg2rad(30.0)
    while len(chosen) < count:
        candidates = np.where(available & (score >= significant))[0]
        if len(candidates) == 0:
            break
        best = int(candidates[np.argmax(score[candidates])])
        chosen.append(best)
        offsets = (np.arange(total) - best) % total
        available &= np.minimum(offsets, total - offsets) > suppression
    if len(chosen) < count:
        chosen = _fill_by_arclength(contour, chosen, count)
    return np.sort(np.asarray(chosen, dtype=np.int64))


def _fill_by_arclength(contour: np.ndarray, chosen: list[int], count: int) -> list[int]:
    """Add points splitting the longest stretches between chosen corners at their middle."""
    steps = np.linalg.norm(np.roll(contour, -1, axis=0) - contour, axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(steps)])
    perimeter = cumulative[-1]
    corners = sorted(chosen) if chosen else [0]
    while len(corners) < count:
        lengths = [
            (cumulative[corners[(i + 1) % len(corners)]] - cumulative[c]) % perimeter or perimeter
            for i, c in enumerate(corners)
        ]
        longest = int(np.argmax(lengths))
        middle = (cumulative[corners[longest]] + lengths[longest] / 2.0) % perimeter
        index = int(np.searchsorted(cumulative, middle)) % len(contour)
        if index in corners:
            break
        corners = sorted([*corners, index])
    return corners


def _fit_cubic(stretch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Control points of the cubic through the stretch's ends that fits its points best."""
    start, end = stretch[0], stretch[-1]
    if len(stretch) <= 2:
        return start + (end - start) / 3.0, start + 2.0 * (end - start) / 3.0
    chords = np.linalg.norm(np.diff(stretch, axis=0), axis=1)
    t = np.concatenate([[0.0], np.cumsum(chords)])
    t /= t[-1] if t[-1] > 0 else 1.0
    b0, b1, b2, b3 = (1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t**2 * (1 - t), t**3
    residual = stretch - np.outer(b0, start) - np.outer(b3, end)
    design = np.stack([b1, b2], axis=1)
    solution, *_ = np.linalg.lstsq(design, residual, rcond=None)
    return solution[0], solution[1]


def trace_mask(mask: np.ndarray, num_segments: int = 5) -> np.ndarray:
    """Trace a mask into a closed cubic path of ``num_segments`` segments: (3K, 2) points."""
    if num_segments < 1:
        raise InputError(f"num_segments must be at least 1, got {num_segments}")
    contour = mask_contour(mask)
    corners = select_corners(contour, num_segments)
    while len(corners) < num_segments:  # tiny contours: repeat a corner (zero-length segment)
        corners = np.sort(np.append(corners, corners[-1]))
    points = []
    for i, first in enumerate(corners):
        last = corners[(i + 1) % len(corners)]
        if last > first:
            stretch = contour[first : last + 1]
        else:
            stretch = np.concatenate([contour[first:], contour[: last + 1]])
        c1, c2 = _fit_cubic(stretch)
        points.extend([contour[first], c1, c2])
    return np.asarray(points, dtype=np.float64)
