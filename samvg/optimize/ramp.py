"""Gradient fills kept as shading: after each fitting step, a gradient whose colour ramp (the
stretch between its first and last stop) is shorter than ``fraction`` of its path's extent along
the gradient is widened to that length about the ramp's middle.

Why: left free, Adam narrows a gradient's ramp until it is a step, and uses the fill to draw an
edge or a blob inside its path (a dark disk in a window, a red cloud where shutters stood). Those
"ghost" shapes have soft or off-colour edges no designer would draw, and they spend the path's
fill on detail that belongs to a path of its own. A fill that must stay a broad ramp leaves
edges to geometry. The extent is measured on the path's control points (they bound its
outline): along the direction of a linear gradient, and as the range of distances from the
centre of a radial one. Stops between the first and last keep their relative places.
"""

from __future__ import annotations

import numpy as np

from samvg.render._paint_kernels import FLAT, LINEAR


def widen_ramps(
    kinds: np.ndarray,
    stop_counts: np.ndarray,
    params: np.ndarray,
    points: np.ndarray,
    offsets: np.ndarray,
    fraction: float,
) -> np.ndarray:
    """The rows of ``params`` (P, PARAMS: geometry, stop offsets, stop RGB as
    `samvg.render.rasterizer.GradientPaints`) whose ramps are too short, widened; a boolean
    (P,) array says which rows changed (``params`` is changed in place). Path ``p`` has the
    control points ``points[offsets[p]:offsets[p + 1]]``."""
    changed = np.zeros(len(kinds), dtype=bool)
    if fraction <= 0:
        return changed
    for row in np.flatnonzero(kinds != FLAT):
        outline = points[offsets[row] : offsets[row + 1]]
        count = int(stop_counts[row])
        if len(outline) == 0 or count < 2:
            continue
        if kinds[row] == LINEAR:
            changed[row] = _widen_linear(params[row], count, outline, fraction)
        else:
            changed[row] = _widen_radial(params[row], count, outline, fraction)
    return changed


def _rescale_stops(row: np.ndarray, count: int, low: float, high: float) -> None:
    """The row's stop offsets mapped onto [low, high]: the first stop to ``low``, the last to
    ``high``, those between in proportion."""
    stops = row[4 : 4 + count]
    first, last = stops[0], stops[count - 1]
    if last - first > 1e-9:
        share = (stops - first) / (last - first)
    else:
        share = np.linspace(0.0, 1.0, count)
    row[4 : 4 + count] = low + share * (high - low)


def _widen_linear(row: np.ndarray, count: int, outline: np.ndarray, fraction: float) -> bool:
    start, end = row[0:2].copy(), row[2:4].copy()
    axis = end - start
    length = float(np.hypot(axis[0], axis[1]))
    if length < 1e-9:
        return False  # no direction to widen along
    unit = axis / length
    along = outline @ unit
    needed = fraction * float(along.max() - along.min())
    first, last = row[4], row[4 + count - 1]
    if (last - first) * length >= needed or needed <= 0:
        return False
    middle = start + axis * (first + last) / 2
    row[0:2] = middle - unit * needed / 2
    row[2:4] = middle + unit * needed / 2
    _rescale_stops(row, count, 0.0, 1.0)
    return True


def _widen_radial(row: np.ndarray, count: int, outline: np.ndarray, fraction: float) -> bool:
    centre, radius = row[0:2], float(row[2])
    distance = np.hypot(outline[:, 0] - centre[0], outline[:, 1] - centre[1])
    needed = fraction * float(distance.max() - distance.min())
    first, last = row[4], row[4 + count - 1]
    inner, outer = first * radius, last * radius
    if outer - inner >= needed or needed <= 0:
        return False
    inner = max(0.0, (inner + outer) / 2 - needed / 2)
    outer = inner + needed
    row[2] = outer
    _rescale_stops(row, count, inner / outer, 1.0)
    return True
