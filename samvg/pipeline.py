"""The vectorization pipeline: segment with SAM, trace masks into paths, fit them to the image."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from samvg.errors import InputError
from samvg.io import to_rgb_uint8
from samvg.vector_image import VectorImage, VectorPath

ProgressCallback = Callable[[str, int, int], None]
"""``progress(stage, done, total)``: called as each stage advances."""


@dataclass
class VectorizeConfig:
    """Settings of :func:`vectorize`; the defaults follow the paper where it gives a value."""

    model: str = "mobile_sam"
    checkpoint: str | None = None
    points_per_side: int = 32
    num_segments: int = 5
    max_paths: int = 64
    min_area_fraction: float = 0.0005
    steps: int = 300
    max_side: int = 512

    def __post_init__(self) -> None:
        minimums = {
            "points_per_side": 1,
            "num_segments": 1,
            "max_paths": 1,
            "steps": 0,
            "max_side": 8,
        }
        for name, smallest in minimums.items():
            value = getattr(self, name)
            if not isinstance(value, int) or value < smallest:
                raise InputError(
                    f"{name.replace('_', ' ')} must be an integer >= {smallest}, got {value!r}"
                )
        if not 0.0 <= self.min_area_fraction < 1.0:
            raise InputError(f"min area fraction must be in [0, 1), got {self.min_area_fraction}")


def _downscale(image: np.ndarray, max_side: int) -> tuple[np.ndarray, float]:
    from PIL import Image

    height, width = image.shape[:2]
    scale = min(1.0, max_side / max(height, width))
    if scale == 1.0:
        return image, 1.0
    size = (max(2, round(width * scale)), max(2, round(height * scale)))
    resized = np.asarray(Image.fromarray(image).resize(size, Image.Resampling.LANCZOS))
    return resized, size[0] / width


def segment(image: np.ndarray, config: VectorizeConfig) -> list[np.ndarray]:
    """SAM automatic masks of ``image`` (uint8 RGB), largest first, small ones dropped."""
    from samvg.sam import SamAutomaticMaskGenerator, load_sam

    model = load_sam(config.model, checkpoint=config.checkpoint)
    generator = SamAutomaticMaskGenerator(model, points_per_side=config.points_per_side)
    records = generator.generate(image)
    minimum = config.min_area_fraction * image.shape[0] * image.shape[1]
    masks = [r["segmentation"] for r in records if r["area"] >= max(minimum, 4)]
    masks.sort(key=lambda m: int(m.sum()), reverse=True)
    return masks[: config.max_paths]


def vectorize(
    image: np.ndarray,
    config: VectorizeConfig | None = None,
    progress: ProgressCallback | None = None,
) -> VectorImage:
    """Vectorize an RGB image (any layout :func:`samvg.io.to_rgb_uint8` accepts) into SVG paths."""
    from samvg.optimize import fit_paths
    from samvg.trace import trace_mask

    config = config or VectorizeConfig()
    report = progress or (lambda _stage, _done, _total: None)
    original = to_rgb_uint8(image)
    working, scale = _downscale(original, config.max_side)
    height, width = working.shape[:2]
    target = working.astype(np.float32) / 255.0

    report("segment", 0, 1)
    masks = segment(working, config)
    report("segment", 1, 1)

    covered = np.zeros((height, width), dtype=bool)
    points, colours = [], []
    for index, mask in enumerate(masks):
        report("trace", index, len(masks))
        try:
            points.append(trace_mask(mask, config.num_segments))
        except InputError:
            continue
        colours.append([*target[mask].mean(axis=0), 1.0])
        covered |= mask
    report("trace", len(masks), len(masks))
    background = tuple(target[~covered].mean(axis=0)) if (~covered).any() else (1.0, 1.0, 1.0)

    point_array = np.asarray(points).reshape(len(points), 3 * config.num_segments, 2)
    colour_array = np.asarray(colours, dtype=np.float64).reshape(len(colours), 4)
    result = fit_paths(
        point_array,
        colour_array,
        target,
        steps=config.steps,
        background=background,
        on_step=lambda step, _loss: report("optimize", step + 1, config.steps),
    )
    if not np.all(np.isfinite(result.points)):
        raise InputError("optimisation diverged (non-finite coordinates)")
    paths = [
        VectorPath(p / scale, tuple(np.clip(c, 0.0, 1.0)))
        for p, c in zip(result.points, result.colours, strict=True)
    ]
    return VectorImage(original.shape[1], original.shape[0], paths, background=background)
