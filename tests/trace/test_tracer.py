"""Tests of mask tracing: traced paths, rendered by resvg, reproduce the masks they came from."""

import io

import numpy as np
import pytest
import resvg_py
from PIL import Image

from samvg import InputError, VectorImage, VectorPath
from samvg.trace import mask_contour, select_corners, trace_components


def trace_largest(mask: np.ndarray, segments: int) -> np.ndarray:
    traced = trace_components(mask, segments, min_area=1)
    if not traced:
        raise InputError("mask is empty: nothing to trace")
    return traced[0].points


def render_with_resvg(points: np.ndarray, width: int, height: int) -> np.ndarray:
    svg = VectorImage(width, height, [VectorPath(points, (0, 0, 0, 1))]).to_svg(precision=4)
    png = resvg_py.svg_to_bytes(svg_string=svg, background="#ffffff")
    return 1.0 - np.asarray(Image.open(io.BytesIO(bytes(png))).convert("L"), np.float64) / 255.0


def iou(coverage: np.ndarray, mask: np.ndarray) -> float:
    inside = coverage > 0.5
    return (inside & mask).sum() / (inside | mask).sum()


def shapes() -> dict[str, np.ndarray]:
    yy, xx = np.mgrid[:96, :128]
    disk = (xx - 60.5) ** 2 + (yy - 50.5) ** 2 < 30**2
    square = np.zeros((96, 128), bool)
    square[20:70, 30:90] = True
    triangle = (yy > 10) & (yy < 85) & (np.abs(xx - 64) < (yy - 10) * 0.6)
    ring_with_speck = disk & ~((xx - 60.5) ** 2 + (yy - 50.5) ** 2 < 10**2)
    ring_with_speck[2:4, 2:4] = True
    return {"disk": disk, "square": square, "triangle": triangle, "ring": ring_with_speck}


@pytest.mark.parametrize("name", ["disk", "square", "triangle", "ring"])
def test_traced_path_reproduces_mask(name):
    mask = shapes()[name]
    points = trace_largest(mask, 5)
    assert points.shape == (15, 2)
    coverage = render_with_resvg(points, mask.shape[1], mask.shape[0])
    filled = shapes()["disk"] if name == "ring" else mask  # holes filled, speck dropped
    assert iou(coverage, filled) > 0.98


def test_square_corners_are_found():
    contour = mask_contour(shapes()["square"])
    corners = contour[select_corners(contour, 4)]
    expected = np.array([[30, 20], [90, 20], [90, 70], [30, 70]], float)
    for corner in expected:
        assert np.min(np.linalg.norm(corners - corner, axis=1)) < 1.5


def test_contour_is_in_pixel_coordinates():
    mask = np.zeros((10, 10), bool)
    mask[2:5, 3:7] = True  # pixels x in [3, 7), y in [2, 5)
    contour = mask_contour(mask)
    assert contour[:, 0].min() == pytest.approx(3.0)
    assert contour[:, 0].max() == pytest.approx(7.0)
    assert contour[:, 1].min() == pytest.approx(2.0)
    assert contour[:, 1].max() == pytest.approx(5.0)


def test_tiny_and_empty_masks():
    speck = np.zeros((8, 8), bool)
    speck[3, 3] = True
    points = trace_largest(speck, 5)
    assert points.shape == (15, 2) and np.all(np.isfinite(points))
    with pytest.raises(InputError, match="empty"):
        trace_largest(np.zeros((8, 8), bool), 5)
    with pytest.raises(InputError, match="two-dimensional"):
        trace_largest(np.zeros((8, 8, 3), bool), 5)
