"""Reduce a scene to a path budget: remove the paths whose removal raises the error least, a
batch at a time, measuring again after each batch (the top-down step of Optimize & Reduce,
Hirschorn et al., AAAI 2024). The caller fits the reduced scene again."""

from __future__ import annotations

import numpy as np

from samvg.scene import Scene


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
