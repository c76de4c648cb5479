"""Which path shows at each pixel: every flattened outline filled by its pixel centres, even-odd
rule, in paint order (the top path's index wins).

skimage's ``draw.polygon`` gives the same pixels but tests every pixel of an outline's bounding
box against every edge, 0.25-0.6 s per fitting phase on a 512-px canvas with a few hundred
paths; this scanline fill crosses each pixel row with the edges once (about 5 ms).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def fill_outlines(vertices: np.ndarray, offsets: np.ndarray, labels: np.ndarray) -> None:
    """Write path ``p``'s index into the pixels of ``labels`` (H, W) whose centres lie inside its
    outline ``vertices[offsets[p]:offsets[p + 1]]`` (x, y in pixel units) by the even-odd rule,
    paths in order; other pixels keep their value."""
    height, width = labels.shape
    crossings = np.empty(vertices.shape[0] + 1, np.float64)
    for p in range(offsets.shape[0] - 1):
        start, stop = offsets[p], offsets[p + 1]
        if stop - start < 3:
            continue
        low = np.inf
        high = -np.inf
        for v in range(start, stop):
            low = min(low, vertices[v, 1])
            high = max(high, vertices[v, 1])
        first = max(0, int(math.ceil(low - 0.5)))
        last = min(height - 1, int(math.floor(high - 0.5)))
        for row in range(first, last + 1):
            y = row + 0.5
            count = 0
            for v in range(start, stop):
                w = v + 1 if v + 1 < stop else start
                y0, y1 = vertices[v, 1], vertices[w, 1]
                if (y0 <= y < y1) or (y1 <= y < y0):
                    x0, x1 = vertices[v, 0], vertices[w, 0]
                    crossings[count] = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
                    count += 1
            crossings[:count].sort()
            for pair in range(0, count - 1, 2):
                # centres x = col + 0.5 with crossings[pair] <= x < crossings[pair + 1]
                begin = max(0, int(math.ceil(crossings[pair] - 0.5)))
                end = min(width, int(math.ceil(crossings[pair + 1] - 0.5)))
                for col in range(begin, end):
                    labels[row, col] = p
