"""Numba kernels of gradient paints: the colour of a linear or radial gradient at a pixel centre,
and that colour's derivatives with respect to every paint parameter.

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
def _parameter(
    kind: int, g0: float, g1: float, g2: float, g3: float, px: float, py: float
) -> tuple[float, float, float, float, float]:
    """(t, dt/dg0, dt/dg1, dt/dg2, dt/dg3) at (px, py); derivatives 0 where t is clamped."""
    if kind == LINEAR:
        dx = g2 - g0
        dy = g3 - g1
        length2 = dx * dx + dy * dy
        if length2 < _TINY:
            return 1.0, 0.0, 0.0, 0.0, 0.0  # SVG: a zero-length vector paints the last stop
        rx = px - g0
        ry = py - g1
        n = rx * dx + ry * dy
        t = n / length2
        if t <= 0.0 or t >= 1.0:
            return min(max(t, 0.0), 1.0), 0.0, 0.0, 0.0, 0.0
        inv = 1.0 / length2
        # n and length2 as functions of the endpoints; dt = (dn - t dlength2) / length2
        d0 = ((-dx - rx) - t * (-2.0 * dx)) * inv
        d1 = ((-dy - ry) - t * (-2.0 * dy)) * inv
        d2 = (rx - t * (2.0 * dx)) * inv
        d3 = (ry - t * (2.0 * dy)) * inv
        return t, d0, d1, d2, d3
    radius = g2
    rx = px - g0
    ry = py - g1
    distance = math.sqrt(rx * rx + ry * ry)
    if radius < _TINY:
        return 1.0, 0.0, 0.0, 0.0, 0.0
    t = distance / radius
    if t >= 1.0 or distance < _TINY:
        return min(t, 1.0), 0.0, 0.0, 0.0, 0.0
    return t, -rx / (distance * radius), -ry / (distance * radius), -t / radius, 0.0


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
def paint_colour(
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray, p: int, px: float, py: float
) -> tuple[float, float, float]:
    """The RGB of gradient paint ``p`` at (px, py)."""
    t = _parameter(kinds[p], params[p, 0], params[p, 1], params[p, 2], params[p, 3], px, py)[0]
    j, w, span = _segment(params, p, stops[p], t)
    if j < 0:
        return params[p, 8], params[p, 9], params[p, 10]
    if span == 0.0:
        base = 8 + 3 * j
        return params[p, base], params[p, base + 1], params[p, base + 2]
    a = 8 + 3 * j
    b = a + 3
    return (
        params[p, a] + w * (params[p, b] - params[p, a]),
        params[p, a + 1] + w * (params[p, b + 1] - params[p, a + 1]),
        params[p, a + 2] + w * (params[p, b + 2] - params[p, a + 2]),
    )


@njit(cache=True, nogil=True)
def paint_backward(
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray, p: int, px: float, py: float,
    gr: float, gg: float, gb: float, gparams: np.ndarray,
) -> None:  # fmt: skip
    """Add dL/d params of paint ``p`` to ``gparams[p]``, given dL/d its colour at (px, py)."""
    t, d0, d1, d2, d3 = _parameter(
        kinds[p], params[p, 0], params[p, 1], params[p, 2], params[p, 3], px, py
    )
    j, w, span = _segment(params, p, stops[p], t)
    if j < 0 or span == 0.0:
        base = 8 + 3 * (0 if j < 0 else j)
        gparams[p, base] += gr
        gparams[p, base + 1] += gg
        gparams[p, base + 2] += gb
        return
    a = 8 + 3 * j
    b = a + 3
    gparams[p, a] += (1.0 - w) * gr
    gparams[p, a + 1] += (1.0 - w) * gg
    gparams[p, a + 2] += (1.0 - w) * gb
    gparams[p, b] += w * gr
    gparams[p, b + 1] += w * gg
    gparams[p, b + 2] += w * gb
    # dL/dw: the colour moves along (stop j+1 - stop j) as w grows
    dw = (
        gr * (params[p, b] - params[p, a])
        + gg * (params[p, b + 1] - params[p, a + 1])
        + gb * (params[p, b + 2] - params[p, a + 2])
    )
    gparams[p, 4 + j] += dw * (w - 1.0) / span
    gparams[p, 5 + j] += -dw * w / span
    dt = dw / span
    gparams[p, 0] += dt * d0
    gparams[p, 1] += dt * d1
    gparams[p, 2] += dt * d2
    gparams[p, 3] += dt * d3
