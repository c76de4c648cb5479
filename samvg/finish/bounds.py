"""Bounded geometry: every control point within the canvas plus a margin.

A path with a control point outside the margin box has its painted area intersected with the box
(shapely) and redrawn (``trim.region_paths``: its own cubics inside the box, straight edges along
the border; the largest part replaces it, others of at least ``min_part_area`` px² follow it); a
path that paints nothing on the canvas is dropped.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from samvg.finish.cubics import Box
from samvg.finish.edits import Edit, apply_edits, edit_counts
from samvg.finish.flatten import flatten_paths
from samvg.finish.outline import DEGENERATE_AREA, fill_region, filled_holes
from samvg.finish.trim import region_paths
from samvg.scene import Scene

#: Default margin around the canvas, as a fraction of its longer side.
MARGIN_FRACTION = 0.02


def default_margin(width: int, height: int) -> float:
    """The default margin in pixels: ``MARGIN_FRACTION`` of the longer side."""
    return MARGIN_FRACTION * max(width, height)


def margin_box(width: int, height: int, margin: float) -> Box:
    """The canvas grown by ``margin`` px on every side."""
    return (-margin, -margin, width + margin, height + margin)


def _outside(points: np.ndarray, offsets: np.ndarray, box: Box) -> np.ndarray:
    """(P,) bool: paths with a control point outside the box."""
    left, top, right, bottom = box
    out = (
        (points[:, 0] < left)
        | (points[:, 0] > right)
        | (points[:, 1] < top)
        | (points[:, 1] > bottom)
    )
    if len(offsets) <= 1:
        return np.zeros(0, dtype=bool)
    return np.logical_or.reduceat(out, offsets[:-1])


def _off_canvas(vertices: np.ndarray, vertex_offsets: np.ndarray, scene: Scene) -> np.ndarray:
    """(P,) bool: paths whose outline's bounding box misses the canvas."""
    if len(vertex_offsets) <= 1:
        return np.zeros(0, dtype=bool)
    low = np.minimum.reduceat(vertices, vertex_offsets[:-1])
    high = np.maximum.reduceat(vertices, vertex_offsets[:-1])
    return np.asarray(
        (high[:, 0] <= 0)
        | (high[:, 1] <= 0)
        | (low[:, 0] >= scene.width)
        | (low[:, 1] >= scene.height)
    )


def _clipped(
    region: BaseGeometry,
    source: np.ndarray,
    box: Box,
    canvas: BaseGeometry,
    tolerance: float,
    min_part_area: float,
) -> tuple[list[np.ndarray], int]:
    """The paths for a painted area clipped to the box (none if it misses the canvas), and
    how many holes they fill."""
    if shapely.intersection(region, canvas).area < DEGENERATE_AREA:
        return [], 0
    clipped = shapely.intersection(region, shapely.box(*box))
    paths = region_paths(clipped, [source], tolerance, min_part_area, box, canvas)
    return paths, filled_holes(clipped) if paths else 0


def bound_paths(
    scene: Scene,
    margin: float | None = None,
    tolerance: float = 0.5,
    min_part_area: float = 4.0,
) -> tuple[Scene, dict[str, int]]:
    """Clip every path reaching beyond the canvas plus ``margin`` px (default
    :func:`default_margin`) to that box, redrawn (fitted within ``tolerance`` px where new).
    Counts: ``bounds_checked``, ``bounds_clipped`` (paths replaced by clipped ones),
    ``bounds_split`` (extra paths from clipping), ``bounds_dropped`` (paths painting nothing
    on the canvas), ``bounds_holes_filled`` (holes of clipped crossing paths painted over)."""
    if margin is None:
        margin = default_margin(scene.width, scene.height)
    box = margin_box(scene.width, scene.height, margin)
    canvas = shapely.box(0.0, 0.0, scene.width, scene.height)
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    off_canvas = _off_canvas(vertices, vertex_offsets, scene)
    edits: dict[int, Edit] = {int(index): [] for index in np.flatnonzero(off_canvas)}
    holes = 0
    for index in np.flatnonzero(_outside(scene.points, scene.offsets, box) & ~off_canvas):
        region = fill_region(vertices[vertex_offsets[index] : vertex_offsets[index + 1]])
        source = scene.path_points(int(index))
        paths, filled = _clipped(region, source, box, canvas, tolerance, min_part_area)
        edits[int(index)] = [(points, scene.paints[index]) for points in paths]
        holes += filled
    return apply_edits(scene, edits), edit_counts("bounds", scene, edits, holes)
