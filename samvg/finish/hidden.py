"""Hidden paths: remove every path whose painted area is covered by opaque paths above it, and
let an opaque path that paints the whole canvas stand in for the background it hides.

Paths are visited from the top down; a path is hidden when the opaque paths painted above it
that are still kept (candidates from a ``shapely.STRtree`` on bounding boxes) leave at most
``tolerance`` px² of its area uncovered. Removing it then changes no pixel beyond that
tolerance, since whatever it paints is painted over.

A SAM mask of an image's plain surround traces to one path round the canvas's edge (a closed
path has no holes), painted in the surround's colour over a background nobody sees. When the
lowest path is opaque and leaves at most ``tolerance`` px² of the canvas uncovered, its paint
becomes the background (flat, or the same linear or radial gradient) and the path goes: one
path fewer, the same picture.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from samvg.finish.edits import Edit, apply_edits
from samvg.finish.flatten import flatten_paths
from samvg.finish.outline import path_regions
from samvg.scene import FlatPaint, Scene

#: Uncovered area (px²) a hidden path may keep.
HIDDEN_TOLERANCE = 0.5


def _covered(region: BaseGeometry, covers: np.ndarray, tolerance: float) -> bool:
    """Whether the union of ``covers`` leaves at most ``tolerance`` px² of ``region``."""
    pieces = shapely.intersection(covers, region)
    if shapely.area(pieces).sum() < region.area - tolerance:
        return False  # even without overlaps between them, the covers are too small
    return bool(shapely.difference(region, shapely.union_all(pieces)).area <= tolerance)


def remove_hidden(
    scene: Scene, tolerance: float = HIDDEN_TOLERANCE
) -> tuple[Scene, dict[str, int]]:
    """Drop the paths covered (within ``tolerance`` px² uncovered) by opaque paths above them.
    Counts: ``hidden_removed``."""
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    regions = path_regions(vertices, vertex_offsets)
    opaque = np.array([paint.opaque for paint in scene.paints], dtype=bool)
    tree = shapely.STRtree(regions)
    removed = np.zeros(scene.path_count, dtype=bool)
    for index in range(scene.path_count - 1, -1, -1):
        region = regions[index]
        if region.is_empty:
            continue
        near = tree.query(region, predicate="intersects")
        covers = near[(near > index) & opaque[near] & ~removed[near]]
        if len(covers) and _covered(region, regions[covers], tolerance):
            removed[index] = True
    edits: dict[int, Edit] = {int(index): [] for index in np.flatnonzero(removed)}
    return apply_edits(scene, edits), {"hidden_removed": int(removed.sum())}


def background_from_cover(
    scene: Scene, tolerance: float = HIDDEN_TOLERANCE
) -> tuple[Scene, dict[str, int]]:
    """``scene`` with its lowest path made the background when that path is opaque and leaves
    at most ``tolerance`` px² of the canvas uncovered (see the module docstring). Counts:
    ``background_from_path`` (0 or 1)."""
    if scene.path_count == 0 or not scene.paints[0].opaque:
        return scene, {"background_from_path": 0}
    points = scene.path_points(0)
    vertices, vertex_offsets = flatten_paths(points, np.array([0, len(points)]))
    region = path_regions(vertices, vertex_offsets)[0]
    canvas = shapely.box(0.0, 0.0, scene.width, scene.height)
    if shapely.difference(canvas, region).area > tolerance:
        return scene, {"background_from_path": 0}
    paint = scene.paints[0]
    rest = scene.subset(range(1, scene.path_count))
    if isinstance(paint, FlatPaint):
        return rest.with_background(paint.rgba[:3]), {"background_from_path": 1}
    return replace(rest, background_gradient=paint), {"background_from_path": 1}
