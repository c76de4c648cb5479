"""Where stage 1 prompts SAM again: the centres of large uncovered regions, found with a
circular-kernel convolution (`disc_sum`, which stage 4 also uses on its error map)."""

from __future__ import annotations

import numpy as np
from scipy import ndimage, signal


def circular_kernel(radius: float) -> np.ndarray:
    """A disc of ones of the given radius (pixels) in a (2r+1)² square; at least the centre."""
    r = max(0, int(round(radius)))
    yy, xx = np.mgrid[-r : r + 1, -r : r + 1]
    disc = (xx * xx + yy * yy <= radius * radius + 1e-9) | ((xx == 0) & (yy == 0))
    return disc.astype(np.float32)


def disc_sum(image: np.ndarray, radius: float) -> np.ndarray:
    """Sum of ``image`` over a disc around every pixel (zero outside the image)."""
    kernel = circular_kernel(radius).astype(np.float64)
    if kernel.size <= 49:
        return ndimage.convolve(image.astype(np.float64), kernel, mode="constant")
    return signal.fftconvolve(image.astype(np.float64), kernel, mode="same")


def uncovered_prompts(
    covered: np.ndarray, radius: float, max_prompts: int = 32, seed: int = 0
) -> np.ndarray:
    """Prompt points (N, 2) as (x, y) in the large regions no kept mask covers.

    A pixel is a candidate when the disc of ``radius`` around it holds no covered pixel (the
    convolution of the coverage with the disc is zero). Candidates are grouped by mean shift
    (bandwidth = 4 × radius), and each cluster centre is snapped to its nearest candidate so the
    prompt lies inside the uncovered region even when the region is not convex.
    """
    from sklearn.cluster import MeanShift

    coverage = disc_sum(covered.astype(np.float32), radius)
    rows, cols = np.nonzero(coverage < 0.5)
    if len(rows) == 0:
        return np.zeros((0, 2))
    candidates = np.stack([cols, rows], axis=1).astype(np.float64)
    rng = np.random.default_rng(seed)
    sample = candidates
    if len(sample) > 4000:
        sample = candidates[rng.choice(len(candidates), 4000, replace=False)]
    clustering = MeanShift(bandwidth=max(4.0 * radius, 1.0), bin_seeding=True, n_jobs=1)
    clustering.fit(sample)
    labels, counts = np.unique(clustering.labels_, return_counts=True)
    centres = clustering.cluster_centers_[labels[np.argsort(-counts, kind="stable")]]
    nearest = np.argmin(((centres[:, None, :] - sample[None, :, :]) ** 2).sum(axis=2), axis=1)
    prompts = sample[nearest][:max_prompts]
    return prompts + 0.5  # pixel centres
