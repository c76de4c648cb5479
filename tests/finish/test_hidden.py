"""Hidden paths: a path wholly under opaque paths above it is removed; translucent covers and
covers below do not hide it."""

from samvg.finish import remove_hidden
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
