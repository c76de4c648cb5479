"""The SAMVG pipeline: segment (stage 1), trace (2), optimize (3), add missing components and
optimize again (4). `run` returns every intermediate result; `vectorize` just the SVG.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from samvg.config import Config
from samvg.errors import SamvgError, WeightsError
from samvg.io import read_image, to_rgb_uint8
from samvg.vector_image import VectorImage, VectorPath

ProgressCallback = Callable[[str, int, int], None]
"""``progress(stage, done, total)``: called as each stage advances."""

STAGES = ("segment", "trace", "optimize", "missing", "refine")
UNIFORM_TOLERANCE = 1.5 / 255.0
MIN_WORKING_SIDE = 8


@dataclass
class PipelineResult:
    """The final SVG and what the stages produced on the way (working-resolution images)."""

    image: VectorImage
    initial: VectorImage | None = None
    optimized: VectorImage | None = None
    target: np.ndarray | None = None
    masks: list[np.ndarray] = field(default_factory=list)
    missing_map: np.ndarray | None = None
    missing_prompts: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    scale: float = 1.0
    timings: dict[str, float] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    mse: float = float("nan")
    notes: list[str] = field(default_factory=list)


def load_input(image: Any) -> np.ndarray:
    """A path or an in-memory image (numpy array or PIL image) as (H, W, 3) uint8 RGB."""
    if isinstance(image, (str, os.PathLike)):
        return read_image(image)
    return to_rgb_uint8(image)


def working_image(original: np.ndarray, size: int) -> tuple[np.ndarray, float]:
    """Downscale so the longer side is at most ``size`` (Lanczos); returns (image, scale)."""
    from PIL import Image

    height, width = original.shape[:2]
    scale = min(1.0, size / max(height, width))
    if scale == 1.0:
        return original, 1.0
    new_size = (max(2, round(width * scale)), max(2, round(height * scale)))
    resized = np.asarray(Image.fromarray(original).resize(new_size, Image.Resampling.LANCZOS))
    return resized, new_size[0] / width


def fit_options(config: Config, target: np.ndarray | None = None) -> dict[str, Any]:
    """The keyword arguments of `samvg.optimize.fit_paths` for one optimization phase.

    With ``target`` and ``config.use_lpips`` the LPIPS loss is loaded and bound to it (raises
    `WeightsError` when its weights cannot be found); baselines use this to run with exactly
    the losses and budget samvg uses.
    """
    options: dict[str, Any] = {
        "steps": config.iterations,
        "point_learning_rate": config.point_learning_rate,
        "colour_learning_rate": config.colour_learning_rate,
        "xing_weight": config.xing_weight,
    }
    if target is not None and config.use_lpips and config.lpips_weight > 0:
        options["lpips"] = perceptual_loss(target, config)
        options["lpips_weight"] = config.lpips_weight
    return options


def perceptual_loss(target: np.ndarray, config: Config) -> Callable:
    """LPIPS of a render against ``target``, both resized to ``config.lpips_size`` (long side)."""
    import torch
    import torch.nn.functional as functional

    from samvg.metrics import load_lpips

    model = load_lpips(config.lpips_weights)
    height, width = target.shape[:2]
    factor = min(1.0, config.lpips_size / max(height, width))
    size = (max(16, round(height * factor)), max(16, round(width * factor)))

    def prepare(image: torch.Tensor) -> torch.Tensor:
        batch = image.permute(2, 0, 1)[None]
        if size != (height, width):
            batch = functional.interpolate(batch, size=size, mode="bilinear", antialias=True)
        return batch

    target_batch = prepare(torch.from_numpy(np.ascontiguousarray(target, dtype=np.float32)))
    against_target = model.fixed_target(target_batch)

    def loss(rendered: torch.Tensor) -> torch.Tensor:
        return against_target(prepare(rendered)).mean()

    return loss


def run(
    image: Any,
    config: Config | None = None,
    progress: ProgressCallback | None = None,
    log: Callable[[str], None] | None = None,
) -> PipelineResult:
    """Vectorize ``image`` (a path, numpy array or PIL image) with every stage's output kept.

    Raises `InputError` for unusable input and `WeightsError` for missing SAM weights. LPIPS
    weights that cannot be found only switch the LPIPS term off (noted in ``result.notes``).
    """
    import torch

    config = config or Config()
    threads = torch.get_num_threads()
    if config.threads is not None:
        torch.set_num_threads(config.threads)
    try:
        return _run(image, config, progress, log)
    finally:
        torch.set_num_threads(threads)


def _run(
    image: Any,
    config: Config,
    progress: ProgressCallback | None,
    log: Callable[[str], None] | None,
) -> PipelineResult:
    import torch

    report = progress or (lambda _stage, _done, _total: None)
    say = log or (lambda _text: None)
    started = time.perf_counter()
    original = load_input(image)
    working, scale = working_image(original, config.size)
    height, width = working.shape[:2]
    target = working.astype(np.float32) / 255.0
    result = PipelineResult(image=VectorImage(original.shape[1], original.shape[0]), scale=scale)
    result.target = target

    mean_colour = tuple(float(v) for v in target.reshape(-1, 3).mean(axis=0, dtype=np.float64))
    if (
        min(height, width) < MIN_WORKING_SIDE
        or np.ptp(target, axis=(0, 1)).max() <= UNIFORM_TOLERANCE
    ):
        reason = "tiny" if min(height, width) < MIN_WORKING_SIDE else "uniform"
        result.notes.append(f"{reason} image: one background colour, no paths")
        result.image = VectorImage(original.shape[1], original.shape[0], background=mean_colour)
        result.mse = float(np.mean((target - np.asarray(mean_colour, np.float32)) ** 2))
        result.timings["total"] = time.perf_counter() - started
        return result

    torch.manual_seed(config.seed)
    from samvg.render import render_array
    from samvg.segment import (
        Segmenter,
        min_component_pixels,
        missing_component_map,
        missing_component_prompts,
        missing_masks,
        select_masks,
    )

    # Stage 1
    clock = time.perf_counter()
    report("segment", 0, 1)
    segmenter = Segmenter(config)
    selection = select_masks(working, segmenter, config)
    report("segment", 1, 1)
    result.timings["segment"] = time.perf_counter() - clock
    result.counts.update(
        amg_masks=selection.amg_masks,
        amg_components=selection.amg_components,
        kept_masks=selection.kept_after_filter,
        reprompt_masks=selection.reprompt_masks,
    )
    result.masks = selection.masks

    # Stage 2
    clock = time.perf_counter()
    min_pixels = min_component_pixels(config, height, width)
    points, colours = _trace(selection.masks, target, config.segments, min_pixels, report)
    covered = np.zeros((height, width), dtype=bool)
    for mask in selection.masks:
        covered |= mask
    background = (
        tuple(float(v) for v in target[~covered].mean(axis=0)) if (~covered).any() else mean_colour
    )
    result.initial = _to_image(points, colours, background, original.shape, scale)
    result.timings["trace"] = time.perf_counter() - clock
    result.counts["paths_initial"] = len(points)

    # Stage 3
    clock = time.perf_counter()
    options = fit_options(config)
    if config.use_lpips and config.lpips_weight > 0 and config.iterations > 0:
        try:
            options = fit_options(config, target)
        except (WeightsError, ImportError) as error:
            first_line = str(error).splitlines()[0]
            result.notes.append(f"LPIPS off (MSE + Xing only): {first_line}")
            say(result.notes[-1])
    fit = _fit(points, colours, target, background, options, "optimize", report)
    points, colours = fit.points, fit.colours
    result.optimized = _to_image(points, colours, background, original.shape, scale)
    result.timings["optimize"] = time.perf_counter() - clock

    # Stage 4
    if config.missing_components:
        clock = time.perf_counter()
        report("missing", 0, 1)
        render = render_array(points, colours, width, height, background)
        radius = config.missing_radius * max(height, width)
        averaged, above = missing_component_map(target, render, radius, config.missing_threshold)
        prompts = missing_component_prompts(averaged, above)
        result.missing_map = averaged
        result.missing_prompts = prompts
        new_masks = missing_masks(segmenter, prompts, target, render, config)
        new_points, new_colours = _trace(new_masks, target, config.segments, min_pixels, None)
        report("missing", 1, 1)
        result.counts["missing_prompts"] = len(prompts)
        result.counts["missing_paths"] = len(new_points)
        result.timings["missing"] = time.perf_counter() - clock
        if len(new_points):
            clock = time.perf_counter()
            points = np.concatenate([points, new_points])
            colours = np.concatenate([colours, new_colours])
            fit = _fit(points, colours, target, background, options, "refine", report)
            points, colours = fit.points, fit.colours
            result.timings["refine"] = time.perf_counter() - clock

    result.image = _to_image(points, colours, background, original.shape, scale)
    final_render = render_array(points, colours, width, height, background)
    result.mse = float(np.mean((final_render - target) ** 2))
    result.counts["paths"] = len(result.image.paths)
    result.timings["total"] = time.perf_counter() - started
    return result


def vectorize(
    image: Any, config: Config | None = None, progress: ProgressCallback | None = None
) -> VectorImage:
    """Vectorize ``image`` (a path, numpy array or PIL image) into a `VectorImage`.

    The SVG is in the input's pixel coordinates whatever the working size; same input, config
    and machine give the same SVG.
    """
    return run(image, config, progress).image


def _trace(
    masks: list[np.ndarray],
    target: np.ndarray,
    segments: int,
    min_pixels: float,
    report: ProgressCallback | None,
) -> tuple[np.ndarray, np.ndarray]:
    """Every component of every mask as a path: points (P, 3K, 2) and RGBA colours (P, 4)."""
    from samvg.trace import trace_masks

    if report is not None:
        report("trace", 0, 1)
    traced = trace_masks(masks, target, segments_per_path=segments, min_area=min_pixels)
    if report is not None:
        report("trace", 1, 1)
    points, colours = traced.stacked_paths()
    return (
        points.reshape(len(traced.paths), 3 * segments, 2),
        colours.reshape(len(traced.paths), 4),
    )


def _fit(points, colours, target, background, options, stage, report):  # type: ignore[no-untyped-def]
    from samvg.optimize import fit_paths

    steps = options["steps"]
    fit = fit_paths(
        points,
        colours,
        target,
        background=background,
        on_step=lambda step, _loss: report(stage, step + 1, steps),
        **options,
    )
    if not (np.all(np.isfinite(fit.points)) and np.all(np.isfinite(fit.colours))):
        raise SamvgError("optimization diverged (non-finite coordinates); try fewer iterations")
    return fit


def _to_image(points, colours, background, shape, scale) -> VectorImage:  # type: ignore[no-untyped-def]
    paths = [
        VectorPath(p / scale, tuple(np.clip(c, 0.0, 1.0)))
        for p, c in zip(points, colours, strict=True)
    ]
    return VectorImage(shape[1], shape[0], paths, background=background)
