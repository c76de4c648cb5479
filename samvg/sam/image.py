"""Image input handling for SAM: conversion to RGB uint8 and longest-side resizing."""

from __future__ import annotations

import numpy as np
from PIL import Image

from samvg.errors import InputError

MIN_SIDE = 2


def to_rgb_uint8(image: np.ndarray | Image.Image) -> np.ndarray:
    """Return an (H, W, 3) uint8 RGB copy of ``image``.

    Accepts PIL images of any mode and numpy arrays (H, W), (H, W, 1|2|3|4) of dtype uint8,
    uint16 (or other integers, scaled down from 16 bit when > 255), bool, or float (values in
    [0, 1], or [0, 255] if any value exceeds 1). Grayscale is replicated to RGB; an alpha
    channel is composited over white. Raises `InputError` for empty images, images smaller than
    2x2, non-finite float values, or unsupported shapes.
    """
    if isinstance(image, Image.Image):
        if image.mode in ("I;16", "I;16B", "I;16L", "I;16N", "I", "F"):
            arr = np.asarray(image)
        elif image.mode in ("RGBA", "LA", "PA") or (
            image.mode == "P" and "transparency" in image.info
        ):
            arr = np.asarray(image.convert("RGBA"))
        else:
            arr = np.asarray(image.convert("RGB"))
    else:
        arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and arr.shape[2] not in (2, 3, 4)):
        raise InputError(f"unsupported image shape {arr.shape}; expected (H, W) or (H, W, 1-4)")
    h, w = arr.shape[:2]
    if h == 0 or w == 0:
        raise InputError(f"image is empty ({h}x{w} pixels)")
    if h < MIN_SIDE or w < MIN_SIDE:
        raise InputError(f"image is too small ({w}x{h} pixels); need at least 2x2")
    x = _to_unit_float(arr) if arr.dtype != np.uint8 else None
    if x is None:
        u8 = arr
        if u8.ndim == 2:
            return np.repeat(u8[:, :, None], 3, axis=2)
        if u8.shape[2] == 3:
            return np.ascontiguousarray(u8)
        x = u8.astype(np.float32) / 255.0
    if x.ndim == 2:
        x = np.repeat(x[:, :, None], 3, axis=2)
    elif x.shape[2] == 2:
        x = np.concatenate([np.repeat(x[:, :, :1], 3, axis=2), x[:, :, 1:]], axis=2)
    if x.shape[2] == 4:
        alpha = x[:, :, 3:4]
        x = x[:, :, :3] * alpha + (1.0 - alpha)
    return np.clip(np.rint(x * 255.0), 0, 255).astype(np.uint8)


def _to_unit_float(arr: np.ndarray) -> np.ndarray:
    """Scale any supported dtype to float32 in [0, 1]."""
    if arr.dtype == np.bool_:
        return arr.astype(np.float32)
    if np.issubdtype(arr.dtype, np.floating):
        x = arr.astype(np.float32)
        if not np.isfinite(x).all():
            raise InputError("image contains NaN or infinite values")
        if x.size and x.max() > 1.0:
            x = x / 255.0
        return np.clip(x, 0.0, 1.0)
    if np.issubdtype(arr.dtype, np.integer):
        x = arr.astype(np.float32)
        if arr.dtype == np.uint16 or (x.size and x.max() > 255):
            return np.clip(x / 65535.0, 0.0, 1.0)
        return np.clip(x / 255.0, 0.0, 1.0)
    raise InputError(f"unsupported image dtype {arr.dtype}")


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
