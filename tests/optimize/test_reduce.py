"""Reducing a scene to a path budget by removal cost; idle paths and gradients."""

from dataclasses import replace

import numpy as np
import pytest

from samvg.optimize.batches import changes_alone, padded_windows
from samvg.optimize.reduce import (
    IDLE_COST,
    IDLE_SHARE,
    WINDOW_PAD,
    cheapest_together,
    collapsed_paths,
    flatten_idle_gradients,
    reduce_paths,
    removal_costs,
    remove_idle_paths,
    smallest_changes_first,
)
from samvg.scene import FlatPaint, LinearGradient, RadialGradient, Scene


def square(left: float, top: float, side: float) -> np.ndarray:
    corners = np.array([[left, top], [left + side, top], [left + side, top + side],
                        [left, top + side]], float)  # fmt: skip
    points = []
    for start, end in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        points += [start, start + (end - start) / 3, start + 2 * (end - start) / 3]
    return np.asarray(points)


BLUE, RED = FlatPaint((0.1, 0.2, 0.8)), FlatPaint((0.9, 0.1, 0.1))


def scene_and_target() -> tuple[Scene, np.ndarray]:
    """A big blue square, a red square hidden under it, a small red square on top, and a red
    square of the wrong colour where the target is white."""
    paths = [
        (square(8, 8, 10), RED),  # hidden under the blue square
        (square(4, 4, 30), BLUE),
        (square(10, 10, 6), RED),
        (square(44, 44, 12), RED),  # harmful: the target is white there
    ]
    scene = Scene.from_paths(64, 64, paths, background=(1.0, 1.0, 1.0))
    target = scene.subset([1, 2]).render()
    return scene, target


def test_removal_costs_rank_hidden_and_harmful_paths_below_visible_ones():
    scene, target = scene_and_target()
    costs = removal_costs(scene, target)
    assert costs[0] == 0.0  # hidden: removing it changes nothing
    assert costs[3] < 0.0  # harmful: removing it helps
    assert costs[1] > costs[2] > 0.0  # the big square matters most


def test_reduce_paths_keeps_the_paths_that_matter_in_paint_order():
    scene, target = scene_and_target()
    reduced, removed = reduce_paths(scene, target, 2)
    assert removed == 2 and reduced.path_count == 2
    assert np.array_equal(reduced.points, scene.subset([1, 2]).points)
    assert np.allclose(reduced.render(), target)
    assert reduce_paths(scene, target, 10)[0].path_count == 4  # under budget: unchanged


def test_a_path_drawn_twice_loses_one_copy_not_both():
    """Each copy of the red square costs nothing alone; removed together they cost the square.
    With two paths to remove from three, one copy and the small blue square go."""
    paths = [(square(8, 8, 20), RED), (square(8, 8, 20), RED), (square(44, 44, 6), BLUE)]
    scene = Scene.from_paths(64, 64, paths, background=(1.0, 1.0, 1.0))
    target = scene.render()
    costs = removal_costs(scene, target)
    assert costs[0] == costs[1] == 0.0 < costs[2]
    assert sorted(cheapest_together(scene, target, costs, 2)) == [0, 2]
    reduced, removed = reduce_paths(scene, target, 1)
    assert removed == 2 and np.array_equal(reduced.points, scene.subset([1]).points)


def test_far_apart_paths_are_chosen_by_their_first_costs_alone():
    scene, target = scene_and_target()
    costs = removal_costs(scene, target)
    assert cheapest_together(scene, target, costs, 2) == list(np.argsort(costs, kind="stable")[:2])


def removal_changes(scene: Scene) -> np.ndarray:
    """Each path's removal change, measured on windows (as `remove_idle_paths` does)."""
    windows = padded_windows(scene.path_boxes(), WINDOW_PAD, scene.width, scene.height)
    return changes_alone(scene, windows, collapsed_paths)


def test_window_changes_equal_whole_canvas_changes():
    scene, _ = scene_and_target()
    picture = scene.render()
    windowed = removal_changes(scene)
    whole = [
        np.mean((picture - scene.subset(np.flatnonzero(np.arange(4) != index)).render()) ** 2)
        for index in range(scene.path_count)
    ]
    assert np.allclose(windowed, whole, rtol=1e-5, atol=1e-9)
    assert windowed[0] == 0.0 and min(windowed[1:]) > 0.0  # only the hidden square changes none


def test_idle_paths_go_and_visible_ones_stay():
    scene, target = scene_and_target()
    same_colour = (square(6, 6, 20), BLUE)  # painted over the blue square in its own colour
    paths = [*zip(map(scene.path_points, range(4)), scene.paints, strict=True)]
    paths.insert(2, same_colour)  # under the small red square
    with_idle = Scene.from_paths(64, 64, paths, background=(1.0, 1.0, 1.0))
    kept, removed = remove_idle_paths(with_idle, target, IDLE_COST)
    assert removed == 2  # the hidden square and the blue over blue
    assert np.array_equal(kept.points, scene.subset([1, 2, 3]).points)
    assert np.allclose(kept.render(), with_idle.render())


def test_a_path_that_raises_the_error_but_changes_the_picture_is_not_idle():
    scene, target = scene_and_target()
    assert removal_costs(scene, target)[3] < 0  # removing the misplaced square helps MSE
    assert remove_idle_paths(scene.subset([1, 2, 3]), target, IDLE_COST)[1] == 0


def test_of_two_copies_of_a_path_one_stays():
    scene, target = scene_and_target()
    doubled = scene.subset([1, 2, 2])  # each copy alone costs nothing: the other paints it
    kept, removed = remove_idle_paths(doubled, target, IDLE_COST)
    assert removed == 1 and kept.path_count == 2
    assert np.allclose(kept.render(), target)


def test_many_faint_paths_stay_though_each_alone_is_under_the_tolerance():
    size, grey, faint = 256, (0.5, 0.5, 0.5), (0.6, 0.6, 0.6)
    dots = [(square(8 * (k % 30) + 4, 8 * (k // 30) + 4, 2), FlatPaint(faint)) for k in range(60)]
    scene = Scene.from_paths(size, size, dots, background=grey)
    picture = scene.render()
    changes = removal_changes(scene)
    assert min(changes) > 0 and max(changes) < IDLE_COST  # each dot alone is "idle"...
    assert remove_idle_paths(scene, picture, IDLE_COST)[1] == 0  # ...but together they show
    target = np.clip(picture + 0.02, 0, 1)  # a scene 4e-4 MSE off: 1 % of that buys a few dots
    thinned, removed = remove_idle_paths(scene, target, IDLE_COST)
    budget = IDLE_SHARE * np.mean((picture - target) ** 2)
    assert 0 < removed <= budget / min(changes)
    assert np.mean((thinned.render() - picture) ** 2) <= budget * 1.0001


def test_window_change_of_a_redrawn_path_equals_the_whole_canvas_change():
    scene, _ = scene_and_target()
    picture = scene.render()
    for index in range(scene.path_count):
        moved = scene.path_points(index) + [1.4, -0.7]
        points = scene.points.copy()
        points[scene.offsets[index] : scene.offsets[index + 1]] = moved
        redrawn = scene.with_geometry(points)
        whole = np.mean((redrawn.render() - picture) ** 2)
        both = np.concatenate([scene.path_points(index), moved])
        box = np.concatenate([both.min(axis=0), both.max(axis=0)])[None]
        window = padded_windows(box, WINDOW_PAD, scene.width, scene.height)
        windowed = changes_alone(scene, window, lambda current, _, redrawn=redrawn: redrawn)[0]
        assert np.isclose(windowed, whole, rtol=1e-5, atol=1e-9)


def gradient_scene() -> Scene:
    """Over a strong linear background gradient: a gradient square whose stops barely differ, a
    strong radial gradient, and a wide opaque band that covers all but a strip of the
    background."""
    faint = RadialGradient(((0.0, (0.50, 0.30, 0.20)), (1.0, (0.51, 0.31, 0.21))), 1.0, (20, 20), 9)
    strong = RadialGradient(((0.0, (1.0, 1.0, 0.0)), (1.0, (0.0, 0.0, 1.0))), 1.0, (46, 20), 9)
    band = FlatPaint((0.2, 0.6, 0.3))
    paths = [(square(-2, 32, 68), band), (square(10, 10, 20), faint), (square(36, 10, 20), strong)]
    background = LinearGradient(
        ((0.0, (0.0, 0.0, 0.0)), (1.0, (1.0, 1.0, 1.0))), 1.0, (0, 0), (64, 0)
    )
    scene = Scene.from_paths(64, 64, paths, background=(0.5, 0.5, 0.5))
    return replace(scene, background_gradient=background)


def test_a_gradient_that_barely_changes_goes_flat_and_a_strong_one_stays():
    scene = gradient_scene()
    flat, count = flatten_idle_gradients(scene, scene.render() + 0.01, IDLE_COST, share=1.0)
    assert count == 1
    assert isinstance(flat.paints[1], FlatPaint) and isinstance(flat.paints[2], RadialGradient)
    assert np.allclose(flat.paints[1].rgba[:3], (0.505, 0.305, 0.205), atol=0.003)  # the mean
    assert flat.background_gradient is not None  # black to white across what shows
    assert np.mean((flat.render() - scene.render()) ** 2) < IDLE_COST


def test_a_background_gradient_that_does_not_show_goes_flat():
    scene = gradient_scene()
    covered = Scene.from_paths(64, 64, [(square(-2, -2, 68), FlatPaint((0.2, 0.6, 0.3)))])
    covered = replace(covered, background_gradient=scene.background_gradient)
    flat, count = flatten_idle_gradients(covered, covered.render() + 0.01, IDLE_COST)
    assert count == 1 and flat.background_gradient is None
    assert np.array_equal(flat.render(), covered.render())


def test_no_gradient_goes_flat_beyond_the_budget():
    scene = gradient_scene()
    picture = scene.render()
    assert flatten_idle_gradients(scene, picture, IDLE_COST)[1] == 0  # the scene has no error
    assert flatten_idle_gradients(scene, picture + 0.01, IDLE_COST)[1] == 1


def test_smallest_changes_first_measures_again_and_keeps_to_the_budget():
    applied: list[int] = []
    base = [0.3, 0.1, 0.5, 0.2, 2.0]

    def change_of(index: int) -> float:
        if index == 3 and 1 in applied:  # 3 and 1 are copies: once 1 goes, 3 changes much
            return 5.0
        return base[index]

    count, left = smallest_changes_first(5, change_of, applied.append, 1.0, 0.7)
    # order by first change: 1 (0.1), 3 (now 5.0: kept), 0 (0.3), 2 (0.5 > 0.3 left); 4 never
    assert applied == [1, 0] and count == 2 and left == pytest.approx(0.3)
    assert smallest_changes_first(2, lambda i: 3.0, applied.append, 1.0, 1.0) == (0, 1.0)
    assert applied == [1, 0]  # nothing under the tolerance: nothing applied


def test_smallest_changes_first_calls_a_lazy_budget_only_when_needed():
    calls: list[int] = []

    def budget() -> float:
        calls.append(1)
        return 0.7

    assert smallest_changes_first(2, lambda i: 3.0, calls.append, 1.0, budget) == (0, 0.0)
    assert calls == []  # nothing under the tolerance: the budget (a full render) never measured
    count, left = smallest_changes_first(2, lambda i: 0.25, lambda i: None, 1.0, budget)
    assert calls == [1] and count == 2 and left == pytest.approx(0.2)


def test_removal_costs_on_windows_equal_those_of_whole_renders(bench_dir):
    """On a real image (24 fitted random paths, overlapping, as the DiffVG baseline starts) the
    windowed costs are the whole-canvas ones: a path changes no pixel outside its padded
    control-point box."""
    from samvg.baselines import random_init
    from samvg.bench.runner import load_target

    target = load_target(bench_dir / "emoji" / "fluentflat_crab.png", 128)
    scene = random_init(target, 24, steps=5, seed=3)
    picture = scene.render()
    base = np.sum((picture - target) ** 2)
    whole = np.array([
        np.sum((scene.subset([o for o in range(24) if o != i]).render() - target) ** 2) - base
        for i in range(24)
    ]) / target.size  # fmt: skip
    windowed = removal_costs(scene, target)
    assert np.abs(whole).max() > 1e-4
    np.testing.assert_allclose(windowed, whole, rtol=1e-4, atol=1e-9)
