"""SAMVG stage 1: SAM's automatic masks, filter by impact, then re-prompts in large uncovered
regions; the result is the list of masks stage 2 traces, in paint order."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from samvg.config import Config
from samvg.imaging import filled_components, to_float_rgb
from samvg.segment.colour_split import ColourSplitSettings, colour_parts, lab_image
from samvg.segment.impact import ImpactCanvas, filter_by_impact, keep_all, offer_best
from samvg.segment.prompts import uncovered_prompts
from samvg.segment.segmenter import Segmenter
from samvg.segment.tonal import TonalSettings, textured, tonal_regions

#: Tonal regions: the blur (× the longer side), k-means clusters, and the least area kept
#: (× the image's).
TONAL_BLUR = 0.008
TONAL_TONES = 6
TONAL_MIN_AREA = 0.002


@dataclass(frozen=True)
class SegmentSettings:
    """Stage 1 in working pixels (derived once from `Config` for one canvas)."""

    min_pixels: float
    filter_by_impact: bool
    impact_threshold: float
    reprompt_uncovered: bool
    uncovered_radius: float
    """Pixels."""
    max_paths: int | None
    seed: int
    colour_split: ColourSplitSettings | None = None
    """How kept masks are split into colour-coherent parts (None: not split, the paper)."""
    tonal: TonalSettings | None = None
    """The tonal regions offered beneath SAM's masks and their colour parts, to a textured
    image (None: none, without a path budget)."""

    @classmethod
    def from_config(cls, config: Config, width: int, height: int) -> SegmentSettings:
        options = config.segment
        return cls(
            min_pixels=options.min_pixels(width, height),
            filter_by_impact=options.filter_by_impact,
            impact_threshold=options.impact_threshold,
            reprompt_uncovered=options.reprompt_uncovered,
            uncovered_radius=options.uncovered_radius * max(height, width),
            max_paths=options.max_paths,
            seed=config.seed,
            colour_split=colour_split_settings(config, width, height),
            tonal=tonal_settings(config, width, height),
        )


def tonal_settings(config: Config, width: int, height: int) -> TonalSettings | None:
    """Tonal regions in working pixels: only under a path budget with the filter by impact on."""
    options = config.segment
    if config.missing.paths is None or not (options.tonal_regions and options.filter_by_impact):
        return None
    return TonalSettings(
        blur=TONAL_BLUR * max(width, height),
        tones=TONAL_TONES,
        min_pixels=TONAL_MIN_AREA * width * height,
        seed=config.seed,
    )


def colour_split_settings(
    config: Config, width: int, height: int, faint: bool = True
) -> ColourSplitSettings | None:
    """Colour splitting in working pixels for stages 1 and 4 (None when it is off). ``faint``:
    whether faint flat colours split too (`ColourSplitSettings.fine_contrast`); stage 4 does not
    split them: among the textures of a painting they became many weak candidates, and the
    rounds stopped early (composition_vii: MSE 9.6 -> 13.3e-3)."""
    options = config.segment
    if not options.colour_split:
        return None
    settings = ColourSplitSettings(
        min_pixels=options.min_pixels(width, height),
        contrast=options.split_contrast,
        seed=config.seed,
    )
    return settings if faint else replace(settings, fine_contrast=settings.contrast)


@dataclass
class MaskSelection:
    """Stage 1's result: masks in paint order (largest first) and how many were seen on the
    way (SAM's masks, their components, kept by the filter, added by re-prompts)."""

    masks: list[np.ndarray]
    amg_masks: int
    amg_components: int
    kept_after_filter: int
    reprompt_masks: int
    colour_parts: int = 0
    tonal_regions: int = 0


def select_masks(
    image: np.ndarray, segmenter: Segmenter, settings: SegmentSettings
) -> MaskSelection:
    """AMG → filter by impact → re-prompt SAM at the centres of large uncovered regions → filter
    the new masks (painted beneath smaller kept masks, as they will be in area order) →
    colour-coherent parts → under a path budget, a textured image's tonal regions, filtered the
    same way (beneath the smaller masks and parts)."""
    target = to_float_rgb(image)
    amg = segmenter.automatic(image)
    candidates = [part for mask in amg for part in filled_components(mask, settings.min_pixels)]
    if settings.filter_by_impact:
        kept, canvas = filter_by_impact(candidates, target, settings.impact_threshold)
    else:
        kept, canvas = keep_all(candidates, target)
    reprompt_masks = 0
    if settings.reprompt_uncovered:
        prompts = uncovered_prompts(canvas.covered, settings.uncovered_radius, seed=settings.seed)
        reprompt_masks = offer_best(
            canvas,
            segmenter.prompt(prompts),
            settings.min_pixels,
            use_filter=settings.filter_by_impact,
            below=True,
        )
    lab = None
    split = 0
    if settings.colour_split is not None:
        lab = lab_image(canvas.target)
        split = offer_colour_parts(
            canvas, settings.colour_split, settings.filter_by_impact, lab=lab
        )
    tonal = 0
    if settings.tonal is not None and textured(target, settings.tonal.min_complexity):
        lab = lab_image(canvas.target) if lab is None else lab
        for region in tonal_regions(lab, settings.tonal):
            tonal += canvas.offer(region, below=True).kept
    pairs = list(zip(canvas.kept_masks, canvas.impacts, strict=True))
    if settings.max_paths is not None and len(pairs) > settings.max_paths:
        pairs = sorted(pairs, key=lambda pair: -pair[1])[: settings.max_paths]
    pairs.sort(key=lambda pair: -int(pair[0].sum()))
    return MaskSelection(
        masks=[mask for mask, _ in pairs],
        amg_masks=len(amg),
        amg_components=len(candidates),
        kept_after_filter=len(kept),
        reprompt_masks=reprompt_masks,
        colour_parts=split,
        tonal_regions=tonal,
    )


def offer_colour_parts(
    canvas: ImpactCanvas,
    settings: ColourSplitSettings,
    use_filter: bool = True,
    include_uncovered: bool = True,
    lab: np.ndarray | None = None,
) -> int:
    """Split every mask kept on ``canvas`` (and, with ``include_uncovered``, the pixels no mask
    covers, which the background fills) into colour-coherent parts and offer the parts to the
    canvas, largest first; returns how many were kept. Then the parts the filter turned down are
    offered again together, one region's parts of one colour as one mask (a folder's stripes:
    each too faint alone to pass the filter, the set of them plain to see; traced, each stripe
    is a path). ``lab``: the target in CIELAB, when the caller has it already."""
    lab = lab_image(canvas.target) if lab is None else lab
    regions = list(canvas.kept_masks)
    if include_uncovered and not canvas.covered.all():
        regions.append(~canvas.covered)
    found = [(source, part) for source, region in enumerate(regions)
             for part in colour_parts(region, lab, settings)]  # fmt: skip
    found.sort(key=lambda item: -int(np.count_nonzero(item[1])))
    forced = None if use_filter else True
    decisions = [canvas.offer(part, keep=forced).kept for _, part in found]
    kept = sum(decisions)
    if not use_filter:
        return kept
    for source in range(len(regions)):  # too small alone, they may matter together: stripes
        rejected = [
            part
            for (at, part), taken in zip(found, decisions, strict=True)
            if at == source and not taken
        ]
        for group in same_colour_groups(rejected, lab, settings.fine_contrast / 2):
            kept += len(group) * canvas.offer(np.logical_or.reduce(group)).kept
    return kept


def same_colour_groups(
    parts: list[np.ndarray], lab: np.ndarray, tolerance: float
) -> list[list[np.ndarray]]:
    """``parts`` gathered by mean colour (CIELAB, each within ``tolerance`` ΔE of its group's
    first part, largest first), the groups of two or more parts only, largest first."""
    parts = sorted(parts, key=lambda part: -int(np.count_nonzero(part)))
    groups: list[tuple[np.ndarray, list[np.ndarray]]] = []
    for part in parts:
        colour = lab[part].mean(axis=0)
        for first, members in groups:
            if np.linalg.norm(colour - first) < tolerance:
                members.append(part)
                break
        else:
            groups.append((colour, [part]))
    found = [members for _, members in groups if len(members) > 1]
    return sorted(found, key=lambda members: -sum(int(np.count_nonzero(m)) for m in members))
