"""The greedy step of idle edits measured in batches: edits of the picture (a path removed, a
path rounded to whole pixels) each changing the render only inside its own window, smallest
change first, each measured again against the edits applied before it and applied while under
a tolerance and within a budget.

Edits whose windows do not meet are measured together: one render of the box around a batch,
the change of each read off its own window. A textured scene holds thousands of small islands,
and a window render each cost as much as the rest of the finishing steps together.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from samvg.scene import Scene

#: ``edited(scene, candidates)``: ``scene`` with the edits of those candidates applied.
Edit = Callable[[Scene, np.ndarray], Scene]


def smallest_changes_in_batches(
    scene: Scene,
    windows: np.ndarray,
    edited: Edit,
    tolerance: float,
    budget: float | Callable[[], float],
) -> np.ndarray:
    """The candidates (rows of ``windows``, (N, 4) int pixel boxes x0, y0, x1, y1 on
    ``scene``'s canvas, outside which a candidate's edit changes nothing) applied by the greedy
    step, in the order applied. A candidate's change is the mean squared change of the render,
    over the whole canvas. A callable ``budget`` (a full render, say) is called only when some
    candidate is under ``tolerance``."""
    picture = scene.render()
    first = changes_alone(scene, windows, edited, picture)
    order = np.argsort(first, kind="stable")
    order = order[first[order] < tolerance]
    if not len(order):
        return order
    left = budget() if callable(budget) else budget
    applied: list[int] = []
    batches = disjoint_batches(windows[order], scene.width, scene.height)
    for batch in range(int(batches.max()) + 1):
        members = order[batches == batch]
        trial = _trial_picture(scene, picture, windows[members], edited(scene, members))
        kept = []
        for member in members:
            change = _mean_square(trial, picture, windows[member])
            if change < tolerance and change <= left:
                left -= change
                kept.append(int(member))
            else:
                x0, y0, x1, y1 = windows[member]
                trial[y0:y1, x0:x1] = picture[y0:y1, x0:x1]
        scene, picture = edited(scene, np.array(kept, dtype=np.int64)), trial
        applied.extend(kept)
    return np.array(applied, dtype=np.int64)


def disjoint_batches(windows: np.ndarray, width: int, height: int) -> np.ndarray:
    """Each window's batch number: windows of one batch do not meet, and a window that meets an
    earlier one (in the order given) goes in a later batch than it."""
    last_batch = np.full((height, width), -1, dtype=np.int64)
    batches = np.empty(len(windows), dtype=np.int64)
    for number, (x0, y0, x1, y1) in enumerate(windows):
        area = last_batch[y0:y1, x0:x1]
        batches[number] = area.max(initial=-1) + 1
        area[...] = batches[number]
    return batches


def packed_batches(windows: np.ndarray, width: int, height: int, cell: int = 4) -> np.ndarray:
    """Each window's batch number, windows of one batch not meeting, in as few batches as
    first fit finds with no order kept (a third as many as `disjoint_batches` on a painting's
    islands). Occupancy is kept on a grid of ``cell``-pixel squares: a batch's grid is small
    however many batches large overlapping windows need."""
    cells = np.concatenate([windows[:, :2] // cell, -(-windows[:, 2:] // cell)], axis=1)
    shape = (-(-height // cell), -(-width // cell))
    occupied: list[np.ndarray] = []
    batches = np.empty(len(windows), dtype=np.int64)
    for number, (x0, y0, x1, y1) in enumerate(cells):
        free = (batch for batch, grid in enumerate(occupied) if not grid[y0:y1, x0:x1].any())
        batch = next(free, len(occupied))
        if batch == len(occupied):
            occupied.append(np.zeros(shape, dtype=bool))
        occupied[batch][y0:y1, x0:x1] = True
        batches[number] = batch
    return batches


def padded_windows(boxes: np.ndarray, pad: int, width: int, height: int) -> np.ndarray:
    """(N, 4) int: float ``boxes`` (x0, y0, x1, y1) grown to whole pixels and by ``pad`` each
    way, cut to the canvas (empty where a box lies off it)."""
    low = np.floor(boxes[:, :2]).astype(np.int64) - pad
    high = np.ceil(boxes[:, 2:]).astype(np.int64) + pad
    limits = np.array([width, height])
    return np.concatenate([np.clip(low, 0, limits), np.clip(high, 0, limits)], axis=1)


def changes_alone(
    scene: Scene, windows: np.ndarray, edited: Edit, picture: np.ndarray | None = None
) -> np.ndarray:
    """Each candidate's change of the render by its edit alone (``picture``: ``scene``'s render,
    where known)."""
    if picture is None:
        picture = scene.render()
    changes = np.zeros(len(windows))
    batches = packed_batches(windows, scene.width, scene.height)
    for batch in range(int(batches.max(initial=-1)) + 1):
        members = np.flatnonzero(batches == batch)
        trial = _trial_picture(scene, picture, windows[members], edited(scene, members))
        for member in members:
            changes[member] = _mean_square(trial, picture, windows[member])
    return changes


def _trial_picture(
    scene: Scene, picture: np.ndarray, windows: np.ndarray, trial: Scene
) -> np.ndarray:
    """``picture`` (``scene``'s render) with the box around ``windows`` rendered from ``trial``
    (a batch of one small edit costs one small render)."""
    x0, y0 = windows[:, :2].min(axis=0)
    x1, y1 = windows[:, 2:].max(axis=0)
    result = picture.copy()
    if x1 > x0 and y1 > y0:
        box = trial.window(int(x0), int(y0), int(x1 - x0), int(y1 - y0))
        result[y0:y1, x0:x1] = box.render()
    return result


def _mean_square(picture: np.ndarray, base: np.ndarray, window: np.ndarray) -> float:
    """The mean squared difference of two renders on ``window``, over the whole canvas."""
    x0, y0, x1, y1 = window
    difference = picture[y0:y1, x0:x1] - base[y0:y1, x0:x1]
    return float(np.sum(difference * difference)) / picture.size
