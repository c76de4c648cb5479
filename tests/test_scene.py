"""The scene type: ragged packed paths, paints, background and the frame to input pixels."""

from dataclasses import replace

import numpy as np
import pytest

from samvg import InputError
from samvg.scene import FlatPaint, Frame, Scene
from tests.paths import square, triangle


def test_paths_of_any_length_pack_and_unpack():
    red, blue = FlatPaint((1, 0, 0)), FlatPaint((0, 0, 1, 0.5))
    scene = Scene.from_paths(20, 10, [(triangle(1, 1, 5), red), (square(8, 2, 6), blue)])
    assert scene.path_count == 2 and list(scene.segment_counts()) == [3, 4]
    assert list(scene.offsets) == [0, 9, 21] and scene.points.shape == (21, 2)
    np.testing.assert_array_equal(scene.path_points(1), square(8, 2, 6))
    np.testing.assert_array_equal(scene.colours(), [[1, 0, 0, 1], [0, 0, 1, 0.5]])
    assert scene.parameter_count == (6 * 3 + 4) + (6 * 4 + 4)
    top = scene.subset([1])
    assert top.path_count == 1 and top.paints == (blue,)
    both = scene.stacked(top)
    assert list(both.offsets) == [0, 9, 21, 33]


def test_render_draws_each_path_with_its_paint():
    scene = Scene.from_paths(
        20, 10, [(square(0, 0, 10), FlatPaint((1, 0, 0)))], background=(0.0, 0.0, 1.0)
    )
    pixels = scene.render()
    np.testing.assert_allclose(pixels[5, 5], (1, 0, 0), atol=1e-6)
    np.testing.assert_allclose(pixels[5, 15], (0, 0, 1), atol=1e-6)
    assert scene.render(scale=2).shape == (20, 40, 3)


def test_frame_maps_working_pixels_to_input_pixels():
    scene = Scene.from_paths(
        50, 25, [(square(10, 5, 10), FlatPaint((0, 0, 0)))], frame=Frame(100, 50, 0.5)
    )
    out = scene.in_input_pixels()
    assert (out.width, out.height, out.frame) == (100, 50, None)
    np.testing.assert_allclose(out.points, scene.points * 2)


def test_a_scene_drawn_at_half_size_on_a_smaller_canvas():
    from samvg.scene import RadialGradient

    glow = RadialGradient(((0.0, (1, 1, 0)), (1.0, (0, 0, 1))), 1.0, (20.0, 10.0), 8.0)
    scene = Scene.from_paths(41, 21, [(square(10, 4, 20), glow)], frame=Frame(82, 42, 0.5))
    half = scene.on_canvas(21, 11, 0.5)
    assert (half.width, half.height, half.frame) == (21, 11, scene.frame)
    np.testing.assert_allclose(half.points, scene.points / 2)
    assert half.paints[0].centre == (10.0, 5.0) and half.paints[0].radius == 4.0
    np.testing.assert_allclose(half.render(), scene.render()[::2, ::2][:11, :21], atol=0.3)


def test_bad_scenes_are_refused():
    with pytest.raises(InputError, match="non-finite"):
        Scene.from_paths(8, 8, [(np.full((3, 2), np.nan), FlatPaint((0, 0, 0)))])
    with pytest.raises(InputError, match="3K"):
        Scene(8, 8, np.zeros((4, 2)), np.array([0, 4]), (FlatPaint((0, 0, 0)),))
    with pytest.raises(InputError, match="paints"):
        Scene(8, 8, np.zeros((3, 2)), np.array([0, 3]), ())
    with pytest.raises(InputError, match="RGBA"):
        FlatPaint((1.5, 0, 0))
    with pytest.raises(InputError, match="width"):
        Scene(0, 8)


def test_a_background_gradient_is_kept_by_every_derived_scene():
    from dataclasses import replace

    from samvg.finish import FinishSettings, finish_scene
    from samvg.optimize.reshape import reshape_scene
    from samvg.scene import LinearGradient

    ramp = LinearGradient(((0.0, (1, 0, 0)), (1.0, (0, 0, 1))), 1.0, (4.0, 2.0), (36.0, 18.0))
    red, blue = FlatPaint((1, 0, 0)), FlatPaint((0, 0, 1, 0.5))
    scene = Scene.from_paths(
        40, 20, [(triangle(1, 1, 5), red), (square(8, 2, 6), blue)],
        frame=Frame(80, 40, 0.5), background_gradient=ramp,
    )  # fmt: skip
    assert scene.background == (0.5, 0.0, 0.5)  # the flat stand-in: the mean stop colour
    assert scene.parameter_count == (6 * 3 + 4) + (6 * 4 + 4) + 9  # 9 over a flat colour
    kept = [
        scene.subset([1]),
        scene.with_paths([]),
        scene.with_geometry(scene.points + 1),
        scene.with_geometry(scene.points, np.ones((2, 4))),
        scene.stacked(scene),
        replace(scene, background=(0, 1, 0)),  # the stand-in follows the gradient
        finish_scene(scene, FinishSettings(colours=1)).scene,
        reshape_scene(scene, 0.5, 8, (-4, -4, 44, 24))[0],
    ]
    for derived in kept:
        assert derived.background_gradient == ramp and derived.background == scene.background
    big = scene.in_input_pixels()
    assert big.background_gradient == ramp.scaled(2.0) and big.frame is None
    assert scene.on_canvas(20, 10, 0.5).background_gradient == ramp.scaled(0.5)
    flat = scene.with_background((0, 1, 0))
    assert flat.background_gradient is None and flat.background == (0.0, 1.0, 0.0)
    rendered = Scene(40, 20, background_gradient=ramp).render()
    assert rendered[10, 0, 0] > 0.9 and rendered[10, -1, 2] > 0.9  # red to blue, left to right


def test_fixed_outlines_follow_their_paths():
    one = Scene.from_paths(32, 32, [(square(2, 2, 8), FlatPaint((1.0, 0.0, 0.0)))])
    free = Scene.from_paths(32, 32, [(square(12, 12, 8), FlatPaint((0.0, 0.0, 1.0)))] * 2)
    stacked = free.stacked(one.with_fixed_outlines())
    assert list(stacked.fixed_paths()) == [False, False, True]
    assert list(stacked.subset([2, 0]).fixed_paths()) == [True, False]
    assert stacked.subset([0, 1]).fixed is None
    assert stacked.with_geometry(stacked.points + 1).fixed is not None
    assert stacked.with_paths(list(stacked.paths())).fixed is None
    with pytest.raises(InputError, match="3 paths but 2 fixed flags"):
        replace(stacked, fixed=np.array([True, False]))


def test_fixed_flags_survive_an_edit_that_leaves_the_path_as_it_was():
    red, blue = FlatPaint((1.0, 0.0, 0.0)), FlatPaint((0.0, 0.0, 1.0))
    before = Scene.from_paths(32, 32, [(square(2, 2, 8), red), (square(12, 12, 8), blue)])
    before = replace(before, fixed=np.array([True, True]))
    edited = before.with_paths([(square(12, 12, 8), blue), (square(3, 2, 8), red)])
    assert edited.fixed is None
    assert list(edited.with_fixed_from(before).fixed_paths()) == [True, False]
    assert edited.with_fixed_from(edited).fixed is None


def test_a_window_renders_as_that_rectangle_of_the_whole_render():
    from samvg.scene import LinearGradient, RadialGradient

    ramp = LinearGradient(((0.0, (1, 0, 0)), (1.0, (0, 0, 1))), 1.0, (4.0, 2.0), (36.0, 18.0))
    glow = RadialGradient(((0.0, (1, 1, 0)), (1.0, (0, 1, 0))), 1.0, (14.0, 9.0), 6.0)
    shade = LinearGradient(((0.0, (0, 0, 0)), (1.0, (1, 1, 1))), 0.7, (20.0, 4.0), (30.0, 16.0))
    paths = [
        (triangle(1, 1, 9), FlatPaint((0.2, 0.6, 0.3))),
        (square(8, 3, 12), glow),
        (square(19, 2, 14), shade),
    ]
    scene = Scene.from_paths(40, 20, paths, background_gradient=ramp)
    whole = scene.render()
    window = scene.window(5, 3, 24, 13)
    assert (window.width, window.height) == (24, 13)
    assert np.allclose(window.render(), whole[3:16, 5:29], atol=1e-5)
    boxes = scene.path_boxes()
    for index, (points, _) in enumerate(scene.paths()):
        assert np.allclose(boxes[index], [*points.min(axis=0), *points.max(axis=0)])
    assert Scene(4, 4).path_boxes().shape == (0, 4)


def test_a_scene_without_paths_has_no_elements():
    assert Scene(4, 4).elements() == [] and Scene(4, 4).element_count == 0
