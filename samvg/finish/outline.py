"""The area a flattened path paints, as shapely geometry, and the outlines that area splits into.

A closed path is drawn with the nonzero fill rule, so where its outline crosses itself the painted
area is every face of the outline's arrangement with a nonzero winding number. ``fill_region``
computes exactly that: it nodes the polygon's edges (``shapely.node``), builds the faces
(``shapely.polygonize``), keeps those whose interior point has a nonzero winding number and
unions them. (``shapely.make_valid`` and ``buffer(0)`` read a crossing ring by the even-odd rule
or drop lobes; they would turn a path's curl, painted twice by the renderer, into a hole.)
``outline_parts`` turns such an area back into the exterior rings of its parts, largest first.
A single closed path cannot carry a hole, and filling one would paint over whatever the hole
showed (a crossing path that loops round the paths beneath it), so a part with a hole of
`HOLE_AREA` px² or more is cut across each such hole, by a line through its middle along its
shorter side, into pieces without holes; the pieces overlap by `CUT_OVERLAP` px along each cut
so that no seam of what lies beneath shows between them. Smaller holes are filled.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

#: Area (px²) under which an outline part paints nothing worth a path.
DEGENERATE_AREA = 0.25
#: Holes of at least this area (px²) are cut round rather than filled (`outline_parts`).
HOLE_AREA = 4.0
#: How far (px) each piece of a part cut at a hole reaches over the cut.
CUT_OVERLAP = 0.5
#: At most this many cuts per part; holes left after them are filled.
MAX_CUTS = 64


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
    return np.abs(signed_polygon_areas(vertices, vertex_offsets))


def signed_polygon_areas(vertices: np.ndarray, vertex_offsets: np.ndarray) -> np.ndarray:
    """(P,) signed shoelace areas of the polygons: positive for those that run clockwise on
    the screen (y pointing down)."""
    if len(vertex_offsets) <= 1:
        return np.zeros(0)
    following = np.arange(len(vertices)) + 1
    following[vertex_offsets[1:] - 1] = vertex_offsets[:-1]
    x, y = vertices[:, 0], vertices[:, 1]
    cross = x * y[following] - x[following] * y
    return np.add.reduceat(cross, vertex_offsets[:-1]) / 2.0


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
    """Exterior rings (N, 2), not closed, of the polygons of ``geometry``, cut round their
    large holes (`hole_free_pieces`), small holes filled, by decreasing area on the ``canvas``
    (if given; parts off it paint nothing): the largest unless it is degenerate
    (< ``DEGENERATE_AREA``), then every other part of at least ``min_area`` px²."""
    shells = np.array(
        [piece for part in _polygons_in(geometry) for piece in hole_free_pieces(part)]
    )
    if len(shells) == 0:
        return []
    areas = shapely.area(shells if canvas is None else shapely.intersection(shells, canvas))
    order = np.argsort(-areas, kind="stable")
    least = np.full(len(shells), max(min_area, DEGENERATE_AREA))
    least[0] = DEGENERATE_AREA
    kept = order[areas[order] >= least]
    return [np.asarray(shells[index].exterior.coords)[:-1] for index in kept]


def filled_holes(geometry: BaseGeometry) -> int:
    """How many holes of ``DEGENERATE_AREA`` to `HOLE_AREA` px² ``outline_parts`` fills (larger
    ones are cut round)."""
    holes = [shapely.Polygon(ring) for part in _polygons_in(geometry) for ring in part.interiors]
    return sum(1 for hole in holes if DEGENERATE_AREA <= hole.area < HOLE_AREA)


def hole_free_pieces(polygon: shapely.Polygon, cuts: int = MAX_CUTS) -> list[shapely.Polygon]:
    """``polygon`` as polygons without holes that paint the same area together: cut across its
    largest hole of `HOLE_AREA` px² or more (along the hole's shorter side, through the middle
    of its bounds), each side reaching `CUT_OVERLAP` px over the cut, then each side the same
    way. Smaller holes, any left after ``cuts`` cuts, and one a cut misses, are filled."""
    holes = [shapely.Polygon(ring) for ring in polygon.interiors]
    large = [hole for hole in holes if hole.area >= HOLE_AREA]
    if not large or cuts <= 0:
        return [shapely.Polygon(polygon.exterior)]
    hole = max(large, key=lambda candidate: candidate.area)
    pieces = [part for side in _sides(polygon, hole) for part in _polygons_in(side)]
    inside = hole.point_on_surface()
    if any(shapely.Polygon(ring).contains(inside) for piece in pieces for ring in piece.interiors):
        # The cut missed (it cannot in exact arithmetic: the hole is at least 2 px across the
        # cut): that hole alone is filled, and the others are cut round as usual.
        others = [ring for ring in polygon.interiors if not shapely.Polygon(ring).equals(hole)]
        return hole_free_pieces(shapely.Polygon(polygon.exterior, others), cuts - 1)
    budget = (cuts - 1) // max(1, len(pieces))
    return [whole for piece in pieces for whole in hole_free_pieces(piece, budget)]


def _sides(polygon: shapely.Polygon, hole: shapely.Polygon) -> list[BaseGeometry]:
    """``polygon`` on either side of a line across ``hole``'s middle (vertical when the hole is
    wider than tall), each side overlapping the line by `CUT_OVERLAP`."""
    left, bottom, right, top = (float(value) for value in polygon.bounds)
    x0, y0, x1, y1 = (float(value) for value in hole.bounds)
    left, bottom, right, top = left - 1.0, bottom - 1.0, right + 1.0, top + 1.0
    if x1 - x0 >= y1 - y0:
        cut = (x0 + x1) / 2
        first = shapely.box(left, bottom, cut + CUT_OVERLAP, top)
        second = shapely.box(cut - CUT_OVERLAP, bottom, right, top)
    else:
        cut = (y0 + y1) / 2
        first = shapely.box(left, bottom, right, cut + CUT_OVERLAP)
        second = shapely.box(left, cut - CUT_OVERLAP, right, top)
    return [polygon.intersection(first), polygon.intersection(second)]


def path_regions(vertices: np.ndarray, vertex_offsets: np.ndarray) -> np.ndarray:
    """(P,) object array: the painted area of every polygon (see :func:`fill_region`)."""
    simple = simple_mask(vertices, vertex_offsets)
    regions = np.empty(len(simple), dtype=object)
    for index, is_simple in enumerate(simple):
        ring = vertices[vertex_offsets[index] : vertex_offsets[index + 1]]
        regions[index] = region_of(ring, bool(is_simple))
    return regions
