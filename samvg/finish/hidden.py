"""Hidden paths: remove every path whose painted area is covered by opaque paths above it.

Paths are visited from the top down; a path is hidden when the opaque paths painted above it
that are still kept (candidates from a ``shapely.STRtree`` on bounding boxes) leave at most
``tolerance`` px² of its area uncovered. Removing it then changes no pixel beyond that
tolerance, since whatever it paints is painted over.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from samvg.finish.edits import Edit, apply_edits
from samvg.finish.flatten import flatten_paths
from samvg.finish.outline import path_regions
from samvg.scene import Scene

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
