"""SAMVG stage 4: error map → prompts → SAM (and, by default, the colour-coherent regions the
render gets wrong) → filter by impact against the current render → trace → fit the enlarged
scene. `add_missing` is one round; `add_missing_rounds` repeats it as many times as asked, until
a round gains less than the detail tolerance, or until a path budget's pool is full."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from samvg.config import Config
from samvg.imaging import error_map
from samvg.missing.marks import MarkSettings, mark_groups
from samvg.missing.prompts import missing_component_map, missing_component_prompts
from samvg.optimize import FitSettings, fit_scene
from samvg.optimize.fit import StepCallback
from samvg.scene import Scene
from samvg.segment import ImpactCanvas, Segmenter, offer_best
from samvg.segment.colour_split import ColourSplitSettings, colour_regions, lab_image
from samvg.segment.select import colour_split_settings, offer_colour_parts
from samvg.trace.stage import TraceSettings, drop_transparent, trace_scene

#: Rounds the automatic detail runs at most (each one fits the whole scene again).
MAX_AUTO_ROUNDS = 6
#: A path budget's pool: stage 4 grows the scene to this many times the budget before the
#: paths of least impact are removed.
BUDGET_POOL = 1.25
#: Under a budget, stage 4 may add this share of the budget even to a scene that stages 1-3
#: already grew past the pool: there the grid's colour parts (a wall's texture) fill the pool
#: first, and parts that no grid point found (kodim01's shutters at 64 paths) were never offered.
BUDGET_GROWTH = 0.25
#: Under a budget, a round that finds nothing halves stage 4's error bars (the prompts' ω and
#: the marks' error; see `eased_settings`) and tries again, at most this many times: the budget is
#: filled from the largest errors left, as LIVE fills it, before the scene is declared done. A
#: round at eased bars keeps its paths only if they lower the error by ``gain_tolerance``.
BUDGET_EASINGS = 3
#: After the error bars, a budget's rounds that still find nothing look for smaller marks this
#: many times (see `smaller_marks`): 16 px (VTracer's speckle) down to 4 px, the stars of a
#: wallpaper. Only once the bars are spent: halved together with the bars, the marks' size cost
#: kodim02 at 256 paths 78 of its 241 paths (MSE 1.41 -> 1.54e-3, LPIPS 0.324 -> 0.349).
MARK_EASINGS = 2


def budget_pool(budget: int, paths: int) -> int:
    """How many paths stage 4 may grow a scene of ``paths`` paths to under a path budget: the
    budget's pool (`BUDGET_POOL` × the budget), or ``paths`` plus `BUDGET_GROWTH` × the budget
    where that is more."""
    return max(math.ceil(BUDGET_POOL * budget), paths + math.ceil(BUDGET_GROWTH * budget))


@dataclass(frozen=True)
class MissingSettings:
    """Stage 4 in working pixels (derived once from `Config` for one canvas)."""

    radius: float
    """Pixels: the disc the error map is averaged over."""
    threshold: float
    impact_threshold: float
    filter_by_impact: bool
    min_pixels: float
    rounds: int | None
    """Rounds to run; None: until a round lowers the error by less than ``gain_tolerance``."""
    max_paths: int | None = None
    """The scene's path limit (`SegmentOptions.max_paths`): a round adds at most what is left."""
    colour_split: ColourSplitSettings | None = None
    """Also offer the colour-coherent regions the render gets wrong (None: SAM's masks only)."""
    pixel_error: float = 0.25
    """A pixel is wrong when its error (sum over RGB, in [0, 3]) reaches this."""
    gain_tolerance: float = 0.01
    """The automatic rounds stop when a round lowers the MSE by less than this fraction."""
    refit_scene: bool = True
    """Each round fits the whole scene (True) or only its new paths over the rest's render."""
    marks: MarkSettings | None = None
    """Also offer the groups of small marks on flat areas (None: no marks)."""
    marks_only: bool = False
    """Offer the marks only: no SAM prompts and no wrong-colour regions (a budget's last rounds,
    whose eased marks are all that changed since a round found nothing; `smaller_marks`)."""

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
            colour_split=colour_split_settings(config, width, height, faint=False),
            gain_tolerance=options.gain_tolerance,
            refit_scene=options.refit_scene,
            marks=MarkSettings(min_pixels=options.filter_speckle**2) if options.marks else None,
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
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """SAM at the prompts (and the regions and marks the render gets wrong), filtered by impact
    with the render I′ as the starting canvas; at most ``limit`` of them (those with the largest
    impact). Returns the regions, largest first, and the groups of marks, largest first: painted
    on top of the scene in this order, the marks last."""
    canvas = ImpactCanvas(target, settings.impact_threshold, start=render)
    lab = None
    if not settings.marks_only:
        offer_best(
            canvas,
            segmenter.prompt(prompts),
            settings.min_pixels,
            use_filter=settings.filter_by_impact,
            below=False,
        )
        if settings.colour_split is not None:
            lab = lab_image(target)
            split = settings.colour_split
            offer_colour_parts(canvas, split, settings.filter_by_impact, False, lab)
            offer_wrong_regions(canvas, render, settings.pixel_error, split, lab)
    regions = len(canvas.kept_masks)
    if settings.marks is not None:
        lab = lab_image(target) if lab is None else lab
        for group in mark_groups(target, render, lab, settings.marks):
            canvas.offer(group)
    order: list[int] = list(range(len(canvas.kept_masks)))
    if limit is not None and len(order) > limit:
        order = sorted(
            int(i) for i in np.argsort(-np.asarray(canvas.impacts), kind="stable")[:limit]
        )
    order = sorted(order, key=lambda i: -int(canvas.kept_masks[i].sum()))
    return (
        [canvas.kept_masks[i] for i in order if i < regions],
        [canvas.kept_masks[i] for i in order if i >= regions],
    )


def offer_wrong_regions(
    canvas: ImpactCanvas,
    render: np.ndarray,
    pixel_error: float,
    split: ColourSplitSettings,
    lab: np.ndarray | None = None,
) -> int:
    """Offer ``canvas`` the colour-coherent regions of the pixels ``render`` gets wrong (text,
    stripes, small marks SAM's prompts missed), largest first; returns how many were kept.
    ``lab``: the target in CIELAB, when the caller has it already."""
    wrong = error_map(canvas.target, render) >= pixel_error
    if np.count_nonzero(wrong) < split.min_pixels:
        return 0
    regions = colour_regions(wrong, lab_image(canvas.target) if lab is None else lab, split)
    regions.sort(key=lambda region: -int(np.count_nonzero(region)))
    return sum(canvas.offer(region).kept for region in regions)


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
    render: np.ndarray | None = None,
) -> MissingRound:
    """One round of stage 4 on ``scene`` (working pixels) against ``target``; it adds no more
    paths than ``settings.max_paths`` leaves room for (none, without asking SAM, when full),
    and none where the input is transparent (``alpha`` below 0.5). ``render``: the scene's
    render, when the caller has it already."""
    clock = time.perf_counter()
    render = scene.render() if render is None else render
    averaged, above = missing_component_map(target, render, settings.radius, settings.threshold)
    prompts = (
        np.zeros((0, 2)) if settings.marks_only else missing_component_prompts(averaged, above)
    )
    room = room_left(scene, settings)
    regions, marks = (
        ([], []) if room == 0 else missing_masks(segmenter, prompts, target, render, settings, room)
    )
    added = trace_scene(drop_transparent(regions, alpha), target, trace)
    if marks and settings.marks is not None:
        fine = settings.marks.trace_settings(trace)
        traced = trace_scene(drop_transparent(marks, alpha), target, fine)
        added = added.stacked(traced.with_fixed_outlines())
    if room is not None and added.path_count > room:
        added = added.subset(range(room))
    result = MissingRound(scene, averaged, prompts, added.path_count)
    result.timings["missing"] = time.perf_counter() - clock
    if added.path_count:
        clock = time.perf_counter()
        if settings.refit_scene:
            result.scene = fit_scene(scene.stacked(added), target, fit, on_step).scene
        else:
            alone = fit.draft()  # the whole fit at the end polishes these paths with the rest
            result.scene = scene.stacked(fit_scene(added, target, alone, on_step, render).scene)
        result.timings["refine"] = time.perf_counter() - clock
    return result


@dataclass
class MissingRounds:
    """What the rounds of stage 4 did: the final scene, the last round's error map and prompts,
    rounds run, paths added, prompts used, seconds spent, and why they stopped."""

    scene: Scene
    error_map: np.ndarray | None = None
    prompts: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    rounds: int = 0
    added: int = 0
    prompt_count: int = 0
    timings: dict[str, float] = field(default_factory=dict)
    stopped: str = ""
    fitted: bool = True
    """Whether the scene was fitted as a whole after its last paths were added."""


def add_missing_rounds(
    scene: Scene,
    target: np.ndarray,
    segmenter: Segmenter,
    stages: tuple[MissingSettings, TraceSettings, FitSettings],
    pool: int | None = None,
    on_round: Callable[[int, MissingRound], None] | None = None,
    alpha: np.ndarray | None = None,
    on_step: StepCallback | None = None,
    fit_at_end: bool = True,
    drafted: bool = False,
) -> MissingRounds:
    """Stage 4 repeated: ``settings.rounds`` rounds, or with None until a round lowers the MSE by
    less than ``settings.gain_tolerance`` (at most `MAX_AUTO_ROUNDS`; a round that raises the MSE
    is rolled back). With a ``pool`` (a path budget), rounds take the candidates of largest
    impact, however small, until the scene has ``pool`` paths or a round finds nothing more even
    with its error bars halved `BUDGET_EASINGS` times and its marks `MARK_EASINGS` times smaller
    (at most ``2 * MAX_AUTO_ROUNDS`` rounds).
    Unless ``settings.refit_scene``, rounds fit only the paths they add and the whole scene is
    fitted once at the end (with ``fit_at_end``; else ``fitted`` is False and the caller fits
    it), also when no round added a path to a ``drafted`` scene (one given a draft fit only)."""
    settings, trace, fit = stages
    first_marks = settings.marks
    full_at = None
    if pool is not None:
        full_at = pool if settings.max_paths is None else min(pool, settings.max_paths)
        settings = replace(settings, impact_threshold=0.0, max_paths=full_at)
    planned = settings.rounds
    most = planned if planned is not None else MAX_AUTO_ROUNDS * (2 if pool else 1)
    automatic = planned is None and pool is None  # rounds until the gain falls off
    eased = 0
    done = MissingRounds(scene)
    render = scene.render()
    error = _mse(render, target)
    while done.rounds < most:
        if full_at is not None and scene.path_count >= full_at:
            done.stopped = f"the pool of {pool} paths is full"
            break
        round_ = add_missing(scene, target, segmenter, settings, trace, fit, on_step, alpha, render)
        done.rounds += 1
        done.added += round_.added
        done.prompt_count += len(round_.prompts)
        done.error_map, done.prompts = round_.error_map, round_.prompts
        for stage, seconds in round_.timings.items():
            done.timings[stage] = done.timings.get(stage, 0.0) + seconds
        if on_round is not None:
            on_round(done.rounds, round_)
        kept = round_.added
        if kept:
            new_render = round_.scene.render()
            now = _mse(new_render, target)
            gain = (error - now) / max(error, 1e-12)
            if eased and gain < settings.gain_tolerance:  # eased paths must earn their place
                done.added, kept = done.added - kept, 0
        if kept == 0:
            easier = None if pool is None else _next_easing(settings, eased, first_marks)
            if easier is not None:
                settings, eased = easier, eased + 1
                continue
            done.stopped = _nothing_left(eased, settings)
            break
        if automatic and gain <= 0:  # the round's paths made the picture worse: they go
            done.added -= round_.added
            done.stopped = f"round {done.rounds} would have raised the error: rolled back"
            break
        scene, render, error = round_.scene, new_render, now
        if automatic and gain < settings.gain_tolerance:
            done.stopped = f"round {done.rounds} lowered the error by {gain:.1%}"
            break
    done.fitted = settings.refit_scene or not (done.added or drafted)
    if not done.fitted and fit_at_end:
        clock = time.perf_counter()
        scene = fit_scene(scene, target, fit, on_step).scene
        done.timings["refine"] = done.timings.get("refine", 0.0) + time.perf_counter() - clock
        done.fitted = True
    done.scene = scene
    done.stopped = done.stopped or f"{done.rounds} rounds"
    return done


def _next_easing(
    settings: MissingSettings, eased: int, first_marks: MarkSettings | None
) -> MissingSettings | None:
    """A budget's settings after ``eased`` easings, eased once more (None: none left): the error
    bars `BUDGET_EASINGS` times, then the marks' size `MARK_EASINGS` times."""
    if eased < BUDGET_EASINGS:
        return eased_settings(settings)
    if first_marks is not None and eased < BUDGET_EASINGS + MARK_EASINGS:
        finest = eased + 1 == BUDGET_EASINGS + MARK_EASINGS
        return smaller_marks(settings, first_marks, finest)
    return None


def _nothing_left(eased: int, settings: MissingSettings) -> str:
    if not eased:
        return "no region left that a new path improves"
    bars = 2 ** min(eased, BUDGET_EASINGS)
    marks = settings.marks
    smaller = (
        f" and marks of {marks.min_pixels:g} px"
        if marks is not None and eased > BUDGET_EASINGS
        else ""
    )
    return (
        f"no region left that a new path improves by {settings.gain_tolerance:.0%}, even at "
        f"1/{bars} of the error bars{smaller}"
    )


def eased_settings(settings: MissingSettings) -> MissingSettings:
    """``settings`` with its error bars halved: SAM prompts where the averaged error reaches
    ω / 2, marks at half the error. The wrong-colour regions keep their bar: at a lower one they
    follow the error's contours across smooth gradients, and their flat paths band a wallpaper
    (debian_joy at 64 paths: LPIPS 0.040 → 0.088; SAM's masks and the marks follow the
    image's own edges)."""
    marks = settings.marks
    if marks is not None:
        marks = replace(marks, pixel_error=marks.pixel_error / 2)
    return replace(
        settings,
        threshold=settings.threshold / 2,
        marks=marks,
    )


def smaller_marks(
    settings: MissingSettings, first: MarkSettings, finest: bool = False
) -> MissingSettings:
    """``settings`` with marks of half the smallest size, at the marks' ``first`` error bar: at
    the eased bars a wallpaper's stars join the error of its smooth background into regions
    that are not flat, so none is a mark. ``finest``: strokes one pixel wide count too (no
    opening; a star's arms). debian_spacefun at 256 paths: 20 -> 37 paths, LPIPS 0.256 -> 0.093
    (VTracer at <= 256 paths: 0.190). Only the marks are offered: SAM's prompts and the
    wrong-colour regions found nothing at these bars already (kodim02: 2 s a round saved)."""
    if settings.marks is None:
        return settings
    marks = replace(
        settings.marks,
        min_pixels=settings.marks.min_pixels / 2,
        pixel_error=first.pixel_error,
        opening=settings.marks.opening and not finest,
    )
    return replace(settings, marks=marks, marks_only=True)


def _mse(render: np.ndarray, target: np.ndarray) -> float:
    return float(np.mean((render - target) ** 2))
