"""Simple paths: find the paths whose outline crosses or touches itself and replace each by
simple paths painting the same area.

A path's flattened outline is checked with shapely (``LinearRing.is_simple``). A crossing path's
painted area (nonzero rule, ``outline.fill_region``) is split into its parts: the largest
replaces the path, every other part of at least ``min_part_area`` px² becomes an extra path with
the same paint right after it (the parts do not overlap, so their order among themselves does
not matter), smaller ones (by their area on the canvas) are dropped; each part's outline is
redrawn with the pieces of the path's own cubics it follows (``trim.redraw_ring``; a fresh fit
if that is not simple).
"""

from __future__ import annotations

import numpy as np
import shapely

from samvg.finish.cubics import Box
from samvg.finish.edits import Edit, apply_edits, edit_counts
from samvg.finish.flatten import flatten_paths
from samvg.finish.outline import fill_region, filled_holes, simple_mask
from samvg.finish.trim import region_paths
from samvg.scene import Scene

#: Smallest area (px²) of a part split off a crossing path that is kept as its own path.
MIN_PART_AREA = 4.0


def crossing_paths(scene: Scene) -> np.ndarray:
    """Indices of the paths whose flattened outline is not simple."""
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    return np.flatnonzero(~simple_mask(vertices, vertex_offsets))


def simplify_paths(
    scene: Scene,
    tolerance: float = 0.5,
    min_part_area: float = MIN_PART_AREA,
    box: Box | None = None,
) -> tuple[Scene, dict[str, int]]:
    """Replace every crossing path by simple ones (refitted within ``tolerance`` px, control
    points inside ``box`` if given). Counts: ``simple_checked`` (paths), ``simple_repaired``
    (crossing paths replaced), ``simple_split`` (extra paths added by splits),
    ``simple_dropped`` (crossing paths that painted no area worth a path),
    ``simple_holes_filled`` (holes, areas a crossing path loops round without painting, that
    its simple outlines paint over)."""
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    crossing = np.flatnonzero(~simple_mask(vertices, vertex_offsets))
    canvas = shapely.box(0.0, 0.0, scene.width, scene.height)
    edits: dict[int, Edit] = {}
    holes = 0
    for index in crossing:
        ring = vertices[vertex_offsets[index] : vertex_offsets[index + 1]]
        sources = [scene.path_points(int(index))]
        region = fill_region(ring)
        holes += filled_holes(region)
        paths = region_paths(region, sources, tolerance, min_part_area, box, canvas)
        edits[int(index)] = [(points, scene.paints[index]) for points in paths]
    return apply_edits(scene, edits), edit_counts("simple", scene, edits, holes)
