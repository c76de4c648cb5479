"""Segments split and merged between fitting phases: each fitted path is untangled (see
`samvg.finish.simplify_paths`) and its outline traced again within the tracer's tolerance, so a
segment count follows the outline the optimizer arrived at (more where it grew detail, fewer
where segments became collinear) before the next phase fits again."""

from __future__ import annotations

import numpy as np

from samvg.finish import flatten_paths, simplify_paths
from samvg.finish.flatten import polygons
from samvg.scene import Scene
from samvg.trace import refit_outlines


def reshape_scene(
    scene: Scene, tolerance: float, max_segments: int, box: tuple[float, float, float, float]
) -> tuple[Scene, dict[str, int]]:
    """``scene`` with simple paths whose segments are re-chosen within ``tolerance`` (pixels);
    paints, background and frame are kept. Counts: the untangling's, plus segments before and
    after."""
    untangled, counts = simplify_paths(scene, tolerance, box=box)
    if untangled.path_count == 0:
        return untangled, counts
    vertices, vertex_offsets = flatten_paths(untangled.points, untangled.offsets)
    outlines = refit_outlines(polygons(vertices, vertex_offsets), tolerance, max_segments)
    x0, y0, x1, y1 = box
    low, high = np.array([x0, y0]), np.array([x1, y1])
    reshaped = untangled.with_paths(
        [
            (np.clip(points, low, high), paint)
            for points, paint in zip(outlines, untangled.paints, strict=True)
        ]
    )
    counts.update(
        reshape_segments_in=int(scene.segment_counts().sum()),
        reshape_segments_out=int(reshaped.segment_counts().sum()),
    )
    return reshaped, counts
