"""Palette: snap the fills of a scene to ``n`` colours, by k-means in CIELAB weighted by the
area each path paints (scikit-learn ``KMeans``); opacity is kept, gradient fills are left as
they are."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from skimage.color import lab2rgb, rgb2lab
from sklearn.cluster import KMeans

from samvg.errors import InputError
from samvg.finish.flatten import flatten_paths
from samvg.finish.outline import polygon_areas
from samvg.scene import FlatPaint, Scene


def check_colour_count(n: object) -> int:
    """``n`` as a colour count (an integer >= 1), else :class:`InputError`."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InputError(f"the number of colours must be an integer >= 1, got {n!r}")
    return int(n)


def snap_colours(scene: Scene, n: int) -> tuple[Scene, dict[str, int]]:
    """``scene`` with every fill replaced by the nearest of ``n`` colours (the centres of an
    area-weighted k-means of the fills in CIELAB); unchanged when it has at most ``n`` distinct
    fill colours. Counts: ``palette_colours`` (distinct fill colours after), ``palette_changed``
    (paths whose fill changed)."""
    n = check_colour_count(n)
    colours = scene.colours()
    distinct = np.unique(colours[:, :3], axis=0) if len(colours) else colours[:, :3]
    if len(distinct) <= n:
        return scene, {"palette_colours": len(distinct), "palette_changed": 0}
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    weights = np.maximum(polygon_areas(vertices, vertex_offsets), 1e-6)
    lab = rgb2lab(colours[None, :, :3])[0]
    kmeans = KMeans(n_clusters=n, n_init=4, random_state=0)
    labels = kmeans.fit_predict(lab, sample_weight=weights)
    centres = np.clip(lab2rgb(kmeans.cluster_centers_[None])[0], 0.0, 1.0)
    snapped = colours.copy()
    snapped[:, :3] = centres[labels]
    paints = tuple(
        FlatPaint(tuple(row)) if isinstance(paint, FlatPaint) else paint  # gradients stay
        for row, paint in zip(snapped, scene.paints, strict=True)
    )
    changed = int(np.sum(np.any(snapped != colours, axis=1)))
    result = replace(scene, paints=paints)
    return result, {
        "palette_colours": len(np.unique(snapped[:, :3], axis=0)),
        "palette_changed": changed,
    }
