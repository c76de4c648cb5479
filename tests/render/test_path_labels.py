"""`path_labels`: which path shows at each pixel, by the coverage the rasterizer draws."""

import numpy as np

from samvg.render import path_labels, render_scene
from samvg.scene import FlatPaint, Scene
from tests.paths import polygon, square


def test_the_top_path_owns_its_pixels_and_the_background_the_rest() -> None:
    scene = Scene.from_paths(
        32,
        24,
        [(square(4, 4, 20), FlatPaint((1, 0, 0))), (square(10, 8, 8), FlatPaint((0, 0, 1)))],
    )
    labels = path_labels(scene)
    assert labels.shape == (24, 32) and labels.dtype == np.int64
    expected = np.full((24, 32), -1)
    expected[4:24, 4:24] = 0
    expected[8:16, 10:18] = 1
    assert np.array_equal(labels, expected)


def test_a_pixel_belongs_to_a_path_when_at_least_half_of_it_is_covered() -> None:
    # x from 2.5 to 9.4: column 2 (half covered) to column 8 are in, column 9 (0.4) is out.
    outline = polygon([[2.5, 1.0], [9.4, 1.0], [9.4, 5.0], [2.5, 5.0]])
    labels = path_labels(Scene.from_paths(12, 6, [(outline, FlatPaint((0, 0, 0)))]))
    for row in range(1, 5):
        assert np.array_equal(np.flatnonzero(labels[row] == 0), np.arange(2, 9))
    assert np.all(labels[0] == -1) and np.all(labels[5] == -1)


def test_inside_its_label_a_path_is_what_the_render_shows() -> None:
    rng = np.random.default_rng(5)
    paths = [
        (square(*rng.uniform(0, 30, 2), rng.uniform(6, 20)), FlatPaint((i / 6, 0.5, 1 - i / 6)))
        for i in range(6)
    ]
    scene = Scene.from_paths(48, 40, paths)
    labels = path_labels(scene)
    image = render_scene(scene)
    colours = scene.colours()[:, :3]
    padded = np.pad(labels, 1, constant_values=-2)
    inner = np.ones(labels.shape, bool)  # pixels whose eight neighbours share their label
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            inner &= padded[1 + dy : 1 + dy + 40, 1 + dx : 1 + dx + 48] == labels
    shown = inner & (labels >= 0)
    assert shown.sum() > 300
    assert np.allclose(image[shown], colours[labels[shown]], atol=1e-6)
    assert np.allclose(image[inner & (labels < 0)], 1.0)
