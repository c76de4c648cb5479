"""The LIVE baseline: paths added layer by layer (1, 2, 4, 8 ... per stage), each new one a small
circle at the centre of one of the largest regions of high error, all paths so far fitted again
after each addition.

LIVE's UDF-weighted loss and its Xing loss schedule are not reproduced: every stage uses the
losses of the given `FitSettings` (samvg's own), so the baselines differ only in initialization.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from samvg.baselines.common import (
    WHITE,
    StepProgress,
    as_target,
    blob,
    check_counts,
    check_steps,
)
from samvg.imaging import error_map
from samvg.optimize import FitSettings, fit_scene
from samvg.scene import RGB, FlatPaint, Scene

#: A pixel is "high error" when |render - target| summed over RGB exceeds this.
ERROR_THRESHOLD = 0.15
#: A new circle's radius: half the region's inscribed radius, at most this fraction of the
#: shorter canvas side and at least one pixel.
MAX_RADIUS_FRACTION = 0.05


@dataclass(frozen=True)
class Seed:
    """Where a new path starts: centre (x, y) in pixels, radius, RGB colour, region area."""

    centre: tuple[float, float]
    radius: float
    colour: tuple[float, float, float]
    area: int


def schedule(path_count: int) -> list[int]:
    """Paths added per stage: 1, 2, 4, 8 ..., the last stage cut so the total is ``path_count``."""
    check_counts(path_count, 1)
    stages, total, size = [], 0, 1
    while total < path_count:
        stages.append(min(size, path_count - total))
        total += stages[-1]
        size *= 2
    return stages


def find_seeds(
    error: np.ndarray,
    target: np.ndarray,
    count: int,
    threshold: float = ERROR_THRESHOLD,
) -> list[Seed]:
    """``count`` places for new paths: the largest connected regions of ``error > threshold``.

    Each seed sits at the region's point farthest from its border (inside even a ring-shaped
    region) and takes the region's mean target colour. When there are fewer regions than
    ``count``, the rest go to the highest-error pixels not yet used.
    """
    height, width = error.shape
    short = min(height, width)
    labels, found = ndimage.label(error > threshold, structure=np.ones((3, 3), dtype=bool))
    seeds: list[Seed] = []
    if found:
        areas = np.bincount(labels.ravel())[1:]
        order = np.argsort(-areas, kind="stable")[:count]
        boxes = ndimage.find_objects(labels)
        for index in order:
            box = boxes[index]
            region = labels[box] == index + 1
            inside = ndimage.distance_transform_edt(np.pad(region, 1))[1:-1, 1:-1]
            row, col = np.unravel_index(int(np.argmax(inside)), inside.shape)
            radius = float(np.clip(0.5 * inside[row, col], 1.0, MAX_RADIUS_FRACTION * short))
            mean = target[box][region].mean(axis=0)
            seeds.append(
                Seed(
                    centre=(box[1].start + col + 0.5, box[0].start + row + 0.5),
                    radius=radius,
                    colour=(float(mean[0]), float(mean[1]), float(mean[2])),
                    area=int(areas[index]),
                )
            )
    if len(seeds) < count:
        remaining = error.astype(np.float64).copy()
        for seed in seeds:
            x, y = int(seed.centre[0]), int(seed.centre[1])
            remaining[max(0, y - 1) : y + 2, max(0, x - 1) : x + 2] = -np.inf
        for flat in np.argsort(-remaining, axis=None, kind="stable")[: count - len(seeds)]:
            row, col = divmod(int(flat), width)
            seeds.append(
                Seed(
                    centre=(col + 0.5, row + 0.5),
                    radius=1.0,
                    colour=(
                        float(target[row, col, 0]),
                        float(target[row, col, 1]),
                        float(target[row, col, 2]),
                    ),
                    area=1,
                )
            )
    return seeds


def live(
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
    """Vectorize ``target`` with ``path_count`` paths added layer-wise, ``steps`` steps in all
    (default ``fit.steps``), fitted with ``fit`` (default `FitSettings()`).

    The step budget is split evenly over the stages of :func:`schedule` (the remainder goes to
    the last). ``seed`` is accepted for a uniform signature; the method is deterministic.
    """
    del seed
    check_counts(path_count, segments)
    fit = fit or FitSettings()
    total = check_steps(fit.steps if steps is None else steps)
    image = as_target(target)
    height, width = image.shape[:2]
    stages = schedule(path_count)
    per_stage = [total // len(stages)] * len(stages)
    per_stage[-1] += total - sum(per_stage)
    scene = Scene(width, height, background=background)
    done = 0
    for added, stage_steps in zip(stages, per_stage, strict=True):
        seeds = find_seeds(error_map(image, scene.render()), image, added)
        circles = [(blob(s.centre, s.radius, segments), FlatPaint((*s.colour, 1.0))) for s in seeds]
        scene = scene.stacked(Scene.from_paths(width, height, circles))

        def on_step(step: int, _loss: float, offset: int = done) -> None:
            if progress is not None:
                progress(offset + step + 1, total)

        scene = fit_scene(scene, image, fit.with_steps(stage_steps), on_step).scene
        done += stage_steps
    return scene
