"""Whole-pixel paths: a path whose control points, rounded to whole pixels of the SVG, change
the picture by less than a tolerance is saved that way (a number without decimals is two or
three characters shorter, a quarter of the path's bytes).

The change is measured like an idle path's (`samvg.optimize.reduce.window_change`: the mean
squared change of the render, on the path's own window) at the working size, smallest first,
each measured again against the paths rounded before it; the changes together stay within a
budget (a share of the scene's MSE), and a path that rounding would make cross itself keeps
its decimals.
"""

from __future__ import annotations

import numpy as np

from samvg.finish.simplicity import crossing_paths
from samvg.optimize.reduce import IDLE_COST, smallest_changes_first, window_change
from samvg.scene import Scene

#: The most the picture may change from all roundings together, as a share of the scene's MSE.
ROUNDING_SHARE = 0.02


def whole_pixel_paths(
    scene: Scene,
    working: tuple[int, int, float],
    budget: float,
    tolerance: float = IDLE_COST,
) -> tuple[Scene, int]:
    """``scene`` (the SVG's pixels) with each path that rounding to whole pixels changes by less
    than ``tolerance`` (mean squared change of the render at the ``working`` canvas: width,
    height and the factor from the SVG's pixels to it) rounded, until the changes add up to
    ``budget``; returns it and how many paths were rounded."""
    rounded = np.rint(scene.points)
    width, height, factor = working
    crossing = set(crossing_paths(scene.with_geometry(rounded)).tolist())
    candidates = [
        index
        for index in range(scene.path_count)
        if index not in crossing
        and not np.array_equal(scene.path_points(index), _part(rounded, scene, index))
    ]
    if not candidates:
        return scene, 0
    current = scene.on_canvas(width, height, factor)
    boxes = current.path_boxes()
    kept = np.ones(scene.path_count, dtype=bool)
    points = scene.points.copy()

    def change_of(candidate: int) -> float:
        index = candidates[candidate]
        return window_change(current, boxes, kept, index, _part(rounded, scene, index) * factor)

    def round_path(candidate: int) -> None:
        nonlocal current
        index = candidates[candidate]
        replacement = _part(rounded, scene, index) * factor
        start, end = scene.offsets[index], scene.offsets[index + 1]
        points[start:end] = rounded[start:end]
        moved = current.points.copy()
        moved[start:end] = replacement
        current = current.with_geometry(moved)
        boxes[index] = np.concatenate([replacement.min(axis=0), replacement.max(axis=0)])

    count, _ = smallest_changes_first(len(candidates), change_of, round_path, tolerance, budget)
    return (scene.with_geometry(points) if count else scene), count


def _part(points: np.ndarray, scene: Scene, index: int) -> np.ndarray:
    """Path ``index``'s rows of packed ``points`` laid out as ``scene``'s."""
    return points[scene.offsets[index] : scene.offsets[index + 1]]
