"""Colour-coherent parts of a mask: stripes and nested rings split, flat masks, soft seams and
small specks do not."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from samvg.config import Config
from samvg.missing.stage import MissingSettings
from samvg.segment.colour_split import ColourSplitSettings, colour_parts, lab_image
from samvg.segment.impact import ImpactCanvas
from samvg.segment.select import colour_split_settings, offer_colour_parts, same_colour_groups

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


def test_a_mask_moved_on_the_canvas_gives_the_same_parts_moved() -> None:
    def ringed(top: int, left: int) -> tuple[np.ndarray, np.ndarray]:
        image = _image(96)
        yy, xx = np.mgrid[:96, :96]
        radius = np.hypot(yy - top - 30, xx - left - 30)
        image[radius < 30] = WHITE
        image[(radius < 20) & (radius >= 10)] = RED
        image[radius < 10] = BLUE
        return radius < 30, image

    corner_mask, corner_image = ringed(0, 0)
    moved_mask, moved_image = ringed(33, 21)
    at_corner = colour_parts(corner_mask, lab_image(corner_image), SETTINGS)
    moved = colour_parts(moved_mask, lab_image(moved_image), SETTINGS)
    assert len(at_corner) == len(moved) == 2
    for part, moved_part in zip(at_corner, moved, strict=True):
        assert part.shape == moved_part.shape == (96, 96)
        assert np.array_equal(np.roll(part, (33, 21), axis=(0, 1)), moved_part)


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


def _shaded_stripes(size: int = 96) -> tuple[np.ndarray, np.ndarray]:
    """A grey panel shaded left to right (L* about 61 to 63) with darker stripes 7 ΔE below
    it, 4 px tall every 10 px (a Tango folder's back), on white, and its mask."""
    image = np.full((size, size, 3), 0.95, dtype=np.float32)
    mask = np.zeros((size, size), dtype=bool)
    mask[8:88, 8:88] = True
    shade = np.linspace(0.55, 0.58, size, dtype=np.float32)
    image[8:88, 8:88] = shade[None, 8:88, None]
    for top in range(14, 84, 10):
        image[top : top + 4, 8:88] -= 0.065
    return image, mask


def test_faint_flat_stripes_split_but_a_ramp_of_that_range_stays_whole() -> None:
    image, mask = _shaded_stripes()
    lab = lab_image(image)
    stripes = np.zeros_like(mask)
    for top in range(14, 84, 10):
        stripes[top : top + 4, 8:88] = True
    gap = np.linalg.norm(lab[20, 40] - lab[14, 40])
    assert 5 < gap < SETTINGS.contrast  # below the contrast that splits any two colours
    parts = colour_parts(mask, lab, SETTINGS)
    assert len(parts) == 7
    assert all(stripes[part].mean() > 0.95 for part in parts)

    ramp = _image(96)
    ramp[8:88, 8:88] = np.linspace(0.45, 0.6, 80, dtype=np.float32)[None, :, None]
    ramp_lab = lab_image(ramp)
    assert 5 < np.linalg.norm(ramp_lab[20, 87] - ramp_lab[20, 8]) / 2 < SETTINGS.contrast
    assert colour_parts(mask, ramp_lab, SETTINGS) == []


def test_stripes_too_small_alone_are_kept_together() -> None:
    image, mask = _shaded_stripes()
    canvas = ImpactCanvas(image, threshold=1e-4)
    canvas.offer(np.ones(mask.shape, dtype=bool), keep=True)
    canvas.offer(mask)
    for part in colour_parts(mask, lab_image(image), SETTINGS):
        assert canvas.impact_of(part)[0] < 1e-4  # each stripe alone falls under the threshold
    before = canvas.mean_error
    assert offer_colour_parts(canvas, SETTINGS) == 7
    stripes = canvas.kept_masks[-1]
    assert ndimage.label(stripes)[1] == 7  # one mask of seven stripes: seven paths when traced
    assert canvas.mean_error < before


def test_same_colour_groups_gather_parts_by_colour() -> None:
    image = _image()
    lab_parts = []
    for left, colour in ((4, RED), (20, BLUE), (36, RED), (52, WHITE)):
        part = np.zeros((64, 64), dtype=bool)
        part[10:20, left : left + 8] = True
        image[part] = colour
        lab_parts.append(part)
    groups = same_colour_groups(lab_parts, lab_image(image), 2.0)
    assert len(groups) == 1 and len(groups[0]) == 2  # the two red ones; blue and white alone
    assert all(np.allclose(image[part], RED) for part in groups[0])


def test_stage_4_does_not_split_faint_colours() -> None:
    stage_1 = colour_split_settings(Config(), 64, 64)
    stage_4 = MissingSettings.from_config(Config(), 64, 64).colour_split
    assert stage_1 is not None and stage_4 is not None
    assert stage_1.fine_contrast < stage_1.contrast
    assert stage_4.fine_contrast == stage_4.contrast == stage_1.contrast
