"""Palette: fills snapped to n colours by area-weighted k-means in CIELAB, opacity kept."""

import numpy as np
import pytest

from samvg import InputError
from samvg.finish import snap_colours
from tests.finish.shapes import scene_of, square

COLOURS = [(0.9, 0.1, 0.1, 1.0), (0.8, 0.15, 0.1, 0.6), (0.1, 0.2, 0.9, 1.0), (0.15, 0.2, 0.8, 1.0)]


def four_colour_scene():
    return scene_of(*[(square(50 + 100 * i, 50, 80), colour) for i, colour in enumerate(COLOURS)])


def test_four_colours_snap_to_exactly_two_with_alpha_kept():
    scene = four_colour_scene()
    snapped, counts = snap_colours(scene, 2)
    rgb = snapped.colours()[:, :3]
    assert len(np.unique(rgb, axis=0)) == 2
    assert counts["palette_colours"] == 2 and counts["palette_changed"] == 4
    assert np.array_equal(snapped.colours()[:, 3], scene.colours()[:, 3])
    assert np.array_equal(rgb[0], rgb[1]) and np.array_equal(rgb[2], rgb[3])
    assert rgb[0, 0] > 0.7 and rgb[2, 2] > 0.7  # reds stay red, blues blue
    assert np.array_equal(snapped.points, scene.points)


def test_a_larger_path_pulls_its_cluster_centre_towards_itself():
    big, small = (0.9, 0.1, 0.1, 1.0), (0.7, 0.1, 0.1, 1.0)
    scene = scene_of((square(0, 0, 300), big), (square(400, 400, 20), small))
    snapped, _ = snap_colours(scene, 1)
    red = snapped.colours()[0, 0]
    assert abs(red - 0.9) < abs(red - 0.7)


def test_fewer_colours_than_asked_leave_the_scene_unchanged():
    scene = four_colour_scene()
    same, counts = snap_colours(scene, 4)
    assert same is scene
    assert counts == {"palette_colours": 4, "palette_changed": 0}


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "3", None])
def test_a_bad_colour_count_is_an_input_error(bad):
    with pytest.raises(InputError, match="number of colours"):
        snap_colours(four_colour_scene(), bad)
