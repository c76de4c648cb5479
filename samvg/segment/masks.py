"""SAMVG stage 1: SAM's automatic masks, filter by impact, and re-prompts in uncovered regions.

`Segmenter` wraps one loaded SAM model: the automatic mask generator, and point prompts that
reuse the image embedding the generator computed (no second encoder pass). `select_masks` runs
the stage; `missing_masks` is the SAM half of stage 4.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from samvg.config import Config
from samvg.segment.components import all_components, split_components
from samvg.segment.impact import ImpactCanvas, filter_by_impact, keep_all
from samvg.segment.prompts import uncovered_prompts


class Segmenter:
    """SAM for one image: ``automatic()`` first, then ``prompt(points)`` as often as needed."""

    def __init__(self, config: Config) -> None:
        from samvg.sam import SamAutomaticMaskGenerator, SamPredictor, load_sam

        self.model = load_sam(config.model, checkpoint=config.checkpoint, device=config.device)
        self.generator = SamAutomaticMaskGenerator(
            self.model,
            points_per_side=config.points_per_side,
            crop_n_layers=config.crop_n_layers,
        )
        self.predictor = SamPredictor(self.model)
        self._image: np.ndarray | None = None

    def automatic(self, image: np.ndarray) -> list[np.ndarray]:
        """AMG masks of an (H, W, 3) uint8 image (SAM's own IoU/stability/NMS filters applied)."""
        self._image = image
        records = self.generator.generate(image)
        embedding = self.generator.image_embedding
        if embedding is not None:
            self.predictor.set_features(embedding, image.shape[:2])
        return [record["segmentation"] for record in records]

    def prompt(self, points: np.ndarray) -> list[list[np.ndarray]]:
        """For each (x, y) point, SAM's three candidate masks (empty ones dropped)."""
        if len(points) == 0:
            return []
        if not self.predictor.is_image_set:
            assert self._image is not None, "call automatic() first"
            self.predictor.set_image(self._image)
        masks, _, _ = self.predictor.predict_points(np.asarray(points, np.float64))
        return [[mask for mask in candidates if mask.any()] for candidates in masks]


@dataclass
class MaskSelection:
    """Stage 1's result: masks in paint order (largest first) and what happened on the way."""

    masks: list[np.ndarray]
    canvas: np.ndarray
    amg_masks: int = 0
    kept_after_filter: int = 0
    reprompts: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    reprompt_masks: int = 0
    error: float = 1.0
    impacts: list[float] = field(default_factory=list)
    amg_components: int = 0


def min_component_pixels(config: Config, height: int, width: int) -> float:
    """Components smaller than this many pixels never become paths."""
    return max(4.0, config.min_area * height * width)


def select_masks(image: np.ndarray, segmenter: Segmenter, config: Config) -> MaskSelection:
    """AMG → filter by impact → re-prompt SAM at the centres of large uncovered regions → filter
    the new masks (painted beneath smaller kept masks, as they will be in area order)."""
    target = image.astype(np.float32) / 255.0
    height, width = image.shape[:2]
    min_pixels = min_component_pixels(config, height, width)
    amg = segmenter.automatic(image)
    candidates = all_components(amg, min_pixels)
    if config.filter_by_impact:
        kept, canvas = filter_by_impact(candidates, target, config.impact_threshold)
    else:
        kept, canvas = keep_all(candidates, target)
    selection = MaskSelection([], canvas.canvas, amg_masks=len(amg), kept_after_filter=len(kept))
    selection.amg_components = len(candidates)
    if config.reprompt_uncovered:
        radius = config.uncovered_radius * max(height, width)
        prompts = uncovered_prompts(canvas.covered, radius, seed=config.seed)
        selection.reprompts = prompts
        selection.reprompt_masks = _offer_best(
            canvas, segmenter.prompt(prompts), config, min_pixels, below=True
        )
    pairs = list(zip(canvas.kept_masks, canvas.impacts, strict=True))
    if config.max_paths is not None and len(pairs) > config.max_paths:
        pairs = sorted(pairs, key=lambda pair: -pair[1])[: config.max_paths]
    pairs.sort(key=lambda pair: -int(pair[0].sum()))
    selection.masks = [mask for mask, _ in pairs]
    selection.impacts = [impact for _, impact in pairs]
    selection.canvas = canvas.canvas
    selection.error = canvas.mean_error
    return selection


def missing_masks(
    segmenter: Segmenter,
    prompts: np.ndarray,
    target: np.ndarray,
    render: np.ndarray,
    config: Config,
) -> list[np.ndarray]:
    """Stage 4's masks: SAM at the missing-component prompts, filtered by impact with the render
    I′ as the starting canvas; returned largest first (they are painted on top of the SVG)."""
    canvas = ImpactCanvas(target, config.missing_impact_threshold, start=render)
    min_pixels = min_component_pixels(config, *target.shape[:2])
    _offer_best(canvas, segmenter.prompt(prompts), config, min_pixels, below=False)
    return sorted(canvas.kept_masks, key=lambda m: -int(m.sum()))


def _offer_best(
    canvas: ImpactCanvas,
    candidates: list[list[np.ndarray]],
    config: Config,
    min_pixels: float,
    below: bool,
) -> int:
    """Per prompt, take the candidate mask with the largest impact (with the filter off: SAM's
    first candidate) and offer its components. Prompts are taken in the order given (largest
    region first). Returns how many components were kept."""
    kept = 0
    for options in candidates:
        if not options:
            continue
        if config.filter_by_impact:
            impacts = [canvas.impact_of(mask, below)[0] for mask in options]
            best = options[int(np.argmax(impacts))]
        else:
            best = options[0]
        for part in split_components(best, min_pixels):
            forced = None if config.filter_by_impact else True
            kept += canvas.offer(part, below=below, keep=forced).kept
    return kept
