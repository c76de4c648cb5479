"""Remove paths by their measured worth: reduce a scene to a path budget, removing the paths
whose removal raises the error least, a batch at a time and measuring again after each batch
(the top-down step of Optimize & Reduce, Hirschorn et al., AAAI 2024; the caller fits the
reduced scene again), and remove the idle paths of any scene, those whose removal changes the
picture by less than a tolerance (a path painted over the same colour, a sliver under a
neighbour's edge).

A path's removal cost is measured on its own window (its control-point box, padded for the
anti-aliased edge): no pixel outside it changes, so the cost is the whole image's, at a cost
in time that follows the path's size rather than the canvas's."""

from __future__ import annotations

import numpy as np

from samvg.scene import Scene

#: The MSE rise below which a path is idle: a quarter of one pixel's full error on a 512² canvas
#: (its squared error summed over the canvas, 0.26 at 512²), a change no eye sees.
IDLE_COST = 1e-6
#: The most the MSE may rise from all idle removals together, as a share of the scene's MSE:
#: many small paths (a field of grass blades) each below ``IDLE_COST`` add up to a visible loss.
IDLE_SHARE = 0.01
#: Pixels around a path's control-point box that its anti-aliased edge may still touch.
WINDOW_PAD = 2


def removal_costs(scene: Scene, target: np.ndarray) -> np.ndarray:
    """For each path, how much the image's MSE rises when that path alone is removed (can be
    negative: the path does harm)."""
    squared = np.sum((scene.render() - target) ** 2)
    costs = np.empty(scene.path_count)
    for index in range(scene.path_count):
        others = [other for other in range(scene.path_count) if other != index]
        without = scene.subset(others).render()
        costs[index] = np.sum((without - target) ** 2) - squared
    return costs / target.size


def reduce_paths(scene: Scene, target: np.ndarray, count: int) -> tuple[Scene, int]:
    """``scene`` with at most ``count`` paths, removing half the excess (at least one path) of
    least removal cost per batch; returns the scene and how many paths were removed."""
    removed = 0
    while scene.path_count > count:
        excess = scene.path_count - count
        batch = max(1, excess // 2) if excess > 4 else excess
        costs = removal_costs(scene, target)
        dropped = set(np.argsort(costs, kind="stable")[:batch].tolist())
        scene = scene.subset([index for index in range(scene.path_count) if index not in dropped])
        removed += batch
    return scene, removed


def _window_cost(scene: Scene, target: np.ndarray, kept: np.ndarray, index: int) -> float:
    """The MSE rise when path ``index`` goes from the paths ``kept`` (a bool mask that holds
    it), measured on the path's window."""
    boxes = scene.path_boxes()
    x0, y0 = np.floor(boxes[index, :2]).astype(int) - WINDOW_PAD
    x1, y1 = np.ceil(boxes[index, 2:]).astype(int) + WINDOW_PAD
    x0, y0 = max(x0, 0), max(y0, 0)
    x1, y1 = min(x1, scene.width), min(y1, scene.height)
    if x1 <= x0 or y1 <= y0:
        return 0.0  # nothing of it on the canvas
    touching = (
        kept
        & (boxes[:, 0] < x1 + 1)
        & (boxes[:, 2] > x0 - 1)
        & (boxes[:, 1] < y1 + 1)
        & (boxes[:, 3] > y0 - 1)
    )
    window = scene.window(int(x0), int(y0), int(x1 - x0), int(y1 - y0))
    inside = target[y0:y1, x0:x1]
    with_path = np.flatnonzero(touching)
    without = with_path[with_path != index]
    squared = np.sum((window.subset(with_path).render() - inside) ** 2)
    squared_without = np.sum((window.subset(without).render() - inside) ** 2)
    return float(squared_without - squared) / target.size


def remove_idle_paths(
    scene: Scene, target: np.ndarray, tolerance: float, share: float = IDLE_SHARE
) -> tuple[Scene, int]:
    """``scene`` without the paths whose removal raises the MSE by less than ``tolerance``, as
    long as the removals together raise it by at most ``share`` of the scene's MSE; returns it
    and how many went. Paths go one at a time, cheapest first, each measured again against the
    scene left by the removals before it (two copies of one path each cost nothing alone; the
    second then costs its full worth and stays)."""
    kept = np.ones(scene.path_count, dtype=bool)
    costs = np.array([_window_cost(scene, target, kept, i) for i in range(scene.path_count)])
    if not np.any(costs < tolerance):
        return scene, 0
    budget = share * float(np.mean((scene.render() - target) ** 2))
    for index in np.argsort(costs, kind="stable"):
        if costs[index] >= tolerance:
            break
        cost = _window_cost(scene, target, kept, int(index))
        if cost < tolerance and cost <= budget:
            kept[index] = False
            budget -= cost
    removed = int(np.count_nonzero(~kept))
    return (scene.subset(np.flatnonzero(kept)) if removed else scene), removed
