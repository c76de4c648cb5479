"""Stage 4 under a path limit: a round adds at most the room ``max_paths`` leaves, keeping the
masks with the largest impact, and asks SAM nothing when the scene is full."""

import numpy as np

from samvg.missing import MissingSettings, add_missing, missing_masks
from samvg.missing.stage import room_left
from samvg.optimize import FitSettings
from samvg.scene import FlatPaint, Scene
from samvg.trace.stage import TraceSettings

SQUARES = {(5, 5): 20, (40, 5): 14, (5, 40): 8}  # top-left corner: side in pixels


class FakeSegmenter:
    """SAM's stand-in: at each prompt, the one square that holds it."""

    def __init__(self) -> None:
        self.prompted = 0

    def prompt(self, points: np.ndarray) -> list[list[np.ndarray]]:
        self.prompted += len(points)
        answers = []
        for x, y in points:
            mask = np.zeros((64, 64), bool)
            for (left, top), side in SQUARES.items():
                if left <= x < left + side and top <= y < top + side:
                    mask[top : top + side, left : left + side] = True
            answers.append([mask])
        return answers


def target() -> np.ndarray:
    image = np.ones((64, 64, 3), np.float32)
    for (left, top), side in SQUARES.items():
        image[top : top + side, left : left + side] = (0.1, 0.2, 0.7)
    return image


def settings(max_paths: int | None) -> MissingSettings:
    return MissingSettings(
        radius=1.0,
        threshold=0.5,
        impact_threshold=0.0,
        filter_by_impact=True,
        min_pixels=4,
        rounds=1,
        max_paths=max_paths,
    )


def corner_scene(paths: int) -> Scene:
    square = np.array([[0, 0], [1, 0], [2, 0], [2, 0], [2, 1], [2, 2],
                       [2, 2], [1, 2], [0, 2], [0, 2], [0, 1], [0, 0]], float)  # fmt: skip
    return Scene.from_paths(64, 64, [(square, FlatPaint((1.0, 1.0, 1.0)))] * paths)


PROMPTS = np.array([[10.0, 10.0], [45.0, 10.0], [10.0, 45.0]])


def test_missing_masks_keep_the_largest_impact_within_the_limit():
    white = np.ones((64, 64, 3), np.float32)
    every, marks = missing_masks(FakeSegmenter(), PROMPTS, target(), white, settings(None))
    assert marks == []
    assert [int(mask.sum()) for mask in every] == [400, 196, 64]
    two, _ = missing_masks(FakeSegmenter(), PROMPTS, target(), white, settings(None), limit=2)
    assert [int(mask.sum()) for mask in two] == [400, 196]  # the two that remove most error


def test_room_left_counts_the_paths_already_there():
    assert room_left(corner_scene(3), settings(None)) is None
    assert room_left(corner_scene(3), settings(5)) == 2
    assert room_left(corner_scene(7), settings(5)) == 0


def test_a_full_scene_asks_sam_nothing_and_adds_nothing():
    segmenter = FakeSegmenter()
    scene = corner_scene(2)
    fit = FitSettings(steps=0)
    done = add_missing(scene, target(), segmenter, settings(2), TraceSettings(5, 4), fit)
    assert segmenter.prompted == 0 and done.added == 0 and done.scene.path_count == 2
    assert len(done.prompts) >= 1  # the error map and its prompts are still reported


def test_a_round_adds_at_most_the_room_left():
    segmenter = FakeSegmenter()
    fit = FitSettings(steps=0)
    done = add_missing(corner_scene(1), target(), segmenter, settings(3), TraceSettings(5, 4), fit)
    assert segmenter.prompted >= 3 and done.added == 2 and done.scene.path_count == 3
