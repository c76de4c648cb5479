"""Bounded geometry: control points end within the canvas plus the margin; the picture holds."""

import numpy as np

from samvg.finish import bound_paths, default_margin, finish_scene, margin_box
from tests.finish.shapes import BLUE, RED, ellipse, is_simple, mean_abs_diff, scene_of, square


def inside(points: np.ndarray, box: tuple[float, float, float, float]) -> bool:
    left, top, right, bottom = box
    x, y = points[:, 0], points[:, 1]
    return bool(np.all((x >= left) & (x <= right) & (y >= top) & (y <= bottom)))


def test_a_path_reaching_x_minus_76_and_574_ends_inside_the_margin():
    # A wide ellipse whose sides and handles lie at x = -76 and 574 on a 512 canvas.
    wide = ellipse(249, 256, 325, 120)
    assert wide[:, 0].min() == -76 and wide[:, 0].max() == 574
    scene = scene_of((square(100, 100, 300), BLUE), (wide, RED))
    assert default_margin(512, 512) == 0.02 * 512
    bounded, counts = bound_paths(scene)
    box = margin_box(512, 512, 0.02 * 512)
    assert counts["bounds_clipped"] == 1 and counts["bounds_dropped"] == 0
    assert inside(bounded.points, box)
    assert all(is_simple(points) for points, _ in bounded.paths())
    assert np.array_equal(bounded.path_points(0), scene.path_points(0))
    assert mean_abs_diff(scene, bounded) < 1e-4
    finished = finish_scene(scene)
    assert inside(finished.scene.points, box)


def test_handles_outside_a_curve_inside_are_pulled_in_without_changing_it():
    bulge = np.array([[100, 300], [-150, 100], [400, -200], [300, 300], [250, 350], [150, 350]])
    scene = scene_of((bulge, RED))
    box = margin_box(512, 512, 5.0)
    bounded, counts = bound_paths(scene, margin=5.0)
    assert counts["bounds_clipped"] == 1
    assert inside(bounded.points, box)
    assert mean_abs_diff(scene, bounded) < 1e-3


def test_a_path_entirely_outside_the_canvas_is_dropped():
    scene = scene_of((square(600, 100, 50), RED), (square(100, 100, 50), BLUE))
    bounded, counts = bound_paths(scene)
    assert counts["bounds_dropped"] == 1
    assert bounded.path_count == 1 and bounded.paints[0].rgba == BLUE


def test_paths_inside_the_box_are_kept_as_they_are():
    scene = scene_of((square(-5, -5, 100), RED), (ellipse(300, 300, 100, 50), BLUE))
    bounded, counts = bound_paths(scene)
    assert bounded is scene
    assert counts == {
        "bounds_checked": 2,
        "bounds_clipped": 0,
        "bounds_split": 0,
        "bounds_dropped": 0,
        "bounds_holes_filled": 0,
    }
