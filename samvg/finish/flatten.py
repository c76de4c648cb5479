"""Flattening closed cubic paths into polygons within a chord tolerance.

The one flattener of the finish stage: every geometric test there (simplicity, clipping, cover,
merging, areas) works on these polygons. Each cubic segment is cut uniformly into ``n`` pieces
with ``n = ceil(sqrt(0.75 m / tolerance))``, ``m`` the larger second difference of its control
points: a uniform cut's chord error is at most ``max |B''| / (8 n²)`` and ``|B''| <= 6 m``, so every
chord lies within ``tolerance`` of its arc (the rasterizer's rule, ``samvg.render``). All segments
of all paths are evaluated in one vectorized pass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Largest distance (pixels) between a cubic arc and the chord that replaces it.
FLATTEN_TOLERANCE = 0.1
#: Most pieces one segment is cut into (reached only by absurdly curved segments).
MAX_PIECES = 256


def segment_ends(offsets: np.ndarray) -> np.ndarray:
    """Index of the end point of every segment of packed paths: ``3s + 3``, except the last
    segment of a path, which returns to the path's first point."""
    offsets = np.asarray(offsets, dtype=np.int64)
    counts = np.diff(offsets) // 3
    ends = np.arange(1, int(counts.sum()) + 1, dtype=np.int64) * 3
    last = np.cumsum(counts) - 1
    ends[last[counts > 0]] = offsets[:-1][counts > 0]
    return ends


def _pieces(points: np.ndarray, offsets: np.ndarray, tolerance: float) -> np.ndarray:
    """Pieces per segment: enough for the chord tolerance, and at least three per path."""
    counts = np.diff(offsets) // 3
    starts = np.arange(int(counts.sum()), dtype=np.int64) * 3
    p0, p1, p2 = points[starts], points[starts + 1], points[starts + 2]
    p3 = points[segment_ends(offsets)]
    second = np.maximum(np.hypot(*(p0 - 2.0 * p1 + p2).T), np.hypot(*(p1 - 2.0 * p2 + p3).T))
    with np.errstate(over="ignore", invalid="ignore"):
        needed = np.ceil(np.sqrt(0.75 * second / tolerance))
    needed = np.nan_to_num(needed, nan=MAX_PIECES, posinf=MAX_PIECES)
    least = np.repeat(-(-3 // np.maximum(counts, 1)), counts)
    return np.clip(needed, least, MAX_PIECES).astype(np.int64)


@dataclass(frozen=True)
class Flattening:
    """Polygons of packed closed cubic paths: polygon ``i`` is
    ``vertices[vertex_offsets[i] : vertex_offsets[i + 1]]`` (at least three vertices, the first
    not repeated at the end, starting at the path's first point). Vertex ``v`` is the point at
    parameter ``t[v]`` of the packed segment ``segment[v]`` (segment ``s`` starts at control
    point ``3s``)."""

    vertices: np.ndarray
    vertex_offsets: np.ndarray
    segment: np.ndarray
    t: np.ndarray


def flatten(
    points: np.ndarray, offsets: np.ndarray, tolerance: float = FLATTEN_TOLERANCE
) -> Flattening:
    """Flatten packed closed cubic paths (``Scene`` layout) into polygons, keeping where on
    the paths every vertex lies."""
    points = np.asarray(points, dtype=np.float64)
    offsets = np.asarray(offsets, dtype=np.int64)
    counts = np.diff(offsets) // 3
    if len(counts) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return Flattening(np.zeros((0, 2)), np.zeros(1, dtype=np.int64), empty, np.zeros(0))
    pieces = _pieces(points, offsets, tolerance)
    segment_first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    per_path = np.add.reduceat(pieces, segment_first)
    vertex_offsets = np.concatenate([[0], np.cumsum(per_path)]).astype(np.int64)
    segment = np.repeat(np.arange(len(pieces)), pieces)
    first = np.cumsum(pieces) - pieces
    t = (np.arange(len(segment)) - first[segment]) / pieces[segment]
    starts = 3 * segment
    p0, p1, p2 = points[starts], points[starts + 1], points[starts + 2]
    p3 = points[segment_ends(offsets)[segment]]
    s, u = (1.0 - t)[:, None], t[:, None]
    vertices = s * s * s * p0 + 3.0 * u * s * s * p1 + 3.0 * u * u * s * p2 + u * u * u * p3
    return Flattening(vertices, vertex_offsets, segment, t)


def flatten_paths(
    points: np.ndarray, offsets: np.ndarray, tolerance: float = FLATTEN_TOLERANCE
) -> tuple[np.ndarray, np.ndarray]:
    """Flatten packed closed cubic paths into polygons: ``(vertices, vertex_offsets)`` of
    :class:`Flattening`."""
    flat = flatten(points, offsets, tolerance)
    return flat.vertices, flat.vertex_offsets


def flatten_path(points: np.ndarray, tolerance: float = FLATTEN_TOLERANCE) -> np.ndarray:
    """One closed cubic path (3K, 2) as a polygon (N, 2), N >= 3."""
    points = np.asarray(points, dtype=np.float64)
    vertices, _ = flatten_paths(points, np.array([0, len(points)]), tolerance)
    return vertices


def polygons(vertices: np.ndarray, vertex_offsets: np.ndarray) -> list[np.ndarray]:
    """The polygons of :func:`flatten_paths` as a list of (N_i, 2) arrays (views)."""
    return [
        vertices[vertex_offsets[i] : vertex_offsets[i + 1]] for i in range(len(vertex_offsets) - 1)
    ]
