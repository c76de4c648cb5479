"""samvg.imaging: float conversion, resizing, error maps and component labelling."""

import numpy as np
import pytest

from samvg import InputError
from samvg.imaging import (
    error_map,
    filled_components,
    halve,
    label_components,
    resize_longest,
    to_float_rgb,
)


def test_float_conversion_of_uint8_float_and_other_inputs():
    pixels = np.array([[[0, 128, 255]] * 2] * 2, np.uint8)
    np.testing.assert_allclose(to_float_rgb(pixels)[0, 0], (0.0, 128 / 255, 1.0), rtol=1e-7)
    assert to_float_rgb(pixels).dtype == np.float32
    floats = np.full((2, 2, 3), 0.25, np.float64)
    assert to_float_rgb(floats).dtype == np.float32 and to_float_rgb(floats)[0, 0, 0] == 0.25
    grey = np.full((3, 3), 65535, np.uint16)
    np.testing.assert_allclose(to_float_rgb(grey), 1.0)
    with pytest.raises(InputError, match=r"\[0, 1\]"):
        to_float_rgb(np.full((2, 2, 3), 2.0))
    with pytest.raises(InputError, match="NaN"):
        to_float_rgb(np.full((2, 2, 3), np.nan))


def test_resize_keeps_small_images_and_scales_the_longer_side():
    image = np.zeros((100, 200, 3), np.uint8)
    same, scale = resize_longest(image, 400)
    assert same is image and scale == 1.0
    smaller, scale = resize_longest(image, 50)
    assert smaller.shape == (25, 50, 3) and scale == 0.25


def test_halving_averages_blocks_and_repeats_an_odd_edge():
    image = np.arange(5 * 3 * 1, dtype=np.float32).reshape(5, 3, 1)
    half = halve(image)
    assert half.shape == (3, 2, 1) and half.dtype == np.float32
    assert half[0, 0, 0] == pytest.approx((0 + 1 + 3 + 4) / 4)
    assert half[0, 1, 0] == pytest.approx((2 + 2 + 5 + 5) / 4)  # the last column repeated
    assert half[2, 0, 0] == pytest.approx((12 + 13 + 12 + 13) / 4)  # the last row repeated


def test_error_map_sums_channels():
    target = np.zeros((2, 2, 3), np.float32)
    render = np.full((2, 2, 3), 0.5, np.float32)
    np.testing.assert_allclose(error_map(target, render), 1.5)


def test_components_are_labelled_largest_first_filled_and_tiny_ones_dropped():
    mask = np.zeros((30, 40), bool)
    mask[2:12, 2:12] = True
    mask[5:8, 5:8] = False  # a hole: filled
    mask[20:28, 20:36] = True  # the larger component
    mask[0, 39] = True  # a speck: dropped
    labels = label_components(mask, 4)
    assert list(labels.areas) == [128, 91]
    parts = filled_components(mask, min_pixels=4)
    assert [int(p.sum()) for p in parts] == [128, 100]
    assert parts[1][6, 6] and not (parts[0] & parts[1]).any()
    assert filled_components(np.zeros((5, 5), bool), 1) == []
