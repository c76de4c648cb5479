"""Where stage 4 prompts SAM: components of the disc-averaged error map between the image and
the optimized render that exceed the paper's threshold ω."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from samvg.imaging import error_map
from samvg.segment.prompts import circular_kernel, disc_sum


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
