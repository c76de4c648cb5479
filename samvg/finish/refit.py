"""Outlines (closed polygons) back into closed cubic paths: corners, least-squares cubics,
split where the error is too large; the result is checked to be simple and kept in a box.

The local fitter for the finish stage (``samvg.trace`` has no outline refitter yet): the ring is
densified to points at most ``STEP`` px apart (its vertices kept), cut at corners (points where
the outline turns by at least ``CORNER_DEGREES`` between the points ``REACH`` px behind and
ahead, strongest first, at most one per ``REACH``), and every stretch between two corners is
fitted with one cubic by ``samvg.trace.fit.fit_cubics``; a stretch whose points stray more than
the tolerance from its cubic is split at its worst point and both halves are fitted again
(Schneider's recursion, all stretches of a round in one batch). If the path this gives crosses
itself, the outline becomes a polygon path instead: the ring simplified within the tolerance
(topology kept), each edge a straight cubic with handles at its thirds.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from samvg.finish.flatten import flatten_path
from samvg.finish.outline import outline_parts, simple_mask
from samvg.trace.fit import fit_cubics

Box = tuple[float, float, float, float]
"""(left, top, right, bottom) in pixels: where control points may lie."""

#: Largest spacing (px) of the points the cubics are fitted to.
STEP = 1.0
#: Most points an outline is densified to (the spacing grows for longer outlines).
MAX_POINTS = 4000
#: Turning angle (degrees) of a corner, measured over ``REACH`` px each way.
CORNER_DEGREES = 50.0
REACH = 2.0
#: Rounds of splitting stretches that miss the tolerance.
MAX_ROUNDS = 12


def _densify(ring: np.ndarray) -> np.ndarray:
    """The closed ring with points inserted so no edge is longer than the step; vertices kept."""
    following = np.roll(ring, -1, axis=0)
    lengths = np.hypot(*(following - ring).T)
    step = max(STEP, float(lengths.sum()) / MAX_POINTS)
    pieces = np.maximum(np.ceil(lengths / step).astype(np.int64), 1)
    edge = np.repeat(np.arange(len(ring)), pieces)
    fraction = (np.arange(len(edge)) - (np.cumsum(pieces) - pieces)[edge]) / pieces[edge]
    return ring[edge] + fraction[:, None] * (following - ring)[edge]


def _corners(ring: np.ndarray) -> np.ndarray:
    """Increasing indices of the corners of a densified closed ring (at least two)."""
    count = len(ring)
    steps = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    perimeter = along[-1]
    position = along[:-1]
    extended = np.concatenate([position - perimeter, position, position + perimeter])
    xs, ys = np.tile(ring[:, 0], 3), np.tile(ring[:, 1], 3)
    reach = min(REACH, perimeter / 8.0)
    back = np.stack([np.interp(position - reach, extended, c) for c in (xs, ys)], axis=1)
    ahead = np.stack([np.interp(position + reach, extended, c) for c in (xs, ys)], axis=1)
    incoming, outgoing = ring - back, ahead - ring
    cross = incoming[:, 0] * outgoing[:, 1] - incoming[:, 1] * outgoing[:, 0]
    turn = np.abs(np.arctan2(cross, np.einsum("ij,ij->i", incoming, outgoing)))
    candidates = np.flatnonzero(turn >= np.deg2rad(CORNER_DEGREES))
    chosen: list[int] = []
    for candidate in candidates[np.argsort(-turn[candidates], kind="stable")]:
        gaps = np.abs(position[chosen] - position[candidate]) if chosen else np.zeros(0)
        if np.all(np.minimum(gaps, perimeter - gaps) > reach):
            chosen.append(int(candidate))
    if len(chosen) < 2:
        start = chosen[0] if chosen else 0
        opposite = (position[start] + perimeter / 2.0) % perimeter
        middle = int(np.searchsorted(position, opposite)) % count
        chosen = [start, middle] if middle != start else [start, (start + count // 2) % count]
    return np.unique(np.asarray(chosen, dtype=np.int64))


def _fit_stretches(ring: np.ndarray, corners: np.ndarray, tolerance: float) -> np.ndarray:
    """(S, 4, 2) cubics covering the closed ring from corner to corner, in ring order."""
    count = len(ring)
    pending = [
        (int(a), int(b))
        for a, b in zip(corners, np.append(corners[1:], corners[0] + count), strict=True)
    ]
    accepted: dict[int, np.ndarray] = {}
    for round_ in range(MAX_ROUNDS + 1):
        if not pending:
            break
        indices = [np.arange(a, b + 1) % count for a, b in pending]
        offsets = np.concatenate([[0], np.cumsum([len(i) for i in indices])])
        fits = fit_cubics(ring[np.concatenate(indices)], offsets)
        following = []
        for run, (a, b) in enumerate(pending):
            errors = fits.distances[offsets[run] : offsets[run + 1]]
            if errors.max() <= tolerance or b - a < 3 or round_ == MAX_ROUNDS:
                accepted[a] = fits.controls[run]
                continue
            split = a + int(np.clip(np.argmax(errors), 1, b - a - 1))
            following += [(a, split), (split, b)]
        pending = following
    return np.stack([accepted[key] for key in sorted(accepted)])


def straight_path(ring: np.ndarray) -> np.ndarray:
    """A closed polygon (N, 2) as N straight cubics with handles at the thirds of each edge."""
    ring = np.asarray(ring, dtype=np.float64)
    delta = np.roll(ring, -1, axis=0) - ring
    return np.stack([ring, ring + delta / 3.0, ring + 2.0 * delta / 3.0], axis=1).reshape(-1, 2)


def _inside(points: np.ndarray, box: Box | None) -> np.ndarray:
    if box is None:
        return points
    left, top, right, bottom = box
    return np.clip(points, (left, top), (right, bottom))


def is_simple_path(points: np.ndarray) -> bool:
    """Whether the closed cubic path (3K, 2) is simple once flattened."""
    ring = flatten_path(points)
    return bool(simple_mask(ring, np.array([0, len(ring)]))[0])


def _polygon_path(ring: np.ndarray, tolerance: float, box: Box | None) -> np.ndarray:
    """The ring simplified within ``tolerance`` (staying simple) as straight cubics."""
    simplified = shapely.simplify(shapely.Polygon(ring), tolerance, preserve_topology=True)
    coarse = np.asarray(simplified.exterior.coords)[:-1]
    if len(coarse) >= 3:
        path = straight_path(_inside(coarse, box))
        if is_simple_path(path):
            return path
    return straight_path(_inside(ring, box))


def refit_ring(ring: np.ndarray, tolerance: float, box: Box | None = None) -> np.ndarray:
    """A closed cubic path (3K, 2) within about ``tolerance`` px of the simple closed polygon
    ``ring`` (N >= 3, not closed), itself simple, every control point inside ``box``."""
    ring = np.asarray(ring, dtype=np.float64)
    dense = _densify(ring)
    cubics = _fit_stretches(dense, _corners(dense), tolerance)
    path = _inside(cubics[:, :3].reshape(-1, 2), box)
    if is_simple_path(path):
        return path
    return _polygon_path(ring, tolerance, box)


def region_paths(
    region: BaseGeometry, tolerance: float, min_area: float, box: Box | None = None
) -> list[np.ndarray]:
    """Closed cubic paths for the parts of a painted area (see ``outline_parts``), largest
    first: the paths that replace one path whose area was repaired or clipped."""
    return [refit_ring(ring, tolerance, box) for ring in outline_parts(region, min_area)]
