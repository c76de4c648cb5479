"""Outlines (closed polygons) back into closed cubic paths, checked to be simple and kept in a
box: for outlines that follow no existing path (``trim`` redraws those that do).

Two fits are made and the simple one with fewer segments is kept: the tracer's, by
``samvg.trace.refit_outline`` (looked up at call time: it is new in the tracer) with any segment
sticking out of the box subdivided into it, and the local fitter's. The local fitter: the ring is
densified to points at most ``STEP`` px apart (its vertices kept), cut at corners (points where
the outline turns by at least ``CORNER_DEGREES`` between the points ``REACH`` px behind and
ahead, strongest first, at most one per ``REACH``, and where it starts or stops running along the
box's border), and every stretch between two corners is fitted with one cubic by
``samvg.trace.fit.fit_cubics``; a stretch whose points stray more than the tolerance from its
cubic, or whose control points leave the box, is split at its worst point and both halves are
fitted again (Schneider's recursion, all stretches of a round in one batch). If both paths
cross themselves, the outline becomes a polygon path: the ring simplified within the tolerance
(topology kept), each edge a straight cubic with handles at its thirds.
"""

from __future__ import annotations

import numpy as np
import shapely

from samvg import trace
from samvg.finish.cubics import Box, clip_points, path_into_box, straight_path
from samvg.finish.flatten import flatten_path
from samvg.finish.outline import simple_mask
from samvg.trace.fit import fit_cubics

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


def _edge_ends(ring: np.ndarray, box: Box | None) -> np.ndarray:
    """Indices where the ring starts or stops running along the box's border (clipped outlines
    get a corner there, so the stretch on the border is fitted on its own, straight)."""
    if box is None:
        return np.zeros(0, dtype=np.int64)
    left, top, right, bottom = box
    x, y = ring[:, 0], ring[:, 1]
    on = (np.abs(x - left) < 1e-6) | (np.abs(x - right) < 1e-6)
    on |= (np.abs(y - top) < 1e-6) | (np.abs(y - bottom) < 1e-6)
    return np.flatnonzero(on & ~(np.roll(on, 1) & np.roll(on, -1)))


def _within(controls: np.ndarray, box: Box | None) -> np.ndarray:
    """(S,) bool: cubics whose control points all lie in the box."""
    if box is None:
        return np.ones(len(controls), dtype=bool)
    left, top, right, bottom = box
    x, y = controls[..., 0], controls[..., 1]
    slack = 1e-6
    inside = (x >= left - slack) & (x <= right + slack) & (y >= top - slack) & (y <= bottom + slack)
    return np.asarray(inside.all(axis=1))


def _fit_stretches(
    ring: np.ndarray, corners: np.ndarray, tolerance: float, box: Box | None
) -> np.ndarray:
    """(S, 4, 2) cubics covering the closed ring from corner to corner, in ring order: each
    within ``tolerance`` of its points and inside ``box``, or a stretch too short to split."""
    count = len(ring)
    ends = np.append(corners[1:], corners[0] + count)
    pending = [(int(a), int(b)) for a, b in zip(corners, ends, strict=True)]
    accepted: dict[int, np.ndarray] = {}
    for round_ in range(MAX_ROUNDS + 1):
        if not pending:
            break
        indices = [np.arange(a, b + 1) % count for a, b in pending]
        offsets = np.concatenate([[0], np.cumsum([len(i) for i in indices])])
        fits = fit_cubics(ring[np.concatenate(indices)], offsets)
        within = _within(fits.controls, box)
        following = []
        for run, (a, b) in enumerate(pending):
            errors = fits.distances[offsets[run] : offsets[run + 1]]
            good = errors.max() <= tolerance and within[run]
            if good or b - a < 2 or round_ == MAX_ROUNDS:
                accepted[a] = fits.controls[run]
                continue
            worst = int(np.argmax(errors)) if errors.max() > tolerance else (b - a) // 2
            split = a + int(np.clip(worst, 1, b - a - 1))
            following += [(a, split), (split, b)]
        pending = following
    return np.stack([accepted[key] for key in sorted(accepted)])


def is_simple_path(points: np.ndarray) -> bool:
    """Whether the closed cubic path (3K, 2) is simple once flattened."""
    ring = flatten_path(points)
    return bool(simple_mask(ring, np.array([0, len(ring)]))[0])


def _polygon_path(ring: np.ndarray, tolerance: float, box: Box | None) -> np.ndarray:
    """The ring simplified within ``tolerance`` (staying simple) as straight cubics."""
    simplified = shapely.simplify(shapely.Polygon(ring), tolerance, preserve_topology=True)
    coarse = np.asarray(simplified.exterior.coords)[:-1]
    if len(coarse) >= 3:
        path = straight_path(clip_points(coarse, box))
        if is_simple_path(path):
            return path
    return straight_path(clip_points(ring, box))


def _local_fit(ring: np.ndarray, tolerance: float, box: Box | None) -> np.ndarray:
    """The local fitter (module docstring): corners, then cubics split until they fit."""
    dense = _densify(ring)
    corners = np.union1d(_corners(dense), _edge_ends(dense, box))
    cubics = _fit_stretches(dense, corners, tolerance, box)
    return clip_points(cubics[:, :3].reshape(-1, 2), box)


def _tracer_fit(ring: np.ndarray, tolerance: float, box: Box | None) -> np.ndarray | None:
    """``samvg.trace.refit_outline`` (the tracer's fewest-segments fit) where the tracer has
    it, subdivided into the box; None without it or when it refuses the ring."""
    refit_outline = getattr(trace, "refit_outline", None)
    if refit_outline is None:
        return None
    try:
        fitted = np.asarray(refit_outline(ring, tolerance), dtype=np.float64)
    except ValueError:  # InputError included: a ring the tracer cannot fit
        return None
    return path_into_box(fitted, box)


def refit_ring(ring: np.ndarray, tolerance: float, box: Box | None = None) -> np.ndarray:
    """A closed cubic path (3K, 2) within about ``tolerance`` px of the simple closed polygon
    ``ring`` (N >= 3, not closed), itself simple, every control point inside ``box``: of the
    tracer's fit and the local fit, the simple one with fewer segments, else a polygon path."""
    ring = np.asarray(ring, dtype=np.float64)
    fits = [_tracer_fit(ring, tolerance, box), _local_fit(ring, tolerance, box)]
    simple = [fit for fit in fits if fit is not None and is_simple_path(fit)]
    if simple:
        return min(simple, key=len)
    return _polygon_path(ring, tolerance, box)
