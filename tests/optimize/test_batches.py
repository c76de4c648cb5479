"""Idle edits measured in batches give what measuring them one by one gives."""

import numpy as np

from samvg.optimize.batches import (
    disjoint_batches,
    packed_batches,
    padded_windows,
    smallest_changes_in_batches,
)
from samvg.optimize.reduce import IDLE_COST, WINDOW_PAD, collapsed_paths, smallest_changes_first
from samvg.scene import FlatPaint, Scene
from tests.paths import square


def meet(first: np.ndarray, second: np.ndarray) -> bool:
    return bool(
        first[0] < second[2]
        and second[0] < first[2]
        and first[1] < second[3]
        and second[1] < first[3]
    )


def random_windows(count: int, size: int, seed: int) -> np.ndarray:
    generator = np.random.default_rng(seed)
    low = generator.integers(0, size - 8, size=(count, 2))
    sides = generator.integers(1, 40, size=(count, 2))
    return np.concatenate([low, np.minimum(low + sides, size)], axis=1)


def test_windows_of_one_batch_never_meet_and_order_is_kept_where_they_do():
    windows = random_windows(300, 128, seed=1)
    layered = disjoint_batches(windows, 128, 128)
    packed = packed_batches(windows, 128, 128)
    for first in range(len(windows)):
        for second in range(first + 1, len(windows)):
            if meet(windows[first], windows[second]):
                assert layered[first] < layered[second]
                assert packed[first] != packed[second]
    assert packed.max() < layered.max()  # first fit packs tighter where order is free


def test_windows_are_whole_pixels_padded_and_cut_to_the_canvas():
    windows = padded_windows(
        np.array([[200.0, 200.0, 220.0, 230.0], [3.2, 4.7, 9.1, 9.9]]), 2, 64, 64
    )
    assert windows.tolist() == [[64, 64, 64, 64], [1, 2, 12, 12]]


def faint_squares() -> Scene:
    """Forty squares, faint to dark, many overlapping, some twice the same."""
    generator = np.random.default_rng(7)
    paths = []
    for number in range(40):
        left, top = generator.uniform(2, 100, size=2)
        grey = 1.0 - 0.004 * number
        paths.append((square(left, top, generator.uniform(2, 20)), FlatPaint((grey, grey, grey))))
    paths.append(paths[5])
    return Scene.from_paths(128, 128, paths, background=(1.0, 1.0, 1.0))


def test_removals_in_batches_equal_removals_one_by_one():
    """The reference measures each change on whole-canvas renders, one path at a time."""
    scene = faint_squares()
    one_by_one: list[int] = []

    def whole_change(index: int) -> float:
        current = collapsed_paths(scene, np.array(one_by_one, dtype=np.int64))
        without = collapsed_paths(current, np.array([index]))
        return float(np.mean((without.render() - current.render()) ** 2))

    budget = 40 * IDLE_COST
    smallest_changes_first(scene.path_count, whole_change, one_by_one.append, IDLE_COST, budget)
    windows = padded_windows(scene.path_boxes(), WINDOW_PAD, scene.width, scene.height)
    batched = smallest_changes_in_batches(scene, windows, collapsed_paths, IDLE_COST, budget)
    assert 0 < len(one_by_one) < scene.path_count
    assert sorted(batched.tolist()) == sorted(one_by_one)


def test_a_lazy_budget_is_not_called_when_nothing_is_under_the_tolerance():
    scene = Scene.from_paths(64, 64, [(square(10, 10, 30), FlatPaint((0.0, 0.0, 0.0)))])
    windows = padded_windows(scene.path_boxes(), WINDOW_PAD, 64, 64)

    def budget() -> float:
        raise AssertionError("called")

    def removed(current: Scene, paths: np.ndarray) -> Scene:
        return current.subset([]) if len(paths) else current

    assert len(smallest_changes_in_batches(scene, windows, removed, IDLE_COST, budget)) == 0
