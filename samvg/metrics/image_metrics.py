"""Pixel metrics between two RGB images (MSE, PSNR, SSIM) and JPEG-based image complexity.

Images are numpy ``(H, W, 3)`` arrays: float in [0, 1], or uint8 (divided by 255).

`complexity` is the image complexity of Machado & Cardoso (1998, "Computing aesthetics", SBIA),
the "Complexity" column of the SAMVG paper's tables: compress the image with JPEG and divide the
compression error by the compression ratio,

    IC(I) = RMSE(I, JPEG(I)) / (size(I) / size(JPEG(I)))

- ``RMSE``: root mean squared difference over all pixels and the three RGB channels, in 8-bit
  units (0..255), between the image and its decoded JPEG;
- ``size(I)``: the uncompressed size, ``H * W * 3`` bytes; ``size(JPEG(I))``: the bytes of the
  JPEG file (Pillow / libjpeg, baseline, 4:2:0 chroma subsampling, no optimisation);
- JPEG quality 75, the setting Machado & Cardoso's image-complexity estimate is described with.

Hard to predict images (noise, texture) compress badly and with large error: high IC; flat
colour fields compress well and almost losslessly: IC near 0. The SAMVG paper states neither
the quality nor the units, so its absolute numbers (about 11) are not reproducible from the
text; compare methods with this function, not with the paper's values.
"""

from __future__ import annotations

import io
import math

import numpy as np
from PIL import Image
from skimage.metrics import structural_similarity

from samvg.errors import InputError
from samvg.imaging import to_float_rgb

__all__ = ["complexity", "jpeg_compression", "mse", "psnr", "ssim"]

JPEG_QUALITY = 75


def _as_rgb_float(image: np.ndarray, name: str) -> np.ndarray:
    """An (H, W, 3) uint8 or [0, 1] float image as float64, converted by `to_float_rgb`."""
    arr = np.asarray(image)
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise InputError(f"{name}: expected an (H, W, 3) RGB image, got shape {arr.shape}")
    if arr.dtype != np.uint8 and not np.issubdtype(arr.dtype, np.floating):
        raise InputError(f"{name}: unsupported dtype {arr.dtype} (use uint8 or float in [0, 1])")
    rgb = to_float_rgb(arr, name)  # checks the values; float32
    if arr.dtype == np.float64:
        return arr.astype(np.float64)  # keep the precision that float32 would round away
    return rgb.astype(np.float64)


def _pair(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    fa, fb = _as_rgb_float(a, "first image"), _as_rgb_float(b, "second image")
    if fa.shape != fb.shape:
        raise InputError(f"images differ in size: {fa.shape} vs {fb.shape}")
    return fa, fb


def mse(a: np.ndarray, b: np.ndarray) -> float:
    """Mean squared error over all pixels and channels, on the [0, 1] scale."""
    fa, fb = _pair(a, b)
    return float(np.mean((fa - fb) ** 2))


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    """Peak signal-to-noise ratio in dB for data range 1: ``10 log10(1 / MSE)``; inf if equal."""
    err = mse(a, b)
    return math.inf if err == 0 else 10.0 * math.log10(1.0 / err)


def ssim(a: np.ndarray, b: np.ndarray) -> float:
    """Mean SSIM (scikit-image defaults: 7x7 uniform window), colour channels averaged."""
    fa, fb = _pair(a, b)
    if min(fa.shape[:2]) < 7:
        raise InputError(f"SSIM needs images of at least 7x7 pixels, got {fa.shape[:2]}")
    return float(structural_similarity(fa, fb, channel_axis=2, data_range=1.0))


def _as_rgb_uint8(image: np.ndarray) -> np.ndarray:
    arr = np.asarray(image)
    if arr.dtype == np.uint8 and arr.ndim == 3 and arr.shape[2] == 3:
        return arr
    return np.round(np.clip(_as_rgb_float(arr, "image"), 0.0, 1.0) * 255.0).astype(np.uint8)


def jpeg_compression(image: np.ndarray, quality: int = JPEG_QUALITY) -> tuple[float, float]:
    """``(rmse, ratio)`` of JPEG-compressing an RGB image at ``quality``.

    ``rmse`` is in 8-bit units (0..255) over all pixels and channels; ``ratio`` is the
    uncompressed size ``H * W * 3`` divided by the JPEG file size.
    """
    if not 1 <= quality <= 100:
        raise InputError(f"JPEG quality must be in 1..100, got {quality}")
    pixels = _as_rgb_uint8(image)
    buf = io.BytesIO()
    Image.fromarray(pixels, "RGB").save(buf, format="JPEG", quality=int(quality))
    size = buf.tell()
    buf.seek(0)
    with Image.open(buf) as decoded:
        back = np.asarray(decoded.convert("RGB"), dtype=np.float64)
    rmse = float(np.sqrt(np.mean((pixels.astype(np.float64) - back) ** 2)))
    return rmse, pixels.size / size


def complexity(image: np.ndarray, quality: int = JPEG_QUALITY) -> float:
    """Machado & Cardoso image complexity: JPEG RMSE / compression ratio (see module doc)."""
    rmse, ratio = jpeg_compression(image, quality)
    return rmse / ratio
