"""Merging: two paths of near-equal colour that touch or overlap become one path, where that
leaves the picture unchanged.

Candidate pairs are paths within ``MERGE_DISTANCE`` px of each other (``shapely.STRtree`` with
``dwithin``) whose fills differ by less than ``delta_e`` (CIE76 ΔE in CIELAB,
``skimage.color.rgb2lab``) with equal opacity, both flat (a gradient fill never merges);
closest colours first. A pair merges only when no
path painted between them in paint order intersects either (so lifting the lower one to the
upper one's place changes no pixel), when they meet along at least ``MIN_CONTACT`` px (not at a
point) and their union is one polygon without holes (a gap under ``MERGE_DISTANCE`` is closed
by a mitred buffer out and back) and, for translucent fills, when
they do not overlap. The merged path takes the upper one's place, the union's outline redrawn from
the two paths' cubics (``trim.redraw_ring``; fitted afresh where a gap was closed), or the path
that already contains the other, and the mean fill weighted by the area of each that shows.
Each path merges at most once per round; rounds repeat until nothing merges.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry
from skimage.color import rgb2lab

from samvg.finish.cubics import Box
from samvg.finish.flatten import flatten_path, flatten_paths
from samvg.finish.outline import path_regions
from samvg.finish.trim import redraw_ring
from samvg.scene import FlatPaint, Paint, Scene

#: Largest gap (px) between two paths that still merge.
MERGE_DISTANCE = 0.5
#: Largest area (px²) of holes, or of overlap of translucent fills, a merge may paint over.
AREA_TOLERANCE = 0.5
#: Largest opacity difference of two paths that merge.
ALPHA_TOLERANCE = 1.0 / 255.0
#: Shortest stretch (px) along which two paths must meet to merge (not at a single point).
MIN_CONTACT = 1.0
MAX_ROUNDS = 16


@dataclass
class _Paths:
    """The scene's paths while merging, by their original index (dead ones left in place)."""

    points: list[np.ndarray]
    paints: list[Paint]
    regions: np.ndarray
    alive: np.ndarray

    @classmethod
    def of(cls, scene: Scene) -> _Paths:
        vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
        return cls(
            [scene.path_points(i).copy() for i in range(scene.path_count)],
            list(scene.paints),
            path_regions(vertices, vertex_offsets),
            np.ones(scene.path_count, dtype=bool),
        )

    def scene(self, like: Scene) -> Scene:
        paths = [(self.points[i], self.paints[i]) for i in np.flatnonzero(self.alive)]
        return like.with_paths(paths)


def _candidate_pairs(
    paths: _Paths, live: np.ndarray, tree: shapely.STRtree, delta_e: float
) -> np.ndarray:
    """(M, 2) live-list positions (lower, upper) of pairs close in space and colour, best first."""
    near = tree.query(paths.regions[live], predicate="dwithin", distance=MERGE_DISTANCE)
    pairs = near.T[near[0] < near[1]]
    if len(pairs) == 0:
        return pairs
    rgba = np.array([paths.paints[i].rgba for i in live])
    lab = rgb2lab(rgba[None, :, :3])[0]
    distance = np.linalg.norm(lab[pairs[:, 0]] - lab[pairs[:, 1]], axis=1)
    alpha = np.abs(rgba[pairs[:, 0], 3] - rgba[pairs[:, 1], 3])
    flat = np.array([isinstance(paths.paints[i], FlatPaint) for i in live])
    keep = (distance < delta_e) & (alpha <= ALPHA_TOLERANCE) & flat[pairs[:, 0]] & flat[pairs[:, 1]]
    return pairs[keep][np.argsort(distance[keep], kind="stable")]


def _union_outline(lower: BaseGeometry, upper: BaseGeometry) -> tuple[BaseGeometry | None, bool]:
    """The union of two areas as one hole-free polygon (or None), and whether a gap between
    them had to be closed (its vertices are then new). Areas that meet only at a point (or
    across a gap only that narrow) do not make one polygon, nor do areas GEOS cannot combine
    (a topology error on nearly degenerate outlines: the two paths then stay as they are)."""
    try:
        return _union_of(lower, upper)
    except shapely.errors.GEOSException:
        return None, False


def _union_of(lower: BaseGeometry, upper: BaseGeometry) -> tuple[BaseGeometry | None, bool]:
    radius = MERGE_DISTANCE / 2.0 + 0.01
    grown = [shapely.buffer(area, radius, join_style="mitre") for area in (lower, upper)]
    if shapely.intersection(*grown).area < 2.0 * radius * MIN_CONTACT:
        return None, False
    union = shapely.union(lower, upper)
    closed = not isinstance(union, shapely.Polygon)
    if closed:
        union = shapely.buffer(shapely.union(*grown), -radius, join_style="mitre")
    if not isinstance(union, shapely.Polygon) or union.is_empty:
        return None, closed
    shell = shapely.Polygon(union.exterior)
    return (shell if shell.area - union.area <= AREA_TOLERANCE else None), closed


def _blocked(
    lower: int,
    upper: int,
    live: np.ndarray,
    tree: shapely.STRtree,
    owner: np.ndarray,
    paths: _Paths,
) -> bool:
    """Whether a path painted between ``lower`` and ``upper`` intersects either."""
    hits = np.concatenate(
        [tree.query(paths.regions[i], predicate="intersects") for i in (lower, upper)]
    )
    where = owner[live[hits]]
    return bool(np.any((where > lower) & (where < upper)))


def _merge_pair(paths: _Paths, lower: int, upper: int, tolerance: float, box: Box | None) -> bool:
    """Merge path ``lower`` into ``upper`` if their union allows it; whether it did."""
    first, second = paths.regions[lower], paths.regions[upper]
    translucent = not (paths.paints[lower].opaque and paths.paints[upper].opaque)
    if translucent and shapely.intersection(first, second).area > AREA_TOLERANCE:
        return False
    outline, closed = _union_outline(first, second)
    if outline is None:
        return False
    if abs(outline.area - second.area) <= AREA_TOLERANCE and isinstance(second, shapely.Polygon):
        points = paths.points[upper]
    elif abs(outline.area - first.area) <= AREA_TOLERANCE and isinstance(first, shapely.Polygon):
        points = paths.points[lower]
    else:
        ring = np.asarray(outline.exterior.coords)[:-1]
        sources = [] if closed else [paths.points[lower], paths.points[upper]]
        points = redraw_ring(ring, sources, tolerance, box)
    # Each fill weighs what of it shows: the lower one only outside the upper one.
    weights = np.array([shapely.difference(first, second).area, second.area]) + 1e-9
    rgba = np.array([paths.paints[lower].rgba, paths.paints[upper].rgba])
    paths.paints[upper] = FlatPaint(tuple(np.clip(weights @ rgba / weights.sum(), 0.0, 1.0)))
    paths.points[upper] = points
    paths.regions[upper] = shapely.Polygon(flatten_path(points))  # what later merges cut
    paths.alive[lower] = False
    return True


def _round(paths: _Paths, delta_e: float, tolerance: float, box: Box | None) -> int:
    """One round of merges (each path at most once); how many merged."""
    live = np.flatnonzero(paths.alive)
    tree = shapely.STRtree(paths.regions[live])
    owner = np.arange(len(paths.alive))
    touched = np.zeros(len(paths.alive), dtype=bool)
    merged = 0
    for first, second in _candidate_pairs(paths, live, tree, delta_e):
        lower, upper = int(live[first]), int(live[second])
        if touched[lower] or touched[upper]:
            continue
        if _blocked(lower, upper, live, tree, owner, paths):
            continue
        if _merge_pair(paths, lower, upper, tolerance, box):
            owner[lower] = upper
            touched[lower] = touched[upper] = True
            merged += 1
    return merged


def merge_paths(
    scene: Scene, delta_e: float = 2.0, tolerance: float = 0.5, box: Box | None = None
) -> tuple[Scene, dict[str, int]]:
    """Merge touching or overlapping paths of fills closer than ``delta_e`` (CIELAB ΔE) where
    the picture allows it (see the module docstring); new outlines are refitted within
    ``tolerance`` px, control points inside ``box`` if given. Counts: ``merged`` (merges done,
    each removing one path)."""
    if scene.path_count < 2:
        return scene, {"merged": 0}
    paths = _Paths.of(scene)
    merged = 0
    for _ in range(MAX_ROUNDS):
        done = _round(paths, delta_e, tolerance, box)
        merged += done
        if done == 0:
            break
    return (paths.scene(scene) if merged else scene), {"merged": merged}
