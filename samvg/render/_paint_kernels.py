"""Numba kernels of gradient paints: the colours of a linear or radial gradient at the pixel
centres of one box row (``paint_row``), and their derivatives with respect to every paint
parameter (``paint_row_backward``).

Why rows: the rasterizer calls these once per box row, not once per pixel. A per-pixel call
with array arguments was not inlined by LLVM and made gradient fills 4-5x slower than flat ones;
per row, the paint constants are read once and the geometry sums of the backward pass stay in
registers. Each pixel still gets exactly the arithmetic of a pixel evaluated alone.

A gradient paint is one row of a float64 parameter array (``PARAMS`` columns):

* ``[0:4]`` geometry: linear ``(x1, y1, x2, y2)``, the gradient vector; radial ``(cx, cy, r, _)``
  (focal point at the centre), in pixel units;
* ``[4:8]`` stop offsets, non-decreasing, in [0, 1];
* ``[8:20]`` stop colours, RGB, three per stop.

and two integers: the kind (``FLAT``, ``LINEAR``, ``RADIAL``) and the stop count (2 to 4). As in
SVG with ``spreadMethod="pad"``: the gradient parameter ``t`` is the projection onto the vector
(linear) or the distance from the centre over the radius (radial), clamped to [0, 1]; the colour
is the first stop's below the first offset, the last stop's above the last, and linear between
neighbouring stops. Paint is sampled at pixel centres, as resvg does.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

FLAT = 0
LINEAR = 1
RADIAL = 2
MAX_STOPS = 4
PARAMS = 8 + 3 * MAX_STOPS
_TINY = 1e-12


@njit(cache=True, nogil=True)
def _frame(kind: int, params: np.ndarray, p: int) -> tuple[float, float, float, float, float]:
    """Per-paint constants ``(g0, g1, dx, dy, den)``: the origin (linear start or radial
    centre), the linear vector, and ``den`` its squared length (linear) or the radius (radial);
    ``den < _TINY`` paints the last stop everywhere (SVG: a zero-length vector or radius)."""
    g0 = params[p, 0]
    g1 = params[p, 1]
    if kind == LINEAR:
        dx = params[p, 2] - g0
        dy = params[p, 3] - g1
        return g0, g1, dx, dy, dx * dx + dy * dy
    return g0, g1, 0.0, 0.0, params[p, 2]


@njit(cache=True, nogil=True)
def _parameter(
    kind: int, g0: float, g1: float, dx: float, dy: float, den: float, px: float, py: float
) -> tuple[float, bool, float, float, float]:
    """``(t, free, rx, ry, distance)`` at (px, py): the clamped gradient parameter, whether it
    moves with the geometry (not clamped), the offset from the origin and (radial) its length."""
    rx = px - g0
    ry = py - g1
    if den < _TINY:
        return 1.0, False, rx, ry, 0.0
    if kind == LINEAR:
        t = (rx * dx + ry * dy) / den
        return min(max(t, 0.0), 1.0), 0.0 < t < 1.0, rx, ry, 0.0
    distance = math.sqrt(rx * rx + ry * ry)
    t = distance / den
    return min(t, 1.0), t < 1.0 and distance >= _TINY, rx, ry, distance


@njit(cache=True, nogil=True)
def _slope(
    kind: int, dx: float, dy: float, den: float, inv: float, t: float, rx: float, ry: float,
    distance: float,
) -> tuple[float, float, float, float]:  # fmt: skip
    """(dt/dg0, dt/dg1, dt/dg2, dt/dg3) where t is free; ``inv`` = 1 / den (linear)."""
    if kind == LINEAR:
        # n = r . d and length2 as functions of the endpoints; dt = (dn - t dlength2) / length2
        return (
            ((-dx - rx) - t * (-2.0 * dx)) * inv,
            ((-dy - ry) - t * (-2.0 * dy)) * inv,
            (rx - t * (2.0 * dx)) * inv,
            (ry - t * (2.0 * dy)) * inv,
        )
    return -rx / (distance * den), -ry / (distance * den), -t / den, 0.0


@njit(cache=True, nogil=True)
def _segment(params: np.ndarray, p: int, stops: int, t: float) -> tuple[int, float, float]:
    """(j, w, span): t lies between stops j and j + 1 at weight w; span = their offset gap
    (j = -1: before the first stop; j = stops - 1: after the last; w, span unused)."""
    if t <= params[p, 4]:
        return -1, 0.0, 0.0
    for j in range(stops - 1):
        low = params[p, 4 + j]
        high = params[p, 5 + j]
        if t < high:
            span = high - low
            if span < _TINY:
                return j + 1, 0.0, 0.0  # coincident stops: a hard step
            return j, (t - low) / span, span
    return stops - 1, 0.0, 0.0


@njit(cache=True, nogil=True)
def paint_row(
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray, p: int, y: int, x0: int, n: int,
    rgb: np.ndarray,
) -> None:  # fmt: skip
    """``rgb[c]`` = the RGB of gradient paint ``p`` at the centre of pixel (y, x0 + c), c < n."""
    kind = kinds[p]
    count = stops[p]
    g0, g1, dx, dy, den = _frame(kind, params, p)
    py = y + 0.5
    for c in range(n):
        t = _parameter(kind, g0, g1, dx, dy, den, x0 + c + 0.5, py)[0]
        j, w, span = _segment(params, p, count, t)
        a = 8 + 3 * max(j, 0)
        if j < 0 or span == 0.0:
            rgb[c, 0] = params[p, a]
            rgb[c, 1] = params[p, a + 1]
            rgb[c, 2] = params[p, a + 2]
        else:
            rgb[c, 0] = params[p, a] + w * (params[p, a + 3] - params[p, a])
            rgb[c, 1] = params[p, a + 1] + w * (params[p, a + 4] - params[p, a + 1])
            rgb[c, 2] = params[p, a + 2] + w * (params[p, a + 5] - params[p, a + 2])


@njit(cache=True, nogil=True)
def paint_row_backward(
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray, p: int, y: int, x0: int, n: int,
    grgb: np.ndarray, gsum: np.ndarray,
) -> None:  # fmt: skip
    """Add to ``gsum`` (PARAMS,) dL/d params of paint ``p``, given dL/d its colour ``grgb[c]``
    at pixel (y, x0 + c), c < n, pixel by pixel in order (a zero gradient adds nothing)."""
    kind = kinds[p]
    count = stops[p]
    g0, g1, dx, dy, den = _frame(kind, params, p)
    inv = 1.0 / den if kind == LINEAR and den >= _TINY else 0.0
    py = y + 0.5
    # The geometry sums stay in registers; the stop sums, indexed by segment, in gsum.
    s0 = gsum[0]
    s1 = gsum[1]
    s2 = gsum[2]
    s3 = gsum[3]
    for c in range(n):
        gr = grgb[c, 0]
        gg = grgb[c, 1]
        gb = grgb[c, 2]
        if gr == 0.0 and gg == 0.0 and gb == 0.0:
            continue
        t, free, rx, ry, distance = _parameter(kind, g0, g1, dx, dy, den, x0 + c + 0.5, py)
        j, w, span = _segment(params, p, count, t)
        a = 8 + 3 * max(j, 0)
        if j < 0 or span == 0.0:
            gsum[a] += gr
            gsum[a + 1] += gg
            gsum[a + 2] += gb
            continue
        gsum[a] += (1.0 - w) * gr
        gsum[a + 1] += (1.0 - w) * gg
        gsum[a + 2] += (1.0 - w) * gb
        gsum[a + 3] += w * gr
        gsum[a + 4] += w * gg
        gsum[a + 5] += w * gb
        # dL/dw: the colour moves along (stop j+1 - stop j) as w grows
        dw = (
            gr * (params[p, a + 3] - params[p, a])
            + gg * (params[p, a + 4] - params[p, a + 1])
            + gb * (params[p, a + 5] - params[p, a + 2])
        )
        gsum[4 + j] += dw * (w - 1.0) / span
        gsum[5 + j] += -dw * w / span
        if free:  # a clamped t does not move: no geometry gradient
            dt = dw / span
            d0, d1, d2, d3 = _slope(kind, dx, dy, den, inv, t, rx, ry, distance)
            s0 += dt * d0
            s1 += dt * d1
            s2 += dt * d2
            s3 += dt * d3
    gsum[0] = s0
    gsum[1] = s1
    gsum[2] = s2
    gsum[3] = s3


@njit(cache=True, nogil=True)
def paint_canvas(
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray, p: int, image: np.ndarray
) -> None:
    """``image`` (H, W, 3) = gradient paint ``p`` at every pixel centre (a gradient background),
    row by row with `paint_row`."""
    for y in range(image.shape[0]):
        paint_row(kinds, stops, params, p, y, 0, image.shape[1], image[y])


@njit(cache=True, nogil=True)
def paint_canvas_backward(
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray, p: int, grad: np.ndarray
) -> np.ndarray:
    """dL/d params of paint ``p`` (PARAMS,), given dL/d the image of `paint_canvas` ``grad``
    (H, W, 3), row by row with `paint_row_backward`."""
    gsum = np.zeros(PARAMS, np.float64)
    for y in range(grad.shape[0]):
        paint_row_backward(kinds, stops, params, p, y, 0, grad.shape[1], grad[y], gsum)
    return gsum
