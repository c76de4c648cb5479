"""Flattening: polygons within the chord tolerance of the cubics, vertices on the curve."""

import numpy as np
import shapely

from samvg.finish.flatten import FLATTEN_TOLERANCE, flatten, flatten_path, flatten_paths
from tests.finish.shapes import ellipse, figure_eight, square


def dense_samples(points: np.ndarray, per_segment: int = 2000) -> np.ndarray:
    """Points on every segment of a closed path at many parameters (the reference curve)."""
    k = len(points) // 3
    t = np.linspace(0.0, 1.0, per_segment)[:, None]
    samples = []
    for s in range(k):
        p0, p1, p2 = points[3 * s : 3 * s + 3]
        p3 = points[(3 * s + 3) % len(points)]
        u = 1 - t
        samples.append(u**3 * p0 + 3 * t * u * u * p1 + 3 * t * t * u * p2 + t**3 * p3)
    return np.concatenate(samples)


def test_every_curve_point_lies_within_the_tolerance_of_the_polygon():
    for points in (ellipse(200, 150, 180, 60), figure_eight(), ellipse(20, 20, 3, 2)):
        polygon = flatten_path(points)
        ring = shapely.LinearRing(polygon)
        distances = shapely.distance(ring, shapely.points(dense_samples(points)))
        assert distances.max() <= FLATTEN_TOLERANCE + 1e-9


def test_straight_sides_flatten_to_their_corners():
    polygon = flatten_path(square(10, 20, 30))
    assert len(polygon) >= 4
    corners = {(10.0, 20.0), (40.0, 20.0), (40.0, 50.0), (10.0, 50.0)}
    assert corners <= {tuple(np.round(v, 9)) for v in polygon}
    assert shapely.Polygon(polygon).area == 900.0


def test_packed_paths_flatten_in_order_with_their_parameters():
    a, b = square(0, 0, 10), ellipse(50, 50, 20, 10)
    points = np.concatenate([a, b])
    offsets = np.array([0, len(a), len(a) + len(b)])
    vertices, vertex_offsets = flatten_paths(points, offsets)
    assert np.allclose(vertices[vertex_offsets[1]], b[0])
    assert np.allclose(vertices[0], a[0])
    flat = flatten(points, offsets)
    # Each vertex is the point of its (segment, t); the first vertex of a segment has t = 0.
    starts = flat.t == 0
    assert np.allclose(flat.vertices[starts], points[3 * flat.segment[starts]])


def test_no_paths_flatten_to_nothing():
    vertices, vertex_offsets = flatten_paths(np.zeros((0, 2)), np.zeros(1, dtype=np.int64))
    assert vertices.shape == (0, 2)
    assert list(vertex_offsets) == [0]
