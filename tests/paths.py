"""Straight-sided closed cubic paths for tests: each side a cubic with handles at its thirds."""

import numpy as np


def polygon(corners: np.ndarray) -> np.ndarray:
    """The (3K, 2) control points of the closed polygon through ``corners`` (K, 2)."""
    corners = np.asarray(corners, dtype=np.float64)
    following = np.roll(corners, -1, axis=0)
    points = np.empty((3 * len(corners), 2))
    points[0::3] = corners
    points[1::3] = corners + (following - corners) / 3
    points[2::3] = corners + 2 * (following - corners) / 3
    return points


def square(x: float, y: float, size: float) -> np.ndarray:
    return polygon([[x, y], [x + size, y], [x + size, y + size], [x, y + size]])


def triangle(x: float, y: float, size: float) -> np.ndarray:
    return polygon([[x, y], [x + size, y], [x, y + size]])
