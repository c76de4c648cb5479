"""Simple paths: crossing outlines are found and replaced by simple paths painting the same."""

import numpy as np

from samvg.finish import crossing_paths, finish_scene, simplify_paths
from samvg.finish.cubics import cubics_of, path_of, straight_path
from samvg.finish.flatten import flatten_path
from samvg.finish.outline import fill_region
from tests.finish.shapes import (
    BLUE,
    RED,
    bow_tie,
    ellipse,
    figure_eight,
    is_simple,
    mean_abs_diff,
    scene_of,
)


def test_a_figure_eight_is_detected_and_finished_into_simple_paths_drawing_the_same():
    scene = scene_of((figure_eight(), RED))
    assert list(crossing_paths(scene)) == [0]
    assert not is_simple(scene.path_points(0))
    finished = finish_scene(scene)
    assert finished.counts["simple_repaired"] == 1
    assert finished.counts["simple_split"] == 1
    assert finished.scene.path_count == 2
    assert all(is_simple(points) for points, _ in finished.scene.paths())
    assert len(crossing_paths(finished.scene)) == 0
    assert mean_abs_diff(scene, finished.scene) < 1e-3


def test_a_crossing_inside_a_segment_splits_the_bow_tie_into_two_triangles():
    scene = scene_of((ellipse(400, 400, 50, 30), BLUE), (bow_tie(), RED))
    repaired, counts = simplify_paths(scene)
    assert counts == {
        "simple_checked": 2,
        "simple_repaired": 1,
        "simple_split": 1,
        "simple_dropped": 0,
        "simple_holes_filled": 0,
    }
    assert repaired.path_count == 3
    assert np.array_equal(repaired.path_points(0), scene.path_points(0))
    assert [paint.rgba for paint in repaired.paints] == [BLUE, RED, RED]
    assert all(is_simple(points) for points, _ in repaired.paths())
    assert mean_abs_diff(scene, repaired) < 1e-3


def test_a_curl_painted_twice_under_the_nonzero_rule_stays_filled():
    # Twice round an ellipse, the second time a little larger: winding 2 inside, 1 in the band.
    inner, outer = ellipse(256, 256, 100, 60), ellipse(256, 256, 110, 70)
    twice = np.concatenate([inner, outer])
    scene = scene_of((twice, RED))
    region = fill_region(flatten_path(twice))
    assert region.area > 0.99 * np.pi * 110 * 70
    repaired, counts = simplify_paths(scene)
    assert counts["simple_repaired"] == 1
    assert all(is_simple(points) for points, _ in repaired.paths())
    assert mean_abs_diff(scene, repaired) < 1e-3


def test_simple_paths_are_left_alone():
    scene = scene_of((ellipse(200, 200, 80, 40), RED), (ellipse(250, 220, 30, 90), BLUE))
    repaired, counts = simplify_paths(scene)
    assert repaired is scene
    assert counts["simple_repaired"] == counts["simple_split"] == 0


def test_a_collapsed_path_is_dropped():
    flat = np.array([[10, 10], [20, 10], [30, 10], [40, 10], [50, 10], [60, 10]], float)
    scene = scene_of((flat, RED), (ellipse(200, 200, 50, 50), BLUE))
    repaired, counts = simplify_paths(scene)
    assert counts["simple_dropped"] == 1
    assert repaired.path_count == 1
    assert repaired.paints[0].rgba == BLUE


def test_a_hole_a_path_loops_round_is_cut_round_not_painted_over():
    # Round an ellipse one way, across to a smaller one, round it the other way and back: the
    # two crossings cancel, and the inner ellipse is a hole (winding number 0) that shows the
    # blue path beneath.
    outer = cubics_of(ellipse(256, 256, 150, 100))
    inner = cubics_of(ellipse(256.5, 256, 60, 40))[::-1, ::-1]  # cut at x = 256.5, mid-pixel
    across = straight_path(np.array([[406.0, 256.0], [316.5, 256.0]]))
    there = np.append(across[:3], [[316.5, 256.0]], axis=0)
    back = np.append(across[3:], [[406.0, 256.0]], axis=0)
    ring = path_of(np.concatenate([outer, there[None], inner, back[None]]))
    scene = scene_of((ellipse(256, 256, 70, 50), BLUE), (ring, RED))
    region = fill_region(flatten_path(ring))
    assert len(region.interiors) == 1
    repaired, counts = simplify_paths(scene)
    assert counts["simple_repaired"] == 1 and counts["simple_holes_filled"] == 0
    assert repaired.path_count >= 3 and len(crossing_paths(repaired)) == 0
    before, after = scene.render(), repaired.render()
    assert np.allclose(after[256, 256], BLUE[:3], atol=1e-3)  # the hole still shows blue
    assert np.allclose(after[180, 256], RED[:3], atol=1e-3)  # no seam where the cut runs
    assert np.abs(after - before).mean() < 1e-3
