"""Baseline vectorizers of the paper's evaluation, run by one function with one shape.

- ``diffvg``: random closed blobs fitted with samvg's optimiser (:mod:`.random_init`);
- ``live``: LIVE-style layer-wise initialization at regions of high error (:mod:`.live`);
- ``vtracer``: VTracer with settings searched to match a path count (:mod:`.vtracer_baseline`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from samvg.baselines.common import WHITE, StepProgress, as_target, blob
from samvg.baselines.live import live, schedule
from samvg.baselines.random_init import random_blobs, random_init
from samvg.baselines.vtracer_baseline import (
    TracedSvg,
    count_paths,
    count_shapes,
    render_svg,
    vtracer_trace,
)
from samvg.errors import InputError
from samvg.optimize import FitSettings
from samvg.scene import RGB, Scene
from samvg.vector_image import VectorImage

BASELINES = ("diffvg", "live", "vtracer", "vtracer-shapes")
#: samvg optimises in two phases (after tracing, after adding missing components); a baseline
#: given only samvg's `FitSettings` (one phase) gets this many times its steps.
SAMVG_PHASES = 2

Vectorized = VectorImage | TracedSvg


def run_baseline(
    name: str,
    target: np.ndarray,
    path_count: int,
    fit: FitSettings | None = None,
    seed: int = 0,
    *,
    steps: int | None = None,
    segments: int = 5,
    background: RGB = WHITE,
    progress: StepProgress | None = None,
) -> Vectorized:
    """Vectorize ``target`` (uint8 or float RGB) with baseline ``name`` and ``path_count`` paths.

    ``fit`` are the settings samvg fits one phase with (its losses, learning rates and steps);
    the optimising baselines run ``steps`` steps in all, by default ``SAMVG_PHASES *
    fit.steps``, so they get samvg's iterations and losses. ``vtracer`` (at most ``path_count``
    ``<path>`` elements) and ``vtracer-shapes`` (at most ``path_count`` closed shapes, counting
    every subpath of its compound paths) ignore the fitting arguments. Optimising baselines come
    back as a `VectorImage` on the target's canvas, with flat fills whatever ``fit`` says about
    gradients.
    """
    if name not in BASELINES:
        raise InputError(f"unknown baseline {name!r}; choose from {', '.join(BASELINES)}")
    if name in ("vtracer", "vtracer-shapes"):
        return vtracer_trace(target, path_count, count="shapes" if name != "vtracer" else "paths")
    if steps is None:
        if fit is None:
            raise InputError("give steps, or samvg's fit settings (steps per phase)")
        steps = SAMVG_PHASES * fit.steps
    method = random_init if name == "diffvg" else live
    if fit is not None:  # DiffVG and LIVE fill flat: samvg's gradient choice is not theirs
        fit = replace(fit, gradient_cost=None)
    scene = method(
        target,
        path_count,
        fit,
        steps=steps,
        segments=segments,
        seed=seed,
        background=background,
        progress=progress,
    )
    return VectorImage.from_scene(scene)


def path_count(result: Vectorized | Scene) -> int:
    """Number of paths: ``<path>`` elements, a compound path one (a background colour or
    rectangle of a VectorImage is not counted)."""
    if isinstance(result, TracedSvg):
        return result.path_count
    scene = result if isinstance(result, Scene) else result.scene
    return scene.element_count


def parameter_count(result: Vectorized | Scene) -> int:
    """All coordinates and colour values: 6K + 4 per path of K cubic segments (34 for K = 5,
    the paper's count); for VTracer, every number of its path data and transforms plus RGB."""
    if isinstance(result, TracedSvg):
        return result.parameter_count
    scene = result if isinstance(result, Scene) else result.scene
    return scene.parameter_count


__all__ = [
    "BASELINES",
    "SAMVG_PHASES",
    "WHITE",
    "TracedSvg",
    "Vectorized",
    "as_target",
    "blob",
    "count_paths",
    "count_shapes",
    "live",
    "parameter_count",
    "path_count",
    "random_blobs",
    "random_init",
    "render_svg",
    "run_baseline",
    "schedule",
    "vtracer_trace",
]
