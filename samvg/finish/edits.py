"""Applying per-path edits to a scene: a path is kept, replaced by one or more paths in its place
in paint order (a split), or dropped; everything else about the scene is kept (a path joined into
a compound path passes that on to the first path that replaces it)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from samvg.scene import Paint, Scene

Edit = Sequence[tuple[np.ndarray, Paint]]
"""What replaces one path, bottom first: (points (3K, 2), paint) pairs; empty drops the path."""


def apply_edits(scene: Scene, edits: Mapping[int, Edit]) -> Scene:
    """``scene`` with path ``i`` replaced by ``edits[i]`` for every ``i`` in ``edits``. A path
    of a compound path passes its place in it on to its first replacement; parts split off stand
    on their own (`samvg.finish.compound` may join them), and so does the path after them."""
    if not edits:
        return scene
    paths: list[tuple[np.ndarray, Paint]] = []
    joined: list[bool] = []
    run = scene.joined_runs()
    last_run = -1
    for index, (points, paint) in enumerate(scene.paths()):
        replaced = edits.get(index, [(points, paint)])
        for part, path in enumerate(replaced):
            paths.append(path)
            joined.append(part == 0 and run[index] == last_run)
            last_run = run[index] if part == 0 else -1
    edited = scene.with_paths(paths)
    return replace(edited, joined=np.array(joined)) if scene.joined is not None else edited


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
