"""`Segmenter`: one loaded SAM model serving stage 1 (automatic masks) and the re-prompts of
stages 1 and 4 (point prompts that reuse the image embedding the generator computed, so there is
no second encoder pass)."""

from __future__ import annotations

import numpy as np

from samvg.config import SegmentOptions
from samvg.errors import SamvgError
from samvg.sam import SamAutomaticMaskGenerator, SamPredictor, load_sam


class Segmenter:
    """SAM for one image: ``automatic()`` first, then ``prompt(points)`` as often as needed."""

    def __init__(self, options: SegmentOptions, device: str = "cpu") -> None:
        self.model = load_sam(options.model, checkpoint=options.checkpoint, device=device)
        self.generator = SamAutomaticMaskGenerator(
            self.model,
            points_per_side=options.points_per_side,
            crop_n_layers=options.crop_n_layers,
            skip_covered=options.skip_covered_points,
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
            if self._image is None:
                raise SamvgError("Segmenter.prompt needs an image: call automatic() first")
            self.predictor.set_image(self._image)
        masks, _, _ = self.predictor.predict_points(np.asarray(points, np.float64))
        return [[mask for mask in candidates if mask.any()] for candidates in masks]
