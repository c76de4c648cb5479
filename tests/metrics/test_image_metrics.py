"""MSE / PSNR / SSIM / JPEG complexity on constructed images with known values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from samvg.errors import InputError
from samvg.metrics import complexity, jpeg_compression, mse, psnr, ssim


def _const(value: float, h: int = 32, w: int = 48) -> np.ndarray:
    return np.full((h, w, 3), value, dtype=np.float64)


def _noise(seed: int = 0, h: int = 64, w: int = 64) -> np.ndarray:
    return np.random.default_rng(seed).random((h, w, 3))


def test_mse_and_psnr_known_values():
    assert mse(_const(0.2), _const(0.5)) == pytest.approx(0.09)
    assert psnr(_const(0.2), _const(0.5)) == pytest.approx(10 * math.log10(1 / 0.09))
    a = np.zeros((10, 10, 3))
    b = a.copy()
    b[0, 0, 0] = 1.0  # one channel of one pixel off by 1: MSE = 1 / 300
    assert mse(a, b) == pytest.approx(1 / 300)
    assert psnr(a, b) == pytest.approx(10 * math.log10(300))
    assert psnr(a, a) == math.inf
    # uint8 input is divided by 255
    u = np.full((4, 4, 3), 255, np.uint8)
    assert mse(u, np.zeros((4, 4, 3))) == pytest.approx(1.0)


def test_ssim_known_values():
    img = _noise()
    assert ssim(img, img) == pytest.approx(1.0)
    assert ssim(_const(0.3), _const(0.3)) == pytest.approx(1.0)
    noisy = np.clip(img + np.random.default_rng(1).normal(0, 0.2, img.shape), 0, 1)
    assert 0 < ssim(img, noisy) < 0.9
    assert ssim(img, 1 - img) < 0  # anti-correlated structure


def test_complexity_orders_flat_smooth_noise():
    flat = _const(0.4, 128, 128)
    yy, xx = np.mgrid[0:128, 0:128] / 127
    smooth = np.stack([xx, yy, (xx + yy) / 2], axis=-1)
    noise = _noise(2, 128, 128)
    c_flat, c_smooth, c_noise = complexity(flat), complexity(smooth), complexity(noise)
    assert 0 <= c_flat < c_smooth < c_noise
    assert c_flat < 0.01 and c_noise > 1.0
    rmse, ratio = jpeg_compression(noise)
    assert c_noise == pytest.approx(rmse / ratio)
    assert rmse > 10 and 1 < ratio < 5  # noise: big error, little compression
    rmse, ratio = jpeg_compression(flat)
    assert rmse < 1 and ratio > 50
    # uint8 and float of the same pixels agree; lower quality compresses more
    as_u8 = np.round(noise * 255).astype(np.uint8)
    assert complexity(as_u8) == pytest.approx(c_noise)
    assert jpeg_compression(noise, 20)[1] > jpeg_compression(noise, 95)[1]


def test_bad_inputs():
    with pytest.raises(InputError, match="differ in size"):
        mse(_const(0, 4, 4), _const(0, 4, 5))
    with pytest.raises(InputError, match="RGB"):
        psnr(np.zeros((4, 4)), np.zeros((4, 4)))
    with pytest.raises(InputError, match="NaN"):
        ssim(_const(np.nan), _const(0))
    with pytest.raises(InputError, match="7x7"):
        ssim(_const(0, 5, 40), _const(0, 5, 40))
    with pytest.raises(InputError, match="dtype"):
        complexity(np.zeros((8, 8, 3), np.int32))
    with pytest.raises(InputError, match="quality"):
        complexity(_const(0), quality=0)
