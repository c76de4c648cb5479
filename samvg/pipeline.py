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

from samvg.config import Config, FitOptions, SegmentOptions
from samvg.device import check_device
from samvg.errors import WeightsNotFoundError
from samvg.finish import (
    FinishSettings,
    crossing_paths,
    finish_scene,
    flatten_paths,
    simplify_paths,
)
from samvg.finish.compound import join_pieces
from samvg.finish.outline import polygon_areas
from samvg.finish.whole_pixels import ROUNDING_SHARE, whole_pixel_paths
from samvg.imaging import alpha_channel, resize_longest, to_float_rgb, to_rgb_uint8
from samvg.io import read_image_with_alpha
from samvg.metrics.lpips import load_lpips, lpips_distance, lpips_weights_path, read_lpips_state
from samvg.missing import MissingSettings
from samvg.missing.stage import MAX_AUTO_ROUNDS, add_missing_rounds, budget_pool
from samvg.missing.texture import TextureSettings, add_texture_layers
from samvg.optimize import FitSettings, fit_scene
from samvg.optimize.fit import margin_box
from samvg.optimize.reduce import (
    IDLE_COST,
    flatten_idle_gradients,
    reduce_paths,
    remove_idle_paths,
)
from samvg.optimize.reshape import reshape_scene
from samvg.render.threads import using_render_threads
from samvg.sam import SPECS
from samvg.scene import FlatPaint, Frame, Scene
from samvg.segment import Segmenter, SegmentSettings, select_masks
from samvg.segment.tonal import textured
from samvg.svg.writer import DEFAULT_PRECISION
from samvg.trace.stage import (
    TraceSettings,
    drop_transparent,
    trace_scene,
    uncovered_background,
)
from samvg.vector_image import VectorImage
from samvg.weights import cache_dir, ensure_cache_folder, resolve_weights

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


def load_input(image: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """A path or an in-memory image (numpy array or PIL image) as (H, W, 3) uint8 RGB, and its
    opacity (H, W) in [0, 1] when it has an alpha channel that is not opaque everywhere."""
    if isinstance(image, (str, os.PathLike)):
        return read_image_with_alpha(image)
    return to_rgb_uint8(image), alpha_channel(image)


def _working_alpha(alpha: np.ndarray | None, shape: tuple[int, ...]) -> np.ndarray | None:
    """The opacity resized to the working image (Lanczos, as the image)."""
    if alpha is None or alpha.shape == shape[:2]:
        return alpha
    grey = np.repeat(np.round(alpha * 255.0).astype(np.uint8)[:, :, None], 3, axis=2)
    return to_float_rgb(resize_longest(grey, max(shape[:2]))[0])[:, :, 0]


@contextlib.contextmanager
def _timed(result: PipelineResult, stage: str) -> Iterator[None]:
    clock = time.perf_counter()
    yield
    result.timings[stage] = result.timings.get(stage, 0.0) + time.perf_counter() - clock


@contextlib.contextmanager
def _threads(threads: int | None) -> Iterator[None]:
    """torch's threads (SAM) and the rasterizer's set to ``threads`` for the run, and set back
    after it (None: both left as they are)."""
    if threads is None:
        yield
        return
    previous = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        with using_render_threads(threads):
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

    Raises `InputError` for unusable input or a device this machine lacks, and `WeightsError`
    for missing SAM weights or LPIPS weights that were named (``lpips_weights`` or
    ``$SAMVG_LPIPS_WEIGHTS``) but cannot be loaded; both before SAM runs. Only LPIPS weights
    that are nowhere to be found switch the LPIPS term off (noted in ``result.notes``).
    """
    config = config or Config()
    report = progress or (lambda _stage, _done, _total: None)
    say = log or (lambda _text: None)
    started = time.perf_counter()
    check_device(config.device)
    with _threads(config.threads):
        original, alpha = load_input(image)
        working, scale = resize_longest(original, config.size)
        target = to_float_rgb(working)
        frame = Frame(original.shape[1], original.shape[0], scale)
        result = PipelineResult(image=VectorImage(frame.width, frame.height), scale=scale)
        result.target = target
        if not _is_flat(target, frame, result):
            inputs = _Inputs(working, target, _working_alpha(alpha, working.shape), frame)
            _run_stages(inputs, config, result, report, say)
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


def check_resources(config: Config) -> None:
    """What a run needs besides its image, checked before any work: the device exists, the SAM
    weights are found (or the cache can take their download), and LPIPS weights that are
    named or cached load. Raises `InputError` or `WeightsError` with a one-line reason."""
    check_device(config.device)
    _check_sam_weights(config.segment)
    _check_lpips_weights(config.fit)


def _check_sam_weights(options: SegmentOptions) -> None:
    try:
        resolve_weights(SPECS[options.model], options.checkpoint, download=False)
    except WeightsNotFoundError:
        ensure_cache_folder(cache_dir())  # the run will download them: the cache must take it


def _check_lpips_weights(options: FitOptions) -> None:
    if not options.wants_lpips:
        return
    try:
        path = lpips_weights_path(options.lpips_weights, download=False)
    except WeightsNotFoundError:
        return  # nothing named, nothing cached: the run downloads them or leaves LPIPS out
    read_lpips_state(path)


def fit_settings(
    options: FitOptions, target: np.ndarray, canvas: tuple[int, int] | None = None
) -> tuple[FitSettings, str | None]:
    """Stage 3's settings bound to ``target``, and a note when LPIPS was left out because its
    weights are nowhere to be found (nothing named, nothing cached, no download worked). LPIPS
    weights that were named or cached but cannot be loaded raise `WeightsError`."""
    try:
        return FitSettings.from_options(options, target, canvas), None
    except (WeightsNotFoundError, ImportError) as error:
        note = f"LPIPS off (MSE + Xing only): {str(error).splitlines()[0]}"
        return FitSettings.from_options(options, canvas=canvas), note


def _progress_of(report: ProgressCallback, stage: str, steps: int) -> Callable[[int, float], None]:
    return lambda step, _loss: report(stage, step + 1, steps)


@dataclass(frozen=True)
class _Inputs:
    """The working image (uint8 and float), its opacity (None: opaque), the input frame."""

    working: np.ndarray
    target: np.ndarray
    alpha: np.ndarray | None
    frame: Frame

    @property
    def size(self) -> tuple[int, int]:
        return self.target.shape[1], self.target.shape[0]


def _run_stages(
    inputs: _Inputs,
    config: Config,
    result: PipelineResult,
    report: ProgressCallback,
    say: LogCallback,
) -> None:
    width, height = inputs.size
    options = config.fit
    if inputs.alpha is not None:  # translucency is learned where the input has it
        options = replace(options, translucent=True)
    fit, note = fit_settings(options, inputs.target, inputs.size)
    if note is not None:  # before SAM: named LPIPS weights that fail to load fail first
        result.notes.append(note)
        say(note)
    torch.manual_seed(config.seed)
    segmenter, masks = _segment(inputs, config, result, report)
    trace_settings = TraceSettings.from_config(config, width, height)
    scene = _trace(masks, inputs, trace_settings, config, result, report)
    missing = MissingSettings.from_config(config, width, height)
    drafted = missing.rounds != 0 and not missing.refit_scene  # the end fits the whole scene
    first = fit.draft() if drafted else fit
    with _timed(result, "optimize"):
        on_step = _progress_of(report, "optimize", first.steps)
        scene = fit_scene(scene, inputs.target, first, on_step).scene
    result.optimized = VectorImage.from_scene(scene)
    if missing.rounds != 0 and config.trace.adaptive and config.trace.reshape:
        with _timed(result, "reshape"):
            scene, counts = reshape_scene(
                scene, config.trace.tolerance, config.trace.max_segments, _box(config, inputs)
            )
        result.counts.update(counts)
    stages = (missing, trace_settings, fit)
    scene, fitted = _add_missing(scene, inputs, segmenter, stages, config, result, report, drafted)
    budget = config.missing.paths
    if budget is not None and config.finish.finish_pass:
        # merges and hidden paths go first; a path over the whole canvas stays a path until the
        # last pass: made the background here, it changed the refit's outcome (worse on 5 of 8
        # emoji and icons at 16 paths), where made so at the end it changes no pixel
        scene = _finish_pass(scene, config, inputs, result, report, background=False)
    if budget is not None:
        scene = _reduce(scene, inputs, fit, budget, result, report, fitted)
    if config.finish.finish_pass:
        scene = _finish_pass(scene, config, inputs, result, report, join_to=budget)
    if budget is not None:
        scene = _meet_budget(scene, inputs, budget, result)
    if _wants_texture(scene, inputs, budget, config):
        scene = _texture(scene, inputs, budget, config, result, report)
    simple = config.finish.finish_pass
    whole = simple and config.finish.whole_pixels
    _finish(scene, inputs.target, result, simple, _path_limit(config), whole)
    if budget is not None:
        _note_short_of(result, budget)


def _finish_pass(
    scene: Scene,
    config: Config,
    inputs: _Inputs,
    result: PipelineResult,
    report: ProgressCallback,
    background: bool = True,
    join_to: int | None = None,
) -> Scene:
    """The finish pass (``background``: whether a path over the whole canvas may become the
    background). With ``join_to``, the pieces a repair split off are joined into compound paths
    (`join_pieces`) until the scene has that many SVG elements: after the idle paths go (or
    joins made for them would leave the scene short of a budget), before idle gradients go
    flat (a gradient made flat in one piece and not in the other would keep them apart)."""
    with _timed(result, "finish"):
        report("finish", 0, 1)
        settings = replace(_finish_settings(config, inputs), background_from_path=background)
        finished = finish_scene(scene, settings)
        scene = _within(finished.scene.with_fixed_from(scene), config, by_area=True)
        counts = dict(finished.counts)
        if config.finish.remove_idle:
            scene, counts["idle_removed"] = remove_idle_paths(scene, inputs.target, IDLE_COST)
        if join_to is not None:
            scene, counts["compound_joined"] = join_pieces(scene, join_to)
        if config.finish.flatten_idle_gradients:
            scene, counts["gradients_flattened"] = flatten_idle_gradients(
                scene, inputs.target, IDLE_COST
            )
        for name, count in counts.items():
            result.counts[name] = result.counts.get(name, 0) + count
        result.notes.append(_finish_note(counts))
        report("finish", 1, 1)
    return scene


def _meet_budget(scene: Scene, inputs: _Inputs, budget: int, result: PipelineResult) -> Scene:
    """Paths the finish pass split off beyond the budget, and could not join into compound
    paths (`_finish_pass`'s ``join_to``), are removed (least cost first)."""
    if scene.element_count > budget:
        scene, removed = reduce_paths(scene, inputs.target, budget)
        result.counts["reduced"] = result.counts.get("reduced", 0) + removed
    return scene


def _note_short_of(result: PipelineResult, budget: int) -> None:
    """A result short of the budget says why."""
    if result.counts["paths"] < budget:
        result.notes.append(
            f"{result.counts['paths']} paths, not {budget}: no further path lowers the error "
            "measurably (or the finish pass merged touching paths of one colour, or made a path "
            "over the whole canvas the background)"
        )


def _wants_texture(scene: Scene, inputs: _Inputs, budget: int | None, config: Config) -> bool:
    """Texture layers go over a textured image; without a budget, also over one whose fitted
    render still looks unlike it (`TextureSettings.min_lpips`): a pattern that stage 4's smooth
    paths left out (a moon's craters, a wallpaper's stars)."""
    if not config.missing.texture_layers:
        return False
    if textured(inputs.target):
        return True
    if budget is not None or not config.fit.wants_lpips:
        return False
    model = load_lpips(config.fit.lpips_weights, progress=False)
    return lpips_distance(model, scene.render(), inputs.target) >= TextureSettings().min_lpips


def _texture(
    scene: Scene,
    inputs: _Inputs,
    budget: int | None,
    config: Config,
    result: PipelineResult,
    report: ProgressCallback,
) -> Scene:
    """A textured image's texture layers (`add_texture_layers`): under a budget its last paths
    (their share of it, and more where the budget still has room), each kept only if the error
    drops (kodim03 at 256 paths: 144 -> 159 paths, LPIPS 0.210 -> 0.201); without a budget, on
    top of the paths, each kept only if it gains the ``--detail`` tolerance (as a round of
    stage 4 must)."""
    with _timed(result, "texture"):
        report("texture", 0, 1)
        settings = TextureSettings(seed=config.seed)
        opaque = None if inputs.alpha is None else inputs.alpha >= 0.5
        room = budget if budget is not None else scene.element_count + settings.max_layers
        min_gain = 0.0 if budget is not None else config.missing.gain_tolerance
        scene, layers = add_texture_layers(scene, inputs.target, room, settings, opaque, min_gain)
        if (
            budget is not None
            and scene.element_count < budget
            and layers == settings.layers(budget)
        ):
            filling = replace(settings, share=1.0, max_layers=budget - scene.element_count)
            scene, more = add_texture_layers(scene, inputs.target, budget, filling, opaque)
            layers += more
        report("texture", 1, 1)
    result.counts["texture_layers"] = layers
    if budget is not None and not settings.layers(budget):
        return scene
    islands = sum(len(element) for element in scene.elements()[-layers:]) if layers else 0
    plural = "" if layers == 1 else "s"
    result.notes.append(f"texture: {layers} layer{plural}, {islands} islands in all")
    return scene


def _segment(
    inputs: _Inputs, config: Config, result: PipelineResult, report: ProgressCallback
) -> tuple[Segmenter, list[np.ndarray]]:
    """Stage 1: the segmenter (kept for stage 4) and the masks to trace, in paint order."""
    width, height = inputs.size
    with _timed(result, "segment"):
        report("segment", 0, 1)
        segmenter = Segmenter(config.segment, config.device)
        settings = SegmentSettings.from_config(config, width, height)
        selection = select_masks(inputs.working, segmenter, settings)
        report("segment", 1, 1)
    result.masks = drop_transparent(selection.masks, inputs.alpha)
    result.counts.update(
        amg_masks=selection.amg_masks,
        amg_components=selection.amg_components,
        kept_masks=selection.kept_after_filter,
        reprompt_masks=selection.reprompt_masks,
        colour_parts=selection.colour_parts,
        tonal_regions=selection.tonal_regions,
    )
    return segmenter, result.masks


def _trace(
    masks: list[np.ndarray],
    inputs: _Inputs,
    settings: TraceSettings,
    config: Config,
    result: PipelineResult,
    report: ProgressCallback,
) -> Scene:
    """Stage 2: the traced scene over the background (none for an input with alpha)."""
    with _timed(result, "trace"):
        report("trace", 0, 1)
        traced = _within(trace_scene(masks, inputs.target, settings), config)
        background = None
        if inputs.alpha is None:
            background = uncovered_background(masks, inputs.target)
        scene = replace(traced, background=background, frame=inputs.frame)
        report("trace", 1, 1)
    result.initial = VectorImage.from_scene(scene)
    result.counts["paths_initial"] = scene.path_count
    return scene


def _add_missing(
    scene: Scene,
    inputs: _Inputs,
    segmenter: Segmenter,
    settings: tuple[MissingSettings, TraceSettings, FitSettings],
    config: Config,
    result: PipelineResult,
    report: ProgressCallback,
    drafted: bool = False,
) -> tuple[Scene, bool]:
    """Stage 4: as many rounds as asked, as ``detail`` decides, or until a path budget's pool is
    full. Returns the scene and whether it was fitted as a whole after its last paths came
    (under a budget it is not: the fit after the cut does it). ``drafted``: stage 3's fit was a
    draft, so the scene is fitted in full even when no round adds a path."""
    budget = config.missing.paths
    pool = budget_pool(budget, scene.path_count) if budget is not None else None
    planned = settings[0].rounds
    total = planned if planned is not None else MAX_AUTO_ROUNDS
    report("missing", 0, total)
    done = add_missing_rounds(
        scene,
        inputs.target,
        segmenter,
        settings,
        pool,
        on_round=lambda count, _round: report("missing", min(count, total), total),
        alpha=inputs.alpha,
        on_step=_progress_of(report, "refine", settings[2].steps),
        fit_at_end=budget is None,  # under a budget, the fit after the cut is the whole fit
        drafted=drafted,
    )
    report("missing", total, total)
    result.missing_map, result.missing_prompts = done.error_map, done.prompts
    result.counts.update(
        missing_rounds=done.rounds, missing_prompts=done.prompt_count, missing_paths=done.added
    )
    for stage, seconds in done.timings.items():
        result.timings[stage] = result.timings.get(stage, 0.0) + seconds
    if done.rounds:
        result.notes.append(f"stage 4: {done.rounds} rounds, {done.added} paths ({done.stopped})")
    return done.scene, done.fitted


def _reduce(
    scene: Scene,
    inputs: _Inputs,
    fit: FitSettings,
    budget: int,
    result: PipelineResult,
    report: ProgressCallback,
    fitted: bool = True,
) -> Scene:
    """The scene cut to ``budget`` paths (those of least removal cost go) and fitted again (or
    fitted for the first time as a whole, when it was not)."""
    if scene.path_count <= budget and fitted:
        return scene
    with _timed(result, "reduce"):
        if scene.path_count > budget:
            scene, removed = reduce_paths(scene, inputs.target, budget)
            result.counts["reduced"] = result.counts.get("reduced", 0) + removed
        return fit_scene(scene, inputs.target, fit, _progress_of(report, "reduce", fit.steps)).scene


def _box(config: Config, inputs: _Inputs) -> tuple[float, float, float, float]:
    """The canvas plus the margin control points stay in (2 % when no margin is set)."""
    fraction = config.fit.margin if config.fit.margin is not None else 0.02
    return margin_box(inputs.size, fraction)


def _finish_settings(config: Config, inputs: _Inputs) -> FinishSettings:
    box = _box(config, inputs)
    return FinishSettings(
        margin=-box[0],
        remove_hidden=config.finish.remove_hidden,
        merge=config.finish.merge_paths,
        colours=config.finish.colors,
    )


def _within(scene: Scene, config: Config, by_area: bool = False) -> Scene:
    """``scene`` with at most ``max_paths`` paths (stage 1 keeps that many masks; a mask that
    traced into several paths, or a path the finish pass split, must not break the promise):
    the first ones, or with ``by_area`` the largest ones, in paint order."""
    limit = config.segment.max_paths
    if limit is None or scene.element_count <= limit:
        return scene
    return _largest(scene, limit) if by_area else scene.subset(range(limit))


def _largest(scene: Scene, limit: int | None) -> Scene:
    """``scene`` with at most ``limit`` SVG elements (None: all): its largest ones (a compound
    path by the area of all its pieces), in paint order."""
    if limit is None or scene.element_count <= limit:
        return scene
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    areas = polygon_areas(vertices, vertex_offsets)
    elements = scene.elements()
    sizes = [float(areas[list(element)].sum()) for element in elements]
    largest = np.sort(np.argsort(-np.asarray(sizes), kind="stable")[:limit])
    return scene.subset([path for chosen in largest for path in elements[int(chosen)]])


def _path_limit(config: Config) -> int | None:
    """The most paths the SVG may have: ``max_paths`` and a ``--paths`` budget, the smaller."""
    limits = [n for n in (config.segment.max_paths, config.missing.paths) if n is not None]
    return min(limits) if limits else None


def _finish_note(counts: dict[str, int]) -> str:
    """What the finish pass changed, in one line."""
    return (
        f"finish: {counts.get('simple_repaired', 0)} self-crossing paths repaired "
        f"({counts.get('simple_split', 0)} parts split off), "
        f"{counts.get('bounds_clipped', 0)} clipped to the canvas, "
        f"{counts.get('hidden_removed', 0)} hidden and {counts.get('idle_removed', 0)} idle "
        f"paths removed, {counts.get('gradients_flattened', 0)} idle gradients made flat, "
        f"{counts.get('merged', 0)} merged"
        + (", the path over the whole canvas made the background"
           if counts.get("background_from_path") else "")
    )  # fmt: skip


def simple_when_saved(scene: Scene, precision: int = DEFAULT_PRECISION) -> Scene:
    """``scene`` (input pixels) with coordinates rounded as the SVG will hold them, repairing a
    path that rounding makes cross itself (two stretches of an outline closer than the
    rounding step now touch)."""
    rounded = scene.with_geometry(np.round(scene.points, precision))
    if len(crossing_paths(rounded)) == 0:
        return rounded
    repaired, _ = simplify_paths(rounded)
    return repaired.with_geometry(np.round(repaired.points, precision))


def _simple_within(scene: Scene, limit: int | None) -> Scene:
    """`simple_when_saved`, with the pieces that its repairs split off joined into compound
    paths (a texture layer's islands, a repaired path's pieces) up to ``limit`` SVG elements
    (None: as many as ``scene`` had) and, where they still go over ``limit``, the smallest
    removed."""
    simple = simple_when_saved(scene)
    simple, _ = join_pieces(simple, scene.element_count if limit is None else limit)
    return _largest(simple, limit)


def _finish(
    scene: Scene,
    target: np.ndarray,
    result: PipelineResult,
    simple: bool = False,
    limit: int | None = None,
    whole_pixels: bool = False,
) -> None:
    """The result's scene, SVG and MSE (of the SVG as written, at the working size). A path that
    rounding to the SVG's precision makes cross itself is repaired (``simple``); parts that
    repair splits off beyond ``limit`` paths go, smallest first, so a budget or a path limit
    still holds. With ``whole_pixels``, paths that rounding to whole pixels changes by less than
    ``IDLE_COST`` are saved so (`whole_pixel_paths`, 2 % of the MSE in all)."""
    result.scene = scene
    output = scene.in_input_pixels()
    saved = _simple_within(output, limit) if simple else output
    scale = scene.frame.scale if scene.frame is not None else 1.0
    written = saved.on_canvas(scene.width, scene.height, scale)  # the SVG at the working size
    result.mse = float(np.mean((written.render() - target) ** 2))
    if whole_pixels:
        with _timed(result, "finish"):
            working = (scene.width, scene.height, scale)
            saved, rounded = whole_pixel_paths(saved, working, ROUNDING_SHARE * result.mse)
            result.counts["whole_pixel_paths"] = rounded
            if rounded:
                written = saved.on_canvas(*working)
                result.mse = float(np.mean((written.render() - target) ** 2))
    result.image = VectorImage.from_scene(saved)
    result.counts["paths"] = result.image.scene.element_count
    result.counts["shapes"] = result.image.scene.path_count
    result.counts["gradient_fills"] = sum(
        not isinstance(paint, FlatPaint) for paint in result.image.scene.paints
    )
    result.counts["background_gradient"] = int(result.image.scene.background_gradient is not None)


def vectorize(
    image: Any, config: Config | None = None, progress: ProgressCallback | None = None
) -> VectorImage:
    """Vectorize ``image`` (a path, numpy array or PIL image) into a `VectorImage`.

    The SVG is in the input's pixel coordinates whatever the working size; same input, config
    and machine give the same SVG.
    """
    return run(image, config, progress).image
