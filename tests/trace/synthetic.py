"""Synthetic masks for testing and benchmarking the tracer: disks, ellipses, rounded rectangles,
smooth blobs, L-shapes, stars and random wavy blobs, plus the IoU of a rendered path against a
mask."""

from __future__ import annotations

import numpy as np

from samvg.vector_image import VectorImage, VectorPath


def _grid(size: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel-centre coordinates (x, y) of a size × size canvas."""
    yy, xx = np.mgrid[:size, :size] + 0.5
    return xx, yy


def _rotated(
    xx: np.ndarray, yy: np.ndarray, cx: float, cy: float, degrees: float
) -> tuple[np.ndarray, np.ndarray]:
    angle = np.deg2rad(degrees)
    u, v = xx - cx, yy - cy
    return np.cos(angle) * u + np.sin(angle) * v, -np.sin(angle) * u + np.cos(angle) * v


def disk(size: int = 128) -> np.ndarray:
    xx, yy = _grid(size)
    return (xx - 0.5 * size - 0.3) ** 2 + (yy - 0.5 * size + 0.2) ** 2 < (0.32 * size) ** 2


def ellipse(size: int = 128) -> np.ndarray:
    u, v = _rotated(*_grid(size), 0.5 * size, 0.5 * size, 30.0)
    return (u / (0.4 * size)) ** 2 + (v / (0.2 * size)) ** 2 < 1.0


def rounded_rectangle(size: int = 128, degrees: float = 15.0) -> np.ndarray:
    u, v = _rotated(*_grid(size), 0.5 * size, 0.5 * size, degrees)
    half_w, half_h, radius = 0.33 * size, 0.2 * size, 0.08 * size
    du = np.maximum(np.abs(u) - (half_w - radius), 0.0)
    dv = np.maximum(np.abs(v) - (half_h - radius), 0.0)
    return du**2 + dv**2 < radius**2


def blob(size: int = 128) -> np.ndarray:
    xx, yy = _grid(size)
    u, v = xx - 0.5 * size, yy - 0.5 * size
    theta = np.arctan2(v, u)
    radius = 0.3 * size * (1.0 + 0.12 * np.sin(2 * theta + 1.0) + 0.06 * np.cos(3 * theta))
    return u**2 + v**2 < radius**2


def l_shape(size: int = 128) -> np.ndarray:
    mask = np.zeros((size, size), dtype=bool)
    low, high, notch = round(0.15 * size), round(0.85 * size), round(0.45 * size)
    mask[low:high, low:high] = True
    mask[low:notch, notch:high] = False
    return mask


def star(size: int = 128, points: int = 5) -> np.ndarray:
    """A regular star (outer radius 0.4 size, inner 0.18 size) with ``points`` tips."""
    xx, yy = _grid(size)
    u, v = xx - 0.5 * size, yy - 0.5 * size
    angles = np.pi * np.arange(2 * points) / points - np.pi / 2
    radii = np.where(np.arange(2 * points) % 2 == 0, 0.4 * size, 0.18 * size)
    vertices = np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)
    inside = np.zeros((size, size), dtype=bool)
    for k in range(len(vertices)):  # even-odd ray casting over the polygon's edges
        (x0, y0), (x1, y1) = vertices[k], vertices[(k + 1) % len(vertices)]
        crosses = (y0 > v) != (y1 > v)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_at = x0 + (v - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (u < x_at)
    return inside


def random_blobs(count: int, size: int = 512, seed: int = 0) -> np.ndarray:
    """``count`` wavy blobs (radius 8-150 px, three lobes) at random places: (count, size, size)."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:size, :size]
    masks = np.empty((count, size, size), dtype=bool)
    for index in range(count):
        cx, cy = rng.uniform(0.12 * size, 0.88 * size, 2)
        angle = np.arctan2(yy - cy, xx - cx)
        radius = rng.uniform(8, 150) * (1 + 0.2 * np.sin(3 * angle + rng.uniform(0, 6)))
        masks[index] = (xx - cx) ** 2 + (yy - cy) ** 2 < radius**2
    return masks


SHAPES = {
    "disk": disk,
    "ellipse": ellipse,
    "rounded_rectangle": rounded_rectangle,
    "blob": blob,
    "l_shape": l_shape,
    "star": star,
}


def render_coverage(points_list: list[np.ndarray], width: int, height: int) -> np.ndarray:
    """Coverage in [0, 1] of the union of closed paths, by the project's exact-area rasterizer."""
    paths = [VectorPath(points, (0.0, 0.0, 0.0, 1.0)) for points in points_list]
    image = VectorImage(width, height, paths).render()
    return 1.0 - image[..., 0].astype(np.float64)


def iou(coverage: np.ndarray, mask: np.ndarray) -> float:
    """Intersection over union of ``coverage > 0.5`` and a boolean mask (1.0 if both empty)."""
    inside = coverage > 0.5
    union = int((inside | mask).sum())
    return 1.0 if union == 0 else int((inside & mask).sum()) / union
