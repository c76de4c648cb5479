"""The SAMVG pipeline as a short driver over the stage functions: segment (stage 1) → trace (2)
→ fit (3) → add missing components, as many rounds as asked (4) → finish. `run` returns every
intermediate result; `vectorize` just the SVG.

Each stage owns its settings: they are derived here once from `Config`, in working pixels.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import torch

from samvg.config import Config
from samvg.errors import WeightsError
from samvg.imaging import resize_longest, to_float_rgb, to_rgb_uint8
from samvg.io import read_image
from samvg.missing import MissingSettings, add_missing
from samvg.optimize import FitSettings, fit_scene
from samvg.scene import Frame, Scene
from samvg.segment import Segmenter, SegmentSettings, select_masks
from samvg.trace.stage import TraceSettings, trace_scene, uncovered_background
from samvg.vector_image import VectorImage

ProgressCallback = Callable[[str, int, int], None]
"""``progress(stage, done, total)``: called as each stage advances."""
LogCallback = Callable[[str], None]

UNIFORM_TOLERANCE = 1.5 / 255.0
MIN_WORKING_SIDE = 8


@dataclass
class PipelineResult:
    """The final SVG and what the stages produced on the way.

    ``scene`` is the final scene in working pixels; ``image``, ``initial`` and ``optimized``
    are in the input's pixels; ``target``, ``masks`` and ``missing_map`` at working size.
    """

    image: VectorImage
    scene: Scene | None = None
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


@contextlib.contextmanager
def _timed(result: PipelineResult, stage: str) -> Iterator[None]:
    clock = time.perf_counter()
    yield
    result.timings[stage] = result.timings.get(stage, 0.0) + time.perf_counter() - clock


@contextlib.contextmanager
def _torch_threads(threads: int | None) -> Iterator[None]:
    previous = torch.get_num_threads()
    if threads is not None:
        torch.set_num_threads(threads)
    try:
        yield
    finally:
        torch.set_num_threads(previous)


def run(
    image: Any,
    config: Config | None = None,
    progress: ProgressCallback | None = None,
    log: LogCallback | None = None,
) -> PipelineResult:
    """Vectorize ``image`` (a path, numpy array or PIL image) with every stage's output kept.

    Raises `InputError` for unusable input and `WeightsError` for missing SAM weights. LPIPS
    weights that cannot be found only switch the LPIPS term off (noted in ``result.notes``).
    """
    config = config or Config()
    report = progress or (lambda _stage, _done, _total: None)
    say = log or (lambda _text: None)
    started = time.perf_counter()
    with _torch_threads(config.threads):
        original = load_input(image)
        working, scale = resize_longest(original, config.size)
        target = to_float_rgb(working)
        frame = Frame(original.shape[1], original.shape[0], scale)
        result = PipelineResult(image=VectorImage(frame.width, frame.height), scale=scale)
        result.target = target
        if not _is_flat(target, frame, result):
            _run_stages(working, target, frame, config, result, report, say)
    result.timings["total"] = time.perf_counter() - started
    return result


def _is_flat(target: np.ndarray, frame: Frame, result: PipelineResult) -> bool:
    """A tiny or uniform image becomes one background colour: no paths, no SAM."""
    height, width = target.shape[:2]
    tiny = min(height, width) < MIN_WORKING_SIDE
    if not tiny and np.ptp(target, axis=(0, 1)).max() > UNIFORM_TOLERANCE:
        return False
    mean = target.reshape(-1, 3).mean(axis=0, dtype=np.float64)
    colour = (float(mean[0]), float(mean[1]), float(mean[2]))
    result.notes.append(f"{'tiny' if tiny else 'uniform'} image: one background colour, no paths")
    result.scene = Scene(width, height, background=colour, frame=frame)
    result.image = VectorImage.from_scene(result.scene)
    result.mse = float(np.mean((target - np.asarray(colour, np.float32)) ** 2))
    return True


def _fit_settings(
    config: Config, target: np.ndarray, result: PipelineResult, say: LogCallback
) -> FitSettings:
    """Stage 3's settings; LPIPS weights that cannot be found switch LPIPS off, with a note."""
    try:
        return FitSettings.from_options(config.fit, target)
    except (WeightsError, ImportError) as error:
        result.notes.append(f"LPIPS off (MSE + Xing only): {str(error).splitlines()[0]}")
        say(result.notes[-1])
        return FitSettings.from_options(config.fit)


def _progress_of(report: ProgressCallback, stage: str, steps: int) -> Callable[[int, float], None]:
    return lambda step, _loss: report(stage, step + 1, steps)


def _run_stages(
    working: np.ndarray,
    target: np.ndarray,
    frame: Frame,
    config: Config,
    result: PipelineResult,
    report: ProgressCallback,
    say: LogCallback,
) -> None:
    height, width = target.shape[:2]
    torch.manual_seed(config.seed)
    with _timed(result, "segment"):
        report("segment", 0, 1)
        segmenter = Segmenter(config.segment, config.device)
        settings = SegmentSettings.from_config(config, width, height)
        selection = select_masks(working, segmenter, settings)
        report("segment", 1, 1)
    result.masks = selection.masks
    result.counts.update(
        amg_masks=selection.amg_masks,
        amg_components=selection.amg_components,
        kept_masks=selection.kept_after_filter,
        reprompt_masks=selection.reprompt_masks,
    )
    trace_settings = TraceSettings.from_config(config, width, height)
    with _timed(result, "trace"):
        report("trace", 0, 1)
        traced = trace_scene(selection.masks, target, trace_settings)
        background = uncovered_background(selection.masks, target)
        scene = replace(traced, background=background, frame=frame)
        report("trace", 1, 1)
    result.initial = VectorImage.from_scene(scene)
    result.counts["paths_initial"] = scene.path_count

    fit = _fit_settings(config, target, result, say)
    with _timed(result, "optimize"):
        scene = fit_scene(scene, target, fit, _progress_of(report, "optimize", fit.steps)).scene
    result.optimized = VectorImage.from_scene(scene)

    missing = MissingSettings.from_config(config, width, height)
    result.counts.update(missing_prompts=0, missing_paths=0)
    for _ in range(missing.rounds):
        report("missing", 0, 1)
        on_step = _progress_of(report, "refine", fit.steps)
        round_ = add_missing(scene, target, segmenter, missing, trace_settings, fit, on_step)
        report("missing", 1, 1)
        scene = round_.scene
        result.missing_map, result.missing_prompts = round_.error_map, round_.prompts
        result.counts["missing_prompts"] += len(round_.prompts)
        result.counts["missing_paths"] += round_.added
        for stage, seconds in round_.timings.items():
            result.timings[stage] = result.timings.get(stage, 0.0) + seconds
    _finish(scene, target, result)


def _finish(scene: Scene, target: np.ndarray, result: PipelineResult) -> None:
    result.scene = scene
    result.image = VectorImage.from_scene(scene)
    result.mse = float(np.mean((scene.render() - target) ** 2))
    result.counts["paths"] = scene.path_count


def vectorize(
    image: Any, config: Config | None = None, progress: ProgressCallback | None = None
) -> VectorImage:
    """Vectorize ``image`` (a path, numpy array or PIL image) into a `VectorImage`.

    The SVG is in the input's pixel coordinates whatever the working size; same input, config
    and machine give the same SVG.
    """
    return run(image, config, progress).image
