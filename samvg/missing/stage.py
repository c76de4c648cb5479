"""SAMVG stage 4, one round: error map → prompts → SAM → filter by impact against the current
render → trace → fit the enlarged scene. The pipeline calls it as many rounds as asked."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from samvg.config import Config
from samvg.missing.prompts import missing_component_map, missing_component_prompts
from samvg.optimize import FitSettings, fit_scene
from samvg.optimize.fit import StepCallback
from samvg.scene import Scene
from samvg.segment import ImpactCanvas, Segmenter, offer_best
from samvg.trace.stage import TraceSettings, drop_transparent, trace_scene


@dataclass(frozen=True)
class MissingSettings:
    """Stage 4 in working pixels (derived once from `Config` for one canvas)."""

    radius: float
    """Pixels: the disc the error map is averaged over."""
    threshold: float
    impact_threshold: float
    filter_by_impact: bool
    min_pixels: float
    rounds: int
    max_paths: int | None = None
    """The scene's path limit (`SegmentOptions.max_paths`): a round adds at most what is left."""

    @classmethod
    def from_config(cls, config: Config, width: int, height: int) -> MissingSettings:
        options = config.missing
        return cls(
            radius=options.missing_radius * max(height, width),
            threshold=options.missing_threshold,
            impact_threshold=options.missing_impact_threshold,
            filter_by_impact=config.segment.filter_by_impact,
            min_pixels=config.segment.min_pixels(width, height),
            rounds=options.rounds,
            max_paths=config.segment.max_paths,
        )


@dataclass
class MissingRound:
    """One round's result: the scene after it, the averaged error map D1 and its prompts, how
    many paths were added, and seconds spent finding them and refitting."""

    scene: Scene
    error_map: np.ndarray
    prompts: np.ndarray
    added: int
    timings: dict[str, float] = field(default_factory=dict)


def missing_masks(
    segmenter: Segmenter,
    prompts: np.ndarray,
    target: np.ndarray,
    render: np.ndarray,
    settings: MissingSettings,
    limit: int | None = None,
) -> list[np.ndarray]:
    """SAM at the prompts, filtered by impact with the render I′ as the starting canvas; at
    most ``limit`` of them (those with the largest impact), returned largest first (they are
    painted on top of the scene)."""
    canvas = ImpactCanvas(target, settings.impact_threshold, start=render)
    offer_best(
        canvas,
        segmenter.prompt(prompts),
        settings.min_pixels,
        use_filter=settings.filter_by_impact,
        below=False,
    )
    masks = canvas.kept_masks
    if limit is not None and len(masks) > limit:
        order = np.argsort(-np.asarray(canvas.impacts), kind="stable")[:limit]
        masks = [masks[index] for index in sorted(order)]
    return sorted(masks, key=lambda mask: -int(mask.sum()))


def room_left(scene: Scene, settings: MissingSettings) -> int | None:
    """How many paths a round may still add under ``settings.max_paths`` (None: no limit)."""
    if settings.max_paths is None:
        return None
    return max(0, settings.max_paths - scene.path_count)


def add_missing(
    scene: Scene,
    target: np.ndarray,
    segmenter: Segmenter,
    settings: MissingSettings,
    trace: TraceSettings,
    fit: FitSettings,
    on_step: StepCallback | None = None,
    alpha: np.ndarray | None = None,
) -> MissingRound:
    """One round of stage 4 on ``scene`` (working pixels) against ``target``; it adds no more
    paths than ``settings.max_paths`` leaves room for (none, without asking SAM, when full),
    and none where the input is transparent (``alpha`` below 0.5)."""
    clock = time.perf_counter()
    render = scene.render()
    averaged, above = missing_component_map(target, render, settings.radius, settings.threshold)
    prompts = missing_component_prompts(averaged, above)
    room = room_left(scene, settings)
    masks = [] if room == 0 else missing_masks(segmenter, prompts, target, render, settings, room)
    added = trace_scene(drop_transparent(masks, alpha), target, trace)
    if room is not None and added.path_count > room:
        added = added.subset(range(room))
    result = MissingRound(scene, averaged, prompts, added.path_count)
    result.timings["missing"] = time.perf_counter() - clock
    if added.path_count:
        clock = time.perf_counter()
        result.scene = fit_scene(scene.stacked(added), target, fit, on_step).scene
        result.timings["refine"] = time.perf_counter() - clock
    return result
