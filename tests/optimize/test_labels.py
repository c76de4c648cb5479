"""The scanline fill of outlines gives the pixels skimage's polygon fill gives, in paint order."""

import numpy as np
from skimage.draw import polygon

from samvg.optimize._labels import fill_outlines


def _reference(vertices: np.ndarray, offsets: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    labels = np.full(shape, -1, np.int64)
    for index in range(len(offsets) - 1):
        ring = vertices[offsets[index] : offsets[index + 1]] - 0.5  # pixel centres
        rows, cols = polygon(ring[:, 1], ring[:, 0], shape)
        labels[rows, cols] = index
    return labels


def test_random_outlines_match_skimage_pixel_for_pixel() -> None:
    rng = np.random.default_rng(11)
    rings = []
    for _ in range(12):  # star-like and self-crossing outlines, some over the canvas edge
        count = int(rng.integers(3, 40))
        angles = np.sort(rng.uniform(0, 2 * np.pi, count))
        if rng.random() < 0.3:
            rng.shuffle(angles)
        radius = rng.uniform(3, 30, count)
        centre = rng.uniform(-5, 70, 2)
        rings.append(centre + radius[:, None] * np.stack([np.cos(angles), np.sin(angles)], 1))
    vertices = np.concatenate(rings)
    offsets = np.cumsum([0] + [len(ring) for ring in rings]).astype(np.int64)
    labels = np.full((60, 72), -1, np.int64)
    fill_outlines(vertices, offsets, labels)
    expected = _reference(vertices, offsets, (60, 72))
    assert (expected >= 0).sum() > 1000
    assert np.array_equal(labels, expected)
