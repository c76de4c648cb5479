"""Redrawing outlines cut from existing paths with the pieces of those paths' own cubics.

An outline shapely computed from flattened paths (a crossing path's repaired area, a path
clipped to the margin box, the union of two merged paths) keeps the flattened vertices it did
not cut, and its new vertices lie on the chords it cut. Where two consecutive outline vertices
lie on one chord of a source path, the outline follows that path there: the stretch is redrawn
as the piece of the source's cubic between the two parameters (de Casteljau), so untouched
geometry keeps its exact curves and segments. Edges that follow no source (the margin box's
border, for instance) become straight cubics. The ends of every piece are moved onto the
outline's vertices (by at most the flattening tolerance), so pieces join exactly. A cubic with a
control point outside the box is subdivided until it is inside (the last bit is clipped). If the
path this gives is not simple, or the outline follows no source at all, the outline is
fitted afresh (``refit.refit_ring``); so is an outline whose pieces are mostly new straight edges
(more than ``MAX_LINES`` of them).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from samvg.finish.cubics import Box, into_box, path_of, straight_path, sub_cubic
from samvg.finish.flatten import flatten, segment_ends
from samvg.finish.outline import outline_parts
from samvg.finish.refit import is_simple_path, refit_ring

#: Distance (px) within which an outline vertex lies on a source chord.
ON_CHORD = 1e-7
#: Most straight edges an outline may add to the sources' pieces when more than half of its
#: pieces are straight (beyond that it mostly follows no source and is fitted afresh).
MAX_LINES = 8

_Piece = tuple[int, int, int, float, float]
"""(first outline vertex, last outline vertex, packed segment or -1 for a line, t from, t to)."""


class _Sources:
    """The source paths packed and flattened, with every chord's place on its cubic."""

    def __init__(self, sources: Sequence[np.ndarray]) -> None:
        arrays = [np.asarray(source, dtype=np.float64) for source in sources]
        offsets = np.concatenate([[0], np.cumsum([len(array) for array in arrays])])
        self.points = np.concatenate(arrays)
        self.ends = segment_ends(offsets)
        flat = flatten(self.points, offsets)
        following = np.arange(len(flat.vertices)) + 1
        following[flat.vertex_offsets[1:] - 1] = flat.vertex_offsets[:-1]
        self.start, self.stop = flat.vertices, flat.vertices[following]
        self.segment, self.t_start = flat.segment, flat.t
        same = flat.segment[following] == flat.segment
        self.t_stop = np.where(same, flat.t[following], 1.0)
        self.tree = shapely.STRtree(shapely.linestrings(np.stack([self.start, self.stop], 1)))

    def chords_of(self, ring: np.ndarray) -> list[dict[int, float]]:
        """For each outline vertex: {chord: fraction along it} of the chords it lies on."""
        vertex, chord = self.tree.query(
            shapely.points(ring), predicate="dwithin", distance=ON_CHORD
        )
        a, d = self.start[chord], self.stop[chord] - self.start[chord]
        length2 = np.einsum("ij,ij->i", d, d)
        along = np.einsum("ij,ij->i", ring[vertex] - a, d) / np.where(length2 > 0, length2, 1.0)
        fraction = np.clip(along, 0.0, 1.0)
        found: list[dict[int, float]] = [{} for _ in range(len(ring))]
        for v, c, f in zip(vertex.tolist(), chord.tolist(), fraction.tolist(), strict=True):
            found[v][c] = f
        return found

    def parameter(self, chord: int, fraction: float) -> float:
        """The parameter on the chord's segment at ``fraction`` along the chord."""
        t0, t1 = self.t_start[chord], self.t_stop[chord]
        return float(t0 + fraction * (t1 - t0))

    def cubic(self, segment: int) -> np.ndarray:
        """(4, 2) control points of a packed segment."""
        first = 3 * segment
        return np.stack([*self.points[first : first + 3], self.points[self.ends[segment]]])


def _joins(before: _Piece, after: _Piece) -> bool:
    """Whether two consecutive pieces run on along one segment the same way."""
    _, _, segment, t_from, t_to = after
    _, _, last_segment, last_from, last_to = before
    same_way = (t_to - t_from) * (last_to - last_from) > 0
    return segment >= 0 and last_segment == segment and same_way and abs(last_to - t_from) < 1e-9


def _pieces(ring: np.ndarray, sources: _Sources) -> list[_Piece]:
    """The outline's edges as pieces of source cubics or lines, runs on one segment joined."""
    chords = sources.chords_of(ring)
    count = len(ring)
    pieces: list[_Piece] = []
    for j in range(count):
        k = (j + 1) % count
        if np.array_equal(ring[j], ring[k]):
            continue
        shared = [chord for chord in chords[j] if chord in chords[k]]
        if not shared:
            pieces.append((j, k, -1, 0.0, 0.0))
            continue
        chord = shared[0]
        piece = (
            j,
            k,
            int(sources.segment[chord]),
            sources.parameter(chord, chords[j][chord]),
            sources.parameter(chord, chords[k][chord]),
        )
        if pieces and _joins(pieces[-1], piece):
            pieces[-1] = (pieces[-1][0], k, piece[2], pieces[-1][3], piece[4])
        else:
            pieces.append(piece)
    if len(pieces) > 1 and _joins(pieces[-1], pieces[0]):  # the ring starts inside a piece
        last, first = pieces.pop(), pieces[0]
        pieces[0] = (last[0], first[1], first[2], last[3], first[4])
    return pieces


def _assemble(
    ring: np.ndarray, pieces: list[_Piece], sources: _Sources, box: Box | None
) -> np.ndarray:
    """The closed path (3K, 2) of the pieces, each moved onto its outline vertices."""
    cubics = []
    for first, last, segment, t_from, t_to in pieces:
        start, end = ring[first], ring[last]
        if segment < 0:
            cubic = straight_path(np.stack([start, end]))[:4].copy()
            cubic[3] = end
        else:
            cubic = sub_cubic(sources.cubic(segment), t_from, t_to)
            cubic[:2] += start - cubic[0]
            cubic[2:] += end - cubic[3]
        cubics.append(cubic)
    return path_of([piece for cubic in cubics for piece in into_box(cubic, box)])


def redraw_ring(
    ring: np.ndarray, sources: Sequence[np.ndarray], tolerance: float, box: Box | None = None
) -> np.ndarray:
    """A simple closed cubic path (3K, 2) for the simple outline ``ring`` (N, 2, not closed)
    cut from the flattened ``sources`` (paths (3K, 2)): their cubics where it follows them,
    straight edges elsewhere, else a fresh fit within ``tolerance`` px; control points in
    ``box``."""
    ring = np.asarray(ring, dtype=np.float64)
    if sources:
        packed = _Sources(sources)
        pieces = _pieces(ring, packed)
        lines = sum(1 for piece in pieces if piece[2] < 0)
        if lines < len(pieces) and (lines <= MAX_LINES or 2 * lines <= len(pieces)):
            path = _assemble(ring, pieces, packed, box)
            if is_simple_path(path):
                return path
    return refit_ring(ring, tolerance, box)


def region_paths(
    region: BaseGeometry,
    sources: Sequence[np.ndarray],
    tolerance: float,
    min_area: float,
    box: Box | None = None,
    canvas: BaseGeometry | None = None,
) -> list[np.ndarray]:
    """Closed cubic paths for the parts of a painted area cut from ``sources`` (see
    ``outline.outline_parts``: largest first, parts off the ``canvas`` left out): what replaces
    a repaired or clipped path."""
    rings = outline_parts(region, min_area, canvas)
    return [redraw_ring(ring, sources, tolerance, box) for ring in rings]
