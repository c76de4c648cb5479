"""Closed outline → closed cubic path with a fixed number of segments (the paper's setting).

An outline is a closed (N, 2) polygon: a mask contour (``samvg.trace.contour``) or any other
closed point sequence. It is cut at ``segments`` corners (``samvg.trace.corners.select_corners``)
and every stretch between two corners becomes one cubic Bézier pinned to them
(``samvg.trace.fit``), all stretches of all outlines in one batch. The stretch sampling
(``stretch_samples``) and the result type are shared with the adaptive fit
(``samvg.trace.adaptive``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from samvg.trace.corners import select_corners
from samvg.trace.fit import fit_cubics

#: Most contour points a stretch contributes to its cubic's fit (evenly spread along it); the
#: fitting error is measured on the same points.
MAX_FIT_POINTS = 64


@dataclass(frozen=True)
class OutlineFit:
    """One fitted outline: ``points`` (3K, 2) in :class:`~samvg.scene.Scene` layout, starting
    at a join (a corner when the outline has one); ``max_error`` / ``rms_error``: max and RMS
    distance in pixels between the fitted outline points and the curve."""

    points: np.ndarray
    max_error: float
    rms_error: float


def densify(contour: np.ndarray, minimum: int) -> np.ndarray:
    """Insert evenly spaced points on every edge until the contour has ``minimum`` points
    (point i moves to index i × ⌈minimum / N⌉)."""
    if len(contour) >= minimum:
        return contour
    pieces = -(-minimum // len(contour))
    following = np.roll(contour, -1, axis=0)
    fractions = np.arange(pieces) / pieces
    dense = contour[:, None, :] + fractions[None, :, None] * (following - contour)[:, None, :]
    return dense.reshape(-1, 2)


def stretch_samples(
    starts: np.ndarray, lengths: np.ndarray, totals: np.ndarray, most: int = MAX_FIT_POINTS
) -> tuple[np.ndarray, np.ndarray]:
    """The points fitted for each stretch of a closed contour: stretch j runs ``lengths[j]``
    steps forward from index ``starts[j]`` of a contour of ``totals[j]`` points (both ends
    included; a whole loop returns to its start). Returns, concatenated, the contour indices of
    at most ``most`` points evenly spread along each stretch, and each one's count."""
    sizes = np.clip(lengths + 1, 2, most)  # a zero-length stretch: a point cubic
    first = np.cumsum(sizes) - sizes
    step = np.arange(int(sizes.sum())) - np.repeat(first, sizes)
    scale = np.repeat(lengths / np.maximum(sizes - 1, 1), sizes)
    indices = np.repeat(starts, sizes) + np.rint(step * scale).astype(np.int64)
    return indices % np.repeat(totals, sizes), sizes


def _stretches(contour: np.ndarray, segments: int) -> tuple[np.ndarray, np.ndarray]:
    """The contour cut at ``segments`` corners, sampled by :func:`stretch_samples`."""
    total = len(contour)
    corners = select_corners(contour, segments)
    while len(corners) < segments:  # cannot happen after densify; keeps K exact regardless
        corners = np.append(corners, corners[-1])
    lengths = (np.append(corners[1:], corners[0]) - corners) % total
    if segments == 1:
        lengths[:] = total
    return stretch_samples(corners, lengths, np.full(segments, total))


def fit_fixed(contours: list[np.ndarray], segments: int) -> list[OutlineFit]:
    """Each closed contour as a path of exactly ``segments`` cubics; one batched fit."""
    runs, sizes = [], []
    for contour in contours:
        contour = densify(contour, 4 * segments)
        indices, stretch_sizes = _stretches(contour, segments)
        runs.append(contour[indices])
        sizes.append(stretch_sizes)
    if not runs:
        return []
    offsets = np.concatenate([[0], np.cumsum(np.concatenate(sizes))])
    fits = fit_cubics(np.concatenate(runs), offsets)
    controls = fits.controls.reshape(len(runs), segments, 4, 2)
    bounds = np.concatenate([[0], np.cumsum([len(run) for run in runs])])
    result = []
    for path in range(len(runs)):
        distances = fits.distances[bounds[path] : bounds[path + 1]]
        result.append(
            OutlineFit(
                points=controls[path, :, :3, :].reshape(3 * segments, 2),
                max_error=float(distances.max()),
                rms_error=float(np.sqrt(np.mean(distances**2))),
            )
        )
    return result
