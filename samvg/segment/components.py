"""Masks as paths will draw them: each connected component, holes filled, tiny ones dropped.

Stage 2 turns every component of a mask into its own path and fills its holes, so stage 1
filters components rather than whole masks: the impact of a candidate is then the impact of
exactly one path, and the path count follows the filter.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage


def split_components(mask: np.ndarray, min_pixels: float) -> list[np.ndarray]:
    """The 4-connected components of ``mask`` with at least ``min_pixels`` pixels, each with its
    holes filled, as full-size boolean masks, largest first."""
    binary = np.asarray(mask, dtype=bool)
    labels, count = ndimage.label(binary)
    if count == 0:
        return []
    sizes = np.bincount(labels.ravel(), minlength=count + 1)[1:]
    boxes = ndimage.find_objects(labels)
    components = []
    for label in np.argsort(-sizes, kind="stable") + 1:
        if sizes[label - 1] < min_pixels:
            break
        rows, cols = boxes[label - 1]
        component = np.zeros(binary.shape, dtype=bool)
        component[rows, cols] = ndimage.binary_fill_holes(labels[rows, cols] == label)
        components.append(component)
    return components


def all_components(masks: list[np.ndarray], min_pixels: float) -> list[np.ndarray]:
    """`split_components` of every mask, in one list (largest first within each mask)."""
    return [part for mask in masks for part in split_components(mask, min_pixels)]
