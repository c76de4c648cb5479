"""Compound paths: pieces of one paint joined into one SVG element, painting what they painted."""

from dataclasses import replace

import numpy as np

from samvg.baselines import render_svg
from samvg.finish import simplify_paths
from samvg.finish.compound import join_pieces, one_way_round, same_way_round
from samvg.finish.edits import apply_edits
from samvg.scene import FlatPaint, Scene
from samvg.svg.writer import scene_to_svg
from samvg.vector_image import VectorImage
from tests.finish.shapes import BLUE, RED, ellipse, figure_eight, mean_abs_diff, scene_of
from tests.paths import square

HALF_RED = (0.9, 0.1, 0.1, 0.5)


def _split_figure_eight(rgba: tuple[float, ...] = RED) -> Scene:
    repaired, counts = simplify_paths(scene_of((figure_eight(), rgba)))
    assert counts["simple_split"] == 1 and repaired.path_count == 2
    return repaired


def test_a_repair_s_pieces_join_into_one_element_that_resvg_draws_as_the_scene():
    pieces = _split_figure_eight()
    joined, made = join_pieces(pieces, limit=1)
    assert made == 1 and joined.element_count == 1 and joined.path_count == 2
    assert np.array_equal(joined.render(), pieces.render())
    text = scene_to_svg(joined)
    assert text.count("<path") == 1 and text.count("M") == 2
    drawn = render_svg(text, 512, 512)
    assert float(np.abs(drawn - pieces.render()).mean()) < 2e-3


def test_pieces_join_only_as_far_as_the_limit_asks():
    pieces = _split_figure_eight()
    assert join_pieces(pieces, limit=2) == (pieces, 0)


def test_pieces_of_another_paint_or_translucent_overlapping_pieces_stay_apart():
    two_colours = scene_of((ellipse(100, 100, 40, 30), RED), (ellipse(300, 300, 40, 30), BLUE))
    assert join_pieces(two_colours, limit=1)[1] == 0
    overlapping = scene_of(
        (ellipse(100, 100, 40, 30), HALF_RED), (ellipse(130, 100, 40, 30), HALF_RED)
    )
    assert join_pieces(overlapping, limit=1)[1] == 0
    apart = scene_of((ellipse(100, 100, 40, 30), HALF_RED), (ellipse(300, 100, 40, 30), HALF_RED))
    assert join_pieces(apart, limit=1)[1] == 1


def test_opaque_overlapping_pieces_drawn_either_way_round_paint_their_union():
    forward = ellipse(100, 100, 40, 30)
    backward = np.concatenate([forward[:1], forward[:0:-1]])[:] + [30.0, 0.0]
    assert not one_way_round([forward, backward])
    turned = same_way_round([forward, backward])
    assert one_way_round(turned) and np.array_equal(turned[0], forward)
    scene = scene_of((forward, RED), (backward, RED), size=200)
    joined, made = join_pieces(scene, limit=1)
    assert made == 1
    drawn = render_svg(scene_to_svg(joined), 200, 200)
    assert float(np.abs(drawn - scene.render()).mean()) < 2e-3  # no hole where they overlap


def test_joins_survive_subsets_and_edits_while_the_path_below_stays():
    paths = [(square(10 + 30 * i, 10, 20), FlatPaint(RED)) for i in range(4)]
    scene = replace(Scene.from_paths(200, 200, paths), joined=np.array([False, True, True, False]))
    assert [list(element) for element in scene.elements()] == [[0, 1, 2], [3]]
    assert scene.subset([0, 2, 3]).element_count == 2
    assert scene.subset([1, 2, 3]).element_count == 2  # the first piece gone, the rest stays one
    dropped_first = apply_edits(scene, {0: []})
    assert [list(element) for element in dropped_first.elements()] == [[0, 1], [2]]
    split = apply_edits(scene, {1: [paths[1], paths[1]]})
    # the part split off stands alone, and so does the path after it: [0, 1] [1'] [2] [3]
    assert split.path_count == 5 and split.element_count == 4


def test_a_compound_path_reads_back_as_the_same_elements():
    joined, _ = join_pieces(_split_figure_eight(), limit=1)
    image = VectorImage.from_scene(joined)
    again = VectorImage.from_svg(image.to_svg())
    assert again.scene.element_count == 1 and again.scene.path_count == 2
    assert mean_abs_diff(again.scene, joined) < 1e-3
