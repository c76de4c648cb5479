"""Applying per-path edits to a scene: a path is kept, replaced by one or more paths in its place
in paint order (a split), or dropped; everything else about the scene is kept."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from samvg.scene import Paint, Scene

Edit = Sequence[tuple[np.ndarray, Paint]]
"""What replaces one path, bottom first: (points (3K, 2), paint) pairs; empty drops the path."""


def apply_edits(scene: Scene, edits: Mapping[int, Edit]) -> Scene:
    """``scene`` with path ``i`` replaced by ``edits[i]`` for every ``i`` in ``edits``."""
    if not edits:
        return scene
    paths: list[tuple[np.ndarray, Paint]] = []
    for index, (points, paint) in enumerate(scene.paths()):
        if index in edits:
            paths.extend(edits[index])
        else:
            paths.append((points, paint))
    return scene.with_paths(paths)


def edit_counts(step: str, scene: Scene, edits: Mapping[int, Edit], holes: int) -> dict[str, int]:
    """A step's counts: paths checked, replaced, parts split off, dropped, holes filled; each
    key starts with ``step``."""
    return {
        f"{step}_checked": scene.path_count,
        f"{step}_{'clipped' if step == 'bounds' else 'repaired'}": sum(
            1 for edit in edits.values() if edit
        ),
        f"{step}_split": sum(max(len(edit) - 1, 0) for edit in edits.values()),
        f"{step}_dropped": sum(1 for edit in edits.values() if not edit),
        f"{step}_holes_filled": holes,
    }
