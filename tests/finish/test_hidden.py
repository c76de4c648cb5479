"""Hidden paths: a path wholly under opaque paths above it is removed; translucent covers and
covers below do not hide it. An opaque lowest path over the whole canvas becomes the
background."""

from samvg.finish import FinishSettings, background_from_cover, finish_scene, remove_hidden
from samvg.scene import FlatPaint, RadialGradient, Scene
from tests.finish.shapes import BLUE, RED, ellipse, mean_abs_diff, scene_of, square


def test_a_path_under_an_opaque_cover_is_removed():
    scene = scene_of((ellipse(200, 200, 40, 30), RED), (square(100, 100, 200), BLUE))
    kept, counts = remove_hidden(scene)
    assert counts == {"hidden_removed": 1}
    assert kept.path_count == 1 and kept.paints[0].rgba == BLUE
    assert mean_abs_diff(scene, kept) < 1e-6


def test_two_opaque_halves_together_hide_the_path_below():
    scene = scene_of(
        (ellipse(200, 200, 60, 30), RED),
        (square(60, 100, 140), BLUE),
        (square(200, 100, 140), (0.1, 0.8, 0.2, 1.0)),
    )
    kept, counts = remove_hidden(scene)
    assert counts["hidden_removed"] == 1
    assert kept.path_count == 2


def test_a_translucent_cover_does_not_hide():
    scene = scene_of((ellipse(200, 200, 40, 30), RED), (square(100, 100, 200), (0, 0, 1, 0.5)))
    kept, counts = remove_hidden(scene)
    assert counts["hidden_removed"] == 0
    assert kept is scene


def test_a_path_sticking_out_or_covered_from_below_is_kept():
    scene = scene_of(
        (square(100, 100, 200), BLUE),  # below the ellipse: covers nothing
        (ellipse(200, 200, 40, 30), RED),
        (square(100, 100, 130), (0.1, 0.8, 0.2, 1.0)),  # covers the ellipse's left part only
    )
    kept, counts = remove_hidden(scene)
    assert counts["hidden_removed"] == 0
    assert kept.path_count == 3


def test_an_opaque_path_over_the_whole_canvas_becomes_the_background():
    surround = square(-4, -4, 520)  # a SAM mask of the plain surround, traced round the edge
    scene = scene_of((surround, RED), (ellipse(200, 200, 40, 30), BLUE))
    kept, counts = background_from_cover(scene)
    assert counts == {"background_from_path": 1}
    assert kept.path_count == 1 and kept.paints[0].rgba == BLUE
    assert kept.background == RED[:3]
    assert mean_abs_diff(scene, kept) < 1e-6


def test_a_gradient_over_the_whole_canvas_becomes_a_gradient_background():
    glow = RadialGradient(((0.0, (1, 1, 0)), (1.0, (0, 0, 1))), 1.0, (256.0, 256.0), 300.0)
    paths = [(square(0, 0, 512), glow), (square(100, 100, 50), FlatPaint(BLUE))]
    scene = Scene.from_paths(512, 512, paths)
    kept, counts = background_from_cover(scene)
    assert counts["background_from_path"] == 1
    assert kept.path_count == 1 and kept.background_gradient == glow
    assert mean_abs_diff(scene, kept) < 1e-6


def test_a_path_short_of_the_canvas_or_translucent_stays_a_path():
    strip_left = scene_of((square(2, 0, 510), RED), (ellipse(200, 200, 40, 30), BLUE))
    translucent = scene_of((square(-4, -4, 520), (0.9, 0.1, 0.1, 0.6)), (square(9, 9, 9), BLUE))
    for scene in (strip_left, translucent):
        kept, counts = background_from_cover(scene)
        assert counts == {"background_from_path": 0}
        assert kept is scene


def test_the_finish_pass_removes_what_the_surround_hides_and_makes_it_the_background():
    scene = scene_of(
        (ellipse(100, 100, 20, 20), BLUE),  # under the surround: hidden
        (square(-4, -4, 520), RED),
        (ellipse(300, 300, 40, 30), BLUE),
    )
    finished = finish_scene(scene)
    assert finished.counts["hidden_removed"] == 1
    assert finished.counts["background_from_path"] == 1
    assert finished.scene.path_count == 1 and finished.scene.background == RED[:3]
    assert mean_abs_diff(scene, finished.scene) < 1e-3


def test_the_finish_pass_can_leave_the_surround_a_path():
    scene = scene_of((square(-4, -4, 520), RED), (ellipse(300, 300, 40, 30), BLUE))
    finished = finish_scene(scene, FinishSettings(background_from_path=False))
    assert "background_from_path" not in finished.counts
    assert finished.scene.path_count == 2
