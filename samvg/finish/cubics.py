"""Single cubic Bézier segments and closed paths of them: de Casteljau splits, the piece between
two parameters, straight cubics, and keeping control points inside a box by subdivision."""

from __future__ import annotations

import numpy as np

Box = tuple[float, float, float, float]
"""(left, top, right, bottom) in pixels: where control points may lie."""

#: Halvings of a cubic sticking out of the box before its control points are clipped.
MAX_HALVINGS = 6


def split_cubic(cubic: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """De Casteljau: the (4, 2) cubic's pieces over [0, t] and [t, 1]."""
    p0, p1, p2, p3 = cubic
    a, b, c = p0 + t * (p1 - p0), p1 + t * (p2 - p1), p2 + t * (p3 - p2)
    d, e = a + t * (b - a), b + t * (c - b)
    f = d + t * (e - d)
    return np.stack([p0, a, d, f]), np.stack([f, e, c, p3])


def sub_cubic(cubic: np.ndarray, t_from: float, t_to: float) -> np.ndarray:
    """(4, 2) control points of the cubic's piece from ``t_from`` to ``t_to`` (either way)."""
    low, high = min(t_from, t_to), max(t_from, t_to)
    left = split_cubic(cubic, high)[0] if high < 1.0 else cubic
    piece = split_cubic(left, low / high)[1] if low > 0.0 and high > 0.0 else left
    return piece[::-1].copy() if t_from > t_to else piece


def straight_path(ring: np.ndarray) -> np.ndarray:
    """A closed polygon (N, 2) as N straight cubics with handles at the thirds of each edge."""
    ring = np.asarray(ring, dtype=np.float64)
    delta = np.roll(ring, -1, axis=0) - ring
    return np.stack([ring, ring + delta / 3.0, ring + 2.0 * delta / 3.0], axis=1).reshape(-1, 2)


def clip_points(points: np.ndarray, box: Box | None) -> np.ndarray:
    """The points moved into the box (unchanged without one)."""
    if box is None:
        return points
    left, top, right, bottom = box
    return np.clip(points, (left, top), (right, bottom))


def into_box(cubic: np.ndarray, box: Box | None, depth: int = 0) -> list[np.ndarray]:
    """The (4, 2) cubic as pieces whose control points lie in the box: halved while they stick
    out (a piece's control points close in on the curve), then clipped by what is left."""
    if box is None:
        return [cubic]
    low, high = np.array(box[:2]), np.array(box[2:])
    if np.all((cubic >= low) & (cubic <= high)):
        return [cubic]
    if depth >= MAX_HALVINGS:
        return [np.clip(cubic, low, high)]
    first, second = split_cubic(cubic, 0.5)
    return into_box(first, box, depth + 1) + into_box(second, box, depth + 1)


def cubics_of(points: np.ndarray) -> np.ndarray:
    """(K, 4, 2): the segments of a closed path (3K, 2)."""
    ends = np.roll(points[0::3], -1, axis=0)
    return np.stack([points[0::3], points[1::3], points[2::3], ends], axis=1)


def path_of(cubics: list[np.ndarray] | np.ndarray) -> np.ndarray:
    """(3K, 2): the closed path through consecutive (4, 2) cubics (each ends where the next
    starts)."""
    return np.concatenate([cubic[:3] for cubic in cubics])


def path_into_box(points: np.ndarray, box: Box | None) -> np.ndarray:
    """The closed path (3K, 2) with every segment sticking out of the box subdivided into it."""
    if box is None:
        return points
    return path_of([piece for cubic in cubics_of(points) for piece in into_box(cubic, box)])
