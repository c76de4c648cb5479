"""Remove paths by their measured worth: reduce a scene to a path budget, removing the paths
whose removal raises the error least, a batch at a time and measuring again after each batch
(the top-down step of Optimize & Reduce, Hirschorn et al., AAAI 2024; the caller fits the
reduced scene again), and remove the idle paths of any scene, those whose removal changes the
picture by less than a tolerance (a path painted over the same colour, a sliver under a
neighbour's edge).

An idle path's change is measured on its own window (its control-point box, padded for the
anti-aliased edge): no pixel outside it changes, so the change is the whole image's, at a cost
in time that follows the path's size rather than the canvas's."""

from __future__ import annotations

import numpy as np

from samvg.scene import Scene

#: The mean squared change of the picture below which a path is idle: on a 512² canvas, a
#: quarter of one pixel turned from black to white (0.26 of squared change summed over the
#: canvas), a change no eye sees.
IDLE_COST = 1e-6
#: The most the picture may change from all idle removals together, as a share of the scene's
#: MSE: many small paths (a field of grass blades) each below
#: ``IDLE_COST`` add up to a visible loss.
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


def window_change(
    scene: Scene,
    boxes: np.ndarray,
    kept: np.ndarray,
    index: int,
    replacement: np.ndarray | None = None,
) -> float:
    """The mean squared change of the picture (over the whole canvas) when path ``index`` goes
    from the paths ``kept`` (a bool mask that holds it), or with ``replacement`` (its control
    points, the same count) when it is redrawn there: rendered on the path's window alone (both
    outlines' boxes, padded) from the kept paths whose ``boxes`` (`Scene.path_boxes`) reach
    into it."""
    low, high = boxes[index, :2], boxes[index, 2:]
    if replacement is not None:
        low = np.minimum(low, replacement.min(axis=0))
        high = np.maximum(high, replacement.max(axis=0))
    x0, y0 = np.floor(low).astype(int) - WINDOW_PAD
    x1, y1 = np.ceil(high).astype(int) + WINDOW_PAD
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
    touching[index] = True
    with_path = np.flatnonzero(touching)
    window = scene.subset(with_path).window(int(x0), int(y0), int(x1 - x0), int(y1 - y0))
    if replacement is None:
        changed = window.subset(np.flatnonzero(with_path != index))
    else:
        local = int(np.searchsorted(with_path, index))
        points = window.points.copy()
        points[window.offsets[local] : window.offsets[local + 1]] = replacement - [x0, y0]
        changed = window.with_geometry(points)
    squared = np.sum((window.render() - changed.render()) ** 2)
    return float(squared) / (scene.width * scene.height * 3)


def remove_idle_paths(
    scene: Scene, target: np.ndarray, tolerance: float, share: float = IDLE_SHARE
) -> tuple[Scene, int]:
    """``scene`` without its idle paths, those whose removal changes the picture by less than
    ``tolerance`` (mean squared change), as long as the changes together stay within ``share``
    of the scene's MSE against ``target``; returns it and how many went. Paths go one at a
    time, smallest change first, each measured again against the scene left by the removals
    before it (two copies of one path each change nothing alone; the second then changes the
    picture and stays). The change, not the error: a path that raises the MSE may still be what
    the LPIPS term of the fit put there."""
    kept = np.ones(scene.path_count, dtype=bool)
    boxes = scene.path_boxes()
    changes = np.array([window_change(scene, boxes, kept, i) for i in range(scene.path_count)])
    if not np.any(changes < tolerance):
        return scene, 0
    budget = share * float(np.mean((scene.render() - target) ** 2))
    for index in np.argsort(changes, kind="stable"):
        if changes[index] >= tolerance:
            break
        change = window_change(scene, boxes, kept, int(index))
        if change < tolerance and change <= budget:
            kept[index] = False
            budget -= change
    removed = int(np.count_nonzero(~kept))
    return (scene.subset(np.flatnonzero(kept)) if removed else scene), removed
