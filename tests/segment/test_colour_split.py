"""Colour-coherent parts of a mask: stripes and nested rings split, flat masks, soft seams and
small specks do not."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from samvg.segment.colour_split import ColourSplitSettings, colour_parts, lab_image
from samvg.segment.impact import ImpactCanvas
from samvg.segment.select import offer_colour_parts

SETTINGS = ColourSplitSettings(min_pixels=20)
RED, WHITE, BLUE = (0.8, 0.1, 0.15), (0.97, 0.95, 0.85), (0.1, 0.2, 0.7)


def _image(size: int = 64) -> np.ndarray:
    return np.full((size, size, 3), 0.5, dtype=np.float32)


def test_a_striped_mask_splits_into_its_stripes() -> None:
    image = _image()
    mask = np.zeros((64, 64), dtype=bool)
    mask[8:56, 8:56] = True
    image[mask] = WHITE
    for top in (14, 30, 46):  # three red stripes, 6 px tall, on a white sail
        image[top : top + 6, 8:56] = RED
    parts = colour_parts(mask, lab_image(image), SETTINGS)
    assert len(parts) == 3
    for part in parts:
        colours = image[part]
        assert np.allclose(colours, RED)
    assert not np.logical_or.reduce(parts)[mask & np.all(image == WHITE, axis=2)].any()


def test_a_flat_or_softly_shaded_mask_stays_whole() -> None:
    image = _image()
    mask = np.zeros((64, 64), dtype=bool)
    mask[4:60, 4:60] = True
    ramp = np.linspace(0.0, 0.03, 64, dtype=np.float32)  # below the contrast of two colours
    image[:, :, 0] = 0.4 + ramp[None, :]
    assert colour_parts(mask, lab_image(image), SETTINGS) == []


def test_a_ring_part_is_split_again_for_what_it_encloses() -> None:
    image = _image()
    yy, xx = np.mgrid[:64, :64]
    radius = np.hypot(yy - 32, xx - 32)
    mask = radius < 30
    image[mask] = WHITE
    image[(radius < 20) & (radius >= 10)] = RED
    image[radius < 10] = BLUE
    parts = colour_parts(mask, lab_image(image), SETTINGS)
    sizes = sorted(int(part.sum()) for part in parts)
    assert len(parts) == 2
    assert abs(sizes[1] - np.count_nonzero(radius < 20)) < 20  # the ring, filled
    assert abs(sizes[0] - np.count_nonzero(radius < 10)) < 20  # the disc it holds


def test_anti_aliased_seams_and_specks_make_no_parts() -> None:
    image = _image()
    mask = np.zeros((64, 64), dtype=bool)
    mask[4:60, 4:60] = True
    image[mask] = WHITE
    image[4:60, 30:60] = BLUE
    image[4:60, 29] = np.add(WHITE, BLUE) / 2  # a one-pixel seam of the mixed colour
    image[10:13, 10:13] = RED  # a 9-pixel speck
    parts = colour_parts(mask, lab_image(image), SETTINGS)
    assert len(parts) == 1
    colours = image[parts[0]]
    share = max(np.all(np.isclose(colours, c), axis=1).mean() for c in (WHITE, BLUE))
    assert share > 0.99  # one colour; the speck is below the smallest part and filled over
    assert 25 * 56 <= parts[0].sum() <= 30 * 56


def test_parts_are_offered_to_the_canvas_and_lower_its_error() -> None:
    image = _image()
    mask = np.zeros((64, 64), dtype=bool)
    mask[8:56, 8:56] = True
    image[mask] = WHITE
    image[20:40, 20:40] = RED
    canvas = ImpactCanvas(image, threshold=1e-4)
    canvas.offer(np.ones((64, 64), dtype=bool), keep=True)
    canvas.offer(mask)
    before = canvas.mean_error
    kept = offer_colour_parts(canvas, SETTINGS)
    assert kept == 1
    assert canvas.mean_error < before / 2  # the parent keeps its mean colour until the fit
    red_part = canvas.kept_masks[-1]
    assert ndimage.label(red_part)[1] == 1 and np.allclose(image[red_part], RED)
