"""Merging: touching paths of near-equal colour become one where the picture allows it."""

import numpy as np
import shapely

from samvg.finish import merge_paths
from tests.finish.shapes import BLUE, RED, ellipse, is_simple, mean_abs_diff, scene_of, square


def test_two_touching_red_squares_merge_into_one_path_drawing_the_same():
    scene = scene_of((square(100, 100, 100), RED), (square(200, 100, 100), RED))
    merged, counts = merge_paths(scene)
    assert counts == {"merged": 1}
    assert merged.path_count == 1
    assert merged.paints[0].rgba == RED
    assert is_simple(merged.path_points(0))
    assert mean_abs_diff(scene, merged) < 1 / 255


def test_a_blue_square_painted_between_them_prevents_the_merge():
    between = square(150, 150, 100)  # overlaps both red squares
    scene = scene_of((square(100, 100, 100), RED), (between, BLUE), (square(200, 100, 100), RED))
    merged, counts = merge_paths(scene)
    assert counts == {"merged": 0}
    assert merged is scene


def test_a_path_between_them_elsewhere_does_not_prevent_it():
    scene = scene_of(
        (square(100, 100, 100), RED), (square(350, 350, 50), BLUE), (square(200, 100, 100), RED)
    )
    merged, counts = merge_paths(scene)
    assert counts["merged"] == 1
    assert merged.path_count == 2
    assert [p.rgba for p in merged.paints] == [BLUE, RED]
    assert mean_abs_diff(scene, merged) < 1 / 255


def test_overlapping_curved_paths_of_nearly_one_colour_merge_on_their_own_curves():
    near_red = (0.9, 0.1, 0.105, 1.0)
    scene = scene_of((ellipse(200, 200, 80, 50), RED), (ellipse(280, 220, 60, 60), near_red))
    merged, counts = merge_paths(scene)
    assert counts["merged"] == 1
    assert is_simple(merged.path_points(0))
    assert merged.segment_counts()[0] <= 10  # pieces of the two ellipses' cubics
    assert mean_abs_diff(scene, merged) < 1 / 255


def test_different_colours_paths_apart_or_meeting_at_a_point_do_not_merge():
    scene = scene_of(
        (square(100, 100, 100), RED),
        (square(200, 100, 100), BLUE),  # touches but another colour
        (square(100, 300, 50), RED),  # same colour, 50 px away from every red path
        (square(150, 350, 50), RED),  # meets the one before at a corner only
    )
    merged, counts = merge_paths(scene)
    assert counts["merged"] == 0
    assert np.array_equal(merged.points, scene.points)


def test_translucent_paths_merge_only_where_they_do_not_overlap():
    pink = (0.9, 0.1, 0.1, 0.5)
    touching = scene_of((square(100, 100, 100), pink), (square(200, 100, 100), pink))
    overlapping = scene_of((square(100, 100, 100), pink), (square(150, 100, 100), pink))
    assert merge_paths(touching)[1]["merged"] == 1
    assert merge_paths(overlapping)[1]["merged"] == 0


def test_a_topology_error_in_geos_leaves_the_pair_unmerged(monkeypatch):
    def fails(*_args, **_kwargs):
        raise shapely.errors.GEOSException("TopologyException: side location conflict")

    monkeypatch.setattr(shapely, "intersection", fails)
    scene = scene_of((square(100, 100, 100), RED), (square(200, 100, 100), RED))
    merged, counts = merge_paths(scene)
    assert counts == {"merged": 0}
    assert np.array_equal(merged.points, scene.points)
