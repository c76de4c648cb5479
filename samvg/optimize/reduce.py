"""Remove paths by their measured worth: reduce a scene to a path budget, removing the paths
whose removal raises the error least, a batch at a time and measuring again after each batch
(the top-down step of Optimize & Reduce, Hirschorn et al., AAAI 2024; the caller fits the
reduced scene again) and, within a batch, measuring again a path that overlaps one already
chosen, and remove the idle paths of any scene, those whose removal changes the
picture by less than a tolerance (a path painted over the same colour, a sliver under a
neighbour's edge); likewise make idle gradient fills flat (a gradient mostly covered by the
paths above it, or one that barely changes over what shows).

An idle path's change is measured on its own window (its control-point box, padded for the
anti-aliased edge): no pixel outside it changes, so the change is the whole image's, at a cost
in time that follows the path's size rather than the canvas's."""

from __future__ import annotations

import heapq
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from samvg.optimize.batches import padded_windows, smallest_changes_in_batches
from samvg.scene import FlatPaint, Paint, Scene

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
    negative: the path does harm), rendered on the path's window alone (`_path_window`)."""
    picture = scene.render()
    boxes = scene.path_boxes()
    kept = np.ones(scene.path_count, dtype=bool)
    costs = np.array(
        [
            _removal_cost(scene, boxes, kept, index, target, picture)
            for index in range(scene.path_count)
        ]
    )
    return costs / target.size


def reduce_paths(scene: Scene, target: np.ndarray, count: int) -> tuple[Scene, int]:
    """``scene`` with at most ``count`` SVG elements (`Scene.element_count`: paths, or compound
    paths), removing half the excess (at least one path) of least removal cost per batch;
    returns the scene and how many paths were removed."""
    removed = 0
    while scene.element_count > count:
        excess = scene.element_count - count
        batch = max(1, excess // 2) if excess > 4 else excess
        dropped = set(cheapest_together(scene, target, removal_costs(scene, target), batch))
        scene = scene.subset([index for index in range(scene.path_count) if index not in dropped])
        removed += batch
    return scene, removed


def cheapest_together(scene: Scene, target: np.ndarray, costs: np.ndarray, batch: int) -> list[int]:
    """``batch`` paths to remove together, cheapest first by ``costs`` (`removal_costs`), where a
    path that overlaps one already chosen is measured again with the chosen ones gone before it
    may join: two overlapping paths that each hide the other's loss (a leg drawn twice) each
    cost little alone, and much together. The lazy greedy step: a path far from every chosen
    one keeps its cost, as removing it changes no pixel another removal changes."""
    boxes = scene.path_boxes()
    reach = boxes + np.array([-WINDOW_PAD, -WINDOW_PAD, WINDOW_PAD, WINDOW_PAD])
    kept = np.ones(scene.path_count, dtype=bool)
    queue = [(float(cost), index, 0) for index, cost in enumerate(costs)]
    heapq.heapify(queue)
    chosen: list[int] = []
    while queue and len(chosen) < batch:
        cost, index, measured_with = heapq.heappop(queue)
        since = reach[chosen[measured_with:]]
        if len(since) and _overlapping(reach[index], since):
            again = _removal_cost(scene, boxes, kept, index, target) / target.size
            heapq.heappush(queue, (again, index, len(chosen)))
            continue
        chosen.append(index)
        kept[index] = False
    return chosen


def _overlapping(box: np.ndarray, others: np.ndarray) -> bool:
    """Whether ``box`` (x0, y0, x1, y1) meets any of ``others`` (N, 4)."""
    return bool(
        np.any(
            (others[:, 0] < box[2])
            & (others[:, 2] > box[0])
            & (others[:, 1] < box[3])
            & (others[:, 3] > box[1])
        )
    )


def _removal_cost(
    scene: Scene,
    boxes: np.ndarray,
    kept: np.ndarray,
    index: int,
    target: np.ndarray,
    picture: np.ndarray | None = None,
) -> float:
    """How much the squared error against ``target`` (summed) rises when path ``index`` goes
    from the paths ``kept``, on its window; ``picture`` is the kept paths' whole render where
    known (else the window is rendered with the path as well)."""
    found = _path_window(scene, boxes, kept, index)
    if found is None:
        return 0.0  # nothing of it on the canvas
    window, local, origin = found
    x0, y0 = int(origin[0]), int(origin[1])
    rows, columns = slice(y0, y0 + window.height), slice(x0, x0 + window.width)
    with_path = picture[rows, columns] if picture is not None else window.render()
    without = _without(window, local).render()
    return float(
        np.sum((without - target[rows, columns]) ** 2)
        - np.sum((with_path - target[rows, columns]) ** 2)
    )


def _without(window: Scene, local: int) -> Scene:
    """``window`` without its path ``local``."""
    return window.subset(np.flatnonzero(np.arange(window.path_count) != local))


def _path_window(
    scene: Scene, boxes: np.ndarray, kept: np.ndarray, index: int
) -> tuple[Scene, int, np.ndarray] | None:
    """Path ``index``'s window (its box, padded) as a scene of the kept paths whose ``boxes``
    reach into it, the path's index there and the window's origin; None when none of it is on
    the canvas."""
    x0, y0, x1, y1 = padded_windows(
        boxes[index : index + 1], WINDOW_PAD, scene.width, scene.height
    )[0]
    if x1 <= x0 or y1 <= y0:
        return None
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
    return window, int(np.searchsorted(with_path, index)), np.array([x0, y0], dtype=np.float64)


def smallest_changes_first(
    count: int,
    change_of: Callable[[int], float],
    apply: Callable[[int], None],
    tolerance: float,
    budget: float | Callable[[], float],
) -> tuple[int, float]:
    """The greedy step of every idle edit: of candidates ``0 .. count - 1`` whose change (by
    ``change_of``) is under ``tolerance``, smallest first, each is measured again (against the
    edits applied before it) and applied (``apply``) when still under ``tolerance`` and within
    what is left of ``budget``. Returns how many were applied and the budget left. A callable
    ``budget`` (a full render, say) is called only when some candidate is under ``tolerance``;
    when none is, the budget left is reported as 0."""
    first = [change_of(index) for index in range(count)]
    if not any(change < tolerance for change in first):
        return 0, budget if isinstance(budget, float) else 0.0
    left = budget() if callable(budget) else budget
    applied = 0
    for order in np.argsort(first, kind="stable"):
        index = int(order)
        if first[index] >= tolerance:
            break
        change = change_of(index)
        if change < tolerance and change <= left:
            apply(index)
            left -= change
            applied += 1
    return applied, left


def _with_paint(scene: Scene, index: int, paint: Paint) -> Scene:
    paints = list(scene.paints)
    paints[index] = paint
    return replace(scene, paints=tuple(paints))


def _least_squares_colour(
    picture: np.ndarray, base: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, float]:
    """The colour c in [0, 1]³ for which ``base + reach * c`` is nearest ``picture`` (a render
    affine in one fill's colour: black gives ``base``, white ``base + reach``), and the squared
    distance left, summed."""
    weight = np.sum(reach * reach, axis=(0, 1))
    fitted = np.sum(reach * (picture - base), axis=(0, 1)) / np.maximum(weight, 1e-12)
    colour = np.clip(fitted, 0.0, 1.0)
    return colour, float(np.sum((base + reach * colour - picture) ** 2))


def _flat_stand_in(scene: Scene, index: int) -> tuple[FlatPaint, float]:
    """The flat fill that changes the render least in place of path ``index``'s gradient, and
    the squared change it makes, summed."""
    opacity = scene.paints[index].rgba[3]
    base = _with_paint(scene, index, FlatPaint((0.0, 0.0, 0.0, opacity))).render()
    white = _with_paint(scene, index, FlatPaint((1.0, 1.0, 1.0, opacity))).render()
    colour, squared = _least_squares_colour(scene.render(), base, white - base)
    return FlatPaint((*colour.tolist(), opacity)), squared


def _flat_background(scene: Scene) -> tuple[tuple[float, float, float], float]:
    """The flat background that changes the render least in place of the background gradient,
    and the squared change it makes, summed."""
    base = scene.with_background((0.0, 0.0, 0.0)).render()
    white = scene.with_background((1.0, 1.0, 1.0)).render()
    colour, squared = _least_squares_colour(scene.render(), base, white - base)
    return (float(colour[0]), float(colour[1]), float(colour[2])), squared


def _gradient_change(
    scene: Scene, boxes: np.ndarray, kept: np.ndarray, index: int
) -> tuple[FlatPaint, float]:
    """Path ``index``'s best flat stand-in and the mean squared change of the picture it makes,
    measured on the path's window."""
    found = _path_window(scene, boxes, kept, index)
    if found is None:
        return FlatPaint(scene.paints[index].rgba), 0.0
    window, local, _ = found
    paint, squared = _flat_stand_in(window, local)
    return paint, squared / (scene.width * scene.height * 3)


def flatten_idle_gradients(
    scene: Scene, target: np.ndarray, tolerance: float, share: float = IDLE_SHARE
) -> tuple[Scene, int]:
    """``scene`` with its idle gradients flat: a gradient fill (or background) whose best flat
    colour changes the picture by less than ``tolerance`` (mean squared change) takes that
    colour, smallest change first, each measured again against the fills flattened before it,
    the changes together within ``share`` of the scene's MSE against ``target``; returns it and
    how many fills went flat. A gradient costs some 200 bytes of SVG; a flat fill, seven."""
    pieces = {path for element in scene.elements() if len(element) > 1 for path in element}
    gradients = [
        index
        for index, paint in enumerate(scene.paints)
        if not isinstance(paint, FlatPaint) and index not in pieces  # a compound's paint is one
    ]
    if not gradients and scene.background_gradient is None:
        return scene, 0
    budget = share * float(np.mean((scene.render() - target) ** 2))
    kept = np.ones(scene.path_count, dtype=bool)
    boxes = scene.path_boxes()
    stand_ins: dict[int, Paint] = {}

    def change_of(candidate: int) -> float:
        stand_ins[candidate], change = _gradient_change(scene, boxes, kept, gradients[candidate])
        return change

    def make_flat(candidate: int) -> None:
        nonlocal scene
        scene = _with_paint(scene, gradients[candidate], stand_ins[candidate])

    flattened, budget = smallest_changes_first(
        len(gradients), change_of, make_flat, tolerance, budget
    )
    if scene.background_gradient is not None:
        colour, squared = _flat_background(scene)
        change = squared / (scene.width * scene.height * 3)
        if change < tolerance and change <= budget:
            scene, flattened = scene.with_background(colour), flattened + 1
    return scene, flattened


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
    windows = padded_windows(scene.path_boxes(), WINDOW_PAD, scene.width, scene.height)
    removed = smallest_changes_in_batches(
        scene,
        windows,
        collapsed_paths,
        tolerance,
        lambda: share * float(np.mean((scene.render() - target) ** 2)),
    )
    if not len(removed):
        return scene, 0
    kept = np.ones(scene.path_count, dtype=bool)
    kept[removed] = False
    return scene.subset(np.flatnonzero(kept)), len(removed)


def collapsed_paths(scene: Scene, paths: np.ndarray) -> Scene:
    """``scene`` with ``paths`` drawn as nothing (each outline collapsed onto its first point:
    no area, so no pixel of it shows), the other paths keeping their indices."""
    if not len(paths):
        return scene
    points = scene.points.copy()
    for index in paths:
        start, end = scene.offsets[index], scene.offsets[index + 1]
        points[start:end] = points[start]
    return scene.with_geometry(points)
