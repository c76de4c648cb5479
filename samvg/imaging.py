"""Raster images in memory: conversion to uint8 or float RGB, resizing to a working size, the
per-pixel error map and connected-component labelling of masks.

Every other module converts, resizes, compares and labels through these functions, so a rule
(how 16-bit input scales, how alpha composites, what a component is) has one place.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from PIL import Image
from scipy import ndimage

from samvg.errors import InputError


def to_rgb_uint8(image: np.ndarray | Image.Image, min_side: int = 1) -> np.ndarray:
    """Return an (H, W, 3) uint8 RGB copy of ``image``.

    Accepts PIL images of any mode and numpy arrays (H, W), (H, W, 1|2|3|4) of dtype uint8,
    uint16 (or other integers, scaled down from 16 bit when > 255), bool, or float (values in
    [0, 1], or [0, 255] if any value exceeds 1). Grayscale is replicated to RGB; an alpha
    channel is composited over white. Raises `InputError` for empty images, images with a side
    below ``min_side`` (1: any image; SAM asks for 2), non-finite float values, or unsupported
    shapes.
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
    if h < min_side or w < min_side:
        raise InputError(
            f"image is too small ({w}x{h} pixels); need at least {min_side}x{min_side}"
        )
    if arr.dtype == np.uint8:
        if arr.ndim == 2:
            return np.repeat(arr[:, :, None], 3, axis=2)
        if arr.shape[2] == 3:
            return np.ascontiguousarray(arr)
        x = arr.astype(np.float32) / 255.0
    else:
        x = _to_unit_float(arr)
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


def alpha_channel(image: np.ndarray | Image.Image) -> np.ndarray | None:
    """The opacity of an image with an alpha channel as float32 (H, W) in [0, 1], or None when
    it has none or every pixel is opaque (the image is then treated as opaque)."""
    if isinstance(image, Image.Image):
        if image.mode not in ("RGBA", "LA", "PA") and not (
            image.mode == "P" and "transparency" in image.info
        ):
            return None
        alpha = np.asarray(image.convert("RGBA"))[:, :, 3].astype(np.float32) / 255.0
    else:
        array = np.asarray(image)
        if array.ndim != 3 or array.shape[2] not in (2, 4):
            return None
        alpha = (
            _to_unit_float(array[:, :, -1])
            if array.dtype != np.uint8
            else (array[:, :, -1].astype(np.float32) / 255.0)
        )
    return alpha if alpha.size and float(alpha.min()) < 1.0 else None


def to_float_rgb(image: np.ndarray | Image.Image, name: str = "image") -> np.ndarray:
    """``image`` as a float32 (H, W, 3) array in [0, 1]: the one uint8-to-float rule of samvg.

    uint8 RGB is divided by 255; float RGB must be finite and in [0, 1] (kept as it is); any
    other array or PIL image goes through :func:`to_rgb_uint8` first. ``name`` labels errors.
    """
    array = np.asarray(image)
    if array.ndim == 3 and array.shape[2] == 3 and array.dtype == np.uint8:
        return array.astype(np.float32) / np.float32(255.0)
    if array.ndim == 3 and array.shape[2] == 3 and np.issubdtype(array.dtype, np.floating):
        if array.size and not np.isfinite(array).all():
            raise InputError(f"{name} has NaN or infinite values")
        if array.size and (array.min() < 0.0 or array.max() > 1.0):
            raise InputError(f"{name}: float values must be in [0, 1]")
        return array.astype(np.float32)
    return to_rgb_uint8(image).astype(np.float32) / np.float32(255.0)


def resize_longest(image: np.ndarray, size: int) -> tuple[np.ndarray, float]:
    """Downscale a uint8 (H, W, 3) image so its longer side is at most ``size`` (Lanczos).

    Returns the image (unchanged when already small enough) and the scale applied, as working
    pixels per input pixel along x (the width is what the coordinates are scaled by).
    """
    height, width = image.shape[:2]
    scale = min(1.0, size / max(height, width))
    if scale == 1.0:
        return image, 1.0
    new_size = (max(2, round(width * scale)), max(2, round(height * scale)))
    resized = np.asarray(Image.fromarray(image).resize(new_size, Image.Resampling.LANCZOS))
    return resized, new_size[0] / width


def halve(image: np.ndarray) -> np.ndarray:
    """A float (H, W, C) image at half size, each pixel the mean of a 2 × 2 block (an odd last
    row or column is repeated): (ceil(H / 2), ceil(W / 2), C)."""
    height, width = image.shape[:2]
    padded = np.pad(image, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
    blocks = padded.reshape(padded.shape[0] // 2, 2, padded.shape[1] // 2, 2, -1)
    return blocks.mean(axis=(1, 3), dtype=np.float64).astype(image.dtype)


def error_map(target: np.ndarray, render: np.ndarray) -> np.ndarray:
    """D: per-pixel sum over R, G, B of |target − render| (float32, values in [0, 3])."""
    return np.abs(np.asarray(target, np.float32) - np.asarray(render, np.float32)).sum(axis=2)


@dataclass(frozen=True)
class Labels:
    """The 4-connected components of a mask, labelled on its bounding box padded by one pixel.

    ``labels[i, j]`` is mask pixel (``origin[0] + i``, ``origin[1] + j``); ``ids`` are the kept
    labels, largest first (ties in label order); ``areas`` their pixel counts; ``boxes`` their
    bounding boxes as slices of ``labels``.
    """

    labels: np.ndarray
    origin: tuple[int, int]
    ids: np.ndarray
    areas: np.ndarray
    boxes: list[tuple[slice, slice]]


def label_components(mask: np.ndarray, min_pixels: float = 1) -> Labels:
    """Label the 4-connected components of a boolean (H, W) mask; keep those with at least
    ``min_pixels`` pixels (and at least one), largest first."""
    binary = np.asarray(mask)
    if binary.ndim != 2:
        raise InputError(f"mask must be two-dimensional, got shape {binary.shape}")
    binary = binary.astype(bool, copy=False)
    rows = np.flatnonzero(binary.any(axis=1))
    empty = np.zeros(0, dtype=np.int64)
    if len(rows) == 0:
        return Labels(np.zeros((2, 2), np.int32), (-1, -1), empty, empty, [])
    cols = np.flatnonzero(binary.any(axis=0))
    crop = binary[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
    labels, count = ndimage.label(np.pad(crop, 1))
    origin = (int(rows[0]) - 1, int(cols[0]) - 1)
    if count == 1:  # the common case: skip counting and boxing, the crop is the box
        areas = np.array([0, int(np.count_nonzero(crop))])
        boxes = [(slice(1, crop.shape[0] + 1), slice(1, crop.shape[1] + 1))]
    else:
        areas = np.bincount(labels.ravel(), minlength=count + 1)
        boxes = ndimage.find_objects(labels)
    ids = np.flatnonzero(areas >= max(min_pixels, 1))
    ids = ids[ids > 0]
    ids = ids[np.argsort(-areas[ids], kind="stable")]
    return Labels(labels, origin, ids, areas[ids], [boxes[label - 1] for label in ids])


def filled_components(mask: np.ndarray, min_pixels: float) -> list[np.ndarray]:
    """The components of ``mask`` with at least ``min_pixels`` pixels as full-size boolean
    masks with their holes filled, largest first: each is what one traced path will cover."""
    found = label_components(mask, min_pixels)
    shape = np.asarray(mask).shape
    top, left = found.origin
    components = []
    for label, (rows, cols) in zip(found.ids, found.boxes, strict=True):
        component = np.zeros(shape, dtype=bool)
        component[top + rows.start : top + rows.stop, left + cols.start : left + cols.stop] = (
            ndimage.binary_fill_holes(found.labels[rows, cols] == label)
        )
        components.append(component)
    return components
