"""Where to prompt SAM again: centres of large uncovered regions (stage 1) and of missing
components in the error map (stage 4), both found with a circular-kernel convolution.
"""

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


def error_map(target: np.ndarray, render: np.ndarray) -> np.ndarray:
    """D: per-pixel sum over R, G, B of |I − I′| (values in [0, 3])."""
    return np.abs(np.asarray(target, np.float32) - np.asarray(render, np.float32)).sum(axis=2)


def missing_component_map(
    target: np.ndarray, render: np.ndarray, radius: float, threshold: float
) -> tuple[np.ndarray, np.ndarray]:
    """(D1, D2): the error map averaged over a disc, and D1 >= ``threshold`` as a boolean map.

    The disc average keeps D1 on D's scale ([0, 3]), so the paper's ω = 0.784 means an average
    error of about 0.26 per channel over the disc.
    """
    kernel_size = circular_kernel(radius).sum()
    averaged = disc_sum(error_map(target, render), radius) / kernel_size
    return averaged, averaged >= threshold


def missing_component_prompts(
    averaged: np.ndarray, above: np.ndarray, max_prompts: int = 32
) -> np.ndarray:
    """Prompt points (N, 2) as (x, y): one per connected component of ``above``, largest first.

    The component's centroid when it lies inside the component, else its point of largest
    averaged error.
    """
    labels, count = ndimage.label(above)
    if count == 0:
        return np.zeros((0, 2))
    index = np.arange(1, count + 1)
    sizes = ndimage.sum_labels(above, labels, index)
    centroids = ndimage.center_of_mass(above, labels, index)
    peaks = ndimage.maximum_position(averaged, labels, index)
    prompts = []
    for label in index[np.argsort(-sizes, kind="stable")][:max_prompts]:
        row, col = centroids[label - 1]
        r, c = int(round(row)), int(round(col))
        if not (0 <= r < above.shape[0] and 0 <= c < above.shape[1]) or labels[r, c] != label:
            r, c = peaks[label - 1]
        prompts.append((c + 0.5, r + 0.5))
    return np.asarray(prompts, dtype=np.float64)
