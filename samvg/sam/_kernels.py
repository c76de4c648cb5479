"""Numba kernels for the mask decoder's output stage (layout of mask logits, stability counts).

The second transposed convolution of SAM's mask decoder maps each cell of the 64x64 embedding
grid to a 4x4 block of low-res pixels. `FastDecoder.masks_and_counts` computes the per-pixel
mask logits cell by cell (``(B, gh, gw, 2, 2, 2, 2, M)``: cell row, cell col, first and second
sub-pixel row/col, mask); `scatter_logits_counts` writes them in image layout and counts, in
the same pass, the logits above the two stability thresholds inside the image region.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def scatter_logits_counts(
    cells: np.ndarray, vh: int, vw: int, hi: float, lo: float, out: np.ndarray, counts: np.ndarray
) -> None:
    """cells (B, gh, gw, 2, 2, 2, 2, M) float32 -> out (B, M, 4gh, 4gw) and counts (B, M, 2).

    counts[b, m, 0] / [b, m, 1]: number of logits > ``hi`` / > ``lo`` among rows < vh and
    cols < vw (the low-res pixels covering the image).
    """
    nb, gh, gw = cells.shape[0], cells.shape[1], cells.shape[2]
    nm = cells.shape[7]
    for b in range(nb):
        for m in range(nm):
            counts[b, m, 0] = 0
            counts[b, m, 1] = 0
        for i in range(gh):
            for a1 in range(2):
                for a2 in range(2):
                    r = 4 * i + 2 * a1 + a2
                    row_in = r < vh
                    for j in range(gw):
                        for b1 in range(2):
                            for b2 in range(2):
                                c = 4 * j + 2 * b1 + b2
                                inside = row_in and c < vw
                                for m in range(nm):
                                    v = cells[b, i, j, a1, b1, a2, b2, m]
                                    out[b, m, r, c] = v
                                    if inside:
                                        if v > hi:
                                            counts[b, m, 0] += 1
                                        if v > lo:
                                            counts[b, m, 1] += 1
