"""Whole-pixel paths: a path whose control points, rounded to whole pixels of the SVG, change
the picture by less than a tolerance is saved that way (a number without decimals is two or
three characters shorter, a quarter of the path's bytes).

The change is the mean squared change of the render at the working size, measured by the
greedy step of idle edits (`samvg.optimize.batches`: smallest first, each measured again
against the paths rounded before it); the changes together stay within a budget (a share of
the scene's MSE), and a path that rounding would make cross itself keeps its decimals.
"""

from __future__ import annotations

import numpy as np

from samvg.finish.simplicity import crossing_paths
from samvg.optimize.batches import padded_windows, smallest_changes_in_batches
from samvg.optimize.reduce import IDLE_COST, WINDOW_PAD
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
    crossing = set(crossing_paths(scene.with_geometry(rounded)).tolist())
    candidates = np.array(
        [
            index
            for index in range(scene.path_count)
            if index not in crossing
            and not np.array_equal(scene.path_points(index), _part(rounded, scene, index))
        ],
        dtype=np.int64,
    )
    if not len(candidates):
        return scene, 0
    width, height, factor = working
    canvas = scene.on_canvas(width, height, factor)
    goal = rounded * factor
    now, then = canvas.path_boxes(), canvas.with_geometry(goal).path_boxes()
    both = np.concatenate(
        [np.minimum(now[:, :2], then[:, :2]), np.maximum(now[:, 2:], then[:, 2:])], 1
    )
    windows = padded_windows(both[candidates], WINDOW_PAD, width, height)

    def edited(current: Scene, members: np.ndarray) -> Scene:
        return _with_rows(current, goal, candidates[members])

    chosen = candidates[smallest_changes_in_batches(canvas, windows, edited, tolerance, budget)]
    if not len(chosen):
        return scene, 0
    return scene.with_geometry(_with_rows(scene, rounded, chosen).points), len(chosen)


def _with_rows(scene: Scene, points: np.ndarray, paths: np.ndarray) -> Scene:
    """``scene`` with the rows of ``paths`` taken from ``points`` (laid out as its own)."""
    if not len(paths):
        return scene
    moved = scene.points.copy()
    for index in paths:
        start, end = scene.offsets[index], scene.offsets[index + 1]
        moved[start:end] = points[start:end]
    return scene.with_geometry(moved)


def _part(points: np.ndarray, scene: Scene, index: int) -> np.ndarray:
    """Path ``index``'s rows of packed ``points`` laid out as ``scene``'s."""
    return points[scene.offsets[index] : scene.offsets[index + 1]]
