"""Tonal regions: the large areas of one tone of a blurred image."""

import numpy as np

from samvg.config import Config
from samvg.segment.colour_split import lab_image
from samvg.segment.select import tonal_settings
from samvg.segment.tonal import TonalSettings, textured, tonal_regions

SETTINGS = TonalSettings(blur=3.0, tones=4, min_pixels=200.0)


def _bricks(size: int = 128) -> np.ndarray:
    """A dark wall of fine light mortar lines (left) beside a pale textured sky (right)."""
    rng = np.random.default_rng(3)
    image = np.empty((size, size, 3))
    image[:, : size // 2] = (0.35, 0.2, 0.15)
    image[::6, : size // 2] = (0.8, 0.8, 0.75)  # mortar: one-pixel lines every 6 rows
    image[:, size // 2 :] = (0.7, 0.8, 0.95)
    image[:, size // 2 :] += rng.normal(0.0, 0.05, (size, size - size // 2, 3))
    return np.clip(image, 0.0, 1.0)


def test_a_texture_s_light_and_dark_areas_are_one_region_each():
    image = _bricks()
    regions = tonal_regions(lab_image(image), SETTINGS)
    assert len(regions) >= 2
    wall, sky = np.zeros((128, 128), bool), np.zeros((128, 128), bool)
    wall[:, :64], sky[:, 64:] = True, True
    for half in (wall, sky):
        best = max(np.count_nonzero(r & half) / np.count_nonzero(r | half) for r in regions)
        assert best > 0.85  # not the mortar lines: the wall as a whole
    assert all(np.count_nonzero(r) >= SETTINGS.min_pixels for r in regions)
    areas = [np.count_nonzero(r) for r in regions]
    assert areas == sorted(areas, reverse=True)


def test_a_flat_image_has_no_tonal_regions():
    assert tonal_regions(lab_image(np.full((64, 64, 3), 0.4)), SETTINGS) == []


def test_tonal_regions_come_only_with_a_path_budget():
    assert tonal_settings(Config(), 512, 384) is None
    assert tonal_settings(Config(paths=16, tonal_regions=False), 512, 384) is None
    settings = tonal_settings(Config(paths=16), 512, 384)
    assert settings is not None and settings.blur == 0.008 * 512


def test_only_a_textured_image_gets_tonal_regions():
    rng = np.random.default_rng(5)
    noise = rng.uniform(0.0, 1.0, (128, 128, 3))
    assert textured(noise)
    assert not textured(np.full((128, 128, 3), 0.4))
    assert textured(_bricks())  # a wall and a grainy sky
