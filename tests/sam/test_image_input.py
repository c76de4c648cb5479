"""Image conversion for SAM: grayscale, RGBA, 16-bit and float inputs; empty/tiny images."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from samvg.errors import InputError
from samvg.sam import SamPredictor, to_rgb_uint8


def test_conversions():
    g = np.arange(12, dtype=np.uint8).reshape(3, 4)
    assert (to_rgb_uint8(g) == g[:, :, None]).all() and to_rgb_uint8(g).shape == (3, 4, 3)
    g16 = g.astype(np.uint16) * 257
    assert (to_rgb_uint8(g16)[:, :, 0] == g).all()
    rgba = np.zeros((2, 2, 4), np.uint8)
    rgba[..., 0] = 255
    rgba[0, 0, 3] = 255  # opaque red; others transparent -> white
    out = to_rgb_uint8(rgba)
    assert out[0, 0].tolist() == [255, 0, 0] and out[1, 1].tolist() == [255, 255, 255]
    f = np.full((2, 3, 3), 0.5, np.float32)
    assert (to_rgb_uint8(f) == 128).all()
    assert to_rgb_uint8(Image.fromarray(g16.astype(np.uint16))).shape == (3, 4, 3)
    assert to_rgb_uint8(Image.fromarray(rgba, "RGBA"))[1, 1].tolist() == [255, 255, 255]
    assert to_rgb_uint8(Image.fromarray(g).convert("P")).shape == (3, 4, 3)
    assert to_rgb_uint8(np.ones((2, 2, 1), bool)).max() == 255


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((0, 5, 3), np.uint8),
        np.zeros((5,), np.uint8),
        np.zeros((4, 4, 5), np.uint8),
        np.full((4, 4), np.nan, np.float32),
    ],
)
def test_bad_images(bad):
    with pytest.raises(InputError):
        to_rgb_uint8(bad)


def test_predictor_accepts_gray_rgba_16bit(sam_model, portrait, portrait_predictor):
    """Grayscale and 16-bit versions of the portrait segment like the original."""
    gray16 = (portrait.mean(2) * 257).astype(np.uint16)
    pred = SamPredictor(sam_model)
    pred.set_image(gray16)
    assert pred.original_size == (512, 341)
    m, s, _ = pred.predict(np.array([[180, 300]]), np.array([1]))
    m0, _, _ = portrait_predictor.predict(np.array([[180, 300]]), np.array([1]))
    inter = (m[2] & m0[2]).sum() / (m[2] | m0[2]).sum()
    assert inter > 0.8
    with pytest.raises(InputError):
        pred.set_image(np.zeros((1, 1), np.uint8))
