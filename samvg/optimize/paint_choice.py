"""Which paths get a gradient fill: every path starts flat; before a fitting phase each flat path
is offered a linear and a radial gradient, fitted in closed form to the target over the pixels
where the path shows, and takes the one that lowers the error by more than
``cost × extra parameters`` (MSE units), else stays flat. An opaque flat background is offered
the same, over the pixels where only it shows (its extra parameters over an RGB colour are those
of a path's gradient over an RGBA fill). Adam then refines what was chosen.

The closed-form fits (least squares, numpy):

* linear: colour = a + b x + c y per channel; the gradient's direction is the top singular
  vector of the 3 × 2 slope matrix (one direction for all channels, as SVG has), and the two
  stops are the least-squares line of colour against the position along it, at the 2nd and 98th
  percentiles of the shown pixels;
* radial: the centre from a paraboloid fit of the luminance (a + b x + c y + d (x² + y²)), the
  radius the 98th percentile of the distance to it, and the two stops the least-squares line of
  colour against the distance.

The cost: stage 4 keeps a new path (about 28 numbers) when it lowers the error by 2e-5, i.e.
about 7e-7 per number; `DEFAULT_COST` asks the same of the 8 or 9 numbers a gradient adds over a
flat fill, so a gradient is bought only where a path would have been worth as much.
"""

from __future__ import annotations

from dataclasses import replace
from typing import cast

import numpy as np

from samvg.errors import InputError
from samvg.finish.flatten import flatten_paths
from samvg.optimize._labels import fill_outlines
from samvg.scene import (
    BackgroundGradient,
    FlatPaint,
    LinearGradient,
    Paint,
    RadialGradient,
    Scene,
)

DEFAULT_COST = 1e-6
"""MSE a gradient must remove per parameter it adds."""
#: Parameters a gradient adds over a flat fill (geometry, two offsets, a second RGB).
EXTRA_PARAMETERS = {"linear": 9, "radial": 8}
MIN_SHOWN_PIXELS = 32
_LOW, _HIGH = 2.0, 98.0


def shown_labels(scene: Scene) -> np.ndarray:
    """(H, W) int: the index of the top path whose outline holds each pixel centre, -1 where
    only the background shows (outlines filled by their polygons, in paint order)."""
    labels = np.full((scene.height, scene.width), -1, dtype=np.int64)
    vertices, offsets = flatten_paths(scene.points, scene.offsets)
    fill_outlines(np.ascontiguousarray(vertices, np.float64), np.asarray(offsets, np.int64), labels)
    return labels


def _line_fit(position: np.ndarray, colours: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares colours = p + q · position: ((2, 3) coefficients, squared error)."""
    design = np.stack([np.ones_like(position), position], axis=1)
    coefficients, *_ = np.linalg.lstsq(design, colours, rcond=None)
    residual = colours - design @ coefficients
    return coefficients, float(np.sum(residual**2))


def _two_stops(
    coefficients: np.ndarray, low: float, high: float
) -> tuple[tuple[float, tuple[float, float, float]], ...]:
    ends = [np.clip(coefficients[0] + coefficients[1] * at, 0.0, 1.0) for at in (low, high)]
    return tuple(
        (offset, (float(colour[0]), float(colour[1]), float(colour[2])))
        for offset, colour in zip((0.0, 1.0), ends, strict=True)
    )


def linear_candidate(
    xy: np.ndarray, colours: np.ndarray, opacity: float
) -> tuple[LinearGradient, float] | None:
    """The closed-form linear gradient over pixel centres ``xy`` (n, 2) of ``colours`` (n, 3)
    and its squared error (None when the colours have no slope)."""
    centred = xy - xy.mean(axis=0)
    design = np.concatenate([np.ones((len(xy), 1)), centred], axis=1)
    coefficients, *_ = np.linalg.lstsq(design, colours, rcond=None)
    slopes = coefficients[1:].T  # (3, 2)
    if not np.any(slopes):
        return None
    direction = np.linalg.svd(slopes)[2][0]
    along = centred @ direction
    low, high = np.percentile(along, [_LOW, _HIGH])
    if high - low < 1.0:
        return None
    line, error = _line_fit((along - low) / (high - low), colours)
    mean = xy.mean(axis=0)
    start, end = mean + low * direction, mean + high * direction
    paint = LinearGradient(_two_stops(line, 0.0, 1.0), opacity, tuple(start), tuple(end))
    return paint, error


def radial_candidate(
    xy: np.ndarray, colours: np.ndarray, opacity: float
) -> tuple[RadialGradient, float] | None:
    """The closed-form radial gradient (see the module docstring) and its squared error (None
    when the luminance has no round extremum)."""
    mean = xy.mean(axis=0)
    centred = xy - mean
    scale = max(float(np.abs(centred).max()), 1.0)
    unit = centred / scale
    luminance = colours @ np.array([0.299, 0.587, 0.114])
    design = np.stack([np.ones(len(xy)), unit[:, 0], unit[:, 1], (unit**2).sum(axis=1)], axis=1)
    (_, b, c, d), *_ = np.linalg.lstsq(design, luminance, rcond=None)
    if abs(d) < 1e-6:
        return None
    centre = mean + scale * np.array([-b / (2 * d), -c / (2 * d)])
    distance = np.linalg.norm(xy - centre, axis=1)
    radius = float(np.percentile(distance, _HIGH))
    if radius < 1.0 or np.linalg.norm(centre - mean) > 4 * scale:
        return None
    line, error = _line_fit(np.minimum(distance / radius, 1.0), colours)
    paint = RadialGradient(_two_stops(line, 0.0, 1.0), opacity, tuple(centre), radius)
    return paint, error


def best_paint(
    xy: np.ndarray, colours: np.ndarray, paint: FlatPaint, pixels: int, cost: float
) -> Paint:
    """``paint``, or the gradient over these shown pixels whose gain (MSE over an image of
    ``pixels`` pixels) beats ``cost`` per added parameter by the most."""
    flat_error = float(np.sum((colours - colours.mean(axis=0)) ** 2))
    best: Paint = paint
    best_margin = 0.0
    opacity = paint.rgba[3]
    for name, found in (
        ("linear", linear_candidate(xy, colours, opacity)),
        ("radial", radial_candidate(xy, colours, opacity)),
    ):
        if found is None:
            continue
        gain = (flat_error - found[1]) / (3 * pixels)
        margin = gain - cost * EXTRA_PARAMETERS[name]
        if margin > best_margin:
            best, best_margin = found[0], margin
    return best


def choose_gradients(
    scene: Scene,
    target: np.ndarray,
    cost: float = DEFAULT_COST,
    start: int = 0,
    *,
    background: bool = True,
) -> tuple[Scene, int]:
    """``scene`` with each flat path from index ``start`` on given a gradient where it pays
    (see the module docstring), and with ``background`` and ``start`` 0 an opaque flat
    background too, fitted over the pixels where only it shows; returns the scene and how many
    paints switched (the background's included)."""
    if np.shape(target) != (scene.height, scene.width, 3):
        raise InputError(
            f"target {np.shape(target)} does not match the {scene.width}x{scene.height} scene"
        )
    labels = shown_labels(scene)
    paints = list(scene.paints)
    switched = 0
    for index in range(start, scene.path_count):
        paint = paints[index]
        if isinstance(paint, FlatPaint):
            chosen = _best_where(labels == index, target, paint, cost)
            if chosen is not paint:
                paints[index] = chosen
                switched += 1
    gradient = None
    if background and start == 0:
        gradient = _background_gradient(scene, labels == -1, target, cost)
    if gradient is not None:
        return replace(scene, paints=tuple(paints), background_gradient=gradient), switched + 1
    if not switched:
        return scene, 0
    return replace(scene, paints=tuple(paints)), switched


def _background_gradient(
    scene: Scene, shown: np.ndarray, target: np.ndarray, cost: float
) -> BackgroundGradient | None:
    """The gradient the scene's opaque flat background takes over its ``shown`` pixels, if one
    pays (None: no background, a gradient already, or flat is best)."""
    if scene.background is None or scene.background_gradient is not None:
        return None
    flat = FlatPaint((*scene.background, 1.0))
    chosen = _best_where(shown, target, flat, cost)
    return None if chosen is flat else cast(BackgroundGradient, chosen)


def _best_where(shown: np.ndarray, target: np.ndarray, paint: FlatPaint, cost: float) -> Paint:
    """`best_paint` over the ``shown`` (H, W) pixels of ``target``; ``paint`` where fewer than
    `MIN_SHOWN_PIXELS` show."""
    rows, cols = np.nonzero(shown)
    if len(rows) < MIN_SHOWN_PIXELS:
        return paint
    xy = np.stack([cols + 0.5, rows + 0.5], axis=1).astype(np.float64)
    return best_paint(xy, target[rows, cols].astype(np.float64), paint, shown.size, cost)
