"""The DiffVG baseline of the paper: closed blobs at random places with random colours, then
fitted with samvg's own optimiser, iteration budget and losses."""

from __future__ import annotations

import numpy as np

from samvg.baselines.common import (
    WHITE,
    StepProgress,
    as_target,
    blob,
    check_counts,
    check_steps,
)
from samvg.optimize import FitSettings, fit_scene
from samvg.scene import RGB, Scene

#: Blob radius range as fractions of the shorter canvas side.
RADIUS_RANGE = (0.03, 0.15)
#: Each anchor's distance from the centre is the radius times a factor in this range.
JITTER_RANGE = (0.75, 1.25)
#: Random fill opacity range (colour channels are uniform in [0, 1]).
ALPHA_RANGE = (0.5, 1.0)


def random_blobs(
    width: int, height: int, path_count: int, segments: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """``path_count`` jittered circles uniformly over the canvas: points (P, 3K, 2) and RGBA."""
    check_counts(path_count, segments)
    short = min(width, height)
    centres = rng.uniform((0.0, 0.0), (width, height), size=(path_count, 2))
    radii = rng.uniform(*RADIUS_RANGE, size=path_count) * short
    jitter = rng.uniform(*JITTER_RANGE, size=(path_count, segments))
    points = np.stack(
        [blob(c, r, segments, j) for c, r, j in zip(centres, radii, jitter, strict=True)]
    )
    colours = np.concatenate(
        [rng.uniform(size=(path_count, 3)), rng.uniform(*ALPHA_RANGE, size=(path_count, 1))],
        axis=1,
    )
    return points, colours


def random_init(
    target: np.ndarray,
    path_count: int,
    fit: FitSettings | None = None,
    *,
    steps: int | None = None,
    segments: int = 5,
    seed: int = 0,
    background: RGB = WHITE,
    progress: StepProgress | None = None,
) -> Scene:
    """Vectorize ``target`` with ``path_count`` random blobs fitted with ``fit`` (samvg's
    losses and learning rates; default `FitSettings()`) for ``steps`` steps (default
    ``fit.steps``); the same ``seed`` gives the same result."""
    fit = fit or FitSettings()
    fit = fit.with_steps(check_steps(fit.steps if steps is None else steps))
    image = as_target(target)
    height, width = image.shape[:2]
    points, colours = random_blobs(width, height, path_count, segments, np.random.default_rng(seed))
    offsets = np.arange(path_count + 1) * 3 * segments
    scene = Scene.from_arrays(
        width, height, points.reshape(-1, 2), offsets, colours, background=background
    )
    on_step = None if progress is None else (lambda step, _loss: progress(step + 1, fit.steps))
    return fit_scene(scene, image, fit, on_step).scene
