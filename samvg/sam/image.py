"""Image preparation for SAM: longest-side resizing (RGB conversion lives in samvg.imaging)."""

from __future__ import annotations

import numpy as np
from PIL import Image

from samvg.imaging import to_rgb_uint8

__all__ = ["resize_longest_side", "resized_shape", "to_rgb_uint8"]


def resized_shape(h: int, w: int, long_side: int) -> tuple[int, int]:
    """(h', w') with the longest side equal to ``long_side`` (SAM's ResizeLongestSide)."""
    scale = long_side / max(h, w)
    return int(h * scale + 0.5), int(w * scale + 0.5)


def resize_longest_side(image: np.ndarray, long_side: int) -> np.ndarray:
    """Bilinear resize of an RGB uint8 image so its longest side is ``long_side``."""
    h, w = image.shape[:2]
    nh, nw = resized_shape(h, w, long_side)
    if (nh, nw) == (h, w):
        return image
    return np.asarray(Image.fromarray(image).resize((nw, nh), Image.Resampling.BILINEAR))
