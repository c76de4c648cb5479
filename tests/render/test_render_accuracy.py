"""The rasterizer against real renders: resvg-py on the same SVG text, and a 16x16 supersampled
nonzero-winding reference (tests/render/render_reference.py)."""

import numpy as np
import pytest
import torch
from render_reference import (
    blob,
    random_scene,
    rectangle,
    resvg_render,
    supersampled_render,
    svg_text,
    tangle,
)

from samvg.render import rasterize

pytest.importorskip("resvg_py")

# (seed, paths, width, height)
SCENES = [
    (0, 12, 64, 64),
    (1, 24, 96, 64),
    (2, 40, 128, 128),
    (3, 64, 256, 256),
    (4, 48, 200, 320),
    (5, 96, 512, 512),
]


def render(points, colors, width, height) -> np.ndarray:
    image = rasterize(torch.tensor(points), torch.tensor(colors), width, height)
    assert image.shape == (height, width, 3)
    assert image.dtype == torch.float64
    return image.numpy()


@pytest.mark.parametrize(("seed", "n_paths", "width", "height"), SCENES)
def test_matches_resvg_and_supersampled_reference(seed, n_paths, width, height):
    rng = np.random.default_rng(seed)
    points, colors = random_scene(rng, n_paths, width, height)
    ours = render(points, colors, width, height)
    theirs = resvg_render(svg_text(points, colors, width, height))
    reference = supersampled_render(points, colors, width, height)
    assert np.abs(ours - theirs).mean() <= 1 / 255
    assert np.abs(ours - reference).mean() <= 0.5 / 255
    # The scene is not trivial: paths changed a good part of the canvas.
    assert (np.abs(reference - 1).max(axis=-1) > 0.05).mean() > 0.2


def test_each_kind_of_path_alone_matches_reference():
    rng = np.random.default_rng(11)
    width = height = 48
    cases = {
        "sub-pixel": blob(rng, 20.3, 17.6, 0.4),
        "tiny": blob(rng, 5.5, 40.2, 1.3),
        "self-intersecting": tangle(rng, 24, 24, 20),
        "left of canvas": blob(rng, -8, 20, 15),
        "right of canvas": blob(rng, 55, 20, 15),
        "above the canvas": blob(rng, 24, -5, 12),
        "below the canvas": blob(rng, 30, 50, 9),
        "covers canvas": blob(rng, 24, 24, 80),
    }
    colors = np.array([[0.2, 0.4, 0.8, 0.7]])
    for name, points in cases.items():
        ours = render(points[None], colors, width, height)
        reference = supersampled_render(points[None], colors, width, height)
        err = np.abs(ours - reference)
        assert err.mean() <= 0.5 / 255, name
        if name != "self-intersecting":  # crossings inside one pixel are approximated
            assert err.max() <= 8 / 255, name


def test_exact_area_of_polygon_pixels():
    # A triangle with straight cubic segments: coverage must be its exact area per pixel.
    a, b, c = np.array([1.25, 0.5]), np.array([6.5, 2.0]), np.array([2.0, 7.25])

    def straight(p, q):
        return [p, p + (q - p) / 3, p + 2 * (q - p) / 3]

    points = np.array(straight(a, b) + straight(b, c) + straight(c, a))[None]
    image = render(points, np.array([[0.0, 0.0, 0.0, 1.0]]), 8, 8)
    coverage = 1 - image[..., 0]
    area = 0.5 * abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
    assert coverage.sum() == pytest.approx(area, abs=1e-9)
    # Reference with many supersamples agrees pixel by pixel.
    reference = 1 - supersampled_render(points, np.array([[0, 0, 0, 1.0]]), 8, 8, ss=64)[..., 0]
    assert np.abs(coverage - reference).max() < 0.02


def test_translucent_overlap_is_straight_alpha_over():
    square = rectangle(2, 2, 8, 8)
    colors = np.array([[1.0, 0.0, 0.0, 0.5], [0.0, 0.0, 1.0, 0.25]])
    image = render(np.stack([square, square]), colors, 10, 10)
    under = np.array([1.0, 0.5, 0.5])  # red at 50 % over white
    expected = under * 0.75 + np.array([0.0, 0.0, 1.0]) * 0.25
    np.testing.assert_allclose(image[5, 5], expected, atol=1e-12)
    np.testing.assert_allclose(image[0, 0], [1, 1, 1], atol=1e-12)
    # Edge pixels: alpha applied once, times coverage (half-covered pixel at x = 1.5).
    half = rectangle(1.5, 2, 8, 8)
    edge = render(half[None], colors[:1], 10, 10)[5, 1]
    np.testing.assert_allclose(edge, [1.0, 0.75, 0.75], atol=1e-12)


def test_float32_default_and_vector_image_render():
    from samvg.vector_image import VectorImage

    rng = np.random.default_rng(5)
    points, colors = random_scene(rng, 10, 40, 30)
    image32 = rasterize(torch.tensor(points, dtype=torch.float32), torch.tensor(colors), 40, 30)
    assert image32.dtype == torch.float32
    image64 = render(points, colors, 40, 30)
    assert np.abs(image32.numpy() - image64).max() < 1e-4
    svg = svg_text(points, colors, 40, 30)
    rendered = VectorImage.from_svg(svg).render()
    assert np.abs(rendered - resvg_render(svg)).mean() <= 1 / 255


def test_list_of_paths_with_different_segment_counts():
    rng = np.random.default_rng(8)
    paths = [blob(rng, 20, 20, 10, k=3), blob(rng, 30, 25, 8, k=6), blob(rng, 12, 30, 5, k=1)]
    colors = np.array([[1, 0, 0, 0.6], [0, 1, 0, 0.6], [0, 0, 1, 0.9]])
    ours = rasterize([torch.tensor(p) for p in paths], torch.tensor(colors), 40, 40).numpy()
    reference = supersampled_render(paths, colors, 40, 40)
    assert np.abs(ours - reference).mean() <= 0.5 / 255
