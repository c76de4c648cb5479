"""Paths saved in whole pixels where rounding changes the picture by less than a tolerance."""

import numpy as np

from samvg.finish import crossing_paths
from samvg.finish.whole_pixels import whole_pixel_paths
from samvg.optimize.reduce import IDLE_COST
from samvg.scene import FlatPaint, Scene
from tests.paths import polygon, square

FAINT = FlatPaint((0.99, 0.99, 0.99))  # on white: moving its edge by half a pixel shows nowhere
BLACK = FlatPaint((0.0, 0.0, 0.0))


def faint_and_sharp() -> Scene:
    """A large faint square and a small black one, both off the pixel grid."""
    paths = [(square(10.3, 10.3, 60.2), FAINT), (square(90.4, 90.4, 6.3), BLACK)]
    return Scene.from_paths(128, 128, paths, background=(1.0, 1.0, 1.0))


def test_a_faint_path_is_rounded_and_a_sharp_small_one_keeps_its_decimals():
    scene = faint_and_sharp()
    rounded, count = whole_pixel_paths(scene, (128, 128, 1.0), budget=1.0)
    assert count == 1
    assert np.array_equal(rounded.path_points(0), np.rint(scene.path_points(0)))
    assert np.array_equal(rounded.path_points(1), scene.path_points(1))
    assert np.mean((rounded.render() - scene.render()) ** 2) < IDLE_COST


def test_nothing_is_rounded_beyond_the_budget():
    scene = faint_and_sharp()
    change = np.mean((scene.with_geometry(np.rint(scene.points)).subset([0]).render()
                      - scene.subset([0]).render()) ** 2)  # fmt: skip
    assert change > 0
    assert whole_pixel_paths(scene, (128, 128, 1.0), budget=change / 2) == (scene, 0)
    assert whole_pixel_paths(scene, (128, 128, 1.0), budget=change * 2)[1] == 1


def test_the_change_is_measured_on_the_working_canvas():
    """The SVG at twice the working size: the sharp square's rounding moves its edge a quarter
    of a working pixel at most, still too much; the faint one is rounded in the SVG's pixels."""
    scene = faint_and_sharp()
    large = scene.on_canvas(256, 256, 2.0).with_geometry(scene.points * 2 + 0.3)
    rounded, count = whole_pixel_paths(large, (128, 128, 0.5), budget=1.0)
    assert count == 1
    assert np.array_equal(rounded.path_points(0), np.rint(large.path_points(0)))


def test_a_path_that_rounding_makes_cross_itself_keeps_its_decimals():
    sliver = polygon(np.array([[0, 0], [10, 0], [10, 0.6], [5, 0.4]]) + [20, 20])
    scene = Scene.from_paths(64, 64, [(sliver, FAINT)], background=(1.0, 1.0, 1.0))
    assert len(crossing_paths(scene.with_geometry(np.rint(scene.points)))) == 1
    assert whole_pixel_paths(scene, (64, 64, 1.0), budget=1.0) == (scene, 0)


def test_a_scene_already_in_whole_pixels_is_returned_as_it_is():
    scene = Scene.from_paths(64, 64, [(square(3, 3, 30), BLACK)], background=(1.0, 1.0, 1.0))
    scene = scene.with_geometry(np.rint(scene.points))
    assert whole_pixel_paths(scene, (64, 64, 1.0), budget=1.0) == (scene, 0)


def test_paths_measured_together_are_rounded_as_if_measured_one_by_one():
    """Thirty squares from faint to dark, some overlapping: batches share one render, yet each
    square is rounded exactly when rounding it alone changes the picture by under the
    tolerance."""
    paths = []
    for number in range(30):
        grey = 1.0 - 0.03 * number
        left = 6.3 + 19.0 * (number % 6) + (4.0 if number % 4 == 0 else 0.0)
        top = 5.4 + 24.0 * (number // 6)
        paths.append((square(left, top, 14.3 + 0.1 * number), FlatPaint((grey, grey, grey))))
    scene = Scene.from_paths(128, 128, paths, background=(1.0, 1.0, 1.0))
    whole = np.rint(scene.points)
    picture = scene.render()
    expected = []
    for index in range(scene.path_count):
        points = scene.points.copy()
        start, end = scene.offsets[index], scene.offsets[index + 1]
        points[start:end] = whole[start:end]
        if np.mean((scene.with_geometry(points).render() - picture) ** 2) < IDLE_COST:
            expected.append(index)
    assert 0 < len(expected) < scene.path_count
    rounded, count = whole_pixel_paths(scene, (128, 128, 1.0), budget=1.0)
    changed = [
        index
        for index in range(scene.path_count)
        if not np.array_equal(rounded.path_points(index), scene.path_points(index))
    ]
    assert changed == expected and count == len(expected)
