"""The area a flattened path paints, as shapely geometry, and the outlines that area splits into.

A closed path is drawn with the nonzero fill rule, so where its outline crosses itself the painted
area is every face of the outline's arrangement with a nonzero winding number. ``fill_region``
computes exactly that: it nodes the polygon's edges (``shapely.node``), builds the faces
(``shapely.polygonize``), keeps those whose interior point has a nonzero winding number and
unions them. (``shapely.make_valid`` and ``buffer(0)`` read a crossing ring by the even-odd rule
or drop lobes; they would turn a path's curl, painted twice by the renderer, into a hole.)
``outline_parts`` turns such an area back into the exterior rings of its parts, largest first,
holes filled (a single closed path cannot carry one; the tracer fills them too).
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

#: Area (px²) under which an outline part paints nothing worth a path.
DEGENERATE_AREA = 0.25


def _ring_array(vertices: np.ndarray, vertex_offsets: np.ndarray) -> np.ndarray:
    """Every polygon as a shapely LinearRing (closed automatically)."""
    indices = np.repeat(np.arange(len(vertex_offsets) - 1), np.diff(vertex_offsets))
    return np.asarray(shapely.linearrings(vertices, indices=indices))


def simple_mask(vertices: np.ndarray, vertex_offsets: np.ndarray) -> np.ndarray:
    """(P,) bool: which polygons are simple rings (no crossing or touching of their own edges,
    not collapsed to a line or a point)."""
    if len(vertex_offsets) <= 1:
        return np.zeros(0, dtype=bool)
    return np.asarray(shapely.is_simple(_ring_array(vertices, vertex_offsets)), dtype=bool)


def polygon_areas(vertices: np.ndarray, vertex_offsets: np.ndarray) -> np.ndarray:
    """(P,) unsigned shoelace areas of the polygons (the painted area of a simple one)."""
    if len(vertex_offsets) <= 1:
        return np.zeros(0)
    following = np.arange(len(vertices)) + 1
    following[vertex_offsets[1:] - 1] = vertex_offsets[:-1]
    x, y = vertices[:, 0], vertices[:, 1]
    cross = x * y[following] - x[following] * y
    return np.abs(np.add.reduceat(cross, vertex_offsets[:-1])) / 2.0


def winding_numbers(queries: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Winding number of the closed polygon ``ring`` (N, 2) around each query point (Q, 2)."""
    ax, ay = ring[:, 0][None, :], ring[:, 1][None, :]
    following = np.roll(ring, -1, axis=0)
    bx, by = following[:, 0][None, :], following[:, 1][None, :]
    qx, qy = queries[:, 0][:, None], queries[:, 1][:, None]
    side = (bx - ax) * (qy - ay) - (qx - ax) * (by - ay)
    upward = (ay <= qy) & (by > qy) & (side > 0)
    downward = (ay > qy) & (by <= qy) & (side < 0)
    return np.asarray(upward.sum(axis=1) - downward.sum(axis=1))


def _dedupe(ring: np.ndarray) -> np.ndarray:
    keep = np.any(ring != np.roll(ring, 1, axis=0), axis=1)
    return ring[keep] if keep.any() else ring[:1]


def fill_region(ring: np.ndarray) -> BaseGeometry:
    """The area a closed polygon (N, 2) paints under the nonzero rule: a valid Polygon or
    MultiPolygon (empty when the polygon encloses no area)."""
    ring = _dedupe(np.asarray(ring, dtype=np.float64))
    if len(ring) < 3:
        return shapely.Polygon()
    line = shapely.linearrings(ring)
    if shapely.is_simple(line):
        return shapely.Polygon(line)
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.node(line))))
    faces = faces[shapely.area(faces) > 0]
    if len(faces) == 0:
        return shapely.Polygon()
    inside = shapely.get_coordinates(shapely.point_on_surface(faces))
    painted = faces[winding_numbers(inside, ring) != 0]
    return shapely.union_all(painted) if len(painted) else shapely.Polygon()


def region_of(ring: np.ndarray, simple: bool) -> BaseGeometry:
    """:func:`fill_region`, short-cut for a polygon already known to be simple."""
    return shapely.Polygon(ring) if simple else fill_region(ring)


def _polygons_in(geometry: BaseGeometry) -> list[BaseGeometry]:
    """The polygons of any geometry (collections searched, lines and points left out)."""
    if geometry.is_empty:
        return []
    if isinstance(geometry, shapely.Polygon):
        return [geometry]
    if isinstance(geometry, (shapely.MultiPolygon, shapely.GeometryCollection)):
        return [part for item in shapely.get_parts(geometry) for part in _polygons_in(item)]
    return []


def outline_parts(
    geometry: BaseGeometry, min_area: float, canvas: BaseGeometry | None = None
) -> list[np.ndarray]:
    """Exterior rings (N, 2), not closed, of the polygons of ``geometry``, holes filled, by
    decreasing area on the ``canvas`` (if given; parts off it paint nothing): the largest
    unless it is degenerate (< ``DEGENERATE_AREA``), then every other part of at least
    ``min_area`` px²."""
    shells = np.array([shapely.Polygon(part.exterior) for part in _polygons_in(geometry)])
    if len(shells) == 0:
        return []
    areas = shapely.area(shells if canvas is None else shapely.intersection(shells, canvas))
    order = np.argsort(-areas, kind="stable")
    least = np.full(len(shells), max(min_area, DEGENERATE_AREA))
    least[0] = DEGENERATE_AREA
    kept = order[areas[order] >= least]
    return [np.asarray(shells[index].exterior.coords)[:-1] for index in kept]


def filled_holes(geometry: BaseGeometry) -> int:
    """How many holes of at least ``DEGENERATE_AREA`` px² ``outline_parts`` fills."""
    holes = [shapely.Polygon(ring) for part in _polygons_in(geometry) for ring in part.interiors]
    return sum(1 for hole in holes if hole.area >= DEGENERATE_AREA)


def path_regions(vertices: np.ndarray, vertex_offsets: np.ndarray) -> np.ndarray:
    """(P,) object array: the painted area of every polygon (see :func:`fill_region`)."""
    simple = simple_mask(vertices, vertex_offsets)
    regions = np.empty(len(simple), dtype=object)
    for index, is_simple in enumerate(simple):
        ring = vertices[vertex_offsets[index] : vertex_offsets[index + 1]]
        regions[index] = region_of(ring, bool(is_simple))
    return regions
